//! The library on emulated Cortex-M and RISC-V cores: builds the firmware in `host-sim/firmware`
//! for a board, runs it under `qemu-system-arm` or `qemu-system-riscv32`, decodes its defmt log,
//! collects its result file and compares it with the golden files ([`crate::golden`],
//! `host-sim qemu --check`) or a fresh host run. Also measures each board (`--measure`):
//! instructions (SysTick, or RISC-V's `mcycle`, under `-icount shift=0`), stack high-water
//! mark, image sizes of the firmware and of the library alone, the flash of one instantiation
//! (the minimal firmware of `tests/flash`, as `scripts/flash.sh` builds it:
//! [`one_instantiation`]), and the largest mesh it simplifies.
//!
//! `host-sim qemu` ([`Args`], [`run`]); `host-sim qemu --help` lists the modes. By hand (what
//! [`build`] and [`run_in`] do):
//!
//! ```text
//! cd host-sim/firmware
//! DEFMT_LOG=info cargo build --release --target thumbv7em-none-eabihf \
//!     --features board-mps2-an386            # [,micromath]
//! qemu-system-arm -machine mps2-an386 -nographic -monitor none -serial null -icount shift=0 \
//!     -semihosting-config enable=on,target=native,arg=fw,arg=case.bin,arg=result.bin \
//!     -kernel target/thumbv7em-none-eabihf/release/tinydecimate-firmware > log.defmt
//! ```
//!
//! (no `-cpu`: the mps2 machines refuse any but their own). A RISC-V board (`virt`, no boot
//! firmware, the core without the extensions the part lacks):
//!
//! ```text
//! DEFMT_LOG=info cargo build --release --target riscv32imc-unknown-none-elf \
//!     --features board-riscv32imc-virt-400k
//! qemu-system-riscv32 -machine virt -bios none -cpu rv32,a=false,f=false,d=false \
//!     -nographic -monitor none -serial null -icount shift=0 \
//!     -semihosting-config enable=on,target=native,arg=fw,arg=case.bin,arg=result.bin \
//!     -kernel target/riscv32imc-unknown-none-elf/release/tinydecimate-firmware > log.defmt
//! ```
//!
//! `case.bin` and `result.bin` are
//! relative to QEMU's working directory; paths must not contain spaces (semihosting joins the
//! arguments with spaces). `log.defmt` holds binary defmt frames: [`decode_defmt`].

use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode, Stdio};
use std::time::{Duration, Instant};

use anyhow::{anyhow, bail, Context, Result};
use meshfmt::{IndexType, Status};

use crate::backend::Backend;
use crate::golden::{self, Case, Golden, Outcome, Verdict};
use crate::golden::stream::StreamCase;

pub mod cluster;

/// An emulated board.
#[derive(Clone, Copy, Debug)]
pub struct Board {
    /// Board name, and the firmware's feature `board-<name>` (the QEMU machine name for the
    /// Cortex-M boards).
    pub name: &'static str,
    /// The core.
    pub core: &'static str,
    /// Rust target.
    pub target: &'static str,
    /// QEMU's system emulator for the core ([`QEMU_ARM`], [`QEMU_RISCV32`]).
    pub qemu: &'static Qemu,
    /// QEMU `-machine`.
    pub machine: &'static str,
    /// More QEMU arguments (RISC-V: no boot firmware, and the core without the extensions the
    /// part lacks, so a stray floating-point or atomic instruction traps).
    pub qemu_args: &'static [&'static str],
    /// RAM in bytes (the memory.x the firmware links with).
    pub ram: u32,
    /// Flash (code memory) in bytes.
    pub flash: u32,
    /// The rate of the counter the firmware reads, in Hz: the core clock QEMU's SysTick counts
    /// on Cortex-M. Under `-icount shift=0` one instruction is 1 ns, so one tick is
    /// 1e9 / clock_hz instructions. On RISC-V the firmware reads `mcycle`, which QEMU's icount
    /// advances by one per instruction: 1 GHz. Checked by [`calibrate`].
    pub clock_hz: u32,
}

/// A QEMU system emulator and the Debian package that has it.
#[derive(Debug)]
pub struct Qemu {
    /// The program.
    pub program: &'static str,
    /// The Debian/Ubuntu package (`apt-get install`).
    pub package: &'static str,
}

/// QEMU's Arm system emulator (the Cortex-M boards).
pub static QEMU_ARM: Qemu = Qemu {
    program: "qemu-system-arm",
    package: "qemu-system-arm",
};

/// QEMU's 32-bit RISC-V system emulator (the RISC-V boards).
pub static QEMU_RISCV32: Qemu = Qemu {
    program: "qemu-system-riscv32",
    package: "qemu-system-misc",
};

/// The golden cases each board is expected to skip because their mesh does not fit its
/// buffers (host-sim/firmware/src/board.rs). `qemu --check` fails on any other skip (a board
/// whose buffers shrank would otherwise pass with its cases skipped) and on a listed case that
/// ran after all (the list is stale). The small-RAM boards (Cortex-M0 16 KB, Cortex-M3 64 KB,
/// the 32 KB RISC-V) are the only ones that skip; docs/devices.md names their cases. Checked against
/// the boards' capacities in the tests.
pub const EXPECTED_SKIPS: &[(&str, &[&str])] = &[
    ("microbit", MICROBIT_SKIPS),
    ("lm3s6965evb", LM3S_SKIPS),
    ("mps2-an386", &[]),
    ("mps2-an500", &[]),
    ("mps2-an505", &[]),
    ("riscv32imc-virt-400k", RISCV_400K_SKIPS),
    ("riscv32imac-virt-32k", RISCV_32K_SKIPS),
];
const MICROBIT_SKIPS: &[&str] = &[
    "plate-new-u16",
    "cow-new-u16",
    "grid12-stored-subset-u16",
    "grid12-stored-optimal-u16",
    "icosphere3-stored-optimal-u32",
    "fin8-stored-optimal-u16",
    "icosphere3-stored-subset-u32",
    "fin8-stored-subset-u16",
    "sphere2-bound-u16",
    "icosphere3-bound-u32",
    "fin10-bound-paper-u32",
    "pm-grid8",
    "pm-cow-quantised",
];
/// No RAM for stored quadrics on the micro:bit and the lm3s6965evb (firmware
/// `board::QUADRIC_VERTICES` = 0), so none for the bounded cases either (they borrow it); the
/// cow's progressive stream needs the 4 MB boards.
const LM3S_SKIPS: &[&str] = &[
    "cow-new-u16",
    "grid12-stored-subset-u16",
    "grid12-stored-optimal-u16",
    "icosphere3-stored-optimal-u32",
    "fin8-stored-optimal-u16",
    "icosphere3-stored-subset-u32",
    "fin8-stored-subset-u16",
    "sphere2-bound-u16",
    "icosphere3-bound-u32",
    "fin10-bound-paper-u32",
    "pm-cow-quantised",
];

/// The 400 KB RISC-V board holds every case (its buffers are sized for the cow's stream).
const RISCV_400K_SKIPS: &[&str] = &[];
/// The 32 KB RISC-V board: the micro:bit's list less the 9 x 9 grid's stream (100 splits fit);
/// no RAM for stored quadrics or bounds, and the plate and the cow are too big.
const RISCV_32K_SKIPS: &[&str] = &[
    "plate-new-u16",
    "cow-new-u16",
    "grid12-stored-subset-u16",
    "grid12-stored-optimal-u16",
    "icosphere3-stored-optimal-u32",
    "fin8-stored-optimal-u16",
    "icosphere3-stored-subset-u32",
    "fin8-stored-subset-u16",
    "sphere2-bound-u16",
    "icosphere3-bound-u32",
    "fin10-bound-paper-u32",
    "pm-cow-quantised",
];

/// Whether `board` is expected to skip `case` ([`EXPECTED_SKIPS`]).
pub fn expected_skip(board: &str, case: &str) -> bool {
    EXPECTED_SKIPS
        .iter()
        .any(|(b, cases)| *b == board && cases.contains(&case))
}

/// A board's verdict on a case, held against [`EXPECTED_SKIPS`]: an unexpected skip, or an
/// expected skip that ran identically, becomes a failure.
pub fn against_expected_skips(board: &str, case: &str, v: Verdict) -> Verdict {
    match v {
        Verdict::Skipped(why) if !expected_skip(board, case) => Verdict::Failed(format!(
            "skipped, but not an expected skip of {board} (qemu::EXPECTED_SKIPS): {why}"
        )),
        Verdict::Identical if expected_skip(board, case) => Verdict::Failed(format!(
            "ran, but listed as an expected skip of {board} in qemu::EXPECTED_SKIPS: update the list"
        )),
        v => v,
    }
}

/// The boards: five Cortex-M, smallest first, then two RISC-V. QEMU 7.2+.
pub const BOARDS: [Board; 7] = [
    Board {
        name: "microbit",
        core: "Cortex-M0",
        target: "thumbv6m-none-eabi",
        qemu: &QEMU_ARM,
        machine: "microbit",
        qemu_args: &[],
        ram: 16 << 10,
        flash: 256 << 10,
        clock_hz: 16_000_000,
    },
    Board {
        name: "lm3s6965evb",
        core: "Cortex-M3",
        target: "thumbv7m-none-eabi",
        qemu: &QEMU_ARM,
        machine: "lm3s6965evb",
        qemu_args: &[],
        ram: 64 << 10,
        flash: 256 << 10,
        clock_hz: 12_500_000,
    },
    Board {
        name: "mps2-an386",
        core: "Cortex-M4F",
        target: "thumbv7em-none-eabihf",
        qemu: &QEMU_ARM,
        machine: "mps2-an386",
        qemu_args: &[],
        ram: 4 << 20,
        flash: 4 << 20,
        clock_hz: 25_000_000,
    },
    Board {
        name: "mps2-an500",
        core: "Cortex-M7",
        target: "thumbv7em-none-eabihf",
        qemu: &QEMU_ARM,
        machine: "mps2-an500",
        qemu_args: &[],
        ram: 4 << 20,
        flash: 4 << 20,
        clock_hz: 25_000_000,
    },
    Board {
        name: "mps2-an505",
        core: "Cortex-M33",
        target: "thumbv8m.main-none-eabihf",
        qemu: &QEMU_ARM,
        machine: "mps2-an505",
        qemu_args: &[],
        ram: 4 << 20,
        flash: 4 << 20,
        clock_hz: 20_000_000,
    },
    // An ESP32-C3-class part: rv32imc, no FPU, 400 KB of RAM (the linker's RAM region; QEMU's
    // virt has more). Its flash is external (4 MB on most modules).
    Board {
        name: "riscv32imc-virt-400k",
        core: "RISC-V rv32imc",
        target: "riscv32imc-unknown-none-elf",
        qemu: &QEMU_RISCV32,
        machine: "virt",
        qemu_args: &["-bios", "none", "-cpu", "rv32,a=false,f=false,d=false"],
        ram: 400 << 10,
        flash: 4 << 20,
        clock_hz: 1_000_000_000,
    },
    // A GD32VF103-class part: rv32imac, no FPU, 32 KB of RAM, 128 KB of flash.
    Board {
        name: "riscv32imac-virt-32k",
        core: "RISC-V rv32imac",
        target: "riscv32imac-unknown-none-elf",
        qemu: &QEMU_RISCV32,
        machine: "virt",
        qemu_args: &["-bios", "none", "-cpu", "rv32,f=false,d=false"],
        ram: 32 << 10,
        flash: 128 << 10,
        clock_hz: 1_000_000_000,
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
    /// Instructions per timer tick (exact for every board above).
    pub fn instructions_per_tick(&self) -> f64 {
        1e9 / f64::from(self.clock_hz)
    }
}

/// The firmware crate.
pub fn firmware_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("firmware")
}

/// The firmware's target directory (also what `cargo build` in `host-sim/firmware` uses): one
/// for every board and backend, so dependencies are built once per Rust target.
pub fn firmware_target_dir() -> PathBuf {
    firmware_dir().join("target")
}

/// Where [`build`] keeps a board's image: `target/images/<board>-<backend>[-nolib].elf`. Cargo
/// leaves one `tinydecimate-firmware` per Rust target, which the next build for another board
/// of the same target (an386/an500) or another backend overwrites, so each image is copied
/// out right after its build.
pub fn elf_path(board: &Board, backend: Backend, with_library: bool) -> PathBuf {
    firmware_target_dir().join("images").join(format!(
        "{}-{}{}.elf",
        board.name,
        backend,
        if with_library { "" } else { "-nolib" }
    ))
}

/// Builds the firmware for `board` (release) with the library on `backend`, or
/// (`with_library = false`) as a boot/semihosting/defmt smoke test that echoes its input.
/// Returns the image.
pub fn build(board: &Board, backend: Backend, with_library: bool) -> Result<PathBuf> {
    let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    let mut features = format!("board-{}", board.name);
    if backend == Backend::Micromath {
        features.push_str(",micromath");
    }
    let mut cmd = Command::new(cargo);
    cmd.current_dir(firmware_dir())
        .args(["build", "--release", "--target", board.target])
        // Only the collapse image (the clustering one is `qemu_cluster::build`'s).
        .args(["--bin", "tinydecimate-firmware", "--features", &features])
        .arg("--target-dir")
        .arg(firmware_target_dir())
        // Library debug logs stay out: they would cost instructions inside the measurement.
        .env("DEFMT_LOG", "info");
    if !with_library {
        cmd.arg("--no-default-features");
    }
    // When host-sim itself runs under cargo, these would leak into the firmware build.
    isolate(&mut cmd);
    let status = cmd
        .status()
        .context("running cargo for the firmware (is the target installed? `rustup target add`)")?;
    if !status.success() {
        bail!(
            "firmware build for {} ({backend}) failed ({status})",
            board.name
        );
    }
    let built = firmware_target_dir()
        .join(board.target)
        .join("release")
        .join("tinydecimate-firmware");
    let elf = elf_path(board, backend, with_library);
    std::fs::create_dir_all(elf.parent().expect("has a parent"))?;
    std::fs::copy(&built, &elf)
        .with_context(|| format!("copying {} to {}", built.display(), elf.display()))?;
    Ok(elf)
}

/// The minimal firmware that measures the flash of one instantiation (`tests/flash`, also
/// built by `scripts/flash.sh`).
pub fn flash_crate_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("host-sim sits in the repository")
        .join("tests/flash")
}

/// Its target directory: the one `scripts/flash.sh` uses by default, so both share builds and
/// `images/`.
pub fn flash_target_dir() -> PathBuf {
    flash_crate_dir().join("target")
}

/// What [`one_instantiation`] measures, as `scripts/flash.sh` describes its first row.
pub const ONE_INSTANTIATION: &str =
    "Workspace<u16, 512, 1024>::simplify, u16 triangles, Config::new(); opt-level s, fat LTO";

/// Builds `tests/flash` for `target` with its own release profile (opt-level "s", fat LTO, one
/// codegen unit, panic = abort) without or with the feature `call`, on `backend`, exactly as
/// `scripts/flash.sh` does. Returns the image, copied to
/// `tests/flash/target/images/<target>-<without|call>[-micromath].elf` (the script's names).
pub fn build_flash(target: &str, backend: Backend, call: bool) -> Result<PathBuf> {
    let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    let mut features = Vec::new();
    if call {
        features.push("call");
    }
    if backend == Backend::Micromath {
        features.push("micromath");
    }
    let mut cmd = Command::new(cargo);
    cmd.current_dir(flash_crate_dir())
        .args(["build", "--release", "--quiet", "--target", target])
        .arg("--target-dir")
        .arg(flash_target_dir());
    if !features.is_empty() {
        cmd.args(["--features", &features.join(",")]);
    }
    isolate(&mut cmd);
    let status = cmd.status().context("running cargo for tests/flash")?;
    if !status.success() {
        bail!("tests/flash build for {target} ({backend}) failed ({status})");
    }
    let built = flash_target_dir()
        .join(target)
        .join("release")
        .join("tinydecimate-flash");
    let elf = flash_target_dir().join("images").join(format!(
        "{target}-{}{}.elf",
        if call { "call" } else { "without" },
        if backend == Backend::Micromath {
            "-micromath"
        } else {
            ""
        }
    ));
    std::fs::create_dir_all(elf.parent().expect("has a parent"))?;
    std::fs::copy(&built, &elf)
        .with_context(|| format!("copying {} to {}", built.display(), elf.display()))?;
    Ok(elf)
}

/// The flash of one instantiation on `target`: `.text + .rodata` of the minimal firmware without
/// and with the call ([`build_flash`]); the library is the difference. The same figure as
/// `scripts/flash.sh`.
pub fn one_instantiation(target: &str, backend: Backend) -> Result<(u64, u64)> {
    let code = |call| -> Result<u64> {
        let s = elf_sizes(&std::fs::read(build_flash(target, backend, call)?)?)?;
        Ok(s.text + s.rodata)
    };
    Ok((code(false)?, code(true)?))
}

/// Whether `program --version` runs.
fn runs(program: &str, arg: &str) -> bool {
    Command::new(program)
        .arg(arg)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .is_ok_and(|s| s.success())
}

/// Makes sure the tools for `boards` are there, on a fresh machine too:
///
/// * the Rust targets of the boards: missing ones are installed with `rustup target add`
///   (harmless, per-user);
/// * the boards' QEMU (`qemu-system-arm`, `qemu-system-riscv32`): if one is missing, and
///   running as root with `CI` set (a throw-away CI machine), `apt-get install -y <package>` is
///   run; otherwise the exact install command is printed and the caller should exit with
///   status 2 (`Ok(Some(2))`): installing system packages is the user's call.
pub fn preflight(boards: &[&Board]) -> Result<Option<ExitCode>> {
    let mut targets: Vec<&str> = boards.iter().map(|b| b.target).collect();
    targets.sort_unstable();
    targets.dedup();
    let installed = Command::new("rustup")
        .args(["target", "list", "--installed"])
        .output();
    match installed {
        Ok(out) if out.status.success() => {
            let have = String::from_utf8_lossy(&out.stdout).into_owned();
            let missing: Vec<&str> = targets
                .iter()
                .copied()
                .filter(|t| !have.lines().any(|l| l.trim() == *t))
                .collect();
            if !missing.is_empty() {
                eprintln!(
                    "installing Rust targets: rustup target add {}",
                    missing.join(" ")
                );
                let ok = Command::new("rustup")
                    .args(["target", "add"])
                    .args(&missing)
                    .status()
                    .is_ok_and(|s| s.success());
                if !ok {
                    bail!("`rustup target add {}` failed", missing.join(" "));
                }
            }
        }
        _ => eprintln!(
            "warning: rustup not found; the firmware needs the Rust targets {} installed",
            targets.join(", ")
        ),
    }
    let mut qemus: Vec<&Qemu> = Vec::new();
    for b in boards {
        if !qemus.iter().any(|q| q.program == b.qemu.program) {
            qemus.push(b.qemu);
        }
    }
    let missing: Vec<&Qemu> = qemus
        .into_iter()
        .filter(|q| !runs(q.program, "--version"))
        .collect();
    if missing.is_empty() {
        return Ok(None);
    }
    let programs: Vec<&str> = missing.iter().map(|q| q.program).collect();
    let packages: Vec<&str> = missing.iter().map(|q| q.package).collect();
    let root = Command::new("id")
        .arg("-u")
        .output()
        .is_ok_and(|o| String::from_utf8_lossy(&o.stdout).trim() == "0");
    if root && std::env::var_os("CI").is_some() && runs("apt-get", "--version") {
        eprintln!(
            "{} missing; CI as root: apt-get install -y {}",
            programs.join(", "),
            packages.join(" ")
        );
        let ok = Command::new("apt-get")
            .args(["update", "-qq"])
            .status()
            .is_ok_and(|s| s.success())
            && Command::new("apt-get")
                .args(["install", "-y", "-qq"])
                .args(&packages)
                .env("DEBIAN_FRONTEND", "noninteractive")
                .status()
                .is_ok_and(|s| s.success());
        if ok && programs.iter().all(|p| runs(p, "--version")) {
            return Ok(None);
        }
        bail!("apt-get install {} failed", packages.join(" "));
    }
    eprintln!(
        "error: {} (QEMU's system emulator, 7.2 or newer) is not installed.\n\
         Install it with:\n\n    sudo apt-get install {}\n\n\
         (Debian/Ubuntu; Fedora: sudo dnf install {}; macOS: brew install qemu),\n\
         then run this command again.",
        programs.join(", "),
        packages.join(" "),
        programs.join(" ")
    );
    Ok(Some(ExitCode::from(2)))
}

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

/// The QEMU command line for `board`, with semihosting arguments `args`.
pub fn qemu_command(board: &Board, elf: &Path, args: &[&str]) -> Command {
    let mut sh = String::from("enable=on,target=native,arg=tinydecimate-firmware");
    for a in args {
        sh.push_str(",arg=");
        sh.push_str(a);
    }
    let mut cmd = Command::new(board.qemu.program);
    cmd.args(["-machine", board.machine])
        .args(board.qemu_args)
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

/// `host-sim run-elf ELF`: the Cargo runner of the firmware example (examples/cortex-m4f).
#[derive(Clone, Debug, clap::Args)]
pub struct RunElfArgs {
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
pub fn run_elf(a: &RunElfArgs) -> Result<ExitCode> {
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

impl Board {
    /// Instructions in `ticks` timer ticks.
    pub fn instructions(&self, ticks: u64) -> u64 {
        (ticks as f64 * self.instructions_per_tick()).round() as u64
    }
}

/// What the boards' outputs are compared with.
#[derive(Clone, Debug)]
pub enum Expected {
    /// The golden files in this directory (`<backend>/<case>.txt|.bin`); the host is checked
    /// against them too.
    Golden(PathBuf),
    /// A fresh run of the library on the host.
    Host,
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

/// Runs `cases` and the progressive `streams` on the host and on every board in `boards` and
/// compares each output with the expectation. Prints a table cases × (host, boards) of identical / skipped / DIFF / FAILED,
/// then a line for every cell that is not identical (board, case, first differing triangle or
/// why it was skipped). Returns how many cells are DIFF or FAILED.
pub fn check(
    boards: &[&'static Board],
    backend: Backend,
    cases: &[Case],
    streams: &[StreamCase],
    expected: &Expected,
    timeout: Duration,
    verbose: bool,
) -> Result<usize> {
    let mut expect: Vec<Option<Golden>> = Vec::new();
    let mut host = Vec::new();
    for case in cases {
        let now = golden::reference(case)?;
        match expected {
            Expected::Golden(dir) => match Golden::load(dir, backend, &case.name)? {
                Some(g) => {
                    host.push(golden::judge(case, backend, &g, &now)?);
                    expect.push(Some(g));
                }
                None => {
                    host.push(Verdict::Failed(format!(
                        "no golden files {}/{backend}/{}.txt|.bin",
                        dir.display(),
                        case.name
                    )));
                    expect.push(None);
                }
            },
            Expected::Host => {
                host.push(Verdict::Identical);
                expect.push(Some(Golden::from_outcome(case, backend, &now)?));
            }
        }
    }
    // Stream cases: golden files only.
    let mut stream_expect: Vec<Option<Golden>> = Vec::new();
    for sc in streams {
        let now = crate::golden::stream::reference(sc);
        let dir = match expected {
            Expected::Golden(dir) => dir,
            Expected::Host => bail!("stream cases are checked against golden files only"),
        };
        match Golden::load(dir, backend, sc.name())? {
            Some(g) => {
                host.push(crate::golden::stream::judge(sc, backend, &g, &now));
                stream_expect.push(Some(g));
            }
            None => {
                host.push(Verdict::Failed(format!(
                    "no golden files {}/{backend}/{}.txt|.bin",
                    dir.display(),
                    sc.name()
                )));
                stream_expect.push(None);
            }
        }
    }
    let names: Vec<&str> = cases
        .iter()
        .map(|c| c.name.as_str())
        .chain(streams.iter().map(|c| c.name()))
        .collect();
    let mut columns: Vec<(String, Vec<Verdict>)> = vec![("host".into(), host)];
    for b in boards {
        let t0 = Instant::now();
        // A failed build or QEMU start fails this board's column, not the whole check.
        let elf = match build(b, backend, true) {
            Ok(elf) => elf,
            Err(e) => {
                let why = format!("firmware build failed: {e:#}");
                eprintln!("{:<20} {why}", b.name);
                columns.push((
                    b.name.to_string(),
                    names.iter().map(|_| Verdict::Failed(why.clone())).collect(),
                ));
                continue;
            }
        };
        let built = t0.elapsed();
        let mut col = Vec::new();
        for (case, exp) in cases.iter().zip(&expect) {
            let v = match (run_case(b, &elf, case, timeout), exp) {
                (Err(e), _) => Verdict::Failed(format!("{e:#}")),
                (Ok((None, run)), _) => Verdict::Failed(format!("no result: {}", run.describe())),
                (Ok((Some(o), run)), Some(g)) => {
                    if verbose {
                        crate::outln!("{} / {}: {}", b.name, case.name, run.describe());
                    }
                    golden::judge(case, backend, g, &o)?
                }
                (Ok(_), None) => Verdict::Failed("no golden files".into()),
            };
            col.push(against_expected_skips(b.name, &case.name, v));
        }
        for (sc, exp) in streams.iter().zip(&stream_expect) {
            let v = match (run_stream_bytes(b, &elf, &sc.stream, timeout), exp) {
                (Err(e), _) => Verdict::Failed(format!("{e:#}")),
                (Ok(run), Some(g)) => match (&run.result, run.ok()) {
                    (Some(out), true) => {
                        if verbose {
                            crate::outln!("{} / {}: {}", b.name, sc.name(), run.describe());
                        }
                        crate::golden::stream::judge(sc, backend, g, out)
                    }
                    _ => Verdict::Failed(format!("no result: {}", run.describe())),
                },
                (Ok(_), None) => Verdict::Failed("no golden files".into()),
            };
            col.push(against_expected_skips(b.name, sc.name(), v));
        }
        eprintln!(
            "{:<20} firmware ({backend}) built in {:.1} s, {} cases run in {:.1} s",
            b.name,
            built.as_secs_f64(),
            names.len(),
            (t0.elapsed() - built).as_secs_f64()
        );
        columns.push((b.name.to_string(), col));
    }

    let what = match expected {
        Expected::Golden(dir) => format!("golden files {}/{backend}", dir.display()),
        Expected::Host => format!("the library on the host ({backend})"),
    };
    crate::outln!("\ncases x boards, compared with {what}:\n");
    let name_w = names.iter().map(|n| n.len()).max().unwrap_or(4).max(4);
    let col_w: Vec<usize> = columns.iter().map(|(n, _)| n.len().max(9)).collect();
    let mut line = format!("{:<name_w$}", "case");
    for ((n, _), w) in columns.iter().zip(&col_w) {
        line.push_str(&format!("  {n:<w$}"));
    }
    crate::outln!("{}", line.trim_end());
    for (i, name) in names.iter().enumerate() {
        let mut line = format!("{name:<name_w$}");
        for ((_, col), w) in columns.iter().zip(&col_w) {
            line.push_str(&format!("  {:<w$}", col[i].cell()));
        }
        crate::outln!("{}", line.trim_end());
    }
    let (mut same, mut skipped, mut failed) = (0, 0, 0);
    let mut details = Vec::new();
    for (n, col) in &columns {
        for (case, v) in names.iter().zip(col) {
            match v {
                Verdict::Identical => same += 1,
                Verdict::Skipped(why) => {
                    skipped += 1;
                    details.push(format!("skipped  {n} / {case}: {why}"));
                }
                Verdict::Diff(d) => {
                    failed += 1;
                    details.push(format!(
                        "DIFF     {n} / {case}: {}",
                        d.join("\n           ")
                    ));
                }
                Verdict::Failed(why) => {
                    failed += 1;
                    details.push(format!(
                        "FAILED   {n} / {case}: {}",
                        why.replace('\n', "\n           ")
                    ));
                }
            }
        }
    }
    crate::outln!();
    for d in &details {
        crate::outln!("{d}");
    }
    crate::outln!(
        "{backend}: {same} identical, {skipped} skipped (too big for the board), {failed} DIFF or FAILED"
    );
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
        // riscv-rt's link.x marks the free RAM as `.heap` and `.stack` (NOLOAD): not statics.
        if name == ".heap" || name == ".stack" {
            continue;
        }
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
        bail!("the timer did not count on {}", board.name);
    }
    Ok(f64::from(o.header.error_a) / o.header.ticks as f64)
}

/// What `host-sim qemu --measure` reports for one board.
#[derive(Clone, Debug)]
pub struct Measurement {
    /// Board.
    pub board: &'static Board,
    /// Math backend.
    pub backend: Backend,
    /// Image sizes of the firmware with the library.
    pub sizes: Sizes,
    /// Image sizes of the same firmware without the library (it echoes its input).
    pub sizes_without: Sizes,
    /// Flash of one instantiation on the board's target ([`one_instantiation`]): `.text +
    /// .rodata` of the minimal firmware without and with the call.
    pub instantiation: (u64, u64),
    /// Measured instructions per timer tick.
    pub instructions_per_tick: f64,
    /// Workspace bytes (the library's static RAM on this board).
    pub workspace_bytes: u32,
    /// Capacity: vertices, u16 triangles, u32 triangles.
    pub capacity: (u32, u32, u32),
    /// Per case.
    pub cases: Vec<CaseMeasurement>,
    /// The largest mesh, per index type.
    pub largest: Vec<Largest>,
    /// The golden progressive streams, decoded on the board.
    pub streams: Vec<StreamMeasurement>,
}

/// One golden stream decoded on a board (`meshfmt::pm::run`).
#[derive(Clone, Debug)]
pub struct StreamMeasurement {
    /// Case name.
    pub name: String,
    /// Vertex splits received, and the trailer's tick counts converted to instructions:
    /// decoding, coarsening every level, refining every level.
    pub splits: u32,
    /// See `splits`.
    pub decode: u64,
    /// See `splits`.
    pub coarsen: u64,
    /// See `splits`.
    pub refine: u64,
    /// Stack of the run.
    pub stack_bytes: u32,
    /// identical / skipped / DIFF / FAILED against the golden files.
    pub verdict: &'static str,
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
    /// Collapses.
    pub collapses: u32,
    /// Instructions inside `Workspace::simplify`.
    pub instructions: u64,
    /// Stack used by the library (below its caller's frame).
    pub stack_bytes: u32,
    /// Deepest stack use of the whole firmware, from the top of the stack.
    pub stack_high_water: u32,
    /// `identical` to the host, `skipped` (too big), `DIFF` or `FAILED`.
    pub verdict: &'static str,
    /// Why it was skipped or failed.
    pub note: String,
}

/// The largest mesh a board simplifies, found by bisection.
#[derive(Clone, Debug)]
pub struct Largest {
    /// Index type of the probes.
    pub index_type: IndexType,
    /// Largest success: vertices, triangles, instructions.
    pub ok: Option<(usize, usize, u64)>,
    /// Smallest failure: vertices, triangles, why.
    pub fail: Option<(usize, usize, String)>,
    /// QEMU runs.
    pub probes: u32,
    /// Host time of the search.
    pub wall: Duration,
}

/// The generated mesh of the capacity search: `strip T` (exactly `t` triangles, ≈ t/2
/// vertices), simplified with `Config::new()`.
pub fn probe_case(t: usize, index_type: IndexType) -> Case {
    let m = meshfmt::golden::strip(t);
    Case {
        name: format!("strip-{t}"),
        mesh: format!("strip {t}"),
        positions: m.positions,
        triangles: m.triangles,
        index_type,
        config: tinydecimate::Config::new(),
        stored: None,
    }
}

/// One capacity probe: `Ok((vertices, triangles, instructions))` if the board simplified
/// it, `Err((vertices, why))` if not.
type Probe = std::result::Result<(usize, usize, u64), (usize, String)>;

/// Bisects the triangle count of [`probe_case`] until a run fails (the mesh does not fit, the
/// library reports an error, or the firmware crashes or times out). Nothing is assumed about
/// the board's capacity: doubling from 64 triangles finds a failure, bisection the boundary.
pub fn largest_mesh(
    board: &Board,
    elf: &Path,
    index_type: IndexType,
    timeout: Duration,
) -> Result<Largest> {
    const LIMIT: usize = 4_000_000;
    let t0 = Instant::now();
    let mut probes = 0;
    let mut probe = |t: usize| -> Result<Probe> {
        probes += 1;
        let case = probe_case(t, index_type);
        let v = case.positions.len();
        if index_type == IndexType::U16 && v > 1 << 16 {
            return Ok(Err((v, "more vertices than u16 indices reach".into())));
        }
        let (outcome, run) = run_case(board, elf, &case, timeout)?;
        Ok(match outcome {
            Some(o) if o.header.status == Status::Ok => {
                Ok((v, t, board.instructions(o.header.ticks)))
            }
            Some(o) if o.header.status == Status::TooBig => Err((
                v,
                format!(
                    "too big for the buffers (holds {} vertices, {} triangles)",
                    o.header.capacity_vertices, o.header.capacity_triangles
                ),
            )),
            Some(o) => Err((
                v,
                format!("{:?} {:?}", o.header.status, o.header.error_kind),
            )),
            None => Err((
                v,
                format!(
                    "firmware exit {:?}{}",
                    run.exit_code,
                    if run.timed_out { " (timed out)" } else { "" }
                ),
            )),
        })
    };
    let (mut ok, mut lo) = (None, 0usize);
    let mut fail = None;
    let mut t = 64usize;
    loop {
        match probe(t)? {
            Ok(r) => {
                ok = Some(r);
                lo = t;
                if t >= LIMIT {
                    break;
                }
                t = (t * 2).min(LIMIT);
            }
            Err((v, why)) => {
                fail = Some((v, t, why));
                break;
            }
        }
    }
    if let Some((_, mut hi, _)) = fail {
        while hi - lo > 1 {
            let mid = lo + (hi - lo) / 2;
            match probe(mid)? {
                Ok(r) => {
                    ok = Some(r);
                    lo = mid;
                }
                Err((v, why)) => {
                    fail = Some((v, mid, why));
                    hi = mid;
                }
            }
        }
    }
    Ok(Largest {
        index_type,
        ok,
        fail,
        probes,
        wall: t0.elapsed(),
    })
}

/// Measures a board: image sizes with and without the library, calibration, every case of the
/// manifest (compared with a fresh host run), and the largest mesh per index type.
pub fn measure(
    board: &'static Board,
    backend: Backend,
    cases: &[Case],
    stream_cases: &[StreamCase],
    timeout: Duration,
) -> Result<Measurement> {
    let without = build(board, backend, false)?;
    let sizes_without = elf_sizes(&std::fs::read(&without)?)?;
    let elf = build(board, backend, true)?;
    let sizes = elf_sizes(&std::fs::read(&elf)?)?;
    let instantiation = one_instantiation(board.target, backend)?;
    // The calibration loop carries a few instructions of overhead, so it measures slightly
    // over the exact figure; it only has to confirm the board's clock.
    let measured = calibrate(board, &elf)?;
    let ipt = board.instructions_per_tick();
    if (measured - ipt).abs() > ipt * 1e-3 {
        bail!(
            "{}: the timer counts {measured:.4} instructions per tick, expected {ipt} \
             (QEMU not run with -icount shift=0, or another clock?)",
            board.name
        );
    }
    let mut out = Vec::new();
    let (mut workspace_bytes, mut capacity) = (0, (0, 0, 0));
    for case in cases {
        let expected = Golden::from_outcome(case, backend, &golden::reference(case)?)?;
        let (outcome, run) = run_case(board, &elf, case, timeout)?;
        let Some(o) = outcome else {
            out.push(CaseMeasurement {
                name: case.name.clone(),
                triangles_in: case.triangles.len() as u32,
                triangles_out: 0,
                collapses: 0,
                instructions: 0,
                stack_bytes: 0,
                stack_high_water: 0,
                verdict: "FAILED",
                note: run.describe(),
            });
            continue;
        };
        let h = &o.header;
        if h.status != Status::TooBig {
            workspace_bytes = h.workspace_bytes;
        }
        let it_cap = h.capacity_triangles;
        match case.index_type {
            IndexType::U16 => capacity = (h.capacity_vertices, it_cap, capacity.2),
            IndexType::U32 => capacity = (h.capacity_vertices, capacity.1, it_cap),
        }
        let v = golden::judge(case, backend, &expected, &o)?;
        out.push(CaseMeasurement {
            name: case.name.clone(),
            triangles_in: h.triangles_in,
            triangles_out: h.triangles_out,
            collapses: h.collapses,
            instructions: board.instructions(h.ticks),
            stack_bytes: h.stack_bytes,
            stack_high_water: h.stack_high_water,
            verdict: v.cell(),
            note: match &v {
                Verdict::Skipped(w) | Verdict::Failed(w) => w.clone(),
                Verdict::Diff(d) => d.join("; "),
                Verdict::Identical => String::new(),
            },
        });
    }
    let mut largest = Vec::new();
    for it in [IndexType::U16, IndexType::U32] {
        let l = largest_mesh(board, &elf, it, timeout)?;
        eprintln!(
            "{}: largest {} mesh found in {} QEMU runs, {:.1} s",
            board.name,
            if it == IndexType::U16 { "u16" } else { "u32" },
            l.probes,
            l.wall.as_secs_f64()
        );
        largest.push(l);
    }
    let mut streams = Vec::new();
    for sc in stream_cases {
        let expected =
            crate::golden::stream::golden_from_output(sc, backend, &crate::golden::stream::reference(sc))?;
        let run = run_stream_bytes(board, &elf, &sc.stream, timeout)?;
        let (verdict, summary) = match (&run.result, run.ok()) {
            (Some(o), true) => (
                crate::golden::stream::judge(sc, backend, &expected, o).cell(),
                meshfmt::pm::parse(o).map(|(_, s)| s),
            ),
            _ => ("FAILED", None),
        };
        let s = summary.unwrap_or_default();
        streams.push(StreamMeasurement {
            name: sc.name().to_string(),
            splits: s.splits,
            decode: board.instructions(s.decode_ticks),
            coarsen: board.instructions(s.coarsen_ticks),
            refine: board.instructions(s.refine_ticks),
            stack_bytes: s.stack_bytes,
            verdict,
        });
    }
    Ok(Measurement {
        board,
        backend,
        sizes,
        sizes_without,
        instantiation,
        instructions_per_tick: measured,
        workspace_bytes,
        capacity,
        cases: out,
        largest,
        streams,
    })
}

/// Signed difference of two sizes.
fn delta(a: u64, b: u64) -> i64 {
    a as i64 - b as i64
}

/// Prints a measurement: sizes, then one line per case, then the largest meshes.
pub fn print_measurement(m: &Measurement) {
    let b = m.board;
    let (s, w) = (&m.sizes, &m.sizes_without);
    crate::outln!(
        "\n== {} ({}, {}), {} backend",
        b.name,
        b.core,
        b.target,
        m.backend
    );
    crate::outln!(
        "firmware:      flash {:>8} B (text {}, rodata {}, .data image {}), static RAM {:>8} B of {} KB, stack {} B",
        s.flash,
        s.text,
        s.rodata,
        s.data,
        s.static_ram,
        b.ram >> 10,
        u64::from(b.ram).saturating_sub(s.static_ram)
    );
    let lib_stack = m.cases.iter().map(|c| c.stack_bytes).max().unwrap_or(0);
    crate::outln!(
        "library alone: flash {:>8} B (text {:+}, rodata {:+}), static RAM {:>8} B (workspace {} B) + stack <= {} B \
         [image with the library - image without]",
        delta(s.flash, w.flash),
        delta(s.text, w.text),
        delta(s.rodata, w.rodata),
        delta(s.static_ram, w.static_ram),
        m.workspace_bytes,
        lib_stack
    );
    let (without, with) = m.instantiation;
    crate::outln!(
        "instantiation: flash {:>8} B ({:.1} KB; text + rodata {with} with the call - {without} without) \
         [tests/flash as scripts/flash.sh builds it: {ONE_INSTANTIATION}]",
        delta(with, without),
        delta(with, without) as f64 / 1024.0,
    );
    crate::outln!(
        "capacity:      {} vertices, {} u16 / {} u32 triangles; {:.4} instructions per timer tick (calibrated)",
        m.capacity.0, m.capacity.1, m.capacity.2, m.instructions_per_tick
    );
    crate::outln!(
        "  {:<26} {:>6} {:>6} {:>9} {:>13} {:>11} {:>9} {:>10}  vs host",
        "case",
        "in",
        "out",
        "collapses",
        "instructions",
        "instr/coll",
        "stack lib",
        "high-water"
    );
    for c in &m.cases {
        if c.verdict == "skipped" || c.verdict == "FAILED" {
            crate::outln!(
                "  {:<26} {:>6}  {}: {}",
                c.name,
                c.triangles_in,
                c.verdict,
                c.note
            );
            continue;
        }
        let per = if c.collapses > 0 {
            format!("{}", c.instructions / u64::from(c.collapses))
        } else {
            "-".into()
        };
        crate::outln!(
            "  {:<26} {:>6} {:>6} {:>9} {:>13} {:>11} {:>9} {:>10}  {}",
            c.name,
            c.triangles_in,
            c.triangles_out,
            c.collapses,
            c.instructions,
            per,
            c.stack_bytes,
            c.stack_high_water,
            c.verdict
        );
    }
    for l in &m.largest {
        let it = if l.index_type == IndexType::U16 {
            "u16"
        } else {
            "u32"
        };
        let ok = match l.ok {
            Some((v, t, i)) => format!("{t} triangles / {v} vertices simplify ({i} instructions)"),
            None => "nothing simplifies".into(),
        };
        let fail = match &l.fail {
            Some((v, t, why)) => format!("{t} / {v} fail: {why}"),
            None => "no failure up to the search limit".into(),
        };
        crate::outln!(
            "largest {it} mesh (bisecting `strip T`, Config::new()): {ok}; {fail} [{} runs, {:.1} s]",
            l.probes,
            l.wall.as_secs_f64()
        );
    }
    crate::outln!(
        "  {:<26} {:>6} {:>13} {:>13} {:>13} {:>9}  vs host   [progressive streams, instructions per split]",
        "stream",
        "splits",
        "decode",
        "collapse",
        "split",
        "stack"
    );
    for st in &m.streams {
        if st.verdict != "identical" {
            crate::outln!("  {:<26} {}", st.name, st.verdict);
            continue;
        }
        let per = |x: u64| format!("{:.0}", x as f64 / f64::from(st.splits.max(1)));
        crate::outln!(
            "  {:<26} {:>6} {:>13} {:>13} {:>13} {:>9}  {}",
            st.name,
            st.splits,
            per(st.decode),
            per(st.coarsen),
            per(st.refine),
            st.stack_bytes,
            st.verdict
        );
    }
}

/// The summary table of several boards' measurements.
pub fn print_summary(ms: &[Measurement]) {
    if ms.is_empty() {
        return;
    }
    crate::outln!(
        "\nsummary ({} backend); sizes in bytes; lib = firmware image with - without the library; \
         1-inst = one instantiation ({ONE_INSTANTIATION}; scripts/flash.sh); \
         instr/collapse over the cases run (min..max)",
        ms[0].backend
    );
    crate::outln!(
        "{:<20} {:>9} {:>9} {:>9} {:>12} {:>9} {:>9} {:>17} {:>10} {:>15} {:>15}",
        "board",
        "fw flash",
        "fw RAM",
        "lib flash",
        "1-inst flash",
        "lib RAM",
        "lib stack",
        "instr/collapse",
        "high-water",
        "largest u16",
        "largest u32"
    );
    for m in ms {
        let per: Vec<u64> = m
            .cases
            .iter()
            .filter(|c| c.collapses > 0)
            .map(|c| c.instructions / u64::from(c.collapses))
            .collect();
        let range = match (per.iter().min(), per.iter().max()) {
            (Some(a), Some(b)) => format!("{a}..{b}"),
            _ => "-".into(),
        };
        let largest = |i: usize| {
            m.largest
                .get(i)
                .and_then(|l| l.ok)
                .map_or("-".into(), |(v, t, _)| format!("{t} T/{v} V"))
        };
        crate::outln!(
            "{:<20} {:>9} {:>9} {:>9} {:>12} {:>9} {:>9} {:>17} {:>10} {:>15} {:>15}",
            m.board.name,
            m.sizes.flash,
            m.sizes.static_ram,
            delta(m.sizes.flash, m.sizes_without.flash),
            delta(m.instantiation.1, m.instantiation.0),
            delta(m.sizes.static_ram, m.sizes_without.static_ram),
            m.cases.iter().map(|c| c.stack_bytes).max().unwrap_or(0),
            range,
            m.cases
                .iter()
                .map(|c| c.stack_high_water)
                .max()
                .unwrap_or(0),
            largest(0),
            largest(1)
        );
    }
}

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

/// The boards named in `names`, or all of them.
pub fn select_boards(names: &[String]) -> Result<Vec<&'static Board>> {
    if names.is_empty() {
        Ok(BOARDS.iter().collect())
    } else {
        names.iter().map(|n| board(n)).collect()
    }
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
                vec![mesh_case(path, a.ratio, a.passes, a.u32)?],
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
        failed = check(
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

/// A case of a mesh file with `Config::new()` and the given ratio and schedule.
pub fn mesh_case(path: &Path, ratio: f32, passes: bool, u32: bool) -> Result<Case> {
    let m = crate::io::load(path)?;
    let config = tinydecimate::Config::new()
        .with_ratio(ratio)
        .with_schedule(if passes {
            tinydecimate::Schedule::Passes
        } else {
            tinydecimate::Schedule::Greedy
        });
    Ok(Case {
        name: path
            .file_stem()
            .unwrap_or_default()
            .to_string_lossy()
            .into_owned(),
        mesh: path.display().to_string(),
        positions: m.positions,
        triangles: m.triangles,
        index_type: if u32 { IndexType::U32 } else { IndexType::U16 },
        config,
        stored: None,
    })
}

/// Removes the variables that would leak from a cargo that runs host-sim into a nested firmware
/// build (its own target directory, target and flags).
pub fn isolate(cmd: &mut std::process::Command) {
    for var in [
        "CARGO_TARGET_DIR",
        "CARGO_BUILD_TARGET",
        "RUSTFLAGS",
        "CARGO_ENCODED_RUSTFLAGS",
        "CARGO_MANIFEST_DIR",
    ] {
        cmd.env_remove(var);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// EXPECTED_SKIPS is exactly the cases that do not fit each board's buffers
    /// (host-sim/firmware/src/board.rs: vertices, and triangles of the case's index type in a
    /// buffer of MAX_TRIANGLES triangles of the board's link type).
    #[test]
    fn expected_skips_match_the_board_capacities() {
        // (board, MAX_VERTICES, MAX_TRIANGLES, bytes per link, QUADRIC_VERTICES)
        let caps = [
            ("microbit", 224, 432, 2, 0),
            ("lm3s6965evb", 1_250, 2_400, 2, 0),
            ("mps2-an386", 53_000, 106_000, 4, 1_024),
            ("mps2-an500", 53_000, 106_000, 4, 1_024),
            ("mps2-an505", 53_000, 106_000, 4, 1_024),
            ("riscv32imc-virt-400k", 6_000, 13_000, 2, 1_024),
            ("riscv32imac-virt-32k", 500, 1_000, 2, 0),
        ];
        let cases = golden::load_cases(&golden::default_dir()).unwrap();
        let streams = crate::golden::stream::load(&golden::default_dir()).unwrap();
        for (board, v, t, link, qv) in caps {
            let too_big: Vec<&str> = cases
                .iter()
                .filter(|c| {
                    let per = c.index_type.triangle_bytes();
                    let fit = (t * 3 * link / per).min(t);
                    c.positions.len() > v
                        || c.triangles.len() > fit
                        || (c.stored.is_some() && c.positions.len() > qv)
                        || (c.config.max_error.is_finite()
                            && c.triangles.len() * 3 * c.index_type.bytes()
                                + tinydecimate::bound::control_len(
                                    c.triangles.len(),
                                    c.positions.len(),
                                ) * link
                                > qv * 40)
                })
                .map(|c| c.name.as_str())
                .collect();
            // Streams: PM_VERTICES vertices, half the triangle buffer of links, PM_BUFFER.
            let (pv, pbuf) = match board {
                "microbit" => (44, 80),
                "lm3s6965evb" => (100, 272),
                "riscv32imac-virt-32k" => (100, 272),
                _ => (3_000, 4_096),
            };
            let too_big: Vec<&str> = too_big
                .into_iter()
                .chain(
                    streams
                        .iter()
                        .filter(|c| !c.fits(pv, (t * 3 * link - pv * link) / (6 * link), pbuf))
                        .map(|c| c.name()),
                )
                .collect();
            let listed: Vec<&str> = EXPECTED_SKIPS
                .iter()
                .find(|(b, _)| *b == board)
                .map(|(_, c)| c.to_vec())
                .unwrap_or_default();
            assert_eq!(too_big, listed, "{board}");
        }
        assert_eq!(EXPECTED_SKIPS.len(), BOARDS.len());
        assert!(matches!(
            against_expected_skips("mps2-an386", "cow-new-u16", Verdict::Skipped("x".into())),
            Verdict::Failed(_)
        ));
    }

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
    fn flash_crate_has_the_features_of_the_measurement() {
        // `one_instantiation` and scripts/flash.sh build these features of tests/flash.
        let manifest = std::fs::read_to_string(flash_crate_dir().join("Cargo.toml")).unwrap();
        for feature in [
            "call = ",
            "paper = ",
            "u32-triangles = ",
            "u32-links = ",
            "micromath = ",
        ] {
            assert!(
                manifest.lines().any(|l| l.starts_with(feature)),
                "tests/flash/Cargo.toml lacks the feature {feature:?}"
            );
        }
        assert!(manifest.contains("opt-level = \"s\"") && manifest.contains("lto = \"fat\""));
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

        // RISC-V: virt without boot firmware, the core without the part's missing extensions.
        let b = board("riscv32imc-virt-400k").unwrap();
        let c = qemu_command(b, Path::new("fw.elf"), &["case.bin", "out.bin"]);
        assert_eq!(c.get_program(), "qemu-system-riscv32");
        let args: Vec<_> = c
            .get_args()
            .map(|a| a.to_string_lossy().into_owned())
            .collect();
        assert!(args.windows(2).any(|w| w == ["-machine", "virt"]));
        assert!(args.windows(2).any(|w| w == ["-bios", "none"]));
        assert!(args
            .windows(2)
            .any(|w| w == ["-cpu", "rv32,a=false,f=false,d=false"]));
        assert!(args.windows(2).any(|w| w == ["-icount", "shift=0"]));
    }
}
