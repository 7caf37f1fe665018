//! compact: the live triangles to the front of the buffer (meshoptimizer's
//! `remapIndexBuffer`; the collapses already wrote their targets), and the pass's locks off.

use super::{dead, flag};
use crate::index::Index;

/// Moves the triangles of the first `nt` without a repeated index to the front, in order,
/// counting their corners per vertex in `counts` (the fan lists' first pass, in the
/// candidates' cost array, free between a pass and the next pick); returns how
/// many there are and how many were dropped.
#[inline(never)]
pub(super) fn compact<I: Index>(
    triangles: &mut [[I; 3]],
    nt: usize,
    counts: &mut [u32],
) -> (usize, usize) {
    compact_with::<I, false>((triangles, &mut []), nt, counts)
}

/// [`compact`] with wedges: each triangle's wedges move with it.
#[inline(never)]
pub(super) fn compact_wedges<I: Index>(
    (triangles, wedges): (&mut [[I; 3]], &mut [[I; 3]]),
    nt: usize,
    counts: &mut [u32],
) -> (usize, usize) {
    compact_with::<I, true>((triangles, wedges), nt, counts)
}

#[inline(always)]
fn compact_with<I: Index, const W: bool>(
    (triangles, wedges): (&mut [[I; 3]], &mut [[I; 3]]),
    nt: usize,
    counts: &mut [u32],
) -> (usize, usize) {
    for c in counts.iter_mut() {
        *c = 0;
    }
    let mut w = 0;
    for r in 0..nt {
        let Some(&x) = triangles.get(r) else { break };
        let tr = [x[0].to_usize(), x[1].to_usize(), x[2].to_usize()];
        if dead(tr) {
            continue;
        }
        for v in tr {
            if let Some(c) = counts.get_mut(v) {
                // At most `nt` corners per vertex: no wrap.
                *c = c.wrapping_add(1);
            }
        }
        if w != r {
            if let Some(y) = triangles.get_mut(w) {
                *y = x;
            }
            if W {
                if let Some(&c) = wedges.get(r) {
                    if let Some(d) = wedges.get_mut(w) {
                        *d = c;
                    }
                }
            }
        }
        w += 1;
    }
    (w, nt - w)
}

/// Clears the pass's locks and marks (not the dirty bits: fill reads them).
#[inline(never)]
pub(super) fn unlock(flags: &mut [u8]) {
    for f in flags.iter_mut() {
        *f &= flag::KIND | flag::HIGH | flag::DIRTY | flag::SEAM;
    }
}
