//! Puts the reference board's memory layout (the repository's `memory.x`: QEMU mps2-an386,
//! 4 MB of code memory at 0, 4 MB of RAM at 0x2000_0000) on the linker's search path. For a
//! real board, replace it with that board's layout (an STM32F407: FLASH 1M at 0x0800_0000,
//! RAM 128K at 0x2000_0000).
use std::path::PathBuf;

fn main() {
    let out = PathBuf::from(std::env::var_os("OUT_DIR").unwrap());
    std::fs::copy("../../memory.x", out.join("memory.x")).unwrap();
    println!("cargo:rustc-link-search={}", out.display());
    println!("cargo:rerun-if-changed=../../memory.x");
    println!("cargo:rerun-if-changed=build.rs");
}
