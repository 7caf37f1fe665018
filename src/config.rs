//! What to simplify to, and how.

/// Which vertices the collapse engine tries first.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Schedule {
    /// Always collapse the cheapest legal edge of the whole mesh (indexed priority queue).
    /// The priority is the configured cost ([`Config::cost`]): the memoryless quadric by
    /// default, or the paper's normal variation W scaled by the squared edge length
    /// ([`CostKind::NormalVariation`]), so that it measures how far the surface moves, not
    /// only how far normals turn.
    Greedy,
    /// The paper's own schedule (Lin 2007, Algorithms 3-4): each pass recomputes feature
    /// flags, sweeps vertices in index order and pairs each unprocessed non-feature vertex with
    /// the neighbour giving its cheapest legal collapse; both are then done for the pass.
    Passes,
    /// Greedy in batches (meshoptimizer's pass structure): each pass prices every vertex's
    /// cheapest candidate once, orders them by price and collapses them in that order, skipping
    /// a vertex whose price a collapse earlier in the pass made stale; a pass aims at half the
    /// live triangles at most, ends at its error limit (the price of the candidate that would
    /// reach that goal) and the next pass prices afresh. Same rules, limits and stops as [`Schedule::Greedy`], with no
    /// re-pricing after each collapse; the order is exact within a pass only. Needs the crate
    /// feature `batched` (else [`Storage::start`](crate::Storage::start) refuses it).
    Batched,
}

impl Schedule {
    /// Whether collapses come in price order over the whole mesh ([`Schedule::Greedy`] and
    /// [`Schedule::Batched`]): these share the defaults and options of the greedy schedule.
    pub const fn is_ordered(self) -> bool {
        !matches!(self, Schedule::Passes)
    }
}

/// Which cost ranks the collapses (see [`crate::cost`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum CostKind {
    /// Memoryless quadric (Lindstrom-Turk style): the squared distance from the kept vertex to
    /// the planes of the removed vertex's current triangles, plus a boundary term. The default.
    Quadric,
    /// The paper's normal variation W (Lin 2007 eq. 1-2); greedy multiplies it by the squared
    /// edge length, passes uses it as written.
    NormalVariation,
}

/// The triangle count a run stops at (or below): the stop of [`Config::target`].
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
// With a 16-bit tag the engine's code comes out smallest on every target `scripts/flash.sh`
// measures (the default tag costs a few dozen bytes on Cortex-M0 and RISC-V).
#[repr(u16)]
pub enum Target {
    /// This fraction of the valid input triangles (those left after dropping degenerate and
    /// duplicate ones), in `[0, 1]`, rounded down.
    Ratio(f32),
    /// This many triangles.
    Triangles(usize),
}

impl Target {
    /// The triangle count for `valid` valid input triangles.
    pub fn triangles(self, valid: usize) -> usize {
        match self {
            // In f32, exact for counts below 2^24; the product is floored.
            Target::Ratio(r) => (r * valid as f32) as usize,
            Target::Triangles(n) => n,
        }
    }
}

/// How the feature test (Lin 2007 §3, eq. 3-5) weighs a vertex's normal variation D.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum FeatureMode {
    /// D as in the paper: the sum over ordered pairs of adjacent triangles. D grows with the
    /// square of the valence k, so high-valence vertices are more often features.
    Paper,
    /// D / k²: the mean pairwise variation, independent of valence.
    ValenceNormalized,
}

/// Simplification settings. Build with [`Config::new`] and the `with_*` methods; the engine
/// checks them in [`Storage::start`](crate::Storage::start), and each policy given there
/// (cost, bound) checks the fields it depends on.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Config {
    pub(crate) schedule: Schedule,
    pub(crate) cost: CostKind,
    pub(crate) target: Target,
    pub(crate) max_cost: f32,
    pub(crate) max_passes: u32,
    pub(crate) lambda: f32,
    pub(crate) features: bool,
    pub(crate) feature_mode: FeatureMode,
    pub(crate) feature_targets: bool,
    pub(crate) max_normal_turn_deg: f32,
    pub(crate) min_quality: f32,
    pub(crate) boundary_weight: f32,
    pub(crate) max_error: f32,
    pub(crate) error_limit: f32,
    pub(crate) control_angle_deg: f32,
    pub(crate) prune_parts: bool,
}

/// What a configuration says: one getter per setting, named as its `with_*` builder.
impl Config {
    /// Collapse order.
    #[inline]
    pub const fn schedule(&self) -> Schedule {
        self.schedule
    }

    /// What a collapse costs: the built-in cost of [`Storage::simplify`](crate::Storage::simplify)
    /// and [`Builtin`](crate::cost::Builtin); a cost given to
    /// [`Storage::start`](crate::Storage::start) must agree with it (stored quadrics are a
    /// [`CostKind::Quadric`]).
    #[inline]
    pub const fn cost(&self) -> CostKind {
        self.cost
    }

    /// Stop at or below this many triangles.
    #[inline]
    pub const fn target(&self) -> Target {
        self.target
    }

    /// Never perform a collapse whose cost exceeds this (in the schedule's cost units): the
    /// other stop, before the target if the remaining collapses all cost more.
    #[inline]
    pub const fn max_cost(&self) -> f32 {
        self.max_cost
    }

    /// Stop after this many passes (for [`Schedule::Greedy`]: rounds of the queue; for
    /// [`Schedule::Batched`]: its batches); at least 1.
    #[inline]
    pub const fn max_passes(&self) -> u32 {
        self.max_passes
    }

    /// A vertex is a feature iff `D > lambda * mean(D)`. The paper uses 1; the default is 2,
    /// chosen by measured error (see docs/algorithm.md). Negative or non-finite values are rejected
    /// (use [`Config::features`] = `false` to turn features off).
    #[inline]
    pub const fn lambda(&self) -> f32 {
        self.lambda
    }

    /// Detect and keep feature vertices at all.
    #[inline]
    pub const fn features(&self) -> bool {
        self.features
    }

    /// How D is normalised before the feature test.
    #[inline]
    pub const fn feature_mode(&self) -> FeatureMode {
        self.feature_mode
    }

    /// Feature vertices may be the kept endpoint of a collapse ([`Schedule::Greedy`] and
    /// [`Schedule::Batched`] only; they
    /// are never removed either way). The paper says no: they take no part in any collapse, and
    /// [`Schedule::Passes`] always follows the paper here.
    #[inline]
    pub const fn feature_targets(&self) -> bool {
        self.feature_targets
    }

    /// Reject a collapse that turns a remaining triangle's normal by more than this many degrees,
    /// in `(0, 180)`.
    #[inline]
    pub const fn max_normal_turn_deg(&self) -> f32 {
        self.max_normal_turn_deg
    }

    /// Reject a collapse that leaves a triangle with quality (`4√3·area / Σ edge²`, 1 for an
    /// equilateral triangle) below this, unless the triangle was already worse or stays in its
    /// plane (within about 1°: a flat face stays flat, so the sliver costs no error). In
    /// `[0, 1)`.
    #[inline]
    pub const fn min_quality(&self) -> f32 {
        self.min_quality
    }

    /// Weight of the boundary retreat (squared distance of a removed boundary vertex to the new
    /// boundary edge) against the normal variation. Non-negative.
    #[inline]
    pub const fn boundary_weight(&self) -> f32 {
        self.boundary_weight
    }

    /// The guaranteed error bound `d_hold` (Zhu, Wang and Meng 2007 §2-§3), in the input's units:
    /// no control point (original triangle centroid or feature-edge vertex) ends farther than this
    /// from the result. Infinite (the default): no bound. A finite value needs
    /// [`Controls`](crate::bound::Controls); with [`NoBound`](crate::bound::NoBound) it is
    /// [`Error::InvalidConfig`](crate::Error::InvalidConfig) for `MaxError`. Non-negative.
    #[inline]
    pub const fn max_error(&self) -> f32 {
        self.max_error
    }

    /// The error limit, in the input's units: the greedy edge collapse refuses a collapse whose
    /// own error ([`Cost::error2`](crate::cost::Cost::error2): for the quadric costs the
    /// area-weighted RMS distance from the kept vertex to the planes it replaces, plus how far
    /// a boundary retreats) is above it, and a run that stops short of its target because of
    /// it reports [`Stop::ErrorLimit`](crate::Stop::ErrorLimit): stopping is better than
    /// cutting a corner to reach a count (meshoptimizer's `target_error` plays this part).
    /// Infinite (the default): no limit. Costs without a distance (normal variation) are never
    /// limited. Not a guarantee: for a guaranteed bound see [`Config::max_error`].
    /// Non-negative; a finite limit needs an ordered schedule (greedy or batched) and edge
    /// collapse or vertex removal.
    #[inline]
    pub const fn error_limit(&self) -> f32 {
        self.error_limit
    }

    /// With an error bound: an original edge is a feature edge (its vertices are control
    /// points of the second kind, Zhu, Wang and Meng 2007 §2 fig. 2) when its two triangles'
    /// normals differ by more than this many degrees, in `(0, 180)`. Boundary and non-manifold
    /// edges always are.
    #[inline]
    pub const fn control_angle_deg(&self) -> f32 {
        self.control_angle_deg
    }

    /// The pipeline (`pipeline::FastWorkspace` and `LeanWorkspace`, crate feature `fast`)
    /// removes a part
    /// (a connected component) whole once the error made reaches its size, and, short of the
    /// target with no collapse left, the smallest parts up to the error limit; the largest part
    /// always stays (meshoptimizer's `meshopt_SimplifyPrune`). Off by default: a part is only
    /// simplified. The exact engine prunes when given part links instead
    /// (`ModelStorage::with_parts`, crate feature `parts`).
    #[inline]
    pub const fn prune_parts(&self) -> bool {
        self.prune_parts
    }
}

impl Config {
    /// The defaults, chosen by measured error: greedy schedule, 10 % of the triangles, λ = 2
    /// with the paper's D, features never removed but allowed as collapse targets, 60°
    /// normal-turn limit.
    pub const fn new() -> Self {
        Config {
            schedule: Schedule::Greedy,
            cost: CostKind::Quadric,
            target: Target::Ratio(0.1),
            max_cost: f32::INFINITY,
            max_passes: 32,
            lambda: 2.0,
            features: true,
            feature_mode: FeatureMode::Paper,
            feature_targets: true,
            max_normal_turn_deg: 60.0,
            min_quality: 0.05,
            boundary_weight: 1.0,
            max_error: f32::INFINITY,
            error_limit: f32::INFINITY,
            control_angle_deg: 30.0,
            prune_parts: false,
        }
    }

    /// The paper as written (Lin 2007): the `Passes` schedule, λ = 1, features take no part in
    /// any collapse.
    pub const fn paper() -> Self {
        let mut c = Self::new();
        c.schedule = Schedule::Passes;
        c.cost = CostKind::NormalVariation;
        c.lambda = 1.0;
        c.feature_targets = false;
        c
    }

    /// The defaults for stored quadrics ([`StoredQuadric`](crate::cost::StoredQuadric), either
    /// placement): [`Config::new`] without Lin 2007's feature rule. The stored quadrics keep
    /// creases themselves, and without the rule the Metro mean error is lower in nearly every run
    /// over the shared meshes, and with subset placement the engine re-keys a collapse's neighbours with one
    /// price each (figures in docs/stored-quadrics.md, "No feature rule by default").
    pub const fn stored() -> Self {
        let mut c = Self::new();
        c.features = false;
        c
    }

    /// Sets [`Config::prune_parts`].
    pub const fn with_prune_parts(mut self, prune: bool) -> Self {
        self.prune_parts = prune;
        self
    }

    /// Sets the schedule.
    pub const fn with_schedule(mut self, schedule: Schedule) -> Self {
        self.schedule = schedule;
        self
    }

    /// Sets the cost.
    pub const fn with_cost(mut self, cost: CostKind) -> Self {
        self.cost = cost;
        self
    }

    /// Sets the target.
    pub const fn with_target(mut self, target: Target) -> Self {
        self.target = target;
        self
    }

    /// Stops at this fraction of the valid input triangles: `with_target(Target::Ratio(ratio))`.
    pub const fn with_ratio(self, ratio: f32) -> Self {
        self.with_target(Target::Ratio(ratio))
    }

    /// Sets the feature factor λ.
    pub const fn with_lambda(mut self, lambda: f32) -> Self {
        self.lambda = lambda;
        self
    }

    /// Sets how D is normalised.
    pub const fn with_feature_mode(mut self, mode: FeatureMode) -> Self {
        self.feature_mode = mode;
        self
    }

    /// Sets the maximum number of passes.
    pub const fn with_max_passes(mut self, passes: u32) -> Self {
        self.max_passes = passes;
        self
    }

    /// Sets the maximum collapse cost.
    pub const fn with_max_cost(mut self, cost: f32) -> Self {
        self.max_cost = cost;
        self
    }

    /// Sets the guaranteed error bound `d_hold` in the input's units (see
    /// [`Config::max_error`]).
    pub const fn with_max_error(mut self, distance: f32) -> Self {
        self.max_error = distance;
        self
    }

    /// Sets the error limit in the input's units (see [`Config::error_limit`]).
    pub const fn with_error_limit(mut self, distance: f32) -> Self {
        self.error_limit = distance;
        self
    }

    /// Detects and keeps feature vertices, or not.
    pub const fn with_features(mut self, features: bool) -> Self {
        self.features = features;
        self
    }

    /// Lets feature vertices be the kept endpoint of a collapse, or not.
    pub const fn with_feature_targets(mut self, targets: bool) -> Self {
        self.feature_targets = targets;
        self
    }

    /// Sets the normal-turn limit in degrees.
    pub const fn with_max_normal_turn(mut self, degrees: f32) -> Self {
        self.max_normal_turn_deg = degrees;
        self
    }

    /// Sets the triangle-quality floor.
    pub const fn with_min_quality(mut self, quality: f32) -> Self {
        self.min_quality = quality;
        self
    }

    /// Sets the weight of the boundary terms (every cost's, given once here).
    pub const fn with_boundary_weight(mut self, weight: f32) -> Self {
        self.boundary_weight = weight;
        self
    }

    /// Sets the feature-edge angle of an error bound's control points, in degrees.
    pub const fn with_control_angle(mut self, degrees: f32) -> Self {
        self.control_angle_deg = degrees;
        self
    }

    /// Sets the guaranteed error bound to `fraction` of the bounding-box diagonal of
    /// `positions` (0.005: 0.5 % of the diagonal).
    pub fn with_relative_max_error(self, fraction: f32, positions: &[[f32; 3]]) -> Self {
        self.with_max_error(fraction * crate::bound::bounding_diagonal(positions))
    }

    /// The error limit `tinydecimate simplify` uses by default, as a fraction of the bounding-box
    /// diagonal ([`Config::with_relative_error_limit`]): on clean meshes no collapse down to
    /// 10 % is over it; on raw CAD exports and multi-part assets it refuses the few collapses
    /// that cut a part or a corner.
    pub const MODEL_ERROR_LIMIT: f32 = 0.02;

    /// Sets the error limit to `fraction` of the bounding-box diagonal of `positions` (0.02:
    /// 2 % of the diagonal, [`Config::MODEL_ERROR_LIMIT`]).
    pub fn with_relative_error_limit(self, fraction: f32, positions: &[[f32; 3]]) -> Self {
        self.with_error_limit(fraction * crate::bound::bounding_diagonal(positions))
    }

    /// Checks every field; the error names the first bad one.
    pub fn validate(&self) -> Result<(), crate::Error> {
        use crate::{ConfigField as F, Error};
        let bad = |field| Err(Error::InvalidConfig { field });
        if let Target::Ratio(r) = self.target {
            if !(le(0.0, r) && le(r, 1.0)) {
                return bad(F::Target);
            }
        }
        if !le(0.0, self.max_cost) {
            return bad(F::MaxCost);
        }
        if self.max_passes == 0 {
            return bad(F::MaxPasses);
        }
        if !(finite(self.lambda) && le(0.0, self.lambda)) {
            return bad(F::Lambda);
        }
        if !(lt(0.0, self.max_normal_turn_deg) && lt(self.max_normal_turn_deg, 180.0)) {
            return bad(F::MaxNormalTurn);
        }
        if !(le(0.0, self.min_quality) && lt(self.min_quality, 1.0)) {
            return bad(F::MinQuality);
        }
        if !(finite(self.boundary_weight) && le(0.0, self.boundary_weight)) {
            return bad(F::BoundaryWeight);
        }
        if !le(0.0, self.max_error) {
            return bad(F::MaxError);
        }
        if !le(0.0, self.error_limit) {
            return bad(F::ErrorLimit);
        }
        if !(lt(0.0, self.control_angle_deg) && lt(self.control_angle_deg, 180.0)) {
            return bad(F::ControlAngle);
        }
        Ok(())
    }
}

// The configuration is checked with integer compares on the floats' bits: on a core without
// an FPU every float compare is a library call, and the integer pipeline would carry them for
// this alone.

/// Whether `x` is NaN.
const fn nan(x: f32) -> bool {
    x.to_bits() & 0x7fff_ffff > 0x7f80_0000
}

/// Whether `x` is finite.
const fn finite(x: f32) -> bool {
    x.to_bits() & 0x7fff_ffff < 0x7f80_0000
}

/// `x`'s place in `f32`'s order as an `i32`, `-0` and `+0` together (NaN excluded by callers).
const fn order(x: f32) -> i32 {
    let b = x.to_bits() as i32;
    if b < 0 {
        -(b & i32::MAX)
    } else {
        b
    }
}

/// `a <= b`, false with a NaN.
const fn le(a: f32, b: f32) -> bool {
    !nan(a) && !nan(b) && order(a) <= order(b)
}

/// `a < b`, false with a NaN.
const fn lt(a: f32, b: f32) -> bool {
    !nan(a) && !nan(b) && order(a) < order(b)
}

impl Default for Config {
    fn default() -> Self {
        Self::new()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_integer_compares_agree_with_the_float_ones() {
        let mut values = [0.0f32, -0.0, 1.0, -1.0, 180.0, 1e-45, -1e-45, 0.5, f32::MAX].to_vec();
        values.extend([
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::NAN,
            -f32::NAN,
            179.99998,
        ]);
        let mut x = 0x1234_5678u32;
        for _ in 0..2_000 {
            x ^= x << 13;
            x ^= x >> 17;
            x ^= x << 5;
            values.push(f32::from_bits(x));
        }
        for &a in &values {
            assert_eq!(nan(a), a.is_nan(), "{a}");
            assert_eq!(finite(a), a.is_finite(), "{a}");
            for &b in values.iter().take(40) {
                assert_eq!(le(a, b), a <= b, "{a} <= {b}");
                assert_eq!(lt(a, b), a < b, "{a} < {b}");
                assert_eq!(le(b, a), b <= a, "{b} <= {a}");
                assert_eq!(lt(b, a), b < a, "{b} < {a}");
            }
        }
    }
}
