//! fill: per-vertex quadrics, afresh before every pass from the triangles as they are then
//! (the memoryless quadric of Lindstrom and Turk 1998, which the default cost also uses; its
//! planes are Garland's, Cheng, Pan and Shi 1998 §2.3 eq. 3): each triangle's plane quadric,
//! weighted by its area, added at its three vertices; and for each border edge a plane
//! through the edge perpendicular to its triangle, weighted by the edge's length times 10,
//! plus the triangle's plane at 10 times its weight, added at both ends, so that borders keep
//! their shape (meshoptimizer's `fillFaceQuadrics` and `fillEdgeQuadrics`); with wedges, at
//! each seam vertex a plane through each seam spoke on each side ([`seam_planes`]). The
//! planes themselves are the arithmetic's ([`Geometry`]); this module says which planes a
//! vertex's quadric holds and where a pass reads it ([`Quadrics`]).

use super::geometry::Geometry;
use super::{fan, flag, flags_of, link, others, tri, NONE};
use crate::index::Index;

/// The area of the first `triangles`.
#[inline(never)]
pub(super) fn area<I: Index, G: Geometry>(frame: &G, triangles: &[[I; 3]]) -> G::Area {
    let mut sum = G::AREA_ZERO;
    for t in 0..triangles.len() {
        let p = tri(triangles, t).map(|v| frame.at(v));
        sum = G::add_area(sum, frame.face_area(p));
    }
    sum
}

/// Whether `v`'s quadric is filled in this pass: every vertex in the first, then those a
/// collapse dirtied (a vertex whose triangles no collapse changed keeps its quadric, which a
/// fill would give again).
#[inline]
pub(super) fn due(flags: &[u8], v: usize, all: bool) -> bool {
    all || flags_of(flags, v) & flag::DIRTY != 0
}

/// With wedges, at seam vertex `v` for its triangle with neighbours `(x, y)` (positions `p`,
/// `v`'s first): the plane through each spoke to a seam or locked neighbour, perpendicular to
/// the triangle, weighted by the spoke's length times the seam weight. A seam spoke has a
/// triangle on each side, so each side adds one: the seam keeps its line on the surface, as
/// a border keeps its own (meshoptimizer's edge quadrics on its seam kind), and the texture
/// on both sides with it.
#[inline(never)]
pub(super) fn seam_planes<G: Geometry>(
    frame: &G,
    flags: &[u8],
    (x, y): (usize, usize),
    [pv, px, py]: [G::P; 3],
    q: &mut G::Sum,
) {
    for (w, pw, po) in [(x, px, py), (y, py, px)] {
        if super::along(flags, w) {
            frame.seam_spoke(q, pv, pw, po);
        }
    }
}

/// `v`'s quadric from its fan as it is now (the lean mode's, which stores none; the fast
/// mode's for a vertex whose fan changed in the pass, and the integer fast mode's fill): the
/// faces, border edges and, with wedges (`W`), seam spokes of its live triangles, summed in
/// fan order, with `borders`' open edges.
#[inline]
pub(super) fn vertex_quadric<I: Index, L: Index, G: Geometry, B: Borders, const W: bool>(
    frame: &G,
    triangles: &[[I; 3]],
    adj: (&[L], &[L]),
    (flags, border_next): (&[u8], &[L]),
    borders: &B,
    v: usize,
) -> G::Q {
    let mut q = G::EMPTY;
    let border = flags_of(flags, v) & flag::KIND == flag::BORDER;
    let seam = W && flags_of(flags, v) & flag::SEAM != 0;
    let next = if border {
        borders.next(triangles, adj, flags, border_next, v)
    } else {
        NONE
    };
    let pv = frame.at(v);
    for (_, tr, k) in fan(triangles, adj, flags, v) {
        if super::dead(tr) {
            continue;
        }
        let (x, y) = others(tr, k);
        let (px, py) = (frame.at(x), frame.at(y));
        frame.face_call(&mut q, [pv, px, py]);
        if seam {
            seam_planes(frame, flags, (x, y), [pv, px, py], &mut q);
        }
        if border {
            border_planes(
                frame,
                (triangles, adj, flags, border_next),
                borders,
                (v, x, y, next),
                [pv, px, py],
                &mut q,
            );
        }
    }
    frame.finish(q)
}

/// The border edge planes [`vertex_quadric`] adds at border vertex `v` for its live triangle
/// `(v, x, y)` (positions `p`), in that order: those of `v → x` if it is v's open out-edge
/// (`x` is `next`), and of `y → v` if that is an open edge. Not inlined: a border vertex's
/// case, rare, kept out of the fan loop and to one copy in flash.
#[inline(never)]
#[allow(clippy::type_complexity)]
fn border_planes<I: Index, L: Index, G: Geometry, B: Borders>(
    frame: &G,
    (triangles, adj, flags, border_next): (&[[I; 3]], (&[L], &[L]), &[u8], &[L]),
    borders: &B,
    (v, x, y, next): (usize, usize, usize, usize),
    [pv, px, py]: [G::P; 3],
    q: &mut G::Sum,
) {
    if x == next {
        frame.border_edge(q, [pv, px, py]);
    }
    if borders.enters(triangles, adj, flags, border_next, y, v) {
        frame.border_edge(q, [py, pv, px]);
    }
}

/// The vertex across `v`'s open out-edge, from `v`'s fan alone (the lean mode stores no border
/// successors): the vertex after `v` in one of its live triangles and before it in none
/// (`NONE` without one).
#[inline]
pub(crate) fn open_out<I: Index, L: Index>(
    triangles: &[[I; 3]],
    adj: (&[L], &[L]),
    flags: &[u8],
    v: usize,
) -> usize {
    unmatched(triangles, adj, flags, v, true, NONE)
}

/// Whether `y → v` is an open edge, from `v`'s fan alone: `y` is before `v` in one of its
/// live triangles and after it in none.
#[inline]
pub(crate) fn opens_into<I: Index, L: Index>(
    triangles: &[[I; 3]],
    adj: (&[L], &[L]),
    flags: &[u8],
    y: usize,
    v: usize,
) -> bool {
    y != NONE && unmatched(triangles, adj, flags, v, false, y) == y
}

/// The first vertex (in fan order; `only`, if given) that is after `v` (`after`) or before it
/// in one of its live triangles and in the other role in none; `NONE` without one. One search
/// for both of the lean mode's open-edge questions, so one copy in flash.
#[inline(never)]
fn unmatched<I: Index, L: Index>(
    triangles: &[[I; 3]],
    adj: (&[L], &[L]),
    flags: &[u8],
    v: usize,
    after: bool,
    only: usize,
) -> usize {
    let live = || fan(triangles, adj, flags, v).filter(|&(_, tr, _)| !super::dead(tr));
    let role = |tr: [usize; 3], k: usize, after: bool| {
        let (x, y) = others(tr, k);
        if after {
            x
        } else {
            y
        }
    };
    live()
        .map(|(_, tr, k)| role(tr, k, after))
        .filter(|&w| only == NONE || w == only)
        .find(|&w| !live().any(|(_, tr, k)| role(tr, k, !after) == w))
        .unwrap_or(NONE)
}

/// Where a pass finds a border vertex's open edges: stored successors (`border_next`, kept up
/// by each collapse: the fast mode) or searched in the fans when read (the lean mode).
pub(crate) trait Borders {
    /// Whether border successors are stored (the lean mode has no `border_next`).
    const STORES_BORDERS: bool;

    /// The vertex across border vertex `v`'s open out-edge (`NONE` without one).
    fn next<I: Index, L: Index>(
        &self,
        triangles: &[[I; 3]],
        adj: (&[L], &[L]),
        flags: &[u8],
        border_next: &[L],
        v: usize,
    ) -> usize;

    /// Whether `y` is a border vertex whose open out-edge is `y → v`.
    fn enters<I: Index, L: Index>(
        &self,
        triangles: &[[I; 3]],
        adj: (&[L], &[L]),
        flags: &[u8],
        border_next: &[L],
        y: usize,
        v: usize,
    ) -> bool;
}

/// Where a pass reads a vertex's quadric: stored and filled before each pass (the fast
/// mode), or built from the vertex's fan whenever it is read (the lean mode, for half the
/// RAM). Both give the same planes; in the float fast mode the stored sums run in triangle
/// order, the fan's in fan order, so their roundings differ.
pub(crate) trait Quadrics<G: Geometry>: Borders {
    /// Before a pass: the stored quadrics of every vertex (`all`) or of the dirty ones.
    /// Returns the triangles' area if it summed it on the way (the float fast mode, with
    /// `all`).
    fn fill<I: Index, L: Index, const W: bool>(
        &mut self,
        frame: &G,
        triangles: &[[I; 3]],
        adj: (&[L], &[L]),
        flags: &mut [u8],
        border_next: &[L],
        all: bool,
    ) -> Option<G::Area>;

    /// `v`'s quadric in this pass.
    fn of<I: Index, L: Index, const W: bool>(
        &self,
        frame: &G,
        triangles: &[[I; 3]],
        adj: (&[L], &[L]),
        flags: &[u8],
        border_next: &[L],
        v: usize,
    ) -> G::Q;
}

/// Stored border successors (the fast mode's, and the integer fast mode's fill).
pub(crate) struct StoredBorders;

impl Borders for StoredBorders {
    const STORES_BORDERS: bool = true;

    #[inline(always)]
    fn next<I: Index, L: Index>(
        &self,
        _: &[[I; 3]],
        _: (&[L], &[L]),
        _: &[u8],
        border_next: &[L],
        v: usize,
    ) -> usize {
        link(border_next, v)
    }

    #[inline(always)]
    fn enters<I: Index, L: Index>(
        &self,
        _: &[[I; 3]],
        _: (&[L], &[L]),
        flags: &[u8],
        border_next: &[L],
        y: usize,
        v: usize,
    ) -> bool {
        flags_of(flags, y) & flag::KIND == flag::BORDER && link(border_next, y) == v
    }
}

/// The fast mode's quadrics: one per vertex, filled before each pass.
pub(crate) struct Stored<'q, Q>(pub(crate) &'q mut [Q]);

impl<Q> Borders for Stored<'_, Q> {
    const STORES_BORDERS: bool = true;

    #[inline(always)]
    fn next<I: Index, L: Index>(
        &self,
        triangles: &[[I; 3]],
        adj: (&[L], &[L]),
        flags: &[u8],
        border_next: &[L],
        v: usize,
    ) -> usize {
        StoredBorders.next(triangles, adj, flags, border_next, v)
    }

    #[inline(always)]
    fn enters<I: Index, L: Index>(
        &self,
        triangles: &[[I; 3]],
        adj: (&[L], &[L]),
        flags: &[u8],
        border_next: &[L],
        y: usize,
        v: usize,
    ) -> bool {
        StoredBorders.enters(triangles, adj, flags, border_next, y, v)
    }
}

impl<G: Geometry> Quadrics<G> for Stored<'_, G::Q> {
    #[inline(always)]
    fn fill<I: Index, L: Index, const W: bool>(
        &mut self,
        frame: &G,
        triangles: &[[I; 3]],
        adj: (&[L], &[L]),
        flags: &mut [u8],
        border_next: &[L],
        all: bool,
    ) -> Option<G::Area> {
        frame.fill_stored::<I, L, W>(triangles, adj, flags, border_next, self.0, all)
    }

    #[inline(always)]
    fn of<I: Index, L: Index, const W: bool>(
        &self,
        _: &G,
        _: &[[I; 3]],
        _: (&[L], &[L]),
        _: &[u8],
        _: &[L],
        v: usize,
    ) -> G::Q {
        match self.0.get(v) {
            Some(q) => *q,
            None => G::Q::default(),
        }
    }
}

/// The lean mode's quadrics: none stored, each built from its fan when read.
pub(crate) struct Fans;

impl Borders for Fans {
    const STORES_BORDERS: bool = false;

    #[inline(always)]
    fn next<I: Index, L: Index>(
        &self,
        triangles: &[[I; 3]],
        adj: (&[L], &[L]),
        flags: &[u8],
        _: &[L],
        v: usize,
    ) -> usize {
        open_out(triangles, adj, flags, v)
    }

    #[inline(always)]
    fn enters<I: Index, L: Index>(
        &self,
        triangles: &[[I; 3]],
        adj: (&[L], &[L]),
        flags: &[u8],
        _: &[L],
        y: usize,
        v: usize,
    ) -> bool {
        flags_of(flags, y) & flag::KIND == flag::BORDER && opens_into(triangles, adj, flags, y, v)
    }
}

impl<G: Geometry> Quadrics<G> for Fans {
    #[inline(always)]
    fn fill<I: Index, L: Index, const W: bool>(
        &mut self,
        _: &G,
        _: &[[I; 3]],
        _: (&[L], &[L]),
        flags: &mut [u8],
        _: &[L],
        _: bool,
    ) -> Option<G::Area> {
        // Nothing is stored; the dirty bits say, in the pass, which fans a collapse changed.
        for f in flags.iter_mut() {
            *f &= !flag::DIRTY;
        }
        None
    }

    #[inline(always)]
    fn of<I: Index, L: Index, const W: bool>(
        &self,
        frame: &G,
        triangles: &[[I; 3]],
        adj: (&[L], &[L]),
        flags: &[u8],
        _: &[L],
        v: usize,
    ) -> G::Q {
        vertex_quadric::<I, L, G, Self, W>(frame, triangles, adj, (flags, &[]), self, v)
    }
}
