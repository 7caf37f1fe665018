//! pick: each vertex's cheapest collapse its kind allows, priced from its quadric at the
//! target (meshoptimizer's `pickEdgeCollapses` and `rankEdgeCollapses`, reduced to one
//! candidate per source vertex). Kinds (meshoptimizer's `kCanCollapse` without seams): a
//! manifold vertex may collapse onto any neighbour; a border vertex only onto a border vertex
//! along its border edge (either direction); a locked vertex never moves.

use super::{flag, flags_of, link, set_link, tri, Frame};
use crate::index::Index;
use crate::math::V3;
use crate::quadric::{self, VertexQuadric};

/// Offers `a → b` (b at `pb`) at its price, keeping the cheaper (ties: the lower target).
#[inline]
fn offer<L: Index>(
    quadrics: &[VertexQuadric],
    target: &mut [L],
    cost: &mut [f32],
    a: usize,
    b: usize,
    pb: V3,
) {
    let Some(q) = quadrics.get(a) else { return };
    let e = quadric::error(q, pb);
    let Some(c) = cost.get_mut(a) else { return };
    if e < *c || (e == *c && b < link(target, a)) {
        *c = e;
        set_link(target, a, b);
    }
}

/// Prices every allowed collapse of the live triangles' edges.
#[inline(never)]
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
        let k = tr.map(|v| flags_of(flags, v) & flag::KIND);
        if k == [flag::LOCKED; 3] {
            continue;
        }
        let p = tr.map(|v| frame.at(v));
        for (e0, e1) in [(0, 1), (1, 2), (2, 0)] {
            let (Some(&i0), Some(&i1), Some(&k0), Some(&k1), Some(&p0), Some(&p1)) = (
                tr.get(e0),
                tr.get(e1),
                k.get(e0),
                k.get(e1),
                p.get(e0),
                p.get(e1),
            ) else {
                continue;
            };
            let free = |k: u8| {
                k == flag::MANIFOLD
                    || (!const { super::perform::on("border") } && k == flag::BORDER)
                    || (!const { super::perform::on("locked") } && k == flag::LOCKED)
            };
            if free(k0) {
                // The other direction comes from the triangle across.
                offer(quadrics, target, cost, i0, i1, p1);
            } else if k0 == flag::BORDER && k1 == flag::BORDER && link(border_next, i0) == i1 {
                // An open edge has no triangle across: both directions here.
                offer(quadrics, target, cost, i0, i1, p1);
                offer(quadrics, target, cost, i1, i0, p0);
            }
        }
    }
}
