//! `tinydecimate cluster`: the library's streaming vertex clustering (`tinydecimate::cluster`) on a
//! mesh file, optionally followed by the collapse engine (`--then-collapse`), with its figures
//! (counts, grid, table bytes, time, error); and `host-sim bench --cluster`: one row per mesh and ratio against
//! meshoptimizer's `simplifySloppy` (`meshopt::simplify_sloppy`).

use std::sync::Mutex;
use std::time::{Duration, Instant};

use anyhow::{anyhow, Result};
use tinydecimate::cluster::{
    cluster_then_collapse, ClusterConfig, ClusterReport, Clusterer, GridChoice, Quadrics, Scratch,
    SliceSource, KEY_LANES,
};
use tinydecimate::{Config, Report, Target};

use crate::io::MeshData;

/// Cells of the harness's table (2^20: any grid of the shared meshes fits).
pub const CELLS: usize = 1 << 20;
static TABLE: Mutex<Clusterer<CELLS>> = Mutex::new(Clusterer::new());
static QUADS: Mutex<Quadrics<CELLS>> = Mutex::new(Quadrics::new());

/// Lends the harness's one cell table and quadric table to `f` (one caller at a time). A call
/// uses the first `ClusterConfig::table_cells` cells (all of them when 0), and gives the same
/// bytes as a table of that size: the golden clustering cases run here as on a board.
pub fn with_tables<R>(f: impl FnOnce(&mut Clusterer<CELLS>, &mut Quadrics<CELLS>) -> R) -> R {
    let mut table = TABLE.lock().unwrap_or_else(|p| p.into_inner());
    let mut quads = QUADS.lock().unwrap_or_else(|p| p.into_inner());
    f(&mut table, &mut quads)
}

/// Memory per input vertex given to the library besides the table and the output.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum VertexMemory {
    /// None: memory for the output only (`Scratch::new()`).
    None,
    /// A bit per vertex (`Scratch::seen`).
    Bit,
    /// 8 bytes per vertex (`Scratch::cache`).
    Cache,
    /// 8 + 32 bytes per vertex (`Scratch::cache` and `Scratch::keys`).
    Keys,
}

/// Clusters `mesh` with the library: output, report, wall time of the call. The per-vertex
/// memory (`mem`) is allocated before the clock starts, like the output buffer.
pub fn cluster(
    mesh: &MeshData,
    config: &ClusterConfig,
    quadric: bool,
    mem: VertexMemory,
) -> Result<(MeshData, ClusterReport, Duration)> {
    let mut table = TABLE.lock().unwrap_or_else(|p| p.into_inner());
    let mut quads = QUADS.lock().unwrap_or_else(|p| p.into_inner());
    let mut out = vec![[0u32; 3]; mesh.triangles.len().max(1)];
    let n = mesh.positions.len();
    let mut bits = vec![
        0u32;
        if mem == VertexMemory::Bit {
            n / 32 + 1
        } else {
            0
        }
    ];
    let with_cache = matches!(mem, VertexMemory::Cache | VertexMemory::Keys);
    let mut cache = vec![0u64; if with_cache { n } else { 0 }];
    let mut keys = vec![[0u32; KEY_LANES]; if mem == VertexMemory::Keys { n } else { 0 }];
    let mut src = SliceSource::new(&mesh.positions, &mesh.triangles);
    let start = Instant::now();
    let q = if quadric { Some(&mut *quads) } else { None };
    // Each buffer is empty unless `mem` asks for it, and an empty buffer is the path without
    // it, so one call serves every choice.
    let r = table
        .cluster(
            &mut src,
            config,
            &mut out,
            Scratch {
                quadrics: q,
                seen: &mut bits,
                cache: &mut cache,
                keys: &mut keys,
                ..Scratch::new()
            },
        )
        .map_err(|e| anyhow!("tinydecimate::cluster: {e}"))?;
    let dt = start.elapsed();
    out.truncate(r.triangles_out);
    Ok((
        MeshData {
            positions: mesh.positions.clone(),
            triangles: out,
        },
        r,
        dt,
    ))
}

/// `cluster_then_collapse` with the harness's buffers.
pub fn then_collapse(
    mesh: &MeshData,
    config: &ClusterConfig,
    quadric: bool,
    target: usize,
) -> Result<(MeshData, ClusterReport, Report, Duration)> {
    let mut table = TABLE.lock().unwrap_or_else(|p| p.into_inner());
    let mut quads = QUADS.lock().unwrap_or_else(|p| p.into_inner());
    let n = mesh.triangles.len().max(1);
    let mut ws = crate::workspace::HostWorkspace::new(n, n);
    let mut out = vec![[0u32; 3]; n];
    let mut vertices = vec![0u32; n];
    let mut positions = vec![[0.0f32; 3]; n];
    let mut src = SliceSource::new(&mesh.positions, &mesh.triangles);
    let start = Instant::now();
    let q = if quadric { Some(&mut *quads) } else { None };
    let scratch = Scratch {
        quadrics: q,
        vertices: &mut vertices,
        positions: &mut positions,
        ..Scratch::new()
    };
    let (cr, r) = cluster_then_collapse(
        &mut table,
        &mut src,
        config,
        &Config::new().with_target(Target::Triangles(target)),
        &mut out,
        ws.storage(),
        scratch,
    )
    .map_err(|e| anyhow!("tinydecimate::cluster_then_collapse: {e}"))?;
    let dt = start.elapsed();
    out.truncate(r.triangles_out);
    Ok((
        MeshData {
            positions: mesh.positions.clone(),
            triangles: out,
        },
        cr,
        r,
        dt,
    ))
}

/// One clustering of [`then_collapse_to`]: its target, the triangles it gave, and the
/// collapses' result from there.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Attempt {
    /// The clustering's target (`None`: the grid given as a cell size).
    pub cluster_target: Option<usize>,
    /// Triangles after clustering.
    pub clustered: usize,
    /// Triangles after the collapses.
    pub collapsed: usize,
    /// Why the collapses stopped.
    pub stop: tinydecimate::Stop,
}

/// [`then_collapse`] that reaches `target`: when the collapses stop short, it clusters again,
/// to halfway between the last clustering's count and `target`, and collapses again, until
/// the count is reached. Each clustering gives fewer triangles than the one before (at most
/// its target), and a clustering to `target` itself needs no collapse, so it ends, at most
/// `target` triangles (unless a clustering fails to give fewer triangles than the one before,
/// which ends it short). Returns the last attempt's output and reports, the total time and
/// every attempt, first to last.
#[allow(clippy::type_complexity)]
pub fn then_collapse_to(
    mesh: &MeshData,
    config: &ClusterConfig,
    quadric: bool,
    target: usize,
) -> Result<(MeshData, ClusterReport, Report, Duration, Vec<Attempt>)> {
    let mut cc = *config;
    let mut attempts = Vec::new();
    let mut total = Duration::ZERO;
    loop {
        let (out, cr, r, dt) = then_collapse(mesh, &cc, quadric, target)?;
        total += dt;
        attempts.push(Attempt {
            cluster_target: match cc.grid {
                GridChoice::TargetTriangles(t) => Some(t),
                GridChoice::CellSize(_) | GridChoice::Resolution(_) => None,
            },
            clustered: cr.triangles_out,
            collapsed: r.triangles_out,
            stop: r.stop,
        });
        // Also ends when a clustering gave no fewer triangles than the one before (a grid
        // search that cannot meet its target): the caller reports the shortfall.
        let stalled = attempts
            .iter()
            .rev()
            .nth(1)
            .is_some_and(|a| a.clustered <= cr.triangles_out);
        if r.triangles_out <= target || cr.triangles_out <= target || stalled {
            return Ok((out, cr, r, total, attempts));
        }
        let next = target + (cr.triangles_out - target) / 2;
        cc.grid = GridChoice::TargetTriangles(next);
    }
}

/// Bytes a right-sized table needs for `cells` occupied cells (no slack), and per output
/// triangle with `u32` indices.
pub fn table_bytes(cells: usize, quadric: bool) -> usize {
    cells
        * (Clusterer::<1>::BYTES_PER_CELL
            + if quadric {
                Quadrics::<1>::BYTES_PER_CELL
            } else {
                0
            })
}

/// Duplicates (same vertex set as an earlier triangle, any winding) and degenerate (repeated
/// index) triangles, non-manifold edges and components of a result.
pub fn defects(mesh: &MeshData) -> (usize, usize, usize, usize) {
    let a = meshcheck::analyse(&mesh.positions, &mesh.triangles);
    (
        a.topology.duplicate_triangles,
        a.topology.degenerate_triangles,
        a.topology.non_manifold_edges,
        a.topology.components,
    )
}
