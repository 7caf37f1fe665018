//! `host-sim`: command-line front end of the harness. Each subcommand's arguments and code live
//! in its module (`Args` + `run`); this file only dispatches. Exit codes: 0 success, 1 the
//! result is not a valid simplification (`check`, `simplify`), 2 error (bad file, bad input).
//! A closed standard output (`host-sim check A B --json | head -1`) ends a command quietly with
//! exit code 0: nothing is printed with `println!`, which would panic (see `host_sim::out!`).

use std::process::ExitCode;

use clap::{Parser, Subcommand};
use host_sim::cmd::{
    bench, bound_table, check, cluster, demo, embed, golden, metro, pm, qemu, render, run_elf,
    simplify,
};

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
    /// The library on QEMU-emulated Cortex-M0/M3/M4F/M7/M33 and RISC-V (RV32IMC, RV32IMAC) boards, compared with the host;
    /// --measure for instructions, stack, image sizes and the largest mesh per board.
    Qemu(qemu::Args),
    /// The golden files in tests/golden: --check them on the host, or --bless (rewrite) them.
    Golden(golden::Args),
    /// First impression: one mesh simplified on the host and on an emulated Cortex-M4F, side by
    /// side, and whether the outputs are byte-identical; then the same with the fast and the
    /// lean mode.
    Demo(demo::Args),
    /// Progressive meshes: encode a mesh as a base mesh plus vertex splits, decode a stream to
    /// a level, measure and draw a ladder of levels.
    Pm(pm::Args),
    /// The error-bound figures: triangles under a guaranteed bound (control points, Zhu, Wang and Meng 2007)
    /// next to meshoptimizer at the same target_error, with E_max, E_mean and Metro.
    BoundTable(bound_table::Args),
    /// Runs a firmware image under QEMU and prints its decoded defmt log: the Cargo runner of
    /// examples/cortex-m4f (`cargo run --example … --target thumbv7em-none-eabihf`).
    RunElf(run_elf::Args),
    /// A mesh file as Rust source for firmware (`static` POSITIONS and TRIANGLES, in flash),
    /// or with --blob as a little-endian binary for `include_bytes!`.
    Embed(embed::Args),
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
        Command::Pm(a) => pm::run(a),
        Command::RunElf(a) => run_elf::run(a),
        Command::BoundTable(a) => bound_table::run(a),
        Command::Embed(a) => embed::run(a),
    };
    result.unwrap_or_else(|e| {
        // A reader that closed the pipe early wants no more: end quietly, as `out!` does.
        if let Some(io) = e
            .chain()
            .find_map(|c| c.downcast_ref::<std::io::Error>())
            .filter(|io| io.kind() == std::io::ErrorKind::BrokenPipe)
        {
            return ExitCode::from(host_sim::exit_code_for_io(io) as u8);
        }
        eprintln!("error: {e:#}");
        ExitCode::from(2)
    })
}
