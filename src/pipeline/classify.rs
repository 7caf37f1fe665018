//! classify: each vertex's kind from its fan (meshoptimizer's `classifyVertices`, without
//! seams): manifold (one closed disk), border (one open fan; `border_next` is the vertex
//! across its open out-edge), locked (anything else: an edge with more than two triangles or
//! two wound the same way, or a pinched fan), gone (no triangle).

use super::{fan, flag, link, list, others, set_link, NONE};
use crate::index::Index;

/// Writes every vertex's kind and border successor; returns the number of locked vertices. `scratch`: two links per vertex,
/// contents on entry and exit meaningless.
#[inline(never)]
pub(super) fn classify<I: Index, L: Index>(
    triangles: &[[I; 3]],
    nt: usize,
    (first, lists): (&[L], &[L]),
    flags: &mut [u8],
    border_next: &mut [L],
    (counts, across): (&mut [L], &mut [L]),
) -> usize {
    let tris = triangles.get(..nt).unwrap_or(&[]);
    for c in counts.iter_mut() {
        *c = L::ZERO;
    }
    let mut locked = 0;
    for v in 0..flags.len() {
        set_link(border_next, v, NONE);
        let l = list(first, flags, lists, v);
        let kind = if l.is_empty() {
            flag::GONE
        } else {
            // The fan as (after, before) pairs; a larger fan is locked.
            let mut pairs = [(0u32, 0u32); MAX_FAN];
            let mut count = 0usize;
            for (_, tr, k) in fan(tris, (first, lists), flags, v) {
                match pairs.get_mut(count) {
                    Some(p) => {
                        let (x, y) = others(tr, k);
                        *p = (x as u32, y as u32);
                    }
                    None => {
                        count = MAX_FAN + 1;
                        break;
                    }
                }
                count += 1;
            }
            let (kind, end) = match pairs.get(..count) {
                Some(pairs) => kind_of(pairs, counts, across),
                None => (flag::LOCKED, NONE),
            };
            if kind == flag::BORDER {
                set_link(border_next, v, end);
            }
            if kind == flag::LOCKED {
                locked += 1;
            }
            kind
        };
        if let Some(f) = flags.get_mut(v) {
            *f = (*f & flag::HIGH) | kind;
        }
    }
    locked
}

/// Fans larger than this are locked.
const MAX_FAN: usize = 32;

/// Per neighbour in `counts`: triangles with it after v (low byte) and before v (times 256).
const IN: usize = 256;

#[inline]
fn bump<L: Index>(s: &mut [L], v: usize, by: usize) {
    if let Some(c) = s.get_mut(v) {
        *c = L::narrow(c.to_usize() + by);
    }
}

/// The kind of a vertex from its fan's (after, before) pairs, and for a border vertex the
/// vertex across its open out-edge. Linear: each neighbour's counts of triangles with it after
/// and before v in `counts`, and in `across` the pair with it before v (left zero / stale).
fn kind_of<L: Index>(pairs: &[(u32, u32)], counts: &mut [L], across: &mut [L]) -> (u8, usize) {
    for (i, &(x, y)) in pairs.iter().enumerate() {
        let (x, y) = (x as usize, y as usize);
        bump(counts, x, 1);
        bump(counts, y, IN);
        set_link(across, y, i);
    }
    let (mut open_out, mut open_in, mut start, mut end, mut bad) = (0, 0, 0, NONE, false);
    for (i, &(x, y)) in pairs.iter().enumerate() {
        let (x, y) = (x as usize, y as usize);
        let (cx, cy) = (link(counts, x), link(counts, y));
        // x: once after v, at most once before; y: once before, at most once after.
        if cx % IN != 1 || cx / IN > 1 || cy / IN != 1 || cy % IN > 1 {
            bad = true;
        }
        if cx / IN == 0 {
            open_out += 1;
            end = x;
        }
        if cy % IN == 0 {
            open_in += 1;
            start = i;
        }
    }
    let mut steps = 0usize;
    if !bad && open_out == open_in && open_out <= 1 {
        // One fan? Walk it across its spokes from the open end (or anywhere): the triangle
        // across spoke v-x has x before v.
        let mut cur = start;
        while steps <= pairs.len() {
            steps += 1;
            let Some(&(x, _)) = pairs.get(cur) else { break };
            let x = x as usize;
            if link(counts, x) / IN == 0 {
                break;
            }
            let j = link(across, x);
            if j == start {
                break;
            }
            cur = j;
        }
    }
    for &(x, y) in pairs {
        set_link(counts, x as usize, 0);
        set_link(counts, y as usize, 0);
    }
    if bad || open_out != open_in || open_out > 1 || steps != pairs.len() {
        (flag::LOCKED, NONE)
    } else if open_out == 1 {
        (flag::BORDER, end)
    } else {
        (flag::MANIFOLD, NONE)
    }
}
