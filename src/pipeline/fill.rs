//! fill: per-vertex quadrics, once (meshoptimizer's `fillFaceQuadrics` and
//! `fillEdgeQuadrics`): each triangle's plane quadric (Garland's, Cheng, Pan and Shi 1998 §2.3 eq. 3) with
//! meshoptimizer's `sqrt(area)` weight, added at its three vertices; and for each border edge
//! a plane through the edge perpendicular to its triangle, weighted by the edge's length
//! times 10, plus the triangle's plane at the same weight, added at both ends, so that
//! borders keep their shape. Every quadric is in its vertex's frame (module `pipeline`), where
//! each of these planes passes through the origin.

use super::{flag, flags_of, link, tri, Frame};
use crate::index::Index;
use crate::math::{self, V3};
use crate::quadric::{self, VertexQuadric};

/// meshoptimizer's `kEdgeWeightBorder`.
const BORDER_WEIGHT: f32 = 10.0;

/// `w · (n nᵀ)` for the plane `n·x + d = 0`.
#[inline]
fn plane(n: V3, d: f32, w: f32) -> VertexQuadric {
    quadric::outer(n, d).map(|x| x * w)
}

#[inline]
fn add_to(q: &mut [VertexQuadric], v: usize, x: &VertexQuadric) {
    if let Some(q) = q.get_mut(v) {
        *q = quadric::add(q, x);
    }
}

/// The plane quadric of triangle `p` with weight `sqrt(area) · w`, zero without area, in the
/// frame of any of its vertices: the plane passes through each, so its offset there is zero
/// (exactly, not to rounding).
#[inline]
fn triangle(p: [V3; 3], w: f32) -> VertexQuadric {
    let c = math::cross(math::sub(p[1], p[0]), math::sub(p[2], p[0]));
    let l2 = math::dot(c, c);
    if !(l2 > math::TINY2 && l2.is_finite()) {
        return [0.0; 10];
    }
    let inv = math::rsqrt(l2);
    let n = math::scale(c, inv);
    let area = 0.5 * l2 * inv;
    plane(n, 0.0, math::sqrt(area) * w)
}

/// Zeroes the quadrics and adds every triangle's plane at its vertices.
#[inline(never)]
pub(super) fn face_quadrics<I: Index>(
    frame: &Frame<'_>,
    triangles: &[[I; 3]],
    nt: usize,
    quadrics: &mut [VertexQuadric],
) {
    for q in quadrics.iter_mut() {
        *q = [0.0; 10];
    }
    for t in 0..nt {
        let tr = tri(triangles, t);
        let q = triangle(tr.map(|v| frame.at(v)), 1.0);
        for v in tr {
            add_to(quadrics, v, &q);
        }
    }
}

/// Adds the border edge quadrics: for each open edge `v → border_next[v]`.
#[inline(never)]
pub(super) fn border_quadrics<I: Index, L: Index>(
    frame: &Frame<'_>,
    triangles: &[[I; 3]],
    nt: usize,
    flags: &[u8],
    border_next: &[L],
    quadrics: &mut [VertexQuadric],
) {
    for t in 0..nt {
        let tr = tri(triangles, t);
        for e in 0..3 {
            let (i0, i1, i2) = match e {
                0 => (tr[0], tr[1], tr[2]),
                1 => (tr[1], tr[2], tr[0]),
                _ => (tr[2], tr[0], tr[1]),
            };
            if flags_of(flags, i0) & flag::KIND != flag::BORDER || link(border_next, i0) != i1 {
                continue;
            }
            let (p0, p1, p2) = (frame.at(i0), frame.at(i1), frame.at(i2));
            let e10 = math::sub(p1, p0);
            let e20 = math::sub(p2, p0);
            let l2 = math::dot(e10, e10);
            let proj = math::dot(e20, e10);
            let perp = math::sub(math::scale(e20, l2), math::scale(e10, proj));
            let pl2 = math::dot(perp, perp);
            if !(l2 > math::TINY2 && pl2 > math::TINY2 && pl2.is_finite()) {
                continue;
            }
            let n = math::scale(perp, math::rsqrt(pl2));
            let w = math::sqrt(l2) * BORDER_WEIGHT;
            let q = quadric::add(&plane(n, 0.0, w), &triangle([p0, p1, p2], BORDER_WEIGHT));
            add_to(quadrics, i0, &q);
            add_to(quadrics, i1, &q);
        }
    }
}
