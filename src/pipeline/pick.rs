//! pick: each vertex's cheapest collapse its kind allows, priced from its quadric (in its own
//! frame) at the target (meshoptimizer's `pickEdgeCollapses` and `rankEdgeCollapses`, reduced to one
//! candidate per source vertex). Kinds (meshoptimizer's `kCanCollapse`): a manifold vertex
//! may collapse onto any neighbour; a seam vertex (with wedges) only onto a seam or locked
//! neighbour; a border vertex only onto a border vertex along its border edge (either
//! direction); a locked vertex never moves.

use super::fill::Quadrics;
use super::geometry::Geometry;
use super::{along, fan, flag, flags_of, others, BINS, NONE};
use crate::index::Index;

/// Prices every allowed collapse of each vertex along its fan's edges: a free vertex towards
/// the vertex after it in each triangle (the triangle across offers the other direction), a
/// border vertex along its open edges only, either way. One vertex at a time, so its quadric
/// and its best candidate stay in registers; ties go to the lower target. Counts each
/// candidate's sort key in `histogram` (the counting sort's first pass).
#[allow(clippy::too_many_arguments)]
#[inline(never)]
pub(super) fn pick<I: Index, L: Index, G: Geometry, Q: Quadrics<G>, const W: bool>(
    frame: &G,
    triangles: &[[I; 3]],
    adj: (&[L], &[L]),
    flags: &[u8],
    border_next: &[L],
    (quadrics, mean): (&Q, G::Area),
    (target, cost): (&mut [L], &mut [u32]),
    histogram: &mut [L; BINS],
) {
    for h in histogram.iter_mut() {
        *h = L::ZERO;
    }
    let free = |k: u8| {
        k == flag::MANIFOLD
            || (!const { super::on("border") } && k == flag::BORDER)
            || (!const { super::on("locked") } && k == flag::LOCKED)
    };
    // The lean mode's neighbours of one fan, reused vertex to vertex.
    let mut seen = [(0u32, G::ORIGIN); FAN];
    for (a, (ta, ca)) in target.iter_mut().zip(cost.iter_mut()).enumerate() {
        let ka = flags_of(flags, a) & flag::KIND;
        let (mut best, mut to) = (G::COST_MAX, NONE);
        let border = !free(ka) && ka == flag::BORDER;
        // Without stored quadrics, a free vertex's quadric and offers come from one walk of
        // its fan (a border vertex's offers need its open edges, found from the fan again).
        // A seam vertex offers only its seam's direction (see `along`).
        let seam = W && flags_of(flags, a) & flag::SEAM != 0;
        let once = if !Q::STORES_BORDERS && ka != flag::BORDER && free(ka) && !seam {
            once(frame, triangles, adj, flags, a, &mut seen)
        } else {
            None
        };
        if let Some((b, e, q)) = once {
            if b != NONE {
                // The factor is a's own: it does not change which target is cheapest.
                best = frame.price(mean, &q, e);
                to = b;
            }
        } else if free(ka) || border {
            let q = quadrics.of::<I, L, W>(frame, triangles, adj, flags, border_next, a);
            let pa = frame.at(a);
            let mut least = G::RAW_MAX;
            let mut offer = |b: usize| {
                let e = frame.raw(&q, pa, frame.at(b));
                if e < least || (e == least && b < to) {
                    least = e;
                    to = b;
                }
            };
            let next = if border {
                quadrics.next(triangles, adj, flags, border_next, a)
            } else {
                NONE
            };
            for (_, tr, k) in fan(triangles, adj, flags, a) {
                let (x, y) = others(tr, k);
                if !border {
                    if !seam || along(flags, x) {
                        offer(x);
                    }
                    continue;
                }
                // An open edge has no triangle across: both directions from its one triangle.
                if x == next && flags_of(flags, x) & flag::KIND == flag::BORDER {
                    offer(x);
                }
                if quadrics.enters(triangles, adj, flags, border_next, y, a) {
                    offer(y);
                }
            }
            // The factor is a's own: it does not change which target is cheapest.
            if to != NONE {
                best = frame.price(mean, &q, least);
            }
        }
        *ca = G::cost_bits(best);
        *ta = if to == NONE {
            L::NIL
        } else {
            if let Some(h) = histogram.get_mut(G::key(G::cost_bits(best))) {
                *h = L::narrow(h.to_usize() + 1);
            }
            L::narrow(to)
        };
    }
}

/// A free vertex's cheapest target (`NONE` without one), its error and its quadric from one
/// walk of its fan: the quadric summed in fan order, as
/// [`vertex_quadric`](super::fill::vertex_quadric) sums it, each neighbour kept in `seen` for
/// the offers. `None` for a fan larger than `seen` (the caller walks it twice).
#[inline]
fn once<I: Index, L: Index, G: Geometry>(
    frame: &G,
    triangles: &[[I; 3]],
    adj: (&[L], &[L]),
    flags: &[u8],
    a: usize,
    seen: &mut [(u32, G::P); FAN],
) -> Option<(usize, G::Raw, G::Q)> {
    let mut q = G::EMPTY;
    let mut n = 0;
    let pa = frame.at(a);
    for (_, tr, k) in fan(triangles, adj, flags, a) {
        let (x, y) = others(tr, k);
        let px = frame.at(x);
        *seen.get_mut(n)? = (x as u32, px);
        n += 1;
        // No triangle is dead at pick (compact dropped them).
        frame.face(&mut q, [pa, px, frame.at(y)]);
    }
    let q = frame.finish(q);
    let (mut best, mut to) = (G::RAW_MAX, NONE);
    for &(b, pb) in seen.get(..n)? {
        let b = b as usize;
        let e = frame.raw(&q, pa, pb);
        if e < best || (e == best && b < to) {
            best = e;
            to = b;
        }
    }
    Some((to, best, q))
}

/// Neighbours one fan walk keeps for the lean mode's offers (a larger fan is walked twice).
const FAN: usize = 32;
