//! `host-sim simplify`: runs the library on a mesh file, prints its report, memory figures and
//! (unless `--no-measure`) the validity check and the Metro error of the result, as text or
//! (`--json`) as one JSON object.
//!
//! The output path and format are checked before anything else; the input may be standard
//! input and the output standard output (`-`). Output files keep only the vertices the result
//! uses unless `--keep-numbering`.

use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::Mutex;
use std::time::{Duration, Instant};

use anyhow::{anyhow, bail, Result};
use tinydecimate::cost::{Placement, StoredQuadric, VertexQuadric};
use tinydecimate::{Config, CostKind, FeatureMode, Report, Schedule, Workspace};

use crate::io::{Format, MeshData};

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

/// Which operator, on the command line (`Config::with_operator`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum OperatorArg {
    /// Half-edge collapse.
    #[default]
    Edge,
    /// Triangle collapse (seed 001 §3): weight of eq. 3, penalty re-insertion; greedy only.
    Triangle,
}

/// Which quadric, on the command line.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum QuadricArg {
    /// The cost of `--cost` (memoryless quadric by default): nothing stored per vertex.
    #[default]
    Memoryless,
    /// `tinydecimate::cost::StoredQuadric`: a 4x4 quadric per vertex (40 B), summed on
    /// collapse, boundary planes weighted by --boundary-weight (greedy schedule only).
    Stored,
}

/// Where stored quadrics leave the kept vertex, on the command line.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum PlacementArg {
    /// At an endpoint: positions are only read.
    #[default]
    Subset,
    /// At the minimiser of the summed quadric (or the best of the endpoints and the
    /// midpoint): the output file carries the moved positions.
    Optimal,
}

impl From<PlacementArg> for Placement {
    fn from(p: PlacementArg) -> Placement {
        match p {
            PlacementArg::Subset => Placement::Subset,
            PlacementArg::Optimal => Placement::Optimal,
        }
    }
}

/// A number in a range, for clap: the error names the range and what the value means.
fn ranged(
    v: &str,
    ok: impl Fn(f32) -> bool,
    range: &str,
    meaning: &str,
) -> std::result::Result<f32, String> {
    let x: f32 = v
        .trim()
        .parse()
        .map_err(|_| format!("{v:?} is not a number; accepted: {range} ({meaning})"))?;
    if x.is_finite() && ok(x) {
        Ok(x)
    } else {
        Err(format!(
            "{v} is out of range; accepted: {range} ({meaning})"
        ))
    }
}

fn parse_ratio(v: &str) -> std::result::Result<f32, String> {
    ranged(
        v,
        |x| (0.0..=1.0).contains(&x),
        "0 to 1",
        "the fraction of the input triangles to keep, 0.25 keeps a quarter",
    )
}

/// A guaranteed error bound on the command line: a percentage of the bounding-box diagonal
/// (`0.5%`) or an absolute distance in the input's units (`0.02`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum MaxError {
    /// This fraction of the diagonal (`0.5%` is 0.005).
    Fraction(f32),
    /// This distance.
    Absolute(f32),
}

impl MaxError {
    /// The distance on `mesh`.
    pub fn distance(self, positions: &[[f32; 3]]) -> f32 {
        match self {
            MaxError::Fraction(f) => f * tinydecimate::bound::bounding_diagonal(positions),
            MaxError::Absolute(d) => d,
        }
    }
}

impl std::fmt::Display for MaxError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            MaxError::Fraction(x) => write!(f, "{}%", 100.0 * x),
            MaxError::Absolute(d) => write!(f, "{d}"),
        }
    }
}

/// `P%` or a distance.
pub fn parse_max_error(v: &str) -> std::result::Result<MaxError, String> {
    let v = v.trim();
    if let Some(p) = v.strip_suffix('%') {
        ranged(
            p,
            |x| x > 0.0 && x <= 100.0,
            "above 0 %, at most 100 %",
            "a percentage of the bounding-box diagonal, 0.5% is half a percent",
        )
        .map(|x| MaxError::Fraction(x / 100.0))
    } else {
        ranged(
            v,
            |x| x >= 0.0,
            "0 or more, or a percentage such as 0.5%",
            "a distance in the input's units",
        )
        .map(MaxError::Absolute)
    }
}

fn parse_lambda(v: &str) -> std::result::Result<f32, String> {
    ranged(v, |x| x >= 0.0, "0 or more", "the feature factor λ")
}

fn parse_turn(v: &str) -> std::result::Result<f32, String> {
    ranged(v, |x| x > 0.0 && x < 180.0, "above 0, below 180", "degrees")
}

fn parse_quality(v: &str) -> std::result::Result<f32, String> {
    ranged(
        v,
        |x| (0.0..1.0).contains(&x),
        "0 or more, below 1",
        "1 is an equilateral triangle",
    )
}

fn parse_weight(v: &str) -> std::result::Result<f32, String> {
    ranged(v, |x| x >= 0.0, "0 or more", "a weight")
}

fn parse_samples(v: &str) -> std::result::Result<f64, String> {
    ranged(v, |x| x > 0.0, "above 0", "samples per triangle").map(f64::from)
}

/// `host-sim simplify IN OUT ...`
#[derive(Clone, Debug, clap::Args)]
#[command(group = clap::ArgGroup::new("target").required(true).multiple(true))]
pub struct Args {
    /// Input mesh (.obj, .ply, .stl, .gltf, .glb; `-` reads standard input, the format found
    /// from the bytes). Quads and n-gons are split into triangles (ear clipping). glTF keeps
    /// every vertex attribute and is written as glTF; an OBJ with texture coordinates or
    /// normals written to OBJ keeps them and its materials, a PLY written to PLY its vertex
    /// properties. Otherwise only positions and faces are read: attributes are not carried,
    /// and a warning says which were dropped.
    pub input: PathBuf,
    /// Output mesh (.obj, .ply or .stl; `-` writes standard output, OBJ unless --format says
    /// otherwise, and the report then goes to stderr). Checked before simplifying. Vertices no
    /// output triangle uses are dropped (see --keep-numbering).
    pub output: PathBuf,
    /// Output format, instead of the output's extension.
    #[arg(long, value_enum)]
    pub format: Option<Format>,
    /// Keep every input vertex in the output file, so that its indices are the input's (what
    /// a firmware's index buffer into the same positions needs). STL has no numbering.
    #[arg(long)]
    pub keep_numbering: bool,
    /// Target fraction of the input triangles, 0 to 1.
    #[arg(long, group = "target", allow_negative_numbers = true, value_parser = parse_ratio)]
    pub ratio: Option<f32>,
    /// Target triangle count (with --ratio, the higher target wins).
    #[arg(long, group = "target")]
    pub target_triangles: Option<usize>,
    /// Guaranteed error bound (Zhu, Wang and Meng 2007, seed 001): no original triangle's
    /// centroid and no vertex of an original feature edge ends farther than this from the
    /// result. `P%` of the bounding-box diagonal (`0.5%`) or an absolute distance in the
    /// input's units. Alone, simplifies as far as the bound allows; with --ratio or
    /// --target-triangles, whichever stops first. Any schedule and cost; `--quadric stored`
    /// with subset placement only. Prints E_max and E_mean (eq. 4-5) next to the Metro
    /// one-sided maximum from the input to the result.
    #[arg(long, group = "target", allow_negative_numbers = true, value_parser = parse_max_error)]
    pub max_error: Option<MaxError>,
    /// Collapse schedule.
    #[arg(long, value_enum, default_value_t = ScheduleArg::Greedy)]
    pub schedule: ScheduleArg,
    /// Feature factor λ: a vertex is a feature iff D > λ·mean(D) (default 2; 1 with passes).
    #[arg(long, allow_negative_numbers = true, value_parser = parse_lambda)]
    pub lambda: Option<f32>,
    /// Normalise the feature measure D by valence² (FeatureMode::ValenceNormalized).
    #[arg(long)]
    pub valence_normalized: bool,
    /// Turn feature detection off (every vertex may be collapsed). The default with
    /// `--quadric stored` (`Config::stored()`).
    #[arg(long, conflicts_with = "features")]
    pub no_features: bool,
    /// Turn feature detection on with `--quadric stored` (seed 004's rule on top of the
    /// quadrics; on by default in every other mode).
    #[arg(long)]
    pub features: bool,
    /// Greedy: feature vertices may not even be the kept end of a collapse (the paper's rule).
    #[arg(long)]
    pub no_feature_targets: bool,
    /// Largest normal turn of a triangle in one collapse, degrees.
    #[arg(long, allow_negative_numbers = true, value_parser = parse_turn)]
    pub max_turn: Option<f32>,
    /// Smallest triangle quality a collapse may create (unless already worse).
    #[arg(long, allow_negative_numbers = true, value_parser = parse_quality)]
    pub min_quality: Option<f32>,
    /// Weight of the boundary retreat in the cost.
    #[arg(long, allow_negative_numbers = true, value_parser = parse_weight)]
    pub boundary_weight: Option<f32>,
    /// Collapse cost (default: the schedule's own, quadric for greedy as in `Config::new()`,
    /// normal for passes as in `Config::paper()`).
    #[arg(long, value_enum)]
    pub cost: Option<CostArg>,
    /// Simplification operator: half-edge collapse, or the triangle collapse of seed 001
    /// (Zhu, Wang and Meng 2007; greedy schedule only).
    #[arg(long, value_enum, default_value_t = OperatorArg::Edge)]
    pub operator: OperatorArg,
    /// Quadric: `stored` keeps a quadric per vertex (issue 15), replacing --cost.
    #[arg(long, value_enum, default_value_t = QuadricArg::Memoryless)]
    pub quadric: QuadricArg,
    /// Placement of the kept vertex with `--quadric stored`.
    #[arg(long, value_enum, default_value_t = PlacementArg::Subset)]
    pub placement: PlacementArg,
    /// Skip the validity check and the Metro measurement afterwards.
    #[arg(long)]
    pub no_measure: bool,
    /// Metro face samples per triangle of the larger mesh.
    #[arg(long, default_value_t = 10.0, allow_negative_numbers = true, value_parser = parse_samples)]
    pub samples_per_triangle: f64,
    /// Print the report, the check and the Metro error as one JSON object on stdout.
    #[arg(long)]
    pub json: bool,
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
        // Stored quadrics default to `Config::stored()`: no feature rule.
        c.features = if self.quadric == QuadricArg::Stored {
            self.features
        } else {
            !self.no_features
        };
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
        if self.operator == OperatorArg::Triangle {
            c = c.with_operator(tinydecimate::Operator::Triangle);
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

/// Runs the library with stored quadrics on `mesh` (`Workspace::start_with_cost`, or
/// `start_moving` for optimal placement), stepping with a progress bar when `progress`. The
/// result carries the positions as the library left them (moved by optimal placement). The
/// wall time is that of the library alone (the quadric storage is allocated before).
pub fn simplify_stored(
    mesh: &MeshData,
    config: &Config,
    placement: Placement,
    progress: bool,
) -> Result<(MeshData, Report, Duration)> {
    let mut tris = mesh.triangles.clone();
    let mut positions = mesh.positions.clone();
    let mut quadrics: Vec<VertexQuadric> = vec![[0.0; 10]; positions.len()];
    let mut ws = WS.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
    let bar = progress.then(|| {
        crate::progress::Progress::new(
            "simplify {bar:40} {pos}/{len} triangles removed ({elapsed})",
            mesh.triangles.len() as u64,
        )
    });
    let start = Instant::now();
    let cost = StoredQuadric::new(&mut quadrics, config.boundary_weight, placement);
    macro_rules! drive {
        ($s:expr) => {{
            let mut s = $s.map_err(|e| anyhow!("tinydecimate: {e}"))?;
            let n0 = s.live_triangles();
            while !s.step(1 << 14) {
                if let Some(b) = &bar {
                    b.set((n0 - s.live_triangles().min(n0)) as u64);
                }
            }
            s.finish()
        }};
    }
    let report = match placement {
        Placement::Subset => drive!(ws.start_with_cost(&positions, &mut tris, config, cost)),
        Placement::Optimal => drive!(ws.start_moving(&mut positions, &mut tris, config, cost)),
    };
    let elapsed = start.elapsed();
    if let Some(b) = bar {
        b.finish();
    }
    tris.truncate(report.triangles_out);
    Ok((
        MeshData {
            positions,
            triangles: tris,
        },
        report,
        elapsed,
    ))
}

/// Runs the library with the error bound (`Workspace::start_bounded`, control points in a
/// `u32` link slice), with the configuration's cost or stored quadrics with subset placement,
/// stepping with a progress bar when `progress`. The wall time is that of the library alone.
pub fn simplify_bounded(
    mesh: &MeshData,
    config: &Config,
    stored: bool,
    progress: bool,
) -> Result<(MeshData, Report, Duration)> {
    let mut tris = mesh.triangles.clone();
    let mut links = vec![0u32; tinydecimate::bound::control_len(tris.len(), mesh.positions.len())];
    let mut quadrics: Vec<VertexQuadric> = if stored {
        vec![[0.0; 10]; mesh.positions.len()]
    } else {
        Vec::new()
    };
    let mut ws = WS.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
    let bar = progress.then(|| {
        crate::progress::Progress::new(
            "simplify {bar:40} {pos}/{len} triangles removed ({elapsed})",
            mesh.triangles.len() as u64,
        )
    });
    let start = Instant::now();
    macro_rules! drive {
        ($s:expr) => {{
            let mut s = $s.map_err(|e| anyhow!("tinydecimate: {e}"))?;
            let n0 = s.live_triangles();
            while !s.step(1 << 12) {
                if let Some(b) = &bar {
                    b.set((n0 - s.live_triangles().min(n0)) as u64);
                }
            }
            s.finish()
        }};
    }
    let (p, o) = (&mesh.positions, &mesh.triangles);
    let report = if stored {
        let cost = StoredQuadric::new(&mut quadrics, config.boundary_weight, Placement::Subset);
        drive!(ws.start_bounded(p, o, &mut tris, &mut links, config, cost))
    } else {
        let cost = tinydecimate::cost::Builtin::of(config);
        drive!(ws.start_bounded(p, o, &mut tris, &mut links, config, cost))
    };
    let elapsed = start.elapsed();
    if let Some(b) = bar {
        b.finish();
    }
    tris.truncate(report.triangles_out);
    Ok((
        MeshData {
            positions: mesh.positions.clone(),
            triangles: tris,
        },
        report,
        elapsed,
    ))
}

/// Bytes of control links per input triangle for a bounded run with `u16`/`u32` links:
/// `control_len(T, V)` links.
pub fn control_bytes(v: usize, t: usize) -> (usize, usize) {
    let n = tinydecimate::bound::control_len(t, v);
    (2 * n, 4 * n)
}

/// Bytes of stored quadrics per vertex.
pub const QUADRIC_BYTES: usize = core::mem::size_of::<VertexQuadric>();

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
         normal turn {}, sliver {}, fold {}, bound {}{}",
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
        j.bound,
        match (r.max_error, r.mean_error) {
            (Some(a), Some(b)) => format!("\n  E_max, E_mean          {a:.6e}, {b:.6e}"),
            _ => String::new(),
        },
    )
}

/// [`simplify`] driven step by step, with a progress bar on stderr when it is a terminal and
/// the run takes over a second. Same result as [`simplify`] (steps of any size give the result
/// of `Workspace::simplify`).
pub fn simplify_with_progress(
    mesh: &MeshData,
    config: &Config,
) -> Result<(MeshData, Report, Duration)> {
    let mut tris = mesh.triangles.clone();
    let mut ws = WS.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
    let start = Instant::now();
    let progress = crate::progress::Progress::new(
        "simplify {bar:40} {pos}/{len} triangles removed ({elapsed})",
        mesh.triangles.len() as u64,
    );
    let report = {
        let mut s = ws
            .start(&mesh.positions, &mut tris, config)
            .map_err(|e| anyhow!("tinydecimate: {e}"))?;
        let n0 = s.live_triangles();
        while !s.step(1 << 14) {
            progress.set((n0 - s.live_triangles().min(n0)) as u64);
        }
        s.finish()
    };
    progress.finish();
    let elapsed = start.elapsed();
    tris.truncate(report.triangles_out);
    let out = MeshData {
        positions: mesh.positions.clone(),
        triangles: tris,
    };
    Ok((out, report, elapsed))
}

/// The report as JSON: every field of `Report`.
pub fn report_json(r: &Report) -> serde_json::Value {
    let j = &r.rejected;
    serde_json::json!({
        "triangles_in": r.triangles_in,
        "degenerate_dropped": r.degenerate_dropped,
        "duplicates_dropped": r.duplicates_dropped,
        "triangles_out": r.triangles_out,
        "target_triangles": r.target_triangles,
        "target_reached": r.target_reached,
        "stop": format!("{:?}", r.stop),
        "collapses": r.collapses,
        "vertices_removed": r.vertices_removed,
        "locked_vertices": r.locked_vertices,
        "feature_vertices": r.feature_vertices,
        "passes": r.passes,
        "pass_triangles": r.pass_triangles.iter().collect::<Vec<_>>(),
        "rejected": {
            "total": j.total(),
            "locked": j.locked,
            "feature": j.feature,
            "boundary": j.boundary,
            "link": j.link,
            "duplicate": j.duplicate,
            "normal_turn": j.normal_turn,
            "sliver": j.sliver,
            "fold": j.fold,
            "bound": j.bound,
        },
        "max_error": r.max_error,
        "mean_error": r.mean_error,
    })
}

/// `host-sim simplify`. Exit code 1 if the measured result is not a valid simplification.
pub fn run(args: &Args) -> Result<ExitCode> {
    use std::fmt::Write as _;
    // Everything that can be refused is refused before the long work.
    let to_stdout = crate::io::is_std(&args.output);
    if to_stdout && args.json {
        bail!("--json and an output of `-` would both write standard output: give an output file");
    }
    // glTF, and OBJ with texture coordinates or normals: attributes carried (textured.rs).
    if let Some(code) = crate::textured::run_if_attributes(args)? {
        return Ok(code);
    }
    let out_format = crate::io::check_writable(&args.output, args.format)?;
    let mesh = crate::io::load_noting(&args.input)?;
    let mut config = args.config();
    if let Some(e) = args.max_error {
        config = config.with_max_error(e.distance(&mesh.positions));
    }
    config
        .validate()
        .map_err(|e| anyhow!("configuration: {e}"))?;
    let stored = args.quadric == QuadricArg::Stored;
    if stored && config.schedule != Schedule::Greedy {
        bail!("--quadric stored runs the greedy schedule only (drop --schedule passes)");
    }
    let bounded = args.max_error.is_some();
    if bounded && stored && args.placement == PlacementArg::Optimal {
        bail!(
            "--max-error keeps positions read only: use --placement subset with --quadric stored"
        );
    }
    let (out, report, elapsed) = if bounded {
        simplify_bounded(&mesh, &config, stored, true)?
    } else if stored {
        simplify_stored(&mesh, &config, args.placement.into(), true)?
    } else {
        simplify_with_progress(&mesh, &config)?
    };
    let written = if args.keep_numbering {
        out.clone()
    } else {
        crate::io::compact(&out).0
    };
    crate::io::save_as(&args.output, out_format, &written)?;

    let mut text = String::new();
    let _ = writeln!(
        text,
        "simplify {} -> {} ({:?}, {} vertices{})",
        args.input.display(),
        args.output.display(),
        out_format,
        written.positions.len(),
        if args.keep_numbering {
            ", input numbering kept"
        } else {
            ", unreferenced dropped"
        }
    );
    if stored {
        let _ = writeln!(
            text,
            "  schedule, cost         {:?}, stored quadric ({:?} placement, boundary weight {})",
            config.schedule, args.placement, config.boundary_weight
        );
    } else {
        let _ = writeln!(
            text,
            "  schedule, cost, op     {:?}, {:?}, {:?} collapse",
            config.schedule, config.cost, config.operator
        );
    }
    if let Some(e) = args.max_error {
        let _ = writeln!(
            text,
            "  error bound            d_hold {e} = {:.6e} (guaranteed at the control points; \
             feature edges past {}°)",
            config.max_error, config.control_angle_deg
        );
    }
    let _ = writeln!(text, "{}", format_report(&report));
    let _ = writeln!(
        text,
        "  library call           {:.3} ms",
        elapsed.as_secs_f64() * 1e3
    );
    let (v, t) = (mesh.positions.len(), mesh.triangles.len());
    let per_tri = |b: usize| b as f64 / t.max(1) as f64;
    let _ = writeln!(
        text,
        "  workspace (static)     {} bytes = Workspace<u32, {MAX_VERTICES}, {MAX_TRIANGLES}> \
         ({:.1} bytes per input triangle, misleading for a fixed big static)",
        HostWorkspace::BYTES,
        per_tri(HostWorkspace::BYTES)
    );
    let (need, link) = workspace_bytes(v, t);
    let _ = writeln!(
        text,
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
    if args.max_error.is_some() {
        let (b16, b32) = control_bytes(v, t);
        let _ = writeln!(
            text,
            "  control links          2T + V = {} links: {b16} bytes with u16 links ({:.2} per \
             input triangle), {b32} with u32 ({:.2})",
            tinydecimate::bound::control_len(t, v),
            per_tri(b16),
            per_tri(b32)
        );
    }
    if stored {
        let _ = writeln!(
            text,
            "  stored quadrics        {} bytes ({QUADRIC_BYTES} per vertex); with the workspace \
             {:.2} bytes per input triangle",
            v * QUADRIC_BYTES,
            per_tri(need + v * QUADRIC_BYTES)
        );
    }
    let say = |text: &str| {
        if to_stdout {
            eprint!("{text}");
        } else if !args.json {
            crate::out!("{text}");
        }
    };
    say(&text);
    text.clear();

    let mut json = serde_json::json!({
        "input": args.input.display().to_string(),
        "output": args.output.display().to_string(),
        "output_format": format!("{out_format:?}"),
        "output_vertices": written.positions.len(),
        "keep_numbering": args.keep_numbering,
        "schedule": format!("{:?}", config.schedule),
        "cost": format!("{:?}", config.cost),
        "operator": format!("{:?}", config.operator),
        "quadric": format!("{:?}", args.quadric),
        "placement": format!("{:?}", args.placement),
        "max_error": args.max_error.map(|e| e.to_string()),
        "d_hold": if config.max_error.is_finite() { Some(config.max_error) } else { None },
        "report": report_json(&report),
        "library_ms": elapsed.as_secs_f64() * 1e3,
        "workspace_bytes": need,
    });
    let mut valid = true;
    if !args.no_measure {
        // The library drops degenerate and duplicate triangles before it starts; the check
        // compares the output with the input as the library saw it (`meshcheck::clean`).
        let moved = stored && args.placement == PlacementArg::Optimal;
        let validity = crate::check::compare_with(&mesh, &out, moved);
        valid = validity.is_valid();
        let _ = writeln!(
            text,
            "check (output vs the cleaned input: the input less its {} degenerate and {} \
             duplicate triangles, as the library dropped them):",
            report.degenerate_dropped, report.duplicates_dropped
        );
        let _ = writeln!(text, "{validity}");
        let opts = crate::metro::MetroOptions {
            samples_per_triangle: args.samples_per_triangle,
            progress: true,
            ..Default::default()
        };
        let m = crate::metro::metro(&mesh, &out, &opts);
        let _ = writeln!(text, "metro (input vs output):");
        let _ = writeln!(text, "{m}");
        if let (Some(emax), Some(emean)) = (report.max_error, report.mean_error) {
            let pct = |x: f64| 100.0 * x / m.diagonal.max(f64::MIN_POSITIVE);
            let _ = writeln!(
                text,
                "error bound (input units; % of the diagonal):\n\
                 \x20 d_hold                   {:.6e} = {:.5} %\n\
                 \x20 E_max  (eq. 4)           {:.6e} = {:.5} %\n\
                 \x20 E_mean (eq. 5)           {:.6e} = {:.5} %\n\
                 \x20 Metro max orig -> simpl  {:.6e} = {:.5} %  (sampled, not bounded)",
                config.max_error,
                pct(f64::from(config.max_error)),
                emax,
                pct(f64::from(emax)),
                emean,
                pct(f64::from(emean)),
                m.a_to_b.max,
                m.a_to_b.max_pct,
            );
        }
        say(&text);
        json["check"] = serde_json::json!({
            "against": "cleaned input",
            "validity": validity,
            "defects": validity.defects.iter().map(|d| d.to_string()).collect::<Vec<_>>(),
            "valid": valid,
        });
        json["metro"] = serde_json::to_value(&m)?;
    }
    json["valid"] = serde_json::Value::Bool(valid);
    if args.json {
        crate::outln!("{}", serde_json::to_string_pretty(&json)?);
    }
    Ok(if valid {
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
        // Stored quadrics: `Config::stored()` (no feature rule) unless --features.
        let stored = |extra: &[&str]| {
            let mut a = vec!["x", "a", "b", "--ratio", "0.1", "--quadric", "stored"];
            a.extend_from_slice(extra);
            Cli::try_parse_from(a).map(|c| c.args.config())
        };
        assert_eq!(stored(&[]).unwrap(), Config::stored().with_ratio(0.1));
        assert_eq!(
            stored(&["--features"]).unwrap(),
            Config::new().with_ratio(0.1)
        );
        assert!(stored(&["--features", "--no-features"]).is_err());
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
