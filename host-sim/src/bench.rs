//! `host-sim bench`: every tinydecimate mode against meshoptimizer on a directory of meshes, in
//! one process and one run, written as Markdown and JSON.
//!
//! For every mesh and ratio `r` every simplifier of [`Method`] (or those `--modes` names) runs
//! on the same input: our modes as `tinydecimate simplify` runs them (each variant's `Method` docs
//! give its configuration), and the reference:
//!
//! * **meshopt**: `meshopt::simplify` (meshoptimizer [`MESHOPTIMIZER_VERSION`], bundled by the
//!   `meshopt` crate [`MESHOPT_CRATE_VERSION`]) with a target index count of
//!   `3·⌊r·T⌋` (the library's own rounding of the ratio), target error 1.0 (100 % of the mesh
//!   extent: no error limit) and default options.
//!
//! Each run is repeated `reps` times, every repetition on a fresh copy of the input, and the
//! median wall time of the simplifier call alone is reported. The result of the last repetition
//! (every simplifier is deterministic) is checked with [`crate::check::compare`] and measured
//! with [`crate::metro::metro`]. Scratch memory per input triangle is, for tinydecimate, the
//! exact right-sized workspace ([`crate::workspace::workspace_bytes`]); for meshoptimizer, the
//! peak of the bytes live in its temporary allocator during the call, counted through
//! `meshopt_setAllocator`. The output index buffer the `meshopt` wrapper allocates is not
//! counted (tinydecimate writes its result over its input instead).
//!
//! **Error at the same triangle count.** The library may stop above its target (messy,
//! multi-part meshes: locked non-manifold parts, no legal collapse left). Comparing that result
//! with meshoptimizer's at the target would flatter the library (more triangles, less error), so
//! whenever one of our modes stops short, meshoptimizer runs once more with the triangle count
//! the library reached as its target ([`SameCount`]), and that mode's error ratios are taken
//! against this run instead.
//!
//! A benchmark reports: nothing here asserts timings or validity.

use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::time::Duration;

use anyhow::{bail, Context, Result};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use serde::Serialize;
use tinydecimate::{Config, CostKind, Rejections, Report};

use crate::check::{compare, Validity};
use crate::io::MeshData;
use crate::metro::{metro, MetroOptions};
use crate::workspace::workspace_bytes;
use meshopt::{meshopt_simplify, meshopt_simplify_with_update};

pub mod cluster;
pub mod markdown;
pub use tinydecimate_cli::meshopt;

/// The meshoptimizer version that `meshopt` [`MESHOPT_CRATE_VERSION`] bundles
/// (`MESHOPTIMIZER_VERSION 1030` in its `vendor/src/meshoptimizer.h`).
pub const MESHOPTIMIZER_VERSION: &str = "1.3";
/// The `meshopt` crate version host-sim pins (`meshopt = "=0.7.0"` in its Cargo.toml).
pub const MESHOPT_CRATE_VERSION: &str = "0.7.0";

/// The meshes `--quick` runs (file names in the mesh directory).
pub const QUICK_MESHES: [&str; 2] = ["cow.obj", "plate_holes.obj"];
/// The ratios `--quick` runs.
pub const QUICK_RATIOS: [f32; 2] = [0.5, 0.1];
/// The messy multi-part meshes of `tests/fixtures` and `bench/meshes` (see their SOURCES.md:
/// many open parts, non-manifold edges, pinched vertices). The summary reports their worst error ratios apart
/// from the other meshes': the targets are ≤ 1.5x meshoptimizer at the same triangle count there,
/// ≤ 0.8x mean and ≤ 1.0x max elsewhere.
pub const MESSY_MESHES: [&str; 3] = ["wuson.obj", "pr2_sensor_mount.obj", "2CylinderEngine.obj"];

/// Whether `mesh` (a file name) is one of [`MESSY_MESHES`].
pub fn is_messy(mesh: &str) -> bool {
    MESSY_MESHES.contains(&mesh)
}

/// The real-world meshes of `tests/fixtures` (see its SOURCES.md, "Added for real-world
/// content"): raw CAD exports (flat faces tessellated into long slivers), a renderer's
/// seam-split index buffer, and a glTF mesh of several materials (its primitives read as
/// `simplify` reads them, positions only). Their worst error ratios are reported apart, held to ≤ 1.0x
/// meshoptimizer (at the same triangle count where ours stops short).
pub const REAL_WORLD_MESHES: [&str; 4] = [
    "pins.obj",
    "tray_bottom.obj",
    "suzanne_seams.obj",
    "CesiumMilkTruck.glb",
];

/// Whether `mesh` (a file name) is one of [`REAL_WORLD_MESHES`].
pub fn is_real_world(mesh: &str) -> bool {
    REAL_WORLD_MESHES.contains(&mesh)
}

/// The ratios the summary's time figure is the geometric mean over (50 % and 10 %).
pub const TIME_RATIOS: [f32; 2] = [0.5, 0.1];

/// The repository's public test meshes (`tests/fixtures`, sources and licences in its
/// SOURCES.md): the default mesh directory.
pub fn default_meshes() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/fixtures")
}

/// The bench's own meshes (`bench/meshes`, sources and licences in its SOURCES.md): messy
/// multi-part models too large for `tests/fixtures`, whose every mesh the tests walk. A run
/// of the default directory adds them.
pub fn bench_meshes() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../bench/meshes")
}

/// Whether `name` is a mesh file the bench reads (by its extension).
fn is_mesh_file(name: &str) -> bool {
    let ext = name.rsplit('.').next().unwrap_or("").to_ascii_lowercase();
    name.contains('.') && matches!(ext.as_str(), "obj" | "ply" | "stl" | "glb" | "gltf")
}

/// What one benchmark run does (the resolved [`Args`](crate::cmd::bench::Args)).
#[derive(Clone, Debug, PartialEq)]
pub struct Options {
    /// Mesh directory.
    pub meshes: PathBuf,
    /// A second mesh directory whose meshes run too (the default run: [`bench_meshes`]).
    pub more: Option<PathBuf>,
    /// Only these file names from the directories (`None`: every mesh file).
    pub only: Option<Vec<String>>,
    /// Target ratios.
    pub ratios: Vec<f32>,
    /// Repetitions per run.
    pub reps: usize,
    /// Metro face samples per triangle.
    pub samples_per_triangle: f64,
    /// Show a progress bar (only if stderr is a terminal).
    pub progress: bool,
    /// Our modes prune parts (`tinydecimate simplify --parts prune`, the default).
    pub prune: bool,
    /// Only these of our modes (`None`: every one); meshoptimizer always runs.
    pub modes: Option<Vec<Method>>,
}

/// One simplifier.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, clap::ValueEnum)]
#[serde(rename_all = "snake_case")]
pub enum Method {
    /// tinydecimate, `Config::new()`: greedy schedule, `CostKind::Quadric` (the default).
    Default,
    /// tinydecimate, `Config::new().with_cost(CostKind::NormalVariation)`: greedy schedule,
    /// the paper's W times ℓ².
    GreedyW,
    /// tinydecimate, `Config::paper()`: the paper's passes with W.
    Paper,
    /// meshoptimizer's `meshopt_simplify`.
    Meshopt,
    /// tinydecimate, stored quadrics with subset placement (`StoredQuadric`, `Placement::Subset`).
    Stored,
    /// tinydecimate, stored quadrics with optimal placement (`StoredQuadric`, `Placement::Optimal`).
    StoredOptimal,
    /// meshoptimizer's `meshopt_simplifyWithUpdate` (positions moved, no attributes).
    MeshoptUpdate,
    /// tinydecimate, `VertexDecimation` (Schroeder, Zarge and Lorensen 1992) with
    /// `Config::new()`.
    VertexDecimation,
    /// tinydecimate, Hoppe's energy (`tinydecimate::cost::Energy`, κ =
    /// `Energy::KAPPA`) with `Config::new()`.
    Energy,
    /// tinydecimate, `Config::new().with_schedule(Schedule::Batched)`: the default's cost
    /// and rules in meshoptimizer's passes.
    Batched,
    /// tinydecimate's fast mode, `pipeline::FastWorkspace` with `Config::new()`:
    /// meshoptimizer's pipeline with every output valid (`tinydecimate simplify --engine fast`).
    Fast,
    /// tinydecimate's lean mode, `pipeline::LeanWorkspace` with `Config::new()`: the fast
    /// mode's pipeline without stored quadrics (`tinydecimate simplify --engine lean`).
    Lean,
    /// The fast mode in integers, `FastWorkspace<_, _, _, Integer>` with `Config::new()`, on
    /// the mesh put on its 15-bit grid (`tinydecimate simplify --integer`): the output's
    /// vertices are grid positions.
    FastInteger,
    /// The lean mode in integers, as [`Method::FastInteger`].
    LeanInteger,
}

impl Method {
    /// All of them, in table order.
    pub const ALL: [Method; 14] = [
        Method::Default,
        Method::GreedyW,
        Method::Paper,
        Method::Meshopt,
        Method::Stored,
        Method::StoredOptimal,
        Method::MeshoptUpdate,
        Method::VertexDecimation,
        Method::Energy,
        Method::Batched,
        Method::Fast,
        Method::Lean,
        Method::FastInteger,
        Method::LeanInteger,
    ];

    /// The operator of our modes.
    pub fn operator(self) -> crate::simplify::OperatorArg {
        match self {
            Method::VertexDecimation => crate::simplify::OperatorArg::VertexDecimation,
            _ => crate::simplify::OperatorArg::Edge,
        }
    }

    /// Stored-quadric placement of our stored modes.
    pub fn placement(self) -> Option<tinydecimate::cost::Placement> {
        use tinydecimate::cost::Placement;
        match self {
            Method::Stored => Some(Placement::Subset),
            Method::StoredOptimal => Some(Placement::Optimal),
            _ => None,
        }
    }

    /// Whether the output's positions may differ from the input's.
    pub fn moves(self) -> bool {
        matches!(self, Method::StoredOptimal | Method::MeshoptUpdate)
    }

    /// Whether the pipeline runs in integers.
    pub fn integer(self) -> bool {
        matches!(self, Method::FastInteger | Method::LeanInteger)
    }

    /// The float mode of an integer one.
    pub fn float(self) -> Method {
        match self {
            Method::FastInteger => Method::Fast,
            Method::LeanInteger => Method::Lean,
            m => m,
        }
    }

    /// Name in the tables.
    pub fn label(self) -> &'static str {
        match self {
            Method::Default => "default (greedy quadric)",
            Method::GreedyW => "greedy W",
            Method::Paper => "paper passes",
            Method::Meshopt => "meshoptimizer",
            Method::Stored => "stored quadric, subset",
            Method::StoredOptimal => "stored quadric, optimal",
            Method::MeshoptUpdate => "meshoptimizer simplifyWithUpdate",
            Method::VertexDecimation => "vertex decimation",
            Method::Energy => "Hoppe's energy",
            Method::Batched => "batched quadric",
            Method::Fast => "fast mode",
            Method::Lean => "lean mode",
            Method::FastInteger => "fast mode, integer",
            Method::LeanInteger => "lean mode, integer",
        }
    }

    /// The library configuration (before the ratio); `None` for meshoptimizer.
    pub fn config(self) -> Option<Config> {
        match self {
            Method::Default
            | Method::VertexDecimation
            | Method::Energy
            | Method::Fast
            | Method::Lean
            | Method::FastInteger
            | Method::LeanInteger => Some(Config::new()),
            Method::GreedyW => Some(Config::new().with_cost(CostKind::NormalVariation)),
            Method::Paper => Some(Config::paper()),
            Method::Stored | Method::StoredOptimal => Some(Config::stored()),
            Method::Batched => Some(Config::new().with_schedule(tinydecimate::Schedule::Batched)),
            Method::Meshopt | Method::MeshoptUpdate => None,
        }
    }

    /// The configuration as written in the tables.
    pub fn config_text(self) -> &'static str {
        match self {
            Method::Default => "`Config::new()`",
            Method::GreedyW => "`Config::new().with_cost(CostKind::NormalVariation)`",
            Method::Paper => "`Config::paper()`",
            Method::Meshopt => "`meshopt::simplify`",
            Method::Stored => "`StoredQuadric` (subset placement) with `Config::stored()`",
            Method::StoredOptimal => "`StoredQuadric` (optimal placement) with `Config::stored()`",
            Method::MeshoptUpdate => "`meshopt::simplify_with_update`",
            Method::VertexDecimation => "`VertexDecimation::new()` with `Config::new()`",
            Method::Energy => "`Energy` (κ = 0.01) with `Config::new()`",
            Method::Batched => "`Config::new().with_schedule(Schedule::Batched)`",
            Method::Fast => "`pipeline::FastWorkspace` with `Config::new()`",
            Method::Lean => "`pipeline::LeanWorkspace` with `Config::new()`",
            Method::FastInteger => {
                "`pipeline::FastWorkspace<_, _, _, Integer>` with `Config::new()` on the mesh \
                 put on its grid by `pipeline::quantise`"
            }
            Method::LeanInteger => {
                "`pipeline::LeanWorkspace<_, _, _, Integer>` with `Config::new()`, as the fast \
                 mode's"
            }
        }
    }

    /// The library's pipeline mode of the fast and the lean mode; `None` for the others.
    pub fn pipeline(self) -> Option<crate::simplify::Pipeline> {
        match self {
            Method::Fast | Method::FastInteger => Some(crate::simplify::Pipeline::Fast),
            Method::Lean | Method::LeanInteger => Some(crate::simplify::Pipeline::Lean),
            _ => None,
        }
    }

    /// Whether this is one of ours.
    pub fn is_ours(self) -> bool {
        !matches!(self, Method::Meshopt | Method::MeshoptUpdate)
    }
}

/// Refused candidate collapses by rule (the library's `Report::rejected`); serialized as
/// `{"total": n, "<rule>": n, ..}` with the rules' names in the order of `tinydecimate::RULES`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Rejected(pub Rejections);

impl Serialize for Rejected {
    fn serialize<S: serde::Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        use serde::ser::SerializeMap;
        let mut m = s.serialize_map(Some(1 + tinydecimate::RULES.len()))?;
        m.serialize_entry("total", &self.0.total())?;
        for (rule, n) in self.0.iter() {
            m.serialize_entry(rule.name, &n)?;
        }
        m.end()
    }
}

impl Rejected {
    fn of(r: &Report) -> Self {
        Rejected(r.rejected)
    }

    /// The non-zero counts, largest first (`"boundary 18034, locked 8112"`).
    pub fn text(&self) -> String {
        let mut v: Vec<(&str, u32)> = self.0.iter().map(|(rule, n)| (rule.name, n)).collect();
        v.sort_by_key(|x| std::cmp::Reverse(x.1));
        let parts: Vec<String> = v
            .iter()
            .filter(|x| x.1 > 0)
            .map(|(n, c)| format!("{n} {c}"))
            .collect();
        if parts.is_empty() {
            "none".into()
        } else {
            parts.join(", ")
        }
    }
}

/// Where and why one of the library's runs stopped (from its `Report`).
#[derive(Clone, Debug, Serialize)]
pub struct Stopped {
    /// `Report::stop`.
    pub stop: String,
    /// Collapses performed.
    pub collapses: usize,
    /// Vertices locked as non-manifold.
    pub locked_vertices: usize,
    /// Feature vertices at the last classification.
    pub feature_vertices: usize,
    /// Passes (greedy: rounds of the queue).
    pub passes: u32,
    /// Parts removed whole (`--parts prune`).
    pub parts_removed: usize,
    /// Refused candidates by reason.
    pub rejected: Rejected,
}

impl Stopped {
    fn of(r: &Report) -> Self {
        Stopped {
            stop: format!("{:?}", r.stop),
            collapses: r.collapses,
            locked_vertices: r.locked_vertices,
            feature_vertices: r.feature_vertices,
            passes: r.passes,
            parts_removed: r.parts_removed,
            rejected: Rejected::of(r),
        }
    }
}

/// meshoptimizer run with the triangle count one of our modes reached as its target.
#[derive(Clone, Debug, Serialize)]
pub struct SameCount {
    /// Target given to meshoptimizer: our `triangles_out`.
    pub target_triangles: usize,
    /// Triangles meshoptimizer left.
    pub triangles_out: usize,
    /// Median wall time, milliseconds.
    pub median_ms: f64,
    /// Metro symmetric mean distance, % of the input's bbox diagonal.
    pub metro_mean_pct: f64,
    /// Metro symmetric Hausdorff distance, % of the input's bbox diagonal.
    pub metro_max_pct: f64,
    /// Whether meshoptimizer's result is a valid simplification.
    pub valid: bool,
    /// Its defect counts.
    pub validity: Validity,
    /// Our mean error over meshoptimizer's at this count.
    pub mean_vs_meshopt: f64,
    /// Our maximum error over meshoptimizer's at this count.
    pub max_vs_meshopt: f64,
}

/// One simplifier on one mesh at one ratio.
#[derive(Clone, Debug, Serialize)]
pub struct Row {
    /// Mesh file name.
    pub mesh: String,
    /// Input positions (unreferenced ones included).
    pub vertices: usize,
    /// Input triangles.
    pub triangles_in: usize,
    /// Target ratio.
    pub ratio: f32,
    /// Simplifier.
    pub method: Method,
    /// Target triangle count: `⌊ratio · T⌋`.
    pub target_triangles: usize,
    /// Triangles in the result.
    pub triangles_out: usize,
    /// Whether `triangles_out <= target_triangles`.
    pub target_reached: bool,
    /// Why tinydecimate stopped (its `Report::stop`); `None` for meshoptimizer.
    pub stop: Option<String>,
    /// The rest of tinydecimate's report on where it stopped; `None` for meshoptimizer.
    pub report: Option<Stopped>,
    /// Wall time of every repetition, milliseconds.
    pub times_ms: Vec<f64>,
    /// Median of `times_ms`.
    pub median_ms: f64,
    /// `median_ms` over meshoptimizer's on the same mesh and ratio.
    pub time_vs_meshopt: f64,
    /// Scratch memory: tinydecimate's right-sized workspace, meshoptimizer's peak allocation.
    pub scratch_bytes: usize,
    /// `scratch_bytes / triangles_in`.
    pub scratch_bytes_per_triangle: f64,
    /// Metro symmetric mean distance, % of the input's bbox diagonal.
    pub metro_mean_pct: f64,
    /// Metro symmetric Hausdorff distance, % of the input's bbox diagonal.
    pub metro_max_pct: f64,
    /// `metro_mean_pct` over meshoptimizer's on the same mesh and ratio (same target).
    pub mean_vs_meshopt: f64,
    /// `metro_max_pct` over meshoptimizer's on the same mesh and ratio (same target).
    pub max_vs_meshopt: f64,
    /// Whether the result is a valid simplification ([`Validity::is_valid`]).
    pub valid: bool,
    /// The defect counts.
    pub validity: Validity,
    /// Ours only, when the target was not reached: meshoptimizer at our triangle count.
    pub same_count: Option<SameCount>,
    /// An integer mode only: its float mode on the same grid mesh, Metro mean and Hausdorff
    /// distance (% of the diagonal, against the input), the arithmetic's own share of the
    /// difference.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub float_on_grid: Option<[f64; 2]>,
    /// An integer mode only: its float mode on the grid mesh mirrored (x negated, winding
    /// reversed; the output mirrored back, all exact), the same figures: how far the float path
    /// itself moves when only its rounding changes, the floor of a row's comparison.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub float_mirrored: Option<[f64; 2]>,
}

impl Row {
    /// The fair mean-error ratio: against meshoptimizer at our triangle count if we stopped
    /// short, else at the same target.
    pub fn fair_mean_vs_meshopt(&self) -> f64 {
        self.same_count
            .as_ref()
            .map_or(self.mean_vs_meshopt, |s| s.mean_vs_meshopt)
    }

    /// The fair maximum-error ratio (see [`Row::fair_mean_vs_meshopt`]).
    pub fn fair_max_vs_meshopt(&self) -> f64 {
        self.same_count
            .as_ref()
            .map_or(self.max_vs_meshopt, |s| s.max_vs_meshopt)
    }
}

/// The worst (largest) fair error ratios vs meshoptimizer over some meshes
/// ([`Row::fair_mean_vs_meshopt`], [`Row::fair_max_vs_meshopt`]).
#[derive(Clone, Debug, Serialize)]
pub struct WorstPair {
    /// Largest mean-error ratio.
    pub mean_vs_meshopt: f64,
    /// The mesh it was measured on.
    pub mean_mesh: String,
    /// Whether that figure is at the same triangle count (the mode stopped short there).
    pub mean_same_count: bool,
    /// Largest maximum-error ratio.
    pub max_vs_meshopt: f64,
    /// The mesh it was measured on.
    pub max_mesh: String,
    /// Whether that figure is at the same triangle count.
    pub max_same_count: bool,
}

impl WorstPair {
    fn of(rows: &[&Row]) -> Option<Self> {
        let wm = worst_by(rows, Row::fair_mean_vs_meshopt)?;
        let wx = worst_by(rows, Row::fair_max_vs_meshopt)?;
        Some(WorstPair {
            mean_vs_meshopt: wm.fair_mean_vs_meshopt(),
            mean_mesh: wm.mesh.clone(),
            mean_same_count: wm.same_count.is_some(),
            max_vs_meshopt: wx.fair_max_vs_meshopt(),
            max_mesh: wx.mesh.clone(),
            max_same_count: wx.same_count.is_some(),
        })
    }
}

/// The worst error ratios of one mode at one ratio: over the clean meshes and over the messy
/// ones ([`MESSY_MESHES`]), which are held to different targets.
#[derive(Clone, Debug, Serialize)]
pub struct Worst {
    /// Target ratio.
    pub ratio: f32,
    /// Over every mesh not in [`MESSY_MESHES`] (`None`: none ran).
    pub clean: Option<WorstPair>,
    /// Over the meshes in [`MESSY_MESHES`] (`None`: none ran).
    pub messy: Option<WorstPair>,
    /// Over the meshes in [`REAL_WORLD_MESHES`] (`None`: none ran).
    pub real_world: Option<WorstPair>,
}

/// One mode over the whole run.
#[derive(Clone, Debug, Serialize)]
pub struct ModeSummary {
    /// Simplifier.
    pub method: Method,
    /// Runs (meshes × ratios).
    pub runs: usize,
    /// Valid results.
    pub valid: usize,
    /// Runs that reached the target.
    pub target_reached: usize,
    /// Geometric mean of `time_vs_meshopt` over every mesh at [`Summary::time_ratios`].
    pub time_vs_meshopt_geomean: f64,
    /// Smallest and largest scratch bytes per input triangle over the meshes.
    pub scratch_bytes_per_triangle: (f64, f64),
    /// Per ratio, the worst error ratios (ours only; empty for meshoptimizer).
    pub worst: Vec<Worst>,
    /// Over every run of this mode, against meshoptimizer at the same count (ours only).
    pub overall: Option<Overall>,
}

/// A mode's error against meshoptimizer over every mesh and ratio of the run: geometric means
/// of the Metro mean and max ratios (the same-count ones where the mode stopped short), and
/// the worst of each.
#[derive(Clone, Debug, Serialize)]
pub struct Overall {
    /// Geometric mean of the mean-error ratios.
    pub mean_geomean: f64,
    /// Geometric mean of the max-error (Hausdorff) ratios.
    pub max_geomean: f64,
    /// The worst mean and max ratios, with their meshes and ratios.
    pub worst: WorstPair,
    /// The ratios of the worst mean and max rows.
    pub worst_at: (f32, f32),
}

/// The summary rows.
#[derive(Clone, Debug, Serialize)]
pub struct Summary {
    /// The ratios the time geometric mean is taken over ([`TIME_RATIOS`] that were run, or
    /// every ratio run if none of them was).
    pub time_ratios: Vec<f32>,
    /// Per mode, in table order.
    pub modes: Vec<ModeSummary>,
    /// meshoptimizer's runs at the library's triangle counts.
    pub same_count_runs: usize,
    /// Of those, valid results.
    pub same_count_valid: usize,
}

/// A whole benchmark.
#[derive(Clone, Debug, Serialize)]
pub struct Results {
    /// The command line.
    pub command: String,
    /// Machine and build description.
    pub machine: String,
    /// The meshoptimizer library version.
    pub meshoptimizer_version: String,
    /// The `meshopt` crate version.
    pub meshopt_crate_version: String,
    /// The mesh directories, comma separated (relative to the repository when inside it).
    pub meshes: String,
    /// Target ratios.
    pub ratios: Vec<f32>,
    /// Repetitions per run.
    pub reps: usize,
    /// Metro face samples per triangle.
    pub samples_per_triangle: f64,
    /// The summary rows.
    pub summary: Summary,
    /// Every run, by mesh (smallest first), ratio, then method.
    pub rows: Vec<Row>,
}

// ---------------------------------------------------------------------------------------------
// The benchmark

/// The median of `xs` (the mean of the middle two of an even count; NaN when empty).
pub fn median(xs: &[f64]) -> f64 {
    let mut v = xs.to_vec();
    v.sort_by(f64::total_cmp);
    match v.len() {
        0 => f64::NAN,
        n if n % 2 == 1 => v[n / 2],
        n => (v[n / 2 - 1] + v[n / 2]) / 2.0,
    }
}

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

/// The mesh files to run: every mesh in the directory (or the named ones), loaded, smallest
/// first.
fn load_meshes(opts: &Options) -> Result<Vec<(String, MeshData)>> {
    let dirs: Vec<&PathBuf> = std::iter::once(&opts.meshes).chain(&opts.more).collect();
    let mut files: Vec<(String, PathBuf)> = Vec::new();
    match &opts.only {
        Some(names) => {
            for name in names {
                let dir = dirs
                    .iter()
                    .find(|d| d.join(name).is_file())
                    .unwrap_or(&dirs[0]);
                files.push((name.clone(), dir.join(name)));
            }
        }
        None => {
            for dir in &dirs {
                let entries = std::fs::read_dir(dir)
                    .with_context(|| format!("{}: cannot list", dir.display()))?;
                for entry in entries {
                    let name = entry?.file_name().to_string_lossy().into_owned();
                    if is_mesh_file(&name) {
                        files.push((name.clone(), dir.join(name)));
                    }
                }
            }
        }
    }
    if files.is_empty() {
        bail!(
            "{}: no .obj, .ply, .stl or glTF meshes",
            opts.meshes.display()
        );
    }
    let mut meshes = Vec::new();
    for (name, path) in files {
        let mesh = crate::io::load(path)?;
        meshes.push((name, mesh));
    }
    meshes.sort_by(|a, b| (a.1.triangles.len(), &a.0).cmp(&(b.1.triangles.len(), &b.0)));
    Ok(meshes)
}

/// A one-line description of this machine and build.
pub fn machine() -> String {
    let cpu = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split(':').nth(1))
                .map(|m| m.trim().to_string())
        })
        .unwrap_or_else(|| "unknown CPU".into());
    let threads = std::thread::available_parallelism().map_or(0, |n| n.get());
    let profile = if cfg!(debug_assertions) {
        "debug build (timings meaningless)"
    } else {
        "release build"
    };
    format!(
        "{} {}, {cpu}, {threads} hardware threads, {profile}; the simplifiers run single-threaded",
        std::env::consts::OS,
        std::env::consts::ARCH
    )
}

/// One simplifier run `reps` times: the last result, every wall time, scratch bytes and (ours)
/// the report.
struct Run {
    out: MeshData,
    times_ms: Vec<f64>,
    scratch: usize,
    report: Option<Report>,
}

fn run_method(
    mesh: &MeshData,
    method: Method,
    ratio: f32,
    target: usize,
    reps: usize,
    prune: bool,
) -> Result<Run> {
    let (v, t) = (mesh.positions.len(), mesh.triangles.len());
    let mut times_ms = Vec::with_capacity(reps);
    let mut last = None;
    for _ in 0..reps {
        let (out, elapsed, scratch, report) = match (method.config(), method.placement()) {
            (Some(config), placement) => {
                // Seams welded (`tinydecimate simplify`'s default), when the mesh has any.
                let run = crate::simplify::Run {
                    operator: method.operator(),
                    placement,
                    weld: true,
                    prune,
                    energy: (method == Method::Energy).then_some(tinydecimate::cost::Energy::KAPPA),
                    pipeline: method.pipeline(),
                    integer: method.integer(),
                    ..Default::default()
                };
                // The error limit measures a collapse or a removal (not a triangle collapse).
                let config = if method.operator() != crate::simplify::OperatorArg::Triangle {
                    with_default_limit(config.with_ratio(ratio), mesh)
                } else {
                    config.with_ratio(ratio)
                };
                let (out, report, elapsed) = crate::simplify::simplify_with(mesh, &config, &run)?;
                // Stored quadrics, or the energy's sample moments: 40 B per vertex either way.
                let quadrics = if placement.is_some() || method == Method::Energy {
                    v * crate::workspace::QUADRIC_BYTES
                } else {
                    0
                };
                // Vertex decimation runs without wedges and parts (`simplify_with`).
                let edge = method.operator() == crate::simplify::OperatorArg::Edge;
                let bytes = match method.pipeline() {
                    Some(mode) => crate::simplify::pipeline_bytes(mode, v, t),
                    None => {
                        workspace_bytes(v, t).0
                            + quadrics
                            + if edge { wedge_bytes(mesh) } else { 0 }
                            + part_bytes(v, &config, prune && edge)
                    }
                };
                (out, elapsed, bytes, Some(report))
            }
            (None, _) => {
                let (out, elapsed, peak) = if method == Method::MeshoptUpdate {
                    meshopt_simplify_with_update(mesh, target)
                } else {
                    meshopt_simplify(mesh, target)
                };
                (out, elapsed, peak, None)
            }
        };
        times_ms.push(ms(elapsed));
        last = Some((out, scratch, report));
    }
    let (out, scratch, report) = last.context("--reps must be at least 1")?;
    Ok(Run {
        out,
        times_ms,
        scratch,
        report,
    })
}

/// `config` with `tinydecimate simplify`'s default error limit where it applies (the greedy
/// schedule).
fn with_default_limit(config: Config, mesh: &MeshData) -> Config {
    if config.schedule().is_ordered() {
        config.with_relative_error_limit(
            tinydecimate_cli::cmd::simplify::DEFAULT_ERROR_LIMIT,
            &mesh.positions,
        )
    } else {
        config
    }
}

/// `mesh` welded by position (`meshcheck::weld`: each corner renumbered to the first vertex at
/// its position), with only the vertices its triangles use, if it has vertices at a shared
/// position; `None` if welding changes nothing. (meshoptimizer finds wedges through every
/// vertex at a position, used or not, so the welded-away vertices must go too.)
fn anchor(mesh: &MeshData) -> Option<MeshData> {
    let welded = meshcheck::weld(&mesh.positions, &mesh.triangles);
    if welded == mesh.triangles {
        return None;
    }
    let mut new_index = vec![u32::MAX; mesh.positions.len()];
    let mut positions = Vec::new();
    let triangles = welded
        .iter()
        .map(|t| {
            t.map(|v| {
                let slot = &mut new_index[v as usize];
                if *slot == u32::MAX {
                    *slot = positions.len() as u32;
                    positions.push(mesh.positions[v as usize]);
                }
                *slot
            })
        })
        .collect();
    Some(MeshData {
        positions,
        triangles,
    })
}

/// Bytes of the wedge copy a welded run keeps (`tinydecimate::seam`): three indices per
/// triangle (`u16` below 65 536 vertices), when the mesh has vertices at a shared position;
/// 0 otherwise (nothing is welded). The sort's scratch is one link per vertex, which the
/// caller's workspace links can lend before the run, so it is not counted.
fn wedge_bytes(mesh: &MeshData) -> usize {
    let mut seen = std::collections::HashSet::new();
    let shared = mesh
        .positions
        .iter()
        .any(|p| !seen.insert(p.map(|x| if x == 0.0 { 0 } else { x.to_bits() })));
    if !shared {
        return 0;
    }
    let index = if mesh.positions.len() <= 65_535 { 2 } else { 4 };
    3 * index * mesh.triangles.len()
}

/// Bytes of the part links a pruning run keeps (`Simplifier::with_parts`): two links per
/// vertex (`u16` below 65 536 vertices), when the mode prunes.
fn part_bytes(vertices: usize, config: &tinydecimate::Config, prune: bool) -> usize {
    if !crate::simplify::prunes(prune, config, false) {
        return 0;
    }
    let link = if vertices <= 65_535 { 2 } else { 4 };
    2 * link * vertices
}

/// Runs the benchmark. `command` is recorded as given.
pub fn bench(opts: &Options, command: &str) -> Result<Results> {
    if opts.reps == 0 {
        bail!("--reps must be at least 1");
    }
    if let Some(r) = opts.ratios.iter().find(|r| !(**r >= 0.0 && **r <= 1.0)) {
        bail!("ratio {r} is not in [0, 1]");
    }
    if !(opts.samples_per_triangle.is_finite() && opts.samples_per_triangle > 0.0) {
        bail!("--samples-per-triangle must be a positive number");
    }
    let meshes = load_meshes(opts)?;
    let methods: Vec<Method> = Method::ALL
        .into_iter()
        .filter(|m| match (m, &opts.modes) {
            (_, None) | (Method::Meshopt, _) => true,
            // The reference of the modes that move vertices.
            (Method::MeshoptUpdate, Some(x)) => x.contains(&Method::StoredOptimal),
            (m, Some(x)) => x.contains(m),
        })
        .collect();
    let steps = (meshes.len() * opts.ratios.len() * methods.len()) as u64;
    let bar = if opts.progress && std::io::stderr().is_terminal() {
        let bar = ProgressBar::with_draw_target(Some(steps), ProgressDrawTarget::stderr());
        if let Ok(style) = ProgressStyle::with_template("bench {bar:30} {pos}/{len} {msg}") {
            bar.set_style(style);
        }
        bar
    } else {
        ProgressBar::hidden()
    };
    let metro_opts = MetroOptions {
        samples_per_triangle: opts.samples_per_triangle,
        ..Default::default()
    };

    let mut rows = Vec::new();
    for (name, mesh) in &meshes {
        let (v, t) = (mesh.positions.len(), mesh.triangles.len());
        // meshoptimizer is given the surface ours simplifies: ours welds vertices at one
        // position (`--seams weld`), so on a seam-split mesh meshoptimizer runs on the mesh
        // welded by position too. On the split mesh its kinds table locks every position with
        // more than two wedges (a flat-shaded model keeps nearly all its triangles at any
        // target), which would make its error an anchor of a run that did not simplify.
        let welded = anchor(mesh);
        let welded = welded.as_ref().unwrap_or(mesh);
        for &ratio in &opts.ratios {
            let target = (ratio as f64 * t as f64) as usize;
            let first = rows.len();
            for &method in &methods {
                bar.set_message(format!("{name} {ratio} {}", method.label()));
                let ours = method.is_ours();
                // An integer mode's input is the mesh on its grid (its output's vertices are
                // the grid's): it is checked against that, and its float mode runs on it too.
                let grid = method.integer().then(|| on_grid(mesh)).transpose()?;
                let input = match &grid {
                    Some(g) => g,
                    None if ours => mesh,
                    None => welded,
                };
                let run = run_method(input, method, ratio, target, opts.reps, opts.prune)
                    .with_context(|| format!("{name} at {ratio}, {}", method.label()))?;
                let (float_on_grid, float_mirrored) = match &grid {
                    Some(g) => {
                        let f = run_method(g, method.float(), ratio, target, 1, opts.prune)?;
                        let m = metro(mesh, &f.out, &metro_opts);
                        let fm =
                            run_method(&mirror(g), method.float(), ratio, target, 1, opts.prune)?;
                        let mm = metro(mesh, &mirror(&fm.out), &metro_opts);
                        (
                            Some([m.symmetric_mean_pct, m.hausdorff_pct]),
                            Some([mm.symmetric_mean_pct, mm.hausdorff_pct]),
                        )
                    }
                    None => (None, None),
                };
                // Ours welded seams: checked welded (no crack), as `tinydecimate simplify` does.
                // Ours may prune parts: a part gone whole is allowed, one cut in part is not.
                let validity = crate::check::compare_parts(
                    input,
                    &run.out,
                    method.moves(),
                    ours,
                    ours && opts.prune,
                );
                let m = metro(mesh, &run.out, &metro_opts);
                let triangles_out = run.out.triangles.len();
                rows.push(Row {
                    mesh: name.clone(),
                    vertices: v,
                    triangles_in: t,
                    ratio,
                    method,
                    target_triangles: target,
                    triangles_out,
                    target_reached: triangles_out <= target,
                    stop: run.report.as_ref().map(|r| format!("{:?}", r.stop)),
                    report: run.report.as_ref().map(Stopped::of),
                    median_ms: median(&run.times_ms),
                    times_ms: run.times_ms,
                    time_vs_meshopt: f64::NAN,
                    scratch_bytes: run.scratch,
                    scratch_bytes_per_triangle: run.scratch as f64 / t.max(1) as f64,
                    metro_mean_pct: m.symmetric_mean_pct,
                    metro_max_pct: m.hausdorff_pct,
                    mean_vs_meshopt: f64::NAN,
                    max_vs_meshopt: f64::NAN,
                    valid: validity.is_valid(),
                    validity,
                    same_count: None,
                    float_on_grid,
                    float_mirrored,
                });
                bar.inc(1);
            }
            let Some(reference) = rows[first..]
                .iter()
                .find(|r| r.method == Method::Meshopt)
                .cloned()
            else {
                continue;
            };
            for r in &mut rows[first..] {
                r.time_vs_meshopt = r.median_ms / reference.median_ms;
                r.mean_vs_meshopt = r.metro_mean_pct / reference.metro_mean_pct;
                r.max_vs_meshopt = r.metro_max_pct / reference.metro_max_pct;
            }
            // Stopped short: meshoptimizer again, down to the count the library reached.
            for r in &mut rows[first..] {
                if !r.method.is_ours() || r.target_reached {
                    continue;
                }
                bar.inc_length(1);
                bar.set_message(format!(
                    "{name} {ratio} meshoptimizer at {} triangles",
                    r.triangles_out
                ));
                let run = run_method(
                    welded,
                    Method::Meshopt,
                    ratio,
                    r.triangles_out,
                    opts.reps,
                    opts.prune,
                )?;
                let validity = compare(welded, &run.out);
                let m = metro(mesh, &run.out, &metro_opts);
                r.same_count = Some(SameCount {
                    target_triangles: r.triangles_out,
                    triangles_out: run.out.triangles.len(),
                    median_ms: median(&run.times_ms),
                    metro_mean_pct: m.symmetric_mean_pct,
                    metro_max_pct: m.hausdorff_pct,
                    valid: validity.is_valid(),
                    validity,
                    mean_vs_meshopt: r.metro_mean_pct / m.symmetric_mean_pct,
                    max_vs_meshopt: r.metro_max_pct / m.hausdorff_pct,
                });
                bar.inc(1);
            }
        }
    }
    bar.finish_and_clear();
    Ok(Results {
        command: command.to_string(),
        machine: machine(),
        meshoptimizer_version: MESHOPTIMIZER_VERSION.into(),
        meshopt_crate_version: MESHOPT_CRATE_VERSION.into(),
        meshes: {
            // Relative to the repository where it is inside it: the report names no machine's path.
            let root = std::fs::canonicalize(crate::repo_root()).unwrap_or_default();
            let shown = |dir: &PathBuf| {
                let abs = std::fs::canonicalize(dir).unwrap_or_else(|_| dir.clone());
                abs.strip_prefix(&root)
                    .unwrap_or(&abs)
                    .display()
                    .to_string()
            };
            std::iter::once(&opts.meshes)
                .chain(&opts.more)
                .map(shown)
                .collect::<Vec<_>>()
                .join(", ")
        },
        ratios: opts.ratios.clone(),
        reps: opts.reps,
        samples_per_triangle: opts.samples_per_triangle,
        summary: summarise(&rows, &opts.ratios),
        rows,
    })
}

/// `mesh` with its positions put on the integer pipeline's grid (`pipeline::quantise`), as
/// `f32`: exact, and quantised again the same grid.
fn on_grid(mesh: &MeshData) -> Result<MeshData> {
    let mut grid = vec![[0u16; 3]; mesh.positions.len()];
    let frame = tinydecimate::pipeline::quantise(&mesh.positions, &mut grid)
        .map_err(|e| anyhow::anyhow!("{e}"))?;
    Ok(MeshData {
        positions: grid.iter().map(|&q| frame.position(q)).collect(),
        triangles: mesh.triangles.clone(),
    })
}

/// `mesh` mirrored in x, its triangles' winding reversed so that they face as before: the same
/// surface, exactly (negation is exact), in other floats. Its own inverse.
fn mirror(mesh: &MeshData) -> MeshData {
    MeshData {
        positions: mesh.positions.iter().map(|&[x, y, z]| [-x, y, z]).collect(),
        triangles: mesh.triangles.iter().map(|&[a, b, c]| [a, c, b]).collect(),
    }
}

/// Geometric mean of the finite, positive values (NaN if there are none).
fn geomean(xs: impl Iterator<Item = f64>) -> f64 {
    let (mut sum, mut n) = (0.0, 0usize);
    for x in xs.filter(|x| x.is_finite() && *x > 0.0) {
        sum += x.ln();
        n += 1;
    }
    if n == 0 {
        f64::NAN
    } else {
        (sum / n as f64).exp()
    }
}

/// The row with the largest `key` (NaN counts as largest: a missing figure is not hidden).
fn worst_by<'a>(rows: &[&'a Row], key: impl Fn(&Row) -> f64) -> Option<&'a Row> {
    rows.iter().copied().max_by(|a, b| {
        let (x, y) = (key(a), key(b));
        match (x.is_nan(), y.is_nan()) {
            (true, true) => std::cmp::Ordering::Equal,
            (true, false) => std::cmp::Ordering::Greater,
            (false, true) => std::cmp::Ordering::Less,
            _ => x.total_cmp(&y),
        }
    })
}

/// The summary of a run's rows.
pub fn summarise(rows: &[Row], ratios: &[f32]) -> Summary {
    let mut time_ratios: Vec<f32> = TIME_RATIOS
        .iter()
        .copied()
        .filter(|r| ratios.contains(r))
        .collect();
    if time_ratios.is_empty() {
        time_ratios = ratios.to_vec();
    }
    let mut modes = Vec::new();
    for method in Method::ALL {
        let mine: Vec<&Row> = rows.iter().filter(|x| x.method == method).collect();
        if mine.is_empty() {
            continue;
        }
        let bpt = mine.iter().map(|x| x.scratch_bytes_per_triangle);
        let mut worst = Vec::new();
        if method.is_ours() {
            for &ratio in ratios {
                let at: Vec<&Row> = mine.iter().copied().filter(|x| x.ratio == ratio).collect();
                let of = |f: &dyn Fn(&str) -> bool| {
                    let rows: Vec<&Row> = at.iter().copied().filter(|x| f(&x.mesh)).collect();
                    WorstPair::of(&rows)
                };
                worst.push(Worst {
                    ratio,
                    clean: of(&|m| !is_messy(m) && !is_real_world(m)),
                    messy: of(&is_messy),
                    real_world: of(&is_real_world),
                });
            }
        }
        let all: Vec<&Row> = mine.clone();
        let overall = if method.is_ours() {
            WorstPair::of(&all).map(|w| Overall {
                mean_geomean: geomean(all.iter().map(|x| x.fair_mean_vs_meshopt())),
                max_geomean: geomean(all.iter().map(|x| x.fair_max_vs_meshopt())),
                worst_at: (
                    worst_by(&all, Row::fair_mean_vs_meshopt).map_or(0.0, |x| x.ratio),
                    worst_by(&all, Row::fair_max_vs_meshopt).map_or(0.0, |x| x.ratio),
                ),
                worst: w,
            })
        } else {
            None
        };
        modes.push(ModeSummary {
            overall,
            method,
            runs: mine.len(),
            valid: mine.iter().filter(|x| x.valid).count(),
            target_reached: mine.iter().filter(|x| x.target_reached).count(),
            time_vs_meshopt_geomean: geomean(
                mine.iter()
                    .filter(|x| time_ratios.contains(&x.ratio))
                    .map(|x| x.time_vs_meshopt),
            ),
            scratch_bytes_per_triangle: (
                bpt.clone().fold(f64::INFINITY, f64::min),
                bpt.fold(f64::NEG_INFINITY, f64::max),
            ),
            worst,
        });
    }
    let same: Vec<&SameCount> = rows.iter().filter_map(|x| x.same_count.as_ref()).collect();
    Summary {
        time_ratios,
        modes,
        same_count_runs: same.len(),
        same_count_valid: same.iter().filter(|s| s.valid).count(),
    }
}

// ---------------------------------------------------------------------------------------------
// Output

#[cfg(test)]
mod tests {
    use super::markdown::{markdown, verdict};
    use super::*;
    use crate::cmd::bench::Args;
    use clap::Parser;

    #[derive(Parser)]
    struct Cli {
        #[command(flatten)]
        args: Args,
    }

    #[test]
    fn arguments() {
        let c = Cli::try_parse_from(["x"]).unwrap();
        let (o, md, js) = c.args.options();
        assert_eq!((o.ratios, o.reps, o.only), (vec![0.5, 0.25, 0.1], 5, None));
        assert_eq!(md, Some(PathBuf::from("bench/RESULTS.md")));
        assert_eq!(js, Some(PathBuf::from("bench/results.json")));
        let c = Cli::try_parse_from(["x", "--quick", "--ratios", "0.3,0.2"]).unwrap();
        let (o, md, js) = c.args.options();
        assert_eq!((o.ratios, o.reps), (vec![0.3, 0.2], 1));
        assert_eq!(o.meshes, default_meshes());
        assert_eq!((md, js), (None, None));
        let c =
            Cli::try_parse_from(["x", "--only", "wuson.obj,cow.obj", "--ratios", "0.1"]).unwrap();
        let (o, md, js) = c.args.options();
        assert_eq!(
            o.only,
            Some(vec!["wuson.obj".to_string(), "cow.obj".to_string()])
        );
        assert_eq!((o.ratios, o.reps), (vec![0.1], 5));
        assert_eq!((md, js), (None, None));
        // The bench's own meshes join the default directory only.
        assert_eq!(o.more, Some(bench_meshes()));
        let c = Cli::try_parse_from(["x", "--meshes", "elsewhere"]).unwrap();
        assert_eq!(c.args.options().0.more, None);
    }

    /// Both directories are listed, glTF files included and other files left out, and a name
    /// asked for by `--only` is found in the second directory.
    #[test]
    fn meshes_come_from_both_directories() {
        let (one, two) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
        let tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
        std::fs::write(one.path().join("a.obj"), tri).unwrap();
        std::fs::write(one.path().join("notes.txt"), "not a mesh").unwrap();
        std::fs::copy(
            default_meshes().join("CesiumMilkTruck.glb"),
            two.path().join("truck.glb"),
        )
        .unwrap();
        let mut opts = Options {
            meshes: one.path().into(),
            more: Some(two.path().into()),
            only: None,
            ratios: vec![0.5],
            reps: 1,
            samples_per_triangle: 1.0,
            progress: false,
            prune: true,
            modes: None,
        };
        let names = |o: &Options| {
            load_meshes(o)
                .unwrap()
                .into_iter()
                .map(|(n, m)| (n, m.triangles.len()))
                .collect::<Vec<_>>()
        };
        let truck = ("truck.glb".to_string(), 2856);
        assert_eq!(names(&opts), vec![("a.obj".to_string(), 1), truck.clone()]);
        opts.only = Some(vec!["truck.glb".into()]);
        assert_eq!(names(&opts), vec![truck]);
        opts.more = None;
        assert!(load_meshes(&opts).is_err());
    }

    #[test]
    fn modes() {
        assert_eq!(Method::Default.config(), Some(Config::new()));
        assert_eq!(Method::Default.config().unwrap().cost(), CostKind::Quadric);
        assert_eq!(
            Method::GreedyW.config(),
            Some(Config::new().with_cost(CostKind::NormalVariation))
        );
        assert_eq!(Method::Paper.config(), Some(Config::paper()));
        assert_eq!(Method::Meshopt.config(), None);
        assert_eq!(Method::Fast.config(), Some(Config::new()));
        assert_eq!(Method::Lean.config(), Some(Config::new()));
        assert_eq!(Method::FastInteger.config(), Some(Config::new()));
        assert_eq!(Method::FastInteger.float(), Method::Fast);
        assert_eq!(Method::LeanInteger.float(), Method::Lean);
        assert!(Method::LeanInteger.integer() && !Method::Lean.integer());
        assert_eq!(Method::ALL.iter().filter(|m| m.is_ours()).count(), 12);
    }

    #[test]
    fn meshopt_version_is_pinned() {
        let toml = include_str!("../Cargo.toml");
        assert!(
            toml.contains(&format!("meshopt = \"={MESHOPT_CRATE_VERSION}\"")),
            "host-sim/Cargo.toml must pin meshopt to {MESHOPT_CRATE_VERSION} (meshoptimizer \
             {MESHOPTIMIZER_VERSION}); update both constants when changing it"
        );
    }

    #[test]
    fn median_and_geomean() {
        assert_eq!(median(&[3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&[4.0, 1.0, 2.0, 3.0]), 2.5);
        assert!((geomean([2.0, 8.0, f64::NAN].into_iter()) - 4.0).abs() < 1e-12);
        assert!(geomean(std::iter::empty()).is_nan());
    }

    #[test]
    fn verdict_lists_what_differs() {
        let square = MeshData {
            positions: vec![
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [1.0, 1.0, 0.0],
                [0.0, 1.0, 0.0],
            ],
            triangles: vec![[0, 1, 2], [0, 2, 3]],
        };
        assert_eq!(verdict(&compare(&square, &square)), "yes");
        let doubled = MeshData {
            triangles: vec![[0, 1, 2], [0, 1, 2]],
            ..square.clone()
        };
        let text = verdict(&compare(&square, &doubled));
        assert!(text.starts_with("**NO** ("), "{text}");
        assert!(text.contains("dup 1"), "{text}");
    }

    fn check_rows(r: &Results) {
        for row in &r.rows {
            let numbers = [
                row.median_ms,
                row.time_vs_meshopt,
                row.scratch_bytes_per_triangle,
                row.metro_mean_pct,
                row.metro_max_pct,
                row.mean_vs_meshopt,
                row.max_vs_meshopt,
            ];
            assert!(numbers.iter().all(|x| x.is_finite()), "{row:?}");
            assert!(row.triangles_out > 0 && row.triangles_out < row.triangles_in);
            assert!(row.scratch_bytes > 0, "{row:?}");
            assert_eq!(row.method.is_ours(), row.report.is_some(), "{row:?}");
            if row.method.is_ours() {
                assert!(row.valid, "{row:?}");
            }
            // meshoptimizer at our count exactly when we stopped short.
            assert_eq!(
                row.same_count.is_some(),
                row.method.is_ours() && !row.target_reached,
                "{row:?}"
            );
        }
    }

    /// The smoke mode CI runs: cow and plate_holes from the repository's fixtures.
    #[test]
    fn quick_smoke() {
        let c = Cli::try_parse_from(["x", "--quick"]).unwrap();
        let (mut opts, _, _) = c.args.options();
        opts.progress = false;
        let r = bench(&opts, "host-sim bench --quick").unwrap();
        assert_eq!(
            r.rows.len(),
            QUICK_MESHES.len() * QUICK_RATIOS.len() * Method::ALL.len()
        );
        check_rows(&r);
        let md = markdown(&r);
        for mesh in QUICK_MESHES {
            assert!(md.contains(&format!("## {mesh}")), "{md}");
        }
        for method in Method::ALL {
            let table_rows = md
                .lines()
                .filter(|l| l.contains(" %") && l.contains(&format!("| {} |", method.label())))
                .count();
            // One row per mesh and ratio, plus (ours) one per ratio in the worst-error table,
            // one in the whole-run error table and one per run that stopped short in the
            // stopped-short table; an integer mode one more in the integer-against-float table,
            // and its float mode one in that section's floor table.
            let extra = if method.is_ours() {
                QUICK_RATIOS.len()
                    + 1
                    + usize::from(method.integer())
                    + usize::from(
                        Method::ALL
                            .iter()
                            .any(|m| m.integer() && m.float() == method),
                    )
                    + r.rows
                        .iter()
                        .filter(|x| x.method == method && !x.target_reached)
                        .count()
            } else {
                0
            };
            assert_eq!(
                table_rows,
                QUICK_MESHES.len() * QUICK_RATIOS.len() + extra,
                "{method:?}\n{md}"
            );
        }
        assert_eq!(r.summary.modes.len(), Method::ALL.len());
        for m in &r.summary.modes {
            assert!(m.time_vs_meshopt_geomean.is_finite(), "{m:?}");
            assert_eq!(m.worst.len(), if m.method.is_ours() { 2 } else { 0 });
            assert_eq!(m.overall.is_some(), m.method.is_ours(), "{m:?}");
        }
        let json: serde_json::Value =
            serde_json::from_str(&serde_json::to_string(&r).unwrap()).unwrap();
        assert_eq!(json["rows"].as_array().unwrap().len(), r.rows.len());
        assert_eq!(json["rows"][0]["method"], "default");
    }

    /// A target the library cannot reach (plate_holes has genus 5 and sharp features): the
    /// same-count comparison runs and is reported.
    #[test]
    fn stopped_short_is_compared_at_the_same_count() {
        let opts = Options {
            meshes: default_meshes(),
            more: None,
            only: Some(vec!["plate_holes.obj".into()]),
            ratios: vec![0.01],
            reps: 1,
            samples_per_triangle: 2.0,
            progress: false,
            prune: true,
            modes: None,
        };
        let r = bench(&opts, "test").unwrap();
        check_rows(&r);
        let short: Vec<&Row> = r.rows.iter().filter(|x| x.same_count.is_some()).collect();
        assert!(!short.is_empty(), "{:?}", r.rows);
        for x in &short {
            let c = x.same_count.as_ref().unwrap();
            assert_eq!(c.target_triangles, x.triangles_out);
            assert!(c.mean_vs_meshopt.is_finite() && c.max_vs_meshopt.is_finite());
            assert_ne!(x.stop.as_deref(), Some("Target"));
        }
        assert_eq!(r.summary.same_count_runs, short.len());
        let md = markdown(&r);
        assert!(md.contains("meshoptimizer at "), "{md}");
        assert!(md.contains("†"), "{md}");
        assert!(!md.contains("Every mode reached every target"), "{md}");
    }
}
