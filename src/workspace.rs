//! The fixed-capacity working memory, sized at compile time.

use crate::bound::{control_len, Bound, Controls, NoBound};
use crate::collapse::Simplifier;
use crate::cost::{Builtin, Cost, Placement, StoredQuadric, VertexQuadric};
use crate::index::Index;
use crate::mesh::{Mesh, Positions};
use crate::{Config, Error, Report};

/// All working state of the simplifier, with capacity fixed by const generics.
///
/// * `L`: link type (`u16` or `u32`) for vertex and corner numbers inside the workspace. With
///   `u16` a mesh may have at most 65 535 vertices and 65 535 triangles (the largest value is
///   reserved as "none").
/// * `MAX_VERTICES`, `MAX_TRIANGLES`: the largest mesh it takes.
///
/// Its size is [`Workspace::BYTES`]: per vertex two links of adjacency and queue position, a
/// heap slot, a 4-byte key and a flag byte; per triangle three corner links. With `u16` links
/// and the usual `V ≈ T/2` that is 11.5 bytes per triangle. [`Workspace::new`] is a `const fn`,
/// so a workspace can be a `static` in `.bss` instead of living on the stack.
///
/// The positions are never copied: they stay wherever the caller keeps them (flash included).
pub struct Workspace<L: Index, const MAX_VERTICES: usize, const MAX_TRIANGLES: usize> {
    /// Triangle of the first corner of each vertex's corner list (NIL: none).
    pub(crate) head: [L; MAX_VERTICES],
    /// For corner `3t + k`, the triangle of the next corner around the same vertex.
    pub(crate) next: [[L; 3]; MAX_TRIANGLES],
    /// Per-vertex flags, see `mesh::flag`.
    pub(crate) flags: [u8; MAX_VERTICES],
    /// Greedy schedule: binary heap of vertices ...
    pub(crate) heap: [L; MAX_VERTICES],
    /// ... each vertex's slot in it (NIL: not queued) ...
    pub(crate) heap_pos: [L; MAX_VERTICES],
    /// ... and its key, the cost of its cheapest legal collapse.
    pub(crate) key: [f32; MAX_VERTICES],
}

impl<L: Index, const MAX_VERTICES: usize, const MAX_TRIANGLES: usize>
    Workspace<L, MAX_VERTICES, MAX_TRIANGLES>
{
    /// Size of the workspace in bytes: all of the simplifier's RAM apart from the caller's
    /// triangle buffer, positions and a bounded stack frame.
    pub const BYTES: usize = core::mem::size_of::<Self>();

    /// An empty workspace. `const`, so it can initialise a `static`; and all zero bits, so
    /// such a `static` goes to `.bss` (zeroed at boot) instead of taking its size again in
    /// flash as `.data`. Nothing here is read before [`Workspace::start`] writes it.
    pub const fn new() -> Self {
        Workspace {
            head: [L::ZERO; MAX_VERTICES],
            next: [[L::ZERO; 3]; MAX_TRIANGLES],
            flags: [0; MAX_VERTICES],
            heap: [L::ZERO; MAX_VERTICES],
            heap_pos: [L::ZERO; MAX_VERTICES],
            key: [0.0; MAX_VERTICES],
        }
    }

    /// Simplifies `triangles` in place, in one call.
    ///
    /// `positions` are only read. On success the first `report.triangles_out` entries of
    /// `triangles` hold the result, referring to the original vertex indices; the rest of the
    /// buffer is left over and meaningless. On error nothing has been written.
    pub fn simplify<I: Index>(
        &mut self,
        positions: &[[f32; 3]],
        triangles: &mut [[I; 3]],
        config: &Config,
    ) -> Result<Report, Error> {
        // One engine for every configuration (the schedule and the built-in cost are chosen
        // at run time, so a configuration received at run time costs no extra flash). For
        // the least flash with one known cost, drive `start_with_cost` with that cost.
        let mut s = self.start(positions, triangles, config)?;
        while !s.step(u32::MAX) {}
        Ok(s.finish())
    }

    /// Validates the input, builds adjacency and returns a [`Simplifier`] to drive step by step
    /// (for watchdogs and frame deadlines). Steps of any size give exactly the result of
    /// [`Workspace::simplify`].
    ///
    /// Errors, all returned before the triangle buffer is touched:
    /// [`Error::Capacity`], [`Error::IndexOutOfRange`], [`Error::NonFinitePosition`],
    /// [`Error::InvalidConfig`].
    pub fn start<'a, I: Index>(
        &'a mut self,
        positions: &'a [[f32; 3]],
        triangles: &'a mut [[I; 3]],
        config: &Config,
    ) -> Result<Simplifier<'a, L, I, Builtin>, Error> {
        self.start_with_cost(positions, triangles, config, Builtin::of(config))
    }

    /// Like [`Workspace::start`], with another [`Cost`].
    pub fn start_with_cost<'a, I: Index, C: Cost>(
        &'a mut self,
        positions: &'a [[f32; 3]],
        triangles: &'a mut [[I; 3]],
        config: &Config,
        cost: C,
    ) -> Result<Simplifier<'a, L, I, C>, Error> {
        self.start_on(Positions::Read(positions), triangles, config, cost, NoBound)
    }

    /// Like [`Workspace::start_with_cost`], on positions that a placing cost may move
    /// ([`Cost::place`]; [`StoredQuadric`] with [`Placement::Optimal`]): the kept vertex of each
    /// collapse is written there, in the input's units. Positions of vertices that no longer
    /// have triangles keep their last value.
    pub fn start_moving<'a, I: Index, C: Cost>(
        &'a mut self,
        positions: &'a mut [[f32; 3]],
        triangles: &'a mut [[I; 3]],
        config: &Config,
        cost: C,
    ) -> Result<Simplifier<'a, L, I, C>, Error> {
        self.start_on(
            Positions::Write(positions),
            triangles,
            config,
            cost,
            NoBound,
        )
    }

    /// Like [`Workspace::start_with_cost`], with the guaranteed error bound
    /// [`Config::max_error`] (Zhu, Wang and Meng 2007, seed 001 §2-§4; see [`crate::bound`]):
    /// no collapse is made that would leave a control point (a centroid of an `original`
    /// triangle, or a vertex of an original feature edge) farther than the bound from the
    /// result, whatever the cost. The report gives E_max and E_mean (eq. 4-5).
    ///
    /// * `original`: the triangles as handed in, read only (they may stay in flash): a copy of
    ///   `triangles` before the call, else [`Error::OriginalMismatch`].
    /// * `controls`: at least [`control_len`]`(triangles.len(), positions.len())` links of
    ///   any [`Index`] type (`2·T + V`: 5 bytes per triangle with `u16` and `V ≈ T/2`), all
    ///   numbered below its `NIL`; else [`Error::Capacity`] with
    ///   [`Capacity::Controls`](crate::Capacity::Controls). Meaningless after
    ///   [`Simplifier::finish`] (the triangles are compacted).
    ///
    /// Positions are only read (subset placement). An infinite `max_error` runs unbounded but
    /// still reports E_max and E_mean.
    #[allow(clippy::too_many_arguments)]
    pub fn start_bounded<'a, I: Index, C: Cost, K: Index>(
        &'a mut self,
        positions: &'a [[f32; 3]],
        original: &'a [[I; 3]],
        triangles: &'a mut [[I; 3]],
        controls: &'a mut [K],
        config: &Config,
        cost: C,
    ) -> Result<Simplifier<'a, L, I, C, Controls<'a, I, K>>, Error> {
        if original.len() != triangles.len() {
            return Err(Error::OriginalMismatch {
                triangle: original.len().min(triangles.len()),
            });
        }
        if let Some(t) = original
            .iter()
            .zip(triangles.iter())
            .position(|(a, b)| a != b)
        {
            return Err(Error::OriginalMismatch { triangle: t });
        }
        let need = control_len(triangles.len(), positions.len());
        if need > K::COUNT {
            return Err(Error::Capacity {
                what: crate::Capacity::Controls,
                needed: need,
                available: K::COUNT,
            });
        }
        let available = controls.len();
        let Some(links) = controls.get_mut(..need) else {
            return Err(Error::Capacity {
                what: crate::Capacity::Controls,
                needed: need,
                available,
            });
        };
        config.validate()?;
        let bound = Controls::new(
            original,
            links,
            crate::math::cos_deg(config.control_angle_deg),
        );
        let mut s = self.start_on(Positions::Read(positions), triangles, config, cost, bound)?;
        s.enrol();
        Ok(s)
    }

    /// [`Workspace::start_bounded`] with the configuration's built-in cost, in one call.
    pub fn simplify_bounded<I: Index, K: Index>(
        &mut self,
        positions: &[[f32; 3]],
        original: &[[I; 3]],
        triangles: &mut [[I; 3]],
        controls: &mut [K],
        config: &Config,
    ) -> Result<Report, Error> {
        let cost = Builtin::of(config);
        let mut s = self.start_bounded(positions, original, triangles, controls, config, cost)?;
        while !s.step(u32::MAX) {}
        Ok(s.finish())
    }

    /// Simplifies with stored quadrics ([`StoredQuadric`], seed 000 §2.3-2.5 and §3.3) and
    /// subset placement: positions are only read. `quadrics` holds one [`VertexQuadric`] (40
    /// bytes) per position; too short a slice is [`Error::Capacity`] with
    /// [`Capacity::Quadrics`](crate::Capacity::Quadrics). Boundary planes are weighted by
    /// [`Config::boundary_weight`]. [`Config::stored`] is the recommended configuration (no
    /// feature rule: lower mean error, and the faster re-keying).
    pub fn simplify_stored<I: Index>(
        &mut self,
        positions: &[[f32; 3]],
        triangles: &mut [[I; 3]],
        config: &Config,
        quadrics: &mut [VertexQuadric],
    ) -> Result<Report, Error> {
        quadrics_fit(positions.len(), quadrics.len())?;
        let cost = StoredQuadric::new(quadrics, config.boundary_weight, Placement::Subset);
        let mut s = self.start_with_cost(positions, triangles, config, cost)?;
        while !s.step(u32::MAX) {}
        Ok(s.finish())
    }

    /// Like [`Workspace::simplify_stored`] with optimal placement: each kept vertex moves to the
    /// minimiser of its summed quadric (or the best of the endpoints and the midpoint), written
    /// into `positions`. On error nothing has been written.
    pub fn simplify_optimal<I: Index>(
        &mut self,
        positions: &mut [[f32; 3]],
        triangles: &mut [[I; 3]],
        config: &Config,
        quadrics: &mut [VertexQuadric],
    ) -> Result<Report, Error> {
        quadrics_fit(positions.len(), quadrics.len())?;
        let cost = StoredQuadric::new(quadrics, config.boundary_weight, Placement::Optimal);
        let mut s = self.start_moving(positions, triangles, config, cost)?;
        while !s.step(u32::MAX) {}
        Ok(s.finish())
    }

    fn start_on<'a, I: Index, C: Cost, B: Bound<'a, I>>(
        &'a mut self,
        positions: Positions<'a>,
        triangles: &'a mut [[I; 3]],
        config: &Config,
        cost: C,
        bound: B,
    ) -> Result<Simplifier<'a, L, I, C, B>, Error> {
        config.validate()?;
        if !B::ON && config.max_error < f32::INFINITY {
            return Err(Error::Capacity {
                what: crate::Capacity::Controls,
                needed: control_len(triangles.len(), positions.len()),
                available: 0,
            });
        }
        if positions.len() > MAX_VERTICES || positions.len() > L::COUNT {
            return Err(Error::Capacity {
                what: crate::Capacity::Vertices,
                needed: positions.len(),
                available: if MAX_VERTICES < L::COUNT {
                    MAX_VERTICES
                } else {
                    L::COUNT
                },
            });
        }
        // Links number triangles (not corners), so the link type caps triangles at its COUNT.
        let corner_cap = L::COUNT;
        if triangles.len() > MAX_TRIANGLES || triangles.len() > corner_cap {
            return Err(Error::Capacity {
                what: crate::Capacity::Triangles,
                needed: triangles.len(),
                available: if MAX_TRIANGLES < corner_cap {
                    MAX_TRIANGLES
                } else {
                    corner_cap
                },
            });
        }
        let nv = positions.len();
        let nt = triangles.len();
        // `get_mut` with lengths just checked against the capacities: cannot fail, but costs
        // nothing and keeps every path panic-free.
        let (Some(head), Some(next), Some(flags), Some(heap), Some(heap_pos), Some(key)) = (
            self.head.get_mut(..nv),
            self.next.get_mut(..nt),
            self.flags.get_mut(..nv),
            self.heap.get_mut(..nv),
            self.heap_pos.get_mut(..nv),
            self.key.get_mut(..nv),
        ) else {
            return Err(Error::Capacity {
                what: crate::Capacity::Vertices,
                needed: nv,
                available: MAX_VERTICES,
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
            crate::heap::Heap::new(heap, heap_pos, key),
            *config,
            cost,
            bound,
        ))
    }
}

/// `Error::Capacity` unless there is a quadric per position.
fn quadrics_fit(positions: usize, quadrics: usize) -> Result<(), Error> {
    if quadrics < positions {
        return Err(Error::Capacity {
            what: crate::Capacity::Quadrics,
            needed: positions,
            available: quadrics,
        });
    }
    Ok(())
}

impl<L: Index, const MAX_VERTICES: usize, const MAX_TRIANGLES: usize> Default
    for Workspace<L, MAX_VERTICES, MAX_TRIANGLES>
{
    fn default() -> Self {
        Self::new()
    }
}
