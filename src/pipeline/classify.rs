//! classify: each vertex's kind from its fan (meshoptimizer's `classifyVertices`, without
//! seams): manifold (one closed disk), border (one open fan; `border_next` is the vertex
//! across its open out-edge), locked (anything else: an edge with more than two triangles or
//! two wound the same way, or a pinched fan), gone (no triangle).

use super::{fan, flag, link, others, set_link, NONE};
use crate::index::Index;

/// Writes every vertex's kind and border successor; returns the number of locked vertices.
#[inline(never)]
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
        // The fan as (after, before) pairs; a larger fan is locked.
        let mut pairs = [(NONE, NONE); MAX_FAN];
        let mut count = 0usize;
        for (_, tr, k) in fan(tris, next, head, v) {
            match pairs.get_mut(count) {
                Some(p) => *p = others(tr, k),
                None => {
                    count = MAX_FAN + 1;
                    break;
                }
            }
            count += 1;
        }
        let kind = match pairs.get(..count) {
            Some(pairs) => kind_of(pairs),
            None => flag::LOCKED,
        };
        if let (flag::BORDER, Some(end)) = (kind, pairs.get(..count).and_then(open_end)) {
            set_link(border_next, v, end);
        }
        if kind == flag::LOCKED {
            locked += 1;
        }
        *f = kind;
    }
    locked
}

/// Fans larger than this are locked.
const MAX_FAN: usize = 64;

/// The kind of a vertex from its fan's (after, before) pairs.
fn kind_of(pairs: &[(usize, usize)]) -> u8 {
    let (mut open_out, mut open_in, mut start) = (0, 0, 0);
    for (i, &(x, y)) in pairs.iter().enumerate() {
        // How many triangles have x after v, x before v, y before, y after.
        let (mut x_out, mut x_in, mut y_in, mut y_out) = (0, 0, 0, 0);
        for &(a, b) in pairs {
            x_out += usize::from(a == x);
            x_in += usize::from(b == x);
            y_in += usize::from(b == y);
            y_out += usize::from(a == y);
        }
        if x_out != 1 || y_in != 1 || x_in > 1 || y_out > 1 {
            return flag::LOCKED;
        }
        open_out += usize::from(x_in == 0);
        if y_out == 0 {
            open_in += 1;
            start = i;
        }
    }
    if open_out != open_in || open_out > 1 {
        return flag::LOCKED;
    }
    // One fan? Walk it across its spokes from the open end (or anywhere): the triangle
    // across spoke v-x has x before v.
    let mut cur = start;
    let mut steps = 0usize;
    while steps <= pairs.len() {
        steps += 1;
        let Some(&(x, _)) = pairs.get(cur) else { break };
        match pairs.iter().position(|&(_, y)| y == x) {
            Some(j) if j != start => cur = j,
            _ => break,
        }
    }
    if steps != pairs.len() {
        flag::LOCKED
    } else if open_out == 1 {
        flag::BORDER
    } else {
        flag::MANIFOLD
    }
}

/// The vertex across the open out-edge of a border fan.
fn open_end(pairs: &[(usize, usize)]) -> Option<usize> {
    pairs
        .iter()
        .find(|&&(x, _)| !pairs.iter().any(|&(_, y)| y == x))
        .map(|&(x, _)| x)
}
