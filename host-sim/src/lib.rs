//! Host harness for `tinydecimate`: mesh files, validity checks, Metro-style error measurement
//! and pictures. The `host-sim` binary (`main.rs`) is a thin command-line front end over these
//! modules.

pub mod bench;
pub mod check;
pub mod cluster;
pub mod demo;
pub mod golden;
pub mod io;
pub mod metro;
pub mod qemu;
pub mod render;
pub mod simplify;
