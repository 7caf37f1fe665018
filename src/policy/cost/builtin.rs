//! The built-in costs behind one run-time choice.

use super::{Cost, Move, NormalVariation, Quadric, QuadricFan};
use crate::math::V3;
use crate::{Config, CostKind, Error};

/// The built-in costs, chosen at run time by [`Config::cost`] when the run starts (what
/// [`Storage::simplify`](crate::Storage::simplify) uses): one engine for both.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Builtin {
    /// [`Quadric`].
    Quadric(Quadric),
    /// [`NormalVariation`].
    NormalVariation(NormalVariation),
}

impl Builtin {
    /// The cost the configuration names when the run starts.
    pub const fn new() -> Self {
        Builtin::Quadric(Quadric::new())
    }

    /// The cost a configuration names (W is length-weighted under the greedy schedule).
    fn from_config(config: &Config) -> Self {
        match config.cost {
            CostKind::Quadric => Builtin::Quadric(Quadric {
                boundary_weight: config.boundary_weight,
                reference: 0.0,
            }),
            CostKind::NormalVariation => {
                Builtin::NormalVariation(NormalVariation::from_config(config))
            }
        }
    }
}

impl Default for Builtin {
    fn default() -> Self {
        Self::new()
    }
}

impl Cost for Builtin {
    type Fan = QuadricFan;

    fn configure(&mut self, config: &Config, _vertices: usize) -> Result<(), Error> {
        *self = Self::from_config(config);
        Ok(())
    }

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

    fn error2(&self, f: &QuadricFan, m: &Move, price: f32) -> f32 {
        match self {
            Builtin::Quadric(q) => q.error2(f, m, price),
            Builtin::NormalVariation(_) => 0.0,
        }
    }

    fn needs_turn(&self) -> bool {
        matches!(self, Builtin::NormalVariation(_))
    }

    fn needs_fan(&self) -> bool {
        matches!(self, Builtin::Quadric(_))
    }

    fn round(&mut self, mean_area2: f32) {
        if let Builtin::Quadric(q) = self {
            q.round(mean_area2)
        }
    }

    fn part(&self, r2: f32, area2: f32) -> f32 {
        match self {
            Builtin::Quadric(q) => q.part(r2, area2),
            Builtin::NormalVariation(w) => w.part(r2, area2),
        }
    }
}
