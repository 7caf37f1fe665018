//! Schroeder's classification of a vertex (simple, boundary, interior edge, corner, complex)
//! and its distance criterion, from its fan in fan order.

use crate::index::Index;
use crate::math;
use crate::mesh::{flag, Mesh, NIL};

use super::*;

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
