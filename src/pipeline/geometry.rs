//! geometry: everything the pipeline computes from positions, behind one trait, so that the
//! passes, the sort and the checks are written once and run in either arithmetic: `f32` in
//! the unit frame ([`Float`], `super::float`) or integers on a 15-bit grid ([`Integer`],
//! `super::integer`). The topology (fans, kinds, the link condition, compaction) never reads
//! a position and is shared as it is.
//!
//! A firmware picks one arithmetic with the workspace's type parameter and carries only
//! that one's code.

use crate::error::Error;
use crate::index::Index;
use crate::legality::Reject;

/// The arithmetic of a pipeline run, chosen by a workspace's last type parameter:
/// [`Float`] (the default: `f32` positions) or [`Integer`] (`u16` positions on a 15-bit grid,
/// no floating-point operation in the run). Sealed: implemented by those two only.
pub trait Arithmetic: sealed::Sealed {
    /// A vertex position as the caller stores it.
    type Position: Copy;
    /// A stored quadric (the fast mode's per-vertex array).
    #[doc(hidden)]
    type Stored: Copy;
    /// An empty stored quadric (a workspace's initial value).
    #[doc(hidden)]
    const EMPTY: Self::Stored;
    /// The run's frame: the positions as the pipeline reads them.
    #[doc(hidden)]
    type Frame<'p>: Geometry<Q = Self::Stored>;
    /// Checks capacities, indices and positions (writing only `used`, scratch) and returns
    /// the frame.
    #[doc(hidden)]
    fn frame<'p, I: Index>(
        positions: &'p [Self::Position],
        triangles: &[[I; 3]],
        capacity: (usize, usize),
        used: &mut [u8],
    ) -> Result<Self::Frame<'p>, Error>;
}

/// `f32` positions, in the unit frame (the bounding box's corner at the origin, scaled by a
/// power of two to an extent in `[1, 2)`): the pipeline's default arithmetic.
pub struct Float;

/// `u16` positions on a 15-bit grid (every coordinate below 32 768: `quantise` puts a float
/// mesh there), and only integer operations in the run: for cores without an FPU. See
/// `pipeline::integer` for the widths.
pub struct Integer;

pub(crate) mod sealed {
    /// Implemented by [`Float`](super::Float) and [`Integer`](super::Integer) only.
    pub trait Sealed {}
    impl Sealed for super::Float {}
    impl Sealed for super::Integer {}
}

/// The pass's error goal over the price of the candidate that would reach its goal
/// (`perform::ERROR_GOAL` or `perform::TAIL_GOAL`).
#[derive(Clone, Copy)]
pub enum Goal {
    /// 0.9: a pass stops before the price of its last planned collapse.
    Error,
    /// 1.5: in a run's tail.
    Tail,
}

/// What the pipeline computes from positions: quadrics, prices, errors and the geometric
/// rules of `perform`. Each method is one decision of the float pipeline; [`Float`]'s
/// implementation is that code as it was, [`Integer`]'s the same decision in fixed point.
pub trait Geometry {
    /// A position in the run's frame.
    type P: Copy;
    /// A quadric while its planes are summed.
    type Sum: Copy;
    /// A quadric as pick and perform read it (and the fast mode stores it).
    type Q: Copy + Default;
    /// `dᵀQd` for one vertex's quadric: compared between that vertex's targets only.
    type Raw: Copy + PartialOrd;
    /// A price: ordered, stored in the candidates' `u32` array, binned by the sort.
    type Cost: Copy + PartialOrd;
    /// A mean squared distance: a collapse's error, a part's size, the error limit.
    type Err: Copy + PartialOrd + Default;
    /// An area (the input's, and the mean triangle's).
    type Area: Copy;
    /// A triangle's normal as the rules read it.
    type N: Copy;

    /// No planes.
    const EMPTY: Self::Sum;
    /// Above every `Raw`.
    const RAW_MAX: Self::Raw;
    /// Above every price.
    const COST_MAX: Self::Cost;
    /// The cheapest price.
    const COST_ZERO: Self::Cost;
    /// No error.
    const ERR_ZERO: Self::Err;
    /// No limit; also "no part left" for prune.
    const ERR_MAX: Self::Err;
    /// No area.
    const AREA_ZERO: Self::Area;
    /// A position to fill scratch arrays with.
    const ORIGIN: Self::P;

    /// Position of vertex `v` (the origin for an index out of range).
    fn at(&self, v: usize) -> Self::P;

    /// Adds the plane of triangle `p` weighted by its area (`p[0]` the quadric's vertex).
    fn face(&self, s: &mut Self::Sum, p: [Self::P; 3]);
    /// [`face`](Self::face), not inlined: for the fan walks off the hot path.
    fn face_call(&self, s: &mut Self::Sum, p: [Self::P; 3]);
    /// Adds the quadric of open edge `p0 → p1` of triangle `(p0, p1, p2)`: the plane through
    /// the edge perpendicular to the triangle, weighted by the edge's length times the border
    /// weight, and the triangle's plane at the border weight times its area; nothing for a
    /// degenerate edge or triangle.
    fn border_edge(&self, s: &mut Self::Sum, p: [Self::P; 3]);
    /// Adds the plane through seam spoke `v-w` perpendicular to triangle `(v, w, o)`, weighted
    /// by the spoke's length times the seam weight.
    fn seam_spoke(&self, s: &mut Self::Sum, pv: Self::P, pw: Self::P, po: Self::P);
    /// The quadric of a sum.
    fn finish(&self, s: Self::Sum) -> Self::Q;

    /// The area of triangle `p`.
    fn face_area(&self, p: [Self::P; 3]) -> Self::Area;
    /// `a + b`.
    fn add_area(a: Self::Area, b: Self::Area) -> Self::Area;
    /// The mean triangle area: `total` over `triangles`.
    fn mean_area(total: Self::Area, triangles: usize) -> Self::Area;

    /// `dᵀQd` for `d = to - from`.
    fn raw(&self, q: &Self::Q, from: Self::P, to: Self::P) -> Self::Raw;
    /// The price of a move whose `dᵀQd` is `raw`: the default cost's, `raw · (1 + Ā/W)`.
    fn price(&self, mean: Self::Area, q: &Self::Q, raw: Self::Raw) -> Self::Cost;
    /// The error behind price `cost` of moving `from → to` under `q`: the weighted mean
    /// squared distance, `raw / W`.
    fn error(
        &self,
        mean: Self::Area,
        q: &Self::Q,
        from_to: (Self::P, Self::P),
        cost: Self::Cost,
    ) -> Self::Err;
    /// The larger of two prices.
    fn cost_max(a: Self::Cost, b: Self::Cost) -> Self::Cost;
    /// `cost` times the pass's error goal factor.
    fn goal(cost: Self::Cost, goal: Goal) -> Self::Cost;
    /// A price as stored in the candidates' array.
    fn cost_bits(c: Self::Cost) -> u32;
    /// A stored price.
    fn cost_of(bits: u32) -> Self::Cost;
    /// The counting sort's bin of a stored price (below `super::BINS`, monotone).
    fn key(bits: u32) -> usize;

    /// [`Target::triangles`](crate::Target::triangles): the triangle count a run stops at.
    fn target(target: crate::Target, valid: usize) -> usize;
    /// The error limit (a distance in the positions' units) as an error.
    fn limit(&self, distance: f32) -> Self::Err;
    /// Whether error `e` is over `limit` (NaN is).
    fn over(e: Self::Err, limit: Self::Err) -> bool;
    /// Whether an error is below [`ERR_MAX`](Self::ERR_MAX).
    fn finite(e: Self::Err) -> bool;
    /// `e` times 1.5 (prune's step), at most `limit`.
    fn grow(e: Self::Err, limit: Self::Err) -> Self::Err;
    /// An error as a distance in the positions' units (for the report).
    fn distance(&self, e: Self::Err) -> f32;
    /// The squared distance from `a` to `b` as an error (a part's size).
    fn size(&self, a: Self::P, b: Self::P) -> Self::Err;
    /// An error as stored in the scratch array.
    fn err_bits(e: Self::Err) -> u32;
    /// A stored error.
    fn err_of(bits: u32) -> Self::Err;

    /// Rules 2 of `perform` on triangle `(a, x, y)` as `a` moves onto `b` (`p` = `[a, b, x,
    /// y]`): zero area (`area`), the flip test (`flip`) and, with wedges (`thin`), the sliver
    /// preference. The moved triangle's normal, or the rule that refuses.
    fn survivor(&self, p: [Self::P; 4], rules: (bool, bool, bool)) -> Result<Self::N, Reject>;
    /// The normal of triangle `p`.
    fn normal(&self, p: [Self::P; 3]) -> Self::N;
    /// Whether two triangles sharing an edge fold onto each other (`a` a survivor's normal);
    /// a neighbour without a direction counts as folded.
    fn folded(a: Self::N, b: Self::N) -> bool;

    /// The fast mode's fill before a pass: the stored quadrics of every vertex (`all`) or of
    /// the dirty ones, and the dirty bits cleared. Returns the triangles' area if it summed
    /// it on the way.
    #[allow(clippy::too_many_arguments)]
    fn fill_stored<I: Index, L: Index, const W: bool>(
        &self,
        triangles: &[[I; 3]],
        adj: (&[L], &[L]),
        flags: &mut [u8],
        border_next: &[L],
        stored: &mut [Self::Q],
        all: bool,
    ) -> Option<Self::Area>;
}
