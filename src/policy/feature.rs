//! Feature vertices (Lin 2007 §3, eq. 3-5).
//!
//! A vertex's *variation* D is the sum, over ordered pairs of its triangles, of the squared
//! distance between their unit normals (eq. 3-4, quantised by eq. 2). A vertex is a feature iff
//! `D > λ · mean(D)` over the vertices that have triangles (eq. 5; λ = 1 in the paper).
//!
//! The paper's double loop is O(k²) in the valence k. Expanding the square gives the same sum
//! in O(k), with N_u the unit normals, so D comes out of the same fan walk that prices a
//! vertex's collapses:
//!
//! ```text
//! Σ_u Σ_w ‖N_u − N_w‖² = 2k · Σ_u ‖N_u‖² − 2 ‖Σ_u N_u‖²
//! ```
//!
//! (‖N_u‖² is 1, or 0 for a zero-area triangle, which has no normal.) Rounding can make the
//! right side slightly negative for a flat fan, so it is clamped at 0.

use crate::config::FeatureMode;
use crate::math::{self, V3};

/// The running sums of one fan walk.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Variation {
    k: u32,
    sum: V3,
    sq: f32,
}

impl Variation {
    /// Adds one triangle's unit normal (zero if it has no area).
    #[inline]
    pub(crate) fn add(&mut self, n: V3) {
        self.sum = math::add(self.sum, n);
        self.sq += math::dot(n, n);
        self.k += 1;
    }

    /// D, normalised as `mode` says, or `None` for a vertex without triangles.
    pub(crate) fn value(&self, mode: FeatureMode) -> Option<f32> {
        if self.k == 0 {
            return None;
        }
        let kf = self.k as f32;
        let d = 2.0 * kf * self.sq - 2.0 * math::dot(self.sum, self.sum);
        let d = if d > 0.0 { d } else { 0.0 };
        Some(match mode {
            FeatureMode::Paper => d,
            FeatureMode::ValenceNormalized => d / (kf * kf),
        })
    }
}

/// Mean of D over a sweep, for the threshold of eq. 5. The sum is kept in fixed point (2⁻¹⁶)
/// in a `u64`: exact, the same on every target, and no software `f64` on a device.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Mean {
    sum: u64,
    count: u32,
}

const ONE: f32 = 65536.0;

impl Mean {
    pub(crate) fn add(&mut self, d: Option<f32>) {
        if let Some(d) = d {
            // `as` saturates: a huge D (valence in the thousands) cannot wrap.
            self.sum = self.sum.saturating_add((d * ONE) as u64);
            self.count += 1;
        }
    }

    /// `λ · mean(D)` (infinite with no vertex: nothing is a feature).
    pub(crate) fn threshold(&self, lambda: f32) -> f32 {
        if self.count == 0 {
            return f32::INFINITY;
        }
        // One conversion and an f32 division: a u64 division is a library routine on a
        // Cortex-M (about 900 bytes of flash).
        let mean = self.sum as f32 / (self.count as f32 * ONE);
        lambda * mean
    }
}
