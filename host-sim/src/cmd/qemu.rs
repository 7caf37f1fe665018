//! `host-sim qemu`: the library on the emulated boards: compared with the golden files
//! (`--check`) or a fresh host run, measured (`--measure`), streaming clustering (`--cluster`),
//! the boot smoke test (`--smoke`) and the exit statuses (`--handlers`).

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Duration;

use anyhow::Result;
use meshfmt::IndexType;

use crate::backend::Backend;
use crate::golden::{self, Case, Outcome};
use crate::qemu::build::{build, preflight};
use crate::qemu::check::{check_boards, Expected};
use crate::qemu::measure::{markdown, measure, print_measurement, print_summary};
use crate::qemu::run::{
    run_case_bytes, run_command, run_in, scratch_dir, EXIT_DONE, EXIT_FAULT, EXIT_IO, EXIT_PANIC,
};
use crate::qemu::{cluster, select_boards};

/// `host-sim qemu ...`: runs the library on the emulated boards.
#[derive(Clone, Debug, clap::Args)]
pub struct Args {
    /// Board to use; repeat for several. Default: all seven (microbit, lm3s6965evb,
    /// mps2-an386, mps2-an500, mps2-an505, riscv32imc-virt-400k, riscv32imac-virt-32k).
    #[arg(long = "board", value_name = "MACHINE")]
    pub boards: Vec<String>,
    /// Math backend of the library (default: the one host-sim was built with). Another one
    /// re-runs host-sim through `cargo run` with or without `--features micromath`; the
    /// firmware is built with the same backend.
    #[arg(long, value_enum)]
    pub backend: Option<Backend>,
    /// Compare every board's output (and the host's) with the golden files; print a table
    /// cases x boards. Exit 1 on any DIFF or failure. Without it, the boards are compared with
    /// a fresh host run.
    #[arg(long, conflicts_with_all = ["mesh", "measure", "smoke", "handlers", "cluster"])]
    pub check: bool,
    /// Streaming clustering of meshes larger than RAM (the bunny on the micro:bit) on the host
    /// and the boards, against the golden files of `cluster.toml`; prints instructions per
    /// input triangle, position reads and stack per board. Exit 1 on any DIFF or failure.
    #[arg(long, conflicts_with_all = ["mesh", "measure", "smoke", "handlers"])]
    pub cluster: bool,
    /// With --cluster: write the golden files of cases that have none (existing ones are
    /// never rewritten).
    #[arg(long, requires = "cluster")]
    pub bless: bool,
    /// Report, per case and board, instructions (SysTick or mcycle, -icount shift=0),
    /// instructions per collapse and stack; per golden progressive stream, instructions per split decoding and
    /// per collapse / split moving the slider; per board the image sizes of the firmware and of the library alone,
    /// the flash of one instantiation (`tests/flash`, as `scripts/flash.sh` measures it) and the
    /// largest mesh it simplifies (bisection). Not pass/fail.
    #[arg(long)]
    pub measure: bool,
    /// With --measure: also write the measurements as Markdown tables to this file (the
    /// project's is bench/DEVICES.md, which the docs quote).
    #[arg(long, value_name = "FILE", requires = "measure")]
    pub out: Option<PathBuf>,
    /// The golden directory (`cases.toml`, `libm/`, `micromath/`).
    #[arg(long, value_name = "DIR", default_value_os_t = golden::default_dir())]
    pub dir: PathBuf,
    /// Run this mesh (.obj/.ply/.stl) instead of the golden cases.
    #[arg(long)]
    pub mesh: Option<PathBuf>,
    /// With --mesh: target ratio.
    #[arg(long, default_value_t = 0.25)]
    pub ratio: f32,
    /// With --mesh: the paper's passes instead of the greedy schedule.
    #[arg(long, conflicts_with = "batched")]
    pub passes: bool,
    /// With --mesh: the batched schedule (`Schedule::Batched`) instead of the greedy one.
    #[arg(long)]
    pub batched: bool,
    /// With --mesh: u32 triangles (default u16).
    #[arg(long)]
    pub u32: bool,
    /// Firmware without the library: boot, semihosting file I/O and defmt only (echo).
    #[arg(long)]
    pub smoke: bool,
    /// Check the exit statuses: self-test 0, panic 101, HardFault 102, missing case file 2.
    #[arg(long)]
    pub handlers: bool,
    /// Seconds before a QEMU run is killed.
    #[arg(long, default_value_t = 600)]
    pub timeout: u64,
    /// Print every run's decoded defmt log.
    #[arg(long, short)]
    pub verbose: bool,
}

/// Runs `host-sim qemu`. Exit code 1 when a board differs or a run fails, 2 on errors (or
/// when QEMU is missing).
pub fn run(a: &Args) -> Result<ExitCode> {
    let backend = a.backend.unwrap_or(Backend::compiled());
    if backend != Backend::compiled() {
        return crate::backend::reinvoke(backend);
    }
    let boards = select_boards(&a.boards)?;
    if let Some(code) = preflight(&boards)? {
        return Ok(code);
    }
    let timeout = Duration::from_secs(a.timeout);
    let mut failed = 0usize;
    if a.cluster {
        failed = cluster::check(&boards, backend, &a.dir, a.bless, timeout, a.verbose)?;
    } else if a.measure {
        let cases = golden::load_cases(&a.dir)?;
        let streams = crate::golden::stream::load(&a.dir)?;
        let mut all = Vec::new();
        for b in &boards {
            let m = measure(b, backend, &cases, &streams, timeout)?;
            print_measurement(&m);
            all.push(m);
        }
        print_summary(&all);
        if let Some(path) = &a.out {
            std::fs::write(path, markdown(&all))
                .map_err(|e| anyhow::anyhow!("{}: cannot write: {e}", path.display()))?;
            crate::outln!("tables: {}", path.display());
        }
    } else if a.smoke {
        let case = &golden::load_cases(&a.dir)?[0];
        for b in &boards {
            let elf = build(b, backend, false)?;
            let run = run_case_bytes(b, &elf, &case.encode()?, timeout)?;
            let echoed = match run.result.as_deref().filter(|_| run.ok()) {
                Some(bytes) => Outcome::decode(bytes)?.triangles == case.triangles,
                None => false,
            };
            failed += usize::from(!echoed);
            crate::outln!(
                "{:<20} echo {}",
                b.name,
                if echoed { "ok" } else { "FAILED" }
            );
            if a.verbose || !echoed {
                crate::outln!("    {}", run.describe().replace('\n', "\n    "));
            }
        }
    } else if a.handlers {
        for b in &boards {
            let elf = build(b, backend, true)?;
            for (cmd, want) in [
                ("selftest", EXIT_DONE),
                ("panic", EXIT_PANIC),
                ("fault", EXIT_FAULT),
            ] {
                let run = run_command(b, &elf, cmd, timeout)?;
                let ok = run.exit_code == Some(want);
                failed += usize::from(!ok);
                crate::outln!(
                    "{:<20} {cmd:<9} {}",
                    b.name,
                    if ok { "ok" } else { "FAILED" }
                );
                if a.verbose || !ok {
                    crate::outln!("    {}", run.describe().replace('\n', "\n    "));
                }
            }
            let dir = scratch_dir("missing")?;
            let run = run_in(
                b,
                &elf,
                &dir,
                &["no-such-case.bin", "out.bin"],
                None,
                timeout,
            )?;
            let _ = std::fs::remove_dir_all(&dir);
            let ok = run.exit_code == Some(EXIT_IO);
            failed += usize::from(!ok);
            crate::outln!(
                "{:<20} {:<9} {}",
                b.name,
                "missing",
                if ok { "ok" } else { "FAILED" }
            );
        }
    } else {
        let (cases, expected) = match &a.mesh {
            Some(path) => (
                vec![mesh_case(path, a.ratio, a.schedule(), a.u32)?],
                Expected::Host,
            ),
            None => (
                golden::load_cases(&a.dir)?,
                if a.check {
                    Expected::Golden(a.dir.clone())
                } else {
                    Expected::Host
                },
            ),
        };
        // Stream cases only against the golden files (with --mesh there are none).
        let streams = match (&a.mesh, &expected) {
            (None, _) => crate::golden::stream::load(&a.dir)?,
            (Some(_), _) => Vec::new(),
        };
        failed = check_boards(
            &boards, backend, &cases, &streams, &expected, timeout, a.verbose,
        )?;
    }
    Ok(if failed == 0 {
        ExitCode::SUCCESS
    } else {
        crate::outln!("{failed} failed");
        ExitCode::from(1)
    })
}

impl Args {
    /// The schedule of a --mesh run.
    fn schedule(&self) -> tinydecimate::Schedule {
        use tinydecimate::Schedule;
        match (self.passes, self.batched) {
            (true, _) => Schedule::Passes,
            (_, true) => Schedule::Batched,
            _ => Schedule::Greedy,
        }
    }
}

/// A case of a mesh file with `Config::new()` and the given ratio and schedule.
pub fn mesh_case(
    path: &Path,
    ratio: f32,
    schedule: tinydecimate::Schedule,
    u32: bool,
) -> Result<Case> {
    let m = crate::io::load(path)?;
    let config = tinydecimate::Config::new()
        .with_ratio(ratio)
        .with_schedule(schedule);
    Ok(Case {
        name: path
            .file_stem()
            .unwrap_or_default()
            .to_string_lossy()
            .into_owned(),
        mesh: path.display().to_string(),
        positions: m.positions,
        triangles: m.triangles,
        wedges: Vec::new(),
        index_type: if u32 { IndexType::U32 } else { IndexType::U16 },
        config,
        stored: None,
        method: None,
    })
}
