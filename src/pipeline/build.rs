//! build: fan lists (the validation before anything is written is the arithmetic's: `float`,
//! `integer`).

use super::{bump_end, set_end};
use crate::error::Capacity;
use crate::index::Index;
use crate::Error;

/// The mesh's vertices and triangles against the workspace's capacities: the first check of
/// either arithmetic's validation, before anything is written.
#[inline]
pub(super) fn fits(
    (vertices, triangles): (usize, usize),
    (cv, ct): (usize, usize),
) -> Result<(), Error> {
    if vertices > cv {
        return Err(Error::Capacity {
            what: Capacity::Vertices,
            needed: vertices,
            available: cv,
        });
    }
    if triangles > ct {
        return Err(Error::Capacity {
            what: Capacity::Triangles,
            needed: triangles,
            available: ct,
        });
    }
    Ok(())
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
