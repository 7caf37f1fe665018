//! The library on emulated Cortex-M cores: builds the firmware in `host-sim/firmware` for a
//! board, runs it under `qemu-system-arm`, decodes its defmt log, collects its result file and
//! compares it with the host reference ([`crate::golden`]). Also measures each board:
//! instructions (SysTick under `-icount shift=0`), stack high-water mark, image sizes and the
//! largest mesh it takes.
//!
//! `host-sim qemu` ([`Args`], [`run`]); `host-sim qemu --help` lists the modes. By hand (what
//! [`build`] and [`run_in`] do):
//!
//! ```text
//! cd host-sim/firmware
//! DEFMT_LOG=info cargo build --release --target thumbv7em-none-eabihf \
//!     --features board-mps2-an386 --target-dir target/mps2-an386
//! qemu-system-arm -machine mps2-an386 -nographic -monitor none -serial null -icount shift=0 \
//!     -semihosting-config enable=on,target=native,arg=fw,arg=case.bin,arg=result.bin \
//!     -kernel target/mps2-an386/thumbv7em-none-eabihf/release/tinydecimate-firmware > log.defmt
//! ```
//!
//! (no `-cpu`: the mps2 machines refuse any but their own). `case.bin` and `result.bin` are
//! relative to QEMU's working directory; paths must not contain spaces (semihosting joins the
//! arguments with spaces). `log.defmt` holds binary defmt frames: [`decode_defmt`].

use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode, Stdio};
use std::time::{Duration, Instant};

use anyhow::{anyhow, bail, Context, Result};
use meshfmt::{IndexType, Status};

use crate::golden::{self, Case, Outcome, Verdict};

/// An emulated board.
#[derive(Clone, Copy, Debug)]
pub struct Board {
    /// QEMU machine name, and the firmware's feature `board-<name>`.
    pub name: &'static str,
    /// The core.
    pub core: &'static str,
    /// Rust target.
    pub target: &'static str,
    /// RAM in bytes (the memory.x the firmware links with).
    pub ram: u32,
    /// Flash (code memory) in bytes.
    pub flash: u32,
    /// The core clock QEMU's SysTick counts, in Hz. Under `-icount shift=0` one instruction is
    /// 1 ns, so one tick is 1e9 / clock_hz instructions. Checked by [`calibrate`].
    pub clock_hz: u32,
}

/// The five boards, smallest first. QEMU 7.2+.
pub const BOARDS: [Board; 5] = [
    Board {
        name: "microbit",
        core: "Cortex-M0",
        target: "thumbv6m-none-eabi",
        ram: 16 << 10,
        flash: 256 << 10,
        clock_hz: 16_000_000,
    },
    Board {
        name: "lm3s6965evb",
        core: "Cortex-M3",
        target: "thumbv7m-none-eabi",
        ram: 64 << 10,
        flash: 256 << 10,
        clock_hz: 12_500_000,
    },
    Board {
        name: "mps2-an386",
        core: "Cortex-M4F",
        target: "thumbv7em-none-eabihf",
        ram: 4 << 20,
        flash: 4 << 20,
        clock_hz: 25_000_000,
    },
    Board {
        name: "mps2-an500",
        core: "Cortex-M7",
        target: "thumbv7em-none-eabihf",
        ram: 4 << 20,
        flash: 4 << 20,
        clock_hz: 25_000_000,
    },
    Board {
        name: "mps2-an505",
        core: "Cortex-M33",
        target: "thumbv8m.main-none-eabihf",
        ram: 4 << 20,
        flash: 4 << 20,
        clock_hz: 20_000_000,
    },
];

/// The reference board.
pub const REFERENCE_BOARD: &str = "mps2-an386";

/// Looks a board up by QEMU machine name.
pub fn board(name: &str) -> Result<&'static Board> {
    BOARDS.iter().find(|b| b.name == name).ok_or_else(|| {
        let names: Vec<_> = BOARDS.iter().map(|b| b.name).collect();
        anyhow!("unknown board {name:?}; boards: {}", names.join(", "))
    })
}

impl Board {
    /// Instructions per SysTick tick (exact for every board above).
    pub fn instructions_per_tick(&self) -> f64 {
        1e9 / f64::from(self.clock_hz)
    }
}

/// The firmware crate.
pub fn firmware_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("firmware")
}

/// Where [`build`] puts a board's image: one target directory per board, because two boards
/// share a Rust target (an386/an500) and would overwrite each other's image.
pub fn elf_path(board: &Board) -> PathBuf {
    firmware_dir()
        .join("target")
        .join(board.name)
        .join(board.target)
        .join("release")
        .join("tinydecimate-firmware")
}

/// Builds the firmware for `board` (release), with the library or (`with_library = false`)
/// as a boot/semihosting/defmt smoke test that echoes its input. Returns the ELF.
pub fn build(board: &Board, with_library: bool) -> Result<PathBuf> {
    let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    let mut cmd = Command::new(cargo);
    cmd.current_dir(firmware_dir())
        .args(["build", "--release", "--target", board.target])
        .arg("--features")
        .arg(format!("board-{}", board.name))
        .arg("--target-dir")
        .arg(firmware_dir().join("target").join(board.name))
        // Library debug logs stay out: they would cost instructions inside the measurement.
        .env("DEFMT_LOG", "info");
    if !with_library {
        cmd.arg("--no-default-features");
    }
    // When host-sim itself runs under cargo, these would leak into the firmware build.
    for var in [
        "CARGO_TARGET_DIR",
        "CARGO_BUILD_TARGET",
        "RUSTFLAGS",
        "CARGO_ENCODED_RUSTFLAGS",
        "CARGO_MANIFEST_DIR",
    ] {
        cmd.env_remove(var);
    }
    let status = cmd
        .status()
        .context("running cargo for the firmware (is the target installed? `rustup target add`)")?;
    if !status.success() {
        bail!("firmware build for {} failed ({status})", board.name);
    }
    let elf = elf_path(board);
    if !elf.exists() {
        bail!("firmware build succeeded but {} is missing", elf.display());
    }
    Ok(elf)
}

/// What one QEMU run gave.
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

/// The `qemu-system-arm` command line for `board`, with semihosting arguments `args`.
pub fn qemu_command(board: &Board, elf: &Path, args: &[&str]) -> Command {
    let mut sh = String::from("enable=on,target=native,arg=tinydecimate-firmware");
    for a in args {
        sh.push_str(",arg=");
        sh.push_str(a);
    }
    let mut cmd = Command::new("qemu-system-arm");
    cmd.args(["-machine", board.name])
        .args(["-nographic", "-monitor", "none", "-serial", "null"])
        // One instruction = 1 ns of virtual time: SysTick counts instructions, repeatably.
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
    let mut child = cmd
        .spawn()
        .context("starting qemu-system-arm (apt-get install qemu-system-arm)")?;
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
fn scratch_dir(tag: &str) -> Result<PathBuf> {
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

/// Decodes defmt frames (rzCOBS, as defmt-semihosting sends them) with the image's table.
pub fn decode_defmt(elf: &[u8], stream: &[u8]) -> Result<Vec<String>> {
    use defmt_decoder::{DecodeError, Table};
    let table = Table::parse(elf)?.ok_or_else(|| anyhow!("the image has no .defmt table"))?;
    let locations = table.get_locations(elf).unwrap_or_default();
    let mut decoder = table.new_stream_decoder();
    decoder.received(stream);
    let mut lines = Vec::new();
    loop {
        match decoder.decode() {
            Ok(frame) => {
                let loc = locations
                    .get(&frame.index())
                    .map(|l| {
                        let file = l.file.file_name().unwrap_or_default().to_string_lossy();
                        format!("  ({file}:{})", l.line)
                    })
                    .unwrap_or_default();
                lines.push(format!("{}{loc}", frame.display(false)));
            }
            Err(DecodeError::UnexpectedEof) => break,
            Err(DecodeError::Malformed) => {
                lines.push("<malformed defmt frame>".into());
                if !table.encoding().can_recover() {
                    break;
                }
            }
        }
    }
    Ok(lines)
}

/// A case run on a board and compared with the host reference.
#[derive(Debug)]
pub struct Checked {
    /// Case name.
    pub case: String,
    /// How the board's output relates to the reference.
    pub verdict: Verdict,
    /// The board's outcome (with measurements), if it wrote one.
    pub outcome: Option<Outcome>,
    /// The run.
    pub run: Run,
}

impl Checked {
    /// Instructions inside `Workspace::simplify`, from the SysTick ticks.
    pub fn instructions(&self, board: &Board) -> Option<u64> {
        let o = self.outcome.as_ref()?;
        Some((o.header.ticks as f64 * board.instructions_per_tick()).round() as u64)
    }
}

/// Runs `case` on `board` and compares with `expected` (the host reference if `None`).
pub fn check_case(
    board: &Board,
    elf: &Path,
    case: &Case,
    expected: Option<&Outcome>,
    timeout: Duration,
) -> Result<Checked> {
    let reference;
    let expected = match expected {
        Some(e) => e,
        None => {
            reference = golden::reference(case)?;
            &reference
        }
    };
    let run = run_case_bytes(board, elf, &case.encode()?, timeout)?;
    let outcome = match (&run.result, run.ok()) {
        (Some(bytes), true) => Some(Outcome::decode(bytes)?),
        _ => None,
    };
    let verdict = match &outcome {
        Some(o) => golden::compare(expected, o),
        None => Verdict::Mismatch(vec![format!("no result: {}", run.describe())]),
    };
    Ok(Checked {
        case: case.name.clone(),
        verdict,
        outcome,
        run,
    })
}

/// Builds the firmware for `board` and checks every case; prints one line per case.
/// Returns how many cases failed (mismatch or crash; "too big" is not a failure).
pub fn check_board(
    board: &Board,
    cases: &[Case],
    timeout: Duration,
    verbose: bool,
) -> Result<usize> {
    let elf = build(board, true)?;
    let mut failed = 0;
    for case in cases {
        let c = check_case(board, &elf, case, None, timeout)?;
        failed += print_checked(board, &c, verbose);
    }
    Ok(failed)
}

/// Image size by ELF section, in bytes.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Sizes {
    /// Allocated read-only sections plus the load image of `.data`: what goes into flash.
    pub flash: u64,
    /// `.data` + `.bss` + `.uninit`: static RAM.
    pub static_ram: u64,
    /// Of which `.text`.
    pub text: u64,
    /// Of which `.rodata`.
    pub rodata: u64,
    /// `.data`.
    pub data: u64,
    /// `.bss` + `.uninit`.
    pub bss: u64,
}

/// Section sizes of a 32-bit little-endian ELF (what `size -A` would print, summed).
pub fn elf_sizes(elf: &[u8]) -> Result<Sizes> {
    let u16_at = |o: usize| -> Result<u64> {
        Ok(u64::from(u16::from_le_bytes(
            elf.get(o..o + 2).context("truncated ELF")?.try_into()?,
        )))
    };
    let u32_at = |o: usize| -> Result<u64> {
        Ok(u64::from(u32::from_le_bytes(
            elf.get(o..o + 4).context("truncated ELF")?.try_into()?,
        )))
    };
    if elf.get(0..4) != Some(b"\x7fELF") || elf.get(4) != Some(&1) || elf.get(5) != Some(&1) {
        bail!("not a 32-bit little-endian ELF");
    }
    let shoff = u32_at(0x20)? as usize;
    let shentsize = u16_at(0x2e)? as usize;
    let shnum = u16_at(0x30)? as usize;
    let shstrndx = u16_at(0x32)? as usize;
    let sh = |i: usize, field: usize| u32_at(shoff + i * shentsize + field);
    let strtab = sh(shstrndx, 0x10)? as usize;
    let name_of = |i: usize| -> Result<String> {
        let start = strtab + sh(i, 0)? as usize;
        let end = elf[start..]
            .iter()
            .position(|&b| b == 0)
            .context("section name")?
            + start;
        Ok(String::from_utf8_lossy(&elf[start..end]).into_owned())
    };
    const SHT_NOBITS: u64 = 8;
    const SHF_WRITE: u64 = 1;
    const SHF_ALLOC: u64 = 2;
    let mut s = Sizes::default();
    for i in 0..shnum {
        let (ty, flags, size) = (sh(i, 4)?, sh(i, 8)?, sh(i, 0x14)?);
        if flags & SHF_ALLOC == 0 {
            continue;
        }
        let name = name_of(i)?;
        if ty == SHT_NOBITS {
            s.static_ram += size;
            s.bss += size;
        } else {
            s.flash += size;
            if flags & SHF_WRITE != 0 {
                s.static_ram += size;
                s.data += size;
            }
        }
        match name.as_str() {
            ".text" => s.text += size,
            ".rodata" => s.rodata += size,
            _ => {}
        }
    }
    Ok(s)
}

/// Runs the firmware's calibration loop (2 × 5 000 001 instructions) and returns the measured
/// instructions per tick. With `-icount shift=0` it equals `1e9 / clock_hz` up to rounding.
pub fn calibrate(board: &Board, elf: &Path) -> Result<f64> {
    let dir = scratch_dir("calibrate")?;
    let run = run_in(
        board,
        elf,
        &dir,
        &["calibrate", "cal.bin"],
        Some("cal.bin"),
        Duration::from_secs(60),
    )?;
    let _ = std::fs::remove_dir_all(&dir);
    let bytes = run
        .result
        .as_ref()
        .filter(|_| run.ok())
        .ok_or_else(|| anyhow!("calibration on {} failed: {}", board.name, run.describe()))?;
    let o = Outcome::decode(bytes)?;
    if o.header.ticks == 0 {
        bail!("SysTick did not count on {}", board.name);
    }
    Ok(f64::from(o.header.error_a) / o.header.ticks as f64)
}

/// What `host-sim qemu --measure` reports for one board.
#[derive(Clone, Debug)]
pub struct Measurement {
    /// Board.
    pub board: &'static Board,
    /// Image sizes.
    pub sizes: Sizes,
    /// Measured instructions per SysTick tick.
    pub instructions_per_tick: f64,
    /// Workspace bytes.
    pub workspace_bytes: u32,
    /// Stack available (RAM − static RAM).
    pub stack_available: u64,
    /// Capacity: vertices, u16 triangles.
    pub capacity: (u32, u32),
    /// Per case: name, triangles in → out, instructions, stack bytes in `simplify`,
    /// stack high-water mark from the top, verdict.
    pub cases: Vec<CaseMeasurement>,
}

/// One measured case.
#[derive(Clone, Debug)]
pub struct CaseMeasurement {
    /// Case name.
    pub name: String,
    /// Triangles in.
    pub triangles_in: u32,
    /// Triangles out.
    pub triangles_out: u32,
    /// Instructions inside `simplify`.
    pub instructions: u64,
    /// Stack used by `simplify` (below its caller's frame).
    pub stack_bytes: u32,
    /// Deepest stack use of the whole firmware so far.
    pub stack_high_water: u32,
    /// Matches the host reference.
    pub matches: bool,
    /// Host wall time of the QEMU run.
    pub wall: Duration,
}

/// Measures a board: sizes, calibration, the built-in cases and the largest grid it holds.
pub fn measure(board: &'static Board, timeout: Duration) -> Result<Measurement> {
    let elf = build(board, true)?;
    let sizes = elf_sizes(&std::fs::read(&elf)?)?;
    // The calibration loop carries a few instructions of overhead, so it measures slightly
    // over the exact figure; it only has to confirm the board's clock.
    let measured = calibrate(board, &elf)?;
    let ipt = board.instructions_per_tick();
    if (measured - ipt).abs() > ipt * 1e-3 {
        bail!(
            "{}: SysTick counts {measured:.4} instructions per tick, expected {ipt} \
             (QEMU not run with -icount shift=0, or another clock?)",
            board.name
        );
    }
    let mut cases = golden::builtin_cases();
    cases.retain(|c| c.name != "grid8-bad-index-u16");
    // Learn the capacity from a first run, then add the largest grid that fits.
    let probe = check_case(board, &elf, &cases[0], None, timeout)?;
    let head = probe
        .outcome
        .as_ref()
        .map(|o| o.header.clone())
        .ok_or_else(|| anyhow!("{} failed: {}", board.name, probe.run.describe()))?;
    let cap_v = head.capacity_vertices;
    let cap_t = head.capacity_triangles; // u16, the index type of cases[0]
    cases.push(golden::largest_grid_case(
        cap_v as usize,
        cap_t as usize,
        IndexType::U16,
    ));
    let mut out = Vec::new();
    let mut workspace_bytes = head.workspace_bytes;
    for case in &cases {
        let c = check_case(board, &elf, case, None, timeout)?;
        let Some(o) = &c.outcome else {
            bail!("{} / {}: {}", board.name, case.name, c.run.describe());
        };
        if o.header.status == Status::TooBig {
            continue;
        }
        workspace_bytes = o.header.workspace_bytes;
        out.push(CaseMeasurement {
            name: case.name.clone(),
            triangles_in: o.header.triangles_in,
            triangles_out: o.header.triangles_out,
            instructions: (o.header.ticks as f64 * ipt).round() as u64,
            stack_bytes: o.header.stack_bytes,
            stack_high_water: o.header.stack_high_water,
            matches: c.verdict == Verdict::Match,
            wall: c.run.wall,
        });
    }
    Ok(Measurement {
        board,
        stack_available: u64::from(board.ram).saturating_sub(sizes.static_ram),
        sizes,
        instructions_per_tick: ipt,
        workspace_bytes,
        capacity: (cap_v, cap_t),
        cases: out,
    })
}

/// Prints a measurement as a small table.
pub fn print_measurement(m: &Measurement) {
    let b = m.board;
    println!(
        "{} ({}, {}): flash {} B (text {}, rodata {}), static RAM {} B (workspace {}), stack {} B free of {} KB RAM",
        b.name,
        b.core,
        b.target,
        m.sizes.flash,
        m.sizes.text,
        m.sizes.rodata,
        m.sizes.static_ram,
        m.workspace_bytes,
        m.stack_available,
        b.ram >> 10
    );
    println!(
        "  capacity {} vertices / {} u16 triangles; {:.3} instructions per SysTick tick",
        m.capacity.0, m.capacity.1, m.instructions_per_tick
    );
    for c in &m.cases {
        println!(
            "  {:<28} {:>6} -> {:<6} {:>12} instr  stack {:>5} B (high-water {:>5} B)  {}  {:.2} s",
            c.name,
            c.triangles_in,
            c.triangles_out,
            c.instructions,
            c.stack_bytes,
            c.stack_high_water,
            if c.matches { "= host" } else { "DIFFERS" },
            c.wall.as_secs_f64()
        );
    }
}

/// `host-sim qemu ...`: runs the library on the emulated boards.
#[derive(Clone, Debug, clap::Args)]
pub struct Args {
    /// Board (QEMU machine) to use; repeat for several. Default: all five
    /// (microbit, lm3s6965evb, mps2-an386, mps2-an500, mps2-an505).
    #[arg(long = "board", value_name = "MACHINE")]
    pub boards: Vec<String>,
    /// Measure instructions (SysTick, -icount shift=0), stack high-water mark, image sizes and
    /// the largest mesh each board simplifies.
    #[arg(long)]
    pub measure: bool,
    /// Compare with the stored goldens (see --golden-dir) instead of a fresh host run.
    #[arg(long)]
    pub golden: bool,
    /// Recompute the built-in cases' goldens on the host and store them, then stop.
    #[arg(long)]
    pub bless: bool,
    /// Directory of the stored goldens (`<case>.case` + `<case>.golden`).
    #[arg(long, value_name = "DIR", default_value_os_t = golden::default_dir())]
    pub golden_dir: PathBuf,
    /// Run this mesh (.obj/.ply/.stl) instead of the built-in cases.
    #[arg(long)]
    pub mesh: Option<PathBuf>,
    /// With --mesh: target ratio.
    #[arg(long, default_value_t = 0.25)]
    pub ratio: f32,
    /// With --mesh: the paper's passes instead of the greedy schedule.
    #[arg(long)]
    pub passes: bool,
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

/// Runs `host-sim qemu`. Exit code 1 when a board differs from the reference or a run fails.
pub fn run(a: &Args) -> Result<ExitCode> {
    let boards: Vec<&'static Board> = if a.boards.is_empty() {
        BOARDS.iter().collect()
    } else {
        a.boards.iter().map(|n| board(n)).collect::<Result<_>>()?
    };
    let timeout = Duration::from_secs(a.timeout);
    let mut failed = 0usize;
    if a.bless {
        let n = golden::bless(&a.golden_dir)?;
        println!("wrote {n} cases to {}", a.golden_dir.display());
        return Ok(ExitCode::SUCCESS);
    }
    if a.measure {
        for b in &boards {
            print_measurement(&measure(b, timeout)?);
        }
    } else if a.smoke {
        let case = &golden::builtin_cases()[0];
        for b in &boards {
            let elf = build(b, false)?;
            let run = run_case_bytes(b, &elf, &case.encode()?, timeout)?;
            let echoed = match run.result.as_deref().filter(|_| run.ok()) {
                Some(bytes) => Outcome::decode(bytes)?.triangles == case.triangles,
                None => false,
            };
            failed += usize::from(!echoed);
            println!(
                "{:<12} echo {}",
                b.name,
                if echoed { "ok" } else { "FAILED" }
            );
            if a.verbose || !echoed {
                println!("    {}", run.describe().replace('\n', "\n    "));
            }
        }
    } else if a.handlers {
        for b in &boards {
            let elf = build(b, true)?;
            for (cmd, want) in [
                ("selftest", EXIT_DONE),
                ("panic", EXIT_PANIC),
                ("fault", EXIT_FAULT),
            ] {
                let run = run_command(b, &elf, cmd, timeout)?;
                let ok = run.exit_code == Some(want);
                failed += usize::from(!ok);
                println!(
                    "{:<12} {cmd:<9} {}",
                    b.name,
                    if ok { "ok" } else { "FAILED" }
                );
                if a.verbose || !ok {
                    println!("    {}", run.describe().replace('\n', "\n    "));
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
            println!(
                "{:<12} {:<9} {}",
                b.name,
                "missing",
                if ok { "ok" } else { "FAILED" }
            );
        }
    } else if a.golden {
        let stored = golden::load_dir(&a.golden_dir)?;
        for b in &boards {
            let elf = build(b, true)?;
            for s in &stored {
                let c = check_case(b, &elf, &s.case()?, Some(&s.golden), timeout)?;
                failed += print_checked(b, &c, a.verbose);
            }
        }
    } else {
        let cases = match &a.mesh {
            Some(path) => {
                let m = crate::io::load(path)?;
                let config = tinydecimate::Config::new()
                    .with_ratio(a.ratio)
                    .with_schedule(if a.passes {
                        tinydecimate::Schedule::Passes
                    } else {
                        tinydecimate::Schedule::Greedy
                    });
                vec![Case {
                    name: path
                        .file_stem()
                        .unwrap_or_default()
                        .to_string_lossy()
                        .into_owned(),
                    positions: m.positions,
                    triangles: m.triangles,
                    index_type: if a.u32 {
                        IndexType::U32
                    } else {
                        IndexType::U16
                    },
                    config,
                }]
            }
            None => golden::builtin_cases(),
        };
        for b in &boards {
            failed += check_board(b, &cases, timeout, a.verbose)?;
        }
    }
    Ok(if failed == 0 {
        ExitCode::SUCCESS
    } else {
        println!("{failed} failed");
        ExitCode::from(1)
    })
}

/// One line per checked case; returns 1 for a failure.
fn print_checked(board: &Board, c: &Checked, verbose: bool) -> usize {
    let (what, failed) = match &c.verdict {
        Verdict::Match => ("ok".to_string(), 0),
        Verdict::TooBig => ("too big for this board (skipped)".to_string(), 0),
        Verdict::Mismatch(d) => (format!("MISMATCH\n    {}", d.join("\n    ")), 1),
    };
    let instr = c
        .instructions(board)
        .map(|i| format!(", {i} instructions"))
        .unwrap_or_default();
    let stack = c
        .outcome
        .as_ref()
        .map(|o| format!(", stack {} B", o.header.stack_bytes))
        .unwrap_or_default();
    println!("{:<12} {:<28} {what}{instr}{stack}", board.name, c.case);
    if !c.run.stderr.trim().is_empty() && verbose {
        println!("    qemu: {}", c.run.stderr.trim());
    }
    if verbose || failed > 0 {
        for l in &c.run.log {
            println!("    | {l}");
        }
    }
    failed
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn boards_are_unique_and_known() {
        for (i, a) in BOARDS.iter().enumerate() {
            assert!(BOARDS[i + 1..].iter().all(|b| b.name != a.name));
            assert_eq!(board(a.name).unwrap().name, a.name);
        }
        assert!(board("nope").is_err());
        assert_eq!(board(REFERENCE_BOARD).unwrap().core, "Cortex-M4F");
    }

    #[test]
    fn qemu_command_line() {
        let b = board("mps2-an505").unwrap();
        let c = qemu_command(b, Path::new("fw.elf"), &["case.bin", "out.bin"]);
        let args: Vec<_> = c
            .get_args()
            .map(|a| a.to_string_lossy().into_owned())
            .collect();
        assert!(args.windows(2).any(|w| w == ["-machine", "mps2-an505"]));
        assert!(args.windows(2).any(|w| w == ["-icount", "shift=0"]));
        assert!(args
            .iter()
            .any(|a| a
                == "enable=on,target=native,arg=tinydecimate-firmware,arg=case.bin,arg=out.bin"));
        assert!(!args.iter().any(|a| a == "-cpu"));
    }
}
