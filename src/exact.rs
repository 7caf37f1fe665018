//! Exact intersection tests on a fixed-point grid, for the simplification envelope
//! ([`crate::bound::Envelope`]): whether two closed triangles share a point.
//!
//! Points are snapped from the engine's normalised units (about `[-1, 1]³`) to integers in
//! units of 2⁻²⁴, clamped to `[-4, 4]`: coordinates fit 27 bits, their differences 28, a cross
//! product of two differences 57 bits of an `i64`, and its dot product with a third difference
//! 87 bits of an `i128`. Every sign below is therefore the exact sign of the determinant of the
//! snapped points: no rounding, no filter, the same answer on every core. The snap moves a point
//! by at most `√3 · 2⁻²⁵` ([`SNAP`]); the envelope shrinks its offsets by more than that.

use crate::math::V3;

/// Grid points per normalised unit.
const SCALE: f32 = 16_777_216.0;
/// The largest coordinate, in grid points (4 normalised units).
const LIMIT: f32 = 67_108_864.0;

/// The largest distance [`snap`] moves a point, in normalised units (with a margin).
pub(crate) const SNAP: f32 = 1.0e-7;

/// A point on the grid.
pub(crate) type P = [i64; 3];

/// `p` on the grid (round to nearest, clamped; NaN to 0).
pub(crate) fn snap(p: V3) -> P {
    p.map(|x| {
        let s = x * SCALE;
        let s = if s > LIMIT {
            LIMIT
        } else if s < -LIMIT {
            -LIMIT
        } else if s.is_nan() {
            0.0
        } else {
            s
        };
        // In range, so the conversion is exact after rounding.
        let r = if s >= 0.0 { s + 0.5 } else { s - 0.5 };
        r as i64
    })
}

#[inline]
fn sub(a: P, b: P) -> P {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

#[inline]
fn cross(a: P, b: P) -> P {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

#[inline]
fn dot(a: P, b: P) -> i128 {
    a[0] as i128 * b[0] as i128 + a[1] as i128 * b[1] as i128 + a[2] as i128 * b[2] as i128
}

/// The sign of the volume of `(a, b, c, d)`: `(b - a) × (c - a) · (d - a)`.
#[inline]
pub(crate) fn orient3d(a: P, b: P, c: P, d: P) -> i8 {
    sign(dot(cross(sub(b, a), sub(c, a)), sub(d, a)))
}

#[inline]
fn sign(x: i128) -> i8 {
    (x > 0) as i8 - (x < 0) as i8
}

/// The sign of the area of `(a, b, c)` in the plane of axes `(u, v)`.
#[inline]
fn orient2d(a: P, b: P, c: P, u: usize, v: usize) -> i8 {
    let g = |p: P, i: usize| p.get(i).copied().unwrap_or(0);
    let (ax, ay) = (g(b, u) - g(a, u), g(b, v) - g(a, v));
    let (bx, by) = (g(c, u) - g(a, u), g(c, v) - g(a, v));
    sign(ax as i128 * by as i128 - ay as i128 * bx as i128)
}

/// Whether the closed segments `[a, b]` and `[c, d]`, in the plane of axes `(u, v)`, share a
/// point.
fn segments_meet_2d(a: P, b: P, c: P, d: P, u: usize, v: usize) -> bool {
    let (o1, o2) = (orient2d(a, b, c, u, v), orient2d(a, b, d, u, v));
    let (o3, o4) = (orient2d(c, d, a, u, v), orient2d(c, d, b, u, v));
    if o1 * o2 < 0 && o3 * o4 < 0 {
        return true;
    }
    // A touching or collinear configuration: some endpoint on the other segment.
    let on = |p: P, q: P, r: P| {
        let g = |x: P, i: usize| x.get(i).copied().unwrap_or(0);
        let within = |i: usize| g(r, i) >= g(p, i).min(g(q, i)) && g(r, i) <= g(p, i).max(g(q, i));
        within(u) && within(v)
    };
    (o1 == 0 && on(a, b, c))
        || (o2 == 0 && on(a, b, d))
        || (o3 == 0 && on(c, d, a))
        || (o4 == 0 && on(c, d, b))
}

/// Whether the closed segment `[a, b]` and the closed triangle `t` share a point. A triangle
/// with no area counts as meeting every segment (the caller refuses what it cannot decide).
fn segment_meets_triangle(a: P, b: P, t: [P; 3]) -> bool {
    let [p, q, r] = t;
    let n = cross(sub(q, p), sub(r, p));
    if n == [0; 3] {
        return true;
    }
    let (sa, sb) = (sign(dot(n, sub(a, p))), sign(dot(n, sub(b, p))));
    if sa * sb > 0 {
        return false;
    }
    if sa != 0 || sb != 0 {
        // One point of the segment in the triangle's plane: inside iff the line through
        // `a, b` passes the three edges on one side.
        let s1 = orient3d(a, b, p, q);
        let s2 = orient3d(a, b, q, r);
        let s3 = orient3d(a, b, r, p);
        return !((s1 > 0 || s2 > 0 || s3 > 0) && (s1 < 0 || s2 < 0 || s3 < 0));
    }
    // Coplanar: in the plane of the two axes the normal is smallest along.
    let m = n.map(|x| x.unsigned_abs());
    let (u, v) = if m[0] >= m[1] && m[0] >= m[2] {
        (1, 2)
    } else if m[1] >= m[2] {
        (2, 0)
    } else {
        (0, 1)
    };
    let inside = |x: P| {
        let (s1, s2, s3) = (
            orient2d(p, q, x, u, v),
            orient2d(q, r, x, u, v),
            orient2d(r, p, x, u, v),
        );
        !((s1 > 0 || s2 > 0 || s3 > 0) && (s1 < 0 || s2 < 0 || s3 < 0))
    };
    inside(a)
        || inside(b)
        || segments_meet_2d(a, b, p, q, u, v)
        || segments_meet_2d(a, b, q, r, u, v)
        || segments_meet_2d(a, b, r, p, u, v)
}

/// Whether the closed triangles `s` and `t` share a point: two convex sets meet iff an edge
/// of one meets the other (the ends of their common segment, or polygon, lie on edges).
pub(crate) fn triangles_meet(s: [P; 3], t: [P; 3]) -> bool {
    // Cheap exact rejections first: all of one on a strict side of the other's plane.
    if strictly_beside(s, t) || strictly_beside(t, s) {
        return false;
    }
    let [a, b, c] = s;
    let [p, q, r] = t;
    segment_meets_triangle(a, b, t)
        || segment_meets_triangle(b, c, t)
        || segment_meets_triangle(c, a, t)
        || segment_meets_triangle(p, q, s)
        || segment_meets_triangle(q, r, s)
        || segment_meets_triangle(r, p, s)
}

/// Whether the closed triangles `s` and `t` share a point other than a corner they have in
/// common (the envelope's pinched vertices, which new triangles may keep). Two common
/// corners, or a corner's edge in the other's plane, count as meeting.
pub(crate) fn triangles_meet_beyond(s: [P; 3], t: [P; 3]) -> bool {
    let mut shared = None;
    let mut count = 0;
    for (i, x) in s.iter().enumerate() {
        if let Some(j) = t.iter().position(|y| y == x) {
            shared = Some((i, j));
            count += 1;
        }
    }
    match (count, shared) {
        (0, _) => triangles_meet(s, t),
        (1, Some((i, j))) => {
            let [x, a, b] = rotate(s, i);
            let [_, c, d] = rotate(t, j);
            // Beyond `x` they meet along a segment from `x` whose far end is on `[a, b]`, on
            // `[c, d]`, or on an edge at `x` (which then lies in the other's plane).
            if orient3d(x, c, d, a) == 0
                || orient3d(x, c, d, b) == 0
                || orient3d(x, a, b, c) == 0
                || orient3d(x, a, b, d) == 0
            {
                return true;
            }
            segment_meets_triangle(a, b, t) || segment_meets_triangle(c, d, s)
        }
        _ => true,
    }
}

/// `t`'s corners from corner `i` on, in winding order.
fn rotate([p, q, r]: [P; 3], i: usize) -> [P; 3] {
    match i {
        1 => [q, r, p],
        2 => [r, p, q],
        _ => [p, q, r],
    }
}

/// Whether the three points of `s` lie strictly on one side of the plane of `t` (never for a
/// `t` with no area).
fn strictly_beside(s: [P; 3], t: [P; 3]) -> bool {
    let [p, q, r] = t;
    let n = cross(sub(q, p), sub(r, p));
    let d = s.map(|x| sign(dot(n, sub(x, p))));
    (d[0] > 0 && d[1] > 0 && d[2] > 0) || (d[0] < 0 && d[1] < 0 && d[2] < 0)
}

/// The sign of `t`'s normal along the normal of `u` (both on the grid): whether an offset
/// triangle kept its original's facing.
pub(crate) fn same_facing(t: [P; 3], u: [P; 3]) -> bool {
    let n = |x: [P; 3]| cross(sub(x[1], x[0]), sub(x[2], x[0]));
    dot(n(t), n(u)) > 0
}

#[cfg(test)]
mod tests {
    use super::*;

    fn g(p: [f32; 3]) -> P {
        snap(p)
    }

    fn tri(a: [f32; 3], b: [f32; 3], c: [f32; 3]) -> [P; 3] {
        [g(a), g(b), g(c)]
    }

    #[test]
    fn crossing_touching_apart_and_coplanar() {
        let base = tri([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
        // Pierces the interior.
        let pierce = tri([0.2, 0.2, -1.0], [0.2, 0.2, 1.0], [0.3, 0.25, 1.0]);
        assert!(triangles_meet(base, pierce) && triangles_meet(pierce, base));
        // Above, apart.
        let above = tri([0.2, 0.2, 0.1], [0.6, 0.2, 0.1], [0.2, 0.6, 0.2]);
        assert!(!triangles_meet(base, above));
        // Touches at one vertex only.
        let touch = tri([0.5, 0.5, 0.0], [0.5, 0.5, 1.0], [1.0, 1.0, 1.0]);
        assert!(triangles_meet(base, touch));
        // Crosses the plane outside the triangle.
        let outside = tri([0.8, 0.8, -1.0], [0.8, 0.8, 1.0], [0.9, 0.9, 0.0]);
        assert!(!triangles_meet(base, outside));
        // Coplanar: inside, overlapping edges, apart.
        let inner = tri([0.1, 0.1, 0.0], [0.2, 0.1, 0.0], [0.1, 0.2, 0.0]);
        assert!(triangles_meet(base, inner) && triangles_meet(inner, base));
        let cross = tri([0.5, -0.5, 0.0], [0.5, 2.0, 0.0], [0.6, 2.0, 0.0]);
        assert!(triangles_meet(base, cross));
        let apart = tri([1.0, 1.0, 0.0], [2.0, 1.0, 0.0], [1.0, 2.0, 0.0]);
        assert!(!triangles_meet(base, apart));
        // Sharing an edge.
        let hinge = tri([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 1.0]);
        assert!(triangles_meet(base, hinge));
    }

    #[test]
    fn agrees_with_a_sampled_reference() {
        // A seeded walk over small random triangle pairs: "meet" must hold whenever sampled
        // points of one lie (up to the grid) on the other, and "apart" must leave a gap.
        let mut s = 0x2545_f491_4f6c_dd1du64;
        let mut r = || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            ((s >> 40) as f32 / (1u64 << 24) as f32) - 0.5
        };
        let mut met = 0;
        for _ in 0..4000 {
            let a = [[r(), r(), r()], [r(), r(), r()], [r(), r(), r()]];
            let b = [[r(), r(), r()], [r(), r(), r()], [r(), r(), r()]];
            let m = triangles_meet(a.map(g), b.map(g));
            assert_eq!(m, triangles_meet(b.map(g), a.map(g)));
            // Reference: the segment of each edge of `a` against `b`, in f64 by Möller-Trumbore.
            let hit = reference(&a, &b) || reference(&b, &a);
            if hit {
                met += 1;
                assert!(m, "{a:?} {b:?}");
            } else {
                assert!(!m, "{a:?} {b:?}");
            }
        }
        assert!(met > 500);
    }

    #[test]
    fn meeting_beyond_a_common_corner() {
        let base = tri([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
        // A fan neighbour above, touching at the corner only.
        let up = tri([0.0, 0.0, 0.0], [-1.0, 0.0, 0.5], [0.0, -1.0, 0.5]);
        assert!(triangles_meet(base, up) && !triangles_meet_beyond(base, up));
        // Through the base beyond the common corner.
        let through = tri([0.0, 0.0, 0.0], [0.5, 0.2, -1.0], [0.2, 0.5, 1.0]);
        assert!(triangles_meet_beyond(base, through));
        // Coplanar, overlapping from the corner: counted as meeting.
        let flat = tri([0.0, 0.0, 0.0], [0.5, 0.1, 0.0], [0.1, 0.5, 0.0]);
        assert!(triangles_meet_beyond(base, flat));
        // No common corner: the plain test.
        let apart = tri([2.0, 2.0, 0.0], [3.0, 2.0, 0.0], [2.0, 3.0, 0.0]);
        assert!(!triangles_meet_beyond(base, apart));
    }

    fn reference(a: &[[f32; 3]; 3], b: &[[f32; 3]; 3]) -> bool {
        let f = |p: [f32; 3]| p.map(f64::from);
        let (p, q, r) = (f(b[0]), f(b[1]), f(b[2]));
        let sub = |x: [f64; 3], y: [f64; 3]| [x[0] - y[0], x[1] - y[1], x[2] - y[2]];
        let cross = |x: [f64; 3], y: [f64; 3]| {
            [
                x[1] * y[2] - x[2] * y[1],
                x[2] * y[0] - x[0] * y[2],
                x[0] * y[1] - x[1] * y[0],
            ]
        };
        let dot = |x: [f64; 3], y: [f64; 3]| x[0] * y[0] + x[1] * y[1] + x[2] * y[2];
        (0..3).any(|i| {
            let (o, e) = (f(a[i]), sub(f(a[(i + 1) % 3]), f(a[i])));
            let (e1, e2) = (sub(q, p), sub(r, p));
            let h = cross(e, e2);
            let det = dot(e1, h);
            if det.abs() < 1e-12 {
                return false;
            }
            let s = sub(o, p);
            let u = dot(s, h) / det;
            let qv = cross(s, e1);
            let v = dot(e, qv) / det;
            let t = dot(e2, qv) / det;
            u >= 0.0 && v >= 0.0 && u + v <= 1.0 && (0.0..=1.0).contains(&t)
        })
    }
}
