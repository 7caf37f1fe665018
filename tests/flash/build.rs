//! Puts the reference board's layout (the repository's `memory.x`, shared with the firmware in
//! host-sim/firmware; on RISC-V its 400 KB `virt` layout) on the linker's search path, and an empty `defmt.x`: the repository's
//! .cargo/config.toml passes `-Tdefmt.x` to every bare-metal ARM and RISC-V link and this firmware links
//! no defmt (as in tests/no-panic). The image is only linked and measured, never run, so one
//! layout serves every target.
use std::path::PathBuf;

/// RISC-V (riscv-rt's link.x): the 400 KB layout of the firmware's RISC-V board.
const RISCV_MEMORY: &str = "../../host-sim/firmware/memory/riscv32-virt-400k.x";

fn main() {
    let out = PathBuf::from(std::env::var_os("OUT_DIR").unwrap());
    let riscv = std::env::var("TARGET").unwrap().starts_with("riscv");
    let layout = if riscv { RISCV_MEMORY } else { "../../memory.x" };
    std::fs::copy(layout, out.join("memory.x")).unwrap();
    std::fs::write(
        out.join("defmt.x"),
        "/* empty: defmt is not linked (tests/flash/build.rs) */\n",
    )
    .unwrap();
    println!("cargo:rustc-link-search={}", out.display());
    println!("cargo:rerun-if-changed=../../memory.x");
    println!("cargo:rerun-if-changed={RISCV_MEMORY}");
    println!("cargo:rerun-if-changed=build.rs");
}
