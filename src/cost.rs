//! Collapse costs: how much moving one vertex onto a neighbour changes the surface.
//!
//! The engine prices a vertex's collapses in one walk around its fan. Each triangle of the fan
//! is handed to [`Cost::add`] (its unit normal and twice its area), building a small summary
//! of the fan on the stack, then each candidate target is priced from that summary by
//! [`Cost::price`] in O(1). A cost that needs every surviving triangle's *new* normal (the
//! paper's W) says so with [`Cost::needs_turn`]; the engine then walks the fan once more per
//! candidate and passes the summed normal change. A new cost is one more implementation of this
//! trait, passed to [`Workspace::start_with_cost`](crate::Workspace::start_with_cost); the
//! engine does not change.
//!
//! All lengths are in the engine's normalised units (the input's bounding box mapped to about
//! `[-1, 1]³`), so costs do not depend on the scale of the input.

use crate::math::{self, V3};
use crate::CostKind;

/// One candidate collapse `from -> to`, as a cost sees it.
#[derive(Clone, Copy, Debug)]
pub struct Move {
    /// How far the moving vertex moves (`to - from`).
    pub d: [f32; 3],
    /// For a boundary vertex moving along its boundary: squared distance from it to the new
    /// boundary edge, i.e. how far the boundary retreats. Zero otherwise.
    pub retreat2: f32,
    /// Σ ‖N_new − N_old‖² over the surviving triangles (unit normals; seed 004 eq. 2), when
    /// [`Cost::needs_turn`]; zero otherwise.
    pub turn: f32,
}

/// A collapse cost. Lower is better; the engine never performs a collapse whose price is not
/// finite.
pub trait Cost {
    /// What the cost keeps of one fan while the engine walks it.
    type Fan: Copy;
    /// The summary of an empty fan.
    fn empty(&self) -> Self::Fan;
    /// Adds one triangle of the moving vertex's fan: its unit normal (zero if it has no area)
    /// and twice its area.
    fn add(&self, fan: &mut Self::Fan, normal: V3, area2: f32);
    /// The price of one move of the vertex whose fan was summarised.
    fn price(&self, fan: &Self::Fan, m: &Move) -> f32;
    /// Whether [`Move::turn`] must be computed (one more fan walk per candidate).
    fn needs_turn(&self) -> bool;
    /// Called at the start of every round with the mean of twice the triangle area over the
    /// current mesh (the scale of its triangles). Nothing by default.
    fn round(&mut self, _mean_area2: f32) {}
}

/// Memoryless quadric error (Lindstrom and Turk's "memoryless" simplification, 1998; the
/// plane quadrics of seed 000 §2.3 (Cheng/Pan/Shi, eq. for K_p and Q_s) and of seed 003 (an
/// implementation of Garland's edge collapse) without
/// the per-vertex matrix): the area-weighted squared distance from the kept vertex to the
/// planes of the removed vertex's current triangles,
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
/// small triangles cheap to remove however far it moves, and the cow's teats and tail went
/// first (Hausdorff 5.1 % of the diagonal at 10 %); dividing by the fan's area alone (a mean
/// squared distance) keeps them but raises the mean error by 10-30 % on every shared mesh.
/// Measured on the shared meshes with `host-sim bench`; see the README.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Quadric {
    /// Weight of the boundary retreat.
    pub boundary_weight: f32,
    /// Twice the mean triangle area of the current mesh (set each round by the engine).
    pub reference: f32,
}

/// The fan summary of [`Quadric`]: `Q` (upper triangle, row by row) and twice the area.
#[derive(Clone, Copy, Debug, Default)]
pub struct QuadricFan {
    q: [f32; 6],
    area2: f32,
}

impl Cost for Quadric {
    type Fan = QuadricFan;

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
        let (q, d) = (&f.q, &m.d);
        let e = q[0] * d[0] * d[0]
            + q[3] * d[1] * d[1]
            + q[5] * d[2] * d[2]
            + 2.0 * (q[1] * d[0] * d[1] + q[2] * d[0] * d[2] + q[4] * d[1] * d[2]);
        let e = if e > 0.0 { e } else { 0.0 };
        let thin = if f.area2 > 0.0 {
            1.0 + self.reference / f.area2
        } else {
            1.0
        };
        e * thin + self.boundary_weight * m.retreat2 * self.reference
    }

    fn needs_turn(&self) -> bool {
        false
    }

    fn round(&mut self, mean_area2: f32) {
        self.reference = mean_area2;
    }
}

/// The memoryless quadric under its former name.
pub type PlaneDistance = Quadric;

/// The paper's normal variation W (seed 004 §2, eq. 1-2, Algorithm 1): the sum over the moving
/// vertex's surviving triangles of ‖N_new − N_old‖², with no trigonometry.
///
/// * `length_weighted`: multiply by the squared edge length (greedy). W measures how far
///   normals turn, not how far the surface moves; as a *global* priority alone it prefers long
///   collapses across flat regions. Displacement is about length × normal change, so W·ℓ²
///   ranks collapses by a squared distance.
/// * `boundary_weight`: a boundary vertex moving along its boundary adds
///   `boundary_weight · retreat² / ℓ²` (scale-free like W; with W·ℓ², `boundary_weight ·
///   retreat²`), so open meshes keep their rims.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NormalVariation {
    /// Multiply by the squared edge length (greedy schedule).
    pub length_weighted: bool,
    /// Weight of the boundary retreat.
    pub boundary_weight: f32,
}

impl NormalVariation {
    /// W as in the paper, plus the boundary term: the cost of `Config::paper()`.
    pub const fn paper(boundary_weight: f32) -> Self {
        NormalVariation {
            length_weighted: false,
            boundary_weight,
        }
    }

    /// W·ℓ² plus the boundary term: greedy with `CostKind::NormalVariation`.
    pub const fn greedy(boundary_weight: f32) -> Self {
        NormalVariation {
            length_weighted: true,
            boundary_weight,
        }
    }
}

impl Cost for NormalVariation {
    type Fan = ();

    fn empty(&self) {}

    #[inline]
    fn add(&self, _: &mut (), _: V3, _: f32) {}

    #[inline]
    fn price(&self, _: &(), m: &Move) -> f32 {
        let l2 = math::dot(m.d, m.d);
        if self.length_weighted {
            m.turn * l2 + self.boundary_weight * m.retreat2
        } else if l2 > 0.0 {
            m.turn + self.boundary_weight * m.retreat2 / l2
        } else {
            m.turn
        }
    }

    fn needs_turn(&self) -> bool {
        true
    }
}

/// The built-in costs, chosen at run time by [`Config::cost`](crate::Config::cost).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Builtin {
    /// [`Quadric`].
    Quadric(Quadric),
    /// [`NormalVariation`].
    NormalVariation(NormalVariation),
}

impl Builtin {
    /// The cost a configuration names (W is length-weighted under the greedy schedule).
    pub fn of(config: &crate::Config) -> Self {
        let boundary_weight = config.boundary_weight;
        match config.cost {
            CostKind::Quadric => Builtin::Quadric(Quadric {
                boundary_weight,
                reference: 0.0,
            }),
            CostKind::NormalVariation => Builtin::NormalVariation(NormalVariation {
                length_weighted: config.schedule == crate::Schedule::Greedy,
                boundary_weight,
            }),
        }
    }
}

impl Cost for Builtin {
    type Fan = QuadricFan;

    fn empty(&self) -> QuadricFan {
        QuadricFan::default()
    }

    #[inline]
    fn add(&self, f: &mut QuadricFan, n: V3, area2: f32) {
        if let Builtin::Quadric(q) = self {
            q.add(f, n, area2)
        }
    }

    #[inline]
    fn price(&self, f: &QuadricFan, m: &Move) -> f32 {
        match self {
            Builtin::Quadric(q) => q.price(f, m),
            Builtin::NormalVariation(w) => w.price(&(), m),
        }
    }

    fn needs_turn(&self) -> bool {
        matches!(self, Builtin::NormalVariation(_))
    }

    fn round(&mut self, mean_area2: f32) {
        if let Builtin::Quadric(q) = self {
            q.round(mean_area2)
        }
    }
}
