//! What the rules read of a triangle ([`Shape`]: its scaled normal and quality) and the
//! shape rules on one triangle before and after a move: zero area, quality, normal turn, and
//! the fold test between two neighbours.

use crate::index::Index;
use crate::math::{self, V3};
use crate::mesh::Mesh;

use super::{on, Reject, Rules};

/// Two adjacent triangles whose unit normals have a dot product below −0.89 are folded onto
/// each other (more than about 153° apart); compared squared. The shared checker's limit is
/// −0.9 in `f64`: the margin covers the rounding of `f32` normals of small triangles far from
/// the origin, so that no pair this test passes is one the checker calls folded.
pub(super) const FOLD_DOT2: f32 = 0.89 * 0.89;

/// A triangle whose normal turns by less than this (cosine of about 1°) stays in its plane:
/// a sliver there costs no error, so the sliver preference does not apply.
pub(super) const COS_PLANAR: f32 = 0.999_85;
pub(super) const COS_PLANAR2: f32 = COS_PLANAR * COS_PLANAR;

/// Below this quality (`|n|² / (Σ edge²)²`: a height about 10⁻⁴ of the longest edge) a
/// triangle's normal is at the mercy of rounding, so it could flip unseen: it counts as zero
/// area, unless it was already that thin.
pub(super) const FLAT: f32 = 1e-8;

/// What the rules need of one triangle.
#[derive(Clone, Copy)]
pub(crate) struct Shape {
    /// The normal (cross product of the edges), scaled by a power of two to a largest
    /// component in `[1, 2)`; zero if the triangle has no area.
    pub(super) n: V3,
    /// `|n|²`.
    pub(super) n2: f32,
    /// quality² / 12 = |cross|² / (Σ edge²)², scale-free; 1/12 for an equilateral triangle.
    pub(super) quality: f32,
}

impl Shape {
    /// The shape of triangle `p`, computed on its edges scaled by a power of two (exact), so
    /// that neither squares nor products of tiny or huge edges leave f32's normal range.
    #[inline]
    pub(crate) fn of(p: [V3; 3]) -> Shape {
        let e = [
            math::sub(p[1], p[0]),
            math::sub(p[2], p[1]),
            math::sub(p[0], p[2]),
        ];
        let m = math::max_abs(e[0])
            .max(math::max_abs(e[1]))
            .max(math::max_abs(e[2]));
        // Subnormal edges (coordinates near zero): lift them by 2^64 first (exact), so that
        // their triangles keep a direction and folds against them are still seen.
        let (e, m) = if m > 0.0 && m < f32::MIN_POSITIVE {
            let lift = f32::from_bits((127 + 64) << 23);
            (e.map(|v| math::scale(v, lift)), m * lift)
        } else {
            (e, m)
        };
        let k = math::pow2_inverse(m);
        if k == 0.0 {
            return Shape {
                n: [0.0; 3],
                n2: 0.0,
                quality: 0.0,
            };
        }
        let e = e.map(|v| math::scale(v, k));
        // cross(p1 - p0, p2 - p0), with p2 - p0 = -e2.
        let c = math::cross(e[0], math::scale(e[2], -1.0));
        let l2 = math::dot(c, c);
        let s = math::dot(e[0], e[0]) + math::dot(e[1], e[1]) + math::dot(e[2], e[2]);
        let n = math::pow2_normalize(c);
        Shape {
            n,
            n2: math::dot(n, n),
            quality: if s > 0.0 { l2 / (s * s) } else { 0.0 },
        }
    }

    /// The unit normal (zero if no area).
    #[inline]
    pub(crate) fn unit(&self) -> V3 {
        math::unit_of(self.n, self.n2)
    }
}

/// The sliver and normal-turn rules on one surviving triangle, `was` before the collapse and
/// `now` after it. One dot product serves both: the turn limit and the plane test (a sliver
/// that stays within about 1° of its plane is allowed).
#[inline(never)]
pub(super) fn shape_rules(rules: &Rules, was: &Shape, now: &Shape) -> Result<(), Reject> {
    let d = math::dot(was.n, now.n);
    let (d2, n2) = (d * d, was.n2 * now.n2);
    // Whether the angle between the normals exceeds the one whose cosine is `cos`.
    let turned = |cos: f32, cos2: f32| {
        if cos >= 0.0 {
            d < 0.0 || d2 < cos2 * n2
        } else {
            d < 0.0 && d2 > cos2 * n2
        }
    };
    let q = now.quality;
    if on!(Sliver)
        && (q <= 0.0
            || (q < was.quality
                && (q < FLAT || (q < rules.min_ratio && turned(COS_PLANAR, COS_PLANAR2)))))
    {
        return Err(Reject::Sliver);
    }
    // A zero-area triangle has no direction to turn from.
    if on!(NormalTurn) && was.quality > 0.0 && turned(rules.cos_turn, rules.cos_turn2) {
        return Err(Reject::NormalTurn);
    }
    Ok(())
}

/// Whether two triangles sharing an edge are folded onto each other.
#[inline]
pub(super) fn folded(u: &Shape, v: &Shape) -> bool {
    let d = math::dot(u.n, v.n);
    d < 0.0 && d * d > FOLD_DOT2 * u.n2 * v.n2
}

/// The shape of live triangle `t`.
#[inline]
pub(super) fn shape_of<L: Index, I: Index>(mesh: &Mesh<'_, L, I>, t: usize) -> Shape {
    Shape::of(mesh.tri(t).map(|v| mesh.p(v)))
}

/// The shape of live triangle `t` once `a` and `b` are both at `p` (`b` moved, `a` merged
/// into it).
#[inline]
pub(super) fn shape_moved<L: Index, I: Index>(
    mesh: &Mesh<'_, L, I>,
    t: usize,
    a: usize,
    b: usize,
    p: V3,
) -> Shape {
    Shape::of(
        mesh.tri(t)
            .map(|v| if v == a || v == b { p } else { mesh.p(v) }),
    )
}
