//! A model as a tool or a renderer writes it, in one call: what `tinydecimate simplify --engine
//! exact` does by default, for firmware.
//!
//! [`Storage::simplify`] takes the index buffer as given. A model whose vertices are split on
//! a UV seam, a hard normal or a material border has two vertices at each seam position; to
//! the engine each side is an open boundary that shrinks on its own, so the result cracks
//! open along every seam, and each small part of a multi-part model holds on to its triangles.
//! [`Storage::simplify_model`] is the run that avoids both:
//!
//! 1. [`seam::weld`](crate::seam::weld) renumbers the corners to one vertex per position, its
//!    sort done in the workspace's queue links (free until the run builds its queue);
//! 2. the edge collapse runs on the welded surface with the built-in cost, each triangle
//!    keeping its own wedge ([`Simplifier::with_wedges`](crate::Simplifier::with_wedges)), so
//!    the output names the caller's vertices again and a seam moves as one;
//! 3. with crate feature `parts` and [`ModelStorage::with_parts`], a part cheaper than the next
//!    collapse vanishes whole ([`Simplifier::with_parts`](crate::Simplifier::with_parts)).
//!
//! The error limit is the configuration's, as everywhere: the CLI's default is
//! [`Config::MODEL_ERROR_LIMIT`] of the diagonal, set with
//! [`Config::with_relative_error_limit`]. With that configuration the call gives the bytes
//! `tinydecimate simplify --engine exact` writes with its other defaults (`--seams weld
//! --parts prune`).
//!
//! ```
//! # #[cfg(all(feature = "seams", feature = "parts"))]
//! # fn main() {
//! use tinydecimate::{Config, ModelStorage, Workspace};
//!
//! // A tetrahedron whose apex is split in two (a UV seam): vertices 3 and 4 share a position.
//! static POSITIONS: [[f32; 3]; 5] = [
//!     [0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, 1.0],
//! ];
//! let mut triangles = [[0u16, 2, 1], [0, 1, 3], [1, 2, 4], [0, 3, 2]];
//!
//! type Ws = Workspace<u16, 512, 1024>;
//! let mut ws = Box::new(Ws::new()); // a `static` on a device, as above
//! let mut wedges = [[0u16; 3]; 1024]; // one per triangle
//! let mut parts = [[0u16; 2]; 512]; // one pair per vertex
//! let mut model = ModelStorage::new(&mut wedges).with_parts(&mut parts);
//! let config = Config::new()
//!     .with_ratio(0.25)
//!     .with_relative_error_limit(Config::MODEL_ERROR_LIMIT, &POSITIONS);
//! let report = ws.simplify_model(&POSITIONS, &mut triangles, &mut model, &config).unwrap();
//! // Welded, it is a closed tetrahedron, and it stays; each corner keeps its own vertex.
//! assert_eq!(report.triangles_out, 4);
//! assert!(triangles.contains(&[1, 2, 4]));
//! # }
//! # #[cfg(not(all(feature = "seams", feature = "parts")))]
//! # fn main() {}
//! ```
//!
//! Extra memory beyond the [`Workspace`]: the wedges, one triangle per
//! triangle (6 B with `u16` indices), and with pruning one pair of links per vertex (4 B with
//! `u16` links).

use crate::index::Index;
use crate::operator::EdgeCollapse;
use crate::policy::bound::NoBound;
use crate::policy::cost::Builtin;
use crate::seam::SeamCorners;
use crate::workspace::{Positions, Storage, Workspace};
use crate::{Config, Error, Report};

/// The caller's storage for [`Storage::simplify_model`] beyond the workspace: the wedge
/// buffer (at least one entry per triangle) and, for part pruning, one pair of links per
/// vertex. Contents on entry do not matter.
pub struct ModelStorage<'m, I: Index, L: Index> {
    wedges: &'m mut [[I; 3]],
    #[cfg(feature = "parts")]
    parts: Option<&'m mut [[L; 2]]>,
    corners: SeamCorners,
    links: core::marker::PhantomData<L>,
}

impl<'m, I: Index, L: Index> ModelStorage<'m, I, L> {
    /// Storage with `wedges` (one entry per triangle), no part pruning, and seam corners that
    /// move ([`SeamCorners::Move`], the CLI's choice for positions alone).
    pub fn new(wedges: &'m mut [[I; 3]]) -> Self {
        ModelStorage {
            wedges,
            #[cfg(feature = "parts")]
            parts: None,
            corners: SeamCorners::Move,
            links: core::marker::PhantomData,
        }
    }

    /// Prunes parts with `links` (one pair per vertex): a part cheaper than the next collapse
    /// vanishes whole. Only with the greedy or batched schedule; any other runs without.
    #[cfg(feature = "parts")]
    pub fn with_parts(mut self, links: &'m mut [[L; 2]]) -> Self {
        self.parts = Some(links);
        self
    }

    /// What a vertex where more than two wedges meet may do: [`SeamCorners::Lock`] when the
    /// caller's vertices carry attributes (UVs, normals) that must not tear, as the CLI does
    /// for glTF; [`SeamCorners::Move`] for positions alone.
    pub fn with_corners(mut self, corners: SeamCorners) -> Self {
        self.corners = corners;
        self
    }
}

impl<L: Index, const MAX_VERTICES: usize, const MAX_TRIANGLES: usize>
    Workspace<L, MAX_VERTICES, MAX_TRIANGLES>
{
    /// [`Storage::simplify_model`] on this workspace: a model's seams welded, its small parts
    /// pruned, as `tinydecimate simplify --engine exact` does by default (crate feature `seams`).
    pub fn simplify_model<I: Index>(
        &mut self,
        positions: &[[f32; 3]],
        triangles: &mut [[I; 3]],
        model: &mut ModelStorage<'_, I, L>,
        config: &Config,
    ) -> Result<Report, Error> {
        self.as_storage()
            .simplify_model(positions, triangles, model, config)
    }
}

impl<L: Index> Storage<'_, L> {
    /// Simplifies a model's `triangles` in place as `tinydecimate simplify --engine exact` does
    /// by default: vertices at one position welded and collapsed together (no crack along a
    /// seam), each corner keeping the caller's vertex (its wedge), and with
    /// [`ModelStorage::with_parts`] small parts removed whole (see [`crate::model`]).
    ///
    /// On success the first `report.triangles_out` entries of `triangles` hold the result in
    /// the caller's vertex numbering. On error `triangles` holds what it held on entry.
    /// Errors as [`Storage::start`], and [`Error::Capacity`] (triangles) if the wedge buffer
    /// is shorter than `triangles` or (vertices) if the part links are shorter than
    /// `positions`.
    pub fn simplify_model<I: Index>(
        &mut self,
        positions: &[[f32; 3]],
        triangles: &mut [[I; 3]],
        model: &mut ModelStorage<'_, I, L>,
        config: &Config,
    ) -> Result<Report, Error> {
        // The queue links are not read before the build writes them: the weld sorts in them.
        let welded = crate::seam::weld(positions, triangles, model.wedges, self.queue_links())?;
        let report = self.run_model(positions, triangles, model, config, welded > 0);
        if report.is_err() {
            // The weld kept the triangles as given in the wedges: put them back.
            for (t, w) in triangles.iter_mut().zip(model.wedges.iter()) {
                *t = *w;
            }
        }
        report
    }

    fn run_model<I: Index>(
        &mut self,
        positions: &[[f32; 3]],
        triangles: &mut [[I; 3]],
        model: &mut ModelStorage<'_, I, L>,
        config: &Config,
        welded: bool,
    ) -> Result<Report, Error> {
        let mut s = self.reborrow().start(
            Positions::Read(positions),
            triangles,
            config,
            Builtin::new(),
            NoBound,
            EdgeCollapse,
        )?;
        if welded {
            s = s.with_wedges(&mut *model.wedges, model.corners)?;
        }
        #[cfg(feature = "parts")]
        if let Some(links) = model.parts.as_deref_mut() {
            if config.schedule.is_ordered() {
                s = s.with_parts(links)?;
            }
        }
        while !s.step(u32::MAX) {}
        Ok(s.finish())
    }
}
