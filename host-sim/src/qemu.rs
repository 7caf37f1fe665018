//! The library on emulated Cortex-M and RISC-V cores: builds the firmware in `host-sim/firmware`
//! for a board, runs it under `qemu-system-arm` or `qemu-system-riscv32`, decodes its defmt log,
//! collects its result file and compares it with the golden files ([`crate::golden`],
//! `host-sim qemu --check`) or a fresh host run. Also measures each board (`--measure`):
//! instructions (SysTick, or RISC-V's `mcycle`, under `-icount shift=0`), stack high-water
//! mark, image sizes of the firmware and of the library alone, the flash of one instantiation
//! (the minimal firmware of `tests/flash`, as `scripts/flash.sh` builds it:
//! [`build::one_instantiation`]), and the largest mesh it simplifies.
//!
//! This file holds the boards; [`mod@build`] the images, [`mod@run`] the QEMU runs, [`defmt`] the
//! log, [`check`] the comparison, [`measure`] the measurements and [`cluster`] the streaming
//! clustering. The command is `host-sim qemu` ([`crate::cmd::qemu`]); `host-sim qemu --help`
//! lists the modes. By hand (what [`build()`] and [`run_in()`] do):
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
//! arguments with spaces). `log.defmt` holds binary defmt frames: [`defmt::decode_defmt`].

use anyhow::{anyhow, Result};

use crate::golden::Verdict;

pub mod build;
pub mod check;
pub mod cluster;
pub mod defmt;
pub mod elf;
pub mod measure;
pub mod run;

pub use build::{build, preflight};
pub use run::{run_case, run_in, run_stream_bytes, Run};

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
    /// advances by one per instruction: 1 GHz. Checked by [`calibrate`](measure::calibrate).
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
/// the 32 KB RISC-V) are the only ones that skip (RAM, or stack for vertex decimation);
/// docs/devices.md names their cases. Checked against
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
    "tray-new-u16",
    "grid12-stored-subset-u16",
    "grid12-stored-optimal-u16",
    "icosphere3-stored-optimal-u32",
    "fin8-stored-optimal-u16",
    "icosphere3-stored-subset-u32",
    "fin8-stored-subset-u16",
    "sphere2-bound-u16",
    "icosphere3-bound-u32",
    "fin10-bound-paper-u32",
    "sphere2-envelope-u16",
    "box6-envelope-u32",
    "grid12-envelope-decimation-u16",
    "grid12-vertex-decimation-u16",
    "box6-vertex-decimation-u16",
    "sphere2-vertex-decimation-u16",
    "grid8-vertex-decimation-u32",
    "cow-vertex-decimation-u16",
    "grid12-energy-u16",
    "sphere2-energy-u16",
    "box4-energy-u32",
    "grid12-fast-u16",
    "box6-fast-u16",
    "grid8-dirty-fast-u32",
    "plate-cut-fast-u16",
    "cow-fast-u16",
    "grid12-lean-u16",
    "box6-lean-u16",
    "grid8-dirty-lean-u32",
    "plate-cut-lean-u16",
    "cow-lean-u16",
    "charts12-fast-wedges-u16",
    "charts12-lean-wedges-u32",
    "grid12-fast-integer-u16",
    "box6-fast-integer-u16",
    "grid8-dirty-fast-integer-u32",
    "plate-cut-fast-integer-u16",
    "cow-fast-integer-u16",
    "box6-lean-integer-u16",
    "plate-cut-lean-integer-u16",
    "cow-lean-integer-u16",
    "pm-grid8",
    "pm-cow-quantised",
];
/// No RAM for stored quadrics on the micro:bit and the lm3s6965evb (firmware
/// `board::QUADRIC_VERTICES` = 0), so none for the bounded cases (they borrow it) or the
/// energy's samples either, no stack for vertex decimation (`board::VERTEX_DECIMATION`) and
/// no float fast or lean mode (`board::FAST_VERTICES` = 0); the cow's cases need the 4 MB
/// boards or the 400 KB RISC-V. Both run the pipeline in integers: the lm3s6965evb every small
/// mesh in either mode, the micro:bit the 12 x 12 and the 8 x 8 grid in the lean mode only
/// (`board::INT_FAST_VERTICES` = 0, `INT_LEAN_VERTICES`).
const LM3S_SKIPS: &[&str] = &[
    "cow-new-u16",
    "tray-new-u16",
    "grid12-stored-subset-u16",
    "grid12-stored-optimal-u16",
    "icosphere3-stored-optimal-u32",
    "fin8-stored-optimal-u16",
    "icosphere3-stored-subset-u32",
    "fin8-stored-subset-u16",
    "sphere2-bound-u16",
    "icosphere3-bound-u32",
    "fin10-bound-paper-u32",
    "sphere2-envelope-u16",
    "box6-envelope-u32",
    "grid12-envelope-decimation-u16",
    "grid12-vertex-decimation-u16",
    "box6-vertex-decimation-u16",
    "sphere2-vertex-decimation-u16",
    "grid8-vertex-decimation-u32",
    "cow-vertex-decimation-u16",
    "grid12-energy-u16",
    "sphere2-energy-u16",
    "box4-energy-u32",
    "grid12-fast-u16",
    "box6-fast-u16",
    "grid8-dirty-fast-u32",
    "plate-cut-fast-u16",
    "cow-fast-u16",
    "grid12-lean-u16",
    "box6-lean-u16",
    "grid8-dirty-lean-u32",
    "plate-cut-lean-u16",
    "cow-lean-u16",
    "charts12-fast-wedges-u16",
    "charts12-lean-wedges-u32",
    "cow-fast-integer-u16",
    "cow-lean-integer-u16",
    "pm-cow-quantised",
];

/// The 400 KB RISC-V board holds every case (its buffers are sized for the cow's stream) but
/// the cow's float fast and lean cases: their workspace holds 2 000 vertices
/// (`board::FAST_VERTICES`); the integer ones hold the cow.
const RISCV_400K_SKIPS: &[&str] = &["cow-fast-u16", "cow-lean-u16"];
/// The 32 KB RISC-V board: the micro:bit's list less the 9 x 9 grid's stream (100 splits fit)
/// and the small meshes in integers; no RAM for stored quadrics, bounds or the energy's
/// samples, and the plate and the cow are too big, vertex decimation overflows its stack, and
/// there is no float fast or lean mode. Its integer workspaces hold every mesh but the cow.
const RISCV_32K_SKIPS: &[&str] = &[
    "plate-new-u16",
    "cow-new-u16",
    "tray-new-u16",
    "grid12-stored-subset-u16",
    "grid12-stored-optimal-u16",
    "icosphere3-stored-optimal-u32",
    "fin8-stored-optimal-u16",
    "icosphere3-stored-subset-u32",
    "fin8-stored-subset-u16",
    "sphere2-bound-u16",
    "icosphere3-bound-u32",
    "fin10-bound-paper-u32",
    "sphere2-envelope-u16",
    "box6-envelope-u32",
    "grid12-envelope-decimation-u16",
    "grid12-vertex-decimation-u16",
    "box6-vertex-decimation-u16",
    "sphere2-vertex-decimation-u16",
    "grid8-vertex-decimation-u32",
    "cow-vertex-decimation-u16",
    "grid12-energy-u16",
    "sphere2-energy-u16",
    "box4-energy-u32",
    "grid12-fast-u16",
    "box6-fast-u16",
    "grid8-dirty-fast-u32",
    "plate-cut-fast-u16",
    "cow-fast-u16",
    "grid12-lean-u16",
    "box6-lean-u16",
    "grid8-dirty-lean-u32",
    "plate-cut-lean-u16",
    "cow-lean-u16",
    "charts12-fast-wedges-u16",
    "charts12-lean-wedges-u32",
    "cow-fast-integer-u16",
    "cow-lean-integer-u16",
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

impl Board {
    /// Instructions in `ticks` timer ticks.
    pub fn instructions(&self, ticks: u64) -> u64 {
        (ticks as f64 * self.instructions_per_tick()).round() as u64
    }
}

/// The boards named in `names`, or all of them.
pub fn select_boards(names: &[String]) -> Result<Vec<&'static Board>> {
    if names.is_empty() {
        Ok(BOARDS.iter().collect())
    } else {
        names.iter().map(|n| board(n)).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::build::flash_crate_dir;
    use super::run::qemu_command;
    use super::*;
    use crate::golden;
    use std::path::Path;

    /// Whether a case runs under the envelope bound.
    fn envelope(c: &golden::case::Case) -> bool {
        matches!(
            c.method,
            Some(golden::case::MethodName::Envelope | golden::case::MethodName::EnvelopeDecimation)
        )
    }

    /// EXPECTED_SKIPS is exactly the cases that do not fit each board's buffers
    /// (host-sim/firmware/src/board.rs: vertices, and triangles of the case's index type in a
    /// buffer of MAX_TRIANGLES triangles of the board's link type).
    #[test]
    fn expected_skips_match_the_board_capacities() {
        // (board, MAX_VERTICES, MAX_TRIANGLES, bytes per link, QUADRIC_VERTICES,
        // VERTEX_DECIMATION); the fast workspace's from `capacity_tests::FAST`.
        let caps = [
            ("microbit", 224, 432, 2, 0, false),
            ("lm3s6965evb", 1_250, 2_400, 2, 0, false),
            ("mps2-an386", 53_000, 106_000, 4, 1_024, true),
            ("mps2-an500", 53_000, 106_000, 4, 1_024, true),
            ("mps2-an505", 53_000, 106_000, 4, 1_024, true),
            ("riscv32imc-virt-400k", 6_000, 13_000, 2, 1_024, true),
            ("riscv32imac-virt-32k", 500, 1_000, 2, 0, false),
        ];
        let cases = golden::load_cases(&golden::default_dir()).unwrap();
        let streams = crate::golden::stream::load(&golden::default_dir()).unwrap();
        for (board, v, t, link, qv, vd) in caps {
            let (_, fv, ft) = *super::capacity_tests::FAST
                .iter()
                .find(|(b, _, _)| *b == board)
                .expect("every board in capacity_tests::FAST");
            let (_, (ifv, ift), (ilv, ilt)) = *super::capacity_tests::INTEGER
                .iter()
                .find(|(b, _, _)| *b == board)
                .expect("every board in capacity_tests::INTEGER");
            let too_big: Vec<&str> = cases
                .iter()
                .filter(|c| {
                    let per = c.index_type.triangle_bytes();
                    let fit = (t * 3 * link / per).min(t);
                    c.positions.len() > v
                        || c.triangles.len() > fit
                        || (c.per_vertex_storage() && (c.positions.len() > qv || qv == 0))
                        || (c.method == Some(golden::case::MethodName::VertexDecimation) && !vd)
                        || (matches!(
                            c.method,
                            Some(golden::case::MethodName::Fast | golden::case::MethodName::Lean)
                        ) && (c.positions.len() > fv || c.triangles.len() > ft))
                        || (c.method == Some(golden::case::MethodName::FastInteger)
                            && (c.positions.len() > ifv || c.triangles.len() > ift))
                        || (c.method == Some(golden::case::MethodName::LeanInteger)
                            && (c.positions.len() > ilv || c.triangles.len() > ilt))
                        // With wedges, the wedges follow the triangles in the buffer.
                        || (matches!(
                            c.method,
                            Some(
                                golden::case::MethodName::FastWedges
                                    | golden::case::MethodName::LeanWedges
                            )
                        ) && (c.positions.len() > fv
                            || c.triangles.len() > ft
                            || 2 * c.triangles.len() > fit))
                        || (envelope(c)
                            && (qv == 0
                                || meshfmt::envelope_bytes(
                                    c.positions.len(),
                                    c.triangles.len(),
                                    c.index_type.bytes(),
                                    link,
                                ) > qv * 40))
                        || (c.method == Some(golden::case::MethodName::EnvelopeDecimation) && !vd)
                        || (c.config.max_error().is_finite() && !envelope(c) && qv == 0)
                        || (c.config.max_error().is_finite()
                            && !envelope(c)
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
        // As this QEMU accepts it: newer ones also get their default Zawrs and Zfa switched
        // off (`run::board_args`).
        assert!(args.windows(2).any(|w| w[0] == "-cpu"
            && w[1].starts_with("rv32,a=false,f=false,d=false")
            && (w[1].len() == "rv32,a=false,f=false,d=false".len()
                || w[1].starts_with("rv32,a=false,f=false,d=false,zawrs=false"))));
        assert!(args.windows(2).any(|w| w == ["-icount", "shift=0"]));
    }
}

/// What a board's streaming firmware holds (host-sim/firmware/src/board.rs): `PM_VERTICES`
/// vertices, the triangle buffer less the list heads, halved between triangles and their
/// links, and a `PM_BUFFER`-byte chunk buffer.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct StreamCapacity {
    /// Vertices of the full mesh.
    pub vertices: usize,
    /// Triangles of the full mesh.
    pub triangles: usize,
    /// Chunk buffer bytes (largest payload plus `CHUNK_OVERHEAD`).
    pub buffer: usize,
}

impl StreamCapacity {
    /// The capacity of the firmware for the board `name`.
    pub fn of(name: &str) -> Option<StreamCapacity> {
        // (MAX_TRIANGLES, link bytes, PM_VERTICES, PM_BUFFER) of board.rs.
        let (max_triangles, link, vertices, buffer) = match name {
            "microbit" => (432, 2, 44, 80),
            "lm3s6965evb" => (2_400, 2, 100, 272),
            "mps2-an386" | "mps2-an500" | "mps2-an505" => (106_000, 4, 3_000, 4_096),
            "riscv32imc-virt-400k" => (13_000, 2, 3_000, 4_096),
            "riscv32imac-virt-32k" => (1_000, 2, 100, 272),
            _ => return None,
        };
        let heads = (vertices * link + 3) & !3;
        Some(StreamCapacity {
            vertices,
            triangles: (max_triangles * 3 * link - heads) / (6 * link),
            buffer,
        })
    }
}

#[cfg(test)]
mod capacity_tests {
    use super::StreamCapacity;

    /// The fast (and lean) workspace per board (firmware `board::FAST_VERTICES`,
    /// `FAST_TRIANGLES`; 0: no fast or lean mode).
    pub(super) const FAST: &[(&str, usize, usize)] = &[
        ("microbit", 0, 0),
        ("lm3s6965evb", 0, 0),
        ("mps2-an386", 32_000, 64_000),
        ("mps2-an500", 32_000, 64_000),
        ("mps2-an505", 32_000, 64_000),
        ("riscv32imc-virt-400k", 2_000, 4_000),
        ("riscv32imac-virt-32k", 0, 0),
    ];

    /// A workspace's capacity: vertices, triangles.
    type Capacity = (usize, usize);

    /// The integer workspaces per board, fast then lean (firmware `board::INT_FAST_VERTICES`,
    /// `INT_FAST_TRIANGLES`, `INT_LEAN_VERTICES`, `INT_LEAN_TRIANGLES`; 0: no such mode).
    pub(super) const INTEGER: &[(&str, Capacity, Capacity)] = &[
        ("microbit", (0, 0), (180, 300)),
        ("lm3s6965evb", (530, 1_060), (530, 1_060)),
        ("mps2-an386", (32_000, 64_000), (32_000, 64_000)),
        ("mps2-an500", (32_000, 64_000), (32_000, 64_000)),
        ("mps2-an505", (32_000, 64_000), (32_000, 64_000)),
        ("riscv32imc-virt-400k", (3_000, 6_000), (3_000, 6_000)),
        ("riscv32imac-virt-32k", (224, 448), (400, 800)),
    ];

    /// [`FAST`] and [`INTEGER`] are copies of the firmware's constants: they must agree with
    /// host-sim/firmware/src/board.rs for every board there.
    #[test]
    fn fast_capacity_agrees_with_the_firmware() {
        let src = include_str!("../firmware/src/board.rs");
        let mut boards = 0;
        for block in src.split("mod sel {").skip(1) {
            let block = &block[..block.find("\n}").unwrap_or(block.len())];
            let (v, t) = (
                constant(block, "FAST_VERTICES"),
                constant(block, "FAST_TRIANGLES"),
            );
            let fast = (
                constant(block, "INT_FAST_VERTICES"),
                constant(block, "INT_FAST_TRIANGLES"),
            );
            let lean = (
                constant(block, "INT_LEAN_VERTICES"),
                constant(block, "INT_LEAN_TRIANGLES"),
            );
            for name in block
                .lines()
                .filter(|l| l.contains("pub const NAME: &str ="))
                .map(|l| l.split('"').nth(1).unwrap())
            {
                boards += 1;
                assert!(FAST.contains(&(name, v, t)), "{name}: {v} / {t}");
                assert!(
                    INTEGER.contains(&(name, fast, lean)),
                    "{name}: integer {fast:?} {lean:?}"
                );
            }
        }
        assert_eq!(boards, FAST.len(), "boards in board.rs");
        assert_eq!(boards, INTEGER.len(), "boards in board.rs");
    }

    /// The value of `pub const NAME...: ... = VALUE;` in one board's block of board.rs.
    fn constant(block: &str, name: &str) -> usize {
        let line = block
            .lines()
            .find(|l| l.trim_start().starts_with(&format!("pub const {name}:")))
            .unwrap_or_else(|| panic!("no {name} in {block}"));
        let v = line.split('=').nth(1).unwrap().trim().trim_end_matches(';');
        v.replace('_', "").parse().unwrap()
    }

    /// `StreamCapacity::of` is a copy of the firmware's constants: it must agree with
    /// host-sim/firmware/src/board.rs for every board there.
    #[test]
    fn stream_capacity_agrees_with_the_firmware() {
        let src = include_str!("../firmware/src/board.rs");
        let blocks: Vec<&str> = src.split("mod sel {").skip(1).collect();
        let mut boards = 0;
        for block in blocks {
            let block = &block[..block.find("\n}").unwrap_or(block.len())];
            let names: Vec<&str> = block
                .lines()
                .filter(|l| l.contains("pub const NAME: &str ="))
                .map(|l| l.split('"').nth(1).unwrap())
                .collect();
            let link = if block.contains("pub type Link = u32;") {
                4
            } else {
                2
            };
            let (t, v, b) = (
                constant(block, "MAX_TRIANGLES"),
                constant(block, "PM_VERTICES"),
                constant(block, "PM_BUFFER"),
            );
            let heads = (v * link + 3) & !3;
            for name in names {
                boards += 1;
                let c = StreamCapacity::of(name)
                    .unwrap_or_else(|| panic!("StreamCapacity::of({name}) is missing"));
                assert_eq!(
                    c,
                    StreamCapacity {
                        vertices: v,
                        triangles: (t * 3 * link - heads) / (6 * link),
                        buffer: b,
                    },
                    "{name}"
                );
            }
        }
        assert_eq!(boards, crate::qemu::BOARDS.len(), "boards in board.rs");
    }
}
