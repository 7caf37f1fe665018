//! `host-sim`: command-line front end of the harness (bench, golden files, QEMU, the demo).
//! Each subcommand's arguments and code live in its module (`Args` + `run`); this file only
//! dispatches. Exit codes: 0 success, 1 a check failed, 2 error. The user's commands are the
//! `tinydecimate` binary's (`cli/`).

use std::process::ExitCode;

use clap::{Parser, Subcommand};
use host_sim::cmd::{bench, bound_table, demo, golden, qemu, run_elf, stream};

#[derive(Parser)]
#[command(name = "host-sim", version, about = "Host harness for tinydecimate")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
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
    /// Stream a `.tdpm` (`tinydecimate pm encode`) into an emulated board through
    /// semihosting, in pieces of 1 to 128 bytes, as over a radio link: print the mesh the
    /// device shows as bytes arrive and its Metro error, the emulated instructions per vertex
    /// split and per edge collapse, and check that the device's bytes equal the host's.
    Stream(stream::Args),
    /// The error-bound figures: triangles under a guaranteed bound (control points, Zhu, Wang and Meng 2007)
    /// next to meshoptimizer at the same target_error, with E_max, E_mean and Metro.
    BoundTable(bound_table::Args),
    /// Runs a firmware image under QEMU and prints its decoded defmt log: the Cargo runner of
    /// examples/cortex-m4f (`cargo run --example … --target thumbv7em-none-eabihf`).
    RunElf(run_elf::Args),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match &cli.command {
        Command::Bench(a) => bench::run(a),
        Command::Qemu(a) => qemu::run(a),
        Command::Golden(a) => golden::run(a),
        Command::Demo(a) => demo::run(a),
        Command::Stream(a) => stream::run(a),
        Command::RunElf(a) => run_elf::run(a),
        Command::BoundTable(a) => bound_table::run(a),
    };
    result.unwrap_or_else(|e| host_sim::exit_code_for_error(&e))
}
