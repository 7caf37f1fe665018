//! The hole's re-triangulation by recursive loop splitting (Schroeder, Zarge and Lorensen
//! 1992): a split line through the loop, accepted by the aspect ratio of its halves, then each
//! half in turn; the fit of a candidate fan to the removed vertex; and the plan that picks a
//! fill by [`Fill`].

use crate::math::{self, V3};

use super::*;

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
pub(super) fn fit2(pv: V3, pos: &[V3; MAX_RING], tris: &[[u8; 3]]) -> (f32, f32, f32) {
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
