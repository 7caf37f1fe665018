//! Plane quadrics (Garland's quadric error metric, as Cheng, Pan and Shi 1998 use it, §2.3): a
//! symmetric 4×4 matrix `Q` stored as its upper triangle, 10 floats, whose form `vᵀ Q v` at
//! `v = (p, 1)` is the (weighted) sum of squared distances from `p` to the planes it was built
//! from. Shared by the stored-quadric cost and the clustering's quadric representative.

use crate::math::V3;

/// Per-vertex storage of [`StoredQuadric`](crate::cost::StoredQuadric): a symmetric 4×4 matrix as its upper triangle, row by
/// row (`a², ab, ac, ad, b², bc, bd, c², cd, d²` for one plane), 40 bytes.
pub type VertexQuadric = [f32; 10];

/// The quadric `p pᵀ` of the plane `p = (n, d)` (Cheng, Pan and Shi 1998 eq. 3, `K_p`), upper
/// triangle.
#[inline]
pub(crate) fn outer(n: V3, d: f32) -> VertexQuadric {
    let [a, b, c] = n;
    [
        a * a,
        a * b,
        a * c,
        a * d,
        b * b,
        b * c,
        b * d,
        c * c,
        c * d,
        d * d,
    ]
}

/// Element-wise sum.
pub(crate) fn add(x: &VertexQuadric, y: &VertexQuadric) -> VertexQuadric {
    let mut s = *x;
    for (s, y) in s.iter_mut().zip(y) {
        *s += y;
    }
    s
}

/// `q` (in a frame centred on `o`) in the frame centred on `o + s`: with `x = x' + s`,
/// `b' = b + A s` and `c' = q(s)`.
pub(crate) fn translate(q: &VertexQuadric, s: V3) -> VertexQuadric {
    let [x, y, z] = s;
    let b0 = q[3] + q[0] * x + q[1] * y + q[2] * z;
    let b1 = q[6] + q[1] * x + q[4] * y + q[5] * z;
    let b2 = q[8] + q[2] * x + q[5] * y + q[7] * z;
    [q[0], q[1], q[2], b0, q[4], q[5], b1, q[7], b2, form(q, s)]
}

/// A plane quadric kept in a frame centred on a point that each of its planes passes through
/// (the fast mode's per-vertex quadric, and the memoryless cost's fan summary, of the planes
/// of the vertex's own triangles): the offset terms of [`VertexQuadric`] are then zero, so
/// only `A = Σ w n nᵀ` is kept, upper triangle row by row (`a², ab, ac, b², bc, c²` for one plane), 24 bytes.
pub(crate) type PointQuadric = [f32; 6];

#[cfg(feature = "fast")]
/// `w · n nᵀ` for a plane of normal `n` through the frame's centre.
#[inline]
pub(crate) fn point_plane(n: V3, w: f32) -> PointQuadric {
    let [a, b, c] = n;
    [
        a * a * w,
        a * b * w,
        a * c * w,
        b * b * w,
        b * c * w,
        c * c * w,
    ]
}

#[cfg(feature = "fast")]
/// Adds `x` to `q`, term by term.
#[inline]
pub(crate) fn point_add(q: &mut PointQuadric, x: &PointQuadric) {
    for (s, y) in q.iter_mut().zip(x) {
        *s += y;
    }
}

/// `dᵀ A d`, clamped at zero: the weighted sum of squared distances from `d` to the planes.
#[inline]
pub(crate) fn point_error(q: &PointQuadric, d: V3) -> f32 {
    let [x, y, z] = d;
    let e = q[0] * x * x
        + q[3] * y * y
        + q[5] * z * z
        + 2.0 * (q[1] * x * y + q[2] * x * z + q[4] * y * z);
    if e > 0.0 {
        e
    } else {
        0.0
    }
}

#[cfg(feature = "fast")]
/// The sum of the planes' weights (`trace A`: each normal is a unit vector).
#[inline]
pub(crate) fn point_weight(q: &PointQuadric) -> f32 {
    q[0] + q[3] + q[5]
}

/// `vᵀ Q v` for `v = (p, 1)`, unclamped.
#[inline]
pub(crate) fn form(q: &VertexQuadric, p: V3) -> f32 {
    let [x, y, z] = p;
    q[0] * x * x
        + q[4] * y * y
        + q[7] * z * z
        + 2.0 * (q[1] * x * y + q[2] * x * z + q[5] * y * z)
        + 2.0 * (q[3] * x + q[6] * y + q[8] * z)
        + q[9]
}

/// `vᵀ Q v` for `v = (p, 1)`, clamped at zero (`p` in the quadric's frame).
#[inline]
pub fn error(q: &VertexQuadric, p: V3) -> f32 {
    let e = form(q, p);
    if e > 0.0 {
        e
    } else {
        0.0
    }
}

/// The minimiser of `vᵀ Q v`: `A p = −b` by Cramer's rule, `None` when `A` is ill-conditioned
/// (|det A| below 1e-5 of (trace A / 3)³: a flat or creased neighbourhood, where the minimiser
/// is a line or a plane) or the result is not finite.
pub(crate) fn solve(q: &VertexQuadric) -> Option<V3> {
    let (a00, a01, a02, a11, a12, a22) = (q[0], q[1], q[2], q[4], q[5], q[7]);
    let (b0, b1, b2) = (-q[3], -q[6], -q[8]);
    let c00 = a11 * a22 - a12 * a12;
    let c01 = a02 * a12 - a01 * a22;
    let c02 = a01 * a12 - a02 * a11;
    let det = a00 * c00 + a01 * c01 + a02 * c02;
    let t = (a00 + a11 + a22) * (1.0 / 3.0);
    let abs = if det < 0.0 { -det } else { det };
    // Written so that NaN fails too.
    let conditioned = t > 0.0 && abs > 1e-5 * t * t * t;
    if !conditioned {
        return None;
    }
    let c11 = a00 * a22 - a02 * a02;
    let c12 = a01 * a02 - a00 * a12;
    let c22 = a00 * a11 - a01 * a01;
    let inv = 1.0 / det;
    let p = [
        (c00 * b0 + c01 * b1 + c02 * b2) * inv,
        (c01 * b0 + c11 * b1 + c12 * b2) * inv,
        (c02 * b0 + c12 * b1 + c22 * b2) * inv,
    ];
    if p[0].is_finite() && p[1].is_finite() && p[2].is_finite() {
        Some(p)
    } else {
        None
    }
}

/// `pᵀ A p + 2 bᵀ p + c` of a plane quadric at `p`: the value of [`form`], summed term by term
/// in the order of `q`. The clustering's representatives are chosen with this order; the two
/// orders round differently, and each is pinned by golden outputs, so both stay.
#[inline]
pub(crate) fn form_by_terms(q: &VertexQuadric, p: V3) -> f32 {
    let [x, y, z] = p;
    q[0] * x * x
        + 2.0 * q[1] * x * y
        + 2.0 * q[2] * x * z
        + 2.0 * q[3] * x
        + q[4] * y * y
        + 2.0 * q[5] * y * z
        + 2.0 * q[6] * y
        + q[7] * z * z
        + 2.0 * q[8] * z
        + q[9]
}
