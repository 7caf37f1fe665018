//! build: validation (before anything is written), corner lists, duplicate triangles.

use super::{link as get_link, slot, tri, Frame, NONE};
use crate::error::Capacity;
use crate::index::Index;
use crate::Error;

/// Checks capacities, indices and the positions the triangles use, and measures their
/// bounding box (the unit frame). Reads only.
#[inline(never)]
pub(super) fn validate<'p, I: Index>(
    positions: &'p [[f32; 3]],
    triangles: &[[I; 3]],
    vertices: usize,
    capacity: usize,
) -> Result<Frame<'p>, Error> {
    if positions.len() > vertices {
        return Err(Error::Capacity {
            what: Capacity::Vertices,
            needed: positions.len(),
            available: vertices,
        });
    }
    if triangles.len() > capacity {
        return Err(Error::Capacity {
            what: Capacity::Triangles,
            needed: triangles.len(),
            available: capacity,
        });
    }
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

/// Corner lists of the first `nt` triangles: `head[v]` the first triangle holding `v`,
/// `next[t][k]` the next triangle holding `t`'s vertex in slot `k`. Each list runs from the
/// highest triangle number down.
#[inline(never)]
pub(super) fn link<I: Index, L: Index>(
    triangles: &[[I; 3]],
    nt: usize,
    head: &mut [L],
    next: &mut [[L; 3]],
) {
    for h in head.iter_mut() {
        *h = L::NIL;
    }
    for (t, (tr, n)) in triangles.iter().zip(next.iter_mut()).take(nt).enumerate() {
        for (i, nk) in tr.iter().zip(n.iter_mut()) {
            let v = i.to_usize();
            if let Some(h) = head.get_mut(v) {
                *nk = *h;
                *h = L::narrow(t);
            }
        }
    }
}

/// Marks every triangle with the vertex set of a lower-numbered one (either winding: a
/// repeated copy, or the back of a double-sided triangle) by writing it degenerate; returns
/// how many. Highest first: a list walk from triangle `t` visits only lower numbers, which
/// are not yet written.
#[inline(never)]
pub(super) fn dedupe<I: Index, L: Index>(
    triangles: &mut [[I; 3]],
    nt: usize,
    next: &[[L; 3]],
) -> usize {
    let mut count = 0;
    for t in (0..nt).rev() {
        let tr = tri(triangles, t);
        let v = tr[0];
        let mut u = next.get(t).map_or(NONE, |n| get_link(n, 0));
        let mut guard = nt;
        let mut dup = false;
        while u != NONE && guard > 0 {
            guard -= 1;
            let s = tri(triangles, u);
            if slot(s, tr[1]).is_some() && slot(s, tr[2]).is_some() {
                dup = true;
                break;
            }
            let Some(k) = slot(s, v) else { break };
            u = next.get(u).map_or(NONE, |n| get_link(n, k));
        }
        if dup {
            if let Some(x) = triangles.get_mut(t) {
                x[1] = x[0];
                x[2] = x[0];
            }
            count += 1;
        }
    }
    count
}
