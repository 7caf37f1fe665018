//! The simplification operator: a type parameter of the engine ([`Storage::start`]'s
//! `operator` argument), so that an image carries the code of the one it uses only.
//!
//! Adding one: a type here with its [`Kind`] (and sealed impl), its method in a file of its
//! own under `src/operator/` (as [`VertexDecimation`] in `operator/decimate/`), and an
//! engine path only if no existing [`Kind`] fits.
//!
//! [`Storage::start`]: crate::Storage::start

mod decimate;

pub(crate) use decimate::{classify, plan, Fan as RemovalFan, MAX_RING};
pub use decimate::{Fill, VertexDecimation};

mod sealed {
    pub trait Sealed {}
    impl Sealed for super::EdgeCollapse {}
    impl Sealed for super::TriangleCollapse {}
    impl Sealed for super::VertexDecimation {}
}

/// Which path of the engine an operator takes.
#[doc(hidden)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// Half-edge collapse: the engine's own path.
    Edge,
    /// Triangle collapse, as half-edge moves (`engine/triangle.rs`).
    Triangle,
    /// Vertex removal: a vertex's fan is replaced by a triangulation of its ring
    /// (`engine/remove.rs`, `Mesh::replace_fan`).
    Removal,
}

/// An operator: [`EdgeCollapse`], [`TriangleCollapse`] or [`VertexDecimation`].
pub trait Operator: sealed::Sealed + Copy {
    /// The engine's path for it (compile-time: the engine's branches on it fold away).
    #[doc(hidden)]
    const KIND: Kind;

    /// A vertex-removal operator's parameters (`None` for the collapses).
    #[doc(hidden)]
    #[inline(always)]
    fn removal(&self) -> Option<VertexDecimation> {
        None
    }

    /// When a round ends without an operation: relaxes the operator for one more round;
    /// `false` if it cannot (the collapses never can).
    #[doc(hidden)]
    #[inline(always)]
    fn relax(&mut self) -> bool {
        false
    }
}

/// Half-edge collapse (the default): one vertex moves onto a neighbour.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct EdgeCollapse;

impl Operator for EdgeCollapse {
    const KIND: Kind = Kind::Edge;
}

/// Triangle collapse (Zhu, Wang and Meng 2007, §3): a triangle's three vertices merge into
/// one of them, smallest weight `W = A (α + rc + d_max)` (eq. 3) first. Greedy schedule only
/// ([`Storage::start`](crate::Storage::start) refuses [`Schedule::Passes`](crate::Schedule::Passes)
/// with [`ConfigField::Operator`](crate::ConfigField::Operator)).
///
///
/// A triangle's three vertices merge into one. The paper puts the new vertex where the normal
/// of the mean plane through the fan (eq. 1-2) meets the original surface; here positions stay
/// read only, so the new vertex is **one of the three** (subset placement): the one whose two
/// half-edge moves the cost prices lowest. The collapse is made as those two moves, `x -> k`
/// then `y -> k`, each checked by the engine's rules and the error bound on the mesh it sees:
///
/// * the loop-of-three test (fig. 4: two triangles of the fan would coincide) is the link and
///   duplicate rules of [`legality`](crate::Reject::Link);
/// * the flip test (fig. 5) is the normal-turn and fold rules;
/// * the bound test (§3 steps 6-8) is the control-point veto ([`crate::bound`]).
///
/// If the first move is refused for all three choices of `k`, the triangle is refused. If the
/// second is refused, the first stands (the triangle collapse degenerates to an edge collapse:
/// positions are read only and the engine has no undo).
///
/// Order (eq. 3): `W_i = A_i (w_α α_i + w_v rc_i + w_d d_i,max)`, smallest first, with the
/// paper's weights `w_α = w_v = w_d = 1`: `A_i` the area, `α_i = 2(Σ cos β_k − 1)` (1 for an
/// equilateral triangle, 0 for a degenerate one), `rc_i = |r_new − 6| / 12` with `r_new` the
/// valence the merged vertex would have (`r_a + r_b + r_c − 9` for an interior triangle), and
/// `d_i,max` the largest distance of the triangle's control points to it (with a bound; 0
/// without). Lengths are in the engine's normalised units.
///
/// Schedule: each vertex is keyed by the smallest `W` of its triangles, in the engine's
/// indexed heap (no per-triangle storage: the extra RAM is the bound's alone). At a pop the
/// vertex's triangles are tried in `W` order; if all are refused its key is multiplied by the
/// penalty `p = 5` (the paper's value) and it goes back in the queue, at most
/// three times before it is dropped until its fan changes (which bounds the pops
/// between two collapses).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct TriangleCollapse;

impl Operator for TriangleCollapse {
    const KIND: Kind = Kind::Triangle;
}

impl Operator for VertexDecimation {
    const KIND: Kind = Kind::Removal;

    #[inline(always)]
    fn removal(&self) -> Option<VertexDecimation> {
        Some(*self)
    }

    fn relax(&mut self) -> bool {
        self.grow()
    }
}

/// The penalty factor `p > 1` for a refused triangle (Zhu, Wang and Meng 2007 §3: `p = 5`).
pub(crate) const PENALTY: f32 = 5.0;

/// How many times in a row a vertex's key is multiplied by [`PENALTY`] before it is dropped
/// from the queue until its fan changes.
pub(crate) const MAX_PENALTIES: u32 = 3;
