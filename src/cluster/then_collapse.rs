//! Clustering down to a size the collapse engine can hold, then collapsing to the target.

use super::{ClusterConfig, ClusterError, ClusterReport, Clusterer, GridChoice, Scratch, Source};
use crate::index::Index;

/// Why [`cluster_then_collapse`] failed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ThenCollapseError {
    /// The clustering step failed.
    Cluster(ClusterError),
    /// The collapse step failed.
    Collapse(crate::Error),
}

impl core::fmt::Display for ThenCollapseError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            ThenCollapseError::Cluster(e) => write!(f, "clustering: {e}"),
            ThenCollapseError::Collapse(e) => write!(f, "collapse: {e}"),
        }
    }
}

/// Cluster, then collapse: clusters `source` down to what fits `storage` (at most its
/// triangle capacity, `out.len()` and twice `scratch.vertices.len()` and
/// `scratch.positions.len()` triangles; the grid is searched as for
/// [`GridChoice::TargetTriangles`] unless `cluster_config` fixes it), copies the surviving
/// vertices' positions into `scratch.positions` (RAM: 12 bytes per vertex), then runs the
/// collapse engine with `config` (give it an absolute target,
/// [`Target::Triangles`](crate::Target::Triangles)). On success the
/// first `collapse.triangles_out` entries of `out` hold the result **in input vertex
/// numbers**. A small device thus gets collapse quality from a mesh it could never hold.
pub fn cluster_then_collapse<S: Source, I: Index, L: Index, const CELLS: usize>(
    table: &mut Clusterer<CELLS>,
    source: &mut S,
    cluster_config: &ClusterConfig,
    config: &crate::Config,
    out: &mut [[I; 3]],
    mut storage: crate::Storage<'_, L>,
    scratch: Scratch<'_, CELLS>,
) -> Result<(ClusterReport, crate::Report), ThenCollapseError> {
    let Scratch {
        quadrics,
        vertices,
        positions,
        ..
    } = scratch;
    let mut cc = *cluster_config;
    let (cap_v, cap_t) = storage.capacity();
    if let GridChoice::TargetTriangles(t) = cc.grid {
        let fit = cap_t
            .min(out.len())
            .min(vertices.len().saturating_mul(2))
            .min(positions.len().saturating_mul(2))
            .min(cap_v.saturating_mul(2));
        cc.grid = GridChoice::TargetTriangles(t.min(fit));
    }
    let nv_cap = vertices.len().min(positions.len());
    let vbuf = vertices.get_mut(..nv_cap).unwrap_or(&mut []);
    let (cr, nv) = table
        .cluster_compact(source, quadrics, &cc, out, vbuf)
        .map_err(ThenCollapseError::Cluster)?;
    let (Some(vs), Some(ps), Some(tris)) = (
        vertices.get(..nv),
        positions.get_mut(..nv),
        out.get_mut(..cr.triangles_out),
    ) else {
        return Err(ThenCollapseError::Cluster(ClusterError::VerticesFull {
            capacity: nv_cap,
        }));
    };
    for (p, &v) in ps.iter_mut().zip(vs) {
        *p = source
            .position(v as usize)
            .ok_or(ThenCollapseError::Cluster(ClusterError::IndexOutOfRange {
                triangle: 0,
                index: v as usize,
            }))?;
    }
    let report = storage
        .simplify(ps, tris, config)
        .map_err(ThenCollapseError::Collapse)?;
    let done = tris.get_mut(..report.triangles_out).unwrap_or(&mut []);
    for t in done.iter_mut() {
        for i in t.iter_mut() {
            let v = vs.get(i.to_usize()).copied().unwrap_or(u32::MAX);
            *i = I::from_usize(v as usize).ok_or(ThenCollapseError::Cluster(
                ClusterError::VertexTooWide { vertex: v as usize },
            ))?;
        }
    }
    Ok((cr, report))
}
