//! fill: per-vertex quadrics, afresh before every pass from the triangles as they are then
//! (the memoryless quadric of Lindstrom and Turk 1998, which the default cost also uses; its
//! planes are Garland's, Cheng, Pan and Shi 1998 §2.3 eq. 3): each triangle's plane quadric,
//! weighted by its area, added at its three vertices; and for each border edge a plane
//! through the edge perpendicular to its triangle, weighted by the edge's length times 10,
//! plus the triangle's plane at 10 times its weight, added at both ends, so that borders keep
//! their shape (meshoptimizer's `fillFaceQuadrics` and `fillEdgeQuadrics`); with wedges, at
//! each seam vertex a plane through each seam spoke on each side ([`seam_planes`]).
//!
//! Every quadric is in its vertex's frame, where each of its planes passes through the
//! origin: its offset terms are zero, exactly, so a [`PointQuadric`] (the 3×3 part, 24 bytes)
//! holds it, and a collapse within a flat patch prices at zero, not at rounding.

use super::{fan, flag, flags_of, link, others, tri, Frame, NONE};
use crate::index::Index;
use crate::math::{self, V3};
use crate::quadric::{point_add, point_error, point_plane, point_weight, PointQuadric};

/// meshoptimizer's `kEdgeWeightBorder`.
const BORDER_WEIGHT: f32 = 10.0;

#[inline]
fn add_to(q: &mut [PointQuadric], v: usize, x: &PointQuadric) {
    if let Some(q) = q.get_mut(v) {
        point_add(q, x);
    }
}

/// The plane quadric of triangle `p`, weighted by its area times `w`, zero without area, and
/// that area (as [`area`] sums it). With `c` the cross product of two edges,
/// `area · n nᵀ = c cᵀ / (2|c|)`: one reciprocal square root, no normalisation.
#[inline]
fn plane(p: [V3; 3], w: f32) -> (PointQuadric, f32) {
    let c = math::cross(math::sub(p[1], p[0]), math::sub(p[2], p[0]));
    let l2 = math::dot(c, c);
    if !(l2 > math::TINY2 && l2.is_finite()) {
        return ([0.0; 6], 0.0);
    }
    let r = math::rsqrt(l2);
    // `math::sqrt(l2)` is `l2 · rsqrt(l2)`.
    (point_plane(c, 0.5 * r * w), 0.5 * (l2 * r))
}

/// The plane quadric of triangle `p`, weighted by its area times `w` ([`plane`]).
#[inline]
pub(super) fn triangle(p: [V3; 3], w: f32) -> PointQuadric {
    plane(p, w).0
}

/// [`triangle`], not inlined: for the fan walks off the hot path (a border edge's quadric, a
/// stale price's quadric), where the lean mode's flash budget counts more than a call.
#[inline(never)]
fn triangle_call(p: [V3; 3], w: f32) -> PointQuadric {
    plane(p, w).0
}

/// The area of the first `triangles` (unit frame).
#[inline(never)]
pub(super) fn area<I: Index>(frame: &Frame<'_>, triangles: &[[I; 3]]) -> f32 {
    let mut sum = 0.0;
    for t in 0..triangles.len() {
        let p = tri(triangles, t).map(|v| frame.at(v));
        let c = math::cross(math::sub(p[1], p[0]), math::sub(p[2], p[0]));
        sum += 0.5 * math::sqrt(math::dot(c, c));
    }
    sum
}

/// A price from a quadric: the default cost's (`cost::Quadric`), the squared distances to the
/// planes weighted by their areas, times `1 + Ā/W` with `W` the planes' weight (the fan's
/// area) and `Ā` the mean triangle area of the live mesh: a sum alone makes a fan of small
/// triangles cheap to move however far it goes, so thin parts would go first.
#[derive(Clone, Copy)]
pub(crate) struct Price {
    /// `Ā`: the input's area over the live triangles (a collapse keeps the area nearly).
    pub(crate) mean_area: f32,
}

impl Price {
    /// `1 + Ā/W` of quadric `q`.
    #[inline]
    pub(crate) fn factor(&self, q: &PointQuadric) -> f32 {
        let w = point_weight(q);
        if w > 0.0 {
            1.0 + self.mean_area / w
        } else {
            1.0
        }
    }

    /// The price of moving by `d` under `q`.
    #[inline]
    pub(crate) fn of(&self, q: &PointQuadric, d: V3) -> f32 {
        point_error(q, d) * self.factor(q)
    }

    /// The error behind price `c` of quadric `q`: the mean squared distance, `c / (W + Ā)`
    /// (`W · (1 + Ā/W)`), zero without weight.
    #[inline]
    pub(crate) fn error(&self, q: &PointQuadric, c: f32) -> f32 {
        let w = point_weight(q);
        if w > 0.0 {
            c / (w + self.mean_area)
        } else {
            0.0
        }
    }
}

/// Whether `v`'s quadric is filled in this pass: every vertex in the first, then those a
/// collapse dirtied (a vertex whose triangles no collapse changed keeps its quadric, which a
/// fill would give again).
#[inline]
fn due(flags: &[u8], v: usize, all: bool) -> bool {
    all || flags_of(flags, v) & flag::DIRTY != 0
}

/// Zeroes the due quadrics and adds every triangle's plane at its due vertices; returns the
/// area of the triangles it took (all of them with `all`, summed as [`area`] sums it).
#[inline(never)]
pub(super) fn face_quadrics<I: Index>(
    frame: &Frame<'_>,
    triangles: &[[I; 3]],
    flags: &[u8],
    quadrics: &mut [PointQuadric],
    all: bool,
) -> f32 {
    for (v, q) in quadrics.iter_mut().enumerate() {
        if due(flags, v, all) {
            *q = [0.0; 6];
        }
    }
    let mut sum = 0.0;
    for t in 0..triangles.len() {
        let tr = tri(triangles, t);
        let d = tr.map(|v| due(flags, v, all));
        if !(d[0] || d[1] || d[2]) {
            continue;
        }
        let (q, area) = plane(tr.map(|v| frame.at(v)), 1.0);
        sum += area;
        for (v, d) in tr.into_iter().zip(d) {
            if d {
                add_to(quadrics, v, &q);
            }
        }
    }
    sum
}

/// The quadric of open edge `p0 → p1` of triangle `(p0, p1, p2)`: the plane through the edge
/// perpendicular to the triangle, weighted by the edge's length times [`BORDER_WEIGHT`], plus
/// the triangle's plane at [`BORDER_WEIGHT`] times its area; `None` for a degenerate edge or
/// triangle.
#[inline]
fn edge_quadric(p0: V3, p1: V3, p2: V3) -> Option<PointQuadric> {
    let e10 = math::sub(p1, p0);
    let e20 = math::sub(p2, p0);
    let l2 = math::dot(e10, e10);
    let proj = math::dot(e20, e10);
    let perp = math::sub(math::scale(e20, l2), math::scale(e10, proj));
    let pl2 = math::dot(perp, perp);
    if !(l2 > math::TINY2 && pl2 > math::TINY2 && pl2.is_finite()) {
        return None;
    }
    let n = math::scale(perp, math::rsqrt(pl2));
    let face = triangle_call([p0, p1, p2], BORDER_WEIGHT);
    let mut q = point_plane(n, math::sqrt(l2) * BORDER_WEIGHT);
    point_add(&mut q, &face);
    Some(q)
}

/// With wedges, at seam vertex `v` for its triangle with neighbours `(x, y)` (positions `p`,
/// `v`'s first): the plane through each spoke to a seam or locked neighbour, perpendicular to
/// the triangle, weighted by the spoke's length times [`SEAM_WEIGHT`]. A seam spoke has a
/// triangle on each side, so each side adds one: the seam keeps its line on the surface, as
/// a border keeps its own (meshoptimizer's edge quadrics on its seam kind), and the texture
/// on both sides with it.
#[inline(never)]
fn seam_planes(flags: &[u8], (x, y): (usize, usize), [pv, px, py]: [V3; 3], q: &mut PointQuadric) {
    for (w, pw, po) in [(x, px, py), (y, py, px)] {
        if !super::along(flags, w) {
            continue;
        }
        let e = math::sub(pw, pv);
        let o = math::sub(po, pv);
        let l2 = math::dot(e, e);
        let perp = math::sub(math::scale(o, l2), math::scale(e, math::dot(o, e)));
        let pl2 = math::dot(perp, perp);
        if l2 > math::TINY2 && pl2 > math::TINY2 && pl2.is_finite() {
            let n = math::scale(perp, math::rsqrt(pl2));
            point_add(q, &point_plane(n, math::sqrt(l2) * SEAM_WEIGHT));
        }
    }
}

/// A seam spoke's plane weight on each of its two sides (against [`BORDER_WEIGHT`] for a
/// border edge, which has one side): a trade between the texture's fidelity along the seam
/// and the geometric error of the collapses the planes refuse to price low (measured in
/// docs/attributes.md#the-fast-mode-with-attributes).
const SEAM_WEIGHT: f32 = 0.1;

/// With wedges: the seam planes ([`seam_planes`]) of every due seam vertex, from its fan.
#[inline(never)]
pub(super) fn seam_quadrics<I: Index, L: Index>(
    frame: &Frame<'_>,
    triangles: &[[I; 3]],
    adj: (&[L], &[L]),
    flags: &[u8],
    quadrics: &mut [PointQuadric],
    all: bool,
) {
    for v in 0..flags.len() {
        if flags_of(flags, v) & flag::SEAM == 0 || !due(flags, v, all) {
            continue;
        }
        let Some(q) = quadrics.get_mut(v) else {
            continue;
        };
        let pv = frame.at(v);
        for (_, tr, k) in fan(triangles, adj, flags, v) {
            let (x, y) = others(tr, k);
            seam_planes(flags, (x, y), [pv, frame.at(x), frame.at(y)], q);
        }
    }
}

/// `v`'s quadric from its fan as it is now (the lean mode's, which stores none; the fast
/// mode's for a vertex whose fan changed in the pass): the same planes as [`face_quadrics`],
/// [`border_quadrics`] and, with wedges (`W`), [`seam_quadrics`] give it, summed in fan order,
/// with `quadrics`' open edges.
#[inline]
pub(super) fn vertex_quadric<I: Index, L: Index, Q: Quadrics, const W: bool>(
    frame: &Frame<'_>,
    triangles: &[[I; 3]],
    adj: (&[L], &[L]),
    (flags, border_next): (&[u8], &[L]),
    quadrics: &Q,
    v: usize,
) -> PointQuadric {
    let mut q = [0.0; 6];
    let border = flags_of(flags, v) & flag::KIND == flag::BORDER;
    let seam = W && flags_of(flags, v) & flag::SEAM != 0;
    let next = if border {
        quadrics.next(triangles, adj, flags, border_next, v)
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
        point_add(&mut q, &triangle_call([pv, px, py], 1.0));
        if seam {
            seam_planes(flags, (x, y), [pv, px, py], &mut q);
        }
        if border {
            border_planes(
                (triangles, adj, flags, border_next),
                quadrics,
                (v, x, y, next),
                [pv, px, py],
                &mut q,
            );
        }
    }
    q
}

/// The border edge planes [`vertex_quadric`] adds at border vertex `v` for its live triangle
/// `(v, x, y)` (positions `p`), in that order: those of `v → x` if it is v's open out-edge
/// (`x` is `next`), and of `y → v` if that is an open edge. Not inlined: a border vertex's
/// case, rare, kept out of the fan loop and to one copy in flash.
#[inline(never)]
#[allow(clippy::type_complexity)]
fn border_planes<I: Index, L: Index, Q: Quadrics>(
    (triangles, adj, flags, border_next): (&[[I; 3]], (&[L], &[L]), &[u8], &[L]),
    quadrics: &Q,
    (v, x, y, next): (usize, usize, usize, usize),
    [pv, px, py]: [V3; 3],
    q: &mut PointQuadric,
) {
    if x == next {
        if let Some(e) = edge_quadric(pv, px, py) {
            point_add(q, &e);
        }
    }
    if quadrics.enters(triangles, adj, flags, border_next, y, v) {
        if let Some(e) = edge_quadric(py, pv, px) {
            point_add(q, &e);
        }
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

/// Adds the border edge quadrics at the due ends of each open edge `v → border_next[v]`, and
/// clears the dirty bits.
#[inline(never)]
pub(super) fn border_quadrics<I: Index, L: Index>(
    frame: &Frame<'_>,
    triangles: &[[I; 3]],
    adj: (&[L], &[L]),
    flags: &mut [u8],
    border_next: &[L],
    quadrics: &mut [PointQuadric],
    all: bool,
) {
    for i0 in 0..flags.len() {
        if flags_of(flags, i0) & flag::KIND != flag::BORDER {
            continue;
        }
        let i1 = link(border_next, i0);
        let (d0, d1) = (due(flags, i0, all), due(flags, i1, all));
        if !(d0 || d1) {
            continue;
        }
        // The open edge's triangle: the one of i0's fan with i1 after i0.
        let Some(i2) = fan(triangles, adj, flags, i0)
            .map(|(_, tr, k)| others(tr, k))
            .find(|&(x, _)| x == i1)
            .map(|(_, y)| y)
        else {
            continue;
        };
        let Some(q) = edge_quadric(frame.at(i0), frame.at(i1), frame.at(i2)) else {
            continue;
        };
        if d0 {
            add_to(quadrics, i0, &q);
        }
        if d1 {
            add_to(quadrics, i1, &q);
        }
    }
    for f in flags.iter_mut() {
        *f &= !flag::DIRTY;
    }
}

/// Where a pass reads a vertex's quadric: stored and filled before each pass (the fast
/// mode), or built from the vertex's fan whenever it is read (the lean mode, for half the
/// RAM). Both give the same planes; the stored sums run in triangle order, the fan's in fan
/// order, so their roundings differ.
pub(crate) trait Quadrics {
    /// Whether border successors are stored (`border_next`, kept up by each collapse) or
    /// found from the fans when read (the lean mode, which has no `border_next`).
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

    /// Before a pass: the stored quadrics of every vertex (`all`) or of the dirty ones.
    /// Returns the triangles' area if it summed it on the way (the fast mode, with `all`).
    fn fill<I: Index, L: Index, const W: bool>(
        &mut self,
        frame: &Frame<'_>,
        triangles: &[[I; 3]],
        adj: (&[L], &[L]),
        flags: &mut [u8],
        border_next: &[L],
        all: bool,
    ) -> Option<f32>;

    /// `v`'s quadric in this pass.
    fn of<I: Index, L: Index, const W: bool>(
        &self,
        frame: &Frame<'_>,
        triangles: &[[I; 3]],
        adj: (&[L], &[L]),
        flags: &[u8],
        border_next: &[L],
        v: usize,
    ) -> PointQuadric;
}

/// The fast mode's quadrics: one per vertex, filled before each pass.
pub(crate) struct Stored<'q>(pub(crate) &'q mut [PointQuadric]);

impl Quadrics for Stored<'_> {
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

    #[inline(always)]
    fn fill<I: Index, L: Index, const W: bool>(
        &mut self,
        frame: &Frame<'_>,
        triangles: &[[I; 3]],
        adj: (&[L], &[L]),
        flags: &mut [u8],
        border_next: &[L],
        all: bool,
    ) -> Option<f32> {
        let area = face_quadrics(frame, triangles, flags, self.0, all);
        if W {
            seam_quadrics(frame, triangles, adj, flags, self.0, all);
        }
        border_quadrics(frame, triangles, adj, flags, border_next, self.0, all);
        all.then_some(area)
    }

    #[inline(always)]
    fn of<I: Index, L: Index, const W: bool>(
        &self,
        _: &Frame<'_>,
        _: &[[I; 3]],
        _: (&[L], &[L]),
        _: &[u8],
        _: &[L],
        v: usize,
    ) -> PointQuadric {
        self.0.get(v).copied().unwrap_or([0.0; 6])
    }
}

/// The lean mode's quadrics: none stored, each built from its fan when read.
pub(crate) struct Fans;

impl Quadrics for Fans {
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

    #[inline(always)]
    fn fill<I: Index, L: Index, const W: bool>(
        &mut self,
        _: &Frame<'_>,
        _: &[[I; 3]],
        _: (&[L], &[L]),
        flags: &mut [u8],
        _: &[L],
        _: bool,
    ) -> Option<f32> {
        // Nothing is stored; the dirty bits say, in the pass, which fans a collapse changed.
        for f in flags.iter_mut() {
            *f &= !flag::DIRTY;
        }
        None
    }

    #[inline(always)]
    fn of<I: Index, L: Index, const W: bool>(
        &self,
        frame: &Frame<'_>,
        triangles: &[[I; 3]],
        adj: (&[L], &[L]),
        flags: &[u8],
        _: &[L],
        v: usize,
    ) -> PointQuadric {
        vertex_quadric::<I, L, Self, W>(frame, triangles, adj, (flags, &[]), self, v)
    }
}
