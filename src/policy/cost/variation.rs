//! The paper's normal variation W.

use super::{bad, Cost, Move};
use crate::math::{self, V3};
use crate::{Config, ConfigField, CostKind, Error};

/// The paper's normal variation W (Lin 2007 §2, eq. 1-2, Algorithm 1): the sum over the moving
/// vertex's surviving triangles of ‖N_new − N_old‖², with no trigonometry.
///
/// Needs [`Config::cost`] = [`CostKind::NormalVariation`]; both settings come from the
/// configuration when the run starts:
///
/// * `length_weighted`: multiply by the squared edge length (the greedy schedule). W measures how
///   far normals turn, not how far the surface moves; as a *global* priority alone it prefers long
///   collapses across flat regions. Displacement is about length × normal change, so W·ℓ²
///   ranks collapses by a squared distance.
/// * `boundary_weight` ([`Config::boundary_weight`]): a boundary vertex moving along its boundary
///   adds `boundary_weight · retreat² / ℓ²` (scale-free like W; with W·ℓ², `boundary_weight ·
///   retreat²`), so open meshes keep their rims.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NormalVariation {
    /// Multiply by the squared edge length (greedy schedule).
    length_weighted: bool,
    /// Weight of the boundary retreat.
    boundary_weight: f32,
}

impl NormalVariation {
    /// The normal variation (its settings come from the configuration).
    pub const fn new() -> Self {
        NormalVariation {
            length_weighted: false,
            boundary_weight: 1.0,
        }
    }

    pub(super) const fn from_config(config: &Config) -> Self {
        NormalVariation {
            length_weighted: config.schedule.is_ordered(),
            boundary_weight: config.boundary_weight,
        }
    }
}

impl Default for NormalVariation {
    fn default() -> Self {
        Self::new()
    }
}

impl Cost for NormalVariation {
    type Fan = ();

    fn configure(&mut self, config: &Config, _vertices: usize) -> Result<(), Error> {
        if config.cost != CostKind::NormalVariation {
            return bad(ConfigField::Cost);
        }
        *self = Self::from_config(config);
        Ok(())
    }

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

    fn needs_fan(&self) -> bool {
        false
    }
}
