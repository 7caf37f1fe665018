//! perform: the pass's collapses in cost order (meshoptimizer's `performEdgeCollapses`).
//!
//! A candidate is skipped when either end is already an end of a collapse in this pass (so a
//! quadric or a fan is never read stale, and a vertex never moves twice), and the pass stops
//! at its goal or at its error goal: a factor of the cost of the candidate that would reach
//! the goal ([`Goal::Error`], [`Goal::Tail`] in a run's tail), once a sixth of the goal is done.
//! A candidate over the error goal is skipped, and the pass ends at the first whose sort key
//! is over the error goal's (the counting sort orders a bin by vertex, not by price). A
//! candidate whose triangles a collapse of the pass changed is priced again from its fan as it
//! is then (the batched schedule prices a popped vertex again for the same reason) and left to
//! the next pass if that price is over the error goal. A refused candidate is followed at once
//! by a's next cheapest target, if it is within the error goal. Each candidate is checked on
//! the current mesh, the rules in order of cost, each where it can fire:
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
//!    the collapse (unit normals' dot below -0.89: the shared checker's -0.9 in `f64`, with
//!    a margin for the rounding of `f32` normals).
//!
//! With wedges, after rule 1: the seam rule ([`along_seam`]), each of a's wedges must have a
//! wedge of b to go to, from the removed triangle on its side, and neither removed triangle
//! may be the last of its chart ([`last_of_chart`]); and with rule 2 the sliver preference
//! (`thinner`), a texture's guard.
//!
//! A candidate over the error limit (its error, the price as a mean squared distance in the
//! unit frame, above the limit's square) is never collapsed.
//!
//! A collapse rewrites a's corners to b in the caller's triangles (the two on a-b become
//! degenerate: compact drops them), with wedges each moved corner's wedge too, and locks both
//! ends.

use super::fill::{vertex_quadric, Quadrics};
use super::geometry::{Geometry, Goal};
use super::{dead, fan, flag, flags_of, link, list, on, others, set_link, slot, tri, Stats, NONE};
use crate::index::Index;
use crate::legality::Reject;

/// The pass's error goal over the price of the candidate that would reach its goal: 0.9
/// ([`Goal::Error`]). meshoptimizer takes 1.5 with its accumulated quadrics; with quadrics
/// filled afresh each pass (a price that only sees the current triangles) a pass that runs past
/// that price collapses vertices whose neighbours, locked by this pass, would have been
/// cheaper: below 1, so that more, shorter passes price from fresher triangles. In the tail of
/// a run, a pass whose goal is under `1 / TAIL_SHARE` of its candidates, 1.5 ([`Goal::Tail`]):
/// there the cheap candidates left are mostly refused, pass after pass, and a goal below 1
/// ends each pass after a collapse or two (a pass costs a sweep of the mesh).
const TAIL_SHARE: usize = 8;

// Rule switches, for showing that each rule matters (`PIPELINE_RULE_OFF=<name>` at build
// time switches one off; a constant, so a normal build carries no trace of it).
const RULE_AREA: &str = "area";
const RULE_FLIP: &str = "flip";
const RULE_LINK: &str = "link";
const RULE_LONE: &str = "lone";
const RULE_DUPLICATE: &str = "duplicate";
const RULE_FOLD: &str = "fold";
const RULE_BORDER: &str = "border";
const RULE_LOCKED: &str = "locked";
const RULE_SEAM: &str = "seam";

/// a's cheapest target other than `b` that its kind allows (pick's rules) and no collapse of
/// this pass has touched, and its price.
#[inline(never)]
#[allow(clippy::too_many_arguments)]
fn alternative<I: Index, L: Index, G: Geometry, Q: Quadrics<G>, const W: bool>(
    frame: &G,
    tris: &[[I; 3]],
    adj: (&[L], &[L]),
    (flags, border_next): (&[u8], &[L]),
    (quadrics, q, mean): (&Q, &G::Q, G::Area),
    a: usize,
    b: usize,
) -> Option<(usize, G::Cost)> {
    let border = flags_of(flags, a) & flag::KIND == flag::BORDER;
    let next = if border {
        quadrics.next(tris, adj, flags, border_next, a)
    } else {
        NONE
    };
    let seam = W && flags_of(flags, a) & flag::SEAM != 0;
    let pa = frame.at(a);
    let mut best: Option<(usize, G::Raw)> = None;
    for (_, tr, k) in fan(tris, adj, flags, a) {
        if dead(tr) {
            continue;
        }
        let (x, y) = others(tr, k);
        for w in [x, y] {
            let fw = flags_of(flags, w);
            if w == b || fw & flag::PASS != 0 || fw & flag::KIND == flag::GONE {
                continue;
            }
            if seam && !super::along(flags, w) {
                continue;
            }
            if border
                && !(fw & flag::KIND == flag::BORDER
                    && (next == w || quadrics.enters(tris, adj, flags, border_next, w, a)))
            {
                continue;
            }
            let e = frame.raw(q, pa, frame.at(w));
            if best.is_none_or(|(v, c)| e < c || (e == c && w < v)) {
                best = Some((w, e));
            }
        }
    }
    best.map(|(w, e)| (w, frame.price(mean, q, e)))
}

/// Runs one pass over `order`; returns the collapses made.
#[allow(clippy::too_many_arguments)]
#[inline(never)]
pub(super) fn perform<I: Index, L: Index, G: Geometry, Q: Quadrics<G>, const W: bool>(
    frame: &G,
    (tris, corners): (&mut [[I; 3]], &mut [[I; 3]]),
    adj: (&[L], &[L]),
    flags: &mut [u8],
    border_next: &mut [L],
    (quadrics, mean): (&Q, G::Area),
    (target, cost, order): (&mut [L], &[u32], &[L]),
    (goal, limit, measure): (usize, G::Err, bool),
    stats: &mut Stats<G::Err>,
) -> usize {
    let m = order.len();
    let cost_of = |v: usize| cost.get(v).map_or(G::COST_MAX, |&c| G::cost_of(c));
    let factor = if goal * TAIL_SHARE < m {
        Goal::Tail
    } else {
        Goal::Error
    };
    let mut edge_goal = goal / 2;
    let (mut removed, mut done, mut worst) = (0usize, 0usize, G::COST_ZERO);
    for i in 0..m {
        if removed >= goal {
            break;
        }
        let a = link(order, i);
        let c = cost_of(a);
        let error_goal = if edge_goal < m {
            G::goal(cost_of(link(order, edge_goal)), factor)
        } else {
            G::COST_MAX
        };
        if c > error_goal && c > worst && removed > goal / 6 {
            // Sorted by key: within a bin the order is by vertex, not by price, so a dearer
            // candidate ends the pass only once the bins are past the goal's.
            if G::key(G::cost_bits(c)) > G::key(G::cost_bits(error_goal)) {
                break;
            }
            continue;
        }
        let b = link(target, a);
        if (flags_of(flags, a) | flags_of(flags, b)) & flag::PASS != 0 {
            continue;
        }
        // A collapse of this pass changed a's triangles: its price is stale. Priced again
        // from its fan as it is now (as the batched schedule prices a popped vertex again),
        // and left to the next pass if that is over the pass's error goal.
        let (c, fresh) = if flags_of(flags, a) & flag::DIRTY != 0 {
            let q = vertex_quadric::<I, L, G, Q, W>(
                frame,
                &*tris,
                adj,
                (&*flags, &*border_next),
                quadrics,
                a,
            );
            let c = frame.price(mean, &q, frame.raw(&q, frame.at(a), frame.at(b)));
            if c > G::cost_max(error_goal, cost_of(a)) {
                continue;
            }
            (c, Some(q))
        } else {
            (c, None)
        };
        // a's quadric: read or built only when the error or a second target needs it.
        let qa = |flags: &[u8], tris: &[[I; 3]]| match fresh {
            Some(q) => q,
            None => quadrics.of::<I, L, W>(frame, tris, adj, flags, &*border_next, a),
        };
        let e = if G::finite(limit) || measure {
            frame.error(mean, &qa(&*flags, &*tris), (frame.at(a), frame.at(b)), c)
        } else {
            G::ERR_ZERO
        };
        if G::over(e, limit) {
            // Sorted by price, not by error: a later candidate may still be under.
            stats.over_limit += 1;
            continue;
        }
        let (b, dying, e) =
            match check::<I, L, G, W>(frame, (&*tris, &*corners), adj, flags, target, a, b) {
                Ok(n) => (b, n, e),
                Err(r) => {
                    stats.rejected.count(r);
                    edge_goal += 1;
                    // a's next cheapest target, at once: a vertex keeps one candidate, so one
                    // whose cheapest collapse stays illegal would otherwise never move.
                    let qa = qa(&*flags, &*tris);
                    let Some((x, cx)) = alternative::<I, L, G, Q, W>(
                        frame,
                        tris,
                        adj,
                        (&*flags, &*border_next),
                        (quadrics, &qa, mean),
                        a,
                        b,
                    ) else {
                        continue;
                    };
                    let ex = if G::finite(limit) || measure {
                        frame.error(mean, &qa, (frame.at(a), frame.at(x)), cx)
                    } else {
                        G::ERR_ZERO
                    };
                    if cx > G::cost_max(error_goal, c) || G::over(ex, limit) {
                        continue;
                    }
                    match check::<I, L, G, W>(frame, (&*tris, &*corners), adj, flags, target, a, x)
                    {
                        Ok(n) => (x, n, ex),
                        Err(r) => {
                            stats.rejected.count(r);
                            continue;
                        }
                    }
                }
            };
        if W {
            move_wedges((&*tris, &mut *corners), adj, flags, (a, b));
        }
        collapse(tris, adj, flags, border_next, (a, b));
        // The live triangles on a-b, which check counted, die.
        removed += dying;
        // b's candidate is spent for this pass: its slot names the vertex that moved onto it.
        set_link(target, b, a);
        done += 1;
        if c > worst {
            worst = c;
        }
        if e > stats.worst {
            stats.worst = e;
        }
    }
    stats.collapses += done;
    done
}

/// A surviving triangle of a's fan: its number, its other vertices (after and before a), their
/// positions and its normal after the collapse with its squared length.
#[derive(Clone, Copy)]
struct Survivor<G: Geometry> {
    t: u32,
    x: u32,
    y: u32,
    n: G::N,
    px: G::P,
    py: G::P,
}

impl<G: Geometry> Survivor<G> {
    #[inline]
    fn x(&self) -> usize {
        self.x as usize
    }
    #[inline]
    fn y(&self) -> usize {
        self.y as usize
    }
}

/// Fans with more survivors than this are not collapsed (counted as locked).
const MAX_FAN: usize = 32;

/// Every rule for `a → b` on the current mesh (module documentation, in that order); `Ok` gives
/// the triangles the collapse removes (the live ones on a-b).
#[inline(never)]
fn check<I: Index, L: Index, G: Geometry, const W: bool>(
    frame: &G,
    (tris, corners): (&[[I; 3]], &[[I; 3]]),
    adj: (&[L], &[L]),
    flags: &mut [u8],
    target: &[L],
    a: usize,
    b: usize,
) -> Result<usize, Reject> {
    let (ka, kb) = (
        flags_of(flags, a) & flag::KIND,
        flags_of(flags, b) & flag::KIND,
    );
    if (const { on(RULE_LOCKED) } && ka == flag::LOCKED) || ka == flag::GONE || kb == flag::GONE {
        return Err(Reject::Locked);
    }
    if const { on(RULE_BORDER) } && ka == flag::BORDER && kb != flag::BORDER {
        return Err(Reject::Boundary);
    }
    // 1 and 2. One walk of a's fan: the vertices opposite a-b (o1 in (a, b, o1), o2 in
    // (a, o2, b)), and each survivor's flip and area.
    let (pa, pb) = (frame.at(a), frame.at(b));
    // Not zeroed: a fan rarely fills it.
    let mut fan_a = heapless::Vec::<Survivor<G>, MAX_FAN>::new();
    let (mut o1, mut o2, mut n_ab, mut na) = (NONE, NONE, 0, 0);
    // With wedges: the removed triangles' (a wedge, b wedge), on the o1 and o2 sides.
    let mut sides = [(NONE, NONE); 2];
    let mut removed = [NONE; 2];
    for (t, tr, k) in fan(tris, adj, flags, a) {
        if dead(tr) {
            continue;
        }
        na += 1;
        let (x, y) = others(tr, k);
        if x == b {
            o1 = y;
            n_ab += 1;
            if W {
                sides[0] = wedge_pair(corners, t, k, (k + 1) % 3);
                removed[0] = t;
            }
            continue;
        }
        if y == b {
            o2 = x;
            n_ab += 1;
            if W {
                sides[1] = wedge_pair(corners, t, k, (k + 2) % 3);
                removed[1] = t;
            }
            continue;
        }
        let (px, py) = (frame.at(x), frame.at(y));
        let rules = (const { on(RULE_AREA) }, const { on(RULE_FLIP) }, W);
        let n = frame.survivor([pa, pb, px, py], rules)?;
        let s = Survivor {
            t: t as u32,
            x: x as u32,
            y: y as u32,
            n,
            px,
            py,
        };
        if fan_a.push(s).is_err() {
            return Err(Reject::Locked);
        }
    }
    let fan_a = fan_a.as_slice();
    let want = if ka == flag::BORDER { 1 } else { 2 };
    let want = if const { on(RULE_BORDER) } {
        want
    } else {
        n_ab.clamp(1, 2)
    };
    if n_ab != want {
        return Err(if n_ab > 2 {
            Reject::Locked
        } else if ka == flag::BORDER {
            Reject::Boundary
        } else {
            Reject::Link
        });
    }
    if W && const { on(RULE_SEAM) } && !along_seam(corners, tris, fan_a, a, sides) {
        return Err(Reject::Seam);
    }
    if W && const { on(RULE_SEAM) } && flags_of(flags, a) & flag::SEAM != 0 {
        for (t, o) in removed.into_iter().zip([o1, o2]) {
            if t != NONE && last_of_chart(tris, corners, adj, flags, t, (a, b, o)) {
                return Err(Reject::Seam);
            }
        }
    }

    // 3. Link condition by marks; duplicates; b's triangles across b-o1 and b-o2.
    for s in fan_a {
        mark(flags, s.x(), true);
        mark(flags, s.y(), true);
    }
    let mut verdict = Ok(());
    let (mut nb, mut on_o1, mut on_o2, mut opposite) = (0, 0, 0, false);
    let (mut across1, mut across2) = (NONE, NONE);
    for (t, tr, k) in fan(tris, adj, flags, b) {
        if dead(tr) {
            continue;
        }
        nb += 1;
        let (x, y) = others(tr, k);
        if x == a || y == a {
            continue;
        }
        for w in [x, y] {
            if const { on(RULE_LINK) } && w != o1 && w != o2 && flags_of(flags, w) & flag::MARK != 0
            {
                verdict = Err(Reject::Link);
            }
        }
        if x == o1 || y == o1 {
            on_o1 += 1;
            across1 = t;
        }
        if x == o2 || y == o2 {
            on_o2 += 1;
            across2 = t;
        }
        opposite |= (x == o1 && y == o2) || (x == o2 && y == o1);
    }
    for s in fan_a {
        mark(flags, s.x(), false);
        mark(flags, s.y(), false);
    }
    verdict?;
    if on_o1 > 1 || on_o2 > 1 {
        // b's edge to o1 or o2 is non-manifold (b locked).
        return Err(Reject::Locked);
    }
    if const { on(RULE_LONE) } && na == 1 && nb == 1 {
        // A lone triangle would vanish (a component, a boundary loop).
        return Err(Reject::Boundary);
    }
    if const { on(RULE_DUPLICATE) }
        && opposite
        && fan_a
            .iter()
            .any(|s| (s.x() == o1 && s.y() == o2) || (s.x() == o2 && s.y() == o1))
    {
        return Err(Reject::Duplicate);
    }
    if !const { on(RULE_FOLD) } {
        return Ok(n_ab);
    }

    // 4. Folds: each survivor against its neighbours after the collapse.
    // b's triangle across b-o1 (or b-o2): b and o1 at their known positions.
    let unchanged = |t: usize, o: usize, po: G::P| {
        frame.normal(tri(tris, t).map(|v| {
            if v == b {
                pb
            } else if v == o {
                po
            } else {
                frame.at(v)
            }
        }))
    };
    for s in fan_a {
        // Across the spoke to x: the survivor with x before a, or b's triangle on b-o1 when
        // the one on a-o1 dies; across the spoke to o2 likewise.
        let spoke = match fan_a.iter().find(|u| u.y == s.x) {
            Some(u) => G::folded(s.n, u.n),
            None if s.x() == o1 && across1 != NONE => G::folded(s.n, unchanged(across1, o1, s.px)),
            None => false,
        };
        if spoke {
            return Err(Reject::Fold);
        }
        if s.y() == o2 && across2 != NONE && G::folded(s.n, unchanged(across2, o2, s.py)) {
            return Err(Reject::Fold);
        }
        // Across the outer edge x-y: searched in the list of an end that has not moved or
        // been moved onto in this pass, else in x's list and the list of the vertex that
        // moved onto x (all of x's triangles now).
        let (from, other, also) = if flags_of(flags, s.x()) & flag::PASS == 0 {
            (s.x(), s.y(), NONE)
        } else if flags_of(flags, s.y()) & flag::PASS == 0 {
            (s.y(), s.x(), NONE)
        } else {
            (s.x(), s.y(), link(target, s.x()))
        };
        let manifold = flags_of(flags, from) & flag::KIND != flag::LOCKED;
        // Compared as u32: every vertex and triangle number fits.
        let (ot, oa) = (other as u32, a as u32);
        'search: for v in [from, also] {
            if v == NONE {
                break;
            }
            for &u in list(adj.0, flags, adj.1, v) {
                let u = u.to_usize();
                let Some(tr) = tris.get(u) else { continue };
                let tr = [
                    tr[0].to_usize() as u32,
                    tr[1].to_usize() as u32,
                    tr[2].to_usize() as u32,
                ];
                if u as u32 == s.t || (tr[0] != ot && tr[1] != ot && tr[2] != ot) {
                    continue;
                }
                if tr[0] == tr[1] || tr[1] == tr[2] || tr[0] == tr[2] {
                    continue;
                }
                let p = tr.map(|v| {
                    if v == s.x {
                        s.px
                    } else if v == s.y {
                        s.py
                    } else if v == oa {
                        pb
                    } else {
                        frame.at(v as usize)
                    }
                });
                if G::folded(s.n, frame.normal(p)) {
                    return Err(Reject::Fold);
                }
                if manifold {
                    break 'search;
                }
            }
        }
    }
    Ok(n_ab)
}

/// Triangle `t`'s wedges at slots `k` and `j`.
#[inline]
fn wedge_pair<I: Index>(corners: &[[I; 3]], t: usize, k: usize, j: usize) -> (usize, usize) {
    match corners.get(t) {
        Some(w) => (
            w.get(k).map_or(NONE, |x| x.to_usize()),
            w.get(j).map_or(NONE, |x| x.to_usize()),
        ),
        None => (NONE, NONE),
    }
}

/// The wedge of b that a corner of a with wedge `x` takes, from the removed triangles'
/// (a wedge, b wedge) `sides` (either may be `(NONE, NONE)` on a border): the removed
/// triangle whose a shares the corner's wedge shares its attribute region. `NONE` when no
/// removed triangle holds `x`, or when both hold it with different wedges of b (a seam that
/// ends at a: its corners on each side would need a different wedge).
#[inline]
fn moved_wedge(x: usize, sides: [(usize, usize); 2]) -> usize {
    let [(a1, b1), (a2, b2)] = sides;
    match (x == a1, x == a2) {
        (true, true) if b1 == b2 => b1,
        (true, false) => b1,
        (false, true) => b2,
        _ => NONE,
    }
}

/// The seam rule: every wedge of a's surviving corners has a wedge of b to go to
/// ([`moved_wedge`]). One wedge: a is inside one attribute region. Two: a-b must be a spoke
/// where the wedge changes, so that each side's removed triangle carries it across.
fn along_seam<I: Index, G: Geometry>(
    corners: &[[I; 3]],
    tris: &[[I; 3]],
    fan_a: &[Survivor<G>],
    a: usize,
    sides: [(usize, usize); 2],
) -> bool {
    fan_a.iter().all(|s| {
        let t = s.t as usize;
        let Some(k) = slot(tri(tris, t), a) else {
            return false;
        };
        let x = wedge_pair(corners, t, k, k).0;
        moved_wedge(x, sides) != NONE
    })
}

/// With wedges: whether removed triangle `t` (`a`, `b`, `o`) is the last of its chart: no
/// live triangle across its edge b-o or a-o shares both wedges of that edge (edge a-b joins
/// only the other removed triangle). A collapse along a seam would take the chart whole: the
/// last piece of a texture chart, or of a material when a mesh's primitives are joined. Only
/// a seam vertex can remove one (a vertex inside a chart has chart neighbours in its fan), and
/// `a` and `b` have not moved in this pass, so their fan lists are whole.
#[inline(never)]
fn last_of_chart<I: Index, L: Index>(
    tris: &[[I; 3]],
    corners: &[[I; 3]],
    adj: (&[L], &[L]),
    flags: &[u8],
    t: usize,
    (a, b, o): (usize, usize, usize),
) -> bool {
    let wedge = |s: usize, v: usize| {
        let k = slot(tri(tris, s), v)?;
        corners.get(s)?.get(k).map(|x| x.to_usize())
    };
    let joined = [(b, o, a), (a, o, b)].into_iter().any(|(u, v, w)| {
        fan(tris, adj, flags, u).any(|(s, tr, _)| {
            s != t
                && !dead(tr)
                && slot(tr, v).is_some()
                && slot(tr, w).is_none()
                && wedge(s, u) == wedge(t, u)
                && wedge(s, v) == wedge(t, v)
        })
    });
    !joined
}

/// With wedges, before `a → b` rewrites the positions: each of a's surviving corners takes
/// its wedge of b ([`moved_wedge`]; the check made sure there is one).
#[inline(never)]
fn move_wedges<I: Index, L: Index>(
    (tris, corners): (&[[I; 3]], &mut [[I; 3]]),
    adj: (&[L], &[L]),
    flags: &[u8],
    (a, b): (usize, usize),
) {
    let mut sides = [(NONE, NONE); 2];
    for (t, tr, k) in fan(tris, adj, flags, a) {
        if dead(tr) {
            continue;
        }
        let (x, y) = others(tr, k);
        if x == b {
            sides[0] = wedge_pair(corners, t, k, (k + 1) % 3);
        } else if y == b {
            sides[1] = wedge_pair(corners, t, k, (k + 2) % 3);
        }
    }
    for (t, tr, k) in fan(tris, adj, flags, a) {
        if dead(tr) || slot(tr, b).is_some() {
            continue;
        }
        if let Some(c) = corners.get_mut(t).and_then(|w| w.get_mut(k)) {
            let w = moved_wedge(c.to_usize(), sides);
            if w != NONE {
                *c = I::narrow(w);
            }
        }
    }
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

/// `a → b`: a's corners rewritten to b, border successors kept, both ends locked for the
/// pass. No quadric is merged: the next pass fills them afresh, and in this pass neither end
/// is priced again.
#[inline(never)]
fn collapse<I: Index, L: Index>(
    tris: &mut [[I; 3]],
    adj: (&[L], &[L]),
    flags: &mut [u8],
    border_next: &mut [L],
    (a, b): (usize, usize),
) {
    if flags_of(flags, a) & flag::KIND == flag::BORDER {
        if link(border_next, a) == b {
            // ... p → a → b ...: p's open edge now ends at b. p is the neighbour before a
            // that no triangle of a has after it.
            let mut p = NONE;
            for (_, tr, k) in fan(tris, adj, flags, a) {
                let (_, y) = others(tr, k);
                if !dead(tr)
                    && !fan(tris, adj, flags, a).any(|(_, s, j)| !dead(s) && others(s, j).0 == y)
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
    let nb = I::narrow(b);
    for &t in list(adj.0, flags, adj.1, a) {
        let t = t.to_usize();
        let Some(k) = tris.get(t).and_then(|x| slot(x.map(|v| v.to_usize()), a)) else {
            break;
        };
        if let Some(x) = tris.get_mut(t) {
            // Each corner's quadric changes: the next fill takes it afresh.
            for v in x.iter() {
                if let Some(f) = flags.get_mut(v.to_usize()) {
                    *f |= flag::DIRTY;
                }
            }
            if let Some(c) = x.get_mut(k) {
                *c = nb;
            }
        }
    }
    if let Some(f) = flags.get_mut(a) {
        *f = (*f & flag::HIGH) | flag::GONE | flag::PASS;
    }
    if let Some(f) = flags.get_mut(b) {
        *f |= flag::PASS;
    }
}
