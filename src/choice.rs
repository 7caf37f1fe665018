//! Policies chosen at run time, for hosts: a command line or a configuration file picks the
//! cost, the error bound and the operator, and one call runs them ([`Storage::run_chosen`]).
//!
//! The policies of [`Storage::start`] are types, so that a firmware carries only the code of
//! the ones it uses. A host that decides at run time would otherwise write a `match` over every
//! combination itself; this module is that `match`, once. Each combination is still its own
//! instantiation of the engine, so a firmware that knows its policies calls
//! [`Storage::start`] with them and carries one.
//!
//! ```
//! use tinydecimate::choice::{Chosen, ChosenBound, ChosenCost, ChosenOperator};
//! use tinydecimate::{Builtin, Config, Positions, Workspace};
//!
//! let positions = [[0.0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
//! let mut triangles = [[0u16, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];
//! let mut ws = Workspace::<u16, 8, 8>::new();
//! // What a command line said: the built-in cost, no bound, edge collapse.
//! let chosen: Chosen<'_, u16, u16, 0> = Chosen::new(
//!     ChosenCost::Builtin(Builtin::new()),
//!     ChosenBound::None,
//!     ChosenOperator::Edge,
//! );
//! let report = ws.as_storage().run_chosen(
//!     Positions::Read(&positions),
//!     &mut triangles,
//!     &Config::new().with_ratio(0.5),
//!     chosen,
//!     |_removed| {},
//! )?;
//! assert!(report.triangles_out <= 4);
//! # Ok::<(), tinydecimate::Error>(())
//! ```

use crate::bound::{Controls, Envelope, NoBound};
use crate::cost::{AttributeQuadric, Builtin, Energy, StoredQuadric};
use crate::operator::{EdgeCollapse, TriangleCollapse, VertexDecimation};
use crate::{Config, Error, Index, Positions, Report, Storage};

/// The cost of a run, chosen at run time.
pub enum ChosenCost<'a, const N: usize> {
    /// The configuration's built-in cost ([`Config::cost`]).
    Builtin(Builtin),
    /// Stored quadrics, subset or optimal placement.
    Stored(StoredQuadric<'a>),
    /// Stored quadrics with `N` attributes per vertex.
    Attributes(AttributeQuadric<'a, 'a, N>),
    /// Hoppe's energy.
    Energy(Energy<'a>),
}

/// The error bound of a run, chosen at run time.
pub enum ChosenBound<'a, I: Index> {
    /// No bound.
    None,
    /// The guaranteed bound at control points ([`Config::with_max_error`]).
    Controls(Controls<'a, I, u32>),
    /// The two-sided bound of simplification envelopes ([`Config::with_max_error`]).
    Envelope(Envelope<'a, I, u32>),
}

/// The operator of a run, chosen at run time.
pub enum ChosenOperator {
    /// Half-edge collapse.
    Edge,
    /// Triangle collapse.
    Triangle,
    /// Vertex decimation, with its fill.
    VertexDecimation(VertexDecimation),
}

/// Everything a run takes beside the mesh and the configuration: the three policies and the
/// optional parts of a run (welded seams, part pruning), each on the caller's storage.
pub struct Chosen<'a, I: Index, L: Index, const N: usize> {
    cost: ChosenCost<'a, N>,
    bound: ChosenBound<'a, I>,
    operator: ChosenOperator,
    #[cfg(feature = "seams")]
    wedges: Option<(&'a mut [[I; 3]], crate::seam::SeamCorners)>,
    #[cfg(feature = "parts")]
    parts: Option<&'a mut [[L; 2]]>,
    budget: u32,
    links: core::marker::PhantomData<L>,
}

impl<'a, I: Index, L: Index, const N: usize> Chosen<'a, I, L, N> {
    /// A run with these policies, no welded seams and no part pruning.
    pub fn new(
        cost: ChosenCost<'a, N>,
        bound: ChosenBound<'a, I>,
        operator: ChosenOperator,
    ) -> Self {
        Chosen {
            cost,
            bound,
            operator,
            #[cfg(feature = "seams")]
            wedges: None,
            #[cfg(feature = "parts")]
            parts: None,
            budget: 1 << 14,
            links: core::marker::PhantomData,
        }
    }

    /// Welded seams: [`Simplifier::with_wedges`](crate::Simplifier::with_wedges) with
    /// `wedges` (crate feature `seams`).
    #[cfg(feature = "seams")]
    pub fn with_wedges(
        mut self,
        wedges: &'a mut [[I; 3]],
        corners: crate::seam::SeamCorners,
    ) -> Self {
        self.wedges = Some((wedges, corners));
        self
    }

    /// Part pruning: [`Simplifier::with_parts`](crate::Simplifier::with_parts) with `links`
    /// (crate feature `parts`).
    #[cfg(feature = "parts")]
    pub fn with_parts(mut self, links: &'a mut [[L; 2]]) -> Self {
        self.parts = Some(links);
        self
    }

    /// The operations per [`Simplifier::step`](crate::Simplifier::step) between two calls of
    /// the progress function (16 384 by default; the output does not depend on it).
    pub fn with_budget(mut self, budget: u32) -> Self {
        self.budget = budget.max(1);
        self
    }
}

impl<'a, L: Index> Storage<'a, L> {
    /// Runs [`Storage::start`] with the policies of `chosen`, with its welded seams and part
    /// pruning when given, to the end, calling `progress` with the triangles removed so far
    /// after every step (the last call has them all); returns the run's [`Report`]. The output is the one the same
    /// policies give through [`Storage::start`]. Errors: those of `start`, of the cost's
    /// placement and of the run's options.
    pub fn run_chosen<I: Index, const N: usize>(
        self,
        positions: Positions<'a>,
        triangles: &'a mut [[I; 3]],
        config: &Config,
        chosen: Chosen<'a, I, L, N>,
        mut progress: impl FnMut(usize),
    ) -> Result<Report, Error> {
        let Chosen {
            cost,
            bound,
            operator,
            #[cfg(feature = "seams")]
            wedges,
            #[cfg(feature = "parts")]
            parts,
            budget,
            links: _,
        } = chosen;
        // One instantiation per combination: the policies are types.
        macro_rules! run {
            ($cost:expr, $bound:expr, $op:expr) => {{
                let s = self.start(positions, triangles, config, $cost, $bound, $op)?;
                #[cfg(feature = "seams")]
                let s = match wedges {
                    Some((w, corners)) => s.with_wedges(w, corners)?,
                    None => s,
                };
                #[cfg(feature = "parts")]
                let s = match parts {
                    Some(links) => s.with_parts(links)?,
                    None => s,
                };
                let mut s = s;
                let before = s.live_triangles();
                loop {
                    let done = s.step(budget);
                    progress(before.saturating_sub(s.live_triangles()));
                    if done {
                        break;
                    }
                }
                Ok(s.finish())
            }};
        }
        macro_rules! with_operator {
            ($cost:expr, $bound:expr) => {
                match operator {
                    ChosenOperator::Edge => run!($cost, $bound, EdgeCollapse),
                    ChosenOperator::Triangle => run!($cost, $bound, TriangleCollapse),
                    ChosenOperator::VertexDecimation(d) => run!($cost, $bound, d),
                }
            };
        }
        macro_rules! with_bound {
            ($cost:expr) => {
                match bound {
                    ChosenBound::None => with_operator!($cost, NoBound),
                    ChosenBound::Controls(c) => with_operator!($cost, c),
                    ChosenBound::Envelope(e) => with_operator!($cost, e),
                }
            };
        }
        match cost {
            ChosenCost::Builtin(c) => with_bound!(c),
            ChosenCost::Stored(c) => with_bound!(c),
            ChosenCost::Attributes(c) => with_bound!(c),
            ChosenCost::Energy(c) => with_bound!(c),
        }
    }
}
