//! `host-sim bench`: every tinydecimate mode against meshoptimizer on a directory of meshes
//! ([`crate::bench`]), written as Markdown and JSON; `--cluster` for the clustering table.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{Context, Result};

use crate::bench::markdown::markdown;
use crate::bench::{bench, default_meshes, Options, QUICK_MESHES, QUICK_RATIOS};

/// `host-sim bench ...`
#[derive(Clone, Debug, clap::Args)]
pub struct Args {
    /// Directory of meshes (.obj, .ply, .stl, .glb, .gltf); every mesh in it runs, smallest
    /// first. Default: the repository's `tests/fixtures`, and `bench/meshes` (messy
    /// multi-part models too large for the fixtures).
    #[arg(long)]
    pub meshes: Option<PathBuf>,
    /// Only these files of the mesh directory, comma separated (e.g. `--only cow.obj`).
    #[arg(long, value_delimiter = ',')]
    pub only: Option<Vec<String>>,
    /// Target ratios, comma separated (default 0.5,0.25,0.1; with --quick 0.5,0.1).
    #[arg(long, value_delimiter = ',')]
    pub ratios: Option<Vec<f32>>,
    /// Repetitions per run; the median wall time is reported (default 5; with --quick 1).
    #[arg(long)]
    pub reps: Option<usize>,
    /// Markdown output (default bench/RESULTS.md; with --quick or --only none).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// JSON output (default bench/results.json; with --quick or --only none).
    #[arg(long)]
    pub json: Option<PathBuf>,
    /// Smoke run for CI: only cow and plate_holes, at 0.5 and 0.1, 1 repetition, no files
    /// written unless --out/--json are given.
    #[arg(long)]
    pub quick: bool,
    /// Metro face samples per triangle of the larger mesh.
    #[arg(long, default_value_t = 10.0)]
    pub samples_per_triangle: f64,
    /// Streaming vertex clustering (`tinydecimate::cluster`, quadric representative) against
    /// meshoptimizer's `simplifySloppy` instead (table to --out only; default ratios 0.2,0.05).
    #[arg(long)]
    pub cluster: bool,
    /// Parts in our modes, as `tinydecimate simplify --parts`: `prune` (the default) lets a part
    /// cheaper than the next collapse vanish whole, `keep` keeps every part.
    #[arg(long, value_enum, default_value_t = tinydecimate_cli::cmd::simplify::PartsArg::Prune)]
    pub parts: tinydecimate_cli::cmd::simplify::PartsArg,
    /// Only these of our modes, comma separated (default: every one); meshoptimizer always
    /// runs, as the reference (simplifyWithUpdate too with stored-optimal).
    #[arg(long, value_enum, value_delimiter = ',')]
    pub modes: Option<Vec<crate::bench::Method>>,
}

impl Args {
    /// The options these arguments ask for, and the Markdown and JSON paths. A partial run
    /// (`--quick` or `--only`) writes no file unless asked to, so it cannot overwrite the full
    /// results by accident.
    pub fn options(&self) -> (Options, Option<PathBuf>, Option<PathBuf>) {
        let (meshes, only, ratios, reps) = if self.quick {
            (
                self.meshes.clone().unwrap_or_else(default_meshes),
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
        let more = self.meshes.is_none().then(crate::bench::bench_meshes);
        let opts = Options {
            meshes,
            more,
            only: self.only.clone().or(only),
            ratios: self.ratios.clone().unwrap_or(ratios),
            reps: self.reps.unwrap_or(reps),
            samples_per_triangle: self.samples_per_triangle,
            progress: true,
            prune: self.parts == tinydecimate_cli::cmd::simplify::PartsArg::Prune,
            modes: self.modes.clone(),
        };
        let partial = self.quick || self.only.is_some();
        let default = |p: &str| (!partial).then(|| PathBuf::from(p));
        (
            opts,
            self.out.clone().or_else(|| default("bench/RESULTS.md")),
            self.json.clone().or_else(|| default("bench/results.json")),
        )
    }
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
    if args.cluster {
        let (mut opts, _, _) = args.options();
        if args.ratios.is_none() {
            opts.ratios = vec![0.2, 0.05];
        }
        return crate::bench::cluster::run(&opts, args.out.as_deref());
    }
    let (opts, out, json) = args.options();
    let results = bench(&opts, &command_line())?;
    let md = markdown(&results);
    crate::out!("{md}");
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
