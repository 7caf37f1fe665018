//! The subcommands of the `host-sim` binary: each file holds one command's arguments and its
//! `run`. The user's commands (simplify, check, render, ...) are the `tinydecimate` binary's,
//! in `tinydecimate_cli::cmd`.

pub mod bench;
pub mod bound_table;
pub mod demo;
pub mod golden;
pub mod qemu;
pub mod run_elf;
pub mod stream;
