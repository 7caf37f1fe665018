//! pick: each vertex's cheapest collapse its kind allows, priced from its quadric at the
//! target (meshoptimizer's `pickEdgeCollapses` and `rankEdgeCollapses`, reduced to one
//! candidate per source vertex). Kinds (meshoptimizer's `kCanCollapse` without seams): a
//! manifold vertex may collapse onto any neighbour; a border vertex only onto a border vertex
//! along its border edge (either direction); a locked vertex never moves.

use super::{flag, flags_of, link, set_link, tri, Frame};
use crate::index::Index;
use crate::quadric::{self, VertexQuadric};

/// Offers `a → b` at its price, keeping the cheaper (ties: the lower target).
#[inline]
fn offer<L: Index>(
    frame: &Frame<'_>,
    quadrics: &[VertexQuadric],
    target: &mut [L],
    cost: &mut [f32],
    a: usize,
    b: usize,
) {
    let Some(q) = quadrics.get(a) else { return };
    let e = quadric::error(q, frame.at(b));
    let Some(c) = cost.get_mut(a) else { return };
    if e < *c || (e == *c && b < link(target, a)) {
        *c = e;
        set_link(target, a, b);
    }
}

/// Prices every allowed collapse of the live triangles' edges.
pub(super) fn pick<I: Index, L: Index>(
    frame: &Frame<'_>,
    triangles: &[[I; 3]],
    flags: &[u8],
    border_next: &[L],
    quadrics: &[VertexQuadric],
    target: &mut [L],
    cost: &mut [f32],
) {
    for (t, c) in target.iter_mut().zip(cost.iter_mut()) {
        *t = L::NIL;
        *c = f32::INFINITY;
    }
    for t in 0..triangles.len() {
        let tr = tri(triangles, t);
        for e in 0..3 {
            let (i0, i1) = match e {
                0 => (tr[0], tr[1]),
                1 => (tr[1], tr[2]),
                _ => (tr[2], tr[0]),
            };
            let k0 = flags_of(flags, i0) & flag::KIND;
            if k0 == flag::MANIFOLD {
                // The other direction comes from the triangle across.
                offer(frame, quadrics, target, cost, i0, i1);
            } else if k0 == flag::BORDER
                && flags_of(flags, i1) & flag::KIND == flag::BORDER
                && link(border_next, i0) == i1
            {
                // An open edge has no triangle across: both directions here.
                offer(frame, quadrics, target, cost, i0, i1);
                offer(frame, quadrics, target, cost, i1, i0);
            }
        }
    }
}
