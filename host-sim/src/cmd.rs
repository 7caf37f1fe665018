//! The subcommands of the `host-sim` binary: each file holds one command's arguments and its
//! `run`.

pub mod bound_table;
pub mod demo;
pub mod simplify;
pub mod check;
pub mod metro;
pub mod render;
pub mod golden;
pub mod qemu;
pub mod run_elf;
