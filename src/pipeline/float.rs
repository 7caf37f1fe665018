//! float: the pipeline's geometry in `f32`, in the unit frame (meshoptimizer's
//! `rescalePositions`: the bounding box's corner at the origin, the extent scaled by a power of
//! two into `[1, 2)`), every function through `crate::math`.
//!
//! Quadrics (fill): each triangle's plane quadric weighted by its area, added at its three
//! vertices; for each border edge a plane through the edge perpendicular to its triangle,
//! weighted by the edge's length times 10, plus the triangle's plane at 10 times its weight,
//! added at both ends, so that borders keep their shape (meshoptimizer's `fillFaceQuadrics`
//! and `fillEdgeQuadrics`); with wedges, at each seam vertex a plane through each seam spoke
//! on each side. The planes are Garland's, as Cheng, Pan and Shi 1998 use them (§2.3, eq. 3).
//! Every quadric is in its vertex's frame, where each of its planes passes through the
//! origin: its offset terms are zero, exactly, so a [`PointQuadric`] (the 3×3 part, 24 bytes)
//! holds it, and a collapse within a flat patch prices at zero, not at rounding.

use super::geometry::{Float, Geometry, Goal};
use super::{fan, flag, flags_of, link, others, tri, Arithmetic, BINS};
use crate::error::Error;
use crate::index::Index;
use crate::legality::Reject;
use crate::math::{self, V3};
use crate::quadric::{point_add, point_error, point_plane, point_weight, PointQuadric};

/// The float frame: the positions and the unit frame's corner and scale.
#[derive(Clone, Copy)]
pub struct Frame<'p> {
    pub(super) positions: &'p [[f32; 3]],
    pub(super) min: V3,
    pub(super) scale: f32,
}

impl Arithmetic for Float {
    type Position = [f32; 3];
    type Stored = PointQuadric;
    const EMPTY: PointQuadric = [0.0; 6];
    type Frame<'p> = Frame<'p>;

    #[inline(always)]
    fn frame<'p, I: Index>(
        positions: &'p [[f32; 3]],
        triangles: &[[I; 3]],
        capacity: (usize, usize),
        used: &mut [u8],
    ) -> Result<Frame<'p>, Error> {
        validate(positions, triangles, capacity, used)
    }
}

/// Checks capacities, indices and the positions the triangles use, and measures their
/// bounding box (the unit frame). Writes only `used` (scratch: the flag bytes, which classify
/// rewrites).
#[inline(never)]
fn validate<'p, I: Index>(
    positions: &'p [[f32; 3]],
    triangles: &[[I; 3]],
    (vertices, capacity): (usize, usize),
    used: &mut [u8],
) -> Result<Frame<'p>, Error> {
    super::build::fits((positions.len(), triangles.len()), (vertices, capacity))?;
    // Each used vertex's position is read once (marked in its flag byte), not once per
    // corner; the first bad index or coordinate in corner order, which the error names, is
    // searched for only when there is one (`x * 0.0` is zero exactly when `x` is finite).
    let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
    let (mut bad, mut inf) = (true, 0.0f32);
    if let Some(used) = used.get_mut(..positions.len()) {
        used.fill(0);
        bad = false;
        for tr in triangles {
            for &i in tr {
                match used.get_mut(i.to_usize()) {
                    Some(u) => *u = 1,
                    None => bad = true,
                }
            }
        }
        for (p, _) in positions.iter().zip(used.iter()).filter(|(_, &u)| u != 0) {
            for ((&x, l), h) in p.iter().zip(lo.iter_mut()).zip(hi.iter_mut()) {
                inf += x * 0.0;
                if x < *l {
                    *l = x;
                }
                if x > *h {
                    *h = x;
                }
            }
        }
    }
    // A zero bound may have come from a -0.0 or a 0.0: the corner order decides, as it did.
    if bad || inf != 0.0 || lo.contains(&0.0) || hi.contains(&0.0) {
        (lo, hi) = in_order(positions, triangles)?;
    }
    let mut extent = 0.0f32;
    for (l, h) in lo.iter().zip(hi.iter()) {
        let d = h - l;
        if d > extent {
            extent = d;
        }
    }
    if !lo[0].is_finite() {
        lo = [0.0; 3];
    }
    Ok(Frame {
        positions,
        min: lo,
        scale: crate::math::pow2_inverse(extent),
    })
}

/// The bounding box of the positions the triangles use, measured corner by corner, or the
/// first bad index or non-finite coordinate.
#[cold]
fn in_order<I: Index>(
    positions: &[[f32; 3]],
    triangles: &[[I; 3]],
) -> Result<([f32; 3], [f32; 3]), Error> {
    let mut lo = [f32::INFINITY; 3];
    let mut hi = [f32::NEG_INFINITY; 3];
    for (t, tr) in triangles.iter().enumerate() {
        for &i in tr {
            let v = i.to_usize();
            let Some(p) = positions.get(v) else {
                return Err(Error::IndexOutOfRange {
                    triangle: t,
                    index: v,
                });
            };
            for ((&x, l), h) in p.iter().zip(lo.iter_mut()).zip(hi.iter_mut()) {
                if !x.is_finite() {
                    return Err(Error::NonFinitePosition { vertex: v });
                }
                if x < *l {
                    *l = x;
                }
                if x > *h {
                    *h = x;
                }
            }
        }
    }
    Ok((lo, hi))
}

/// meshoptimizer's `kEdgeWeightBorder`.
const BORDER_WEIGHT: f32 = 10.0;

/// A seam spoke's plane weight on each of its two sides (against [`BORDER_WEIGHT`] for a
/// border edge, which has one side): a trade between the texture's fidelity along the seam
/// and the geometric error of the collapses the planes refuse to price low
/// (docs/attributes.md#the-fast-mode-with-attributes).
pub(super) const SEAM_WEIGHT: f32 = 0.1;

/// Below this a squared cross product (in the unit frame) has no direction: a triangle of area
/// 5e-10 of the bounding box's face. Survivors must be above it, so fold tests never underflow.
const TINY: f32 = 1e-18;
/// `|n|² / (Σ edge²)²` below this: a normal that rounding decides (zero area).
const FLAT: f32 = 1e-8;
/// meshoptimizer's flip limit, `cos ≈ 0.25` (about 75°), squared.
const FLIP2: f32 = 0.0625;
/// The fold limit, `-0.89`, squared: the checker's `-0.9` (in `f64`) with a margin for the
/// rounding of `f32` normals of small triangles, so that no pair this test passes is one the
/// checker calls folded.
const FOLD2: f32 = 0.89 * 0.89;
/// See [`thinner`]: `Config::new()`'s `min_quality`.
const MIN_QUALITY: f32 = 0.05;
/// The pass's error goal factors (see `perform`).
const ERROR_GOAL: f32 = 0.9;
const TAIL_GOAL: f32 = 1.5;
/// `2⁻⁴⁸`'s 12-bit key: costs below it share bin 0.
const BASE: usize = (127 - 48) << 4;

impl Frame<'_> {
    /// Position of `v`, translated by the bounding box's corner and scaled by a power of two
    /// to an extent in `[1, 2)`.
    #[inline]
    pub(crate) fn at(&self, v: usize) -> V3 {
        let p = self.positions.get(v).copied().unwrap_or([0.0; 3]);
        [
            (p[0] - self.min[0]) * self.scale,
            (p[1] - self.min[1]) * self.scale,
            (p[2] - self.min[2]) * self.scale,
        ]
    }
}

/// The plane quadric of triangle `p`, weighted by its area times `w`, zero without area, and
/// that area. With `c` the cross product of two edges, `area · n nᵀ = c cᵀ / (2|c|)`: one
/// reciprocal square root, no normalisation.
#[inline]
fn plane(p: [V3; 3], w: f32) -> (PointQuadric, f32) {
    let c = math::cross(math::sub(p[1], p[0]), math::sub(p[2], p[0]));
    let l2 = math::dot(c, c);
    if !(l2 > math::TINY2 && l2.is_finite()) {
        return ([0.0; 6], 0.0);
    }
    let r = math::rsqrt(l2);
    // `math::sqrt(l2)` is `l2 · rsqrt(l2)`.
    (point_plane(c, 0.5 * r * w), 0.5 * (l2 * r))
}

/// [`plane`]'s quadric, not inlined: for the fan walks off the hot path (a border edge's
/// quadric, a stale price's quadric), where the lean mode's flash budget counts more than a
/// call.
#[inline(never)]
fn triangle_call(p: [V3; 3], w: f32) -> PointQuadric {
    plane(p, w).0
}

/// The quadric of open edge `p0 → p1` of triangle `(p0, p1, p2)` ([`Geometry::border_edge`]).
#[inline]
fn edge_quadric(p0: V3, p1: V3, p2: V3) -> Option<PointQuadric> {
    let e10 = math::sub(p1, p0);
    let e20 = math::sub(p2, p0);
    let l2 = math::dot(e10, e10);
    let proj = math::dot(e20, e10);
    let perp = math::sub(math::scale(e20, l2), math::scale(e10, proj));
    let pl2 = math::dot(perp, perp);
    if !(l2 > math::TINY2 && pl2 > math::TINY2 && pl2.is_finite()) {
        return None;
    }
    let n = math::scale(perp, math::rsqrt(pl2));
    let face = triangle_call([p0, p1, p2], BORDER_WEIGHT);
    let mut q = point_plane(n, math::sqrt(l2) * BORDER_WEIGHT);
    point_add(&mut q, &face);
    Some(q)
}

#[inline]
fn normal(p: [V3; 3]) -> V3 {
    math::cross(math::sub(p[1], p[0]), math::sub(p[2], p[0]))
}

/// With wedges: whether a surviving triangle becomes a sliver, its quality (`4√3 · area /
/// Σ edge²`) below [`MIN_QUALITY`] and lower than before. A thin triangle stretches the
/// texture across it; the exact engine's sliver preference (`Config::min_quality`), kept to
/// textured runs, where the positions-only bench found no gain in it.
#[inline(never)]
fn thinner(new: f32, s_new: f32, old: f32, [px, py, pa]: [V3; 3]) -> bool {
    let (ex, ey, exy) = (math::sub(px, pa), math::sub(py, pa), math::sub(px, py));
    let s_old = math::dot(ex, ex) + math::dot(ey, ey) + math::dot(exy, exy);
    // quality² = 12 |n|² / s², compared without a division.
    let limit = MIN_QUALITY * MIN_QUALITY / 12.0;
    new < limit * s_new * s_new && new * s_old * s_old < old * s_new * s_new
}

impl Geometry for Frame<'_> {
    type P = V3;
    type Sum = PointQuadric;
    type Q = PointQuadric;
    type Raw = f32;
    type Cost = f32;
    type Err = f32;
    type Area = f32;
    /// A normal and its squared length.
    type N = (V3, f32);

    const EMPTY: PointQuadric = [0.0; 6];
    const RAW_MAX: f32 = f32::INFINITY;
    const COST_MAX: f32 = f32::INFINITY;
    const COST_ZERO: f32 = 0.0;
    const ERR_ZERO: f32 = 0.0;
    const ERR_MAX: f32 = f32::INFINITY;
    const AREA_ZERO: f32 = 0.0;
    const ORIGIN: V3 = [0.0; 3];

    #[inline]
    fn at(&self, v: usize) -> V3 {
        Frame::at(self, v)
    }

    #[inline]
    fn face(&self, s: &mut PointQuadric, p: [V3; 3]) {
        point_add(s, &plane(p, 1.0).0);
    }

    #[inline]
    fn face_call(&self, s: &mut PointQuadric, p: [V3; 3]) {
        point_add(s, &triangle_call(p, 1.0));
    }

    #[inline]
    fn border_edge(&self, s: &mut PointQuadric, [p0, p1, p2]: [V3; 3]) {
        if let Some(e) = edge_quadric(p0, p1, p2) {
            point_add(s, &e);
        }
    }

    #[inline]
    fn seam_spoke(&self, s: &mut PointQuadric, pv: V3, pw: V3, po: V3) {
        let e = math::sub(pw, pv);
        let o = math::sub(po, pv);
        let l2 = math::dot(e, e);
        let perp = math::sub(math::scale(o, l2), math::scale(e, math::dot(o, e)));
        let pl2 = math::dot(perp, perp);
        if l2 > math::TINY2 && pl2 > math::TINY2 && pl2.is_finite() {
            let n = math::scale(perp, math::rsqrt(pl2));
            point_add(s, &point_plane(n, math::sqrt(l2) * SEAM_WEIGHT));
        }
    }

    #[inline(always)]
    fn finish(&self, s: PointQuadric) -> PointQuadric {
        s
    }

    #[inline]
    fn face_area(&self, p: [V3; 3]) -> f32 {
        let c = math::cross(math::sub(p[1], p[0]), math::sub(p[2], p[0]));
        0.5 * math::sqrt(math::dot(c, c))
    }

    #[inline(always)]
    fn add_area(a: f32, b: f32) -> f32 {
        a + b
    }

    #[inline(always)]
    fn mean_area(total: f32, triangles: usize) -> f32 {
        total / triangles as f32
    }

    #[inline]
    fn raw(&self, q: &PointQuadric, from: V3, to: V3) -> f32 {
        point_error(q, math::sub(to, from))
    }

    #[inline]
    fn price(&self, mean: f32, q: &PointQuadric, raw: f32) -> f32 {
        // `1 + Ā/W`: a sum alone makes a fan of small triangles cheap to move however far it
        // goes, so thin parts would go first.
        let w = point_weight(q);
        let factor = if w > 0.0 { 1.0 + mean / w } else { 1.0 };
        raw * factor
    }

    #[inline]
    fn error(&self, mean: f32, q: &PointQuadric, _: (V3, V3), c: f32) -> f32 {
        // `c / (W + Ā)` (`W · (1 + Ā/W)`), zero without weight.
        let w = point_weight(q);
        if w > 0.0 {
            c / (w + mean)
        } else {
            0.0
        }
    }

    #[inline(always)]
    fn cost_max(a: f32, b: f32) -> f32 {
        a.max(b)
    }

    #[inline(always)]
    fn goal(cost: f32, goal: Goal) -> f32 {
        match goal {
            Goal::Error => ERROR_GOAL * cost,
            Goal::Tail => TAIL_GOAL * cost,
        }
    }

    #[inline(always)]
    fn cost_bits(c: f32) -> u32 {
        c.to_bits()
    }

    #[inline(always)]
    fn cost_of(bits: u32) -> f32 {
        f32::from_bits(bits)
    }

    /// 12 bits of the cost (meshoptimizer's `sortEdgeCollapses`: 8 of exponent, 4 of
    /// mantissa), from `2⁻⁴⁸`.
    #[inline]
    fn key(bits: u32) -> usize {
        let k = (bits >> 19) as usize & 0xfff;
        let k = k.saturating_sub(BASE);
        if k < BINS {
            k
        } else {
            BINS - 1
        }
    }

    #[inline]
    fn target(target: crate::Target, valid: usize) -> usize {
        target.triangles(valid)
    }

    #[inline]
    fn limit(&self, distance: f32) -> f32 {
        // A squared distance in the unit frame.
        let l = distance * self.scale;
        l * l
    }

    #[inline(always)]
    fn over(e: f32, limit: f32) -> bool {
        e > limit || e.is_nan()
    }

    #[inline(always)]
    fn finite(e: f32) -> bool {
        e.is_finite()
    }

    #[inline(always)]
    fn grow(e: f32, limit: f32) -> f32 {
        (e * 1.5).min(limit)
    }

    #[inline]
    fn distance(&self, e: f32) -> f32 {
        math::sqrt(e) / self.scale
    }

    #[inline]
    fn size(&self, a: V3, b: V3) -> f32 {
        let d = math::sub(b, a);
        math::dot(d, d)
    }

    #[inline(always)]
    fn err_bits(e: f32) -> u32 {
        e.to_bits()
    }

    #[inline(always)]
    fn err_of(bits: u32) -> f32 {
        f32::from_bits(bits)
    }

    #[inline(always)]
    fn survivor(
        &self,
        [pa, pb, px, py]: [V3; 4],
        (area, flip, thin): (bool, bool, bool),
    ) -> Result<(V3, f32), Reject> {
        let n0 = normal([pa, px, py]);
        let n1 = normal([pb, px, py]);
        let abd = math::dot(n1, n1);
        let (ex, ey, exy) = (math::sub(px, pb), math::sub(py, pb), math::sub(px, py));
        let s = math::dot(ex, ex) + math::dot(ey, ey) + math::dot(exy, exy);
        if area && !(abd > TINY && abd > FLAT * s * s) {
            return Err(Reject::Sliver);
        }
        let ndp = math::dot(n0, n1);
        let abc = math::dot(n0, n0);
        if flip && (ndp <= 0.0 || ndp * ndp <= FLIP2 * abc * abd) {
            return Err(Reject::NormalTurn);
        }
        if thin && thinner(abd, s, abc, [px, py, pa]) {
            return Err(Reject::Sliver);
        }
        Ok((n1, abd))
    }

    #[inline]
    fn normal(&self, p: [V3; 3]) -> (V3, f32) {
        let n = normal(p);
        (n, math::dot(n, n))
    }

    /// `a` is a survivor's normal (`|a|² > TINY`); a neighbour's normal below `TINY` counts
    /// as folded (refused, never guessed). With both above `TINY` no product here leaves
    /// f32's normal range in the unit frame.
    #[inline(always)]
    fn folded((n1, u2): (V3, f32), (n2, v2): (V3, f32)) -> bool {
        // Written so that NaN refuses too.
        let directed = v2 > TINY;
        let d = math::dot(n1, n2);
        !directed || (d < 0.0 && d * d > FOLD2 * u2 * v2)
    }

    #[inline(always)]
    fn fill_stored<I: Index, L: Index, const W: bool>(
        &self,
        triangles: &[[I; 3]],
        adj: (&[L], &[L]),
        flags: &mut [u8],
        border_next: &[L],
        stored: &mut [PointQuadric],
        all: bool,
    ) -> Option<f32> {
        let area = face_quadrics(self, triangles, flags, stored, all);
        if W {
            seam_quadrics(self, triangles, adj, flags, stored, all);
        }
        border_quadrics(self, triangles, adj, flags, border_next, stored, all);
        all.then_some(area)
    }
}

#[inline]
fn add_to(q: &mut [PointQuadric], v: usize, x: &PointQuadric) {
    if let Some(q) = q.get_mut(v) {
        point_add(q, x);
    }
}

/// Zeroes the due quadrics and adds every triangle's plane at its due vertices; returns the
/// area of the triangles it took (all of them with `all`, summed as `fill::area` sums it).
#[inline(never)]
fn face_quadrics<I: Index>(
    frame: &Frame<'_>,
    triangles: &[[I; 3]],
    flags: &[u8],
    quadrics: &mut [PointQuadric],
    all: bool,
) -> f32 {
    for (v, q) in quadrics.iter_mut().enumerate() {
        if super::fill::due(flags, v, all) {
            *q = [0.0; 6];
        }
    }
    let mut sum = 0.0;
    for t in 0..triangles.len() {
        let tr = tri(triangles, t);
        let d = tr.map(|v| super::fill::due(flags, v, all));
        if !(d[0] || d[1] || d[2]) {
            continue;
        }
        let (q, area) = plane(tr.map(|v| frame.at(v)), 1.0);
        sum += area;
        for (v, d) in tr.into_iter().zip(d) {
            if d {
                add_to(quadrics, v, &q);
            }
        }
    }
    sum
}

/// With wedges: the seam planes of every due seam vertex, from its fan.
#[inline(never)]
fn seam_quadrics<I: Index, L: Index>(
    frame: &Frame<'_>,
    triangles: &[[I; 3]],
    adj: (&[L], &[L]),
    flags: &[u8],
    quadrics: &mut [PointQuadric],
    all: bool,
) {
    for v in 0..flags.len() {
        if flags_of(flags, v) & flag::SEAM == 0 || !super::fill::due(flags, v, all) {
            continue;
        }
        let Some(q) = quadrics.get_mut(v) else {
            continue;
        };
        let pv = frame.at(v);
        for (_, tr, k) in fan(triangles, adj, flags, v) {
            let (x, y) = others(tr, k);
            super::fill::seam_planes(frame, flags, (x, y), [pv, frame.at(x), frame.at(y)], q);
        }
    }
}

/// Adds the border edge quadrics at the due ends of each open edge `v → border_next[v]`, and
/// clears the dirty bits.
#[inline(never)]
fn border_quadrics<I: Index, L: Index>(
    frame: &Frame<'_>,
    triangles: &[[I; 3]],
    adj: (&[L], &[L]),
    flags: &mut [u8],
    border_next: &[L],
    quadrics: &mut [PointQuadric],
    all: bool,
) {
    for i0 in 0..flags.len() {
        if flags_of(flags, i0) & flag::KIND != flag::BORDER {
            continue;
        }
        let i1 = link(border_next, i0);
        let (d0, d1) = (
            super::fill::due(flags, i0, all),
            super::fill::due(flags, i1, all),
        );
        if !(d0 || d1) {
            continue;
        }
        // The open edge's triangle: the one of i0's fan with i1 after i0.
        let Some(i2) = fan(triangles, adj, flags, i0)
            .map(|(_, tr, k)| others(tr, k))
            .find(|&(x, _)| x == i1)
            .map(|(_, y)| y)
        else {
            continue;
        };
        let Some(q) = edge_quadric(frame.at(i0), frame.at(i1), frame.at(i2)) else {
            continue;
        };
        if d0 {
            add_to(quadrics, i0, &q);
        }
        if d1 {
            add_to(quadrics, i1, &q);
        }
    }
    for f in flags.iter_mut() {
        *f &= !flag::DIRTY;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_pair_at_the_checkers_fold_limit_is_folded() {
        let sq = |n: V3| (n, math::dot(n, n));
        let up = sq([0.0, 0.0, 2.0]);
        let at = |d: f32| sq([3.0 * math::sqrt(1.0 - d * d), 0.0, 3.0 * d]);
        assert!(<Frame<'_> as Geometry>::folded(up, at(-0.9)));
        assert!(<Frame<'_> as Geometry>::folded(up, at(-0.895)));
        assert!(!<Frame<'_> as Geometry>::folded(up, at(-0.88)));
    }
}
