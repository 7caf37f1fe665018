//! Schroeder's vertex decimation as an operator of the engine ([`VertexDecimation`]): the
//! classification of a vertex, its distance criterion and the re-triangulation of its hole
//! by recursive loop splitting. The engine's removal path (`engine/remove.rs`) keys vertices
//! by [`classify`], asks [`triangulate`] for the new fan, checks it with the shared rules
//! (`legality::check_fan`) and writes it with `Mesh::replace_fan`.

mod classify;
#[cfg(test)]
mod tests;
mod triangulate;

pub(crate) use classify::classify;
pub(crate) use triangulate::plan;

use crate::math::{self, V3};

/// The largest ring a vertex may have to be removed (its valence, plus one on a boundary):
/// the hole's loop, and so every buffer of one removal, is at most this long. The mesh's
/// bound on a replaced fan, so that every planned fan can be written.
pub(crate) const MAX_RING: usize = crate::mesh::MAX_FAN;

/// The default smallest aspect ratio of a split (distance of the loop's nearest vertex to the
/// split plane over the split line's length): 1/25, between a limit that stops the CAD meshes'
/// long thin fans short of their target and one that lets them reach it with thin triangles
/// (docs/decimation.md).
const MIN_ASPECT: f32 = 0.04;
/// cos 60°: with [`Fill::Fit`], a vertex with more than two spokes sharper than this is a
/// corner (a CAD model's corner); softer ones (a coarse organic mesh has many) may move.
const COS_HARD: f32 = 0.5;

/// Vertex decimation (Schroeder, Zarge and Lorensen 1992): a vertex is removed with its
/// triangles, and the hole is filled by triangulating the loop of its neighbours.
///
/// The survey of mesh simplification (a Chinese blog post, "图形学——网格简化"), section
/// "基于相邻面片和边界的局部平坦性原则" (local flatness from the adjacent faces and the
/// boundary, among its vertex-removal methods), gives the criterion: for an interior vertex
/// `v` with fan `S`, the distance `d = |N · (v − C)|` to the average plane, `N` the unit
/// vector of the area-weighted mean of the faces' normals and `C` the area-weighted mean of
/// their centroids (the post divides by `A(f)`; read as `Σ A(f)`); for a boundary vertex, its
/// distance to the line through its two boundary neighbours. The classification and the
/// loop splitting are the paper's (the seed does not describe them):
///
/// * **complex** (non-manifold, pinched or inconsistently wound: the engine's locked
///   vertices) and vertices with a locked neighbour are never removed;
/// * a spoke is a **feature edge** when the normals of its two triangles differ by more than
///   the feature angle ([`VertexDecimation::with_feature_angle`], 30° by default; when a round
///   of the queue removes nothing it grows by 15° up to 60°,
///   [`VertexDecimation::with_feature_growth`], so that coarse meshes reach their targets);
/// * **simple** (interior, no feature edge): distance to the average plane;
/// * **boundary** (no feature edge among its interior spokes): distance to the line through
///   its two boundary neighbours;
/// * **interior edge** (interior, exactly two feature edges): distance to the line through
///   their other ends, and the hole is first split along that line, so the feature line stays;
/// * **corner** (one or more than two feature edges, or a boundary vertex with one): never
///   removed.
///
/// Order: the greedy queue, smallest distance first (ties by vertex index); `Config::max_cost`
/// is Schroeder's threshold (no removal farther than it), the target count the stop.
///
/// That is [`Fill::Shape`], the paper as written. The default, [`Fill::Fit`], keeps the
/// classification and the loop splitting but chooses the fill by how well it fits: the
/// candidates are the loop splitting's triangulation and the ring's fans (the fan from one
/// ring vertex to the rest of the loop, which is the half-edge collapse of the removed vertex
/// onto it), the fit of each is the area-weighted squared distance from the removed vertex to
/// the planes of the new triangles (plus, on a boundary, its squared distance to the new
/// boundary edge times their area), times the memoryless quadric's thin-part factor
/// `1 + Ā / A_fan`, and the key is the best fit. Feature lines restrict the fans to those from
/// the ends of feature spokes (a dart or a soft corner moves along one of its feature lines; an
/// interior-edge vertex along its line), and only a vertex with more than two spokes sharper
/// than 60° is a corner that never goes. Schroeder's distance orders by shape alone and the
/// loop splitting fills for shape alone, so error piles up where vertices go in turn (both
/// fills: docs/decimation.md, its decision records).
///
/// Triangulation: recursive loop splitting. A split line joins two loop vertices that are not
/// neighbours; its split plane holds the line and the average plane's normal. A split is
/// valid when the two halves of the loop lie strictly on opposite sides of the plane (each on
/// its own side, so no triangle turns over in the average plane), and its aspect ratio is the
/// nearest vertex's distance to the plane over the line's length; the valid split with the
/// largest ratio is taken (ties: the first in loop order) if its ratio is at least the minimum
/// ([`VertexDecimation::with_min_aspect`], 0.04 by default), and each half is split again
/// until it is a triangle. The halves of an interior-edge vertex's loop (split along its
/// feature line) are split against their own planes (their loops' vector areas), each side of
/// the line being a surface of its own. No split: the vertex stays until its fan changes.
/// The loop is at most 32 vertices long (a vertex of higher valence stays), so every buffer
/// is fixed.
///
/// The new fan then passes the same hard rules as a collapse (`legality::check_fan`): no
/// diagonal (or a boundary vertex's new boundary edge) that is already an edge, no new
/// triangle that already exists, none of zero area, none facing away from the average plane
/// or turned from it past `Config::max_normal_turn_deg`, and no fold against the triangles
/// across the loop or between the new ones. The `k` triangles of the fan are replaced by
/// `k − 2` (`k − 1` on a boundary) written into the first of their own slots: fixed memory,
/// triangles in the caller's buffer, positions only read.
///
/// [`Config::error_limit`](crate::Config::error_limit) refuses a removal whose own error is
/// over it: the removed vertex's distance to the farthest plane of its new triangles, or how
/// far the boundary retreats ([`Fill::Shape`]: Schroeder's distance); such a vertex waits until
/// its fan changes, and a run that ends short because of such refusals stops with
/// [`Stop::ErrorLimit`](crate::Stop::ErrorLimit).
///
/// Greedy schedule only, without an error bound, welded seams or a collapse log (none of
/// these can describe a removal): [`Storage::start`](crate::Storage::start) refuses the first
/// two with [`ConfigField::Operator`](crate::ConfigField::Operator); a welded run removes
/// nothing (every candidate counts as a `seam` refusal) and a logged one stops at once with
/// [`Stop::LogFull`](crate::Stop::LogFull). The report's `collapses` counts removals.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct VertexDecimation {
    /// The feature angle now, degrees.
    pub(crate) feature_deg: f32,
    /// Its cosine.
    pub(crate) cos_feature: f32,
    /// How much it grows when a round removes nothing, degrees.
    pub(crate) step_deg: f32,
    /// The most it grows to, degrees.
    pub(crate) max_deg: f32,
    /// Smallest aspect ratio of a split.
    pub(crate) min_aspect: f32,
    /// How the hole is filled and the vertex keyed.
    pub(crate) fill: Fill,
}

/// How [`VertexDecimation`] fills a vertex's hole and orders the vertices.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Fill {
    /// Schroeder's as written: recursive loop splitting chosen for shape (aspect ratio),
    /// vertices ordered by their distance to the average plane (or boundary or feature line).
    Shape,
    /// The default: of the loop splitting's triangulation and the ring's fans (the fan from
    /// a ring vertex to the rest of the loop: from either end of a boundary or feature line,
    /// from any ring vertex of a simple vertex), the one that fits the removed vertex best,
    /// and vertices ordered by that fit: the area-weighted squared distance from the removed
    /// vertex to the planes of the new triangles, plus on a boundary its squared distance to
    /// the new boundary edge times the new area. `Config::max_cost` bounds that fit.
    Fit,
}

/// An angle in degrees clamped to `[0, 180]` (NaN: 0).
fn clamp_deg(deg: f32) -> f32 {
    if deg > 180.0 {
        180.0
    } else if deg > 0.0 {
        deg
    } else {
        0.0
    }
}

impl VertexDecimation {
    /// Feature angle 30°, growing by 15° up to 60° when a round removes nothing; smallest
    /// split aspect ratio 0.04; the best-fitting fill ([`Fill::Fit`]).
    pub const fn new() -> Self {
        VertexDecimation {
            feature_deg: 30.0,
            // cos 30°.
            cos_feature: 0.866_025_4,
            step_deg: 15.0,
            max_deg: 60.0,
            min_aspect: MIN_ASPECT,
            fill: Fill::Fit,
        }
    }

    /// How the hole is filled and the vertices ordered ([`Fill::Fit`] by default).
    pub fn with_fill(mut self, fill: Fill) -> Self {
        self.fill = fill;
        self
    }

    /// A spoke whose two triangles' normals differ by more than `deg` degrees (clamped to
    /// `[0, 180]`) is a feature edge.
    pub fn with_feature_angle(mut self, deg: f32) -> Self {
        self.feature_deg = clamp_deg(deg);
        self.cos_feature = math::cos_deg(self.feature_deg);
        self
    }

    /// When a round of the queue removes nothing, the feature angle grows by `step` degrees,
    /// up to `max` (as the original implementation's feature-angle increment and maximum):
    /// corners and interior-edge vertices of the smaller angle become removable. A step of 0
    /// (or a maximum at or below the angle) keeps the angle fixed.
    pub fn with_feature_growth(mut self, step: f32, max: f32) -> Self {
        self.step_deg = clamp_deg(step);
        self.max_deg = clamp_deg(max);
        self
    }

    /// The smallest aspect ratio a split may have (0 accepts any split whose halves lie on
    /// their sides; negative values count as 0).
    pub fn with_min_aspect(mut self, ratio: f32) -> Self {
        self.min_aspect = if ratio > 0.0 { ratio } else { 0.0 };
        self
    }

    /// Grows the feature angle by a step (see [`Self::with_feature_growth`]); `false` if it
    /// is at its maximum already.
    pub(crate) fn grow(&mut self) -> bool {
        if !(self.step_deg > 0.0 && self.feature_deg < self.max_deg) {
            return false;
        }
        let next = self.feature_deg + self.step_deg;
        self.feature_deg = if next < self.max_deg {
            next
        } else {
            self.max_deg
        };
        self.cos_feature = math::cos_deg(self.feature_deg);
        true
    }
}

impl Default for VertexDecimation {
    fn default() -> Self {
        Self::new()
    }
}

/// A removable vertex's fan, classified.
pub(crate) struct Fan {
    /// The loop of neighbours in fan order (a boundary fan: from the first triangle's `a` to
    /// the last one's `b`).
    pub(crate) ring: [usize; MAX_RING],
    /// Its length.
    pub(crate) n: usize,
    /// A boundary vertex (the loop's closing edge, last to first, becomes a boundary edge).
    pub(crate) boundary: bool,
    /// The average plane's unit normal.
    pub(crate) normal: V3,
    /// Schroeder's distance (normalised units).
    pub(crate) key: f32,
    /// An interior-edge vertex: the ring positions of its two feature spokes' ends.
    pub(crate) line: Option<(usize, usize)>,
    /// With [`Fill::Fit`], an interior vertex with one or more than two feature spokes: the
    /// ring positions of their ends (bits), the only fans that keep a feature line where it was.
    pub(crate) ends: u32,
}

impl Fan {
    /// The loop's vertices.
    pub(crate) fn ring(&self) -> &[usize] {
        self.ring.get(..self.n).unwrap_or(&[])
    }
}

/// Distance from `p` to the line through `a` and `b`; `None` if `a` and `b` coincide.
fn line_distance(p: V3, a: V3, b: V3) -> Option<f32> {
    let e = math::sub(b, a);
    let l2 = math::dot(e, e);
    if !(l2 > math::TINY2 && l2.is_finite()) {
        return None;
    }
    let c = math::cross(math::sub(p, a), e);
    Some(math::sqrt(math::dot(c, c) / l2))
}
