//! `tinydecimate`: the command line. Each subcommand's arguments and code live in the
//! library's `cmd` module; this file only parses and dispatches. Exit codes: 0 success, 1 the
//! result is not a valid simplification (`check`, `simplify`), 2 error (bad file, bad input).
//! A closed standard output (`tinydecimate check A B --json | head -1`) ends a command quietly
//! with exit code 0 (see `tinydecimate_cli::out!`).

use std::process::ExitCode;

use clap::Parser;
use tinydecimate_cli::cmd::Cli;

fn main() -> ExitCode {
    let cli = Cli::parse();
    cli.command
        .run()
        .unwrap_or_else(|e| tinydecimate_cli::exit_code_for_error(&e))
}
