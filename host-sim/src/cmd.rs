//! The subcommands of the `host-sim` binary: each file holds one command's arguments and its
//! `run`.

pub mod bench;
pub mod bound_table;
pub mod check;
pub mod cluster;
pub mod demo;
pub mod embed;
pub mod golden;
pub mod metro;
pub mod pm;
pub mod qemu;
pub mod render;
pub mod run_elf;
pub mod simplify;
