//! Feature vertices (seed 004 §3, eq. 3-5).
//!
//! A vertex's *variation* D is the sum, over ordered pairs of its triangles, of the squared
//! distance between their unit normals (eq. 3-4, quantised by eq. 2). A vertex is a feature iff
//! `D > λ · mean(D)` over the vertices that have triangles (eq. 5; λ = 1 in the paper).
//!
//! The paper's double loop is O(k²) in the valence k. Expanding the square gives the same sum
//! in O(k), with N_u the unit normals:
//!
//! ```text
//! Σ_u Σ_w ‖N_u − N_w‖² = 2k · Σ_u ‖N_u‖² − 2 ‖Σ_u N_u‖²
//! ```
//!
//! (‖N_u‖² is 1, or 0 for a zero-area triangle, which has no normal.) Rounding can make the
//! right side slightly negative for a flat fan, so it is clamped at 0.

use crate::config::FeatureMode;
use crate::index::Index;
use crate::math;
use crate::mesh::Mesh;

/// D of vertex `v`, normalised as `mode` says, or `None` for a vertex without triangles.
pub(crate) fn variation<L: Index, I: Index>(
    mesh: &Mesh<'_, L, I>,
    v: usize,
    mode: FeatureMode,
) -> Option<f32> {
    let mut k = 0u32;
    let mut sum = [0.0f32; 3];
    let mut sq = 0.0f32;
    for (t, _) in mesh.corners(v) {
        let n = mesh.unit_normal(mesh.tri(t));
        sum = math::add(sum, n);
        sq += math::dot(n, n);
        k += 1;
    }
    if k == 0 {
        return None;
    }
    let kf = k as f32;
    let d = 2.0 * kf * sq - 2.0 * math::dot(sum, sum);
    let d = if d > 0.0 { d } else { 0.0 };
    Some(match mode {
        FeatureMode::Paper => d,
        FeatureMode::ValenceNormalized => d / (kf * kf),
    })
}

/// Running mean of D, kept up to date around each collapse by the greedy schedule.
///
/// The sum is kept in f64 so that thousands of local updates do not drift visibly; it is
/// deterministic all the same (IEEE arithmetic, soft-float where there is no double FPU).
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Mean {
    sum: f64,
    count: u32,
}

impl Mean {
    pub(crate) fn add(&mut self, d: Option<f32>) {
        if let Some(d) = d {
            self.sum += d as f64;
            self.count += 1;
        }
    }

    pub(crate) fn sub(&mut self, d: Option<f32>) {
        if let Some(d) = d {
            self.sum -= d as f64;
            self.count = self.count.saturating_sub(1);
        }
    }

    pub(crate) fn threshold(&self, lambda: f32) -> f32 {
        if self.count == 0 {
            return f32::INFINITY;
        }
        let mean = (self.sum / self.count as f64) as f32;
        lambda * if mean > 0.0 { mean } else { 0.0 }
    }
}
