//! Host harness for `tinydecimate`: mesh files, validity checks, Metro-style error measurement
//! and pictures. The `host-sim` binary (`main.rs`) is a thin command-line front end over these
//! modules.
//!
//! Everything the commands print on standard output goes through [`outln!`] / [`out!`]: a
//! closed pipe (`host-sim check A B --json | head -1`) ends the process quietly with exit
//! code 0, as `println!` would have panicked (exit 101).

/// Writes to standard output like `print!`, never panicking: a broken pipe exits the process
/// with code 0 at once (the reader wants no more), any other write error with code 2.
#[macro_export]
macro_rules! out {
    ($($arg:tt)*) => {
        $crate::stdout_or_exit(::std::io::Write::write_fmt(
            &mut ::std::io::stdout().lock(),
            format_args!($($arg)*),
        ))
    };
}

/// `println!` through [`out!`].
#[macro_export]
macro_rules! outln {
    () => { $crate::out!("\n") };
    ($($arg:tt)*) => {
        $crate::stdout_or_exit(::std::io::Write::write_fmt(
            &mut ::std::io::stdout().lock(),
            format_args!("{}\n", format_args!($($arg)*)),
        ))
    };
}

/// What [`out!`] does with the result of a write to standard output.
pub fn stdout_or_exit(r: std::io::Result<()>) {
    if let Err(e) = r {
        std::process::exit(exit_code_for_io(&e));
    }
}

/// Exit code after a failed write to standard output: 0 for a closed pipe (reported by
/// nobody), 2 otherwise (reported on stderr).
pub fn exit_code_for_io(e: &std::io::Error) -> i32 {
    if e.kind() == std::io::ErrorKind::BrokenPipe {
        0
    } else {
        eprintln!("error: cannot write to standard output: {e}");
        2
    }
}

pub mod backend;
pub mod bench;
pub mod check;
pub mod cluster;
pub mod cmd;
pub mod golden;
pub mod io;
pub mod metro;
pub mod pm;
pub mod progress;
pub mod qemu;
pub mod render;
pub mod simplify;
pub mod texrender;
pub mod uvstretch;
pub mod workspace;

/// The repository root (the parent of host-sim).
pub fn repo_root() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("host-sim lives inside the repository")
        .to_path_buf()
}

/// The glTF reader and writer (`io::gltf`), also at the crate's root.
pub use io::gltf;
