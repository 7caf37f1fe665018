//! `host-sim bench`: tinydecimate (both schedules) against meshoptimizer on a directory of
//! meshes, in one process and one run, written as Markdown and JSON.
//!
//! For every mesh and ratio `r` three simplifiers run on the same input:
//!
//! * **greedy**: `Config::new().with_ratio(r)` (the library's defaults);
//! * **passes**: `Config::paper().with_ratio(r)` (the paper's schedule);
//! * **meshopt**: `meshopt::simplify` (meshoptimizer [`MESHOPTIMIZER_VERSION`], bundled by the
//!   `meshopt` crate [`MESHOPT_CRATE_VERSION`]) with a target index count of
//!   `3·⌊r·T⌋` (the library's own rounding of the ratio), target error 1.0 (100 % of the mesh
//!   extent: no error limit) and default options.
//!
//! Each run is repeated `reps` times, every repetition on a fresh copy of the input, and the
//! median wall time of the simplifier call alone is reported. The result of the last repetition
//! (every simplifier is deterministic) is checked with [`crate::check::compare`] and measured
//! with [`crate::metro::metro`]. Scratch memory per input triangle is, for tinydecimate, the
//! exact right-sized workspace ([`crate::simplify::workspace_bytes`]); for meshoptimizer, the
//! peak of the bytes live in its temporary allocator during the call, counted through
//! `meshopt_setAllocator`. The output index buffer the `meshopt` wrapper allocates is not
//! counted (tinydecimate writes its result over its input instead).
//!
//! A benchmark reports: nothing here asserts timings or validity.

use std::fmt::Write as _;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::Mutex;
use std::time::{Duration, Instant};

use anyhow::{bail, Context, Result};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use serde::Serialize;
use tinydecimate::Config;

use crate::check::{compare, Validity};
use crate::io::MeshData;
use crate::metro::{metro, MetroOptions};
use crate::simplify::{simplify_with, workspace_bytes, CostArg};

/// The meshoptimizer version that `meshopt` [`MESHOPT_CRATE_VERSION`] bundles
/// (`MESHOPTIMIZER_VERSION 1030` in its `vendor/src/meshoptimizer.h`).
pub const MESHOPTIMIZER_VERSION: &str = "1.3";
/// The `meshopt` crate version host-sim pins (`meshopt = "=0.7.0"` in its Cargo.toml).
pub const MESHOPT_CRATE_VERSION: &str = "0.7.0";

/// The meshes `--quick` runs (file names in the mesh directory).
pub const QUICK_MESHES: [&str; 2] = ["cow.obj", "plate_holes.obj"];
/// The ratios `--quick` runs.
pub const QUICK_RATIOS: [f32; 2] = [0.5, 0.1];

/// `../shared/meshes` beside the checkout (the default mesh directory).
fn default_meshes() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/meshes")
}

/// The repository's own copies of the quick meshes (`tests/fixtures`), so `--quick` runs
/// without the shared meshes (in CI).
pub fn fixture_meshes() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/fixtures")
}

/// `host-sim bench ...`
#[derive(Clone, Debug, clap::Args)]
pub struct Args {
    /// Directory of meshes (.obj, .ply, .stl); every mesh in it runs, smallest first. Default:
    /// `../shared/meshes` beside the checkout (with --quick: the repository's tests/fixtures).
    #[arg(long)]
    pub meshes: Option<PathBuf>,
    /// Target ratios, comma separated (default 0.5,0.25,0.1; with --quick 0.5,0.1).
    #[arg(long, value_delimiter = ',')]
    pub ratios: Option<Vec<f32>>,
    /// Repetitions per run; the median wall time is reported (default 5; with --quick 1).
    #[arg(long)]
    pub reps: Option<usize>,
    /// Markdown output (default bench/RESULTS.md; with --quick none).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// JSON output (default bench/results.json; with --quick none).
    #[arg(long)]
    pub json: Option<PathBuf>,
    /// Smoke run for CI: only cow and plate_holes, at 0.5 and 0.1, 1 repetition, no files
    /// written unless --out/--json are given.
    #[arg(long)]
    pub quick: bool,
    /// Metro face samples per triangle of the larger mesh.
    #[arg(long, default_value_t = 10.0)]
    pub samples_per_triangle: f64,
}

/// What one benchmark run does (the resolved [`Args`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Options {
    /// Mesh directory.
    pub meshes: PathBuf,
    /// Only these file names from the directory (`None`: every mesh file).
    pub only: Option<Vec<String>>,
    /// Target ratios.
    pub ratios: Vec<f32>,
    /// Repetitions per run.
    pub reps: usize,
    /// Metro face samples per triangle.
    pub samples_per_triangle: f64,
    /// Show a progress bar (only if stderr is a terminal).
    pub progress: bool,
}

impl Args {
    /// The options these arguments ask for, and the Markdown and JSON paths.
    pub fn options(&self) -> (Options, Option<PathBuf>, Option<PathBuf>) {
        let (meshes, only, ratios, reps) = if self.quick {
            (
                self.meshes.clone().unwrap_or_else(fixture_meshes),
                Some(QUICK_MESHES.iter().map(|s| s.to_string()).collect()),
                QUICK_RATIOS.to_vec(),
                1,
            )
        } else {
            (
                self.meshes.clone().unwrap_or_else(default_meshes),
                None,
                vec![0.5, 0.25, 0.1],
                5,
            )
        };
        let opts = Options {
            meshes,
            only,
            ratios: self.ratios.clone().unwrap_or(ratios),
            reps: self.reps.unwrap_or(reps),
            samples_per_triangle: self.samples_per_triangle,
            progress: true,
        };
        let default = |p: &str| (!self.quick).then(|| PathBuf::from(p));
        (
            opts,
            self.out.clone().or_else(|| default("bench/RESULTS.md")),
            self.json.clone().or_else(|| default("bench/results.json")),
        )
    }
}

/// One simplifier.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Method {
    /// tinydecimate, `Config::new()` (greedy schedule).
    Greedy,
    /// tinydecimate, `Config::paper()` (passes schedule).
    Passes,
    /// meshoptimizer's `meshopt_simplify`.
    Meshopt,
}

impl Method {
    /// All three, in table order.
    pub const ALL: [Method; 3] = [Method::Greedy, Method::Passes, Method::Meshopt];

    /// Name in the tables.
    pub fn label(self) -> &'static str {
        match self {
            Method::Greedy => "tinydecimate greedy",
            Method::Passes => "tinydecimate passes",
            Method::Meshopt => "meshoptimizer",
        }
    }

    /// Whether this is one of ours.
    pub fn is_ours(self) -> bool {
        self != Method::Meshopt
    }
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
    /// Whether the result is a valid simplification ([`Validity::is_valid`]).
    pub valid: bool,
    /// The defect counts.
    pub validity: Validity,
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
    /// The mesh directory.
    pub meshes: String,
    /// Target ratios.
    pub ratios: Vec<f32>,
    /// Repetitions per run.
    pub reps: usize,
    /// Metro face samples per triangle.
    pub samples_per_triangle: f64,
    /// Every run, by mesh (smallest first), ratio, then method.
    pub rows: Vec<Row>,
}

// ---------------------------------------------------------------------------------------------
// meshoptimizer with counted scratch memory

/// Counts the bytes meshoptimizer holds in its temporary allocator (`meshopt_setAllocator`).
mod counted {
    use std::alloc::{GlobalAlloc, Layout, System};
    use std::ffi::c_void;
    use std::sync::atomic::{AtomicUsize, Ordering::Relaxed};
    use std::sync::Once;

    /// Bytes before each block holding its size (16 keeps the C++ alignment guarantee).
    const HEADER: usize = 16;
    static LIVE: AtomicUsize = AtomicUsize::new(0);
    static PEAK: AtomicUsize = AtomicUsize::new(0);

    unsafe extern "C" fn allocate(size: usize) -> *mut c_void {
        let Some(layout) = size
            .checked_add(HEADER)
            .and_then(|n| Layout::from_size_align(n, HEADER).ok())
        else {
            return std::ptr::null_mut();
        };
        // SAFETY: `layout` has a non-zero size.
        let p = unsafe { System.alloc(layout) };
        if p.is_null() {
            return p.cast();
        }
        // SAFETY: the block is at least HEADER bytes and 16-aligned.
        unsafe { p.cast::<usize>().write(size) };
        let live = LIVE.fetch_add(size, Relaxed) + size;
        PEAK.fetch_max(live, Relaxed);
        // SAFETY: within the block.
        unsafe { p.add(HEADER).cast() }
    }

    unsafe extern "C" fn deallocate(ptr: *mut c_void) {
        if ptr.is_null() {
            return;
        }
        // SAFETY: `ptr` came from `allocate`, so its block starts HEADER bytes before it, with
        // the size written there, and was allocated with this layout.
        unsafe {
            let p = ptr.cast::<u8>().sub(HEADER);
            let size = p.cast::<usize>().read();
            LIVE.fetch_sub(size, Relaxed);
            System.dealloc(p, Layout::from_size_align_unchecked(size + HEADER, HEADER));
        }
    }

    /// Runs `f` (which calls meshoptimizer; the caller serialises such calls) and returns the
    /// peak of the bytes meshoptimizer had allocated at once during it.
    pub fn peak_during<R>(f: impl FnOnce() -> R) -> (R, usize) {
        static INSTALL: Once = Once::new();
        // SAFETY: done once, before any other meshopt call of this process (every one goes
        // through here, under the caller's lock).
        INSTALL.call_once(|| unsafe {
            meshopt::ffi::meshopt_setAllocator(Some(allocate), Some(deallocate))
        });
        let base = LIVE.load(Relaxed);
        PEAK.store(base, Relaxed);
        let r = f();
        (r, PEAK.load(Relaxed) - base)
    }
}

/// meshoptimizer is not to be called concurrently while its allocator is (re)set, and the
/// counters are global: one call at a time.
static MESHOPT: Mutex<()> = Mutex::new(());

/// `meshopt::simplify` on `mesh` down to `target_triangles`: result, wall time of the call and
/// peak scratch bytes.
pub fn meshopt_simplify(mesh: &MeshData, target_triangles: usize) -> (MeshData, Duration, usize) {
    let indices: Vec<u32> = mesh.triangles.iter().flatten().copied().collect();
    let bytes = meshopt::utilities::typed_to_bytes(&mesh.positions);
    let adapter = meshopt::VertexDataAdapter::new(bytes, std::mem::size_of::<[f32; 3]>(), 0)
        .expect("12-byte vertices");
    let _lock = MESHOPT.lock().unwrap_or_else(|p| p.into_inner());
    let ((out, elapsed), peak) = counted::peak_during(|| {
        let start = Instant::now();
        let out = meshopt::simplify(
            &indices,
            &adapter,
            3 * target_triangles,
            1.0,
            meshopt::SimplifyOptions::None,
            None,
        );
        (out, start.elapsed())
    });
    let triangles = out.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
    let result = MeshData {
        positions: mesh.positions.clone(),
        triangles,
    };
    (result, elapsed, peak)
}

// ---------------------------------------------------------------------------------------------
// The benchmark

fn median(xs: &[f64]) -> f64 {
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
    let names: Vec<String> = match &opts.only {
        Some(names) => names.clone(),
        None => {
            let mut names = Vec::new();
            let dir = std::fs::read_dir(&opts.meshes)
                .with_context(|| format!("{}: cannot list", opts.meshes.display()))?;
            for entry in dir {
                let name = entry?.file_name().to_string_lossy().into_owned();
                let ext = name.rsplit('.').next().unwrap_or("").to_ascii_lowercase();
                if name.contains('.') && matches!(ext.as_str(), "obj" | "ply" | "stl") {
                    names.push(name);
                }
            }
            names
        }
    };
    if names.is_empty() {
        bail!("{}: no .obj, .ply or .stl meshes", opts.meshes.display());
    }
    let mut meshes = Vec::new();
    for name in names {
        let mesh = crate::io::load(opts.meshes.join(&name))?;
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
    let steps = (meshes.len() * opts.ratios.len() * Method::ALL.len()) as u64;
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
        for &ratio in &opts.ratios {
            let target = (ratio as f64 * t as f64) as usize;
            let first = rows.len();
            for method in Method::ALL {
                bar.set_message(format!("{name} {ratio} {}", method.label()));
                let mut times = Vec::with_capacity(opts.reps);
                let mut result = None;
                for _ in 0..opts.reps {
                    let (out, elapsed, scratch, stop) = match method {
                        Method::Greedy | Method::Passes => {
                            let config = if method == Method::Greedy {
                                Config::new()
                            } else {
                                Config::paper()
                            }
                            .with_ratio(ratio);
                            let (out, report, elapsed) =
                                simplify_with(mesh, &config, CostArg::Normal)
                                    .with_context(|| format!("{name} at {ratio}"))?;
                            let stop = Some(format!("{:?}", report.stop));
                            (out, elapsed, workspace_bytes(v, t).0, stop)
                        }
                        Method::Meshopt => {
                            let (out, elapsed, peak) = meshopt_simplify(mesh, target);
                            (out, elapsed, peak, None)
                        }
                    };
                    times.push(ms(elapsed));
                    result = Some((out, scratch, stop));
                }
                let (out, scratch, stop) = result.expect("reps >= 1");
                let validity = compare(mesh, &out);
                let m = metro(mesh, &out, &metro_opts);
                let triangles_out = out.triangles.len();
                rows.push(Row {
                    mesh: name.clone(),
                    vertices: v,
                    triangles_in: t,
                    ratio,
                    method,
                    target_triangles: target,
                    triangles_out,
                    target_reached: triangles_out <= target,
                    stop,
                    median_ms: median(&times),
                    times_ms: times,
                    time_vs_meshopt: f64::NAN,
                    scratch_bytes: scratch,
                    scratch_bytes_per_triangle: scratch as f64 / t.max(1) as f64,
                    metro_mean_pct: m.symmetric_mean_pct,
                    metro_max_pct: m.hausdorff_pct,
                    valid: validity.is_valid(),
                    validity,
                });
                bar.inc(1);
            }
            let reference = rows[first..]
                .iter()
                .find(|r| r.method == Method::Meshopt)
                .map_or(f64::NAN, |r| r.median_ms);
            for r in &mut rows[first..] {
                r.time_vs_meshopt = r.median_ms / reference;
            }
        }
    }
    bar.finish_and_clear();
    Ok(Results {
        command: command.to_string(),
        machine: machine(),
        meshoptimizer_version: MESHOPTIMIZER_VERSION.into(),
        meshopt_crate_version: MESHOPT_CRATE_VERSION.into(),
        meshes: std::fs::canonicalize(&opts.meshes)
            .unwrap_or_else(|_| opts.meshes.clone())
            .display()
            .to_string(),
        ratios: opts.ratios.clone(),
        reps: opts.reps,
        samples_per_triangle: opts.samples_per_triangle,
        rows,
    })
}

// ---------------------------------------------------------------------------------------------
// Output

fn signed(x: i64) -> String {
    if x > 0 {
        format!("+{x}")
    } else {
        x.to_string()
    }
}

/// Time in ms with 3 significant-ish digits.
fn fmt_ms(x: f64) -> String {
    if x >= 100.0 {
        format!("{x:.0}")
    } else if x >= 10.0 {
        format!("{x:.1}")
    } else if x >= 1.0 {
        format!("{x:.2}")
    } else {
        format!("{x:.3}")
    }
}

/// The results as Markdown: a header, a summary, then one table per mesh.
pub fn markdown(r: &Results) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "# tinydecimate vs meshoptimizer\n");
    let _ = writeln!(s, "Written by `host-sim bench` (host-sim/src/bench.rs).\n");
    let _ = writeln!(s, "* Command: `{}`", r.command);
    let _ = writeln!(
        s,
        "* Machine: {}; shared with other jobs, so the timings are indicative only.",
        r.machine
    );
    let _ = writeln!(
        s,
        "* meshoptimizer {} (bundled by the `meshopt` crate {}): `meshopt::simplify`, target \
         index count 3·⌊ratio·T⌋, target error 1.0 (no limit), default options.",
        r.meshoptimizer_version, r.meshopt_crate_version
    );
    let ratios: Vec<String> = r.ratios.iter().map(|x| x.to_string()).collect();
    let _ = writeln!(
        s,
        "* tinydecimate: greedy = `Config::new().with_ratio(r)`, passes = \
         `Config::paper().with_ratio(r)`.\n* Meshes: `{}`; ratios {}; {} repetition(s) per run, \
         each on a fresh copy of the input; Metro with {} face samples per triangle.",
        r.meshes,
        ratios.join(", "),
        r.reps,
        r.samples_per_triangle
    );
    let _ = writeln!(
        s,
        "\nColumns: **tris** triangles reached (target ⌊ratio·T⌋); **ms** median wall time of the \
         simplifier call; **× mopt** that time over meshoptimizer's; **B/tri** scratch bytes per \
         input triangle (tinydecimate: exact right-sized `Workspace`; meshoptimizer: peak of its \
         temporary allocations, counted with `meshopt_setAllocator`, output index buffer not \
         counted); **mean %** / **max %** Metro symmetric mean and Hausdorff distance in % of the \
         input's bbox diagonal; validity from `host-sim check`: **NM** new non-manifold edges, \
         **dup** duplicate triangles, **deg** degenerate triangles, **fold** new folded pairs, \
         **Δloops** change of the boundary-loop count, **Δχ** change of the Euler \
         characteristic.\n"
    );

    // Summary per method.
    let _ = writeln!(s, "## Summary\n");
    let _ = writeln!(
        s,
        "| method | valid runs | target reached | geo. mean × mopt | mean of mean % | mean of max % |"
    );
    let _ = writeln!(s, "|---|---:|---:|---:|---:|---:|");
    for method in Method::ALL {
        let rows: Vec<&Row> = r.rows.iter().filter(|x| x.method == method).collect();
        if rows.is_empty() {
            continue;
        }
        let n = rows.len() as f64;
        let valid = rows.iter().filter(|x| x.valid).count();
        let reached = rows.iter().filter(|x| x.target_reached).count();
        let geo = (rows.iter().map(|x| x.time_vs_meshopt.ln()).sum::<f64>() / n).exp();
        let mean = rows.iter().map(|x| x.metro_mean_pct).sum::<f64>() / n;
        let max = rows.iter().map(|x| x.metro_max_pct).sum::<f64>() / n;
        let _ = writeln!(
            s,
            "| {} | {valid}/{} | {reached}/{} | {geo:.2} | {mean:.4} | {max:.3} |",
            method.label(),
            rows.len(),
            rows.len()
        );
    }
    let invalid: Vec<String> = r
        .rows
        .iter()
        .filter(|x| !x.valid)
        .map(|x| format!("{} {} @ {}", x.method.label(), x.mesh, x.ratio))
        .collect();
    if !invalid.is_empty() {
        let _ = writeln!(s, "\nInvalid results: {}.", invalid.join("; "));
    }

    let mut mesh_names: Vec<&str> = Vec::new();
    for row in &r.rows {
        if !mesh_names.contains(&row.mesh.as_str()) {
            mesh_names.push(&row.mesh);
        }
    }
    for name in mesh_names {
        let rows: Vec<&Row> = r.rows.iter().filter(|x| x.mesh == name).collect();
        let _ = writeln!(
            s,
            "\n## {name} (V = {}, T = {})\n",
            rows[0].vertices, rows[0].triangles_in
        );
        let _ = writeln!(
            s,
            "| ratio | method | tris | ms | × mopt | B/tri | mean % | max % | valid | NM | dup | deg | fold | Δloops | Δχ |"
        );
        let _ = writeln!(
            s,
            "|---:|---|---:|---:|---:|---:|---:|---:|---|---:|---:|---:|---:|---:|---:|"
        );
        for x in rows {
            let v = &x.validity;
            let _ = writeln!(
                s,
                "| {} | {} | {}{} | {} | {:.2} | {:.1} | {:.4} | {:.3} | {} | {} | {} | {} | {} | {} | {} |",
                x.ratio,
                x.method.label(),
                x.triangles_out,
                if x.target_reached { "" } else { " (short)" },
                fmt_ms(x.median_ms),
                x.time_vs_meshopt,
                x.scratch_bytes_per_triangle,
                x.metro_mean_pct,
                x.metro_max_pct,
                if x.valid { "yes" } else { "**NO**" },
                v.new_non_manifold_edges,
                v.duplicate_triangles,
                v.degenerate_triangles,
                v.new_folded_pairs,
                signed(v.boundary_loops.1 as i64 - v.boundary_loops.0 as i64),
                signed(v.euler.1 - v.euler.0),
            );
        }
    }
    s
}

fn write_file(path: &Path, text: &str) -> Result<()> {
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("{}: cannot create", dir.display()))?;
    }
    std::fs::write(path, text).with_context(|| format!("{}: cannot write", path.display()))
}

/// The command line as typed, with the program shown as `host-sim`.
fn command_line() -> String {
    let mut args: Vec<String> = std::env::args().collect();
    if let Some(a) = args.first_mut() {
        *a = "host-sim".into();
    }
    args.join(" ")
}

/// `host-sim bench`. Always exit code 0 when it ran: a benchmark reports, it does not judge.
pub fn run(args: &Args) -> Result<ExitCode> {
    let (opts, out, json) = args.options();
    let results = bench(&opts, &command_line())?;
    let md = markdown(&results);
    print!("{md}");
    if let Some(p) = &out {
        write_file(p, &md)?;
        eprintln!("wrote {}", p.display());
    }
    if let Some(p) = &json {
        write_file(p, &(serde_json::to_string_pretty(&results)? + "\n"))?;
        eprintln!("wrote {}", p.display());
    }
    Ok(ExitCode::SUCCESS)
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
    fn arguments() {
        let c = Cli::try_parse_from(["x"]).unwrap();
        let (o, md, js) = c.args.options();
        assert_eq!((o.ratios, o.reps, o.only), (vec![0.5, 0.25, 0.1], 5, None));
        assert_eq!(md, Some(PathBuf::from("bench/RESULTS.md")));
        assert_eq!(js, Some(PathBuf::from("bench/results.json")));
        let c = Cli::try_parse_from(["x", "--quick", "--ratios", "0.3,0.2"]).unwrap();
        let (o, md, js) = c.args.options();
        assert_eq!((o.ratios, o.reps), (vec![0.3, 0.2], 1));
        assert_eq!(o.meshes, fixture_meshes());
        assert_eq!((md, js), (None, None));
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
    fn median_of_odd_and_even() {
        assert_eq!(median(&[3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&[4.0, 1.0, 2.0, 3.0]), 2.5);
    }

    /// The smoke mode CI runs: cow and plate_holes from the repository's fixtures.
    #[test]
    fn quick_smoke() {
        let c = Cli::try_parse_from(["x", "--quick"]).unwrap();
        let (mut opts, _, _) = c.args.options();
        opts.progress = false;
        let r = bench(&opts, "host-sim bench --quick").unwrap();
        assert_eq!(r.rows.len(), QUICK_MESHES.len() * QUICK_RATIOS.len() * 3);
        for row in &r.rows {
            let numbers = [
                row.median_ms,
                row.time_vs_meshopt,
                row.scratch_bytes_per_triangle,
                row.metro_mean_pct,
                row.metro_max_pct,
            ];
            assert!(numbers.iter().all(|x| x.is_finite()), "{row:?}");
            assert!(row.triangles_out > 0 && row.triangles_out < row.triangles_in);
            assert!(row.scratch_bytes > 0, "{row:?}");
            if row.method.is_ours() {
                assert!(row.valid, "{row:?}");
            }
        }
        let md = markdown(&r);
        for mesh in QUICK_MESHES {
            assert!(md.contains(&format!("## {mesh}")), "{md}");
        }
        let table_rows = md
            .lines()
            .filter(|l| l.starts_with("| 0.") && l.contains("tinydecimate"))
            .count();
        assert_eq!(table_rows, QUICK_MESHES.len() * QUICK_RATIOS.len() * 2);
        let json: serde_json::Value =
            serde_json::from_str(&serde_json::to_string(&r).unwrap()).unwrap();
        assert_eq!(json["rows"].as_array().unwrap().len(), r.rows.len());
    }
}
