//! Meshes for the firmware examples: `static`s, so in flash.

#![no_std]

/// The cow of the tinydecimate repository's `tests/fixtures/cow.obj`, written by
/// `tinydecimate embed` (the command that regenerates it heads the file). For a mesh of your own,
/// run the same command on your OBJ, PLY, STL or glTF file and replace `src/cow.rs`.
pub mod cow;
