//! The working memory: caller slices of run-time length ([`Storage`]), and a fixed-capacity
//! [`Workspace`] sized at compile time that lends them.
//!
//! Both have the same two entry points: [`Storage::simplify`] for the common case (read-only
//! positions, the built-in cost [`Config::cost`] names, no error bound) and [`Storage::start`]
//! for everything else, with the cost (and its placement) and the error bound as values:
//!
//! ```text
//! ws.simplify(&positions, &mut triangles, &config)                                  // common case
//! ws.start(Positions::Read(&p), &mut t, &config, Builtin::new(), NoBound)?.run()  // = the line above
//! ws.start(Positions::Read(&p), &mut t, &config, StoredQuadric::new(&mut q, Placement::Subset),
//!          Controls::new(&original, &mut links))?.run()                             // stored + bound
//! ws.start(Positions::Write(&mut p), &mut t, &config, StoredQuadric::new(&mut q, Placement::Optimal),
//!          NoBound)?                                                                // a stepping Simplifier
//! ```
//!
//! Each policy checks its own storage and configuration when the run starts, before anything
//! is written: [`StoredQuadric`] one quadric per position and the greedy schedule,
//! [`Controls`] its links and original triangles, [`NoBound`] that [`Config::max_error`] is
//! infinite; optimal placement needs [`Positions::Write`] and no bound (the bound's control
//! points are read at the positions placement would move). A refusal names the field
//! ([`Error::InvalidConfig`]) or the storage ([`Error::Capacity`]).
//!
//! [`StoredQuadric`]: crate::cost::StoredQuadric
//! [`Controls`]: crate::bound::Controls

use crate::engine::heap::Heap;
use crate::engine::Simplifier;
use crate::index::Index;
use crate::mesh::Mesh;
use crate::operator::{EdgeCollapse, Kind, Operator};
use crate::policy::bound::{Bound, NoBound};
use crate::policy::cost::{Builtin, Cost, Placement};
use crate::{Capacity, Config, ConfigField, Error, Report, Schedule};

pub use crate::mesh::Positions;

/// The simplifier's working memory as caller slices of run-time length (sized to the mesh on
/// a host, or lent by a [`Workspace`] with [`Workspace::as_storage`]).
///
/// Per vertex: three links (corner-list head, heap slot, heap position), a 4-byte key and a
/// flag byte; per triangle: three corner links. [`Storage::bytes`] gives the total. With `u16`
/// links a mesh may have at most 65 535 vertices and 65 535 triangles (the largest value is
/// reserved as "none"); `u32` links take any mesh that fits in memory.
pub struct Storage<'a, L: Index> {
    head: &'a mut [L],
    heap: &'a mut [L],
    heap_pos: &'a mut [L],
    next: &'a mut [[L; 3]],
    keys: &'a mut [f32],
    flags: &'a mut [u8],
}

impl<'a, L: Index> Storage<'a, L> {
    /// Bytes of storage per vertex.
    pub const VERTEX_BYTES: usize = 3 * core::mem::size_of::<L>() + 5;
    /// Bytes of storage per triangle.
    pub const TRIANGLE_BYTES: usize = 3 * core::mem::size_of::<L>();

    /// Bytes of storage for a mesh of `vertices` positions and `triangles` triangles.
    pub const fn bytes(vertices: usize, triangles: usize) -> usize {
        vertices * Self::VERTEX_BYTES + triangles * Self::TRIANGLE_BYTES
    }

    /// Storage for `keys.len()` vertices and `corners.len()` triangles: `links` holds three
    /// links per vertex and `flags` one byte per vertex (contents on entry do not matter).
    /// Slices that disagree are [`Error::Capacity`] for [`Capacity::Vertices`] (`needed`: the
    /// keys' length, `available`: what the shorter slice holds).
    pub fn new(
        links: &'a mut [L],
        corners: &'a mut [[L; 3]],
        keys: &'a mut [f32],
        flags: &'a mut [u8],
    ) -> Result<Self, Error> {
        let nv = keys.len();
        let short = Error::Capacity {
            what: Capacity::Vertices,
            needed: nv,
            available: (links.len() / 3).min(flags.len()),
        };
        if flags.len() != nv || links.len() != nv.saturating_mul(3) {
            return Err(short);
        }
        let (head, rest) = links.split_at_mut_checked(nv).ok_or(short)?;
        let (heap, heap_pos) = rest.split_at_mut_checked(nv).ok_or(short)?;
        Ok(Storage {
            head,
            heap,
            heap_pos,
            next: corners,
            keys,
            flags,
        })
    }

    /// The largest mesh it takes: `(vertices, triangles)`, the link type's limit included.
    pub fn capacity(&self) -> (usize, usize) {
        (self.keys.len().min(L::COUNT), self.next.len().min(L::COUNT))
    }

    /// The queue's slots, one link per vertex: scratch before a run (the build writes them).
    #[cfg(feature = "seams")]
    pub(crate) fn queue_links(&mut self) -> &mut [L] {
        self.heap
    }

    /// A shorter-lived copy of the same storage (to run again after a [`Storage::start`]).
    pub fn reborrow(&mut self) -> Storage<'_, L> {
        Storage {
            head: &mut *self.head,
            heap: &mut *self.heap,
            heap_pos: &mut *self.heap_pos,
            next: &mut *self.next,
            keys: &mut *self.keys,
            flags: &mut *self.flags,
        }
    }

    /// Simplifies `triangles` in place, in one call: read-only `positions`, the built-in cost
    /// [`Config::cost`] names, no error bound.
    ///
    /// On success the first `report.triangles_out` entries of `triangles` hold the result,
    /// referring to the original vertex indices; the rest of the buffer is left over and
    /// meaningless. On error nothing has been written. Errors as [`Storage::start`].
    pub fn simplify<I: Index>(
        &mut self,
        positions: &[[f32; 3]],
        triangles: &mut [[I; 3]],
        config: &Config,
    ) -> Result<Report, Error> {
        // One engine for every built-in configuration (the schedule and the built-in cost are
        // chosen at run time, so a configuration received at run time costs no extra flash).
        // For the least flash with one known cost, `start` with that cost.
        let mut s = self.reborrow().start(
            Positions::Read(positions),
            triangles,
            config,
            Builtin::new(),
            NoBound,
            EdgeCollapse,
        )?;
        while !s.step(u32::MAX) {}
        Ok(s.finish())
    }

    /// Validates the input, builds adjacency and returns a [`Simplifier`] to drive step by
    /// step ([`Simplifier::step`], for watchdogs and frame deadlines) or to the end
    /// ([`Simplifier::run`]). Steps of any size give exactly the result of one run.
    ///
    /// * `positions`: [`Positions::Read`] (flash is fine), or [`Positions::Write`] for a cost
    ///   with [`Placement::Optimal`], which writes each kept vertex there.
    /// * `cost`: [`Builtin::new`]`()` (the cost [`Config::cost`] names: what [`Storage::simplify`] uses), any other
    ///   [`Cost`], e.g. [`StoredQuadric`](crate::cost::StoredQuadric).
    /// * `bound`: [`NoBound`], or the guaranteed error bound [`Config::max_error`] with
    ///   [`Controls`](crate::bound::Controls) (Zhu, Wang and Meng 2007; see [`crate::bound`]).
    /// * `operator`: [`EdgeCollapse`], [`TriangleCollapse`](crate::TriangleCollapse) (greedy
    ///   schedule only) or [`VertexDecimation`](crate::VertexDecimation) (greedy schedule, no
    ///   bound).
    ///
    /// Errors, all returned before the triangle buffer (or the positions) is touched:
    /// [`Error::InvalidConfig`] (a field out of range, or a policy that cannot run with it),
    /// [`Error::OriginalMismatch`], [`Error::Capacity`], [`Error::IndexOutOfRange`],
    /// [`Error::NonFinitePosition`].
    #[inline(always)]
    pub fn start<I: Index, C: Cost, B: Bound<'a, I>, O: Operator>(
        self,
        positions: Positions<'a>,
        triangles: &'a mut [[I; 3]],
        config: &Config,
        mut cost: C,
        mut bound: B,
        operator: O,
    ) -> Result<Simplifier<'a, L, I, C, B, O>, Error> {
        let nv = positions.len();
        let nt = triangles.len();
        if B::ON {
            // A bound's own storage first: its original triangles and its links.
            bound.prepare(triangles, nv, config)?;
        }
        config.validate()?;
        if config.schedule == Schedule::Batched && !cfg!(feature = "batched") {
            return Err(Error::InvalidConfig {
                field: ConfigField::Schedule,
            });
        }
        if (!matches!(O::KIND, Kind::Edge) && config.schedule != Schedule::Greedy)
            || (matches!(O::KIND, Kind::Removal) && B::ON && !B::FILLS)
        {
            return Err(Error::InvalidConfig {
                field: ConfigField::Operator,
            });
        }
        if config.error_limit.is_finite()
            && (matches!(O::KIND, Kind::Triangle) || !config.schedule.is_ordered())
        {
            // Only the greedy and batched edge collapse and vertex removal measure each
            // operation's own error.
            return Err(Error::InvalidConfig {
                field: ConfigField::ErrorLimit,
            });
        }
        if !B::ON {
            bound.prepare(triangles, nv, config)?;
        }
        cost.configure(config, nv)?;
        if cost.placement() == Placement::Optimal && (B::ON || !positions.is_write()) {
            // The bound reads control points at the positions placement would move.
            return Err(Error::InvalidConfig {
                field: ConfigField::Placement,
            });
        }
        let (cv, ct) = self.capacity();
        if nv > cv {
            return Err(Error::Capacity {
                what: Capacity::Vertices,
                needed: nv,
                available: cv,
            });
        }
        // Links number triangles (not corners), so the link type caps triangles at its COUNT.
        if nt > ct {
            return Err(Error::Capacity {
                what: Capacity::Triangles,
                needed: nt,
                available: ct,
            });
        }
        let Storage {
            head,
            heap,
            heap_pos,
            next,
            keys,
            flags,
        } = self;
        // `get_mut` with lengths just checked against the capacities: cannot fail, but costs
        // nothing and keeps every path panic-free.
        let (Some(head), Some(next), Some(flags), Some(heap), Some(heap_pos), Some(key)) = (
            head.get_mut(..nv),
            next.get_mut(..nt),
            flags.get_mut(..nv),
            heap.get_mut(..nv),
            heap_pos.get_mut(..nv),
            keys.get_mut(..nv),
        ) else {
            return Err(Error::Capacity {
                what: Capacity::Vertices,
                needed: nv,
                available: cv,
            });
        };
        let mesh = Mesh::build(
            positions,
            triangles,
            head,
            next,
            flags,
            (&mut *heap, &mut *heap_pos),
        )?;
        Ok(Simplifier::new(
            mesh,
            Heap::new(heap, heap_pos, key),
            *config,
            cost,
            bound,
            operator,
        ))
    }
}

/// A fixed-capacity [`Storage`], sized by const generics, that can be a `static`.
///
/// * `L`: link type (`u16` or `u32`) for vertex and corner numbers inside the workspace. With
///   `u16` a mesh may have at most 65 535 vertices and 65 535 triangles (the largest value is
///   reserved as "none").
/// * `MAX_VERTICES`, `MAX_TRIANGLES`: the largest mesh it takes.
///
/// Its size is [`Workspace::BYTES`]: per vertex three links (corner-list head, heap slot, heap
/// position), a 4-byte key and a flag byte; per triangle three corner links. With `u16` links
/// and the usual `V ≈ T/2` that is 11.5 bytes per triangle. [`Workspace::new`] is a `const fn`,
/// so a workspace can be a `static` in `.bss` instead of living on the stack.
///
/// The positions are never copied: they stay wherever the caller keeps them (flash included).
pub struct Workspace<L: Index, const MAX_VERTICES: usize, const MAX_TRIANGLES: usize> {
    /// Per vertex: the triangle of the first corner of its corner list (NIL: none), its heap
    /// slot and its slot's vertex (the greedy schedule's binary heap).
    links: [[L; MAX_VERTICES]; 3],
    /// For corner `4t + k`, the triangle of the next corner around the same vertex.
    next: [[L; 3]; MAX_TRIANGLES],
    /// Per-vertex flags, see `mesh::flag`.
    flags: [u8; MAX_VERTICES],
    /// Each vertex's key, the cost of its cheapest legal collapse.
    key: [f32; MAX_VERTICES],
}

impl<L: Index, const MAX_VERTICES: usize, const MAX_TRIANGLES: usize>
    Workspace<L, MAX_VERTICES, MAX_TRIANGLES>
{
    /// Size of the workspace in bytes: all of the simplifier's RAM apart from the caller's
    /// triangle buffer, positions and a bounded stack frame.
    pub const BYTES: usize = core::mem::size_of::<Self>();

    /// An empty workspace. `const`, so it can initialise a `static`; and all zero bits, so
    /// such a `static` goes to `.bss` (zeroed at boot) instead of taking its size again in
    /// flash as `.data`. Nothing here is read before [`Storage::start`] writes it.
    pub const fn new() -> Self {
        Workspace {
            links: [[L::ZERO; MAX_VERTICES]; 3],
            next: [[L::ZERO; 3]; MAX_TRIANGLES],
            flags: [0; MAX_VERTICES],
            key: [0.0; MAX_VERTICES],
        }
    }

    /// The workspace as [`Storage`] of `MAX_VERTICES` vertices and `MAX_TRIANGLES` triangles.
    pub fn as_storage(&mut self) -> Storage<'_, L> {
        let [head, heap, heap_pos] = &mut self.links;
        Storage {
            head,
            heap,
            heap_pos,
            next: &mut self.next,
            keys: &mut self.key,
            flags: &mut self.flags,
        }
    }

    /// [`Storage::simplify`] on this workspace.
    pub fn simplify<I: Index>(
        &mut self,
        positions: &[[f32; 3]],
        triangles: &mut [[I; 3]],
        config: &Config,
    ) -> Result<Report, Error> {
        self.as_storage().simplify(positions, triangles, config)
    }

    /// [`Storage::start`] on this workspace.
    pub fn start<'a, I: Index, C: Cost, B: Bound<'a, I>, O: Operator>(
        &'a mut self,
        positions: Positions<'a>,
        triangles: &'a mut [[I; 3]],
        config: &Config,
        cost: C,
        bound: B,
        operator: O,
    ) -> Result<Simplifier<'a, L, I, C, B, O>, Error> {
        self.as_storage()
            .start(positions, triangles, config, cost, bound, operator)
    }
}

impl<L: Index, const MAX_VERTICES: usize, const MAX_TRIANGLES: usize> Default
    for Workspace<L, MAX_VERTICES, MAX_TRIANGLES>
{
    fn default() -> Self {
        Self::new()
    }
}
