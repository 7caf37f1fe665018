//! classify: each vertex's kind from its fan (meshoptimizer's `classifyVertices`, without
//! seams): manifold (one closed disk), border (one open fan; `border_next` is the vertex
//! across its open out-edge), locked (anything else: an edge with more than two triangles or
//! two wound the same way, or a pinched fan), gone (no triangle); and duplicate triangles
//! dropped on the way.

use super::{dead, flag, flags_of, list, others, set_link, slot, tri, NONE};
use crate::index::Index;

/// Writes every vertex's kind and border successor, and drops duplicate triangles: every
/// triangle with the vertex set of a lower-numbered one (either winding: a repeated copy, or
/// the back of a double-sided triangle) is written degenerate, seen from any of its vertices
/// (a duplicate is in all three fans with its original) and left out of the kinds. Returns
/// the numbers of locked vertices and of duplicates.
#[inline(never)]
pub(super) fn classify<I: Index, L: Index>(
    triangles: &mut [[I; 3]],
    nt: usize,
    (first, lists): (&[L], &[L]),
    flags: &mut [u8],
    border_next: &mut [L],
) -> (usize, usize) {
    let (mut locked, mut duplicates) = (0, 0);
    for v in 0..flags.len() {
        let l = list(first, flags, lists, v);
        let (kind, end) = match fast(triangles, nt, l, v) {
            Some(r) => r,
            None => slow(triangles, nt, l, v, &mut duplicates),
        };
        // `NONE` but for a border vertex.
        set_link(border_next, v, end);
        if kind == flag::LOCKED {
            locked += 1;
        }
        if let Some(f) = flags.get_mut(v) {
            *f = (*f & flag::HIGH) | kind;
        }
    }
    (locked, duplicates)
}

/// With wedges, after [`classify`]: a manifold vertex with two wedges in its fan is a seam
/// vertex ([`flag::SEAM`]); one with more (seams meet: no wedge of a kept vertex belongs to
/// every region), or a border vertex with more than one (a seam ends on the border), is
/// locked, as meshoptimizer locks its complex vertices. A border vertex locked here keeps its
/// successor (its open edge's planes). Returns how many it locked.
#[inline(never)]
pub(super) fn seams<I: Index, L: Index>(
    triangles: &[[I; 3]],
    wedges: &[[I; 3]],
    nt: usize,
    (first, lists): (&[L], &[L]),
    flags: &mut [u8],
) -> usize {
    let mut locked = 0;
    for v in 0..flags.len() {
        let kind = flags_of(flags, v) & flag::KIND;
        let l = list(first, flags, lists, v);
        let new = seam(triangles, wedges, nt, l, v, kind);
        if new != kind {
            if new == flag::LOCKED {
                locked += 1;
            }
            if let Some(f) = flags.get_mut(v) {
                *f = (*f & !flag::KIND) | new;
            }
        }
    }
    locked
}

/// [`seams`] for one vertex: its kind with the [`flag::SEAM`] bit.
fn seam<I: Index, L: Index>(
    triangles: &[[I; 3]],
    wedges: &[[I; 3]],
    nt: usize,
    l: &[L],
    v: usize,
    kind: u8,
) -> u8 {
    if kind != flag::MANIFOLD && kind != flag::BORDER {
        return kind;
    }
    let (mut first, mut second, mut more) = (NONE, NONE, false);
    for &t in l {
        let t = t.to_usize();
        let tr = tri(triangles, t);
        if t >= nt || dead(tr) {
            continue;
        }
        let Some(w) = slot(tr, v).and_then(|k| wedges.get(t).and_then(|w| w.get(k))) else {
            continue;
        };
        let w = w.to_usize();
        if first == NONE || w == first {
            first = w;
        } else if second == NONE || w == second {
            second = w;
        } else {
            more = true;
        }
    }
    match (kind, second != NONE, more) {
        (_, false, _) => kind,
        (flag::MANIFOLD, true, false) => kind | flag::SEAM,
        _ => flag::LOCKED,
    }
}

/// The kind of `v` from its fan as listed, when no triangle of the fan can be a duplicate:
/// two triangles with one vertex set repeat a before-vertex (same winding) or match each
/// other's spokes (opposite winding), and `kind_of` reports either. `None` then, or for a
/// fan larger than the buffer.
#[inline]
fn fast<I: Index, L: Index>(
    triangles: &[[I; 3]],
    nt: usize,
    l: &[L],
    v: usize,
) -> Option<(u8, usize)> {
    let mut pairs = heapless::Vec::<(u32, u32), MAX_FAN>::new();
    for &t in l {
        let t = t.to_usize();
        let Some(x) = triangles.get(t).filter(|_| t < nt) else {
            continue;
        };
        let tr = [x[0].to_usize(), x[1].to_usize(), x[2].to_usize()];
        if dead(tr) {
            continue;
        }
        let Some(k) = slot(tr, v) else { continue };
        let (x, y) = others(tr, k);
        pairs.push((x as u32, y as u32)).ok()?;
    }
    if pairs.is_empty() {
        return Some((flag::GONE, NONE));
    }
    let (kind, end, suspect) = kind_of(&pairs);
    (!suspect).then_some((kind, end))
}

/// The kind of `v` with its fan's duplicates dropped: lowest triangle first, each vertex set
/// once (as the ordered pair of the other two vertices); a larger fan is locked (its
/// duplicates found against its whole list).
fn slow<I: Index, L: Index>(
    triangles: &mut [[I; 3]],
    nt: usize,
    l: &[L],
    v: usize,
    duplicates: &mut usize,
) -> (u8, usize) {
    let mut pairs = heapless::Vec::<(u32, u32), MAX_FAN>::new();
    let mut sets = [(0u32, 0u32); MAX_FAN];
    for &t in l.iter().rev() {
        let t = t.to_usize();
        let tr = tri(triangles, t);
        if t >= nt || dead(tr) {
            continue;
        }
        let Some(k) = slot(tr, v) else { continue };
        let (x, y) = others(tr, k);
        let (x, y) = (x as u32, y as u32);
        let set = (x.min(y), x.max(y));
        let seen = sets.get(..pairs.len()).unwrap_or(&[]);
        if seen.contains(&set) {
            if drop(triangles, t) {
                *duplicates += 1;
            }
            continue;
        }
        if let Some(s) = sets.get_mut(pairs.len()) {
            *s = set;
        }
        if pairs.push((x, y)).is_err() {
            *duplicates += dedupe_all(triangles, nt, l);
            return (flag::LOCKED, NONE);
        }
    }
    if pairs.is_empty() {
        (flag::GONE, NONE)
    } else {
        let (kind, end, _) = kind_of(&pairs);
        (kind, end)
    }
}

/// Writes triangle `t` degenerate; whether it was there.
#[inline]
fn drop<I: Index>(triangles: &mut [[I; 3]], t: usize) -> bool {
    match triangles.get_mut(t) {
        Some(x) => {
            x[1] = x[0];
            x[2] = x[0];
            true
        }
        None => false,
    }
}

/// Duplicates in a fan too large for the pair buffer, against the whole list; returns how many
/// were dropped.
fn dedupe_all<I: Index, L: Index>(triangles: &mut [[I; 3]], nt: usize, l: &[L]) -> usize {
    let mut count = 0;
    for &t in l {
        let t = t.to_usize();
        let tr = tri(triangles, t);
        if t >= nt || dead(tr) {
            continue;
        }
        let dup = l.iter().any(|u| {
            let u = u.to_usize();
            u < t && {
                let s = tri(triangles, u);
                !dead(s) && tr.iter().all(|&w| slot(s, w).is_some())
            }
        });
        if dup && drop(triangles, t) {
            count += 1;
        }
    }
    count
}

/// Fans larger than this are locked.
const MAX_FAN: usize = 32;

/// The kind of a vertex from its fan's (after, before) pairs, and for a border vertex the
/// vertex across its open out-edge. The triangle across spoke v-x is the first one with x
/// before v, found by a linear search (a fan has a handful of triangles: cheaper than a hash
/// table to clear). Manifold or border needs each before-vertex once and each match taken
/// once (a repeated after-vertex either takes a match twice or leaves two triangles without
/// one), as many unmatched after- as before-vertices (at most one: the open ends), and
/// following the matches from the open end (or anywhere) must visit every triangle. No
/// scratch memory.
fn kind_of(pairs: &[(u32, u32)]) -> (u8, usize, bool) {
    let n = pairs.len();
    let mut bad = false;
    let mut next = [u8::MAX; MAX_FAN];
    let (mut seen, mut open_out, mut end) = (0u32, 0, NONE);
    for (&(x, _), nx) in pairs.iter().zip(next.iter_mut()) {
        let mut found = None;
        for (j, &(_, y)) in pairs.iter().enumerate() {
            if y == x {
                found = Some(j);
                break;
            }
        }
        match found {
            Some(j) => {
                let bit = 1u32.checked_shl(j as u32).unwrap_or(0);
                bad |= seen & bit != 0;
                seen |= bit;
                *nx = j as u8;
            }
            None => {
                open_out += 1;
                end = x as usize;
            }
        }
    }
    let all = if n >= 32 { u32::MAX } else { (1u32 << n) - 1 };
    // A repeated before-vertex: a search finds only its first triangle, so with every triangle
    // found there is none, and only a fan with an unmatched triangle needs the pairwise test.
    let repeated = seen != all
        && pairs
            .iter()
            .enumerate()
            .any(|(j, &(_, y))| pairs.iter().take(j).any(|&(_, z)| z == y));
    bad |= repeated;
    // Two triangles on each other's spokes: (v, x, y) and (v, y, x).
    let twins = || {
        next.iter()
            .take(n)
            .enumerate()
            .any(|(i, &j)| next.get(j as usize).is_some_and(|&k| k as usize == i))
    };
    let open = all & !seen;
    let open_in = open.count_ones();
    if bad || open_out != open_in || open_out > 1 {
        return (flag::LOCKED, NONE, repeated || twins());
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
    // One chain or one cycle of three or more through every triangle holds no pair of twins.
    if steps != n {
        (flag::LOCKED, NONE, repeated || twins())
    } else if open_out == 1 {
        (flag::BORDER, end, repeated)
    } else if n >= 3 {
        (flag::MANIFOLD, NONE, repeated)
    } else {
        (flag::MANIFOLD, NONE, repeated || twins())
    }
}
