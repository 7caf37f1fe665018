//! sort: the candidates in cost order by one counting sort on the top bits of the float cost
//! (meshoptimizer's `sortEdgeCollapses`: 8 bits of exponent and 4 of mantissa), stable, so
//! equal keys stay in vertex order.

use super::geometry::Geometry;
use super::BINS;
use crate::index::Index;

/// Writes the vertices with a candidate into `order` by cost, from the key counts that pick
/// left in `histogram`; returns how many.
#[inline(never)]
pub(super) fn sort<L: Index, G: Geometry>(
    target: &[L],
    cost: &[u32],
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
        if let Some(h) = histogram.get_mut(G::key(*c)) {
            let at = h.to_usize();
            if let Some(o) = order.get_mut(at) {
                *o = L::narrow(v);
            }
            *h = L::narrow(at + 1);
        }
    }
    sum
}
