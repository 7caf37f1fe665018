//! prune: parts removed whole, when [`Config::prune_parts`](crate::Config::prune_parts) asks
//! for it (meshoptimizer's `meshopt_SimplifyPrune`: `buildComponents`, `measureComponents`,
//! `pruneComponents`).
//!
//! A collapse never changes topology, so on an assembly of many parts each part keeps its last
//! few triangles however far the rest goes, and a run over many small closed parts (pins,
//! screws, a car's bolts) stops short of its target on the link condition. meshoptimizer's
//! answer: a part whose size is within the error already made goes whole. Here, after each
//! pass whose largest collapse error reached the smallest part's size, every part within that
//! error goes; and once no collapse is left short of the target, the smallest parts go, up to
//! 1.5 times the smallest size at a time (meshoptimizer's factor) and never past the error
//! limit. The largest part is never removed, so the result is never empty.
//!
//! No memory of its own: parts are labelled afresh each time, by union-find over the live
//! triangles (path halving, the smaller vertex as root: deterministic) in the sort order's
//! links, and sized in the candidates' cost array (as the arithmetic stores an error), both free between a pass and the next pick.
//! A part's size is the largest squared distance of its vertices from its root (its smallest
//! live vertex), in the run's frame: between r² and 4r² for the radius r of its bounding
//! sphere, so a part goes no earlier than meshoptimizer's measure (the squared radius about
//! the centroid) would let it. Time: O(V + T) a call.

use super::geometry::Geometry;
use super::{dead, flag, flags_of, link, set_link, tri};
use crate::index::Index;

/// What a call removed, and the smallest part it left (besides the largest).
pub(super) struct Pruned<E> {
    /// Triangles removed.
    pub triangles: usize,
    /// Parts removed.
    pub parts: usize,
    /// Vertices removed with them.
    pub vertices: usize,
    /// The largest size among the parts removed (0 if none).
    pub largest: E,
    /// The smallest size above the cutoff among the parts left, the largest part aside
    /// (infinite if none).
    pub next: E,
}

/// The root of `v`'s part, halving the path on the way.
#[inline]
fn find<L: Index>(parent: &mut [L], mut v: usize) -> usize {
    // At most one step per vertex: the loop ends even on a corrupted array.
    for _ in 0..parent.len() {
        let p = link(parent, v);
        if p == v || p >= parent.len() {
            return v;
        }
        let g = link(parent, p);
        set_link(parent, v, g);
        v = g;
    }
    v
}

/// Joins the parts of `a` and `b`; the smaller root stays the root.
#[inline]
fn join<L: Index>(parent: &mut [L], a: usize, b: usize) {
    let (ra, rb) = (find(parent, a), find(parent, b));
    if ra < rb {
        set_link(parent, rb, ra);
    } else if rb < ra {
        set_link(parent, ra, rb);
    }
}

/// Removes every part of the first `nt` triangles whose size is at most `cutoff` (squared,
/// unit frame), the largest part aside: its triangles become dead (a repeated index, which
/// compact drops) and its vertices `GONE`. `parent` and `size` are scratch, one entry per
/// vertex (as `flags`).
#[inline(never)]
pub(super) fn prune<I: Index, L: Index, G: Geometry>(
    frame: &G,
    triangles: &mut [[I; 3]],
    nt: usize,
    flags: &mut [u8],
    (parent, size): (&mut [L], &mut [u32]),
    cutoff: G::Err,
) -> Pruned<G::Err> {
    let nv = flags.len().min(parent.len()).min(size.len());
    let (parent, size) = (
        parent.get_mut(..nv).unwrap_or(&mut []),
        size.get_mut(..nv).unwrap_or(&mut []),
    );
    for v in 0..nv {
        set_link(parent, v, v);
    }
    for t in 0..nt {
        let tr = tri(triangles, t);
        if dead(tr) || tr.iter().any(|&v| v >= nv) {
            continue;
        }
        join(parent, tr[0], tr[1]);
        join(parent, tr[0], tr[2]);
    }
    // Sizes at the roots, every live vertex pointing at its root.
    for s in size.iter_mut() {
        *s = G::err_bits(G::ERR_ZERO);
    }
    for v in 0..nv {
        if flags_of(flags, v) & flag::KIND == flag::GONE {
            continue;
        }
        let r = find(parent, v);
        set_link(parent, v, r);
        let d2 = frame.size(frame.at(r), frame.at(v));
        if let Some(s) = size.get_mut(r) {
            if d2 > G::err_of(*s) {
                *s = G::err_bits(d2);
            }
        }
    }
    let root = |parent: &[L], v: usize| link(parent, v) == v;
    let live = |flags: &[u8], v: usize| flags_of(flags, v) & flag::KIND != flag::GONE;
    // The largest part stays (ties: the smaller root).
    let mut keep = usize::MAX;
    let mut keep_size = None;
    for v in 0..nv {
        let s = size.get(v).map_or(G::ERR_ZERO, |&s| G::err_of(s));
        if root(parent, v) && live(flags, v) && keep_size.is_none_or(|k| s > k) {
            keep = v;
            keep_size = Some(s);
        }
    }
    let mut out = Pruned {
        triangles: 0,
        parts: 0,
        vertices: 0,
        largest: G::ERR_ZERO,
        next: G::ERR_MAX,
    };
    for t in 0..nt {
        let tr = tri(triangles, t);
        if dead(tr) || tr.iter().any(|&v| v >= nv) {
            continue;
        }
        let r = link(parent, tr[0]);
        let s = size.get(r).map_or(G::ERR_MAX, |&s| G::err_of(s));
        // NaN keeps the part.
        if r == keep || G::over(s, cutoff) {
            continue;
        }
        // A part is counted at its first triangle: its root's mark.
        if flags_of(flags, r) & flag::MARK == 0 {
            if let Some(f) = flags.get_mut(r) {
                *f |= flag::MARK;
            }
            out.parts += 1;
            if s > out.largest {
                out.largest = s;
            }
        }
        if let Some(x) = triangles.get_mut(t) {
            *x = [x[0]; 3];
        }
        out.triangles += 1;
    }
    // The removed parts' vertices go, roots (and their marks) last.
    for v in 0..nv {
        let r = link(parent, v);
        if live(flags, v) && r != v && flags_of(flags, r) & flag::MARK != 0 {
            if let Some(f) = flags.get_mut(v) {
                *f = (*f & flag::HIGH) | flag::GONE;
            }
            out.vertices += 1;
        }
    }
    for v in 0..nv {
        let s = size.get(v).map_or(G::ERR_ZERO, |&s| G::err_of(s));
        if flags_of(flags, v) & flag::MARK != 0 {
            if let Some(f) = flags.get_mut(v) {
                *f = (*f & flag::HIGH) | flag::GONE;
            }
            out.vertices += 1;
        } else if root(parent, v) && live(flags, v) && v != keep && s > cutoff && s < out.next {
            out.next = s;
        }
    }
    out
}
