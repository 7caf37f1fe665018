//! `host-sim`: command-line front end of the harness. Each subcommand's arguments and code live
//! in its module (`Args` + `run`); this file only dispatches. Exit codes: 0 success, 1 the
//! result is not a valid simplification (`check`, `simplify`), 2 error (bad file, bad input).

use std::process::ExitCode;

use clap::{Parser, Subcommand};
use host_sim::{bench, check, cluster, demo, golden, metro, qemu, render, simplify};

#[derive(Parser)]
#[command(name = "host-sim", version, about = "Host harness for tinydecimate")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
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
    /// Every tinydecimate mode (default, greedy W, paper passes) against meshoptimizer: time,
    /// memory, error (also at the same triangle count when the library stops short), validity.
    Bench(bench::Args),
    /// The library on QEMU-emulated Cortex-M0/M3/M4F/M7/M33 boards, compared with the host;
    /// --measure for instructions, stack, image sizes and the largest mesh per board.
    Qemu(qemu::Args),
    /// The golden files in tests/golden: --check them on the host, or --bless (rewrite) them.
    Golden(golden::Args),
    /// First impression: one mesh simplified on the host and on an emulated Cortex-M4F, side by
    /// side, and whether the outputs are byte-identical.
    Demo(demo::Args),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match &cli.command {
        Command::Simplify(a) => simplify::run(a),
        Command::Cluster(a) => cluster::run(a),
        Command::Metro(a) => metro::run(a),
        Command::Check(a) => check::run(a),
        Command::Render(a) => render::run(a),
        Command::Bench(a) => bench::run(a),
        Command::Qemu(a) => qemu::run(a),
        Command::Golden(a) => golden::run(a),
        Command::Demo(a) => demo::run(a),
    };
    result.unwrap_or_else(|e| {
        eprintln!("error: {e:#}");
        ExitCode::from(2)
    })
}
