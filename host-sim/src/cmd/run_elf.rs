//! `host-sim run-elf ELF`: the Cargo runner of the firmware example (examples/cortex-m4f).

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Duration;

use anyhow::{Context, Result};

use crate::qemu::board;
use crate::qemu::run::{run_in, scratch_dir};

/// `host-sim run-elf ELF`: the Cargo runner of the firmware example (examples/cortex-m4f).
#[derive(Clone, Debug, clap::Args)]
pub struct Args {
    /// The firmware image (as Cargo hands it to a runner).
    pub elf: PathBuf,
    /// QEMU board (machine) to run it on.
    #[arg(long, default_value = "mps2-an386")]
    pub board: String,
    /// Kill QEMU after this many seconds.
    #[arg(long, default_value_t = 60)]
    pub timeout: u64,
}

/// Runs a firmware image under QEMU, prints its defmt log decoded with the image's own table,
/// and exits with the firmware's semihosting exit code (124 on a timeout).
pub fn run(a: &Args) -> Result<ExitCode> {
    let b = board(&a.board)?;
    let elf = std::fs::canonicalize(&a.elf).with_context(|| format!("{}", a.elf.display()))?;
    let dir = scratch_dir("run-elf")?;
    let run = run_in(b, &elf, &dir, &[], None, Duration::from_secs(a.timeout));
    let _ = std::fs::remove_dir_all(&dir);
    let run = run?;
    for l in &run.log {
        crate::outln!("{l}");
    }
    if !run.stderr.trim().is_empty() {
        eprintln!("qemu: {}", run.stderr.trim());
    }
    if run.timed_out {
        eprintln!("killed after {} s", a.timeout);
        return Ok(ExitCode::from(124));
    }
    Ok(ExitCode::from(
        run.exit_code.map_or(1, |c| c.clamp(0, 255) as u8),
    ))
}
