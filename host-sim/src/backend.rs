//! The library's math backend (its `micromath` feature), chosen when host-sim is compiled, and
//! the re-run of host-sim built with the other one ([`reinvoke`]).

use std::process::{Command, ExitCode};

use anyhow::{bail, Context, Result};

use crate::repo_root;

/// The library's math backend (its `micromath` feature). Chosen when host-sim is compiled.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Backend {
    /// libm, the default: correctly rounded `sqrtf`.
    Libm,
    /// micromath: fast approximations.
    Micromath,
}

impl Backend {
    /// Both backends.
    pub const ALL: [Backend; 2] = [Backend::Libm, Backend::Micromath];

    /// The backend this host-sim binary was built with.
    pub const fn compiled() -> Self {
        if cfg!(feature = "micromath") {
            Backend::Micromath
        } else {
            Backend::Libm
        }
    }

    /// `libm` or `micromath`: the golden subdirectory and the cargo feature.
    pub const fn name(self) -> &'static str {
        match self {
            Backend::Libm => "libm",
            Backend::Micromath => "micromath",
        }
    }
}

impl std::fmt::Display for Backend {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// Set in the environment of a re-invoked host-sim, so it never re-invokes itself again.
const REINVOKED: &str = "HOST_SIM_REINVOKED";

/// Runs this same command line again through `cargo run -p host-sim`, built for `backend`
/// (same profile; same target directory, so both builds stay cached side by side). The host
/// side of a check must run the library with the backend being checked, and the backend is a
/// compile-time feature. Returns the child's exit code.
pub fn reinvoke(backend: Backend) -> Result<ExitCode> {
    if std::env::var_os(REINVOKED).is_some() {
        bail!(
            "host-sim built with {} was asked for {backend} again after re-invoking itself",
            Backend::compiled()
        );
    }
    let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    let mut cmd = Command::new(cargo);
    cmd.arg("run");
    if !cfg!(debug_assertions) {
        cmd.arg("--release");
    }
    cmd.args(["-p", "host-sim", "--manifest-path"])
        .arg(repo_root().join("Cargo.toml"));
    if backend == Backend::Micromath {
        cmd.args(["--features", "micromath"]);
    }
    if std::env::var_os("CARGO_TARGET_DIR").is_none() {
        // Run from its target directory by path: build the other variant next to it.
        if let Some(dir) = std::env::current_exe()
            .ok()
            .and_then(|e| Some(e.parent()?.parent()?.to_path_buf()))
            .filter(|d| d.join("CACHEDIR.TAG").exists())
        {
            cmd.arg("--target-dir").arg(dir);
        }
    }
    cmd.arg("--").args(std::env::args_os().skip(1));
    cmd.env(REINVOKED, "1");
    eprintln!(
        "host-sim: this binary runs the library with {}; re-running under `cargo run -p host-sim{}` for --backend {backend}",
        Backend::compiled(),
        if backend == Backend::Micromath {
            " --features micromath"
        } else {
            ""
        }
    );
    let status = cmd.status().context("re-running host-sim through cargo")?;
    Ok(ExitCode::from(
        status.code().map_or(2, |c| u8::try_from(c).unwrap_or(2)),
    ))
}
