//! `host-sim bench --cluster`: the library's streaming vertex clustering against
//! meshoptimizer's `simplifySloppy` (`meshopt::simplify_sloppy`), one row per mesh and ratio.

use std::fmt::Write as _;
use std::path::Path;
use std::process::ExitCode;

use anyhow::{Context, Result};
use tinydecimate::cluster::ClusterConfig;

use super::meshopt::sloppy;
use super::{median, Options};
use crate::cluster::{cluster, defects, VertexMemory};
use crate::metro::{metro, MetroOptions};

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

/// `host-sim bench --cluster`: every mesh of the directory (smallest first) at each ratio.
pub fn rows(
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
                    median(&ours_t),
                    om.symmetric_mean_pct,
                    od,
                    odg,
                ),
                ours_keys_ms: median(&keys_t),
                ours_bit_ms: median(&bit_t),
                ours_stream_ms: median(&stream_t),
                sloppy: (s.triangles.len(), median(&sl_t), sd, sdg),
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
pub fn run(opts: &Options, out: Option<&Path>) -> Result<ExitCode> {
    let rows = rows(&opts.meshes, opts.only.as_deref(), &opts.ratios, opts.reps)?;
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
