//! # tinydecimate
//!
//! A triangle mesh simplifier for microcontrollers: no heap, no `unsafe`, no panics, and every
//! byte of working memory fixed at compile time. Positions are only read (they may stay in
//! flash); the triangles are simplified in place in the caller's buffer, and a [`Report`]
//! says what was done and why the run stopped.
//!
//! ## Three ways in
//!
//! 1. **[`Workspace::simplify`]**: one call with a [`Config`]. The default is greedy edge
//!    collapse with a memoryless quadric cost, in a [`Workspace`] sized by its type
//!    (`Workspace::<u16, V, T>::BYTES`, known at compile time).
//! 2. **[`Workspace::start`]**: the same engine with its three policies as values, each on the
//!    caller's storage: the cost ([`cost`]: stored quadrics, the paper's normal variation,
//!    Hoppe's energy), the error bound ([`bound`]: a guaranteed distance at control points)
//!    and the operator ([`operator`]: edge collapse, triangle collapse, vertex decimation). It
//!    returns a [`Simplifier`]: `run` it to the end, or `step(budget)` between a watchdog's
//!    kicks; every step leaves a valid mesh.
//! 3. **`pipeline::FastWorkspace`** (crate feature `fast`): meshoptimizer's pipeline (stored
//!    quadrics, passes sorted by cost) in fixed memory with every output valid, the fastest
//!    way; `pipeline::LeanWorkspace` is the same in the first way's memory. Both also run in
//!    integers on a 15-bit grid (`pipeline::Integer`, for cores without an FPU).
//!
//! Beside them: [`cluster`] for meshes larger than RAM (vertex clustering of a stream),
//! [`progressive`] and [`stream`] for progressive meshes sent over a link, [`remap`] for the
//! per-vertex attributes after a run, and `model` (crate feature `seams`) for real-world
//! models: seams welded, small parts pruned, in one call.
//!
//! ```
//! use tinydecimate::{Config, Schedule, Workspace};
//!
//! // A 4x4 grid of quads on the plane z = 0: 32 triangles.
//! let mut positions = [[0.0f32; 3]; 25];
//! for (i, p) in positions.iter_mut().enumerate() {
//!     *p = [(i % 5) as f32, (i / 5) as f32, 0.0];
//! }
//! let mut triangles = [[0u16; 3]; 32];
//! for y in 0..4u16 {
//!     for x in 0..4u16 {
//!         let v = y * 5 + x;
//!         let q = usize::from(y * 4 + x) * 2;
//!         triangles[q] = [v, v + 1, v + 6];
//!         triangles[q + 1] = [v, v + 6, v + 5];
//!     }
//! }
//! // 64 vertices and 64 triangles of capacity, u16 links. `new` is const: on a device this
//! // can be a `static`.
//! let mut ws = Workspace::<u16, 64, 64>::new();
//! let config = Config::new().with_ratio(0.25).with_schedule(Schedule::Greedy);
//! // An error is a typed value and the buffer is untouched: firmware hands it on (`?`) or
//! // logs it; it never needs to panic.
//! let grid = triangles;
//! let report = ws.simplify(&positions, &mut triangles, &config)?;
//! let simplified = &triangles[..report.triangles_out];
//! assert!(report.triangles_out < 32);
//! assert_eq!(simplified.len(), report.triangles_out);
//!
//! // Any other choice goes through `start`, with the cost (and its placement), the error
//! // bound and the operator as values, each on the caller's storage and checked when the run
//! // starts: here stored quadrics under a guaranteed bound of 0.05, edge collapse (`run` to
//! // the end, or `step`).
//! use tinydecimate::{bound, Controls, EdgeCollapse, Placement, Positions, StoredQuadric};
//! let (original, mut triangles) = (grid, grid);
//! let mut quadrics = [[0.0f32; 10]; 25];
//! let mut links = [0u16; bound::control_len(32, 25)];
//! let report = ws
//!     .start(
//!         Positions::Read(&positions),
//!         &mut triangles,
//!         &Config::stored().with_ratio(0.25).with_max_error(0.05),
//!         StoredQuadric::new(&mut quadrics, Placement::Subset),
//!         Controls::new(&original, &mut links),
//!         EdgeCollapse,
//!     )?
//!     .run();
//! assert!(report.max_error.is_some_and(|e| e <= 0.05));
//! # Ok::<(), tinydecimate::Error>(())
//! ```
//!
//! ## Where the method comes from
//!
//! The engine follows the mobile-terminal method of Lin Mouguang ("A Geometry Compression Method for
//! Mobile Computing Terminal", 2007): edge collapse with subset placement (§2), so
//! the positions are only ever read and may stay in flash, and *feature vertices*, whose
//! triangles' normals differ most from each other (§3, eq. 3-5), are never removed while they
//! are features. The
//! default cost is a memoryless quadric (Lindstrom-Turk style; the plane quadrics of Cheng, Pan
//! and Shi 1998 §2.3 without per-vertex storage); the paper's own normal variation W (eq. 1-2,
//! Algorithm 1) and its passes are [`Config::paper`]. Legality follows Cheng, Pan and Shi 1998 ("A
//! fast algorithm for generating progressive meshes"): irregular vertices locked (§3.1), the
//! link condition and boundary edges only between boundary vertices (§3.2(1)), a dihedral
//! (normal-turn and fold) threshold (§3.2(2)); plus no sliver or duplicate triangles.
//!
//! A guaranteed error bound (Zhu, Wang and Meng 2007, §2-§4) is a policy of the same engine:
//! [`Config::with_max_error`] with [`bound::Controls`] given to [`Workspace::start`] checks control
//! points (original centroids and feature-edge vertices) before every collapse; see [`bound`]. The
//! paper's own operator, triangle collapse, is [`TriangleCollapse`] (see [`operator`]);
//! Schroeder's vertex decimation is [`VertexDecimation`].
//!
//! Data flows one way:
//!
//! ```text
//! positions (read-only) + caller's triangles
//!   -> mesh      validate, drop degenerate/duplicate triangles, build adjacency, lock non-manifold vertices
//!   -> feature   feature flags (eq. 3-5)
//!   -> cost      memoryless quadric, the paper's W (eq. 1-2), or any other `Cost`
//!   -> collapse  schedule (greedy heap or the paper's passes), legality, apply
//!   -> the compacted triangles in the caller's buffer, and a `Report`
//! ```
//!
//! Only positions and triangles are read. Normals, texture coordinates, colours and any other
//! per-vertex attribute stay in the caller's buffers, indexed like the positions: with subset
//! placement every vertex of the result is an input vertex, so they are exactly right for the
//! result as they are. [`remap`] packs them (and the positions) after a run, in place; optimal
//! placement moves vertices and does not interpolate attributes.
#![cfg_attr(not(test), no_std)]
#![forbid(unsafe_code)]
#![deny(missing_docs)]

pub mod choice;
pub mod cluster;
mod config;
mod engine;
mod error;
mod exact;
mod index;
mod math;
mod mesh;
#[cfg(feature = "seams")]
pub mod model;
pub mod operator;
#[cfg(feature = "fast")]
pub mod pipeline;
mod policy;
pub mod progressive;
mod quadric;
pub mod remap;
mod report;
#[cfg(feature = "seams")]
pub mod seam;
mod tri;
mod workspace;

pub use policy::{bound, cost, legality};
pub use progressive::stream;

pub use config::{Config, CostKind, FeatureMode, Schedule, Target};
pub use engine::Simplifier;
pub use error::{Capacity, ConfigField, Error};
pub use index::Index;
pub use report::{Rejections, Report, Stop, PASS_LOG};
pub use workspace::{Positions, Storage, Workspace};

// Shortcuts to the items of the public modules a run names most: each has one home (its
// module), where the documentation shows it.
#[doc(no_inline)]
pub use bound::{Controls, Envelope, NoBound};
#[doc(no_inline)]
pub use cost::{Builtin, Placement, StoredQuadric};
#[doc(no_inline)]
pub use legality::{Reject, RULES};
#[cfg(feature = "seams")]
#[doc(no_inline)]
pub use model::ModelStorage;
#[doc(no_inline)]
pub use operator::{EdgeCollapse, Fill, TriangleCollapse, VertexDecimation};
#[doc(no_inline)]
pub use progressive::Progressive;

/// The README's Rust examples, compiled and run as doctests.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
pub struct ReadmeDoctests;

/// docs/integer.md's example, compiled and run as a doctest.
#[cfg(all(doctest, feature = "fast"))]
#[doc = include_str!("../docs/integer.md")]
pub struct IntegerDoctests;

/// docs/envelope.md's example, compiled and run as a doctest.
#[cfg(doctest)]
#[doc = include_str!("../docs/envelope.md")]
pub struct EnvelopeDoctests;
