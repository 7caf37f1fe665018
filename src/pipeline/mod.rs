//! The pipeline (engine v4): meshoptimizer's edge-collapse pipeline in fixed caller memory,
//! with every output valid, in two modes that differ only in what they store, each in either
//! of two arithmetics (the workspace's last type parameter): [`Float`] (`f32` positions, the
//! default) or [`Integer`] (`u16` positions on a 15-bit grid and fixed point throughout, for
//! cores without an FPU: `integer`'s module documentation and docs/integer.md). The
//! passes, the sort and the topology are written once; what they compute from positions is
//! the arithmetic's (`geometry::Geometry`).
//!
//! | mode | workspace | per vertex | bytes per triangle (`u16` links) |
//! |---|---|---|---|
//! | fast | [`FastWorkspace`] | a quadric, filled before each pass; the border successor | 24.5 |
//! | lean | [`LeanWorkspace`] | neither: both found from the vertex's fan whenever read | 11.5 |
//!
//! The lean mode walks a vertex's fan for its quadric each time a pass prices it (and for a
//! border vertex's open edges), where the fast mode reads an array: it trades instructions for
//! RAM (its instructions: the `cow-lean-u16` row of bench/DEVICES.md; the decision:
//! docs/speed.md#lean-mode). Both price with the same planes and
//! apply the same rules; only the order of each quadric's sum differs (triangle order
//! against fan order), so a price may differ in its last bits and the outputs with it.
//!
//! The pipeline follows `meshopt_simplifyEdge` of Arseny Kapoulkine's meshoptimizer
//! (`src/simplifier.cpp`): passes that price every candidate once from per-vertex plane
//! quadrics (Garland's quadric error metric as Cheng, Pan and Shi 1998 use it, §2.3: the
//! quadric `K_p = p pᵀ` of each triangle's plane, eq. 3, summed at its vertices; see
//! `crate::quadric`), order them by a counting sort on the top bits of the float cost, and
//! collapse in that order while locking both ends of each collapse for the rest of the pass;
//! a pass ends at its error goal (a factor of the cost of the collapse that would reach the
//! pass's goal, which is half the live triangles at most), the triangle buffer is compacted,
//! and the next pass runs on the smaller mesh. Placement is the subset one of Lin 2007 §2 (a
//! vertex collapses onto an existing vertex), so the positions are only read and may stay in
//! flash.
//!
//! ```text
//! build     validate, drop degenerate triangles, fan lists
//! classify  manifold / border / locked (non-manifold, pinched, inconsistent) per vertex,
//!           with wedges seam or locked (more than two wedges); drop duplicate triangles
//! loop {
//!   fill      the quadrics of the vertices whose triangles changed (all in the first pass):
//!             area-weighted face planes and border edge planes, each in its vertex's frame
//!   pick      each vertex's cheapest collapse its kind allows, from its quadric
//!   sort      counting sort on the cost's top 12 bits
//!   perform   in order, to the pass's error goal: skip locked ends, check, collapse, lock both
//!   compact   drop dead triangles
//!   prune     with Config::prune_parts, the parts within the error made so far
//!   link      rebuild the fan lists
//! }
//! prune     short of the target with no collapse left, the smallest parts up to the limit
//! ```
//!
//! The quadrics are not accumulated, as meshoptimizer's are, but filled before each pass from
//! the triangles as they are then (the memoryless quadric of Lindstrom and Turk 1998, the
//! default cost's): a collapse's price is the area-weighted squared distance from its target
//! to the planes of the surface it changes, not to the input's surface near it. That orders
//! collapses by the error they add to the current mesh, which lowers the mean error; and no
//! quadric is merged on a collapse (in its pass neither end is priced again), so only the
//! vertices whose triangles a collapse changed (the `DIRTY` flag) are filled again.
//!
//! Each vertex's quadric is in a frame centred on that vertex: every plane it holds passes
//! through the vertex, so its offset terms are zero exactly and it is a
//! `quadric::PointQuadric`, the 3×3 part alone (24 bytes, not 40); and
//! a collapse within a flat patch prices at zero instead of at the rounding of terms of order
//! one, so CAD models lose their flat regions' triangles first and without error.
//!
//! Differences from meshoptimizer, each for a promise this crate makes: a vertex keeps one
//! candidate (its cheapest allowed collapse) instead of one per edge, so the sort buffer is one
//! link per vertex, and when the checks refuse it the vertex's next cheapest target is tried
//! at once (priced from the same quadric); the checks are not only its flip test
//! (`hasTriangleFlips`, on unnormalised cross products, no square root) but also the link
//! condition by marks (Cheng, Pan and Shi 1998 §3.2(1)), no duplicate triangle, no fold
//! across any edge of a changed triangle, no zero-area triangle; border vertices only slide
//! along their border edge and a lone triangle is never collapsed away, so the Euler
//! characteristic, the boundary loops and the components are kept.
//!
//! What each kind of vertex may still do (meshoptimizer's `kCanCollapse`, with the kinds
//! classify gives; a collapse moves `a` onto `b`):
//!
//! | kind of `a` | what makes it | may move onto | and the checks add |
//! |---|---|---|---|
//! | manifold | its triangles form one closed disk | any neighbour | two triangles on a-b |
//! | border | one open fan | a border neighbour along an open edge (either way) | one triangle on a-b; not a lone triangle |
//! | seam (with wedges) | a manifold vertex whose fan holds two wedges | a seam or locked neighbour along the seam | each wedge has a wedge of `b` on its side; no chart loses its last triangle |
//! | locked | non-manifold, pinched or inconsistently wound; more than two wedges, or two on a border; more than 32 triangles | nothing (others may move onto it) | - |
//!
//! Every collapse, of any kind, then passes the checks of `perform` (flip, area, link
//! condition, duplicates, folds; listed above), which keep the output valid: a non-manifold or inconsistently wound
//! input keeps its defects where they are, locked, and gets no new ones.
//!
//! Candidates are ordered by price, the default cost's (`cost::Quadric`, see `fill::Price`):
//! the source's quadric at the target, a sum of squared distances weighted by area, so a
//! collapse over little area goes first, times `1 + Ā/W` (`W` the fan's area, `Ā` the mean
//! triangle area), so that thin parts do not go first for being thin. Its error, checked
//! against [`Config::error_limit`] as for the stored quadric, is the distance part over the
//! planes' weight (the quadric's trace): a weighted mean squared distance, a distance in the
//! input's units once its root is taken.
//!
//! Welded seams: [`FastWorkspace::simplify_with_wedges`] takes the triangles welded by
//! position (`seam::weld`, crate feature `seams`, or welded by a host ahead of time, as the
//! golden wedge cases on the boards are) with the caller's wedges, and keeps both up to date:
//! a vertex on a seam (two wedges in its fan) slides only along it, one where
//! more than two meet never moves, and a moved corner takes its new vertex's wedge on its own
//! side (meshoptimizer's seam kind and `remap`/`wedge` pair; the exact engine's
//! [`Simplifier::with_wedges`](crate::Simplifier::with_wedges) with
//! [`SeamCorners::Lock`](crate::seam::SeamCorners::Lock)). Welding adds no RAM to the
//! workspace (one flag bit) and, as a separate instantiation, no flash to a firmware that
//! does not call it.
//!
//! Not the crate's default ([`Config::new`]'s engine is); `tinydecimate simplify`'s (`--engine
//! auto`, unless an option of the exact engine's alone is given or the mesh is double-sided;
//! `--engine fast` or `lean` ask for it): without attributes seams welded by position before
//! the call, with them (glTF, OBJ with `vt`/`vn`) with wedges, and parts pruned (`prune`,
//! [`Config::prune_parts`]: a part goes whole once the error made reaches its size, as
//! meshoptimizer's `meshopt_SimplifyPrune`; no memory of its own). Not in it: the error
//! bound, double-sided twins (the back of a double-sided triangle is dropped as a duplicate)
//! and `step(budget)`. A vertex with more than 32 triangles is locked, and a
//! collapse whose moving vertex would keep more is refused, so the checks run on fixed fan
//! buffers. `examples/fast_cow.rs` runs it on one mesh (`FAST_COW_LEAN=1`: the lean mode), for
//! callgrind and timing;
//! docs/speed.md#fast-mode has the decisions behind its passes.

mod build;
mod classify;
mod compact;
mod fill;
mod float;
mod geometry;
mod integer;
mod perform;
mod pick;
mod prune;
mod sort;

pub use geometry::{Arithmetic, Float, Integer};
pub use integer::{quantise, GridFrame, GRID};

use crate::error::Capacity;
use crate::index::Index;
use crate::report::{Rejections, Report, Stop};
use crate::{Config, Error};
use core::marker::PhantomData;
use geometry::Geometry;

/// Bins of the counting sort (the float cost's 8 bits of exponent and 4 of mantissa from 2⁻⁴⁸;
/// the integer price's 6 and 4).
pub(crate) const BINS: usize = 1024;

/// A pass removes at most `1 / PASS_SHARE` of the live triangles, however far the target is:
/// a price from the current triangles goes stale as the pass changes them, so a pass that
/// aims far collapses past prices that its locked vertices would have undercut (the batched
/// schedule's `PASS_SHARE` for the memoryless cost, the same reason); meshoptimizer, whose
/// accumulated quadrics do not go stale, aims each pass at the target.
const PASS_SHARE: usize = 2;

/// "No vertex" / "no triangle" as `usize`.
pub(crate) const NONE: usize = usize::MAX;

/// Per-vertex flag bits.
pub(crate) mod flag {
    /// Kind bits.
    pub const KIND: u8 = 3;
    /// An interior vertex whose triangles form one disk.
    pub const MANIFOLD: u8 = 0;
    /// A vertex whose triangles form one open fan: slides along its border edges only.
    pub const BORDER: u8 = 1;
    /// Non-manifold, pinched or inconsistently wound: never moves (others may move onto it).
    pub const LOCKED: u8 = 2;
    /// No triangle (unused or collapsed away).
    pub const GONE: u8 = 3;
    /// An end of a collapse in this pass.
    pub const PASS: u8 = 4;
    /// Scratch mark (the link condition).
    pub const MARK: u8 = 8;
    /// A collapse changed one of the vertex's triangles in this pass (or, in the fast mode,
    /// since its quadric was filled): fill takes its quadric again, perform its price.
    pub const DIRTY: u8 = 0x40;
    /// The bits of a fan list's end above the link type's width (see [`super::end`]): two, as
    /// `3·T` entries with `T ≤ L::COUNT` need at most two more bits than the link has.
    pub const HIGH: u8 = 0x30;
    /// Shift of [`HIGH`].
    pub const HIGH_SHIFT: u32 = 4;
    /// With wedges: a manifold vertex whose fan holds two wedges (a seam runs through it). It
    /// collapses only along a spoke where its wedge changes, onto a seam or locked vertex.
    pub const SEAM: u8 = 0x80;
}

/// The fast mode's working memory, sized at compile time (it can be a `static`).
///
/// * `L`: link type (`u16` or `u32`); with `u16` at most 65 535 vertices and triangles.
/// * `V`, `T`: the largest mesh it takes (vertices, triangles).
///
/// Per vertex: a quadric (6 `f32`, 24 B), four links (fan list end, border successor,
/// candidate target, sort slot), a candidate cost (`f32`) and a flag byte; per triangle three
/// fan list entries (one per corner); plus a histogram of [`BINS`](FastWorkspace::BINS) links. With `u16` links and
/// `V ≈ T/2` that is about 24.5 bytes per triangle ([`FastWorkspace::BYTES`]).
pub struct FastWorkspace<L: Index, const V: usize, const T: usize, N: Arithmetic = Float> {
    quadrics: [N::Stored; V],
    first: [L; V],
    border_next: [L; V],
    target: [L; V],
    cost: [u32; V],
    order: [L; V],
    flags: [u8; V],
    lists: [[L; 3]; T],
    histogram: [L; BINS],
}

impl<L: Index, const V: usize, const T: usize, N: Arithmetic> Default
    for FastWorkspace<L, V, T, N>
{
    fn default() -> Self {
        Self::new()
    }
}

/// Triangle `t` as `usize` indices (`NONE` if out of range).
#[inline]
pub(crate) fn tri<I: Index>(tris: &[[I; 3]], t: usize) -> [usize; 3] {
    match tris.get(t) {
        Some(x) => [x[0].to_usize(), x[1].to_usize(), x[2].to_usize()],
        None => [NONE; 3],
    }
}

/// Whether a triangle has a repeated index (collapsed away in this pass).
#[inline]
pub(crate) fn dead(tr: [usize; 3]) -> bool {
    tr[0] == tr[1] || tr[1] == tr[2] || tr[0] == tr[2]
}

/// The slot of `v` in `tr`.
#[inline]
pub(crate) fn slot(tr: [usize; 3], v: usize) -> Option<usize> {
    if tr[0] == v {
        Some(0)
    } else if tr[1] == v {
        Some(1)
    } else if tr[2] == v {
        Some(2)
    } else {
        None
    }
}

/// The vertices after and before slot `k` in winding order.
#[inline]
pub(crate) fn others(tr: [usize; 3], k: usize) -> (usize, usize) {
    match k {
        0 => (tr[1], tr[2]),
        1 => (tr[2], tr[0]),
        _ => (tr[0], tr[1]),
    }
}

/// Link `i` of `s` as `usize` (`NONE` for NIL or out of range).
#[inline]
pub(crate) fn link<L: Index>(s: &[L], i: usize) -> usize {
    match s.get(i) {
        Some(&l) if l != L::NIL => l.to_usize(),
        _ => NONE,
    }
}

/// Sets link `i` of `s` (NIL for `NONE`).
#[inline]
pub(crate) fn set_link<L: Index>(s: &mut [L], i: usize, v: usize) {
    if let Some(x) = s.get_mut(i) {
        *x = if v == NONE { L::NIL } else { L::narrow(v) };
    }
}

/// Flag byte of `v` (`GONE` if out of range).
#[inline]
pub(crate) fn flags_of(f: &[u8], v: usize) -> u8 {
    f.get(v).copied().unwrap_or(flag::GONE)
}

/// Whether a seam vertex may offer a collapse onto `x`: a seam or locked vertex (the spoke
/// may be the seam; the checks refuse one across which the wedge does not change).
#[inline]
pub(super) fn along(flags: &[u8], x: usize) -> bool {
    let f = flags_of(flags, x);
    f & flag::SEAM != 0 || f & flag::KIND == flag::LOCKED
}

/// Whether rule `name` is on in this build (`PIPELINE_RULE_OFF=<name>` at build time switches
/// one off; the rules' names are in `perform.rs`).
#[inline(always)]
pub(super) const fn on(name: &str) -> bool {
    let off = match option_env!("PIPELINE_RULE_OFF") {
        Some(s) => s.as_bytes(),
        None => b"",
    };
    let name = name.as_bytes();
    if off.len() != name.len() {
        return true;
    }
    let mut i = 0;
    while i < off.len() {
        if off[i] != name[i] {
            return true;
        }
        i += 1;
    }
    false
}

/// Bits of the link type `L`.
#[inline]
const fn bits<L>() -> u32 {
    (core::mem::size_of::<L>() * 8) as u32
}

/// Where `v`'s fan list ends in the fan lists (or, while they are built, the next free
/// entry): its low bits in `first[v]`, the bits above the link type's width in `v`'s flag
/// byte's [`flag::HIGH`] (3·T entries need two more bits than a `u16` link has).
#[inline]
pub(crate) fn end<L: Index>(first: &[L], flags: &[u8], v: usize) -> usize {
    let lo = first.get(v).map_or(0, |l| l.to_usize());
    let hi = ((flags_of(flags, v) & flag::HIGH) >> flag::HIGH_SHIFT) as usize;
    lo | hi.checked_shl(bits::<L>()).unwrap_or(0)
}

/// Sets `v`'s list end (below `4 << bits(L)`).
#[inline]
pub(crate) fn set_end<L: Index>(first: &mut [L], flags: &mut [u8], v: usize, s: usize) {
    let hi = s.checked_shr(bits::<L>()).unwrap_or(0);
    let lo = s ^ hi.checked_shl(bits::<L>()).unwrap_or(0);
    if let Some(l) = first.get_mut(v) {
        *l = L::narrow(lo);
    }
    if let Some(f) = flags.get_mut(v) {
        *f = (*f & !flag::HIGH) | (((hi as u8) << flag::HIGH_SHIFT) & flag::HIGH);
    }
}

/// Adds one to `v`'s list end, returning the old value.
#[inline]
pub(crate) fn bump_end<L: Index>(first: &mut [L], flags: &mut [u8], v: usize) -> usize {
    let (Some(l), Some(f)) = (first.get_mut(v), flags.get_mut(v)) else {
        return NONE;
    };
    let lo = l.to_usize();
    let hi = ((*f & flag::HIGH) >> flag::HIGH_SHIFT) as usize;
    let old = lo | hi.checked_shl(bits::<L>()).unwrap_or(0);
    match L::from_usize(lo + 1) {
        Some(n) if lo + 1 < L::COUNT => *l = n,
        _ if lo + 1 == L::COUNT => *l = L::NIL,
        _ => {
            *l = L::ZERO;
            *f = f.wrapping_add(1 << flag::HIGH_SHIFT);
        }
    }
    old
}

/// The triangle numbers around `v` (its fan list, highest first).
#[inline]
pub(crate) fn list<'m, L: Index>(first: &[L], flags: &[u8], lists: &'m [L], v: usize) -> &'m [L] {
    let s = match v.checked_sub(1) {
        Some(u) => end(first, flags, u),
        None => 0,
    };
    lists.get(s..end(first, flags, v)).unwrap_or(&[])
}

/// The triangles around one vertex, from its fan list.
pub(crate) struct Fan<'m, L: Index, I: Index> {
    tris: &'m [[I; 3]],
    list: core::slice::Iter<'m, L>,
    v: usize,
}

impl<L: Index, I: Index> Iterator for Fan<'_, L, I> {
    /// Triangle, its vertices, the slot of the vertex.
    type Item = (usize, [usize; 3], usize);

    #[inline]
    fn next(&mut self) -> Option<Self::Item> {
        let t = self.list.next()?.to_usize();
        // A number out of range ends the fan, as a triangle without the vertex does.
        let x = self.tris.get(t)?;
        let tr = [x[0].to_usize(), x[1].to_usize(), x[2].to_usize()];
        let k = slot(tr, self.v)?;
        Some((t, tr, k))
    }
}

/// The fan of `v`.
#[inline]
pub(crate) fn fan<'m, L: Index, I: Index>(
    tris: &'m [[I; 3]],
    (first, lists): (&[L], &'m [L]),
    flags: &[u8],
    v: usize,
) -> Fan<'m, L, I> {
    Fan {
        tris,
        list: list(first, flags, lists, v).iter(),
        v,
    }
}

/// What one pass or one run counted.
#[derive(Default)]
pub(crate) struct Stats<E> {
    pub(crate) collapses: usize,
    pub(crate) rejected: Rejections,
    /// Candidates not collapsed because their price was over the error limit.
    pub(crate) over_limit: u32,
    /// The largest error of a collapse made (the arithmetic's squared distance).
    pub(crate) worst: E,
}

impl<L: Index, const V: usize, const T: usize, N: Arithmetic> FastWorkspace<L, V, T, N> {
    /// Size of the workspace in bytes: all of the fast mode's RAM apart from the caller's
    /// triangle buffer, positions and a bounded stack frame.
    pub const BYTES: usize = core::mem::size_of::<Self>();

    /// Bins of the counting sort's histogram.
    pub const BINS: usize = BINS;

    /// An empty workspace; `const` and all zero bits, so a `static` goes to `.bss`.
    pub const fn new() -> Self {
        FastWorkspace {
            quadrics: [N::EMPTY; V],
            first: [L::ZERO; V],
            border_next: [L::ZERO; V],
            target: [L::ZERO; V],
            cost: [0; V],
            order: [L::ZERO; V],
            flags: [0; V],
            lists: [[L::ZERO; 3]; T],
            histogram: [L::ZERO; BINS],
        }
    }

    /// Simplifies `triangles` in place towards [`Config::target`], with read-only `positions`.
    ///
    /// On success the first `report.triangles_out` entries of `triangles` hold the result,
    /// every index an input vertex; the rest of the buffer is meaningless. Of the [`Config`]
    /// only `target`, `max_passes` and `error_limit` are used (the whole configuration is
    /// validated): no collapse whose error, as a distance, is over `error_limit`; a run
    /// stopped by it reports [`Stop::ErrorLimit`], with the largest error made as
    /// `collapse_error` and the refusals as `over_limit`.
    ///
    /// Errors, all returned before the triangle buffer is touched: [`Error::InvalidConfig`],
    /// [`Error::Capacity`], [`Error::IndexOutOfRange`], [`Error::NonFinitePosition`].
    pub fn simplify<I: Index>(
        &mut self,
        positions: &[N::Position],
        triangles: &mut [[I; 3]],
        config: &Config,
    ) -> Result<Report, Error> {
        self.run::<I, false>(positions, (triangles, &mut []), config)
    }

    /// [`simplify`](Self::simplify) on a welded mesh with wedges (`crate::seam`):
    /// `triangles` numbered by position (as `seam::weld` leaves them) and `wedges`
    /// the same triangles as the caller's vertices (one entry per triangle). The seams move
    /// as one surface: a vertex where the wedge changes across two of its spokes slides only
    /// along that seam, one where more than two wedges meet (or two on a border) never moves,
    /// and each moved corner takes the wedge of its new vertex on its own side of the seam
    /// (from the removed triangle of that side). On success the first
    /// `report.triangles_out` entries of `triangles` hold the result as wedges (the caller's
    /// vertices); `wedges` is scratch.
    ///
    /// Crate feature `fast` (`seam::weld` needs `seams`; a firmware may take cases welded by
    /// a host instead). Errors, before either buffer is touched: those of
    /// [`simplify`](Self::simplify), and
    /// [`Error::Capacity`] (triangles) if `wedges` is shorter than `triangles`,
    /// [`Error::IndexOutOfRange`] for a wedge past `positions`.
    pub fn simplify_with_wedges<I: Index>(
        &mut self,
        positions: &[N::Position],
        triangles: &mut [[I; 3]],
        wedges: &mut [[I; 3]],
        config: &Config,
    ) -> Result<Report, Error> {
        self.run::<I, true>(positions, (triangles, wedges), config)
    }

    /// The pipeline on this workspace's arrays, with wedges when `W`.
    #[inline(always)]
    fn run<I: Index, const W: bool>(
        &mut self,
        positions: &[N::Position],
        buffers: (&mut [[I; 3]], &mut [[I; 3]]),
        config: &Config,
    ) -> Result<Report, Error> {
        let nv = positions.len();
        let arrays = Arrays {
            first: &mut self.first,
            border_next: &mut self.border_next,
            target: &mut self.target,
            cost: &mut self.cost,
            order: &mut self.order,
            flags: &mut self.flags,
            lists: self.lists.as_flattened_mut(),
            histogram: &mut self.histogram,
        };
        let quadrics = self.quadrics.get_mut(..nv).unwrap_or(&mut []);
        run::<I, L, N, _, W>(positions, buffers, config, arrays, fill::Stored(quadrics))
    }
}

/// The lean mode's working memory: the fast mode's without the stored quadrics (each vertex's
/// quadric is built from its fan whenever a pass reads it), for about half the RAM.
///
/// * `L`: link type (`u16` or `u32`); with `u16` at most 65 535 vertices and triangles.
/// * `V`, `T`: the largest mesh it takes (vertices, triangles).
///
/// Per vertex three links (fan list end, candidate target, sort slot), a candidate cost
/// (`f32`) and a flag byte; per triangle three fan list entries; plus a histogram of
/// [`BINS`](LeanWorkspace::BINS) links. A border vertex's open edges are found from its fan
/// where the fast mode reads its stored successor. With `u16` links and `V ≈ T/2` that is
/// about 11.5 bytes per triangle ([`LeanWorkspace::BYTES`]).
pub struct LeanWorkspace<L: Index, const V: usize, const T: usize, N: Arithmetic = Float> {
    first: [L; V],
    target: [L; V],
    cost: [u32; V],
    order: [L; V],
    flags: [u8; V],
    lists: [[L; 3]; T],
    histogram: [L; BINS],
    arithmetic: PhantomData<N>,
}

impl<L: Index, const V: usize, const T: usize, N: Arithmetic> Default
    for LeanWorkspace<L, V, T, N>
{
    fn default() -> Self {
        Self::new()
    }
}

impl<L: Index, const V: usize, const T: usize, N: Arithmetic> LeanWorkspace<L, V, T, N> {
    /// Size of the workspace in bytes: all of the lean mode's RAM apart from the caller's
    /// triangle buffer, positions and a bounded stack frame.
    pub const BYTES: usize = core::mem::size_of::<Self>();

    /// Bins of the counting sort's histogram.
    pub const BINS: usize = BINS;

    /// An empty workspace; `const` and all zero bits, so a `static` goes to `.bss`.
    pub const fn new() -> Self {
        LeanWorkspace {
            first: [L::ZERO; V],
            target: [L::ZERO; V],
            cost: [0; V],
            order: [L::ZERO; V],
            flags: [0; V],
            lists: [[L::ZERO; 3]; T],
            histogram: [L::ZERO; BINS],
            arithmetic: PhantomData,
        }
    }

    /// Simplifies `triangles` in place towards [`Config::target`], with read-only `positions`:
    /// [`FastWorkspace::simplify`]'s contract, errors and configuration, its passes and checks,
    /// each quadric built from its vertex's fan where the fast mode reads a stored one.
    pub fn simplify<I: Index>(
        &mut self,
        positions: &[N::Position],
        triangles: &mut [[I; 3]],
        config: &Config,
    ) -> Result<Report, Error> {
        self.run::<I, false>(positions, (triangles, &mut []), config)
    }

    /// [`FastWorkspace::simplify_with_wedges`] in the lean mode: a welded mesh with wedges,
    /// the same contract and errors.
    pub fn simplify_with_wedges<I: Index>(
        &mut self,
        positions: &[N::Position],
        triangles: &mut [[I; 3]],
        wedges: &mut [[I; 3]],
        config: &Config,
    ) -> Result<Report, Error> {
        self.run::<I, true>(positions, (triangles, wedges), config)
    }

    /// The pipeline on this workspace's arrays, with wedges when `W`.
    #[inline(always)]
    fn run<I: Index, const W: bool>(
        &mut self,
        positions: &[N::Position],
        buffers: (&mut [[I; 3]], &mut [[I; 3]]),
        config: &Config,
    ) -> Result<Report, Error> {
        let arrays = Arrays {
            first: &mut self.first,
            border_next: &mut [],
            target: &mut self.target,
            cost: &mut self.cost,
            order: &mut self.order,
            flags: &mut self.flags,
            lists: self.lists.as_flattened_mut(),
            histogram: &mut self.histogram,
        };
        run::<I, L, N, _, W>(positions, buffers, config, arrays, fill::Fans)
    }
}

/// compact, with the wedges when `W`.
#[inline(always)]
fn compact_pass<I: Index, const W: bool>(
    (triangles, wedges): (&mut [[I; 3]], &mut [[I; 3]]),
    nt: usize,
    counts: &mut [u32],
) -> (usize, usize) {
    if W {
        compact::compact_wedges((triangles, wedges), nt, counts)
    } else {
        compact::compact(triangles, nt, counts)
    }
}

/// The wedge buffer against the triangles: long enough, every wedge a vertex.
fn check_wedges<I: Index>(nv: usize, nt: usize, wedges: &[[I; 3]]) -> Result<(), Error> {
    let Some(wedges) = wedges.get(..nt) else {
        return Err(Error::Capacity {
            what: Capacity::Triangles,
            needed: nt,
            available: wedges.len(),
        });
    };
    for (t, w) in wedges.iter().enumerate() {
        for &i in w {
            if i.to_usize() >= nv {
                return Err(Error::IndexOutOfRange {
                    triangle: t,
                    index: i.to_usize(),
                });
            }
        }
    }
    Ok(())
}

/// A workspace's arrays apart from the quadrics, at its capacity (`border_next` empty in the
/// lean mode).
struct Arrays<'w, L: Index> {
    first: &'w mut [L],
    border_next: &'w mut [L],
    target: &'w mut [L],
    cost: &'w mut [u32],
    order: &'w mut [L],
    flags: &'w mut [u8],
    lists: &'w mut [L],
    histogram: &'w mut [L; BINS],
}

/// The pipeline, top to bottom (module documentation), with quadrics from `quadrics`; with
/// wedges when `W` (`wedges` then at least as long as `triangles`, else unused).
fn run<'p, I: Index, L: Index, N: Arithmetic, Q: fill::Quadrics<N::Frame<'p>>, const W: bool>(
    positions: &'p [N::Position],
    (triangles, wedges): (&mut [[I; 3]], &mut [[I; 3]]),
    config: &Config,
    w: Arrays<'_, L>,
    mut quadrics: Q,
) -> Result<Report, Error> {
    config.validate()?;
    if W {
        check_wedges(positions.len(), triangles.len(), wedges)?;
    }
    let wedges = if W {
        wedges.get_mut(..triangles.len()).unwrap_or(&mut [])
    } else {
        &mut []
    };
    let (cv, ct) = (
        w.first.len().min(L::COUNT),
        (w.lists.len() / 3).min(L::COUNT),
    );
    let frame = N::frame(positions, triangles, (cv, ct), w.flags)?;
    let nv = positions.len();
    let short = Error::Capacity {
        what: Capacity::Vertices,
        needed: nv,
        available: cv,
    };
    let Arrays {
        first,
        border_next,
        target,
        cost,
        order,
        flags,
        lists,
        histogram,
    } = w;
    // The lean mode has no border successors (an empty slice: `link` reads NONE, `set_link`
    // writes nothing).
    let border_next = if Q::STORES_BORDERS {
        border_next.get_mut(..nv)
    } else {
        Some(border_next)
    };
    let (Some(first), Some(border_next), Some(target), Some(cost), Some(order), Some(flags)) = (
        first.get_mut(..nv),
        border_next,
        target.get_mut(..nv),
        cost.get_mut(..nv),
        order.get_mut(..nv),
        flags.get_mut(..nv),
    ) else {
        return Err(short);
    };
    let triangles_in = triangles.len();
    // build
    let (mut nt, degenerate) = compact_pass::<I, W>((triangles, wedges), triangles_in, cost);
    build::link(triangles, nt, (first, flags), cost, lists);

    // classify (and duplicates)
    let (mut locked, duplicates) = classify::classify(
        triangles,
        nt,
        (&*first, lists.get(..3 * nt).unwrap_or(&[])),
        flags,
        border_next,
    );
    if duplicates > 0 {
        nt = compact_pass::<I, W>((triangles, wedges), nt, cost).0;
        build::link(triangles, nt, (first, flags), cost, lists);
    }
    if W {
        let adj = (&*first, lists.get(..3 * nt).unwrap_or(&[]));
        locked += classify::seams(triangles, wedges, nt, adj, flags);
    }
    let valid = nt;

    // The limit as an error: a squared distance in the run's frame.
    let limit = frame.limit(config.error_limit);

    let target_triangles = <N::Frame<'p> as Geometry>::target(config.target, valid);
    let mut stats = Stats::default();
    let mut passes = 0u32;
    // The input's area, for the price's mean triangle area.
    let mut area = <N::Frame<'p> as Geometry>::AREA_ZERO;
    let mut pass_triangles = heapless::Vec::new();
    // prune: the smallest part's size (0 until measured), the parts gone.
    let prune = config.prune_parts;
    let mut next_part = <N::Frame<'p> as Geometry>::ERR_ZERO;
    let (mut parts_removed, mut part_vertices) = (0usize, 0usize);
    let mut stop = loop {
        if nt <= target_triangles {
            break Stop::Target;
        }
        if passes >= config.max_passes {
            break Stop::MaxPasses;
        }
        let tris = triangles.get(..nt).unwrap_or(&[]);
        let adj = (&*first, lists.get(..3 * nt).unwrap_or(&[]));
        let summed = quadrics.fill::<I, L, W>(&frame, tris, adj, flags, border_next, passes == 0);
        if passes == 0 {
            area = summed.unwrap_or_else(|| fill::area(&frame, tris));
        }
        let mean = <N::Frame<'p> as Geometry>::mean_area(area, nt);
        pick::pick::<I, L, _, Q, W>(
            &frame,
            tris,
            adj,
            flags,
            border_next,
            (&quadrics, mean),
            (&mut *target, &mut *cost),
            histogram,
        );
        let m = sort::sort::<L, N::Frame<'p>>(target, cost, order, histogram);
        if m == 0 {
            break Stop::NoLegalCollapse;
        }
        let tris = triangles.get_mut(..nt).unwrap_or(&mut []);
        let corners = wedges.get_mut(..nt).unwrap_or(&mut []);
        // A pass aims at half the live triangles at most (see `PASS_SHARE`).
        let goal = (nt - target_triangles).min((nt / PASS_SHARE).max(2));
        let refused = stats.over_limit;
        let done = perform::perform::<I, L, _, Q, W>(
            &frame,
            (tris, corners),
            (&*first, lists.get(..3 * nt).unwrap_or(&[])),
            flags,
            border_next,
            (&quadrics, mean),
            (&mut *target, &*cost, order.get(..m).unwrap_or(&[])),
            (goal, limit, prune),
            &mut stats,
        );
        passes += 1;
        nt = compact_pass::<I, W>((triangles, wedges), nt, cost).0;
        // prune: every part within the error made so far (meshoptimizer's cutoff); the parts'
        // labels overwrite compact's counts, so compact runs again.
        if prune && nt > target_triangles && stats.worst >= next_part {
            let p = prune::prune(&frame, triangles, nt, flags, (order, cost), stats.worst);
            next_part = p.next;
            parts_removed += p.parts;
            part_vertices += p.vertices;
            nt = compact_pass::<I, W>((triangles, wedges), nt, cost).0;
        }
        let _ = pass_triangles.push(nt as u32);
        if done == 0 {
            break if stats.over_limit > refused {
                Stop::ErrorLimit
            } else {
                Stop::NoLegalCollapse
            };
        }
        // No fan lists for a pass that will not run.
        if nt > target_triangles && passes < config.max_passes {
            build::link(triangles, nt, (first, flags), cost, lists);
            compact::unlock(flags);
        }
    };
    // No collapse left short of the target: the smallest parts, up to 1.5 times the smallest
    // size at a time (meshoptimizer's step) and the error limit. Each round removes a part or
    // raises the smallest size, so it ends within a round per vertex.
    if prune && matches!(stop, Stop::ErrorLimit | Stop::NoLegalCollapse) {
        for _ in 0..=nv {
            if nt <= target_triangles
                || next_part > limit
                || !<N::Frame<'p> as Geometry>::finite(next_part)
            {
                break;
            }
            let cutoff = <N::Frame<'p> as Geometry>::grow(next_part, limit);
            let p = prune::prune(&frame, triangles, nt, flags, (order, cost), cutoff);
            parts_removed += p.parts;
            part_vertices += p.vertices;
            if p.largest > stats.worst {
                stats.worst = p.largest;
            }
            nt = compact_pass::<I, W>((triangles, wedges), nt, cost).0;
            next_part = p.next;
        }
        if nt <= target_triangles {
            stop = Stop::Target;
        }
    }
    // With wedges the output names them.
    if W {
        for (t, w) in triangles.iter_mut().zip(wedges.iter()).take(nt) {
            *t = *w;
        }
    }
    // A finite limit, by its bits (a float compare is a library call on a core without FPU).
    let collapse_error = if config.error_limit.to_bits() & 0x7fff_ffff < 0x7f80_0000 {
        frame.distance(stats.worst)
    } else {
        0.0
    };
    Ok(Report {
        triangles_in,
        degenerate_dropped: degenerate,
        duplicates_dropped: duplicates,
        twins: 0,
        triangles_out: nt,
        target_triangles,
        target_reached: nt <= target_triangles,
        stop,
        collapses: stats.collapses,
        vertices_removed: stats.collapses + part_vertices,
        parts_removed,
        locked_vertices: locked,
        feature_vertices: 0,
        passes,
        pass_triangles,
        rejected: stats.rejected,
        over_limit: stats.over_limit,
        collapse_error,
        max_error: None,
        mean_error: None,
    })
}
