//! What each board holds. All buffers are statics in `.bss`; their sizes are chosen so that
//! buffers + workspace + the measured stack fit the board's RAM (see README.md for the budget).
//!
//! The case file's positions and triangles are read straight into these buffers, in the file's
//! index type: the triangle buffer is raw bytes viewed as `[[u16; 3]]` or `[[u32; 3]]`.

#![allow(dead_code)]

use meshfmt::{Board, IndexType};

#[cfg(feature = "board-microbit")]
mod sel {
    pub const BOARD: super::Board = super::Board::Microbit;
    pub const NAME: &str = "microbit";
    /// 16 KB of RAM: positions 2 976 B, triangles 2 592 B, workspace 5 608 B; ~4.4 KB of
    /// stack, of which the firmware needs ~4.0 KB at its deepest (measured with `qemu
    /// --measure`). 432 triangles are exactly the largest case run here (box6-new-u16, and
    /// fin10-paper-u32 as 214 u32 triangles); 248 vertices take the `strip 430` of the
    /// capacity search.
    pub const MAX_VERTICES: usize = 248;
    pub const MAX_TRIANGLES: usize = 432;
    /// No room for stored quadrics (40 B per vertex): their cases are skipped here.
    pub const QUADRIC_VERTICES: usize = 0;
    /// No stack for vertex decimation (a removal's fixed buffers overflow the Cortex-M3's
    /// 5.8 KB and the 32 KB RISC-V's 7 KB): its cases are skipped here and its code left out.
    pub const VERTEX_DECIMATION: bool = false;
    /// No fast or lean mode: their code would not fit the flash beside the exact engine's, and
    /// their workspace (the 2 KB histogram alone) is most of what this board's RAM holds:
    /// their cases are skipped here.
    pub const FAST_VERTICES: usize = 0;
    pub const FAST_TRIANGLES: usize = 0;
    /// The lean mode in integers (`pipeline::Integer`, `u16` links: 11 B per vertex, 6 B per
    /// triangle, 2 KB of histogram: 5 828 B) holds the 12 x 12 grid, in the engine's RAM with
    /// the stream arena's bytes beside the exact engine's ([`Engine`]); the box and the plate's
    /// corner would need more than both. No fast mode in integers: its run's frames are deeper
    /// than the lean run's, and the lean run's high-water leaves the stack no room for them.
    pub const INT_FAST_VERTICES: usize = 0;
    pub const INT_FAST_TRIANGLES: usize = 0;
    pub const INT_LEAN_VERTICES: usize = 180;
    pub const INT_LEAN_TRIANGLES: usize = 300;
    pub type Link = u16;
    /// Progressive streams (`pm-*` cases): 44 vertex splits (704 B) and an 80 B chunk buffer
    /// (chunks of up to 71 B), in the engine's RAM ([`Engine`]); triangles, their links, the
    /// list heads and the positions reuse the buffers above.
    pub const PM_VERTICES: usize = 44;
    pub const PM_BUFFER: usize = 80;
}

#[cfg(feature = "board-lm3s6965evb")]
mod sel {
    pub const BOARD: super::Board = super::Board::Lm3s6965evb;
    pub const NAME: &str = "lm3s6965evb";
    /// 64 KB of RAM: positions 15 000 B, triangles 14 400 B, workspace ≈ 28 100 B.
    pub const MAX_VERTICES: usize = 1_250;
    pub const MAX_TRIANGLES: usize = 2_400;
    /// No room for stored quadrics (40 B per vertex): their cases are skipped here.
    pub const QUADRIC_VERTICES: usize = 0;
    /// Vertex decimation needs more stack than the ~5.8 KB left here (a removal's fixed
    /// buffers): its cases are skipped and its code left out.
    pub const VERTEX_DECIMATION: bool = false;
    /// No fast or lean mode: their code would not fit the flash beside the exact engine's, and
    /// their workspace (the 2 KB histogram alone) is most of what this board's RAM holds:
    /// their cases are skipped here.
    pub const FAST_VERTICES: usize = 0;
    pub const FAST_TRIANGLES: usize = 0;
    /// The integer modes (`pipeline::Integer`, `u16` links: 37 B per vertex for the fast one,
    /// 11 B for the lean one, 6 B per triangle, 2 KB of histogram): as large a mesh as the fast
    /// workspace holds in the exact engine's RAM, 2 vertices per triangle (28 018 B), for both.
    pub const INT_FAST_VERTICES: usize = 530;
    pub const INT_FAST_TRIANGLES: usize = 1_060;
    pub const INT_LEAN_VERTICES: usize = 530;
    pub const INT_LEAN_TRIANGLES: usize = 1_060;
    pub type Link = u16;
    /// Progressive streams: 100 vertex splits (1 600 B) and a 272 B chunk buffer.
    pub const PM_VERTICES: usize = 100;
    pub const PM_BUFFER: usize = 272;
}

#[cfg(any(
    feature = "board-mps2-an386",
    feature = "board-mps2-an500",
    feature = "board-mps2-an505"
))]
mod sel {
    #[cfg(feature = "board-mps2-an386")]
    pub const BOARD: super::Board = super::Board::Mps2An386;
    #[cfg(feature = "board-mps2-an386")]
    pub const NAME: &str = "mps2-an386";
    #[cfg(feature = "board-mps2-an500")]
    pub const BOARD: super::Board = super::Board::Mps2An500;
    #[cfg(feature = "board-mps2-an500")]
    pub const NAME: &str = "mps2-an500";
    #[cfg(feature = "board-mps2-an505")]
    pub const BOARD: super::Board = super::Board::Mps2An505;
    #[cfg(feature = "board-mps2-an505")]
    pub const NAME: &str = "mps2-an505";
    /// 4 MB of RAM, u32 links (u16 links stop at 65 535 vertices and 65 535 triangles, below
    /// this board's 106 000 triangles): positions
    /// 636 000 B, triangles 1 272 000 B, workspace 2 173 000 B; ~110 KB left for the stack.
    pub const MAX_VERTICES: usize = 53_000;
    pub const MAX_TRIANGLES: usize = 106_000;
    /// Stored quadrics (40 B per vertex) for meshes up to this many vertices: 40 960 B of
    /// the stack's ~110 KB.
    pub const QUADRIC_VERTICES: usize = 1_024;
    pub const VERTEX_DECIMATION: bool = true;
    /// The fast mode's workspace, `u16` links (53 B per vertex, 6 B per triangle, 2 KB of
    /// histogram: 2 082 048 B), shares the exact engine's RAM ([`Engine`]): as large a mesh
    /// as fits it, 2 vertices per triangle. The lean mode's workspace has the same capacity
    /// (11 B per vertex: 738 048 B).
    pub const FAST_VERTICES: usize = 32_000;
    pub const FAST_TRIANGLES: usize = 64_000;
    /// The integer modes (`pipeline::Integer`) with the float modes' capacity: the fast
    /// workspace takes 37 B per vertex (1 570 048 B), the lean one 11 B (738 048 B).
    pub const INT_FAST_VERTICES: usize = 32_000;
    pub const INT_FAST_TRIANGLES: usize = 64_000;
    pub const INT_LEAN_VERTICES: usize = 32_000;
    pub const INT_LEAN_TRIANGLES: usize = 64_000;
    pub type Link = u32;
    /// Progressive streams: 3 000 vertex splits (48 000 B: the cow's 2 844 fit) and a 4 KB
    /// chunk buffer. With the quadrics that leaves ~20 KB of stack (the firmware needs ~4 KB).
    pub const PM_VERTICES: usize = 3_000;
    pub const PM_BUFFER: usize = 4_096;
}

/// An ESP32-C3-class RISC-V part (riscv32imc, no FPU: soft float as on the M0 and M3) on QEMU's
/// `virt` machine, linked into 400 KB of RAM (memory/riscv32-virt-400k.x).
#[cfg(feature = "board-riscv32imc-virt-400k")]
mod sel {
    pub const BOARD: super::Board = super::Board::Riscv32ImcVirt400k;
    pub const NAME: &str = "riscv32imc-virt-400k";
    /// 400 KB of RAM, u16 links: positions 72 000 B, triangles 78 000 B, workspace ≈ 144 000 B;
    /// quadrics 40 960 B and the stream arena 52 096 B below; the rest is stack. 13 000
    /// triangles rather than 2 per vertex: the cow's stream (5 804 triangles and as many links
    /// after the list heads) needs the bytes.
    pub const MAX_VERTICES: usize = 6_000;
    pub const MAX_TRIANGLES: usize = 13_000;
    /// Stored quadrics (40 B per vertex) for meshes up to this many vertices, as on the 4 MB
    /// boards: every stored-quadric and bounded golden case fits.
    pub const QUADRIC_VERTICES: usize = 1_024;
    pub const VERTEX_DECIMATION: bool = true;
    /// The fast mode's workspace, `u16` links (53 B per vertex, 6 B per triangle, 2 KB of
    /// histogram: 132 048 B), shares the exact engine's RAM ([`Engine`]): as large a mesh
    /// as fits it, 2 vertices per triangle (the cow does not). The lean mode's workspace has
    /// the same capacity (11 B per vertex: 48 048 B).
    pub const FAST_VERTICES: usize = 2_000;
    pub const FAST_TRIANGLES: usize = 4_000;
    /// The integer modes (`pipeline::Integer`, the arithmetic for this core without an FPU):
    /// room for the cow (2 903 vertices, 5 804 triangles), which the float workspaces lack.
    /// The fast workspace (37 B per vertex: 149 048 B) is larger than the exact engine's and
    /// takes the stream arena's bytes too ([`Engine`]); the lean one (71 048 B) is not.
    pub const INT_FAST_VERTICES: usize = 3_000;
    pub const INT_FAST_TRIANGLES: usize = 6_000;
    pub const INT_LEAN_VERTICES: usize = 3_000;
    pub const INT_LEAN_TRIANGLES: usize = 6_000;
    pub type Link = u16;
    /// Progressive streams: 3 000 vertex splits (48 000 B) and a 4 KB chunk buffer.
    pub const PM_VERTICES: usize = 3_000;
    pub const PM_BUFFER: usize = 4_096;
}

/// A GD32VF103-class RISC-V part (riscv32imac, no FPU) on QEMU's `virt` machine, linked into
/// 32 KB of RAM (memory/riscv32-virt-32k.x).
#[cfg(feature = "board-riscv32imac-virt-32k")]
mod sel {
    pub const BOARD: super::Board = super::Board::Riscv32ImacVirt32k;
    pub const NAME: &str = "riscv32imac-virt-32k";
    /// 32 KB of RAM, u16 links: positions 6 000 B, triangles 6 000 B, workspace ≈ 11 500 B.
    pub const MAX_VERTICES: usize = 500;
    pub const MAX_TRIANGLES: usize = 1_000;
    /// No room for stored quadrics (40 B per vertex): their cases are skipped here.
    pub const QUADRIC_VERTICES: usize = 0;
    /// Vertex decimation overflows the ~7 KB of stack left here (a removal's fixed buffers):
    /// its cases are skipped and its code left out.
    pub const VERTEX_DECIMATION: bool = false;
    /// No fast or lean mode: their code would not fit the flash beside the exact engine's, and
    /// their workspace (the 2 KB histogram alone) is most of what this board's RAM holds:
    /// their cases are skipped here.
    pub const FAST_VERTICES: usize = 0;
    pub const FAST_TRIANGLES: usize = 0;
    /// The integer modes (`pipeline::Integer`, `u16` links): the fast workspace (37 B per
    /// vertex: 13 024 B, with the stream arena's bytes, [`Engine`]) holds the small golden
    /// meshes, the lean one (11 B per vertex: 11 248 B) more.
    pub const INT_FAST_VERTICES: usize = 224;
    pub const INT_FAST_TRIANGLES: usize = 448;
    pub const INT_LEAN_VERTICES: usize = 400;
    pub const INT_LEAN_TRIANGLES: usize = 800;
    pub type Link = u16;
    /// Progressive streams: 100 vertex splits (1 600 B) and a 272 B chunk buffer, as on the
    /// lm3s6965evb.
    pub const PM_VERTICES: usize = 100;
    pub const PM_BUFFER: usize = 272;
}

pub use sel::*;

/// Whether the board has quadric storage at all. Without it the firmware skips every case that
/// borrows it (stored quadrics, the energy's samples, the error bound) and leaves their code
/// out of the image.
pub const HAS_QUADRICS: bool = QUADRIC_VERTICES > 0;

/// Bytes a bounded case (`Controls`) borrows from the quadric storage, which
/// it does not use: a read-only copy of the input triangles and the control-point links
/// (`bound::control_len(T, V)` of `Link`).
pub const BOUND_BYTES: usize = QUADRIC_VERTICES * 40;

/// Bytes a bounded case of `v` vertices and `t` triangles of `index_bytes` needs: the
/// triangles' copy and `tinydecimate::bound::control_len(t, v)` = `2t + v` links (written out:
/// the image without the library must build too).
pub const fn bound_bytes(v: usize, t: usize, index_bytes: usize) -> usize {
    t * 3 * index_bytes + (2 * t + v) * core::mem::size_of::<Link>()
}

/// The largest mesh (vertices, triangles of `it`) a case of `entry` takes on this board: the
/// buffers', and for the fast and the lean mode their workspace's.
pub const fn capacity(it: IndexType, entry: meshfmt::Entry) -> (usize, usize) {
    let t = triangle_capacity(it);
    match entry {
        meshfmt::Entry::Fast | meshfmt::Entry::Lean => {
            (min(FAST_VERTICES, MAX_VERTICES), min(FAST_TRIANGLES, t))
        }
        meshfmt::Entry::FastInteger => (
            min(INT_FAST_VERTICES, MAX_VERTICES),
            min(INT_FAST_TRIANGLES, t),
        ),
        meshfmt::Entry::LeanInteger => (
            min(INT_LEAN_VERTICES, MAX_VERTICES),
            min(INT_LEAN_TRIANGLES, t),
        ),
        // The wedges follow the triangles in the triangle buffer.
        meshfmt::Entry::FastWedges | meshfmt::Entry::LeanWedges => {
            (min(FAST_VERTICES, MAX_VERTICES), min(FAST_TRIANGLES, t / 2))
        }
        _ => (MAX_VERTICES, t),
    }
}

const fn min(a: usize, b: usize) -> usize {
    if a < b {
        a
    } else {
        b
    }
}

/// Bytes of the triangle buffer: `MAX_TRIANGLES` triangles of the widest index type this board
/// takes (`u16` boards read `u32` files too, with half as many triangles).
pub const TRIANGLE_BYTES: usize = MAX_TRIANGLES * 3 * core::mem::size_of::<Link>();

/// How many triangles of `it` fit the triangle buffer.
pub const fn triangle_capacity(it: IndexType) -> usize {
    let by_buffer = TRIANGLE_BYTES / it.triangle_bytes();
    if by_buffer < MAX_TRIANGLES {
        by_buffer
    } else {
        MAX_TRIANGLES
    }
}

/// The triangle buffer: raw bytes, 4-aligned so they can be viewed as `u16` or `u32` triples.
#[repr(C, align(4))]
pub struct TriangleBytes(pub [u8; TRIANGLE_BYTES]);

#[cfg(feature = "lib")]
pub type Workspace = tinydecimate::Workspace<Link, MAX_VERTICES, MAX_TRIANGLES>;

/// Whether the board runs the fast and the lean mode (`MethodCode::Fast`, `MethodCode::Lean`,
/// and with wedges `FastWedges`, `LeanWedges`). Without them the firmware skips every fast and
/// lean case and leaves their code out of the image.
pub const FAST: bool = FAST_VERTICES > 0;

/// The fast mode's workspace (`u16` links on every board: it holds at most 32 000 vertices).
#[cfg(feature = "lib")]
pub type FastWorkspace = tinydecimate::pipeline::FastWorkspace<u16, FAST_VERTICES, FAST_TRIANGLES>;

/// The lean mode's workspace: the fast mode's capacity, without its stored quadrics.
#[cfg(feature = "lib")]
pub type LeanWorkspace = tinydecimate::pipeline::LeanWorkspace<u16, FAST_VERTICES, FAST_TRIANGLES>;

/// Whether the board runs the fast mode in integers (`MethodCode::FastInteger`); without it
/// the firmware skips those cases and leaves the code out, as for [`FAST`].
pub const INT_FAST: bool = INT_FAST_VERTICES > 0;

/// Whether the board runs the lean mode in integers (`MethodCode::LeanInteger`), as
/// [`INT_FAST`].
pub const INT_LEAN: bool = INT_LEAN_VERTICES > 0;

/// Whether this image carries the library entry point of `entry` among those a board may
/// leave out for want of RAM or flash: the float pipeline ([`FAST`]) and each integer mode.
pub const fn has_mode(entry: meshfmt::Entry) -> bool {
    match entry {
        meshfmt::Entry::Fast
        | meshfmt::Entry::Lean
        | meshfmt::Entry::FastWedges
        | meshfmt::Entry::LeanWedges => FAST,
        meshfmt::Entry::FastInteger => INT_FAST,
        meshfmt::Entry::LeanInteger => INT_LEAN,
        _ => true,
    }
}

/// The fast mode's workspace in integers (`pipeline::Integer`: `[u16; 3]` grid positions).
#[cfg(feature = "lib")]
pub type FastIntWorkspace = tinydecimate::pipeline::FastWorkspace<
    u16,
    INT_FAST_VERTICES,
    INT_FAST_TRIANGLES,
    tinydecimate::pipeline::Integer,
>;

/// The lean mode's workspace in integers.
#[cfg(feature = "lib")]
pub type LeanIntWorkspace = tinydecimate::pipeline::LeanWorkspace<
    u16,
    INT_LEAN_VERTICES,
    INT_LEAN_TRIANGLES,
    tinydecimate::pipeline::Integer,
>;

/// The working memory of a run, one static for every engine and for the progressive stream's
/// arena: a run is one case or one stream, so it needs the exact engine's workspace, one of
/// the pipeline's (fast or lean, in floats or in integers) or the stream arena, never two, and
/// the RAM is the largest of them rather than their sum (on the 4 MB boards their sum does not
/// fit). `Exact` is variant 0 and every variant is all zero, so the static is all zero and
/// sits in `.bss`; a fast case turns it into `Fast` before its run (`main.rs`,
/// `fast_workspace`), a lean case into `Lean` (`lean_workspace`), an integer case into
/// `FastInteger` or `LeanInteger`, a stream into `Stream` (`stream_arena`). The tag is a `u64`
/// so that no padding lies between it and any variant (the arena's vertex splits are
/// 8-aligned): the switch is then a store of the tag and a memset of the variant in place
/// (with a `u8` tag the compiler built the new value on the stack and copied it, a frame of
/// the workspace's size).
#[cfg(feature = "lib")]
#[repr(C, u64)]
// Every variant is large on purpose: the enum is how they share the RAM (no heap to box one).
#[allow(clippy::large_enum_variant)]
pub enum Engine {
    /// `Workspace`, the exact engine (every method but the pipeline's).
    Exact(Workspace),
    /// `FastWorkspace`, the fast mode.
    Fast(FastWorkspace),
    /// `LeanWorkspace`, the lean mode.
    Lean(LeanWorkspace),
    /// `FastIntWorkspace`, the fast mode in integers.
    FastInteger(FastIntWorkspace),
    /// `LeanIntWorkspace`, the lean mode in integers.
    LeanInteger(LeanIntWorkspace),
    /// `PmArena`, a progressive stream's vertex splits and chunk buffer.
    Stream(PmArena),
}

// The fast mode adds no RAM: its workspace fits in the exact engine's.
#[cfg(feature = "lib")]
const _: () = assert!(FastWorkspace::BYTES <= Workspace::BYTES);
// Nor does the lean mode.
#[cfg(feature = "lib")]
const _: () = assert!(LeanWorkspace::BYTES <= Workspace::BYTES);
/// What the engine may take without adding RAM: the exact engine's workspace and the stream
/// arena, which would otherwise be two statics side by side.
#[cfg(feature = "lib")]
pub const ENGINE_BYTES: usize = Workspace::BYTES + core::mem::size_of::<PmArena>();
// The integer modes add no RAM: each workspace fits in the exact engine's and the arena's
// bytes (on the micro:bit and the 400 KB RISC-V it needs both), and so does the engine whole,
// its tag included.
#[cfg(feature = "lib")]
const _: () = assert!(FastIntWorkspace::BYTES <= ENGINE_BYTES);
#[cfg(feature = "lib")]
const _: () = assert!(LeanIntWorkspace::BYTES <= ENGINE_BYTES);
#[cfg(feature = "lib")]
const _: () = assert!(
    core::mem::size_of::<Engine>()
        <= Workspace::BYTES
            + core::mem::size_of::<PmArena>()
            + core::mem::size_of::<u64>()
);

/// What a progressive stream needs beyond the triangle and position buffers (which it reuses:
/// the triangle bytes hold a list head per vertex, then the triangles and their links): a split
/// record per vertex and a chunk buffer. All zero; it lives in the [`Engine`], whose RAM a
/// stream does not otherwise use.
#[cfg(feature = "lib")]
pub struct PmArena {
    pub splits: [tinydecimate::progressive::Split<Link>; PM_VERTICES],
    pub buffer: [u8; PM_BUFFER],
}

#[cfg(feature = "lib")]
impl PmArena {
    pub const fn new() -> Self {
        PmArena {
            splits: [tinydecimate::progressive::Split::EMPTY; PM_VERTICES],
            buffer: [0; PM_BUFFER],
        }
    }
}

/// Bytes of the list heads at the start of the triangle buffer (4-aligned).
pub const PM_HEAD_BYTES: usize = (PM_VERTICES * core::mem::size_of::<Link>() + 3) & !3;
/// Triangles of a progressive stream: what is left of the triangle buffer after the heads,
/// halved (triangles, links).
pub const PM_TRIANGLES: usize =
    (TRIANGLE_BYTES - PM_HEAD_BYTES) / (2 * 3 * core::mem::size_of::<Link>());
