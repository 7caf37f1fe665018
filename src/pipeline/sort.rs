//! sort: the candidates in cost order by one counting sort on the top bits of the float cost
//! (meshoptimizer's `sortEdgeCollapses`: 8 bits of exponent and 4 of mantissa), stable, so
//! equal keys stay in vertex order.

use super::BINS;
use crate::index::Index;

/// `2⁻⁴⁸`'s 12-bit key: costs below it share bin 0.
const BASE: usize = (127 - 48) << 4;

/// The bin of a non-negative cost.
#[inline]
pub(super) fn key(cost: f32) -> usize {
    let k = (cost.to_bits() >> 19) as usize & 0xfff;
    let k = k.saturating_sub(BASE);
    if k < BINS {
        k
    } else {
        BINS - 1
    }
}

/// Writes the vertices with a candidate into `order` by cost, from the key counts that pick
/// left in `histogram`; returns how many.
#[inline(never)]
pub(super) fn sort<L: Index>(
    target: &[L],
    cost: &[f32],
    order: &mut [L],
    histogram: &mut [L; BINS],
) -> usize {
    let mut sum = 0usize;
    for h in histogram.iter_mut() {
        let n = h.to_usize();
        *h = L::narrow(sum);
        sum += n;
    }
    for (v, (t, c)) in target.iter().zip(cost).enumerate() {
        if *t == L::NIL {
            continue;
        }
        if let Some(h) = histogram.get_mut(key(*c)) {
            let at = h.to_usize();
            if let Some(o) = order.get_mut(at) {
                *o = L::narrow(v);
            }
            *h = L::narrow(at + 1);
        }
    }
    sum
}
