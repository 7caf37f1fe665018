//! `tinydecimate cluster IN OUT`: the library's streaming vertex clustering on a mesh file
//! ([`crate::cluster`]), optionally followed by the collapse engine (`--then-collapse`), with
//! its figures: counts, grid, table bytes, time, error.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{bail, Result};
use tinydecimate::cluster::{ClusterConfig, GridChoice};

use crate::cluster::{cluster, defects, table_bytes, then_collapse_to, VertexMemory};
use crate::metro::{metro, MetroOptions};

/// `tinydecimate cluster IN OUT (--target-triangles N | --cell SIZE) [--then-collapse N]`
#[derive(Clone, Debug, clap::Args)]
#[command(group = clap::ArgGroup::new("grid").required(true))]
pub struct Args {
    /// Input mesh (.obj, .ply, .stl, .gltf, .glb).
    pub input: PathBuf,
    /// Output mesh (.obj or .ply); keeps the input's vertex numbering.
    pub output: PathBuf,
    /// Finest grid whose output has at most this many triangles.
    #[arg(long, group = "grid")]
    pub target_triangles: Option<usize>,
    /// Cells of this edge length (in the mesh's units).
    #[arg(long, group = "grid")]
    pub cell: Option<f32>,
    /// Then run the collapse engine (`Config::new()`) to this many triangles. It reaches
    /// them: when the collapses stop short, it clusters again, to halfway between the last
    /// clustering's count and this one, and collapses again (each attempt is printed); a
    /// clustering to this count itself needs no collapse.
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

/// `tinydecimate cluster`.
pub fn run(args: &Args) -> Result<ExitCode> {
    let mesh = crate::io::load_noting(&args.input)?;
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
            let (out, r, c, dt, attempts) = then_collapse_to(&mesh, &config, quadric, n)?;
            (out, r, dt, Some((c, attempts)))
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
    if let Some((c, attempts)) = &collapse {
        // Every attempt but the last stopped short; the last is the one written.
        for a in &attempts[..attempts.len() - 1] {
            crate::outln!(
                "short            clustered to {} (target {}), collapses stopped at {} ({:?}): \
                 clustering again",
                a.clustered,
                a.cluster_target
                    .map_or_else(|| "the cell size".to_string(), |t| t.to_string()),
                a.collapsed,
                a.stop
            );
        }
        crate::outln!(
            "then collapsed   {}{}",
            c.triangles_out,
            if c.target_reached {
                String::new()
            } else {
                format!(" (short of {}: {:?})", c.target_triangles, c.stop)
            }
        );
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
