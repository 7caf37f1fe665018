//! `host-sim cluster`: the library's streaming vertex clustering (`tinydecimate::cluster`) on a
//! mesh file, optionally followed by the collapse engine (`--then-collapse`), with its figures
//! (counts, grid, table bytes, time, error); and `host-sim bench --cluster`: one row per mesh and ratio against
//! meshoptimizer's `simplifySloppy` (`meshopt::simplify_sloppy`).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::Mutex;
use std::time::{Duration, Instant};

use anyhow::{anyhow, bail, Context, Result};
use tinydecimate::cluster::{
    cluster_then_collapse, ClusterConfig, ClusterReport, Clusterer, GridChoice, Quadrics, Scratch,
    SliceSource, KEY_LANES,
};
use tinydecimate::{Config, Report};

use crate::io::MeshData;
use crate::metro::{metro, MetroOptions};

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

/// `host-sim cluster IN OUT (--target-triangles N | --cell SIZE) [--then-collapse N]`
#[derive(Clone, Debug, clap::Args)]
#[command(group = clap::ArgGroup::new("grid").required(true))]
pub struct Args {
    /// Input mesh (.obj, .ply, .stl).
    pub input: PathBuf,
    /// Output mesh (.obj or .ply); keeps the input's vertex numbering.
    pub output: PathBuf,
    /// Finest grid whose output has at most this many triangles.
    #[arg(long, group = "grid")]
    pub target_triangles: Option<usize>,
    /// Cells of this edge length (in the mesh's units).
    #[arg(long, group = "grid")]
    pub cell: Option<f32>,
    /// Then run the collapse engine (`Config::new()`) to this many triangles.
    #[arg(long)]
    pub then_collapse: Option<usize>,
    /// The nearest-to-centre representative (12 B per cell, one pass) instead of the quadric
    /// one (52 B per cell, two passes).
    #[arg(long)]
    pub nearest: bool,
    /// Remove zero-area and (quadric representative) flipped output triangles
    /// (`ClusterConfig::cleanup`).
    #[arg(long)]
    pub cleanup: bool,
    /// Memory per input vertex besides the table and the output (the same output; time
    /// only), given to `Clusterer::cluster` in its `Scratch`: none, a bit (`seen`), 8 bytes
    /// (`cache`) or 40 bytes (`cache` and `keys`).
    #[arg(long, value_enum, default_value_t = VertexMemory::None)]
    pub vertex_memory: VertexMemory,
    /// Skip the Metro measurement.
    #[arg(long)]
    pub no_measure: bool,
    /// Metro face samples per triangle of the larger mesh.
    #[arg(long, default_value_t = 10.0)]
    pub samples_per_triangle: f64,
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
fn then_collapse(
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
        &Config::new().with_target_triangles(target),
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

/// `host-sim cluster`.
pub fn run(args: &Args) -> Result<ExitCode> {
    let mesh = crate::io::load(&args.input)?;
    let grid = match (args.target_triangles, args.cell) {
        (Some(t), _) => GridChoice::TargetTriangles(t),
        (None, Some(c)) => GridChoice::CellSize(c),
        _ => bail!("give --target-triangles or --cell"),
    };
    let config = ClusterConfig {
        grid,
        cleanup: args.cleanup,
        ..ClusterConfig::target(0)
    };
    let quadric = !args.nearest;
    let (out, r, dt, collapse) = match args.then_collapse {
        None => {
            let (out, r, dt) = cluster(&mesh, &config, quadric, args.vertex_memory)?;
            (out, r, dt, None)
        }
        Some(n) => {
            let (out, r, c, dt) = then_collapse(&mesh, &config, quadric, n)?;
            (out, r, dt, Some(c))
        }
    };
    crate::outln!(
        "representative   {}",
        if quadric {
            "quadric (least cell-quadric error)"
        } else {
            "nearest to the cell centre"
        }
    );
    crate::outln!("triangles in     {}", r.triangles_in);
    crate::outln!("clustered        {}", r.triangles_out);
    if let Some(c) = &collapse {
        crate::outln!("then collapsed   {}", c.triangles_out);
    }
    crate::outln!(
        "dropped          {} collapsed into < 3 cells, {} duplicates ({} opposite winding)",
        r.collapsed,
        r.duplicates,
        r.opposite_duplicates
    );
    crate::outln!(
        "grid             {} x {} x {} cells of {} (origin {:?})",
        r.grid.dims[0],
        r.grid.dims[1],
        r.grid.dims[2],
        r.grid.cell,
        r.grid.origin
    );
    crate::outln!("passes           {}", r.passes);
    if args.cleanup {
        crate::outln!(
            "cleanup          {} zero-area, {} flipped triangles removed",
            r.slivers_removed,
            r.flipped_removed
        );
    }
    crate::outln!(
        "table            {} occupied cells x {} B = {} B (+ output {} triangles x 12 B with u32, 6 B with u16)",
        r.cells,
        table_bytes(1, quadric),
        table_bytes(r.cells, quadric),
        r.triangles_out
    );
    crate::outln!("time             {:.3} ms", dt.as_secs_f64() * 1e3);
    let (dup, deg, nme, comp) = defects(&out);
    crate::outln!("duplicates       {dup}");
    crate::outln!("degenerate       {deg}");
    crate::outln!("non-manifold     {nme} edges");
    crate::outln!("components       {comp}");
    if !args.no_measure {
        let m = metro(
            &mesh,
            &out,
            &MetroOptions {
                samples_per_triangle: args.samples_per_triangle,
                ..MetroOptions::default()
            },
        );
        crate::outln!(
            "Metro            mean {:.4} % of the diagonal, Hausdorff {:.4} %",
            m.symmetric_mean_pct,
            m.hausdorff_pct
        );
    }
    crate::io::save(&args.output, &out)?;
    Ok(ExitCode::SUCCESS)
}

/// `meshopt::simplify_sloppy` on `mesh` to `target` triangles (target error 1.0: no limit).
pub fn sloppy(mesh: &MeshData, target: usize) -> (MeshData, Duration) {
    let indices: Vec<u32> = mesh.triangles.iter().flatten().copied().collect();
    let bytes = meshopt::utilities::typed_to_bytes(&mesh.positions);
    let adapter = meshopt::VertexDataAdapter::new(bytes, std::mem::size_of::<[f32; 3]>(), 0)
        .expect("12-byte vertices");
    let start = Instant::now();
    let out = meshopt::simplify_sloppy(&indices, &adapter, 3 * target, 1.0, None);
    let dt = start.elapsed();
    (
        MeshData {
            positions: mesh.positions.clone(),
            triangles: out.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect(),
        },
        dt,
    )
}

/// One row of `bench --cluster`.
#[derive(Clone, Debug)]
pub struct Row {
    /// Mesh file name.
    pub mesh: String,
    /// Input triangles.
    pub triangles: usize,
    /// Target ratio.
    pub ratio: f32,
    /// Ours (quadric representative, 8 B cache per vertex): count, median ms, Metro mean %,
    /// duplicates, degenerate.
    pub ours: (usize, f64, f64, usize, usize),
    /// Ours with 40 B per vertex (cache and keys): median ms.
    pub ours_keys_ms: f64,
    /// Ours with a bit per vertex: median ms.
    pub ours_bit_ms: f64,
    /// Ours with memory for the output only: median ms.
    pub ours_stream_ms: f64,
    /// Sloppy at the same target: count, median ms, duplicates, degenerate.
    pub sloppy: (usize, f64, usize, usize),
    /// Sloppy run to our count: count, Metro mean %.
    pub sloppy_same: (usize, f64),
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// `host-sim bench --cluster`: every mesh of the directory (smallest first) at each ratio.
pub fn bench(
    meshes: &Path,
    only: Option<&[String]>,
    ratios: &[f32],
    reps: usize,
) -> Result<Vec<Row>> {
    let mut names: Vec<String> = match only {
        Some(n) => n.to_vec(),
        None => std::fs::read_dir(meshes)
            .with_context(|| format!("{}: cannot list", meshes.display()))?
            .filter_map(|e| e.ok())
            .map(|e| e.file_name().to_string_lossy().into_owned())
            .filter(|n| n.ends_with(".obj") || n.ends_with(".ply") || n.ends_with(".stl"))
            .collect(),
    };
    names.sort();
    let mut loaded = Vec::new();
    for n in names {
        let m = crate::io::load(meshes.join(&n))?;
        loaded.push((n, m));
    }
    loaded.sort_by_key(|(n, m)| (m.triangles.len(), n.clone()));
    let opts = MetroOptions::default();
    let mut rows = Vec::new();
    for (name, mesh) in &loaded {
        for &ratio in ratios {
            let target = ((mesh.triangles.len() as f64) * f64::from(ratio)) as usize;
            let config = ClusterConfig::target(target);
            let mut ours_t = Vec::new();
            let mut stream_t = Vec::new();
            let mut bit_t = Vec::new();
            let mut keys_t = Vec::new();
            let mut sl_t = Vec::new();
            let mut ours = None;
            let mut sl = None;
            for _ in 0..reps.max(1) {
                let (o, r, dt) = cluster(mesh, &config, true, VertexMemory::Cache)?;
                ours_t.push(dt.as_secs_f64() * 1e3);
                let (o2, r2, dt) = cluster(mesh, &config, true, VertexMemory::Keys)?;
                keys_t.push(dt.as_secs_f64() * 1e3);
                anyhow::ensure!(
                    o2.triangles == o.triangles && r2 == r,
                    "{name}: keys differ"
                );
                let (o2, r2, dt) = cluster(mesh, &config, true, VertexMemory::Bit)?;
                bit_t.push(dt.as_secs_f64() * 1e3);
                anyhow::ensure!(
                    o2.triangles == o.triangles && r2 == r,
                    "{name}: bits differ"
                );
                let (o2, r2, dt) = cluster(mesh, &config, true, VertexMemory::None)?;
                stream_t.push(dt.as_secs_f64() * 1e3);
                anyhow::ensure!(
                    o2.triangles == o.triangles && r2 == r,
                    "{name}: cache differs"
                );
                ours = Some((o, r));
                let (s, dt) = sloppy(mesh, target);
                sl_t.push(dt.as_secs_f64() * 1e3);
                sl = Some(s);
            }
            let (o, r) = ours.expect("one repetition");
            let s = sl.expect("one repetition");
            let (same, _) = sloppy(mesh, r.triangles_out);
            let om = metro(mesh, &o, &opts);
            let sm = metro(mesh, &same, &opts);
            let (od, odg, _, _) = defects(&o);
            let (sd, sdg, _, _) = defects(&s);
            let row = Row {
                mesh: name.clone(),
                triangles: mesh.triangles.len(),
                ratio,
                ours: (
                    o.triangles.len(),
                    median(ours_t),
                    om.symmetric_mean_pct,
                    od,
                    odg,
                ),
                ours_keys_ms: median(keys_t),
                ours_bit_ms: median(bit_t),
                ours_stream_ms: median(stream_t),
                sloppy: (s.triangles.len(), median(sl_t), sd, sdg),
                sloppy_same: (same.triangles.len(), sm.symmetric_mean_pct),
            };
            eprintln!("{}", markdown_row(&row));
            rows.push(row);
        }
    }
    Ok(rows)
}

fn markdown_row(r: &Row) -> String {
    format!(
        "| {} | {} | {} | {} | {:.3} | {} | {:.3} | {:.2}x | {:.3} | {:.2}x | {:.3} | {:.2}x | {:.3} | {:.2}x | {} / {} | {} / {} | {:.4} | {} | {:.4} | {:.2}x |",
        r.mesh,
        r.triangles,
        r.ratio,
        r.ours.0,
        r.ours_keys_ms,
        r.sloppy.0,
        r.sloppy.1,
        r.ours_keys_ms / r.sloppy.1,
        r.ours.1,
        r.ours.1 / r.sloppy.1,
        r.ours_bit_ms,
        r.ours_bit_ms / r.sloppy.1,
        r.ours_stream_ms,
        r.ours_stream_ms / r.sloppy.1,
        r.ours.3,
        r.ours.4,
        r.sloppy.2,
        r.sloppy.3,
        r.ours.2,
        r.sloppy_same.0,
        r.sloppy_same.1,
        r.ours.2 / r.sloppy_same.1,
    )
}

/// The rows as a Markdown table, with the worst ratios.
pub fn markdown(rows: &[Row], command: &str) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "Command: `{command}`\n");
    let _ = writeln!(
        s,
        "| mesh | triangles | ratio | ours | ours ms, 40 B/vertex | sloppy | sloppy ms | time ours/sloppy | ours ms, 8 B/vertex | its time / sloppy | ours ms, 1 bit/vertex | its time / sloppy | ours ms, output memory only | its time / sloppy | ours dup / degen | sloppy dup / degen | ours mean % | sloppy at our count | its mean % | error ours/sloppy |"
    );
    let _ = writeln!(
        s,
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
    );
    for r in rows {
        let _ = writeln!(s, "{}", markdown_row(r));
    }
    let geo = |f: &dyn Fn(&Row) -> f64| {
        (rows.iter().map(|r| f(r).ln()).sum::<f64>() / rows.len().max(1) as f64).exp()
    };
    let worst = |f: &dyn Fn(&Row) -> f64| rows.iter().map(f).fold(0.0, f64::max);
    // A time of ours over sloppy's, all rows together.
    let total = |f: &dyn Fn(&Row) -> f64| {
        rows.iter().map(f).sum::<f64>() / rows.iter().map(|r| r.sloppy.1).sum::<f64>()
    };
    let worst_t = worst(&|r| r.ours.1 / r.sloppy.1);
    let worst_e = worst(&|r| r.ours.2 / r.sloppy_same.1);
    let tot_t = total(&|r| r.ours.1);
    let geo_t = geo(&|r| r.ours.1 / r.sloppy.1);
    let geo_k = geo(&|r| r.ours_keys_ms / r.sloppy.1);
    let worst_k = worst(&|r| r.ours_keys_ms / r.sloppy.1);
    let tot_k = total(&|r| r.ours_keys_ms);
    let geo_s = geo(&|r| r.ours_stream_ms / r.sloppy.1);
    let geo_b = geo(&|r| r.ours_bit_ms / r.sloppy.1);
    let worst_b = worst(&|r| r.ours_bit_ms / r.sloppy.1);
    let worst_s = worst(&|r| r.ours_stream_ms / r.sloppy.1);
    let tot_s = total(&|r| r.ours_stream_ms);
    let dups: usize = rows.iter().map(|r| r.ours.3 + r.ours.4).sum();
    let sdups: usize = rows.iter().map(|r| r.sloppy.2 + r.sloppy.3).sum();
    let _ = writeln!(
        s,
        "\nTime ours/sloppy (40 B per input vertex, `Scratch` `cache` + `keys`): worst row {worst_k:.2}x, all rows together {tot_k:.2}x, geometric mean {geo_k:.2}x. With 8 B per vertex (`Scratch` `cache`): worst row {worst_t:.2}x, all rows together {tot_t:.2}x, geometric mean {geo_t:.2}x. With a bit per vertex (`Scratch` `seen`): worst row {worst_b:.2}x, geometric mean {geo_b:.2}x. With memory for the output only (`Scratch::new()`, same output): worst row {worst_s:.2}x, all rows together {tot_s:.2}x, geometric mean {geo_s:.2}x. Mean error ours/sloppy at our count: worst row {worst_e:.2}x. Duplicate + degenerate triangles: ours {dups}, sloppy {sdups}."
    );
    s
}

/// `host-sim bench --cluster ...`.
pub fn bench_run(opts: &crate::bench::Options, out: Option<&Path>) -> Result<ExitCode> {
    let rows = bench(&opts.meshes, opts.only.as_deref(), &opts.ratios, opts.reps)?;
    let mut args: Vec<String> = std::env::args().collect();
    if let Some(a) = args.first_mut() {
        *a = "host-sim".into();
    }
    let md = markdown(&rows, &args.join(" "));
    crate::out!("{md}");
    if let Some(p) = out {
        std::fs::write(p, &md).with_context(|| format!("{}: cannot write", p.display()))?;
        eprintln!("wrote {}", p.display());
    }
    Ok(ExitCode::SUCCESS)
}
