//! The memoryless quadric, the default cost.

use super::{bad, Cost, Move};
use crate::math::V3;
use crate::{Config, ConfigField, CostKind, Error};

/// Memoryless quadric error (Lindstrom and Turk's "memoryless" simplification, 1998; the
/// plane quadrics of Cheng, Pan and Shi 1998 §2.3 (their K_p and Q_s) and of an
/// implementation of Garland's edge collapse, without the per-vertex matrix): the area-weighted
/// squared distance from the kept vertex to the planes of the removed vertex's current triangles,
///
/// ```text
/// E(a -> b) = dᵀ Q d · (1 + Ā / A_fan),   Q = Σ_t A_t n_t n_tᵀ,   d = p_b − p_a
/// ```
///
/// plus `boundary_weight` times the squared boundary retreat times `Ā`. `Q` is six floats on
/// the stack, built in one fan walk; each candidate then costs a 3×3 quadratic form.
///
/// The factor `1 + Ā/A_fan` (Ā: the mean triangle area of the mesh at the start of the round,
/// A_fan: the fan's area) is what keeps thin parts: an area-weighted sum alone makes a fan of
/// small triangles cheap to remove however far it moves, so thin parts (the cow's teats and
/// tail) go first; dividing by the fan's area alone (a mean squared distance) keeps them but
/// raises the mean error on every shared mesh (decision record: docs/algorithm.md).
///
/// Needs [`Config::cost`] = [`CostKind::Quadric`]; the boundary weight is
/// [`Config::boundary_weight`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Quadric {
    /// Weight of the boundary retreat (set when the run starts).
    pub(super) boundary_weight: f32,
    /// Twice the mean triangle area of the current mesh (set each round by the engine).
    pub(super) reference: f32,
}

impl Quadric {
    /// The memoryless quadric (its settings come from the configuration).
    pub const fn new() -> Self {
        Quadric {
            boundary_weight: 1.0,
            reference: 0.0,
        }
    }
}

impl Default for Quadric {
    fn default() -> Self {
        Self::new()
    }
}

/// `dᵀ Q d` of the fan's quadric, clamped at zero (rounding can make it slightly negative).
#[inline]
fn form(f: &QuadricFan, d: [f32; 3]) -> f32 {
    crate::quadric::point_error(&f.q, d)
}

/// The fan summary of [`Quadric`]: `Q` (upper triangle, row by row) and twice the area.
#[derive(Clone, Copy, Debug, Default)]
pub struct QuadricFan {
    q: [f32; 6],
    area2: f32,
}

impl Cost for Quadric {
    type Fan = QuadricFan;

    fn configure(&mut self, config: &Config, _vertices: usize) -> Result<(), Error> {
        if config.cost != CostKind::Quadric {
            return bad(ConfigField::Cost);
        }
        self.boundary_weight = config.boundary_weight;
        Ok(())
    }

    fn empty(&self) -> QuadricFan {
        QuadricFan::default()
    }

    #[inline]
    fn add(&self, f: &mut QuadricFan, n: V3, area2: f32) {
        let w = area2;
        let q = &mut f.q;
        q[0] += w * n[0] * n[0];
        q[1] += w * n[0] * n[1];
        q[2] += w * n[0] * n[2];
        q[3] += w * n[1] * n[1];
        q[4] += w * n[1] * n[2];
        q[5] += w * n[2] * n[2];
        f.area2 += area2;
    }

    #[inline]
    fn price(&self, f: &QuadricFan, m: &Move) -> f32 {
        let e = form(f, m.d);
        let thin = if f.area2 > 0.0 {
            1.0 + self.reference / f.area2
        } else {
            1.0
        };
        e * thin + self.boundary_weight * m.retreat2 * self.reference
    }

    /// The area-weighted mean squared distance from the kept vertex to the planes of the
    /// triangles around the removed one (`dᵀQd / A_fan`), plus the squared boundary retreat.
    fn error2(&self, f: &QuadricFan, m: &Move, _price: f32) -> f32 {
        let e = form(f, m.d);
        let e = if f.area2 > 0.0 { e / f.area2 } else { 0.0 };
        e + m.retreat2
    }

    fn needs_turn(&self) -> bool {
        false
    }

    fn round(&mut self, mean_area2: f32) {
        self.reference = mean_area2;
    }

    /// `r2 · area2` (the crate-private `quadric_part`): without the thin-part factor,
    /// whose reference area changes every round (a part's place in the order must not).
    fn part(&self, r2: f32, area2: f32) -> f32 {
        super::quadric_part(r2, area2)
    }
}
