//! The mesh as the engine sees it: the caller's read-only positions and triangle buffer, plus
//! adjacency in the workspace.
//!
//! Adjacency is a *corner list*: corner `4t + k` is slot `k` of triangle `t`, and every vertex
//! owns a singly linked list of its corners (`head[v]`, then `next[corner]`). That is one link
//! per vertex and three per triangle, the least that still lets a collapse re-home a vertex's
//! triangles in O(valence). A link stores only the next *triangle*: the slot is found again by
//! looking for the vertex among the triangle's three (live triangles never repeat a vertex), so
//! `u16` links reach 65 535 triangles instead of the 16 384 that corner numbers would allow.
//! Removed triangles are unlinked from every list, then written as `[b, b, b]` in the caller's
//! buffer (a degenerate triangle, which renders as nothing), so lists only hold live corners.
//!
//! Every list is kept in *fan order*: for a vertex `v` whose fan is a disc or half-disc, the
//! triangle after `(v, a, b)` (in winding order from `v`) is the one across edge `v-b`, i.e.
//! `(v, b, c)`. A boundary vertex's list starts at the triangle whose edge `v-a` has no twin
//! and ends at the one whose `v-b` has none. So a fan walk needs no search, each corner names
//! one new neighbour (its `a`; a boundary fan adds its last `b`), and a collapse splices `a`'s
//! surviving run into `b`'s list where the two removed triangles were. Locked vertices
//! (non-manifold, pinched, inconsistently wound) keep an unordered list: they never move, and
//! when one is the kept end the run goes in front of its list; nothing walks their fans in
//! order.
//!
//! Every access goes through `get`, so a broken invariant shows up as a refused collapse, never
//! as a panic.

use core::cell::Cell;

use crate::index::Index;
use crate::math::V3;
pub(crate) use crate::tri::{next3, prev3, NIL};

mod build;
mod collapse;
mod replace;
pub(crate) use replace::MAX_FAN;

/// Per-vertex flag bits.
pub(crate) mod flag {
    /// The vertex has at least one live triangle.
    pub const USED: u8 = 1;
    /// Non-manifold, pinched or inconsistently wound around the vertex: never collapsed.
    pub const LOCKED: u8 = 2;
    /// On a boundary (an edge with one triangle).
    pub const BOUNDARY: u8 = 4;
    /// Feature vertex (Lin 2007 §3).
    pub const FEATURE: u8 = 8;
    /// Already paired in the current pass (Passes schedule).
    pub const DONE: u8 = 16;
    /// Scratch mark for one legality check (neighbours of the kept vertex); always cleared.
    pub const MARK: u8 = 32;
    /// Build only: the vertex is some corner's `a` in the fan being ordered.
    pub const SEEN_A: u8 = 64;
    /// Greedy queue, after the build: the vertex went back in at its cheapest *legal* price,
    /// above a cheaper refused candidate, so its key is no lower bound of its prices (see
    /// `Simplifier::keys_only_fall`).
    /// `SEEN_A`'s bit, never both at once: `order` (build only) clears `SEEN_A` before it returns.
    pub const RAISED: u8 = 64;
    /// Build only: the vertex is some corner's `b` in the fan being ordered.
    pub const SEEN_B: u8 = 128;
}

/// Corner `k` of triangle `t`: `4t + k`, so that taking it apart is a shift and a mask (a
/// Cortex-M0 has no divider; `3t + k` would cost a library call per step of every walk).
#[inline]
pub(crate) const fn corner(t: usize, k: usize) -> usize {
    t << 2 | k
}

/// Where the positions live: the caller's read-only slice (subset placement: flash is fine),
/// or a mutable one that a placement may write (optimal placement of stored quadrics).
pub enum Positions<'a> {
    /// Only read.
    Read(&'a [[f32; 3]]),
    /// Read, and written by optimal placement (the kept vertex of each collapse, in the
    /// input's units). Positions of vertices that no longer have triangles keep their last
    /// value.
    Write(&'a mut [[f32; 3]]),
}

impl Positions<'_> {
    /// How many positions.
    pub fn len(&self) -> usize {
        match self {
            Positions::Read(p) => p.len(),
            Positions::Write(p) => p.len(),
        }
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Whether they may be written ([`Positions::Write`]).
    pub fn is_write(&self) -> bool {
        matches!(self, Positions::Write(_))
    }

    #[inline]
    fn get(&self, v: usize) -> Option<&[f32; 3]> {
        match self {
            Positions::Read(p) => p.get(v),
            Positions::Write(p) => p.get(v),
        }
    }
}

/// The mesh under simplification.
pub(crate) struct Mesh<'a, L: Index, I: Index> {
    pos: Positions<'a>,
    pub(crate) tris: &'a mut [[I; 3]],
    head: &'a mut [L],
    next: &'a mut [[L; 3]],
    /// Flags behind `Cell`s, so that a legality check (which only reads the mesh) can mark
    /// and unmark vertices: the safe `Cell::as_slice_of_cells` view of the workspace's bytes.
    flags: &'a [Cell<u8>],
    /// Positions are read through this affine map into roughly `[-1, 1]³`, so that squared
    /// lengths and cross products can neither overflow nor underflow whatever the input's scale
    /// (coordinates near `f32::MAX` included). Every cost and test is scale-free or uses these
    /// normalised units.
    half_centre: V3,
    inv_half: f32,
    /// Live triangles.
    pub(crate) live: usize,
    /// Input triangles dropped at the start.
    pub(crate) degenerate: usize,
    pub(crate) duplicates: usize,
    /// Input triangles that are an earlier triangle turned over (the back of a double-sided
    /// surface): out of the run, written back at [`Mesh::compact`] behind their front.
    pub(crate) twins: usize,
    pub(crate) valid_in: usize,
    /// With welded seams ([`crate::seam`]): each triangle's corners as wedges (the caller's
    /// vertices), kept up to date by [`Mesh::collapse`] and written back by [`Mesh::compact`];
    /// empty otherwise.
    #[cfg(feature = "seams")]
    pub(crate) wedges: &'a mut [[I; 3]],
    /// With welded seams: a vertex where more than two wedges meet never moves
    /// ([`crate::seam::SeamCorners::Lock`]).
    #[cfg(feature = "seams")]
    pub(crate) lock_corners: bool,
}

impl<'a, L: Index, I: Index> Mesh<'a, L, I> {
    // ---- raw access, panic-free -------------------------------------------------------

    pub(crate) fn vertex_count(&self) -> usize {
        self.head.len()
    }

    pub(crate) fn triangle_count(&self) -> usize {
        self.tris.len()
    }

    /// Triangle `t`'s corners as the caller's vertices, starting at corner `k`: its wedges
    /// with welded seams (what a corner's attributes are read by), else its vertices.
    #[inline]
    pub(crate) fn caller_corners(&self, t: usize, k: usize) -> [usize; 3] {
        let c = self.tri(t);
        #[cfg(feature = "seams")]
        let c = self.wedges.get(t).map_or(c, |w| w.map(|x| x.to_usize()));
        [k, next3(k), prev3(k)].map(|i| c.get(i).copied().unwrap_or(NIL))
    }

    /// The vertices of triangle `t` (all `NIL` if out of range).
    #[inline]
    pub(crate) fn tri(&self, t: usize) -> [usize; 3] {
        match self.tris.get(t) {
            Some(x) => [x[0].to_usize(), x[1].to_usize(), x[2].to_usize()],
            None => [NIL; 3],
        }
    }

    #[inline]
    fn set_corner(&mut self, c: usize, v: usize) {
        if let Some(x) = self.tris.get_mut(c >> 2).and_then(|t| t.get_mut(c & 3)) {
            *x = I::narrow(v);
        }
    }

    /// Writes `t` as removed: `[v, v, v]` with its first vertex.
    fn kill(&mut self, t: usize) {
        if let Some(x) = self.tris.get_mut(t) {
            *x = [x[0]; 3];
        }
    }

    /// Writes `t` as the twin of `front` (`t` turned over), out of the run until
    /// [`Mesh::compact`]: `[v, v, w]` (removed, but told apart from `[v, v, v]`), with `front`
    /// in its first link (a removed triangle's links are never read).
    fn kill_twin(&mut self, t: usize, front: usize) {
        let x2 = self.tri(t)[2];
        if let (Some(x), Some(n), Some(f)) = (
            self.tris.get_mut(t),
            self.next.get_mut(t),
            L::from_usize(front),
        ) {
            *x = [x[0], x[0], x[1]];
            n[0] = f;
            // Its third position, for the backs' wedges at the end (links hold vertices).
            n[1] = L::narrow(x2);
        }
    }

    /// The corner of `v` in triangle `t`, or `NIL` if `t` does not hold `v`. Three plain
    /// comparisons, not `position` over the triple: this is inlined into every list walk, and
    /// the iterator's code there costs flash (scripts/flash.sh).
    #[inline]
    fn corner_of(&self, t: usize, v: usize) -> usize {
        let [x, y, z] = self.tri(t);
        if x == v {
            corner(t, 0)
        } else if y == v {
            corner(t, 1)
        } else if z == v {
            corner(t, 2)
        } else {
            NIL
        }
    }

    /// First corner of `v`'s list.
    #[inline]
    pub(crate) fn first(&self, v: usize) -> usize {
        match self.head.get(v) {
            Some(&t) if t != L::NIL => self.corner_of(t.to_usize(), v),
            _ => NIL,
        }
    }

    #[inline]
    fn set_first(&mut self, v: usize, c: usize) {
        if let Some(h) = self.head.get_mut(v) {
            *h = if c == NIL { L::NIL } else { L::narrow(c >> 2) };
        }
    }

    /// The corner after `c` in its vertex's list (`c`'s triangle must still hold the vertex in
    /// slot `(c & 3)`).
    #[inline]
    pub(crate) fn after(&self, c: usize) -> usize {
        // One index read, not the whole triangle.
        let v = match self.tris.get(c >> 2).and_then(|t| t.get(c & 3)) {
            Some(&x) => x.to_usize(),
            None => NIL,
        };
        match self.next.get(c >> 2).and_then(|n| n.get(c & 3)) {
            Some(&t) if t != L::NIL => self.corner_of(t.to_usize(), v),
            _ => NIL,
        }
    }

    /// [`Mesh::after`] for a corner of `v`'s own list (a fan walk knows its vertex, so the
    /// corner's index is not read again).
    #[inline]
    pub(crate) fn after_in(&self, c: usize, v: usize) -> usize {
        match self.next.get(c >> 2).and_then(|n| n.get(c & 3)) {
            Some(&t) if t != L::NIL => self.corner_of(t.to_usize(), v),
            _ => NIL,
        }
    }

    #[inline]
    fn set_after(&mut self, c: usize, n: usize) {
        if let Some(x) = self.next.get_mut(c >> 2).and_then(|t| t.get_mut(c & 3)) {
            *x = if n == NIL { L::NIL } else { L::narrow(n >> 2) };
        }
    }

    #[inline]
    pub(crate) fn flags(&self, v: usize) -> u8 {
        self.flags.get(v).map_or(flag::LOCKED, Cell::get)
    }

    #[inline]
    pub(crate) fn has(&self, v: usize, f: u8) -> bool {
        self.flags(v) & f != 0
    }

    #[inline]
    pub(crate) fn set_flags(&mut self, v: usize, f: u8) {
        if let Some(x) = self.flags.get(v) {
            x.set(f);
        }
    }

    #[inline]
    pub(crate) fn set_flag(&self, v: usize, f: u8, on: bool) {
        if let Some(x) = self.flags.get(v) {
            x.set(if on { x.get() | f } else { x.get() & !f });
        }
    }

    /// Normalised position of `v`.
    #[inline]
    pub(crate) fn p(&self, v: usize) -> V3 {
        match self.pos.get(v) {
            Some(q) => [
                (q[0] * 0.5 - self.half_centre[0]) * self.inv_half,
                (q[1] * 0.5 - self.half_centre[1]) * self.inv_half,
                (q[2] * 0.5 - self.half_centre[2]) * self.inv_half,
            ],
            None => [0.0; 3],
        }
    }

    /// A length in the input's units, in the normalised units of [`Mesh::p`].
    pub(crate) fn normalised_length(&self, d: f32) -> f32 {
        d * 0.5 * self.inv_half
    }

    /// A length in the normalised units of [`Mesh::p`], in the input's units.
    pub(crate) fn input_length(&self, d: f32) -> f32 {
        d * 2.0 / self.inv_half
    }

    /// `v`'s position as stored (input units).
    pub(crate) fn input_position(&self, v: usize) -> Option<[f32; 3]> {
        self.pos.get(v).copied()
    }

    /// Whether positions may be written ([`Mesh::place`]).
    pub(crate) fn movable(&self) -> bool {
        matches!(self.pos, Positions::Write(_))
    }

    /// The input-unit coordinates of normalised position `p` (the inverse of [`Mesh::p`]).
    #[inline]
    fn denormalise(&self, p: V3) -> [f32; 3] {
        let h = 1.0 / self.inv_half;
        [
            (p[0] * h + self.half_centre[0]) * 2.0,
            (p[1] * h + self.half_centre[1]) * 2.0,
            (p[2] * h + self.half_centre[2]) * 2.0,
        ]
    }

    /// Normalised position `p` as it will be stored: its input-unit coordinates, and the
    /// normalised position they read back as (the engine then works on exactly what it
    /// wrote). `None` if they would not be finite.
    pub(crate) fn stored_form(&self, p: V3) -> Option<([f32; 3], V3)> {
        let q = self.denormalise(p);
        if !(q[0].is_finite() && q[1].is_finite() && q[2].is_finite()) {
            return None;
        }
        let r = [
            (q[0] * 0.5 - self.half_centre[0]) * self.inv_half,
            (q[1] * 0.5 - self.half_centre[1]) * self.inv_half,
            (q[2] * 0.5 - self.half_centre[2]) * self.inv_half,
        ];
        Some((q, r))
    }

    /// Writes `q` (input units, from [`Mesh::stored_form`]) as `v`'s position; nothing if the
    /// positions are read-only.
    pub(crate) fn place(&mut self, v: usize, q: [f32; 3]) {
        if let Positions::Write(pos) = &mut self.pos {
            if let Some(x) = pos.get_mut(v) {
                *x = q;
            }
        }
    }

    // ---- queries ----------------------------------------------------------------------

    /// Iterates `v`'s corners as `(triangle, slot)`, in fan order for a regular fan.
    #[inline]
    pub(crate) fn corners(&self, v: usize) -> Corners<'_, 'a, L, I> {
        Corners {
            mesh: self,
            c: self.first(v),
            v,
        }
    }

    /// The last corner of `v`'s list (`NIL` if none).
    pub(crate) fn last(&self, v: usize) -> usize {
        let mut c = self.first(v);
        let mut last = NIL;
        let mut guard = self.tris.len();
        while c != NIL && guard > 0 {
            guard -= 1;
            last = c;
            c = self.after_in(c, v);
        }
        last
    }

    /// The two ends of a boundary vertex's fan: the `a` of its first triangle and the `b` of
    /// its last (`NIL` if none).
    pub(crate) fn boundary_ends(&self, v: usize) -> (usize, usize) {
        let (f, l) = (self.first(v), self.last(v));
        let x = if f == NIL {
            NIL
        } else {
            self.tri(f >> 2)[next3(f & 3)]
        };
        let y = if l == NIL {
            NIL
        } else {
            self.tri(l >> 2)[prev3(l & 3)]
        };
        (x, y)
    }

    /// Calls `f` for each neighbour of `v`: both neighbours of every corner, so each neighbour
    /// once or twice, in any fan (a locked vertex's list has no order).
    pub(crate) fn for_each_neighbour(&self, v: usize, mut f: impl FnMut(usize)) {
        let mut c = self.first(v);
        let mut guard = self.tris.len();
        while c != NIL && guard > 0 {
            guard -= 1;
            let (x, y) = crate::tri::others(self.tri(c >> 2), c & 3);
            f(x);
            f(y);
            c = self.after_in(c, v);
        }
    }

    /// Sets or clears [`flag::MARK`] on `v`.
    #[inline]
    pub(crate) fn mark(&self, v: usize, on: bool) {
        if let Some(f) = self.flags.get(v) {
            f.set(if on {
                f.get() | flag::MARK
            } else {
                f.get() & !flag::MARK
            });
        }
    }
}

/// A removed (or input-degenerate) triangle: live ones never repeat an index.
#[inline]
pub(crate) fn is_dead(t: [usize; 3]) -> bool {
    t[0] == t[1]
}

/// Iterator over a vertex's corners.
pub(crate) struct Corners<'m, 'a, L: Index, I: Index> {
    mesh: &'m Mesh<'a, L, I>,
    c: usize,
    v: usize,
}

impl<L: Index, I: Index> Iterator for Corners<'_, '_, L, I> {
    type Item = (usize, usize);
    #[inline]
    fn next(&mut self) -> Option<(usize, usize)> {
        if self.c == NIL {
            return None;
        }
        let c = self.c;
        self.c = self.mesh.after_in(c, self.v);
        Some(((c >> 2), (c & 3)))
    }
}
