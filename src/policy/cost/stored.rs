//! Stored quadrics: Garland's accumulated quadric error with per-vertex storage, and where it
//! places the kept vertex.

use super::{bad, Cost, Move};
use crate::math::{self, V3};
use crate::quadric::{add, error, form, outer, solve, translate, VertexQuadric};
use crate::{Config, ConfigField, CostKind, Error};

/// Where a collapse with stored quadrics leaves the kept vertex.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Placement {
    /// At one of the two endpoints (positions are only read, flash is fine).
    Subset,
    /// At the minimiser of Δ over the edge's summed quadric (Cheng, Pan and Shi 1998 §2.3, and
    /// Garland), written into the caller's mutable positions; the best of the endpoints and the
    /// midpoint when the 3×3 system is ill-conditioned or its solution lies far from the edge.
    Optimal,
}

/// Accumulated quadric error metric (Garland's, as Cheng, Pan and Shi 1998 use it, §2.3-2.5)
/// with per-vertex storage (`K_p = p pᵀ`, `Q_s` the sum over the vertex's triangles,
/// `Q = Q_s + Q_t` on a collapse, `Δ = vᵀ Q v` and an error-cost queue), as in an
/// implementation of Garland's edge collapse. Planes are area-weighted; a boundary vertex also
/// gets, for each boundary edge it is on, the plane through that edge perpendicular to its triangle
/// (Cheng, Pan and Shi 1998 §3.3), weighted by `boundary_weight` times the squared edge length.
///
/// The matrices live in a caller-provided slice, one [`VertexQuadric`] (40 bytes) per vertex, at
/// least as long as the positions (else [`Error::Capacity`] for
/// [`Capacity::Quadrics`](crate::Capacity::Quadrics) when the run starts). Needs the greedy
/// or batched schedule (else [`Error::InvalidConfig`] for [`ConfigField::Schedule`]) and [`Config::cost`]
/// = [`CostKind::Quadric`]; the boundary weight is [`Config::boundary_weight`].
/// [`Config::stored`] is the recommended configuration (no feature rule: lower mean error,
/// and the faster re-keying). All in the engine's normalised units, and each vertex's
/// matrix in a frame centred on that vertex (moved to the kept vertex's new position on a
/// collapse): in `f32`, `vᵀQv` with a global origin loses the small errors of early collapses
/// to cancellation between terms of order one.
pub struct StoredQuadric<'q> {
    q: &'q mut [VertexQuadric],
    boundary_weight: f32,
    placement: Placement,
}

impl<'q> StoredQuadric<'q> {
    /// A stored quadric over `storage` (contents on entry do not matter: zeroed when the run
    /// starts; the engine fills it), leaving kept vertices where `placement` says.
    pub fn new(storage: &'q mut [VertexQuadric], placement: Placement) -> Self {
        StoredQuadric {
            q: storage,
            boundary_weight: 1.0,
            placement,
        }
    }

    /// The boundary-plane weight.
    pub fn boundary_weight(&self) -> f32 {
        self.boundary_weight
    }

    /// The placement.
    pub fn placement(&self) -> Placement {
        self.placement
    }

    /// Vertex `v`'s quadric (zero if out of range).
    pub fn quadric(&self, v: usize) -> VertexQuadric {
        self.q.get(v).copied().unwrap_or([0.0; 10])
    }

    /// The edge's quadric `Q_from + Q_to` in the frame centred on `p_to`.
    fn edge(&self, m: &Move) -> VertexQuadric {
        add(
            &translate(&self.quadric(m.from), math::sub(m.p_to, m.p_from)),
            &self.quadric(m.to),
        )
    }

    /// The best position for `m` relative to `p_to`, and its error: the solution of the 3×3 system
    /// if it is well conditioned and near the edge, else (and if better) an endpoint or the
    /// midpoint. Candidates are compared in a fixed order with `<`, so ties go to the earlier one.
    fn best(&self, m: &Move) -> (V3, f32) {
        if m.keep || self.placement == Placement::Subset {
            // At p_to, the edge's quadric is `Q_from` read at `p_to − p_from` plus `Q_to`'s
            // constant term (its own frame's origin): the same sum `edge` would form, bit for
            // bit, without building the 10-term matrix (a third of a subset run's pricing).
            let c = form(&self.quadric(m.from), math::sub(m.p_to, m.p_from))
                + self.q.get(m.to).map_or(0.0, |q| q[9]);
            return ([0.0; 3], if c > 0.0 { c } else { 0.0 });
        }
        let q = self.edge(m);
        // Relative to p_to: the kept end is 0, the removed one -d.
        let mut best = ([0.0; 3], error(&q, [0.0; 3]));
        {
            let back = math::scale(m.d, -1.0);
            let mid = math::scale(m.d, -0.5);
            let l2 = math::dot(m.d, m.d);
            if let Some(x) = solve(&q) {
                let off = math::sub(x, mid);
                if math::dot(off, off) <= l2 {
                    let c = error(&q, x);
                    if c < best.1 {
                        best = (x, c);
                    }
                }
            }
            for x in [back, mid] {
                let c = error(&q, x);
                if c < best.1 {
                    best = (x, c);
                }
            }
        }
        best
    }
}

impl Cost for StoredQuadric<'_> {
    type Fan = ();
    const PLACES: bool = true;

    fn configure(&mut self, config: &Config, vertices: usize) -> Result<(), Error> {
        if self.q.len() < vertices {
            return Err(Error::Capacity {
                what: crate::Capacity::Quadrics,
                needed: vertices,
                available: self.q.len(),
            });
        }
        if !config.schedule.is_ordered() {
            return bad(ConfigField::Schedule);
        }
        if config.cost != CostKind::Quadric {
            return bad(ConfigField::Cost);
        }
        self.boundary_weight = config.boundary_weight;
        for q in self.q.iter_mut() {
            *q = [0.0; 10];
        }
        Ok(())
    }

    fn placement(&self) -> Placement {
        self.placement
    }

    fn empty(&self) {}

    #[inline]
    fn add(&self, _: &mut (), _: V3, _: f32) {}

    #[inline]
    fn price(&self, _: &(), m: &Move) -> f32 {
        self.best(m).1
    }

    /// The price over the summed plane weights (the trace of the two quadrics' 3×3 parts, as
    /// each plane's normal is a unit vector): the weighted mean squared distance to every
    /// original plane the two vertices carry.
    fn error2(&self, _: &(), m: &Move, price: f32) -> f32 {
        let trace = |q: VertexQuadric| q[0] + q[4] + q[7];
        let w = trace(self.quadric(m.from)) + trace(self.quadric(m.to));
        if w > 0.0 {
            price / w
        } else {
            0.0
        }
    }

    fn needs_turn(&self) -> bool {
        false
    }

    fn needs_fan(&self) -> bool {
        false
    }

    fn stores(&self) -> bool {
        true
    }

    fn plane(&mut self, v: usize, n: V3, d: f32, w: f32) {
        if let Some(q) = self.q.get_mut(v) {
            for (q, k) in q.iter_mut().zip(outer(n, d)) {
                *q += w * k;
            }
        }
    }

    fn boundary_plane(&mut self, v: usize, n: V3, d: f32, w: f32) {
        self.plane(v, n, d, w * self.boundary_weight)
    }

    fn merge(&mut self, from: usize, to: usize, p_from: V3, p_to: V3, p_new: V3) {
        let s = add(
            &translate(&self.quadric(from), math::sub(p_new, p_from)),
            &translate(&self.quadric(to), math::sub(p_new, p_to)),
        );
        if let Some(q) = self.q.get_mut(to) {
            *q = s;
        }
    }

    fn place(&self, m: &Move) -> Option<V3> {
        if m.keep || self.placement == Placement::Subset {
            return None;
        }
        let x = self.best(m).0;
        if x == [0.0; 3] {
            // The kept end stays where it is.
            return None;
        }
        Some(math::add(m.p_to, x))
    }

    /// `r2 · area2` (the crate-private `quadric_part`).
    fn part(&self, r2: f32, area2: f32) -> f32 {
        super::quadric_part(r2, area2)
    }
}
