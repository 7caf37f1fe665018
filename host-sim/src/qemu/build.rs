//! Firmware images: the tools they need ([`preflight`]), the board's image with or without the
//! library ([`build`]) and the minimal image that measures one instantiation
//! ([`one_instantiation`], as `scripts/flash.sh` builds it).

use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode, Stdio};

use anyhow::{bail, Context, Result};

use super::elf::elf_sizes;
use super::{Board, Qemu};
use crate::backend::Backend;

/// The firmware crate.
pub fn firmware_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("firmware")
}

/// The firmware's target directory (also what `cargo build` in `host-sim/firmware` uses): one
/// for every board and backend, so dependencies are built once per Rust target.
pub fn firmware_target_dir() -> PathBuf {
    firmware_dir().join("target")
}

/// Where [`build`] keeps a board's image: `target/images/<board>-<backend>[-nolib].elf`. Cargo
/// leaves one `tinydecimate-firmware` per Rust target, which the next build for another board
/// of the same target (an386/an500) or another backend overwrites, so each image is copied
/// out right after its build.
pub fn elf_path(board: &Board, backend: Backend, with_library: bool) -> PathBuf {
    firmware_target_dir().join("images").join(format!(
        "{}-{}{}.elf",
        board.name,
        backend,
        if with_library { "" } else { "-nolib" }
    ))
}

/// Builds the firmware for `board` (release) with the library on `backend`, or
/// (`with_library = false`) as a boot/semihosting/defmt smoke test that echoes its input.
/// Returns the image.
pub fn build(board: &Board, backend: Backend, with_library: bool) -> Result<PathBuf> {
    let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    let mut features = format!("board-{}", board.name);
    if backend == Backend::Micromath {
        features.push_str(",micromath");
    }
    let mut cmd = Command::new(cargo);
    cmd.current_dir(firmware_dir())
        .args(["build", "--release", "--target", board.target])
        // Only the collapse image (the clustering one is `qemu::cluster::build`'s).
        .args(["--bin", "tinydecimate-firmware", "--features", &features])
        .arg("--target-dir")
        .arg(firmware_target_dir())
        // Library debug logs stay out: they would cost instructions inside the measurement.
        .env("DEFMT_LOG", "info");
    if !with_library {
        cmd.arg("--no-default-features");
    }
    // When host-sim itself runs under cargo, these would leak into the firmware build.
    isolate(&mut cmd);
    let status = cmd
        .status()
        .context("running cargo for the firmware (is the target installed? `rustup target add`)")?;
    if !status.success() {
        bail!(
            "firmware build for {} ({backend}) failed ({status})",
            board.name
        );
    }
    let built = firmware_target_dir()
        .join(board.target)
        .join("release")
        .join("tinydecimate-firmware");
    let elf = elf_path(board, backend, with_library);
    std::fs::create_dir_all(elf.parent().expect("has a parent"))?;
    std::fs::copy(&built, &elf)
        .with_context(|| format!("copying {} to {}", built.display(), elf.display()))?;
    Ok(elf)
}

/// The minimal firmware that measures the flash of one instantiation (`tests/flash`, also
/// built by `scripts/flash.sh`).
pub fn flash_crate_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("host-sim sits in the repository")
        .join("tests/flash")
}

/// Its target directory: the one `scripts/flash.sh` uses by default, so both share builds and
/// `images/`.
pub fn flash_target_dir() -> PathBuf {
    flash_crate_dir().join("target")
}

/// What [`one_instantiation`] measures, as `scripts/flash.sh` describes its first row.
pub const ONE_INSTANTIATION: &str =
    "Workspace<u16, 512, 1024>::simplify, u16 triangles, Config::new(); opt-level s, fat LTO";

/// Builds `tests/flash` for `target` with its own release profile (opt-level "s", fat LTO, one
/// codegen unit, panic = abort) without or with the feature `call`, on `backend`, exactly as
/// `scripts/flash.sh` does. Returns the image, copied to
/// `tests/flash/target/images/<target>-<without|call>[-micromath].elf` (the script's names).
pub fn build_flash(target: &str, backend: Backend, call: bool) -> Result<PathBuf> {
    let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    let mut features = Vec::new();
    if call {
        features.push("call");
    }
    if backend == Backend::Micromath {
        features.push("micromath");
    }
    let mut cmd = Command::new(cargo);
    cmd.current_dir(flash_crate_dir())
        .args(["build", "--release", "--quiet", "--target", target])
        .arg("--target-dir")
        .arg(flash_target_dir());
    if !features.is_empty() {
        cmd.args(["--features", &features.join(",")]);
    }
    isolate(&mut cmd);
    let status = cmd.status().context("running cargo for tests/flash")?;
    if !status.success() {
        bail!("tests/flash build for {target} ({backend}) failed ({status})");
    }
    let built = flash_target_dir()
        .join(target)
        .join("release")
        .join("tinydecimate-flash");
    let elf = flash_target_dir().join("images").join(format!(
        "{target}-{}{}.elf",
        if call { "call" } else { "without" },
        if backend == Backend::Micromath {
            "-micromath"
        } else {
            ""
        }
    ));
    std::fs::create_dir_all(elf.parent().expect("has a parent"))?;
    std::fs::copy(&built, &elf)
        .with_context(|| format!("copying {} to {}", built.display(), elf.display()))?;
    Ok(elf)
}

/// The flash of one instantiation on `target`: `.text + .rodata` of the minimal firmware without
/// and with the call ([`build_flash`]); the library is the difference. The same figure as
/// `scripts/flash.sh`.
pub fn one_instantiation(target: &str, backend: Backend) -> Result<(u64, u64)> {
    let code = |call| -> Result<u64> {
        let s = elf_sizes(&std::fs::read(build_flash(target, backend, call)?)?)?;
        Ok(s.text + s.rodata)
    };
    Ok((code(false)?, code(true)?))
}

/// Removes the variables that would leak from a cargo that runs host-sim into a nested firmware
/// build (its own target directory, target and flags, and its release profile: a
/// `CARGO_PROFILE_RELEASE_LTO=false` meant for the host build would leave the firmware without
/// LTO, deeper in stack than the micro:bit has and larger than the lm3s6965evb's flash).
pub fn isolate(cmd: &mut std::process::Command) {
    for var in [
        "CARGO_TARGET_DIR",
        "CARGO_BUILD_TARGET",
        "RUSTFLAGS",
        "CARGO_ENCODED_RUSTFLAGS",
        "CARGO_MANIFEST_DIR",
    ] {
        cmd.env_remove(var);
    }
    for (var, _) in std::env::vars_os() {
        if var
            .to_str()
            .is_some_and(|v| v.starts_with("CARGO_PROFILE_"))
        {
            cmd.env_remove(var);
        }
    }
}

/// Whether `program --version` runs.
fn runs(program: &str, arg: &str) -> bool {
    Command::new(program)
        .arg(arg)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .is_ok_and(|s| s.success())
}

/// The distribution's release name (`VERSION_CODENAME` of `/etc/os-release`).
fn distribution_codename() -> Option<String> {
    let text = std::fs::read_to_string("/etc/os-release").ok()?;
    text.lines()
        .find_map(|l| l.strip_prefix("VERSION_CODENAME="))
        .map(|c| c.trim_matches('"').to_string())
        .filter(|c| !c.is_empty())
}

/// Makes sure the tools for `boards` are there, on a fresh machine too:
///
/// * the Rust targets of the boards: missing ones are installed with `rustup target add`
///   (harmless, per-user);
/// * the boards' QEMU (`qemu-system-arm`, `qemu-system-riscv32`): if one is missing, and
///   running as root with `CI` set (a throw-away CI machine), `apt-get install -y <package>` is
///   run; otherwise the exact install command is printed and the caller should exit with
///   status 2 (`Ok(Some(2))`): installing system packages is the user's call.
pub fn preflight(boards: &[&Board]) -> Result<Option<ExitCode>> {
    let mut targets: Vec<&str> = boards.iter().map(|b| b.target).collect();
    targets.sort_unstable();
    targets.dedup();
    let installed = Command::new("rustup")
        .args(["target", "list", "--installed"])
        .output();
    match installed {
        Ok(out) if out.status.success() => {
            let have = String::from_utf8_lossy(&out.stdout).into_owned();
            let missing: Vec<&str> = targets
                .iter()
                .copied()
                .filter(|t| !have.lines().any(|l| l.trim() == *t))
                .collect();
            if !missing.is_empty() {
                eprintln!(
                    "installing Rust targets: rustup target add {}",
                    missing.join(" ")
                );
                let ok = Command::new("rustup")
                    .args(["target", "add"])
                    .args(&missing)
                    .status()
                    .is_ok_and(|s| s.success());
                if !ok {
                    bail!("`rustup target add {}` failed", missing.join(" "));
                }
            }
        }
        _ => eprintln!(
            "warning: rustup not found; the firmware needs the Rust targets {} installed",
            targets.join(", ")
        ),
    }
    let mut qemus: Vec<&Qemu> = Vec::new();
    for b in boards {
        if !qemus.iter().any(|q| q.program == b.qemu.program) {
            qemus.push(b.qemu);
        }
    }
    let missing: Vec<&Qemu> = qemus
        .into_iter()
        .filter(|q| !runs(q.program, "--version"))
        .collect();
    if missing.is_empty() {
        return Ok(None);
    }
    let programs: Vec<&str> = missing.iter().map(|q| q.program).collect();
    let packages: Vec<&str> = missing.iter().map(|q| q.package).collect();
    let root = Command::new("id")
        .arg("-u")
        .output()
        .is_ok_and(|o| String::from_utf8_lossy(&o.stdout).trim() == "0");
    if root && std::env::var_os("CI").is_some() && runs("apt-get", "--version") {
        eprintln!(
            "{} missing; CI as root: apt-get install -y {}",
            programs.join(", "),
            packages.join(" ")
        );
        let install = |extra: &[String]| {
            Command::new("apt-get")
                .args(["install", "-y", "-qq"])
                .args(&packages)
                .args(extra)
                .env("DEBIAN_FRONTEND", "noninteractive")
                .status()
                .is_ok_and(|s| s.success())
        };
        // Some images ship a newer qemu-utils than their distribution's QEMU, which then
        // refuses to install beside it: take the distribution's qemu-utils too (as
        // scripts/install-qemu.sh does).
        let ok = Command::new("apt-get")
            .args(["update", "-qq"])
            .status()
            .is_ok_and(|s| s.success())
            && (install(&[])
                || distribution_codename().is_some_and(|c| {
                    install(&["--allow-downgrades".into(), format!("qemu-utils/{c}")])
                }));
        if ok && programs.iter().all(|p| runs(p, "--version")) {
            return Ok(None);
        }
        bail!("apt-get install {} failed", packages.join(" "));
    }
    eprintln!(
        "error: {} (QEMU's system emulator, 7.2 or newer) is not installed.\n\
         Install it with:\n\n    sudo apt-get install {}\n\n\
         (Debian/Ubuntu; Fedora: sudo dnf install {}; macOS: brew install qemu),\n\
         then run this command again.",
        programs.join(", "),
        packages.join(" "),
        programs.join(" ")
    );
    Ok(Some(ExitCode::from(2)))
}
