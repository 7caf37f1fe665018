//! `host-sim qemu --cluster`: streaming vertex clustering of meshes larger than the board's RAM
//! (the Stanford bunny, 69 451 triangles, on the 16 KB micro:bit), on the host and on every
//! emulated board, compared byte for byte with the golden files of
//! `tests/golden/cluster.toml` ([`crate::golden::cluster`]).
//!
//! The firmware image is `tinydecimate-cluster` (host-sim/firmware/src/bin/cluster.rs). It reads
//! the case file through semihosting: the triangles in chunks of 32 through one file handle, each
//! corner's position on demand (seek + 12-byte read) through another; RAM holds the cell table
//! and the output buffer only.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

use anyhow::{anyhow, bail, Context, Result};
use meshfmt::cluster::{ClusterResult, CLUSTER_RESULT_LEN};
use meshfmt::Status;

use crate::backend::Backend;
use crate::golden::cluster::{compared, golden_paths, load_specs, reference, summary, Case};
use crate::qemu::{self, Board};

/// Builds the clustering image for `board`; returns it (copied to
/// `target/images/<board>-<backend>-cluster.elf`).
pub fn build(board: &Board, backend: Backend) -> Result<PathBuf> {
    let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    let mut features = format!("board-{}", board.name);
    if backend == Backend::Micromath {
        features.push_str(",micromath");
    }
    let mut cmd = Command::new(cargo);
    cmd.current_dir(qemu::build::firmware_dir())
        .args(["build", "--release", "--target", board.target])
        .args(["--bin", "tinydecimate-cluster", "--features", &features])
        .arg("--target-dir")
        .arg(qemu::build::firmware_target_dir())
        .env("DEFMT_LOG", "info");
    qemu::build::isolate(&mut cmd);
    let status = cmd
        .status()
        .context("running cargo for the cluster firmware")?;
    if !status.success() {
        bail!(
            "cluster firmware build for {} ({backend}) failed",
            board.name
        );
    }
    let built = qemu::build::firmware_target_dir()
        .join(board.target)
        .join("release")
        .join("tinydecimate-cluster");
    let elf = qemu::build::firmware_target_dir()
        .join("images")
        .join(format!("{}-{backend}-cluster.elf", board.name));
    std::fs::create_dir_all(elf.parent().expect("has a parent"))?;
    std::fs::copy(&built, &elf)?;
    Ok(elf)
}

/// One board's run of one case.
pub struct BoardRun {
    pub result: Option<(ClusterResult, Vec<u8>)>,
    pub run: qemu::Run,
}

/// Runs `case` (already encoded) on `board`.
pub fn run_on(board: &Board, elf: &Path, case_file: &Path, timeout: Duration) -> Result<BoardRun> {
    let dir = case_file.parent().context("case file directory")?;
    let name = case_file
        .file_name()
        .and_then(|n| n.to_str())
        .context("case file name")?;
    let out = format!("{name}.{}.result", board.name);
    let run = qemu::run_in(board, elf, dir, &[name, &out], Some(&out), timeout)?;
    let _ = std::fs::remove_file(dir.join(&out));
    let result = match (&run.result, run.ok()) {
        (Some(b), true) if b.len() >= CLUSTER_RESULT_LEN => {
            let head: &[u8; CLUSTER_RESULT_LEN] = b[..CLUSTER_RESULT_LEN].try_into()?;
            let r = ClusterResult::from_bytes(head).map_err(|e| anyhow!("result: {e:?}"))?;
            let t = b
                .get(CLUSTER_RESULT_LEN..CLUSTER_RESULT_LEN + r.triangles_len())
                .context("result file truncated")?
                .to_vec();
            Some((r, t))
        }
        _ => None,
    };
    Ok(BoardRun { result, run })
}

/// Runs every cluster case on the host and on `boards`, compares with the golden files (or
/// writes the missing ones with `bless`), prints a table and the measurements. Returns the
/// number of failures.
pub fn check(
    boards: &[&'static Board],
    backend: Backend,
    dir: &Path,
    bless: bool,
    timeout: Duration,
    verbose: bool,
) -> Result<usize> {
    let specs = load_specs(dir)?;
    let work = std::env::temp_dir().join(format!("tinydecimate-cluster-{}", std::process::id()));
    std::fs::create_dir_all(&work)?;
    let mut failed = 0usize;
    let mut cases = Vec::new();
    crate::outln!(
        "clustering cases ({backend}), compared with {}/{backend}:",
        dir.display()
    );
    for spec in &specs {
        let case = Case::load(spec)?;
        let t0 = Instant::now();
        let (r, tri) = reference(&case)?;
        let host_ms = t0.elapsed().as_secs_f64() * 1e3;
        let got = compared(&r, &tri);
        let (bin, txt) = golden_paths(dir, backend, &spec.name);
        let verdict = match std::fs::read(&bin) {
            Ok(g) if g == got => "identical".to_string(),
            Ok(_) => {
                failed += 1;
                "DIFF".to_string()
            }
            Err(_) if bless => {
                std::fs::write(&bin, &got)?;
                std::fs::write(&txt, summary(&case, &r, &tri))?;
                "written (new)".to_string()
            }
            Err(_) => {
                failed += 1;
                format!("no golden file {}", bin.display())
            }
        };
        crate::outln!(
            "  {:<28} host: {} -> {} triangles ({:?}), {} cells, grid {}, {:.1} ms: {verdict}",
            spec.name,
            r.triangles_in,
            r.triangles_out,
            r.status,
            r.cells,
            r.grid_n,
            host_ms
        );
        let file = work.join(format!("{}.case", spec.name));
        std::fs::write(&file, case.encode())?;
        cases.push((case, got, file));
    }
    for b in boards {
        let t0 = Instant::now();
        let elf = match build(b, backend) {
            Ok(e) => e,
            Err(e) => {
                failed += cases.len();
                crate::outln!("{:<20} FAILED: {e:#}", b.name);
                continue;
            }
        };
        let built = t0.elapsed().as_secs_f64();
        for (case, want, file) in &cases {
            let expect_skip = case.spec.skip.iter().any(|s| s == b.name);
            let br = run_on(b, &elf, file, timeout)?;
            let line = match &br.result {
                Some((r, _)) if r.status == Status::TooBig => {
                    if expect_skip {
                        "skipped (too big for the board, expected)".to_string()
                    } else {
                        failed += 1;
                        "FAILED: skipped, but not listed in the case's `skip`".to_string()
                    }
                }
                Some((r, tri)) => {
                    let same = compared(r, tri) == *want;
                    if !same || expect_skip {
                        failed += 1;
                    }
                    let instr = b.instructions(r.ticks);
                    format!(
                        "{}{}: {} -> {} triangles; {} instructions ({:.0} per input triangle); {} position reads; table {} B + output {} B; stack {} B in the call, high-water {} B; {:.1} s",
                        if same { "identical" } else { "DIFF" },
                        if expect_skip { " (but listed in `skip`)" } else { "" },
                        r.triangles_in,
                        r.triangles_out,
                        instr,
                        instr as f64 / f64::from(r.triangles_in.max(1)),
                        r.position_reads,
                        r.table_bytes,
                        r.output_bytes,
                        r.stack_bytes,
                        r.stack_high_water,
                        br.run.wall.as_secs_f64()
                    )
                }
                None => {
                    failed += 1;
                    format!("FAILED: {}", br.run.describe())
                }
            };
            crate::outln!("  {:<20} {:<28} {line}", b.name, case.spec.name);
            if verbose {
                crate::outln!("    {}", br.run.describe().replace('\n', "\n    "));
            }
        }
        eprintln!(
            "{:<20} cluster firmware ({backend}) built in {built:.1} s",
            b.name
        );
    }
    let _ = std::fs::remove_dir_all(&work);
    crate::outln!("{backend}: clustering, {failed} DIFF or FAILED");
    Ok(failed)
}
