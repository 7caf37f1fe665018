//! Puts the reference board's layout (the repository's `memory.x`, shared with the firmware in
//! host-sim/firmware) on the linker's search path, and an empty `defmt.x`: the repository's
//! .cargo/config.toml passes `-Tdefmt.x` to every bare-metal ARM link and this firmware links
//! no defmt (as in tests/no-panic). The image is only linked and measured, never run, so one
//! layout serves every target.
use std::path::PathBuf;

fn main() {
    let out = PathBuf::from(std::env::var_os("OUT_DIR").unwrap());
    std::fs::copy("../../memory.x", out.join("memory.x")).unwrap();
    std::fs::write(
        out.join("defmt.x"),
        "/* empty: defmt is not linked (tests/flash/build.rs) */\n",
    )
    .unwrap();
    println!("cargo:rustc-link-search={}", out.display());
    println!("cargo:rerun-if-changed=../../memory.x");
    println!("cargo:rerun-if-changed=build.rs");
}
