//! classify: each vertex's kind from its fan (meshoptimizer's `classifyVertices`, without
//! seams): manifold (one closed disk), border (one open fan; `border_next` is the vertex
//! across its open out-edge), locked (anything else: an edge with more than two triangles or
//! two wound the same way, or a pinched fan), gone (no triangle).

use super::{fan, flag, list, others, set_link, NONE};
use crate::index::Index;

/// Writes every vertex's kind and border successor; returns the number of locked vertices.
#[inline(never)]
pub(super) fn classify<I: Index, L: Index>(
    triangles: &[[I; 3]],
    nt: usize,
    (first, lists): (&[L], &[L]),
    flags: &mut [u8],
    border_next: &mut [L],
) -> usize {
    let tris = triangles.get(..nt).unwrap_or(&[]);
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
                Some(pairs) => kind_of(pairs),
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

/// Slots of the small hash table of a fan's before-vertices (twice the largest fan).
const SLOTS: usize = 2 * MAX_FAN;

/// The kind of a vertex from its fan's (after, before) pairs, and for a border vertex the
/// vertex across its open out-edge. The triangle across spoke v-x is the one with x before v,
/// found in a small hash table of the before-vertices. Manifold or border needs each
/// before-vertex once and each match taken once (a repeated after-vertex either takes a match
/// twice or leaves two triangles without one), as many unmatched after- as before-vertices
/// (at most one: the open ends), and following the matches from the open end (or anywhere)
/// must visit every triangle. No scratch memory.
fn kind_of(pairs: &[(u32, u32)]) -> (u8, usize) {
    let n = pairs.len();
    let hash = |v: u32| (v.wrapping_mul(0x9e37_79b1) >> 26) as usize;
    let mut keys = [u32::MAX; SLOTS];
    let mut vals = [0u8; SLOTS];
    let mut bad = false;
    for (j, &(_, y)) in pairs.iter().enumerate() {
        let mut h = hash(y);
        for _ in 0..SLOTS {
            match keys.get(h) {
                Some(&k) if k == u32::MAX => {
                    if let (Some(k), Some(v)) = (keys.get_mut(h), vals.get_mut(h)) {
                        *k = y;
                        *v = j as u8;
                    }
                    break;
                }
                Some(&k) if k == y => {
                    bad = true;
                    break;
                }
                _ => h = (h + 1) % SLOTS,
            }
        }
    }
    let mut next = [u8::MAX; MAX_FAN];
    let (mut seen, mut open_out, mut end) = (0u32, 0, NONE);
    for (&(x, _), nx) in pairs.iter().zip(next.iter_mut()) {
        let mut h = hash(x);
        let mut found = None;
        for _ in 0..SLOTS {
            match keys.get(h) {
                Some(&k) if k == x => {
                    found = vals.get(h).copied();
                    break;
                }
                Some(&k) if k != u32::MAX => h = (h + 1) % SLOTS,
                _ => break,
            }
        }
        match found {
            Some(j) => {
                let bit = 1u32.checked_shl(j as u32).unwrap_or(0);
                bad |= seen & bit != 0;
                seen |= bit;
                *nx = j;
            }
            None => {
                open_out += 1;
                end = x as usize;
            }
        }
    }
    let all = if n >= 32 { u32::MAX } else { (1u32 << n) - 1 };
    let open = all & !seen;
    let open_in = open.count_ones();
    if bad || open_out != open_in || open_out > 1 {
        return (flag::LOCKED, NONE);
    }
    let start = if open == 0 {
        0
    } else {
        31 - open.leading_zeros() as usize
    };
    let (mut cur, mut steps) = (start, 0usize);
    while steps <= n {
        steps += 1;
        match next.get(cur) {
            Some(&j) if (j as usize) < n && j as usize != start => cur = j as usize,
            _ => break,
        }
    }
    if steps != n {
        (flag::LOCKED, NONE)
    } else if open_out == 1 {
        (flag::BORDER, end)
    } else {
        (flag::MANIFOLD, NONE)
    }
}
