//! perform: the pass's collapses in cost order (meshoptimizer's `performEdgeCollapses`).
//!
//! A candidate is skipped when either end is already an end of a collapse in this pass (so a
//! quadric or a fan is never read stale, and a vertex never moves twice), and the pass stops
//! at its goal or at its error goal: 1.5 times the cost of the candidate that would reach the
//! goal, once a sixth of the goal is done. Each candidate is checked on the current mesh, the
//! rules in order of cost, each where it can fire:
//!
//! 1. the edge: two triangles on a-b (one for a border vertex: its border edge);
//! 2. meshoptimizer's flip test (`hasTriangleFlip`) on each surviving triangle of a's fan:
//!    unnormalised normals before and after, refused when they turn by 75° or more (no square
//!    root: the dot product's sign and its square); and zero area (a cross product that
//!    rounding decides);
//! 3. the link condition by marks: a's neighbours marked, b's walked; a common neighbour
//!    other than the vertices opposite a-b would pinch the surface or add a non-manifold edge;
//!    no duplicate triangle (a's triangle on both opposite vertices against b's); a lone
//!    triangle is never collapsed away;
//! 4. no fold: each surviving triangle against its neighbours across its three edges after
//!    the collapse (unit normals' dot below -0.9, as the shared checker).
//!
//! A collapse rewrites a's corners to b in the caller's triangles (the two on a-b become
//! degenerate: compact drops them), adds a's quadric to b's, and locks both ends.

use super::{dead, fan, flag, flags_of, link, others, set_link, slot, tri, Frame, Stats, NONE};
use crate::index::Index;
use crate::legality::Reject;
use crate::math::{self, V3};
use crate::quadric::{self, VertexQuadric};

/// Below this a squared cross product has no direction.
const TINY: f32 = 1e-30;
/// `|n|² / (Σ edge²)²` below this: a normal that rounding decides (zero area).
const FLAT: f32 = 1e-8;
/// meshoptimizer's flip limit, `cos ≈ 0.25` (about 75°), squared.
const FLIP2: f32 = 0.0625;
/// The checker's fold limit, `-0.9`, squared.
const FOLD2: f32 = 0.81;

#[inline]
fn normal(p: [V3; 3]) -> V3 {
    math::cross(math::sub(p[1], p[0]), math::sub(p[2], p[0]))
}

/// The positions of `tr` after `a` moves onto `b` (at `pb`).
#[inline]
fn after(frame: &Frame<'_>, tr: [usize; 3], a: usize, pb: V3) -> [V3; 3] {
    tr.map(|v| if v == a { pb } else { frame.at(v) })
}

/// Whether two triangles sharing an edge fold onto each other (normals scaled by powers of
/// two first, so that no product leaves f32's range); a normal without direction counts as
/// folded (refused, never guessed).
#[inline]
fn folded(n1: V3, n2: V3) -> bool {
    let (u, v) = (math::pow2_normalize(n1), math::pow2_normalize(n2));
    let (u2, v2) = (math::dot(u, u), math::dot(v, v));
    if !(u2 > 0.0 && v2 > 0.0) {
        return true;
    }
    let d = math::dot(u, v);
    d < 0.0 && d * d > FOLD2 * u2 * v2
}

/// Runs one pass over `order`; returns the collapses made.
#[allow(clippy::too_many_arguments)]
pub(super) fn perform<I: Index, L: Index>(
    frame: &Frame<'_>,
    tris: &mut [[I; 3]],
    (head, next): (&[L], &[[L; 3]]),
    flags: &mut [u8],
    border_next: &mut [L],
    quadrics: &mut [VertexQuadric],
    (target, cost, order): (&[L], &[f32], &[L]),
    goal: usize,
    stats: &mut Stats,
) -> usize {
    let m = order.len();
    let cost_of = |v: usize| cost.get(v).copied().unwrap_or(f32::INFINITY);
    let mut edge_goal = goal / 2;
    let (mut removed, mut done, mut worst) = (0usize, 0usize, 0.0f32);
    for i in 0..m {
        if removed >= goal {
            break;
        }
        let a = link(order, i);
        let c = cost_of(a);
        let error_goal = if edge_goal < m {
            1.5 * cost_of(link(order, edge_goal))
        } else {
            f32::INFINITY
        };
        if c > error_goal && c > worst && removed > goal / 6 {
            break;
        }
        let b = link(target, a);
        if (flags_of(flags, a) | flags_of(flags, b)) & flag::PASS != 0 {
            continue;
        }
        if let Err(r) = check(frame, tris, (head, next), flags, a, b) {
            stats.rejected.count(r);
            edge_goal += 1;
            continue;
        }
        removed += collapse(tris, (head, next), flags, border_next, quadrics, a, b);
        done += 1;
        if c > worst {
            worst = c;
        }
    }
    stats.collapses += done;
    done
}

/// Every rule for `a → b` on the current mesh (module documentation, in that order).
fn check<I: Index, L: Index>(
    frame: &Frame<'_>,
    tris: &[[I; 3]],
    (head, next): (&[L], &[[L; 3]]),
    flags: &mut [u8],
    a: usize,
    b: usize,
) -> Result<(), Reject> {
    let (ka, kb) = (
        flags_of(flags, a) & flag::KIND,
        flags_of(flags, b) & flag::KIND,
    );
    if ka == flag::LOCKED || ka == flag::GONE || kb == flag::GONE {
        return Err(Reject::Locked);
    }
    if ka == flag::BORDER && kb != flag::BORDER {
        return Err(Reject::Boundary);
    }
    // 1. The edge and the vertices opposite it: o1 in (a, b, o1), o2 in (a, o2, b).
    let (mut o1, mut o2, mut n_ab, mut na) = (NONE, NONE, 0, 0);
    for (_, tr, k) in fan(tris, next, head, a) {
        if dead(tr) {
            continue;
        }
        na += 1;
        let (x, y) = others(tr, k);
        if x == b {
            o1 = y;
            n_ab += 1;
        } else if y == b {
            o2 = x;
            n_ab += 1;
        }
    }
    let want = if ka == flag::BORDER { 1 } else { 2 };
    if n_ab != want {
        return Err(if n_ab > 2 {
            Reject::Locked
        } else if ka == flag::BORDER {
            Reject::Boundary
        } else {
            Reject::Link
        });
    }

    // 2. Flip and zero area, on a's surviving triangles.
    let (pa, pb) = (frame.at(a), frame.at(b));
    for (_, tr, k) in fan(tris, next, head, a) {
        let (x, y) = others(tr, k);
        if dead(tr) || x == b || y == b {
            continue;
        }
        let (px, py) = (frame.at(x), frame.at(y));
        let n0 = normal([pa, px, py]);
        let n1 = normal([pb, px, py]);
        let abd = math::dot(n1, n1);
        let (ex, ey, exy) = (math::sub(px, pb), math::sub(py, pb), math::sub(px, py));
        let s = math::dot(ex, ex) + math::dot(ey, ey) + math::dot(exy, exy);
        if !(abd > TINY && abd > FLAT * s * s) {
            return Err(Reject::Sliver);
        }
        let ndp = math::dot(n0, n1);
        let abc = math::dot(n0, n0);
        if ndp <= 0.0 || ndp * ndp <= FLIP2 * abc * abd {
            return Err(Reject::NormalTurn);
        }
    }

    // 3. Link condition by marks; duplicates; b's triangles across b-o1 and b-o2.
    for (_, tr, k) in fan(tris, next, head, a) {
        if !dead(tr) {
            let (x, y) = others(tr, k);
            mark(flags, x, true);
            mark(flags, y, true);
        }
    }
    let mut verdict = Ok(());
    let (mut nb, mut on_o1, mut on_o2, mut opposite) = (0, 0, 0, false);
    for (_, tr, k) in fan(tris, next, head, b) {
        if dead(tr) {
            continue;
        }
        nb += 1;
        let (x, y) = others(tr, k);
        for w in [x, y] {
            if w != a && w != o1 && w != o2 && flags_of(flags, w) & flag::MARK != 0 {
                verdict = Err(Reject::Link);
            }
        }
        if x == a || y == a {
            continue;
        }
        on_o1 += usize::from(x == o1 || y == o1);
        on_o2 += usize::from(x == o2 || y == o2);
        opposite |= (x == o1 && y == o2) || (x == o2 && y == o1);
    }
    for (_, tr, k) in fan(tris, next, head, a) {
        if !dead(tr) {
            let (x, y) = others(tr, k);
            mark(flags, x, false);
            mark(flags, y, false);
        }
    }
    verdict?;
    if on_o1 > 1 || on_o2 > 1 {
        // b's edge to o1 or o2 is non-manifold (b locked).
        return Err(Reject::Locked);
    }
    if na == 1 && nb == 1 {
        // A lone triangle would vanish (a component, a boundary loop).
        return Err(Reject::Boundary);
    }
    if opposite
        && fan(tris, next, head, a).any(|(_, tr, k)| {
            let (x, y) = others(tr, k);
            !dead(tr) && ((x == o1 && y == o2) || (x == o2 && y == o1))
        })
    {
        return Err(Reject::Duplicate);
    }

    // 4. Folds: each survivor against its neighbours after the collapse.
    for (t, tr, k) in fan(tris, next, head, a) {
        let (x, y) = others(tr, k);
        if dead(tr) || x == b || y == b {
            continue;
        }
        let n1 = normal([pb, frame.at(x), frame.at(y)]);
        // Across the spoke to x (and to y when its partner dies): a's other triangle on it,
        // or b's when the one on a-x dies.
        for w in [x, y] {
            if w == y && w != o1 && w != o2 {
                continue;
            }
            for (u, s, _) in fan(tris, next, head, a) {
                if u != t && !dead(s) && slot(s, w).is_some() && slot(s, b).is_none() {
                    if folded(n1, normal(after(frame, s, a, pb))) {
                        return Err(Reject::Fold);
                    }
                }
            }
            if w == o1 || w == o2 {
                for (_, s, _) in fan(tris, next, head, b) {
                    if !dead(s) && slot(s, w).is_some() && slot(s, a).is_none() {
                        if folded(n1, normal(after(frame, s, a, pb))) {
                            return Err(Reject::Fold);
                        }
                    }
                }
            }
        }
        // Across the outer edge x-y: searched from an end whose list is current.
        let from = if flags_of(flags, x) & flag::PASS == 0 {
            x
        } else if flags_of(flags, y) & flag::PASS == 0 {
            y
        } else {
            return Err(Reject::Fold);
        };
        let other = if from == x { y } else { x };
        for (u, s, _) in fan(tris, next, head, from) {
            if u != t && !dead(s) && slot(s, other).is_some() {
                if folded(n1, normal(after(frame, s, a, pb))) {
                    return Err(Reject::Fold);
                }
            }
        }
    }
    Ok(())
}

#[inline]
fn mark(flags: &mut [u8], v: usize, on: bool) {
    if let Some(f) = flags.get_mut(v) {
        if on {
            *f |= flag::MARK;
        } else {
            *f &= !flag::MARK;
        }
    }
}

/// `a → b`: a's corners rewritten to b, a's quadric added to b's, border successors kept,
/// both ends locked for the pass. Returns the triangles that died.
fn collapse<I: Index, L: Index>(
    tris: &mut [[I; 3]],
    (head, next): (&[L], &[[L; 3]]),
    flags: &mut [u8],
    border_next: &mut [L],
    quadrics: &mut [VertexQuadric],
    a: usize,
    b: usize,
) -> usize {
    if flags_of(flags, a) & flag::KIND == flag::BORDER {
        if link(border_next, a) == b {
            // ... p → a → b ...: p's open edge now ends at b. p is the neighbour before a
            // that no triangle of a has after it.
            let mut p = NONE;
            for (_, tr, k) in fan(tris, next, head, a) {
                let (_, y) = others(tr, k);
                if !dead(tr) && !fan(tris, next, head, a).any(|(_, s, j)| !dead(s) && others(s, j).0 == y)
                {
                    p = y;
                }
            }
            if flags_of(flags, p) & flag::KIND == flag::BORDER {
                set_link(border_next, p, b);
            }
        } else {
            // ... b → a → q ...: b's open edge now ends at q.
            let q = link(border_next, a);
            set_link(border_next, b, q);
        }
    }
    let mut dying = 0;
    let mut t = link(head, a);
    let mut guard = tris.len();
    let nb = I::narrow(b);
    while t != NONE && guard > 0 {
        guard -= 1;
        let tr = tri(tris, t);
        let Some(k) = slot(tr, a) else { break };
        if !dead(tr) && slot(tr, b).is_some() {
            dying += 1;
        }
        if let Some(c) = tris.get_mut(t).and_then(|x| x.get_mut(k)) {
            *c = nb;
        }
        t = next.get(t).map_or(NONE, |n| link(n, k));
    }
    if let Some(&qa) = quadrics.get(a) {
        if let Some(q) = quadrics.get_mut(b) {
            *q = quadric::add(q, &qa);
        }
    }
    if let Some(f) = flags.get_mut(a) {
        *f = flag::GONE | flag::PASS;
    }
    if let Some(f) = flags.get_mut(b) {
        *f |= flag::PASS;
    }
    dying
}
