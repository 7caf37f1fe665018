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
//! (non-manifold, pinched, inconsistently wound) keep an unordered list: they never move and are
//! never the kept end, so nothing walks their fans in order.
//!
//! Every access goes through `get`, so a broken invariant shows up as a refused collapse, never
//! as a panic.

use core::cell::Cell;

use crate::index::Index;
use crate::math::{self, V3};
use crate::Error;

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

/// The slot after `k` in winding order (a corner's `a`).
#[inline]
pub(crate) const fn next3(k: usize) -> usize {
    // Written so that the result is below 3 for any `k`: indexing with it needs no check.
    match k {
        0 => 1,
        1 => 2,
        _ => 0,
    }
}

/// The slot before `k` in winding order (a corner's `b`).
#[inline]
pub(crate) const fn prev3(k: usize) -> usize {
    match k {
        1 => 0,
        2 => 1,
        _ => 2,
    }
}

/// Marks the end of a corner list.
pub(crate) const NIL: usize = usize::MAX;

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
    pub(crate) valid_in: usize,
}

impl<'a, L: Index, I: Index> Mesh<'a, L, I> {
    /// Validates the input (reading only), then drops degenerate and duplicate triangles,
    /// builds the corner lists and classifies vertices.
    pub(crate) fn build(
        pos: Positions<'a>,
        tris: &'a mut [[I; 3]],
        head: &'a mut [L],
        next: &'a mut [[L; 3]],
        flags: &'a mut [u8],
        scratch: (&mut [L], &mut [L]),
    ) -> Result<Self, Error> {
        // 1. Validate before touching anything: indices in range, used positions finite.
        let mut lo = [f32::INFINITY; 3];
        let mut hi = [f32::NEG_INFINITY; 3];
        for (t, tri) in tris.iter().enumerate() {
            for &i in tri {
                let index = i.to_usize();
                let Some(p) = pos.get(index) else {
                    return Err(Error::IndexOutOfRange { triangle: t, index });
                };
                if !(p[0].is_finite() && p[1].is_finite() && p[2].is_finite()) {
                    return Err(Error::NonFinitePosition { vertex: index });
                }
                for a in 0..3 {
                    lo[a] = lo[a].min(p[a]);
                    hi[a] = hi[a].max(p[a]);
                }
            }
        }
        // Halves first, so that `hi - lo` cannot overflow for coordinates near f32::MAX.
        let mut centre = [0.0; 3];
        let mut half = 0.0f32;
        if !tris.is_empty() {
            for a in 0..3 {
                centre[a] = lo[a] * 0.5 + hi[a] * 0.5;
                half = half.max(hi[a] * 0.5 - lo[a] * 0.5);
            }
        }
        let inv = 1.0 / half;
        let inv_half = if inv.is_finite() { inv } else { 1.0 };
        // A workspace is reused: nothing of an earlier run's flags may reach the fan
        // ordering below (its SEEN bits are the queue's RAISED bit).
        for f in flags.iter_mut() {
            *f = 0;
        }

        let mut mesh = Mesh {
            pos,
            tris,
            head,
            next,
            flags: Cell::from_mut(flags).as_slice_of_cells(),
            half_centre: math::scale(centre, 0.5),
            inv_half,
            live: 0,
            degenerate: 0,
            duplicates: 0,
            valid_in: 0,
        };

        // 2. Drop triangles with a repeated index.
        for t in 0..mesh.tris.len() {
            let [a, b, c] = mesh.tri(t);
            if a == b || b == c || a == c {
                mesh.kill(t);
                mesh.degenerate += 1;
            }
        }
        mesh.link_all();

        // 3. Drop exact duplicates (same vertex set, any order or winding): keep the first.
        // A later copy shows up in the corner list of its first vertex. A copy leaves all
        // three lists while it is intact (a list walk finds its slot by its vertex), and only
        // then is written as removed, so no walk ever meets it.
        for t in 0..mesh.tris.len() {
            let tri = mesh.tri(t);
            if is_dead(tri) {
                continue;
            }
            let mut c = mesh.first(tri[0]);
            let mut dup = false;
            while c != NIL {
                let u = c >> 2;
                if u < t && same_set(mesh.tri(u), tri) {
                    dup = true;
                    break;
                }
                c = mesh.after(c);
            }
            if dup {
                for &x in &tri {
                    mesh.unlink(x, t);
                }
                mesh.kill(t);
                mesh.duplicates += 1;
                mesh.live = mesh.live.saturating_sub(1);
            }
        }
        mesh.valid_in = mesh.live;

        // 4. Classify vertices.
        for v in 0..mesh.head.len() {
            let mut f = 0;
            if mesh.first(v) != NIL {
                f |= flag::USED;
                match mesh.order(v, &mut *scratch.0, &mut *scratch.1) {
                    Fan::Interior => {}
                    Fan::Boundary => f |= flag::BOUNDARY,
                    Fan::Irregular => f |= flag::LOCKED,
                }
            }
            mesh.set_flags(v, f);
        }
        Ok(mesh)
    }

    /// (Re)links every live triangle's corners, in triangle order.
    fn link_all(&mut self) {
        for h in self.head.iter_mut() {
            *h = L::NIL;
        }
        self.live = 0;
        for t in (0..self.tris.len()).rev() {
            let tri = self.tri(t);
            if is_dead(tri) {
                continue;
            }
            self.live += 1;
            for (k, &v) in tri.iter().enumerate() {
                let c = corner(t, k);
                let h = self.first(v);
                self.set_after(c, h);
                self.set_first(v, c);
            }
        }
    }

    // ---- raw access, panic-free -------------------------------------------------------

    pub(crate) fn vertex_count(&self) -> usize {
        self.head.len()
    }

    pub(crate) fn triangle_count(&self) -> usize {
        self.tris.len()
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

    /// The corner of `v` in triangle `t`, or `NIL` if `t` does not hold `v`.
    #[inline]
    fn corner_of(&self, t: usize, v: usize) -> usize {
        match self.tri(t).iter().position(|&x| x == v) {
            Some(k) => corner(t, k),
            None => NIL,
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
    pub(crate) fn raw(&self, v: usize) -> Option<[f32; 3]> {
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
            c = self.after(c);
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

    /// Calls `f` once for each neighbour of `v`, in fan order: each corner's `a`, and for a
    /// boundary fan the last corner's `b` too. Only for regular (unlocked) fans.
    pub(crate) fn for_each_neighbour(&self, v: usize, mut f: impl FnMut(usize)) {
        let mut c = self.first(v);
        let mut last = NIL;
        let mut guard = self.tris.len();
        while c != NIL && guard > 0 {
            guard -= 1;
            f(self.tri(c >> 2)[next3(c & 3)]);
            last = c;
            c = self.after(c);
        }
        if self.has(v, flag::BOUNDARY) && last != NIL {
            f(self.tri(last >> 2)[prev3(last & 3)]);
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

    /// Classifies the fan of triangles around `v` and, if it is a disc or half-disc, relinks
    /// its list in fan order (see the module comment).
    ///
    /// The fan is regular iff no directed edge `v->x` or `x->v` occurs twice (that would be a
    /// non-manifold or inconsistently wound edge), at most one triangle has no predecessor
    /// (the start of a half-disc; two would be two fans pinched together), and the walk from
    /// the start takes in every triangle. O(valence): `by_a[x]` notes the triangle whose `a`
    /// is `x` (flag `SEEN_A` says it is set), so each successor is one look-up; `by_b` and
    /// `SEEN_B` the same for `b`. Both are the queue's arrays, unused until the queue starts.
    fn order(&mut self, v: usize, by_a: &mut [L], by_b: &mut [L]) -> Fan {
        let mut total = 0;
        let mut twice = false;
        for (t, k) in self.corners(v) {
            let tri = self.tri(t);
            for (x, f, map) in [
                (tri[next3(k)], flag::SEEN_A, &mut *by_a),
                (tri[prev3(k)], flag::SEEN_B, &mut *by_b),
            ] {
                twice |= self.has(x, f);
                self.set_flag(x, f, true);
                if let Some(m) = map.get_mut(x) {
                    *m = L::narrow(t);
                }
            }
            total += 1;
        }
        let mut fan = Fan::Irregular;
        if !twice {
            // The start: a triangle whose `a` is no triangle's `b` (none: a disc, start
            // anywhere).
            let mut starts = 0;
            let mut start = self.first(v);
            for (t, k) in self.corners(v) {
                if !self.has(self.tri(t)[next3(k)], flag::SEEN_B) {
                    starts += 1;
                    start = corner(t, k);
                }
            }
            if starts <= 1 && self.fan_walk(v, start, by_a, false) == total {
                self.fan_walk(v, start, by_a, true);
                fan = if starts == 0 {
                    Fan::Interior
                } else {
                    Fan::Boundary
                };
            }
        }
        for (t, k) in self.corners(v) {
            let tri = self.tri(t);
            self.set_flag(tri[next3(k)], flag::SEEN_A, false);
            self.set_flag(tri[prev3(k)], flag::SEEN_B, false);
        }
        fan
    }

    /// Follows `v`'s fan from `start`, successor by successor, until it closes or ends;
    /// returns how many triangles it met. With `relink`, makes that the list's order.
    fn fan_walk(&mut self, v: usize, start: usize, by_a: &[L], relink: bool) -> usize {
        let mut c = start;
        let mut count = 1;
        let limit = self.tris.len();
        if relink {
            self.set_first(v, start);
        }
        loop {
            let b = self.tri(c >> 2)[prev3(c & 3)];
            let n = match by_a.get(b) {
                Some(&t) if self.has(b, flag::SEEN_A) => self.corner_of(t.to_usize(), v),
                _ => NIL,
            };
            if n == NIL || n == start || count > limit {
                break;
            }
            if relink {
                self.set_after(c, n);
            }
            c = n;
            count += 1;
        }
        if relink {
            self.set_after(c, NIL);
        }
        count
    }

    // ---- changes ------------------------------------------------------------------------

    /// Removes triangle `t` (still intact) from `v`'s list; a vertex left without triangles
    /// loses its flags.
    fn unlink(&mut self, v: usize, t: usize) {
        let mut prev = NIL;
        let mut c = self.first(v);
        let mut guard = self.tris.len() + 1;
        while c != NIL && guard > 0 {
            guard -= 1;
            let n = self.after(c);
            if (c >> 2) == t {
                if prev == NIL {
                    self.set_first(v, n);
                } else {
                    self.set_after(prev, n);
                }
                break;
            }
            prev = c;
            c = n;
        }
        if self.first(v) == NIL {
            self.set_flags(v, 0);
        }
    }

    /// Moves `a` onto `b` (half-edge collapse with subset placement, Lin 2007 §2): the (one or
    /// two) triangles on edge `a-b` are removed, `a`'s other triangles now use `b`. The caller
    /// has checked legality. Returns the number of triangles removed.
    ///
    /// Fan order is kept: in `a`'s fan the survivors run from the triangle after `(a, b, o1)`
    /// to the one before `(a, o2, b)`; in `b`'s fan the removed `(b, o1, a)` and `(b, a, o2)`
    /// are adjacent, and the run takes their place. `o1` and `o2` just lose one triangle.
    pub(crate) fn collapse(&mut self, a: usize, b: usize) -> usize {
        // Rotate a's list to start right after (a, b, o1), so that the survivors come out in
        // fan order whether a's fan is a disc or a half-disc.
        let first = self.first(a);
        let (mut c1, mut last) = (NIL, NIL);
        let mut c = first;
        let mut guard = self.tris.len();
        while c != NIL && guard > 0 {
            guard -= 1;
            let tri = self.tri(c >> 2);
            if tri[next3(c & 3)] == b {
                c1 = c;
            }
            last = c;
            c = self.after(c);
        }
        let mut c = first;
        if c1 != NIL && c1 != last {
            self.set_after(last, first);
            c = self.after(c1);
            self.set_after(c1, NIL);
        }
        // Walk the rotated list: survivors are re-pointed at b and chained into the run;
        // removed triangles are noted (at most two in a regular fan).
        let (mut run_head, mut run_tail) = (NIL, NIL);
        let mut dead = [NIL; 2];
        let mut n_dead = 0;
        let mut guard = self.tris.len();
        while c != NIL && guard > 0 {
            guard -= 1;
            let n = self.after(c);
            let t = c >> 2;
            if self.tri(t).contains(&b) {
                if let Some(d) = dead.get_mut(n_dead) {
                    *d = t;
                    n_dead += 1;
                } else {
                    // Only with a switched-off rule: a third triangle on a-b.
                    self.remove_triangle(t, a);
                }
            } else {
                self.set_corner(c, b);
                self.set_after(c, NIL);
                if run_tail == NIL {
                    run_head = c;
                } else {
                    self.set_after(run_tail, c);
                }
                run_tail = c;
            }
            c = n;
        }
        let dead = dead.get(..n_dead).unwrap_or(&[]);
        self.splice(b, dead, run_head, run_tail);
        self.set_first(a, NIL);
        self.set_flags(a, 0);
        for &t in dead {
            self.remove_triangle(t, b);
        }
        dead.len()
    }

    /// Replaces the (adjacent) corners of `b` in the `dead` triangles with the run
    /// `head..tail`. Non-adjacent windows only arise from a switched-off rule: then the dead
    /// corners are unlinked and the run goes in front.
    fn splice(&mut self, b: usize, dead: &[usize], head: usize, tail: usize) {
        let (mut w_first, mut w_pred, mut w_last, mut w_last_pred, mut w_succ) =
            (NIL, NIL, NIL, NIL, NIL);
        let mut adjacent = true;
        let (mut prev, mut c) = (NIL, self.first(b));
        let mut guard = self.tris.len();
        while c != NIL && guard > 0 {
            guard -= 1;
            let n = self.after(c);
            if dead.contains(&(c >> 2)) {
                if w_first == NIL {
                    w_first = c;
                    w_pred = prev;
                } else if prev != w_last {
                    adjacent = false;
                }
                w_last = c;
                w_last_pred = prev;
                w_succ = n;
            }
            prev = c;
            c = n;
        }
        let list_last = prev;
        // What comes after the run, and where the run hangs.
        if w_first != NIL && adjacent {
            // ... pred, [dead], succ ...  ->  ... pred, run, succ ...
            self.link_run(b, w_pred, head, tail, w_succ);
        } else if dead.len() == 2 && w_first == self.first(b) && w_last == list_last {
            // The window wraps around the end of a disc's list: [d2, x.., y, d1]
            // -> [x.., y, run].
            let x = self.after(w_first);
            if w_last_pred == w_first {
                self.set_first(b, NIL);
                self.link_run(b, NIL, head, tail, NIL);
            } else {
                self.set_first(b, x);
                self.link_run(b, w_last_pred, head, tail, NIL);
            }
        } else {
            for &t in dead {
                self.unlink(b, t);
            }
            let h = self.first(b);
            self.link_run(b, NIL, head, tail, h);
        }
    }

    /// Links `pred -> head..tail -> succ` in `b`'s list (`pred` NIL: the run becomes the head;
    /// an empty run links `pred -> succ`).
    fn link_run(&mut self, b: usize, pred: usize, head: usize, tail: usize, succ: usize) {
        let (h, t) = if head == NIL {
            (succ, NIL)
        } else {
            (head, tail)
        };
        if pred == NIL {
            self.set_first(b, h);
        } else {
            self.set_after(pred, h);
        }
        if t != NIL {
            self.set_after(t, succ);
        }
    }

    /// Takes triangle `t` (still intact) out of the lists of its vertices other than `skip`
    /// and writes it as removed.
    fn remove_triangle(&mut self, t: usize, skip: usize) {
        for x in self.tri(t) {
            if x != skip {
                self.unlink(x, t);
            }
        }
        self.kill(t);
        self.live = self.live.saturating_sub(1);
    }

    /// Moves the live triangles to the front of the buffer, in their original order, and
    /// returns how many there are. The workspace's lists are stale afterwards.
    pub(crate) fn compact(&mut self) -> usize {
        let mut n = 0;
        for t in 0..self.tris.len() {
            let Some(&tri) = self.tris.get(t) else { break };
            if tri[0] != tri[1] {
                if let Some(slot) = self.tris.get_mut(n) {
                    *slot = tri;
                }
                n += 1;
            }
        }
        n
    }
}

#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum Fan {
    Interior,
    Boundary,
    Irregular,
}

/// A removed (or input-degenerate) triangle: live ones never repeat an index.
#[inline]
pub(crate) fn is_dead(t: [usize; 3]) -> bool {
    t[0] == t[1]
}

/// Same three vertices. Both directions, so a removed `[x, x, x]` never matches.
fn same_set(a: [usize; 3], b: [usize; 3]) -> bool {
    a.iter().all(|x| b.contains(x)) && b.iter().all(|x| a.contains(x))
}

/// Iterator over a vertex's corners.
pub(crate) struct Corners<'m, 'a, L: Index, I: Index> {
    mesh: &'m Mesh<'a, L, I>,
    c: usize,
}

impl<L: Index, I: Index> Iterator for Corners<'_, '_, L, I> {
    type Item = (usize, usize);
    #[inline]
    fn next(&mut self) -> Option<(usize, usize)> {
        if self.c == NIL {
            return None;
        }
        let c = self.c;
        self.c = self.mesh.after(c);
        Some(((c >> 2), (c & 3)))
    }
}
