//! Puts this crate's `memory.x` (the board's memory layout, which cortex-m-rt's `link.x`
//! includes) on the linker's search path. The linker flags themselves are in
//! `.cargo/config.toml`.
use std::path::PathBuf;

fn main() {
    let out = PathBuf::from(std::env::var_os("OUT_DIR").unwrap());
    std::fs::copy("memory.x", out.join("memory.x")).unwrap();
    println!("cargo:rustc-link-search={}", out.display());
    println!("cargo:rerun-if-changed=memory.x");
    println!("cargo:rerun-if-changed=build.rs");
}
