//! Building the mesh: validating the input, dropping degenerate and duplicate triangles,
//! linking the corner lists and classifying each vertex by its fan.

use core::cell::Cell;

use super::{corner, flag, is_dead, Mesh, Positions};
use crate::index::Index;
use crate::math;
use crate::tri::{self, next3, prev3, NIL};
use crate::Error;

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
        // Steps 2-4 are `#[inline(always)]`: each is called once, and as calls (or with step
        // 1 as a function of its own) they cost flash (scripts/flash.sh).
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
            twins: 0,
            valid_in: 0,
            #[cfg(feature = "seams")]
            wedges: &mut [],
            #[cfg(feature = "seams")]
            lock_corners: false,
        };
        // 2. Drop triangles with a repeated index.
        mesh.drop_degenerate();
        mesh.link_all();
        // 3. Drop exact duplicates.
        mesh.drop_duplicates();
        mesh.valid_in = mesh.live;
        // 4. Classify vertices.
        mesh.classify(scratch);
        Ok(mesh)
    }

    /// Writes every triangle with a repeated index as removed (before the lists are built).
    #[inline(always)]
    fn drop_degenerate(&mut self) {
        for t in 0..self.tris.len() {
            if tri::is_degenerate(self.tri(t)) {
                self.kill(t);
                self.degenerate += 1;
            }
        }
    }

    /// Drops exact duplicates (same vertex set and winding) and keeps the first. A later copy
    /// shows up in the corner list of its first vertex. A copy leaves all three lists while it
    /// is intact (a list walk finds its slot by its vertex), and only then is written as
    /// removed, so no walk ever meets it. A copy turned over (opposite winding: the back of a
    /// double-sided leaf, card or pane) is not a duplicate but a twin: once every duplicate is
    /// gone (the first sweep), the second sweep takes each twin out of the run too, so that the
    /// front simplifies as the one-sided surface it is, and [`Mesh::compact`] writes it back
    /// turned over from whatever its front became, as meshoptimizer keeps both sides.
    #[inline(always)]
    fn drop_duplicates(&mut self) {
        // Twins need a pair with the same vertex set; without one in the first sweep (every
        // clean mesh) the second finds nothing.
        let mut pairs = false;
        for twins in [false, true] {
            for t in 0..self.tris.len() {
                let tri = self.tri(t);
                if is_dead(tri) || (twins && !pairs) {
                    continue;
                }
                let mut c = self.first(tri[0]);
                let mut first = NIL;
                while c != NIL {
                    let u = c >> 2;
                    if u < t && tri::same_set(self.tri(u), tri) {
                        pairs = true;
                        if twins || tri::same_winding(self.tri(u), tri) {
                            first = u;
                            break;
                        }
                    }
                    c = self.after(c);
                }
                if first != NIL {
                    for &x in &tri {
                        self.unlink(x, t);
                    }
                    if twins {
                        self.kill_twin(t, first);
                        self.twins += 1;
                    } else {
                        self.kill(t);
                        self.duplicates += 1;
                    }
                    self.live = self.live.saturating_sub(1);
                }
            }
        }
    }

    /// Sets every vertex's flags: used, and boundary or locked from its fan (which
    /// [`Mesh::order`] puts in fan order when it is regular).
    #[inline(always)]
    fn classify(&mut self, scratch: (&mut [L], &mut [L])) {
        for v in 0..self.head.len() {
            let mut f = 0;
            if self.first(v) != NIL {
                f |= flag::USED;
                match self.order(v, &mut *scratch.0, &mut *scratch.1) {
                    Fan::Interior => {}
                    Fan::Boundary => f |= flag::BOUNDARY,
                    Fan::Irregular => f |= flag::LOCKED,
                }
            }
            self.set_flags(v, f);
        }
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
        // Vertices that are both some triangle's `a` and some triangle's `b`, each counted
        // when its second flag is set.
        let mut both = 0;
        for (t, k) in self.corners(v) {
            let (a, b) = tri::others(self.tri(t), k);
            for (x, f, g, map) in [
                (a, flag::SEEN_A, flag::SEEN_B, &mut *by_a),
                (b, flag::SEEN_B, flag::SEEN_A, &mut *by_b),
            ] {
                twice |= self.has(x, f);
                both += usize::from(self.has(x, g));
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
            // anywhere). With no `a` twice, there are `total - both` of them.
            let starts = total - both.min(total);
            let mut start = self.first(v);
            if starts == 1 {
                for (t, k) in self.corners(v) {
                    if !self.has(self.tri(t)[next3(k)], flag::SEEN_B) {
                        start = corner(t, k);
                    }
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
            let (a, b) = tri::others(self.tri(t), k);
            self.set_flag(a, flag::SEEN_A, false);
            self.set_flag(b, flag::SEEN_B, false);
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
}

#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum Fan {
    Interior,
    Boundary,
    Irregular,
}
