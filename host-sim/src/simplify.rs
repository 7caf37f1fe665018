//! `host-sim simplify`: runs the library on a mesh file, prints its report, memory figures and
//! (unless `--no-measure`) the validity check and the Metro error of the result.

use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::Mutex;
use std::time::{Duration, Instant};

use anyhow::{anyhow, Result};
use tinydecimate::{Config, CostKind, FeatureMode, Report, Schedule, Workspace};

use crate::io::MeshData;

/// Largest mesh the harness takes: vertices.
pub const MAX_VERTICES: usize = 262_144;
/// Largest mesh the harness takes: triangles.
pub const MAX_TRIANGLES: usize = 524_288;
/// The harness's workspace type.
pub type HostWorkspace = Workspace<u32, MAX_VERTICES, MAX_TRIANGLES>;

/// One big workspace in `.bss` (about 12 MB: too large for a thread's stack).
pub static WS: Mutex<HostWorkspace> = Mutex::new(Workspace::new());

/// Bytes of `tinydecimate::Workspace` per vertex and per triangle for link type `L`, read
/// off the library's own `BYTES` (differences, so no fixed part or padding leaks in).
const fn costs<L: tinydecimate::Index>() -> (usize, usize) {
    const P: usize = 1024;
    let v = (Workspace::<L, { 2 * P }, 0>::BYTES - Workspace::<L, P, 0>::BYTES) / P;
    let t = (Workspace::<L, 0, { 2 * P }>::BYTES - Workspace::<L, 0, P>::BYTES) / P;
    (v, t)
}

/// Bytes a workspace sized exactly for `v` vertices and `t` triangles needs, and its link size
/// `L` in bytes: `u16` links (L = 2) when `v <= 65535 && t <= 65535`, else `u32` (L = 4).
///
/// The per-vertex and per-triangle costs are taken from the library's `Workspace::BYTES`
/// instead of being hard-coded, so this stays exact when the workspace changes: today (3 links
/// per vertex: list head, heap slot, heap position; a 4-byte key and a flag byte; 3 links per
/// triangle) it is `v·(3L + 4 + 1) + t·3L`, rounded up to the struct's 4-byte alignment.
pub fn workspace_bytes(v: usize, t: usize) -> (usize, usize) {
    // The library's links number vertices and triangles below the link type's NIL.
    let small = v <= 65_535 && t <= 65_535;
    let ((pv, pt), link) = if small {
        (costs::<u16>(), 2)
    } else {
        (costs::<u32>(), 4)
    };
    let fixed = if small {
        Workspace::<u16, 0, 0>::BYTES
    } else {
        Workspace::<u32, 0, 0>::BYTES
    };
    ((fixed + v * pv + t * pt).next_multiple_of(4), link)
}

/// Which schedule, on the command line.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum ScheduleArg {
    /// Cheapest legal collapse of the whole mesh first.
    Greedy,
    /// The paper's passes.
    Passes,
}

/// Which cost, on the command line (`Config::with_cost`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum CostArg {
    /// `CostKind::Quadric`: memoryless quadric, squared distance to the removed vertex's
    /// current planes plus a boundary term (the default of `Config::new()`).
    Quadric,
    /// `CostKind::NormalVariation`: the paper's normal variation W, scaled by ℓ² for the
    /// greedy schedule (the cost of `Config::paper()`).
    Normal,
}

impl From<CostArg> for CostKind {
    fn from(c: CostArg) -> CostKind {
        match c {
            CostArg::Quadric => CostKind::Quadric,
            CostArg::Normal => CostKind::NormalVariation,
        }
    }
}

/// `host-sim simplify IN OUT ...`
#[derive(Clone, Debug, clap::Args)]
#[command(group = clap::ArgGroup::new("target").required(true).multiple(true))]
pub struct Args {
    /// Input mesh (.obj, .ply, .stl).
    pub input: PathBuf,
    /// Output mesh (.obj or .ply); keeps the input's vertex numbering.
    pub output: PathBuf,
    /// Target fraction of the input triangles, in [0, 1].
    #[arg(long, group = "target")]
    pub ratio: Option<f32>,
    /// Target triangle count (with --ratio, the higher target wins).
    #[arg(long, group = "target")]
    pub target_triangles: Option<usize>,
    /// Collapse schedule.
    #[arg(long, value_enum, default_value_t = ScheduleArg::Greedy)]
    pub schedule: ScheduleArg,
    /// Feature factor λ: a vertex is a feature iff D > λ·mean(D) (default 2; 1 with passes).
    #[arg(long)]
    pub lambda: Option<f32>,
    /// Normalise the feature measure D by valence² (FeatureMode::ValenceNormalized).
    #[arg(long)]
    pub valence_normalized: bool,
    /// Turn feature detection off (every vertex may be collapsed).
    #[arg(long)]
    pub no_features: bool,
    /// Greedy: feature vertices may not even be the kept end of a collapse (the paper's rule).
    #[arg(long)]
    pub no_feature_targets: bool,
    /// Largest normal turn of a triangle in one collapse, degrees.
    #[arg(long)]
    pub max_turn: Option<f32>,
    /// Smallest triangle quality a collapse may create (unless already worse).
    #[arg(long)]
    pub min_quality: Option<f32>,
    /// Weight of the boundary retreat in the cost.
    #[arg(long)]
    pub boundary_weight: Option<f32>,
    /// Collapse cost (default: the schedule's own, quadric for greedy as in `Config::new()`,
    /// normal for passes as in `Config::paper()`).
    #[arg(long, value_enum)]
    pub cost: Option<CostArg>,
    /// Skip the validity check and the Metro measurement afterwards.
    #[arg(long)]
    pub no_measure: bool,
    /// Metro face samples per triangle of the larger mesh.
    #[arg(long, default_value_t = 10.0)]
    pub samples_per_triangle: f64,
}

impl Args {
    /// The library configuration these arguments ask for.
    pub fn config(&self) -> Config {
        // `passes` means the paper as written (λ = 1, features take no part in any collapse).
        let base = match self.schedule {
            ScheduleArg::Greedy => Config::new().with_schedule(Schedule::Greedy),
            ScheduleArg::Passes => Config::paper(),
        };
        let base = match self.cost {
            Some(cost) => base.with_cost(cost.into()),
            None => base,
        };
        let mut c = base.with_feature_mode(if self.valence_normalized {
            FeatureMode::ValenceNormalized
        } else {
            FeatureMode::Paper
        });
        // Only a triangle count: let it alone decide.
        c = c.with_ratio(self.ratio.unwrap_or(0.0));
        if let Some(t) = self.target_triangles {
            c = c.with_target_triangles(t);
        }
        if let Some(l) = self.lambda {
            c = c.with_lambda(l);
        }
        c.features = !self.no_features;
        if self.no_feature_targets {
            c.feature_targets = false;
        }
        if let Some(x) = self.max_turn {
            c.max_normal_turn_deg = x;
        }
        if let Some(x) = self.min_quality {
            c.min_quality = x;
        }
        if let Some(x) = self.boundary_weight {
            c.boundary_weight = x;
        }
        c
    }
}

/// Runs the library on `mesh`. The result keeps all of `mesh`'s positions (the library only
/// rewrites triangles).
/// The cost is `config.cost`; the wall time is that of `Workspace::simplify` alone.
pub fn simplify(mesh: &MeshData, config: &Config) -> Result<(MeshData, Report, Duration)> {
    let mut tris = mesh.triangles.clone();
    let mut ws = WS.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
    let start = Instant::now();
    let report = ws
        .simplify(&mesh.positions, &mut tris, config)
        .map_err(|e| anyhow!("tinydecimate: {e}"))?;
    let elapsed = start.elapsed();
    tris.truncate(report.triangles_out);
    let out = MeshData {
        positions: mesh.positions.clone(),
        triangles: tris,
    };
    Ok((out, report, elapsed))
}

/// The report, every field, one per line.
pub fn format_report(r: &Report) -> String {
    let j = &r.rejected;
    let passes: Vec<String> = r.pass_triangles.iter().map(|t| t.to_string()).collect();
    format!(
        "  triangles in           {}\n\
         \x20 degenerate dropped     {}\n\
         \x20 duplicates dropped     {}\n\
         \x20 triangles out          {} ({:.2} % of the input)\n\
         \x20 target                 {} (reached: {})\n\
         \x20 stop                   {:?}\n\
         \x20 collapses              {}\n\
         \x20 vertices removed       {}\n\
         \x20 locked vertices        {}\n\
         \x20 feature vertices       {}\n\
         \x20 passes                 {}\n\
         \x20 triangles after pass   [{}]\n\
         \x20 rejected (total {}): locked {}, feature {}, boundary {}, link {}, duplicate {}, \
         normal turn {}, sliver {}, fold {}",
        r.triangles_in,
        r.degenerate_dropped,
        r.duplicates_dropped,
        r.triangles_out,
        100.0 * r.triangles_out as f64 / r.triangles_in.max(1) as f64,
        r.target_triangles,
        if r.target_reached { "yes" } else { "no" },
        r.stop,
        r.collapses,
        r.vertices_removed,
        r.locked_vertices,
        r.feature_vertices,
        r.passes,
        passes.join(", "),
        j.total(),
        j.locked,
        j.feature,
        j.boundary,
        j.link,
        j.duplicate,
        j.normal_turn,
        j.sliver,
        j.fold,
    )
}

/// `host-sim simplify`. Exit code 1 if the measured result is not a valid simplification.
pub fn run(args: &Args) -> Result<ExitCode> {
    let mesh = crate::io::load(&args.input)?;
    let config = args.config();
    let (out, report, elapsed) = simplify(&mesh, &config)?;
    crate::io::save(&args.output, &out)?;

    println!(
        "simplify {} -> {}",
        args.input.display(),
        args.output.display()
    );
    println!(
        "  schedule, cost         {:?}, {:?}",
        config.schedule, config.cost
    );
    println!("{}", format_report(&report));
    println!(
        "  library call           {:.3} ms",
        elapsed.as_secs_f64() * 1e3
    );
    let (v, t) = (mesh.positions.len(), mesh.triangles.len());
    let per_tri = |b: usize| b as f64 / t.max(1) as f64;
    println!(
        "  workspace (static)     {} bytes = Workspace<u32, {MAX_VERTICES}, {MAX_TRIANGLES}> \
         ({:.1} bytes per input triangle, misleading for a fixed big static)",
        HostWorkspace::BYTES,
        per_tri(HostWorkspace::BYTES)
    );
    let (need, link) = workspace_bytes(v, t);
    println!(
        "  workspace (right-size) {need} bytes for V = {v}, T = {t} with {link}-byte links \
         ({} bytes per vertex, {} per triangle; {:.2} bytes per input triangle)",
        if link == 2 {
            costs::<u16>().0
        } else {
            costs::<u32>().0
        },
        if link == 2 {
            costs::<u16>().1
        } else {
            costs::<u32>().1
        },
        per_tri(need)
    );

    if args.no_measure {
        return Ok(ExitCode::SUCCESS);
    }
    let validity = crate::check::compare(&mesh, &out);
    println!("check (input vs output):");
    println!("{validity}");
    let opts = crate::metro::MetroOptions {
        samples_per_triangle: args.samples_per_triangle,
        progress: true,
        ..Default::default()
    };
    let m = crate::metro::metro(&mesh, &out, &opts);
    println!("metro (input vs output):");
    println!("{m}");
    Ok(if validity.is_valid() {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[derive(Parser)]
    struct Cli {
        #[command(flatten)]
        args: Args,
    }

    #[test]
    fn workspace_bytes_formula() {
        // Exactly the library's size for a right-sized workspace.
        assert_eq!(
            workspace_bytes(100, 200),
            (Workspace::<u16, 100, 200>::BYTES, 2)
        );
        assert_eq!(
            workspace_bytes(101, 7),
            (Workspace::<u16, 101, 7>::BYTES, 2)
        );
        assert_eq!(
            workspace_bytes(70_000, 9),
            (Workspace::<u32, 70_000, 9>::BYTES, 4)
        );
        // The per-element costs the lead's formula names: 3 corner links per triangle, a
        // 4-byte key and a flag byte plus some links per vertex.
        let (v16, t16) = costs::<u16>();
        let (v32, t32) = costs::<u32>();
        assert_eq!((t16, t32), (6, 12));
        assert_eq!((v16 - 5) % 2, 0);
        assert_eq!((v32 - 5) / 4, (v16 - 5) / 2);
        // u16 limits: 65 535 vertices, 65 535 triangles.
        assert_eq!(workspace_bytes(65_535, 65_535).1, 2);
        assert_eq!(workspace_bytes(65_536, 10).1, 4);
        assert_eq!(workspace_bytes(10, 65_536).1, 4);
    }

    #[test]
    fn arguments_make_the_config() {
        let c = Cli::try_parse_from(["x", "a.obj", "b.obj", "--ratio", "0.25"]).unwrap();
        let cfg = c.args.config();
        assert_eq!(cfg.target_ratio, 0.25);
        assert_eq!(cfg.schedule, Schedule::Greedy);
        assert_eq!(cfg.feature_mode, FeatureMode::Paper);
        assert_eq!(cfg.cost, CostKind::Quadric);
        assert_eq!(cfg, Config::new().with_ratio(0.25));
        let c = Cli::try_parse_from(["x", "a.obj", "b.obj", "--ratio", "0.1", "--cost", "normal"])
            .unwrap();
        assert_eq!(
            c.args.config(),
            Config::new().with_cost(CostKind::NormalVariation)
        );
        let c =
            Cli::try_parse_from(["x", "a", "b", "--ratio", "0.1", "--schedule", "passes"]).unwrap();
        assert_eq!(c.args.config(), Config::paper().with_ratio(0.1));
        let c = Cli::try_parse_from([
            "x",
            "a",
            "b",
            "--ratio",
            "0.1",
            "--schedule",
            "passes",
            "--cost",
            "quadric",
        ])
        .unwrap();
        assert_eq!(c.args.config().cost, CostKind::Quadric);
        assert!(Cli::try_parse_from(["x", "a", "b", "--ratio", "0.1", "--cost", "plane"]).is_err());
        let c = Cli::try_parse_from([
            "x",
            "a.obj",
            "b.obj",
            "--target-triangles",
            "500",
            "--schedule",
            "passes",
            "--lambda",
            "1.5",
            "--valence-normalized",
        ])
        .unwrap();
        let cfg = c.args.config();
        assert_eq!((cfg.target_ratio, cfg.target_triangles), (0.0, 500));
        assert_eq!(cfg.schedule, Schedule::Passes);
        assert_eq!(cfg.lambda, 1.5);
        assert_eq!(cfg.feature_mode, FeatureMode::ValenceNormalized);
        assert!(Cli::try_parse_from(["x", "a.obj", "b.obj"]).is_err());
    }

    #[test]
    fn simplifies_a_grid_validly() {
        let n = 12u32;
        let mut m = MeshData::default();
        for y in 0..=n {
            for x in 0..=n {
                let (fx, fy) = (x as f32 / n as f32, y as f32 / n as f32);
                m.positions
                    .push([fx, fy, 0.1 * (fx * 3.0).sin() * (fy * 2.0).cos()]);
            }
        }
        for y in 0..n {
            for x in 0..n {
                let v = y * (n + 1) + x;
                m.triangles.push([v, v + 1, v + n + 2]);
                m.triangles.push([v, v + n + 2, v + n + 1]);
            }
        }
        let cfg = Config::new().with_ratio(0.3);
        let (out, report, _) = simplify(&m, &cfg).unwrap();
        assert_eq!(out.triangles.len(), report.triangles_out);
        assert!(report.triangles_out < m.triangles.len());
        assert_eq!(out.positions, m.positions);
        let v = crate::check::compare(&m, &out);
        assert!(v.is_valid(), "{v}");
        assert!(format_report(&report).contains("triangles out"));
    }
}
