//! The mesh as the engine sees it: the caller's read-only positions and triangle buffer, plus
//! adjacency in the workspace.
//!
//! Adjacency is a *corner list*: corner `3t + k` is slot `k` of triangle `t`, and every vertex
//! owns a singly linked list of its corners (`head[v]`, then `next[corner]`). That is one link
//! per vertex and three per triangle, the least that still lets a collapse re-home a vertex's
//! triangles in O(valence). A link stores only the next *triangle*: the slot is found again by
//! looking for the vertex among the triangle's three (live triangles never repeat a vertex), so
//! `u16` links reach 65 535 triangles instead of the 21 845 that corner numbers would allow.
//! Removed triangles are unlinked from every list, then written as `[b, b, b]` in the caller's
//! buffer (a degenerate triangle, which renders as nothing), so lists only hold live corners.
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
    /// Feature vertex (seed 004 §3).
    pub const FEATURE: u8 = 8;
    /// Already paired in the current pass (Passes schedule).
    pub const DONE: u8 = 16;
    /// Scratch mark for one legality check (neighbours of the kept vertex); always cleared.
    pub const MARK: u8 = 32;
}

/// Marks the end of a corner list.
pub(crate) const NIL: usize = usize::MAX;

/// The mesh under simplification.
pub(crate) struct Mesh<'a, L: Index, I: Index> {
    pos: &'a [[f32; 3]],
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
    centre: V3,
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
        pos: &'a [[f32; 3]],
        tris: &'a mut [[I; 3]],
        head: &'a mut [L],
        next: &'a mut [[L; 3]],
        flags: &'a mut [u8],
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

        let mut mesh = Mesh {
            pos,
            tris,
            head,
            next,
            flags: Cell::from_mut(flags).as_slice_of_cells(),
            centre,
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
                let u = c / 3;
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
                match mesh.fan(v) {
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
                let c = 3 * t + k;
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
        if let Some(x) = self.tris.get_mut(c / 3).and_then(|t| t.get_mut(c % 3)) {
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
            Some(k) => 3 * t + k,
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
            *h = if c == NIL { L::NIL } else { L::narrow(c / 3) };
        }
    }

    /// The corner after `c` in its vertex's list (`c`'s triangle must still hold the vertex in
    /// slot `c % 3`).
    #[inline]
    pub(crate) fn after(&self, c: usize) -> usize {
        let v = self.tri(c / 3).get(c % 3).copied().unwrap_or(NIL);
        match self.next.get(c / 3).and_then(|n| n.get(c % 3)) {
            Some(&t) if t != L::NIL => self.corner_of(t.to_usize(), v),
            _ => NIL,
        }
    }

    #[inline]
    fn set_after(&mut self, c: usize, n: usize) {
        if let Some(x) = self.next.get_mut(c / 3).and_then(|t| t.get_mut(c % 3)) {
            *x = if n == NIL { L::NIL } else { L::narrow(n / 3) };
        }
    }

    #[inline]
    pub(crate) fn flags(&self, v: usize) -> u8 {
        self.flags.get(v).map_or(flag::LOCKED, Cell::get)
    }

    /// Sets or clears [`flag::MARK`] on every vertex of `v`'s triangles (`v` included).
    pub(crate) fn mark_fan(&self, v: usize, on: bool) {
        for (t, _) in self.corners(v) {
            for x in self.tri(t) {
                if let Some(f) = self.flags.get(x) {
                    f.set(if on {
                        f.get() | flag::MARK
                    } else {
                        f.get() & !flag::MARK
                    });
                }
            }
        }
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
    pub(crate) fn set_flag(&mut self, v: usize, f: u8, on: bool) {
        if let Some(x) = self.flags.get(v) {
            x.set(if on { x.get() | f } else { x.get() & !f });
        }
    }

    /// Normalised position of `v`.
    #[inline]
    pub(crate) fn p(&self, v: usize) -> V3 {
        match self.pos.get(v) {
            Some(q) => [
                (q[0] * 0.5 - self.centre[0] * 0.5) * self.inv_half,
                (q[1] * 0.5 - self.centre[1] * 0.5) * self.inv_half,
                (q[2] * 0.5 - self.centre[2] * 0.5) * self.inv_half,
            ],
            None => [0.0; 3],
        }
    }

    /// Unit normal of the triangle `[a, b, c]` (zero if it has no area). The edges are
    /// divided by their largest component before the cross product, so that a triangle that is
    /// tiny in normalised units (a mesh dwarfed by one stray far vertex) keeps its direction
    /// instead of underflowing to zero (found by fuzzing).
    #[inline]
    pub(crate) fn unit_normal(&self, tri: [usize; 3]) -> V3 {
        let p0 = self.p(tri[0]);
        let e1 = math::sub(self.p(tri[1]), p0);
        let e2 = math::sub(self.p(tri[2]), p0);
        let m = math::max_abs(e1).max(math::max_abs(e2));
        if m.is_nan() || m <= 0.0 {
            return [0.0; 3];
        }
        math::unit(math::cross(math::div(e1, m), math::div(e2, m)))
    }

    // ---- queries ----------------------------------------------------------------------

    /// Iterates `v`'s corners as `(triangle, slot)`.
    #[inline]
    pub(crate) fn corners(&self, v: usize) -> Corners<'_, 'a, L, I> {
        Corners {
            mesh: self,
            c: self.first(v),
        }
    }

    /// Calls `f` once for each distinct neighbour of `v`, in corner-list order.
    pub(crate) fn for_each_neighbour(&self, v: usize, mut f: impl FnMut(usize)) {
        let mut c = self.first(v);
        while c != NIL {
            let t = c / 3;
            let tri = self.tri(t);
            let k = c % 3;
            for x in [tri[(k + 1) % 3], tri[(k + 2) % 3]] {
                if !self.seen_before(v, c, x) {
                    f(x);
                }
            }
            c = self.after(c);
        }
    }

    /// Whether `x` is in a triangle of `v`'s list before corner `c`: O(valence), so a walk
    /// over distinct neighbours is O(valence²), and valences are small.
    #[inline]
    pub(crate) fn seen_before(&self, v: usize, c: usize, x: usize) -> bool {
        let mut e = self.first(v);
        while e != c && e != NIL {
            if self.tri(e / 3).contains(&x) {
                return true;
            }
            e = self.after(e);
        }
        false
    }

    /// The other end of `v`'s boundary edges, except `not`; `NIL` if none.
    pub(crate) fn boundary_neighbour(&self, v: usize, not: usize) -> usize {
        for (t, k) in self.corners(v) {
            let tri = self.tri(t);
            for x in [tri[(k + 1) % 3], tri[(k + 2) % 3]] {
                if x != not && self.edge_valence(v, x) == 1 {
                    return x;
                }
            }
        }
        NIL
    }

    /// Number of live triangles on edge `u`-`w`.
    pub(crate) fn edge_valence(&self, u: usize, w: usize) -> usize {
        self.corners(u)
            .filter(|&(t, _)| self.tri(t).contains(&w))
            .count()
    }

    /// Classifies the fan of triangles around `v`.
    ///
    /// Walking around `v` from triangle `(v, a, b)` (in winding order) crosses edge `v-a` into
    /// the triangle `(v, a', a)`. The fan is a manifold disc (interior) or half-disc (boundary)
    /// iff every edge `v-x` is used at most once in each direction, and one walk, started at
    /// the boundary if there is one, visits every triangle.
    fn fan(&self, v: usize) -> Fan {
        let k_total = self.corners(v).count();
        let mut boundary_edges = 0;
        let mut start = self.first(v);
        for (t, k) in self.corners(v) {
            let tri = self.tri(t);
            let (a, b) = (tri[(k + 1) % 3], tri[(k + 2) % 3]);
            // Edge v->a is outgoing here; count how often v->a and a->v occur.
            let (mut out_a, mut in_a) = (0, 0);
            for (u, j) in self.corners(v) {
                let s = self.tri(u);
                if s[(j + 1) % 3] == a {
                    out_a += 1;
                }
                if s[(j + 2) % 3] == a {
                    in_a += 1;
                }
            }
            if out_a > 1 || in_a > 1 {
                return Fan::Irregular;
            }
            if in_a == 0 {
                boundary_edges += 1;
            }
            // Edge b->v with no v->b: this triangle starts the chain.
            if !self.corners(v).any(|(u, j)| self.tri(u)[(j + 1) % 3] == b) {
                boundary_edges += 1;
                start = 3 * t + k;
            }
        }
        if boundary_edges > 2 {
            return Fan::Irregular;
        }
        // Walk from `start`, crossing v-a each time.
        let mut visited = 1;
        let mut c = start;
        while visited <= k_total {
            let tri = self.tri(c / 3);
            let a = tri[(c % 3 + 1) % 3];
            let mut found = NIL;
            for (u, j) in self.corners(v) {
                if self.tri(u)[(j + 2) % 3] == a {
                    found = 3 * u + j;
                    break;
                }
            }
            if found == NIL || found == start {
                break;
            }
            visited += 1;
            c = found;
        }
        match (visited == k_total, boundary_edges) {
            (true, 0) => Fan::Interior,
            (true, 2) => Fan::Boundary,
            _ => Fan::Irregular,
        }
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
            if c / 3 == t {
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

    /// Moves `a` onto `b` (half-edge collapse with subset placement, seed 004 §2): triangles on
    /// edge `a-b` are removed, `a`'s other triangles now use `b`. The caller has checked
    /// legality. Returns the number of triangles removed.
    pub(crate) fn collapse(&mut self, a: usize, b: usize) -> usize {
        let mut removed = 0;
        let mut keep = NIL;
        let mut c = self.first(a);
        let mut guard = self.tris.len() + 1;
        while c != NIL && guard > 0 {
            guard -= 1;
            let n = self.after(c);
            let t = c / 3;
            let tri = self.tri(t);
            if tri.contains(&b) {
                // Dies: out of b's and the third vertex's lists while it is intact, then gone.
                for &x in &tri {
                    if x != a {
                        self.unlink(x, t);
                    }
                }
                self.kill(t);
                removed += 1;
            } else {
                self.set_corner(c, b);
                self.set_after(c, keep);
                keep = c;
            }
            c = n;
        }
        self.set_first(a, NIL);
        self.set_flags(a, 0);
        // Splice a's surviving corners in front of b's list.
        let mut c = keep;
        let mut guard = 3 * self.tris.len() + 1;
        while c != NIL && guard > 0 {
            guard -= 1;
            let n = self.after(c);
            let h = self.first(b);
            self.set_after(c, h);
            self.set_first(b, c);
            c = n;
        }
        self.live = self.live.saturating_sub(removed);
        removed
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
        Some((c / 3, c % 3))
    }
}
