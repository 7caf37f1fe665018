//! compact: the live triangles to the front of the buffer (meshoptimizer's
//! `remapIndexBuffer`; the collapses already wrote their targets), and the pass's locks off.

use super::{dead, flag, tri};
use crate::index::Index;

/// Moves the triangles of the first `nt` without a repeated index to the front, in order;
/// returns how many there are and how many were dropped.
#[inline(never)]
pub(super) fn compact<I: Index>(triangles: &mut [[I; 3]], nt: usize) -> (usize, usize) {
    let mut w = 0;
    for r in 0..nt {
        let tr = tri(triangles, r);
        if dead(tr) {
            continue;
        }
        if w != r {
            if let Some(&x) = triangles.get(r) {
                if let Some(y) = triangles.get_mut(w) {
                    *y = x;
                }
            }
        }
        w += 1;
    }
    (w, nt - w)
}

/// Clears the pass's locks and marks.
#[inline(never)]
pub(super) fn unlock(flags: &mut [u8]) {
    for f in flags.iter_mut() {
        *f &= flag::KIND | flag::HIGH;
    }
}
