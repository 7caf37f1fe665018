//! Schroeder's vertex decimation as an operator of the engine ([`VertexDecimation`]): the
//! classification of a vertex, its distance criterion and the re-triangulation of its hole
//! by recursive loop splitting. The engine's removal path (`engine/remove.rs`) keys vertices
//! by [`classify`], asks [`triangulate`] for the new fan, checks it with the shared rules
//! (`legality::check_fan`) and writes it with `Mesh::replace_fan`.

use crate::index::Index;
use crate::math::{self, V3};
use crate::mesh::{flag, Mesh, NIL};

/// The largest ring a vertex may have to be removed (its valence, plus one on a boundary):
/// the hole's loop, and so every buffer of one removal, is at most this long.
pub(crate) const MAX_RING: usize = 32;

/// The default smallest aspect ratio of a split (distance of the loop's nearest vertex to the
/// split plane over the split line's length): 1/25. At 0.1 the CAD meshes (long thin fans)
/// stopped near half their triangles; at 0.01 they reach 10 % with thin triangles.
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
/// fills measured: docs/decimation.md).
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

/// Classifies `v` and measures its distance; `None` if it is never removed now (complex,
/// corner, a locked neighbour, a ring longer than [`MAX_RING`], a fan out of order or of no
/// area).
pub(crate) fn classify<L: Index, I: Index>(
    mesh: &Mesh<'_, L, I>,
    v: usize,
    op: &VertexDecimation,
) -> Option<Fan> {
    let f = mesh.flags(v);
    if f & flag::USED == 0 || f & flag::LOCKED != 0 {
        return None;
    }
    let boundary = f & flag::BOUNDARY != 0;
    let pv = mesh.p(v);
    let mut fan = Fan {
        ring: [NIL; MAX_RING],
        n: 0,
        boundary,
        normal: [0.0; 3],
        key: f32::INFINITY,
        line: None,
        ends: 0,
    };
    // Unit normals of the fan's triangles, in order.
    let mut units = [[0.0f32; 3]; MAX_RING];
    let (mut sum_n, mut sum_c, mut sum_a) = ([0.0f32; 3], [0.0f32; 3], 0.0f32);
    let mut last_y = NIL;
    let mut k = 0;
    for (t, c) in mesh.corners(v) {
        let tri = mesh.tri(t);
        let (x, y) = crate::tri::others(tri, c);
        if k > 0 && last_y != x {
            return None;
        }
        if mesh.has(x, flag::LOCKED) || mesh.has(y, flag::LOCKED) {
            return None;
        }
        *fan.ring.get_mut(k)? = x;
        let (px, py) = (mesh.p(x), mesh.p(y));
        let n = math::cross(math::sub(px, pv), math::sub(py, pv));
        let l2 = math::dot(n, n);
        let a2 = math::sqrt(l2);
        *units.get_mut(k)? = math::unit_of(n, l2);
        // Σ n(f) A(f) and Σ c(f) A(f), each area twice over (it cancels).
        sum_n = math::add(sum_n, n);
        let centroid = math::scale(math::add(pv, math::add(px, py)), 1.0 / 3.0);
        sum_c = math::add(sum_c, math::scale(centroid, a2));
        sum_a += a2;
        last_y = y;
        k += 1;
    }
    if boundary {
        *fan.ring.get_mut(k)? = last_y;
        fan.n = k + 1;
        if k < 2 {
            return None;
        }
    } else {
        fan.n = k;
        if k < 3 || fan.ring.first() != Some(&last_y) {
            return None;
        }
    }
    // A fan through one vertex twice is no disc.
    let ring = fan.ring();
    for (i, x) in ring.iter().enumerate() {
        if ring.iter().skip(i + 1).any(|y| y == x) {
            return None;
        }
    }
    let l2 = math::dot(sum_n, sum_n);
    if !(l2 > math::TINY2 && l2.is_finite() && sum_a > 0.0) {
        return None;
    }
    fan.normal = math::scale(sum_n, math::rsqrt(l2));
    // Feature spokes: spoke i (to ring[i]) lies between triangles i - 1 and i.
    let mut features = [0usize; 2];
    let mut nf = 0;
    let mut ends = 0u32;
    let mut hard = 0;
    let first_spoke = if boundary { 1 } else { 0 };
    for i in first_spoke..k {
        let before = if i == 0 { k - 1 } else { i - 1 };
        let (Some(&u), Some(&w)) = (units.get(before), units.get(i)) else {
            return None;
        };
        let cos = math::dot(u, w);
        if cos < COS_HARD {
            hard += 1;
        }
        if cos < op.cos_feature {
            ends |= 1 << i;
            if let Some(s) = features.get_mut(nf) {
                *s = i;
            }
            nf += 1;
        }
    }
    let p = |i: usize| fan.ring.get(i).map_or([0.0; 3], |&x| mesh.p(x));
    let key = match (boundary, nf) {
        // Simple: the distance to the average plane.
        (false, 0) => {
            let c = math::scale(sum_c, 1.0 / sum_a);
            let d = math::dot(fan.normal, math::sub(pv, c));
            Some(if d < 0.0 { -d } else { d })
        }
        // Interior edge: the distance to the feature line.
        (false, 2) => {
            let (i, j) = (features[0], features[1]);
            fan.line = Some((i, j));
            line_distance(pv, p(i), p(j))
        }
        // Boundary: the distance to the line through the boundary neighbours.
        (true, 0) => line_distance(pv, p(0), p(k)),
        // A dart or a corner, when the fill is measured: onto a feature spoke's end, the
        // fit deciding whether that is cheap.
        (false, _) if op.fill == Fill::Fit && hard <= 2 => {
            fan.ends = ends;
            Some(0.0)
        }
        // A boundary vertex with a feature spoke: along the boundary, measured.
        (true, _) if op.fill == Fill::Fit => Some(0.0),
        // Corner.
        _ => None,
    }?;
    if !key.is_finite() {
        return None;
    }
    fan.key = key;
    Some(fan)
}

/// Why no triangulation was found.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum NoSplit {
    /// A loop had no split line whose halves lie on their sides of its plane with at least
    /// the smallest aspect ratio.
    Aspect,
}

/// The loop positions of mask `m`, in order, into `out`; how many.
fn members(m: u32, out: &mut [u8; MAX_RING]) -> usize {
    let mut c = 0;
    for i in 0..MAX_RING {
        if m >> i & 1 != 0 {
            if let Some(s) = out.get_mut(c) {
                *s = i as u8;
            }
            c += 1;
        }
    }
    c
}

/// The squared aspect ratio of splitting loop `l` (positions into `pos`) along `l[x]`-`l[y]`
/// (`x < y`, not neighbours) with the split plane through the line and `normal`: `None` if
/// the halves do not lie strictly on their own sides (the inner half, `l[x+1..y]`, on the
/// right of the line seen from `normal`, the outer half on the left).
fn split_aspect2(l: &[u8], pos: &[V3; MAX_RING], normal: V3, x: usize, y: usize) -> Option<f32> {
    let at = |i: usize| {
        l.get(i)
            .and_then(|&k| pos.get(k as usize))
            .copied()
            .unwrap_or([0.0; 3])
    };
    let (a, b) = (at(x), at(y));
    let e = math::sub(b, a);
    let s = math::cross(e, normal);
    let (l2, s2) = (math::dot(e, e), math::dot(s, s));
    if !(l2 > math::TINY2 && s2 > math::TINY2 && l2.is_finite() && s2.is_finite()) {
        return None;
    }
    let mut least = f32::INFINITY;
    for i in 0..l.len() {
        if i == x || i == y {
            continue;
        }
        let d = math::dot(s, math::sub(at(i), a));
        let inner = x < i && i < y;
        // `cross(e, normal)` points to the right of the line, where a counter-clockwise
        // loop's inner half lies.
        if (inner && d <= 0.0) || (!inner && d >= 0.0) {
            return None;
        }
        let d2 = d * d;
        if d2 < least {
            least = d2;
        }
    }
    // (distance to the plane / length)² = (d / |s|)² / |e|².
    Some(least / s2 / l2)
}

/// The unit normal of loop `l` (positions into `pos`): its vector area (Newell), `None` if
/// it has none.
fn loop_normal(l: &[u8], pos: &[V3; MAX_RING]) -> Option<V3> {
    let at = |k: u8| pos.get(k as usize).copied().unwrap_or([0.0; 3]);
    let mut sum = [0.0f32; 3];
    let mut prev = l.last().map(|&k| at(k))?;
    for &k in l {
        let p = at(k);
        sum = math::add(sum, math::cross(prev, p));
        prev = p;
    }
    let l2 = math::dot(sum, sum);
    (l2 > math::TINY2 && l2.is_finite()).then(|| math::scale(sum, math::rsqrt(l2)))
}

/// Triangulates `fan`'s loop (positions `pos`, normalised, in ring order) by recursive loop
/// splitting (see [`VertexDecimation`]) into `out` as triples of ring positions, each in loop
/// order (so wound as the fan was), and each triangle's reference plane normal into `planes`:
/// the fan's average plane, or for an interior-edge vertex the plane of its half of the loop
/// (each side of the feature line is a surface of its own). Returns how many (`n − 2`).
pub(crate) fn triangulate(
    fan: &Fan,
    pos: &[V3; MAX_RING],
    min_aspect: f32,
    out: &mut [[u8; 3]; MAX_RING],
    planes: &mut [V3; MAX_RING],
) -> Result<usize, NoSplit> {
    let n = fan.n;
    if !(3..=MAX_RING).contains(&n) {
        return Err(NoSplit::Aspect);
    }
    let full = if n == 32 { u32::MAX } else { (1u32 << n) - 1 };
    let min2 = min_aspect * min_aspect;
    // Loops still to split, with their planes: each split makes two from one, and there are
    // n - 2 triangles.
    let mut stack = [(0u32, [0.0f32; 3]); MAX_RING];
    let mut sp = 0;
    if let Some(s) = stack.get_mut(sp) {
        *s = (full, fan.normal);
        sp += 1;
    }
    let mut made = 0;
    let mut l = [0u8; MAX_RING];
    while sp > 0 {
        sp -= 1;
        let (m, normal) = stack.get(sp).copied().unwrap_or((0, [0.0; 3]));
        let c = members(m, &mut l);
        let lp = l.get(..c).unwrap_or(&[]);
        if c == 3 {
            let (Some(slot), Some(plane)) = (out.get_mut(made), planes.get_mut(made)) else {
                return Err(NoSplit::Aspect);
            };
            *slot = [l[0], l[1], l[2]];
            *plane = normal;
            made += 1;
            continue;
        }
        if c < 3 {
            return Err(NoSplit::Aspect);
        }
        // The best split: the feature line first for an interior-edge vertex.
        let mut best: Option<(f32, usize, usize)> = None;
        let forced = match fan.line {
            Some((i, j)) if m == full => lp
                .iter()
                .position(|&k| k as usize == i)
                .zip(lp.iter().position(|&k| k as usize == j)),
            _ => None,
        };
        if let Some((x, y)) = forced {
            let (x, y) = if x < y { (x, y) } else { (y, x) };
            if let Some(a2) = split_aspect2(lp, pos, normal, x, y) {
                best = Some((a2, x, y));
            }
        } else {
            for x in 0..c {
                for y in x + 2..c {
                    if x == 0 && y == c - 1 {
                        continue;
                    }
                    if let Some(a2) = split_aspect2(lp, pos, normal, x, y) {
                        if best.is_none_or(|b| a2 > b.0) {
                            best = Some((a2, x, y));
                        }
                    }
                }
            }
        }
        let Some((a2, x, y)) = best else {
            return Err(NoSplit::Aspect);
        };
        if a2 < min2 {
            return Err(NoSplit::Aspect);
        }
        let (Some(&kx), Some(&ky)) = (lp.get(x), lp.get(y)) else {
            return Err(NoSplit::Aspect);
        };
        // Inner half: positions kx..=ky of the mask; outer: the rest and both ends.
        let span = if ky as usize >= 31 {
            u32::MAX
        } else {
            (1u32 << (ky as u32 + 1)) - 1
        } & !((1u32 << kx) - 1);
        let inner = m & span;
        let outer = (m & !span) | (1u32 << kx) | (1u32 << ky);
        for h in [inner, outer] {
            // The feature line's halves take their own planes.
            let plane = if forced.is_some() {
                let mut hl = [0u8; MAX_RING];
                let hc = members(h, &mut hl);
                loop_normal(hl.get(..hc).unwrap_or(&[]), pos).ok_or(NoSplit::Aspect)?
            } else {
                normal
            };
            let s = stack.get_mut(sp).ok_or(NoSplit::Aspect)?;
            *s = (h, plane);
            sp += 1;
        }
    }
    if made + 2 == n {
        Ok(made)
    } else {
        Err(NoSplit::Aspect)
    }
}

/// The area-weighted squared distance from `pv` to the planes of the new triangles `tris`
/// (ring positions into `pos`): `Σ (n·(pv − a))² / |n|`, `n` a triangle's unnormalised
/// normal (twice its area); the new triangles' total of `|n|`; and the largest squared
/// distance from `pv` to one of their planes.
fn fit2(pv: V3, pos: &[V3; MAX_RING], tris: &[[u8; 3]]) -> (f32, f32, f32) {
    let at = |k: u8| pos.get(k as usize).copied().unwrap_or([0.0; 3]);
    let (mut e, mut area2, mut far2) = (0.0f32, 0.0f32, 0.0f32);
    for t in tris {
        let a = at(t[0]);
        let n = math::cross(math::sub(at(t[1]), a), math::sub(at(t[2]), a));
        let l2 = math::dot(n, n);
        let l = math::sqrt(l2);
        if l > 0.0 {
            let d = math::dot(n, math::sub(pv, a));
            e += d * d / l;
            area2 += l;
            let d2 = d * d / l2;
            if d2 > far2 {
                far2 = d2;
            }
        }
    }
    (e, area2, far2)
}

/// `x` modulo `n` for `x < 2n`: a ring position past the end wraps once. No division (the
/// Cortex-M0 has none, and a remainder by a length the compiler cannot prove nonzero keeps a
/// panic path).
#[inline]
fn wrap(x: usize, n: usize) -> usize {
    if x >= n {
        x - n
    } else {
        x
    }
}

/// The fan of ring position `i` over `fan`'s loop: triangles `(i, j, j + 1)` around the loop
/// (the half-edge collapse of the removed vertex onto `ring[i]`), each rotated to loop order,
/// into `out`; how many. A boundary loop is open: only its ends have a fan.
fn ring_fan(fan: &Fan, i: usize, out: &mut [[u8; 3]; MAX_RING]) -> usize {
    let n = fan.n;
    let mut made = 0;
    for j in 1..n.saturating_sub(1) {
        let (b, c) = (wrap(i + j, n), wrap(i + j + 1, n));
        // Three ring positions in cyclic order from `i`, rotated so the smallest leads.
        let t = [i as u8, b as u8, c as u8];
        let r = if t[1] < t[0] && t[1] < t[2] {
            [t[1], t[2], t[0]]
        } else if t[2] < t[0] && t[2] < t[1] {
            [t[2], t[0], t[1]]
        } else {
            t
        };
        if let Some(s) = out.get_mut(made) {
            *s = r;
            made += 1;
        }
    }
    made
}

/// The new fan of `fan` (the removed vertex at `pv`, the ring at `pos`) into `out` and
/// `planes` (as [`triangulate`]) and its key: with [`Fill::Shape`] the loop splitting and
/// Schroeder's distance; with [`Fill::Fit`] the best-fitting of the loop splitting and the
/// ring's fans (ties: the loop splitting, then the lower ring position) and its fit.
pub(crate) fn plan(
    fan: &Fan,
    pv: V3,
    pos: &[V3; MAX_RING],
    op: &VertexDecimation,
    reference: f32,
    out: &mut [[u8; 3]; MAX_RING],
    planes: &mut [V3; MAX_RING],
) -> Result<(usize, f32, f32), NoSplit> {
    let split = if fan.ends != 0 {
        Err(NoSplit::Aspect)
    } else {
        triangulate(fan, pos, op.min_aspect, out, planes)
    };
    if op.fill == Fill::Shape {
        return split.map(|n| (n, fan.key, fan.key * fan.key));
    }
    let n = fan.n;
    // A boundary vertex's fill loses its place on the boundary: its distance to the new
    // boundary edge, over the new area.
    let retreat2 = if fan.boundary {
        let (a, b) = (
            pos.first().copied().unwrap_or([0.0; 3]),
            pos.get(n.saturating_sub(1)).copied().unwrap_or([0.0; 3]),
        );
        math::segment_distance2(pv, a, b)
    } else {
        0.0
    };
    // The old fan's area (twice), for the thin-part factor of the memoryless quadric:
    // `1 + Ā / A_fan` (`cost::Quadric`), so that small fans are not cheap however far
    // their vertex stands out.
    let mut old2 = 0.0f32;
    let closed = if fan.boundary { n.saturating_sub(1) } else { n };
    for k in 0..closed {
        let (a, b) = (
            pos.get(k).copied().unwrap_or(pv),
            pos.get(wrap(k + 1, n)).copied().unwrap_or(pv),
        );
        let c = math::cross(math::sub(a, pv), math::sub(b, pv));
        old2 += math::sqrt(math::dot(c, c));
    }
    let thin = if old2 > 0.0 {
        1.0 + reference / old2
    } else {
        1.0
    };
    // The fit, and the removal's own error (squared): its distance to the farthest new
    // plane, or the boundary's retreat.
    let price = |tris: &[[u8; 3]]| {
        let (e, area2, far2) = fit2(pv, pos, tris);
        let err2 = if far2 > retreat2 { far2 } else { retreat2 };
        ((e + retreat2 * area2) * thin, err2)
    };
    let best = match split {
        Ok(k) => {
            let (e, err2) = price(out.get(..k).unwrap_or(&[]));
            Some((e, k, err2))
        }
        Err(_) => None,
    };
    // The two halves' planes of a feature line (each side a surface of its own).
    let halves = match fan.line {
        Some((i, j)) => {
            let (i, j) = if i < j { (i, j) } else { (j, i) };
            let mut inner = [0u8; MAX_RING];
            let mut outer = [0u8; MAX_RING];
            let (mut ni, mut no) = (0, 0);
            for k in 0..n {
                if (i..=j).contains(&k) {
                    if let Some(s) = inner.get_mut(ni) {
                        *s = k as u8;
                        ni += 1;
                    }
                }
                if k <= i || k >= j {
                    if let Some(s) = outer.get_mut(no) {
                        *s = k as u8;
                        no += 1;
                    }
                }
            }
            let a = loop_normal(inner.get(..ni).unwrap_or(&[]), pos);
            let b = loop_normal(outer.get(..no).unwrap_or(&[]), pos);
            match (a, b) {
                (Some(a), Some(b)) => Some((i, j, a, b)),
                _ => {
                    return split.map(|k| {
                        let (e, err2) = price(out.get(..k).unwrap_or(&[]));
                        (k, e, err2)
                    })
                }
            }
        }
        None => None,
    };
    let mut cand = [[0u8; 3]; MAX_RING];
    let mut best_fan: Option<(f32, usize, f32)> = None;
    for i in 0..n {
        let allowed = match (fan.boundary, halves) {
            _ if fan.ends != 0 => fan.ends >> i & 1 != 0,
            (true, _) => i == 0 || i + 1 == n,
            (false, Some((a, b, _, _))) => i == a || i == b,
            (false, None) => true,
        };
        if !allowed {
            continue;
        }
        let k = ring_fan(fan, i, &mut cand);
        let (e, err2) = price(cand.get(..k).unwrap_or(&[]));
        let least = match (best, best_fan) {
            (_, Some((f, _, _))) => f,
            (Some((s, _, _)), None) => s,
            (None, None) => f32::INFINITY,
        };
        if e < least || (least == f32::INFINITY && best_fan.is_none() && best.is_none()) {
            best_fan = Some((e, i, err2));
        }
    }
    if let Some((e, i, err2)) = best_fan {
        let k = ring_fan(fan, i, out);
        // Each new triangle (i, b, b + 1) takes the place of the old (v, b, b + 1): its
        // normal is the reference, as for the collapse's own normal rules.
        for (j, p) in planes.iter_mut().enumerate().take(k) {
            let b = wrap(i + j + 1, n);
            let (pb, pc) = (
                pos.get(b).copied().unwrap_or(pv),
                pos.get(wrap(b + 1, n)).copied().unwrap_or(pv),
            );
            let c = math::cross(math::sub(pb, pv), math::sub(pc, pv));
            let l2 = math::dot(c, c);
            *p = if l2 > math::TINY2 && l2.is_finite() {
                math::scale(c, math::rsqrt(l2))
            } else {
                fan.normal
            };
        }
        return Ok((k, e, err2));
    }
    match best {
        Some((e, k, err2)) => Ok((k, e, err2)),
        None => Err(NoSplit::Aspect),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fan_of(p: &[V3]) -> (Fan, [V3; MAX_RING]) {
        let mut pos = [[0.0; 3]; MAX_RING];
        let mut ring = [NIL; MAX_RING];
        for (i, q) in p.iter().enumerate() {
            pos[i] = *q;
            ring[i] = i;
        }
        (
            Fan {
                ring,
                n: p.len(),
                boundary: false,
                normal: [0.0, 0.0, 1.0],
                key: 0.0,
                line: None,
                ends: 0,
            },
            pos,
        )
    }

    /// Signed doubled area of a triangle of ring positions, seen from +z.
    fn area_z(pos: &[V3; MAX_RING], t: [u8; 3]) -> f32 {
        let [a, b, c] = t.map(|k| pos[k as usize]);
        (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
    }

    /// Concave loops (an L, a star, counter-clockwise): every triangle the splitting makes
    /// faces +z and they tile the loop. Fails if the side test of the split plane is dropped
    /// (a star's triangle then faces −z) or if the aspect ratio stops choosing (a hexagon's
    /// triangles are then not the widest splits').
    #[test]
    fn concave_loops_split_inside() {
        let p = [
            [0.0, 0.0, 0.0],
            [4.0, 0.0, 0.0],
            [4.0, 1.0, 0.0],
            [1.0, 1.0, 0.0],
            [1.0, 4.0, 0.0],
            [0.0, 4.0, 0.0],
        ];
        let (fan, pos) = fan_of(&p);
        let mut out = [[0u8; 3]; MAX_RING];
        let mut planes = [[0.0f32; 3]; MAX_RING];
        let n = triangulate(&fan, &pos, 0.1, &mut out, &mut planes).expect("a split");
        assert_eq!(n, 4);
        let total: f32 = out[..n].iter().map(|&t| area_z(&pos, t)).sum();
        for &t in &out[..n] {
            assert!(area_z(&pos, t) > 0.0, "{t:?} faces away");
        }
        // The pieces tile the loop exactly (no overlap, nothing outside).
        let mut shoelace = 0.0;
        for i in 0..p.len() {
            let (a, b) = (p[i], p[(i + 1) % p.len()]);
            shoelace += a[0] * b[1] - a[1] * b[0];
        }
        assert!((total - shoelace).abs() < 1e-4, "{total} vs {shoelace}");
        // The widest split first: in this hexagon 2-5 (aspect 0.45, then 1-4 at 0.42), then
        // 1-5 and 2-4 in the halves; taking the first valid split instead gives a fan from 0.
        let hex = [
            [2.0, 0.0, 0.0],
            [1.2, 1.5, 0.0],
            [-0.8, 1.6, 0.0],
            [-2.0, 0.2, 0.0],
            [-1.0, -1.4, 0.0],
            [1.0, -1.3, 0.0],
        ];
        let (fan, pos) = fan_of(&hex);
        let n = triangulate(&fan, &pos, 0.1, &mut out, &mut planes).expect("a split");
        let mut got = out[..n].to_vec();
        got.sort();
        assert_eq!(got, [[0, 1, 5], [1, 2, 5], [2, 3, 4], [2, 4, 5]]);
        // A star whose widest chord (1-3, around the notch at 2) leaves the loop: without
        // the side test it is taken and a triangle faces −z.
        let star = [
            [-0.4, 1.8, 0.0],
            [-0.3, 0.0, 0.0],
            [-0.8, -0.2, 0.0],
            [-0.2, -1.5, 0.0],
            [0.2, -0.7, 0.0],
            [1.0, -1.3, 0.0],
            [0.5, 0.0, 0.0],
        ];
        let (fan, pos) = fan_of(&star);
        let n = triangulate(&fan, &pos, 0.1, &mut out, &mut planes).expect("a split");
        assert_eq!(n, 5);
        for &t in &out[..n] {
            assert!(area_z(&pos, t) > 0.0, "{t:?} faces away");
        }
        // Below the aspect limit: refused.
        let thin = [
            [0.0, 0.0, 0.0],
            [10.0, 0.0, 0.0],
            [10.0, 0.2, 0.0],
            [0.0, 0.2, 0.0],
        ];
        let (fan, pos) = fan_of(&thin);
        assert_eq!(
            triangulate(&fan, &pos, 0.1, &mut out, &mut planes),
            Err(NoSplit::Aspect)
        );
        assert!(triangulate(&fan, &pos, 0.0, &mut out, &mut planes).is_ok());
    }

    /// A vertex on a fold (two planes meeting along the line through ring positions 0 and 3):
    /// the fan from 0 keeps both planes exactly, so the fitted fill takes it at no cost, while
    /// the loop splitting, chosen for shape, crosses the fold. Fails if the ring's fans are
    /// not candidates or the fill is not chosen by fit.
    #[test]
    fn the_fitted_fill_keeps_a_fold() {
        let p = [
            [2.0, 0.0, 0.0],
            [1.0, 1.5, 1.5],
            [-1.0, 1.5, 1.5],
            [-2.0, 0.0, 0.0],
            [-1.0, -1.5, 0.0],
            [1.0, -1.5, 0.0],
        ];
        let (mut fan, pos) = fan_of(&p);
        fan.normal = math::scale([0.0, -1.0, 1.0 + 2.0f32.sqrt()], 1.0 / 2.613_126);
        let pv = [0.0, 0.0, 0.0];
        let mut out = [[0u8; 3]; MAX_RING];
        let mut planes = [[0.0f32; 3]; MAX_RING];
        let op = VertexDecimation::new();
        let (n, key, _) = plan(&fan, pv, &pos, &op, 0.0, &mut out, &mut planes).expect("a fill");
        assert_eq!(n, 4);
        assert!(key.abs() < 1e-6, "{key}");
        for t in &out[..n] {
            assert!(t.contains(&0), "{t:?} is not the fan from 0");
        }
        let shape = op.with_fill(Fill::Shape);
        let (n, _, _) = plan(&fan, pv, &pos, &shape, 0.0, &mut out, &mut planes).expect("a split");
        let (e, _, _) = fit2(pv, &pos, &out[..n]);
        assert!(e > 1e-3, "the loop splitting fits too: {e}");
    }
}
