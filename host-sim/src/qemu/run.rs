//! One QEMU run of a firmware image: the command line ([`qemu_command`]), the run with its
//! files and timeout ([`run_in`]), and the runs of a case, a stream or a command.

use std::io::{Read, Write};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::Mutex;
use std::time::{Duration, Instant};

use anyhow::{Context, Result};

use super::defmt::decode_defmt;
use super::Board;
use crate::golden::{Case, Outcome};

#[derive(Debug)]
pub struct Run {
    /// QEMU's exit code (the firmware's semihosting exit code: 0 done, 2 host I/O failed,
    /// 101 panic, 102 fault); `None` if killed.
    pub exit_code: Option<i32>,
    /// Killed after the timeout.
    pub timed_out: bool,
    /// Decoded defmt log lines.
    pub log: Vec<String>,
    /// QEMU's stderr (its own diagnostics).
    pub stderr: String,
    /// The result file, if the firmware wrote one.
    pub result: Option<Vec<u8>>,
    /// Host wall time of the run.
    pub wall: Duration,
}

impl Run {
    /// Whether QEMU exited with status 0.
    pub fn ok(&self) -> bool {
        self.exit_code == Some(0) && !self.timed_out
    }

    /// The log, the stderr and the exit status in a few lines, for error messages.
    pub fn describe(&self) -> String {
        let mut s = format!(
            "exit {:?}{}, {:.2} s",
            self.exit_code,
            if self.timed_out { " (timed out)" } else { "" },
            self.wall.as_secs_f64()
        );
        for l in &self.log {
            s.push_str("\n  ");
            s.push_str(l);
        }
        if !self.stderr.trim().is_empty() {
            s.push_str("\n  qemu: ");
            s.push_str(self.stderr.trim());
        }
        s
    }
}

/// `board.qemu_args`, with a RISC-V `-cpu rv32,...` as this QEMU accepts it: since QEMU 8 the
/// `rv32` CPU has extensions on by default (Zawrs, Zfa) that need the A or F extension a board
/// switches off, and QEMU then refuses to start ("Zawrs extension requires A extension"), while
/// QEMU 7.2 has no such properties to switch off. The first of the board's CPU with both off,
/// with Zawrs off, and as given that this QEMU starts is used (probed once per CPU string).
fn board_args(board: &Board) -> Vec<String> {
    board
        .qemu_args
        .iter()
        .map(|a| match a.strip_prefix("rv32,") {
            Some(_) => riscv_cpu(board.qemu.program, board.machine, a),
            None => a.to_string(),
        })
        .collect()
}

/// See [`board_args`].
fn riscv_cpu(program: &str, machine: &str, cpu: &str) -> String {
    static SEEN: Mutex<Vec<(String, String)>> = Mutex::new(Vec::new());
    let mut seen = SEEN.lock().unwrap_or_else(|e| e.into_inner());
    if let Some((_, c)) = seen.iter().find(|(k, _)| k == cpu) {
        return c.clone();
    }
    let chosen = [",zawrs=false,zfa=false", ",zawrs=false", ""]
        .iter()
        .map(|extra| format!("{cpu}{extra}"))
        .find(|c| qemu_starts(program, machine, c))
        .unwrap_or_else(|| cpu.to_string());
    seen.push((cpu.to_string(), chosen.clone()));
    chosen
}

/// Whether QEMU starts `machine` with CPU `cpu`: paused (`-S`), told to quit on its monitor; a
/// CPU it refuses makes it exit with an error before it reads the monitor.
fn qemu_starts(program: &str, machine: &str, cpu: &str) -> bool {
    let child = Command::new(program)
        .args(["-machine", machine, "-bios", "none", "-cpu", cpu, "-S"])
        .args(["-display", "none", "-serial", "null", "-monitor", "stdio"])
        .stdin(Stdio::piped())
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn();
    let Ok(mut child) = child else {
        return false;
    };
    if let Some(mut stdin) = child.stdin.take() {
        let _ = stdin.write_all(b"quit\n");
    }
    child.wait().is_ok_and(|s| s.success())
}

/// The QEMU command line for `board`, with semihosting arguments `args`.
pub fn qemu_command(board: &Board, elf: &Path, args: &[&str]) -> Command {
    let mut sh = String::from("enable=on,target=native,arg=tinydecimate-firmware");
    for a in args {
        sh.push_str(",arg=");
        sh.push_str(a);
    }
    let mut cmd = Command::new(board.qemu.program);
    cmd.args(["-machine", board.machine])
        .args(board_args(board))
        .args(["-nographic", "-monitor", "none", "-serial", "null"])
        // One instruction = 1 ns of virtual time: SysTick (and RISC-V's mcycle) counts
        // instructions, repeatably.
        .args(["-icount", "shift=0"])
        .args(["-semihosting-config", &sh])
        .arg("-kernel")
        .arg(elf);
    cmd
}

/// Runs `elf` on `board` in the directory `workdir` with semihosting arguments `args`
/// (file names relative to `workdir`, no spaces). Reads `result_name` afterwards if given.
pub fn run_in(
    board: &Board,
    elf: &Path,
    workdir: &Path,
    args: &[&str],
    result_name: Option<&str>,
    timeout: Duration,
) -> Result<Run> {
    if let Some(r) = result_name {
        let _ = std::fs::remove_file(workdir.join(r));
    }
    let mut cmd = qemu_command(board, elf, args);
    cmd.current_dir(workdir)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    let start = Instant::now();
    let mut child = cmd.spawn().with_context(|| {
        format!(
            "starting {} (apt-get install {})",
            board.qemu.program, board.qemu.package
        )
    })?;
    let mut stdout = child.stdout.take().context("qemu stdout")?;
    let mut stderr = child.stderr.take().context("qemu stderr")?;
    let out_thread = std::thread::spawn(move || {
        let mut b = Vec::new();
        let _ = stdout.read_to_end(&mut b);
        b
    });
    let err_thread = std::thread::spawn(move || {
        let mut b = Vec::new();
        let _ = stderr.read_to_end(&mut b);
        b
    });
    let mut timed_out = false;
    let status = loop {
        if let Some(s) = child.try_wait()? {
            break Some(s);
        }
        if start.elapsed() > timeout {
            let _ = child.kill();
            let _ = child.wait();
            timed_out = true;
            break None;
        }
        std::thread::sleep(Duration::from_millis(5));
    };
    let wall = start.elapsed();
    let stdout = out_thread.join().unwrap_or_default();
    let stderr = String::from_utf8_lossy(&err_thread.join().unwrap_or_default()).into_owned();
    let elf_bytes = std::fs::read(elf)?;
    let log = decode_defmt(&elf_bytes, &stdout)
        .unwrap_or_else(|e| vec![format!("<defmt decoding failed: {e:#}>")]);
    let result = match result_name {
        Some(r) => std::fs::read(workdir.join(r)).ok(),
        None => None,
    };
    Ok(Run {
        exit_code: status.and_then(|s| s.code()),
        timed_out,
        log,
        stderr,
        result,
        wall,
    })
}

/// A fresh scratch directory for one run.
pub fn scratch_dir(tag: &str) -> Result<PathBuf> {
    use std::sync::atomic::{AtomicU32, Ordering};
    static N: AtomicU32 = AtomicU32::new(0);
    let d = std::env::temp_dir().join(format!(
        "tinydecimate-qemu-{}-{}-{tag}",
        std::process::id(),
        N.fetch_add(1, Ordering::Relaxed)
    ));
    std::fs::create_dir_all(&d)?;
    Ok(d)
}

/// Runs one case file on `board`; the result is in `Run::result`.
pub fn run_case_bytes(board: &Board, elf: &Path, case: &[u8], timeout: Duration) -> Result<Run> {
    let dir = scratch_dir(board.name)?;
    std::fs::write(dir.join("case.bin"), case)?;
    let run = run_in(
        board,
        elf,
        &dir,
        &["case.bin", "result.bin"],
        Some("result.bin"),
        timeout,
    );
    let _ = std::fs::remove_dir_all(&dir);
    run
}

/// Runs a firmware command without files: `selftest` (simplify the built-in grid; exit 0),
/// `panic` (exit 101) or `fault` (HardFault, exit 102).
pub fn run_command(board: &Board, elf: &Path, command: &str, timeout: Duration) -> Result<Run> {
    let dir = scratch_dir(command)?;
    let run = run_in(board, elf, &dir, &[command], None, timeout);
    let _ = std::fs::remove_dir_all(&dir);
    run
}

/// Firmware exit status: the result file was written.
pub const EXIT_DONE: i32 = 0;

/// Firmware exit status: host file I/O through semihosting failed.
pub const EXIT_IO: i32 = 2;

/// Firmware exit status: panic.
pub const EXIT_PANIC: i32 = 101;

/// Firmware exit status: HardFault or an unexpected exception.
pub const EXIT_FAULT: i32 = 102;

/// A case run on a board and compared with the host reference.
/// Runs one case on `board`: the decoded outcome (if the firmware exited 0 and wrote a result)
/// and the run.
pub fn run_case(
    board: &Board,
    elf: &Path,
    case: &Case,
    timeout: Duration,
) -> Result<(Option<Outcome>, Run)> {
    let run = run_case_bytes(board, elf, &case.encode()?, timeout)?;
    let outcome = match (&run.result, run.ok()) {
        (Some(bytes), true) => Some(Outcome::decode(bytes)?),
        _ => None,
    };
    Ok((outcome, run))
}

/// Runs one progressive stream through the firmware on `board` (it reads the stream in small
/// pieces through semihosting); the output file (`meshfmt::pm`) is in `Run::result`.
pub fn run_stream_bytes(
    board: &Board,
    elf: &Path,
    stream: &[u8],
    timeout: Duration,
) -> Result<Run> {
    let dir = scratch_dir(board.name)?;
    std::fs::write(dir.join("stream.tdpm"), stream)?;
    let run = run_in(
        board,
        elf,
        &dir,
        &["stream.tdpm", "out.bin"],
        Some("out.bin"),
        timeout,
    );
    let _ = std::fs::remove_dir_all(&dir);
    run
}
