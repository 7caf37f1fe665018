//! The triangle collapse operator in the engine (see [`TriangleCollapse`](crate::TriangleCollapse)).

use crate::index::Index;
use crate::math::{self, V3};
use crate::mesh::Mesh;
use crate::mesh::{flag, next3, prev3, NIL};
use crate::operator::{Operator, MAX_PENALTIES, PENALTY};
use crate::policy::bound::Bound;
use crate::policy::cost::Cost;
use crate::policy::legality::on;

use super::price::take_cheapest;
use super::walk::MAX_CANDIDATES;
use super::{Phase, Simplifier};

/// Valence of `v`: its number of triangles.
fn valence<L: Index, I: Index>(mesh: &Mesh<'_, L, I>, v: usize) -> usize {
    mesh.corners(v).take(1 << 16).count()
}

/// `A (α + rc)` of triangle `tri` (eq. 3 without the error term), and its area `A`;
/// `None` if not finite.
pub(crate) fn weight<L: Index, I: Index>(
    mesh: &Mesh<'_, L, I>,
    tri: [usize; 3],
) -> Option<(f32, f32)> {
    let p: [V3; 3] = tri.map(|v| mesh.p(v));
    let e = [
        math::sub(p[1], p[0]),
        math::sub(p[2], p[1]),
        math::sub(p[0], p[2]),
    ];
    let l = e.map(|x| math::dot(x, x));
    let n = math::cross(e[0], math::scale(e[2], -1.0));
    let area = 0.5 * math::sqrt(math::dot(n, n));
    // cos β_k at vertex k: between the edges leaving it.
    let mut sum = 0.0;
    for (u, w) in [(0usize, 2usize), (1, 0), (2, 1)] {
        let (Some(&eu), Some(&ew), Some(&lu), Some(&lw)) = (e.get(u), e.get(w), l.get(u), l.get(w))
        else {
            return None;
        };
        let d = lu * lw;
        let c = if d > math::TINY2 && d.is_finite() {
            -math::dot(eu, ew) * math::rsqrt(d)
        } else {
            0.0
        };
        sum += c;
    }
    let alpha = 2.0 * (sum - 1.0);
    let r = (valence(mesh, tri[0]) + valence(mesh, tri[1]) + valence(mesh, tri[2])) as f32;
    let r_new = r - 9.0;
    let rc = if r_new > 6.0 {
        r_new - 6.0
    } else {
        6.0 - r_new
    } / 12.0;
    let w = area * (alpha + rc);
    if w.is_finite() {
        Some((w, area))
    } else {
        None
    }
}

impl<'a, L: Index, I: Index, C: Cost, B: Bound<'a, I>, O: Operator> Simplifier<'a, L, I, C, B, O> {
    /// Triangle collapse (Zhu, Wang and Meng 2007 eq. 3): the weight of live triangle `t`, `A (α +
    /// rc + d_max)`; `None` if not finite.
    pub(super) fn triangle_weight(&self, t: usize) -> Option<f32> {
        let tri = self.mesh.tri(t);
        let (w, area) = weight(&self.mesh, tri)?;
        let d = match self.bound.controls() {
            Some(c) if B::ON => c.max_distance(&self.mesh, t),
            _ => 0.0,
        };
        let w = w + area * d;
        w.is_finite().then_some(w)
    }

    /// Triangle collapse: `v`'s key is the smallest weight of its triangles (feature and
    /// locked vertices are not queued: their triangles are reached from their other vertices).
    pub(super) fn rekey_triangles(&mut self, v: usize) {
        let f = self.mesh.flags(v);
        if f & flag::USED == 0 || (on!(Locked) && f & flag::LOCKED != 0) {
            return self.heap.remove(v);
        }
        let mut w = self.unwalked();
        let w = self.walk(v, &mut w);
        let is = self.config.features && self.is_feature_now(w);
        self.mesh.set_flag(v, flag::FEATURE, is);
        if is && on!(Feature) {
            return self.heap.remove(v);
        }
        let mut key = f32::INFINITY;
        for (t, _) in self.mesh.corners(v) {
            if let Some(x) = self.triangle_weight(t) {
                if x < key {
                    key = x;
                }
            }
        }
        if key.is_finite() {
            self.heap.set(v, key)
        } else {
            self.heap.remove(v)
        }
    }

    /// Triangle collapse: one pop. `v`'s triangles in weight order; the first that collapses
    /// ends the pop. All refused: the key times the penalty `p` (Zhu, Wang and Meng 2007 §3), at
    /// most `MAX_PENALTIES` times in a row.
    pub(super) fn pop_triangles(&mut self) {
        let Some((v, key)) = self.top() else {
            return;
        };
        let mut cand = [(f32::INFINITY, NIL); MAX_CANDIDATES];
        let mut n = 0;
        for (t, _) in self.mesh.corners(v) {
            if let (Some(w), Some(slot)) = (self.triangle_weight(t), cand.get_mut(n)) {
                *slot = (w, t);
                n += 1;
            }
        }
        let cand = cand.get_mut(..n).unwrap_or(&mut []);
        let mut least = f32::INFINITY;
        for c in cand.iter() {
            if c.0 < least {
                least = c.0;
            }
        }
        while let Some((_, t)) = take_cheapest(cand) {
            if self.collapse_triangle(t) {
                return;
            }
        }
        // Every triangle refused: back in at p times the key, unless it was already
        // penalised MAX_PENALTIES times since its weights last changed.
        let mut cap = least;
        for _ in 0..MAX_PENALTIES {
            cap *= PENALTY;
        }
        let next = key * PENALTY;
        if least.is_finite() && next > key && key < cap && next.is_finite() {
            self.heap.set(v, next);
        } else {
            self.heap.remove(v);
        }
    }

    /// Collapses live triangle `t` into one of its vertices, as two half-edge moves `x -> k`,
    /// `y -> k` (see `crate::triangle`); `false` if the first move is refused for every `k`.
    pub(super) fn collapse_triangle(&mut self, t: usize) -> bool {
        let tri = self.mesh.tri(t);
        if crate::mesh::is_dead(tri) {
            return false;
        }
        // The kept vertex: the one whose two moves the cost prices lowest (ties: lower slot).
        let mut order = [(f32::INFINITY, 0usize); 3];
        for (k, slot) in order.iter_mut().enumerate() {
            let mut sum = 0.0f32;
            // Indexed with next3/prev3 directly: provably below 3 (no bounds check).
            for x in [tri[next3(k)], tri[prev3(k)]] {
                let mut w = self.unwalked();
                let w = self.walk(x, &mut w);
                sum += self
                    .price_kept(x, w, tri[prev3(next3(k))], true)
                    .unwrap_or(f32::INFINITY);
            }
            *slot = (sum, k);
        }
        for _ in 0..3 {
            // The cheapest choice left (a selection, not a sort: no comparator to misuse).
            let mut best: Option<usize> = None;
            for (i, c) in order.iter().enumerate() {
                if c.0.is_finite() && best.is_none_or(|b| order.get(b).is_some_and(|o| c.0 < o.0)) {
                    best = Some(i);
                }
            }
            let Some((price, k)) = best.and_then(|b| order.get_mut(b)).map(|o| {
                let v = *o;
                o.0 = f32::INFINITY;
                v
            }) else {
                break;
            };
            if !price.is_finite() {
                continue;
            }
            let keep = tri[prev3(next3(k))];
            let (x, y) = crate::tri::others(tri, k);
            match self.check(x, keep, None) {
                Ok(()) => {
                    self.heap.remove(x);
                    self.collapse_greedy(x, keep, None);
                    if matches!(self.phase, Phase::Done(_)) {
                        return true;
                    }
                    // The second move, on the mesh after the first.
                    let mut w = self.unwalked();
                    let w = self.walk(y, &mut w);
                    if self.mesh.live > self.target && self.price_kept(y, w, keep, true).is_some() {
                        match self.check(y, keep, None) {
                            Ok(()) => {
                                self.heap.remove(y);
                                self.collapse_greedy(y, keep, None);
                            }
                            Err(r) => self.rejected.count(r),
                        }
                    }
                    return true;
                }
                Err(r) => self.rejected.count(r),
            }
        }
        false
    }
}
