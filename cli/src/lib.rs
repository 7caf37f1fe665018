//! The `tinydecimate` command line's library: mesh files in and out ([`io`]: OBJ, PLY, STL,
//! glTF with its attributes), the validity check ([`check`], over the shared `meshcheck`
//! crate), Metro-style error ([`metro`]), pictures ([`render`], textured in [`render::textured`]), and each
//! command's arguments and run ([`cmd`]). The `tinydecimate` binary (`main.rs`) only
//! dispatches; the harness (host-sim: bench, golden files, QEMU) uses these modules too.
//!
//! Everything the commands print on standard output goes through [`outln!`] / [`out!`]: a
//! closed pipe (`tinydecimate check A B --json | head -1`) ends the process quietly with exit
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

/// Exit code of a command that failed with `e`: a closed pipe ends quietly (0, as [`out!`]
/// does), anything else is printed on standard error and gives 2.
pub fn exit_code_for_error(e: &anyhow::Error) -> std::process::ExitCode {
    if let Some(io) = e
        .chain()
        .find_map(|c| c.downcast_ref::<std::io::Error>())
        .filter(|io| io.kind() == std::io::ErrorKind::BrokenPipe)
    {
        return std::process::ExitCode::from(exit_code_for_io(io) as u8);
    }
    eprintln!("error: {e:#}");
    std::process::ExitCode::from(2)
}

pub mod check;
pub mod cluster;
pub mod cmd;
pub mod io;
#[cfg(feature = "meshopt")]
pub mod meshopt;
pub mod metro;
pub mod pm;
pub mod progress;
pub mod render;
pub mod simplify;
pub mod uvstretch;
mod vec3;
pub mod workspace;

/// The glTF reader and writer (`io::gltf`), also at the crate's root.
pub use io::gltf;
