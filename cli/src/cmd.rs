//! The subcommands of the `tinydecimate` binary: each file holds one command's arguments and
//! its `run`.

pub mod check;
pub mod cluster;
pub mod embed;
pub mod metro;
pub mod pm;
pub mod render;
pub mod simplify;

use clap::{Parser, Subcommand};

/// The `tinydecimate` command line.
#[derive(Parser)]
#[command(
    name = "tinydecimate",
    version,
    about = "Simplify triangle meshes (OBJ, PLY, STL, glTF) with tinydecimate, then check, \
             measure and draw the result"
)]
pub struct Cli {
    /// The command.
    #[command(subcommand)]
    pub command: Command,
}

/// The commands.
#[derive(Subcommand)]
pub enum Command {
    /// Simplify a mesh file with tinydecimate, then check and measure the result.
    Simplify(simplify::Args),
    /// Streaming vertex clustering of a mesh file (by target count or cell size), optionally
    /// followed by the collapse engine; prints counts, grid, table bytes, time, Metro error.
    Cluster(cluster::Args),
    /// Metro surface distance between an original and a simplified mesh.
    Metro(metro::Args),
    /// Topology of both meshes and whether the second is a valid simplification of the first.
    Check(check::Args),
    /// Flat-shaded PNG of a mesh, or a side-by-side comparison with an error heatmap.
    Render(render::Args),
    /// Progressive meshes: encode a mesh as a base mesh plus vertex splits, decode a stream to
    /// a level, measure and draw a ladder of levels.
    Pm(pm::Args),
    /// A mesh file as Rust source for firmware (`static` POSITIONS and TRIANGLES, in flash),
    /// or with --blob as a little-endian binary for `include_bytes!`.
    Embed(embed::Args),
}

impl Command {
    /// Runs the command. Exit codes: 0 success, 1 the result is not a valid simplification
    /// (`check`, `simplify`), 2 error (bad file, bad input).
    pub fn run(&self) -> anyhow::Result<std::process::ExitCode> {
        match self {
            Command::Simplify(a) => simplify::run(a),
            Command::Cluster(a) => cluster::run(a),
            Command::Metro(a) => metro::run(a),
            Command::Check(a) => check::run(a),
            Command::Render(a) => render::run(a),
            Command::Pm(a) => pm::run(a),
            Command::Embed(a) => embed::run(a),
        }
    }
}
