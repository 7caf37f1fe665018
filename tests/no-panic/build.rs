//! Puts this crate's memory.x on the linker's search path, and (without the `defmt` feature) an
//! empty defmt.x: the repository's .cargo/config.toml passes `-Tdefmt.x` to every bare-metal
//! ARM link, and cargo joins rustflags arrays across config files, so a nested config cannot
//! take that flag away. An empty linker script satisfies it; with the feature, defmt's own
//! build script provides the real one (and ours must not shadow it).
use std::path::PathBuf;

fn main() {
    let out = PathBuf::from(std::env::var_os("OUT_DIR").unwrap());
    std::fs::copy("memory.x", out.join("memory.x")).unwrap();
    if std::env::var_os("CARGO_FEATURE_DEFMT").is_none() {
        std::fs::write(
            out.join("defmt.x"),
            "/* empty: defmt is not linked (tests/no-panic/build.rs) */\n",
        )
        .unwrap();
    }
    println!("cargo:rustc-link-search={}", out.display());
    println!("cargo:rerun-if-changed=memory.x");
    println!("cargo:rerun-if-changed=build.rs");
}
