//! What a run did: counts, rejections by reason, why it stopped.

/// Maximum number of passes whose triangle counts a [`Report`] keeps.
pub const PASS_LOG: usize = 32;

/// Why a candidate collapse was refused. The engine counts each in [`Rejections`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Reject {
    /// An endpoint is locked: on a non-manifold edge, a pinched fan or an inconsistently wound
    /// edge.
    Locked,
    /// An endpoint is a feature vertex (seed 004 §3.3).
    Feature,
    /// A boundary vertex would leave its boundary, or two boundary vertices are joined across
    /// the interior, or a boundary loop of three edges would close.
    Boundary,
    /// The link condition fails (seed 000 §3.2(1), first condition; Cheng/Pan/Shi): a common neighbour of both endpoints is not
    /// opposite the edge, so the collapse would pinch the surface.
    Link,
    /// The collapse would create a triangle that already exists.
    Duplicate,
    /// A remaining triangle's normal would turn by more than the configured limit.
    NormalTurn,
    /// A triangle would become zero-area or a sliver below the quality limit.
    Sliver,
    /// Two adjacent triangles would fold onto each other (normals nearly opposite).
    Fold,
    /// A control point would end farther than [`Config::max_error`](crate::Config::max_error)
    /// from every triangle of the new fan (seed 001 §3).
    Bound,
}

/// Collapses refused, by reason. A candidate is counted once per evaluation, so the figures
/// say which rule binds most, not how many distinct edges were refused.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[allow(missing_docs)]
pub struct Rejections {
    pub locked: u32,
    pub feature: u32,
    pub boundary: u32,
    pub link: u32,
    pub duplicate: u32,
    pub normal_turn: u32,
    pub sliver: u32,
    pub fold: u32,
    pub bound: u32,
}

impl Rejections {
    pub(crate) fn count(&mut self, r: Reject) {
        let c = match r {
            Reject::Locked => &mut self.locked,
            Reject::Feature => &mut self.feature,
            Reject::Boundary => &mut self.boundary,
            Reject::Link => &mut self.link,
            Reject::Duplicate => &mut self.duplicate,
            Reject::NormalTurn => &mut self.normal_turn,
            Reject::Sliver => &mut self.sliver,
            Reject::Fold => &mut self.fold,
            Reject::Bound => &mut self.bound,
        };
        *c = c.saturating_add(1);
    }

    /// All rejections together.
    pub fn total(&self) -> u32 {
        [
            self.locked,
            self.feature,
            self.boundary,
            self.link,
            self.duplicate,
            self.normal_turn,
            self.sliver,
            self.fold,
            self.bound,
        ]
        .iter()
        .fold(0u32, |a, b| a.saturating_add(*b))
    }
}

/// Why the engine stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Stop {
    /// Still running (only seen in a report taken between steps).
    Running,
    /// The target triangle count was reached.
    Target,
    /// No legal collapse is left: every remaining one is locked, feature-protected or illegal.
    NoLegalCollapse,
    /// Every remaining legal collapse costs more than `max_cost`.
    MaxCost,
    /// `max_passes` passes were run ([`Schedule::Passes`](crate::Schedule::Passes)).
    MaxPasses,
    /// The collapse log given to [`Simplifier::record_into`](crate::Simplifier::record_into)
    /// is full: the mesh is valid and every collapse made is in the log.
    LogFull,
}

/// The outcome of a simplification.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Report {
    /// Triangles handed in.
    pub triangles_in: usize,
    /// Input triangles dropped because two of their indices were equal.
    pub degenerate_dropped: usize,
    /// Input triangles dropped because an earlier triangle had the same three vertices.
    pub duplicates_dropped: usize,
    /// Triangles in the output (the prefix of the caller's buffer that holds the result).
    pub triangles_out: usize,
    /// The triangle count the engine aimed for.
    pub target_triangles: usize,
    /// Whether `triangles_out <= target_triangles`.
    pub target_reached: bool,
    /// Why it stopped.
    pub stop: Stop,
    /// Edge collapses performed (each removes one vertex).
    pub collapses: usize,
    /// Vertices that lost all their triangles.
    pub vertices_removed: usize,
    /// Vertices locked because the mesh is not a manifold around them.
    pub locked_vertices: usize,
    /// Feature vertices found by the last global classification (the start of the last pass
    /// or round).
    pub feature_vertices: usize,
    /// Passes run. For `Greedy`, rounds: the queue is refilled with fresh feature flags each
    /// time it runs empty, until a round collapses nothing.
    pub passes: u32,
    /// Triangles after each pass (the first [`PASS_LOG`] passes).
    pub pass_triangles: heapless::Vec<u32, PASS_LOG>,
    /// Refused candidate collapses by reason.
    pub rejected: Rejections,
    /// With an error bound ([`Controls`](crate::bound::Controls)):
    /// E_max of seed 001 eq. 4, the largest distance of a control point (original centroid
    /// or feature-edge vertex) to its controlled triangle, in the input's units. Never more
    /// than [`Config::max_error`](crate::Config::max_error). `None` without a bound.
    pub max_error: Option<f32>,
    /// With an error bound: E_mean of seed 001 eq. 5, `Σ dc_i·A_i / Σ A_i` over the original
    /// triangles' centroids (`A_i`: the original triangle's area), in the input's units.
    pub mean_error: Option<f32>,
}
