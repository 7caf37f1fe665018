//! classify: each vertex's kind from its fan (meshoptimizer's `classifyVertices`, without
//! seams): manifold (one closed disk), border (one open fan; `border_next` is the vertex
//! across its open out-edge), locked (anything else: an edge with more than two triangles or
//! two wound the same way, or a pinched fan), gone (no triangle).

use super::{fan, flag, link, others, set_link, slot, tri, NONE};
use crate::index::Index;

/// Writes every vertex's kind and border successor; returns the number of locked vertices.
pub(super) fn classify<I: Index, L: Index>(
    triangles: &[[I; 3]],
    nt: usize,
    head: &[L],
    next: &[[L; 3]],
    flags: &mut [u8],
    border_next: &mut [L],
) -> usize {
    let tris = triangles.get(..nt).unwrap_or(&[]);
    let mut locked = 0;
    for (v, f) in flags.iter_mut().enumerate() {
        set_link(border_next, v, NONE);
        if link(head, v) == NONE {
            *f = flag::GONE;
            continue;
        }
        let (mut count, mut open_out, mut open_in, mut bad) = (0usize, 0, 0, false);
        let (mut out_end, mut start) = (NONE, NONE);
        for (t, tr, k) in fan(tris, next, head, v) {
            count += 1;
            let (x, y) = others(tr, k);
            // In v's fan: how many triangles have x after v, x before v, y before, y after.
            let (mut x_out, mut x_in, mut y_in, mut y_out) = (0, 0, 0, 0);
            for (_, s, j) in fan(tris, next, head, v) {
                let (a, b) = others(s, j);
                x_out += usize::from(a == x);
                x_in += usize::from(b == x);
                y_in += usize::from(b == y);
                y_out += usize::from(a == y);
            }
            if x_out != 1 || y_in != 1 || x_in > 1 || y_out > 1 {
                bad = true;
                break;
            }
            if x_in == 0 {
                open_out += 1;
                out_end = x;
            }
            if y_out == 0 {
                open_in += 1;
                start = t;
            }
        }
        let kind = if bad || open_out != open_in || open_out > 1 {
            flag::LOCKED
        } else {
            // One fan? Walk it across its spokes from the open end (or anywhere).
            let first = if start == NONE { link(head, v) } else { start };
            let mut cur = first;
            let mut steps = 0usize;
            let mut guard = count + 1;
            while cur != NONE && guard > 0 {
                guard -= 1;
                steps += 1;
                let tr = tri(tris, cur);
                let Some(k) = slot(tr, v) else { break };
                let (x, _) = others(tr, k);
                // The triangle across spoke v-x has x before v.
                cur = fan(tris, next, head, v)
                    .find(|(_, s, j)| others(*s, *j).1 == x)
                    .map_or(NONE, |(t, _, _)| t);
                if cur == first {
                    break;
                }
            }
            if steps != count {
                flag::LOCKED
            } else if open_out == 1 {
                set_link(border_next, v, out_end);
                flag::BORDER
            } else {
                flag::MANIFOLD
            }
        };
        if kind == flag::LOCKED {
            locked += 1;
        }
        *f = kind;
    }
    locked
}
