//! Fan walks: one walk around a vertex's fan gathers what pricing and the feature rule read
//! (the cost's summary, the normal variation D, the boundary ends, the neighbours), and hands a
//! storing cost each vertex's planes once.

use super::Simplifier;
use crate::index::Index;
use crate::math::{self, V3};
use crate::mesh::{flag, NIL};
use crate::operator::Operator;
use crate::policy::bound::Bound;
use crate::policy::cost::Cost;
use crate::policy::feature::Variation;
use crate::policy::legality::Shape;
use crate::tri;

/// Candidates priced per vertex: its first `MAX_CANDIDATES` neighbours in fan order (a vertex
/// of higher valence never moves onto the others).
pub(super) const MAX_CANDIDATES: usize = 32;

/// One walk around a fan: the cost's summary, D, and the boundary ends.
pub(super) struct FanSummary<F> {
    pub(super) fan: F,
    pub(super) variation: Variation,
    /// For a boundary vertex: the `a` of its first triangle and the `b` of its last.
    pub(super) ends: (usize, usize),
    /// The walked vertex's position.
    pub(super) p: V3,
    /// Twice the fan's area.
    pub(super) area2: f32,
    /// Its neighbours in fan order.
    pub(super) nb: [u32; MAX_CANDIDATES],
    pub(super) n: usize,
}

impl<F> FanSummary<F> {
    pub(super) fn push(&mut self, x: usize) {
        if let Some(slot) = self.nb.get_mut(self.n) {
            *slot = x as u32;
            self.n += 1;
        }
    }

    pub(super) fn neighbours(&self) -> impl Iterator<Item = usize> + '_ {
        self.nb.iter().take(self.n).map(|&x| x as usize)
    }
}

impl<'a, L: Index, I: Index, C: Cost, B: Bound<'a, I>, O: Operator> Simplifier<'a, L, I, C, B, O> {
    /// Whether walks compute the fan's normals and areas: the cost or the feature rule reads
    /// them.
    pub(super) fn normals(&self) -> bool {
        self.config.features || self.cost.needs_fan()
    }

    pub(super) fn is_feature_now(&self, w: &FanSummary<C::Fan>) -> bool {
        w.variation
            .value(self.config.feature_mode)
            .is_some_and(|d| d > self.threshold)
    }

    /// A summary of no walk yet, for [`Self::walk`] to fill in the caller's frame (a summary
    /// returned from the walk was copied out with a `memcpy`, which took the library's
    /// `memcpy` into every image: scripts/flash.sh).
    #[inline(always)]
    pub(super) fn unwalked(&self) -> FanSummary<C::Fan> {
        FanSummary {
            fan: self.cost.empty(),
            variation: Variation::default(),
            ends: (NIL, NIL),
            p: [0.0; 3],
            area2: 0.0,
            nb: [0; MAX_CANDIDATES],
            n: 0,
        }
    }

    /// One walk around `v`'s fan into `w` (from [`Self::unwalked`]): the cost's summary of it,
    /// D, the boundary ends and the neighbours (each corner's `a`, and a boundary fan's last
    /// `b`). Returns `w`.
    pub(super) fn walk<'w>(
        &self,
        v: usize,
        w: &'w mut FanSummary<C::Fan>,
    ) -> &'w FanSummary<C::Fan> {
        let mesh = &self.mesh;
        let pv = mesh.p(v);
        w.p = pv;
        // Normals only when something reads them: the cost's fan summary or the feature rule.
        let normals = self.normals();
        let mut c = mesh.first(v);
        while c != NIL {
            let (x, y) = tri::others(mesh.tri(c >> 2), c & 3);
            if w.n == 0 {
                w.ends.0 = x;
            }
            w.ends.1 = y;
            w.push(x);
            c = mesh.after_in(c, v);
            if !normals {
                continue;
            }
            let dx = math::sub(mesh.p(x), pv);
            let dy = math::sub(mesh.p(y), pv);
            // Twice the area and the unit normal from one cross product and one 1/√.
            let n = math::cross(dx, dy);
            let l2 = math::dot(n, n);
            let (unit, area2) = if l2 > math::TINY2 && l2.is_finite() {
                let r = math::rsqrt(l2);
                (math::scale(n, r), l2 * r)
            } else {
                ([0.0; 3], 0.0)
            };
            self.cost.add(&mut w.fan, unit, area2);
            self.cost.corner(&mut w.fan, dx, dy);
            w.variation.add(unit);
            w.area2 += area2;
        }
        if mesh.has(v, flag::BOUNDARY) && w.n > 0 {
            w.push(w.ends.1);
        }
        w
    }

    /// Hands the cost `v`'s planes (costs that store per-vertex state): each triangle (its
    /// corners, [`Cost::triangle`]) and its plane
    /// weighted by twice its area, and for a boundary vertex the plane through each of its two
    /// boundary edges perpendicular to the edge's triangle (Cheng, Pan and Shi 1998 §3.3).
    pub(super) fn init_vertex(&mut self, v: usize) {
        let f = self.mesh.flags(v);
        if f & flag::USED == 0 {
            return;
        }
        let pv = self.mesh.p(v);
        let (first, last) = (self.mesh.first(v), self.mesh.last(v));
        let mut c = first;
        let mut guard = self.mesh.triangle_count();
        while c != NIL && guard > 0 {
            guard -= 1;
            let tri = self.mesh.tri(c >> 2);
            let (x, y) = tri::others(tri, c & 3);
            let (px, py) = (self.mesh.p(x), self.mesh.p(y));
            let (ex, ey) = (math::sub(px, pv), math::sub(py, pv));
            self.cost
                .triangle(v, self.mesh.caller_corners(c >> 2, c & 3), ex, ey);
            let n = math::cross(ex, ey);
            let l2 = math::dot(n, n);
            if l2 > math::TINY2 && l2.is_finite() {
                let r = math::rsqrt(l2);
                let unit = math::scale(n, r);
                // Planes through v, in v's own frame (d = 0).
                self.cost.plane(v, unit, 0.0, l2 * r);
                if f & flag::BOUNDARY != 0 {
                    // The first triangle's edge v-x and the last one's v-y have no twin.
                    for (is, e) in [
                        (c == first, math::sub(px, pv)),
                        (c == last, math::sub(py, pv)),
                    ] {
                        if !is {
                            continue;
                        }
                        let m = math::cross(e, unit);
                        let m2 = math::dot(m, m);
                        if m2 > math::TINY2 && m2.is_finite() {
                            let m = math::scale(m, math::rsqrt(m2));
                            self.cost.boundary_plane(v, m, 0.0, math::dot(e, e));
                        }
                    }
                }
            }
            c = self.mesh.after_in(c, v);
        }
    }

    /// Σ ‖N_new − N_old‖² over `from`'s triangles that survive the move onto `to` (Lin 2007
    /// eq. 1-2), for costs that need it.
    pub(super) fn turn(&self, from: usize, to: usize) -> f32 {
        let mesh = &self.mesh;
        let pt = mesh.p(to);
        let mut sum = 0.0;
        for (t, k) in mesh.corners(from) {
            let tri = mesh.tri(t);
            if tri.contains(&to) {
                continue;
            }
            let q = tri.map(|v| mesh.p(v));
            let mut r = q;
            if let Some(x) = r.get_mut(k) {
                *x = pt;
            }
            let d = math::sub(Shape::of(r).unit(), Shape::of(q).unit());
            sum += math::dot(d, d);
        }
        sum
    }
}
