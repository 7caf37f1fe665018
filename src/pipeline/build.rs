//! build: validation (before anything is written), fan lists.

use super::float::Frame;
use super::{bump_end, set_end};
use crate::error::Capacity;
use crate::index::Index;
use crate::Error;

/// Checks capacities, indices and the positions the triangles use, and measures their
/// bounding box (the unit frame). Writes only `used` (scratch: the flag bytes, which classify
/// rewrites).
#[inline(never)]
pub(super) fn validate<'p, I: Index>(
    positions: &'p [[f32; 3]],
    triangles: &[[I; 3]],
    (vertices, capacity): (usize, usize),
    used: &mut [u8],
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

/// Fan lists of the first `nt` triangles (a counting sort of their corners by vertex, as
/// meshoptimizer's `buildTriangleAdjacency`), from the corner counts that compact left in
/// `scratch` (the cost array, free until the next pick; it then holds
/// each list's write position): `v`'s list is `lists[end(v - 1)..end(v)]`, its triangles from
/// the highest number down.
#[inline(never)]
pub(super) fn link<I: Index, L: Index>(
    triangles: &[[I; 3]],
    nt: usize,
    (first, flags): (&mut [L], &mut [u8]),
    scratch: &mut [u32],
    lists: &mut [L],
) {
    let tris = triangles.get(..nt).unwrap_or(&[]);
    if u32::try_from(3 * nt).is_err() {
        return link_wide(tris, first, flags, scratch, lists);
    }
    // Each list's start as its write position, its end in `first` (below 3·nt: fits a u32).
    let mut sum = 0u32;
    for (v, c) in scratch.iter_mut().enumerate() {
        let count = *c;
        *c = sum;
        sum = sum.wrapping_add(count);
        set_end(first, flags, v, sum as usize);
    }
    // Filled from the start up, highest triangle first.
    for (t, tr) in tris.iter().enumerate().rev() {
        for i in tr {
            if let Some(c) = scratch.get_mut(i.to_usize()) {
                let s = *c;
                *c = s.wrapping_add(1);
                if let Some(x) = lists.get_mut(s as usize) {
                    *x = L::narrow(t);
                }
            }
        }
    }
}

/// [`link`] for more than `u32::MAX` list entries: the write positions in `first` and the
/// flag bytes, which end as the lists' ends.
#[cold]
fn link_wide<I: Index, L: Index>(
    tris: &[[I; 3]],
    first: &mut [L],
    flags: &mut [u8],
    counts: &[u32],
    lists: &mut [L],
) {
    let mut sum = 0;
    for (v, c) in counts.iter().enumerate() {
        set_end(first, flags, v, sum);
        sum += *c as usize;
    }
    for (t, tr) in tris.iter().enumerate().rev() {
        for i in tr {
            let s = bump_end(first, flags, i.to_usize());
            if let Some(x) = lists.get_mut(s) {
                *x = L::narrow(t);
            }
        }
    }
}
