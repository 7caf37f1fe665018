//! The project's harness for `tinydecimate`: the bench against meshoptimizer, the golden
//! files, the library under QEMU on the Cortex-M and RISC-V boards (with its firmware in
//! `firmware/`), the demo. The `host-sim` binary (`main.rs`) is a thin command-line front end
//! over these modules. Mesh files, the validity check, Metro, pictures and the user's commands
//! are the command line's (`tinydecimate-cli`, in `cli/`); the harness uses them from there.

pub mod backend;
pub mod bench;
pub mod cmd;
pub mod golden;
pub mod qemu;

// The command line's modules the harness runs on.
pub use tinydecimate_cli::{
    check, cluster, exit_code_for_error, exit_code_for_io, io, meshopt, metro, out, outln, pm,
    progress, render, simplify, stdout_or_exit, uvstretch, workspace,
};

/// The repository root (the parent of host-sim).
pub fn repo_root() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("host-sim lives inside the repository")
        .to_path_buf()
}
