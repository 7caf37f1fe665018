//! Picks the memory layout of the selected board and puts it on the linker's search path as
//! `memory.x` (cortex-m-rt's and riscv-rt's `link.x` include it by that name).
//!
//! The linker does not track `memory.x` as an input, so every candidate file is listed with
//! `rerun-if-changed`: without it, switching boards or editing a layout would link with the
//! stale copy (a 4 MB layout on the 16 KB micro:bit puts the stack in unmapped memory and the
//! core locks up on its first push).

use std::{env, fs, path::PathBuf};

/// (cargo feature, memory layout relative to this crate, targets the board can run)
const BOARDS: &[(&str, &str, &[&str])] = &[
    (
        "BOARD_MICROBIT",
        "memory/microbit.x",
        &["thumbv6m-none-eabi"],
    ),
    (
        "BOARD_LM3S6965EVB",
        "memory/lm3s6965evb.x",
        &["thumbv7m-none-eabi"],
    ),
    // The reference layout lives at the top of the repository.
    (
        "BOARD_MPS2_AN386",
        "../../memory.x",
        &["thumbv7em-none-eabihf", "thumbv7em-none-eabi"],
    ),
    // QEMU's AN500 model has AN386's SSRAM map.
    (
        "BOARD_MPS2_AN500",
        "../../memory.x",
        &["thumbv7em-none-eabihf", "thumbv7em-none-eabi"],
    ),
    (
        "BOARD_MPS2_AN505",
        "memory/mps2-an505.x",
        &["thumbv8m.main-none-eabihf", "thumbv8m.main-none-eabi"],
    ),
    // QEMU's RISC-V `virt` machine with RAM regions the size of real parts (riscv-rt's link.x).
    (
        "BOARD_RISCV32IMC_VIRT_400K",
        "memory/riscv32-virt-400k.x",
        &["riscv32imc-unknown-none-elf"],
    ),
    (
        "BOARD_RISCV32IMAC_VIRT_32K",
        "memory/riscv32-virt-32k.x",
        &["riscv32imac-unknown-none-elf"],
    ),
];

fn main() {
    let manifest = PathBuf::from(env::var("CARGO_MANIFEST_DIR").unwrap());
    let out = PathBuf::from(env::var("OUT_DIR").unwrap());
    let target = env::var("TARGET").unwrap();

    for (_, file, _) in BOARDS {
        println!("cargo:rerun-if-changed={}", manifest.join(file).display());
    }
    println!("cargo:rerun-if-changed=build.rs");

    let selected: Vec<_> = BOARDS
        .iter()
        .filter(|(feature, _, _)| env::var_os(format!("CARGO_FEATURE_{feature}")).is_some())
        .collect();
    let (feature, file, targets) = match selected.as_slice() {
        [one] => **one,
        [] => panic!(
            "select a board: --features board-microbit | board-lm3s6965evb | board-mps2-an386 | \
             board-mps2-an500 | board-mps2-an505 | board-riscv32imc-virt-400k | \
             board-riscv32imac-virt-32k"
        ),
        _ => panic!("select exactly one board feature"),
    };
    if (target.starts_with("thumb") || target.starts_with("riscv"))
        && !targets.contains(&target.as_str())
    {
        panic!("{feature} runs {targets:?}, not {target}");
    }
    let layout = fs::read(manifest.join(file)).unwrap_or_else(|e| panic!("{file}: {e}"));
    fs::write(out.join("memory.x"), layout).unwrap();
    println!("cargo:rustc-link-search={}", out.display());
}
