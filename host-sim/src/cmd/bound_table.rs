//! `host-sim bound-table`: the error-bound figures of docs/error-bound.md ("Figures"). For each
//! mesh: the triangles tinydecimate reaches under a guaranteed bound (a fraction of the
//! bounding-box diagonal; control points of Zhu, Wang and Meng 2007), with the edge
//! and the triangle operator, their E_max / E_mean (eq. 4-5) and the Metro one-sided maximum
//! from the original to the result; the same bound as simplification envelopes (Cohen et al.,
//! `bound::Envelope`): its count, its symmetric Hausdorff distance (Metro, both directions,
//! guaranteed below the bound) and its count over the control points'; next to meshoptimizer at
//! the same `target_error` (its count, and its Metro maximum: measured, not guaranteed). Prints
//! a Markdown table.

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

use anyhow::Result;
use tinydecimate::Config;

use crate::simplify::OperatorArg;

use crate::io::MeshData;
use crate::metro::{metro, MetroOptions};

/// `host-sim bound-table [MESH...]`
#[derive(Clone, Debug, clap::Args)]
pub struct Args {
    /// Meshes (default: every .obj in tests/fixtures, smallest first).
    pub meshes: Vec<PathBuf>,
    /// The bound and meshoptimizer's target_error, as a fraction (0.005 = 0.5 %; ours of the
    /// bounding-box diagonal, meshoptimizer's of its own scale, the largest bbox side).
    #[arg(long, default_value_t = 0.005)]
    pub fraction: f32,
    /// Metro face samples per triangle.
    #[arg(long, default_value_t = 4.0)]
    pub samples_per_triangle: f64,
    /// Also run the triangle operator (`--operator triangle`).
    #[arg(long)]
    pub triangle: bool,
}

fn default_meshes() -> Vec<PathBuf> {
    let dir = crate::bench::default_meshes();
    let mut v: Vec<(u64, PathBuf)> = std::fs::read_dir(&dir)
        .map(|d| {
            d.filter_map(|e| e.ok())
                .map(|e| e.path())
                .filter(|p| p.extension().is_some_and(|x| x == "obj"))
                .map(|p| (std::fs::metadata(&p).map(|m| m.len()).unwrap_or(0), p))
                .collect()
        })
        .unwrap_or_default();
    v.sort();
    v.into_iter().map(|x| x.1).collect()
}

/// meshoptimizer down to `target_error` (no triangle target): the result and its own error.
fn meshopt_at(mesh: &MeshData, target_error: f32) -> (MeshData, f32) {
    let indices: Vec<u32> = mesh.triangles.iter().flatten().copied().collect();
    let bytes = meshopt::utilities::typed_to_bytes(&mesh.positions);
    let adapter = meshopt::VertexDataAdapter::new(bytes, std::mem::size_of::<[f32; 3]>(), 0)
        .expect("12-byte vertices");
    let mut err = 0.0f32;
    let out = meshopt::simplify(
        &indices,
        &adapter,
        0,
        target_error,
        meshopt::SimplifyOptions::None,
        Some(&mut err),
    );
    let triangles = out.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
    (
        MeshData {
            positions: mesh.positions.clone(),
            triangles,
        },
        err,
    )
}

/// `host-sim bound-table`.
pub fn run(args: &Args) -> Result<ExitCode> {
    let meshes = if args.meshes.is_empty() {
        default_meshes()
    } else {
        args.meshes.clone()
    };
    let f = args.fraction;
    let opts = MetroOptions {
        samples_per_triangle: args.samples_per_triangle,
        ..Default::default()
    };
    crate::outln!(
        "bound d_hold = {} % of the bbox diagonal; meshoptimizer target_error = {f}; Metro {} \
         face samples per triangle; distances in % of the diagonal",
        100.0 * f,
        args.samples_per_triangle
    );
    crate::outln!();
    let mut head = String::from(
        "| mesh | triangles in | ours (edge) | E_max | E_mean | Metro max orig→ours | Hausdorff | ms \
         | envelope | its Hausdorff | ms | envelope / controls |",
    );
    let mut rule = String::from("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
    if args.triangle {
        head += " ours (triangle op) | E_max | Metro max orig→ours |";
        rule += "---:|---:|---:|";
    }
    head += " meshopt @ target_error | its Metro max orig→mopt | ours / mopt |";
    rule += "---:|---:|---:|";
    crate::outln!("{head}");
    crate::outln!("{rule}");
    let mut ok = true;
    for path in &meshes {
        let mesh = crate::io::load(path)?;
        let name = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        let diag = mesh.bbox_diagonal();
        let pct = |x: f64| 100.0 * x / diag.max(f64::MIN_POSITIVE);
        let config = Config::new()
            .with_ratio(0.0)
            .with_relative_max_error(f, &mesh.positions);
        let start = Instant::now();
        let bounded = crate::simplify::Run {
            bounded: true,
            ..Default::default()
        };
        let (ours, r, _) = crate::simplify::simplify_with(&mesh, &config, &bounded)?;
        let ms = start.elapsed().as_secs_f64() * 1e3;
        let m = metro(&mesh, &ours, &opts);
        let emax = f64::from(r.max_error.unwrap_or(f32::NAN));
        let emean = f64::from(r.mean_error.unwrap_or(f32::NAN));
        ok &= emax <= f64::from(config.max_error());
        let hausdorff = m.a_to_b.max_pct.max(m.b_to_a.max_pct);
        let start = Instant::now();
        let (env, re, _) = crate::simplify::simplify_with(
            &mesh,
            &config.with_error_limit(f32::INFINITY),
            &crate::simplify::Run {
                envelope: true,
                ..bounded
            },
        )?;
        let env_ms = start.elapsed().as_secs_f64() * 1e3;
        let me = metro(&mesh, &env, &opts);
        let env_h = me.a_to_b.max.max(me.b_to_a.max);
        ok &= env_h <= f64::from(config.max_error());
        let mut row = format!(
            "| {name} | {} | {} | {:.3} % | {:.3} % | {:.3} % | {hausdorff:.3} % | {ms:.0} | {} | \
             {:.3} % | {env_ms:.0} | {:.2}x |",
            mesh.triangles.len(),
            r.triangles_out,
            pct(emax),
            pct(emean),
            m.a_to_b.max_pct,
            re.triangles_out,
            pct(env_h),
            re.triangles_out as f64 / r.triangles_out.max(1) as f64,
        );
        if args.triangle {
            let (tri, rt, _) = crate::simplify::simplify_with(
                &mesh,
                &config,
                &crate::simplify::Run {
                    operator: OperatorArg::Triangle,
                    ..bounded
                },
            )?;
            let mt = metro(&mesh, &tri, &opts);
            let e = f64::from(rt.max_error.unwrap_or(f32::NAN));
            ok &= e <= f64::from(config.max_error());
            row += &format!(
                " {} | {:.3} % | {:.3} % |",
                rt.triangles_out,
                pct(e),
                mt.a_to_b.max_pct
            );
        }
        let (mo, _err) = meshopt_at(&mesh, f);
        let mm = metro(&mesh, &mo, &opts);
        row += &format!(
            " {} | {:.3} % | {:.2}x |",
            mo.triangles.len(),
            mm.a_to_b.max_pct,
            r.triangles_out as f64 / mo.triangles.len().max(1) as f64
        );
        crate::outln!("{row}");
    }
    Ok(if ok {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}
