//! Sets `armv6m` when the library is built for a Cortex-M0/M0+ (`thumbv6m-*`), as the
//! `cortex-m` crate does: that core has no divide, no 32×32→64 multiply and no count of leading
//! zeros, so the integer pipeline computes those few steps there with other exact routines
//! (same results, fewer instructions). Stable Rust has no `cfg` for the ARM architecture
//! version.
fn main() {
    println!("cargo::rustc-check-cfg=cfg(armv6m)");
    println!("cargo::rerun-if-changed=build.rs");
    if std::env::var("TARGET").is_ok_and(|t| t.starts_with("thumbv6m")) {
        println!("cargo::rustc-cfg=armv6m");
    }
}
