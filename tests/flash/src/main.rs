//! Minimal firmware for the flash of one instantiation of tinydecimate, as a user would build it.
//!
//! Positions are a `static` in flash, the triangles a static buffer in RAM, the workspace a
//! static in `.bss`. With the feature `call`, `main` runs
//! `ws.simplify(&POSITIONS, tris, &Config::new())` on `Workspace<u16, 512, 1024>` and hands the
//! resulting triangle count to `black_box`, as firmware would use it. Without it, `main` touches
//! the same statics and nothing else, so (image with) - (image without) is the library.
//! `paper`, `u32-triangles` and `u32-links` change or add instantiations, `fast` calls the fast
//! mode (`pipeline::FastWorkspace<u16, 512, 1024>`) instead, `lean` the lean mode
//! (`pipeline::LeanWorkspace<u16, 512, 1024>`), `fast-integer` and `lean-integer` the same
//! modes in the integer arithmetic (`pipeline::Integer`) on grid positions, a second static in
//! flash that `grid` alone adds to the image without the call; `batched`, `seams` and `parts`
//! compile the library feature of that name into the default call (see Cargo.toml).
//!
//! Never run, only linked and measured: `scripts/flash.sh` (and `host-sim qemu --measure`).
#![no_std]
#![no_main]

use core::hint::black_box;

#[cfg(feature = "call")]
use tinydecimate::Config;
use tinydecimate::Workspace;

/// The library cannot panic (tests/no-panic), so this is never reached; it only has to link.
#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    loop {
        core::sync::atomic::compiler_fence(core::sync::atomic::Ordering::SeqCst);
    }
}

/// A regular octahedron: 6 vertices, in flash (the library only reads positions).
static POSITIONS: [[f32; 3]; 6] = [
    [1.0, 0.0, 0.0],
    [-1.0, 0.0, 0.0],
    [0.0, 1.0, 0.0],
    [0.0, -1.0, 0.0],
    [0.0, 0.0, 1.0],
    [0.0, 0.0, -1.0],
];

/// The same octahedron on the integer pipeline's 15-bit grid (where `pipeline::quantise` puts
/// it), in flash: the integer calls' positions, also in their image without the call.
#[cfg(feature = "grid")]
static GRID_POSITIONS: [[u16; 3]; 6] = [
    [16384, 8192, 8192],
    [0, 8192, 8192],
    [8192, 16384, 8192],
    [8192, 0, 8192],
    [8192, 8192, 16384],
    [8192, 8192, 0],
];

/// Its 8 triangles, wound outwards.
const OCTAHEDRON: [[u16; 3]; 8] = [
    [0, 2, 4],
    [2, 1, 4],
    [1, 3, 4],
    [3, 0, 4],
    [2, 0, 5],
    [1, 2, 5],
    [3, 1, 5],
    [0, 3, 5],
];

/// The same triangles with u32 indices.
const fn octahedron_u32() -> [[u32; 3]; 8] {
    let mut out = [[0u32; 3]; 8];
    let mut t = 0;
    while t < 8 {
        let mut k = 0;
        while k < 3 {
            out[t][k] = OCTAHEDRON[t][k] as u32;
            k += 1;
        }
        t += 1;
    }
    out
}

/// The configuration of every call.
#[cfg(feature = "call")]
const CONFIG: Config = if cfg!(feature = "paper") {
    Config::paper()
} else {
    Config::new()
};

#[cfg(target_arch = "arm")]
#[cortex_m_rt::entry]
fn main() -> ! {
    // cortex-m-rt turns these into `&'static mut` references (no `unsafe`): RAM statics, the
    // workspaces zeroed in `.bss` (`Workspace::new` is const and all zero).
    static mut WS: Workspace<u16, 512, 1024> = Workspace::new();
    static mut WS32: Workspace<u32, 512, 1024> = Workspace::new();
    static mut TRIS: [[u16; 3]; 8] = OCTAHEDRON;
    static mut TRIS32: [[u32; 3]; 8] = octahedron_u32();
    run(WS, WS32, TRIS, TRIS32)
}

#[cfg(target_arch = "riscv32")]
#[riscv_rt::entry]
fn main() -> ! {
    static mut WS: Workspace<u16, 512, 1024> = Workspace::new();
    static mut WS32: Workspace<u32, 512, 1024> = Workspace::new();
    static mut TRIS: [[u16; 3]; 8] = OCTAHEDRON;
    static mut TRIS32: [[u32; 3]; 8] = octahedron_u32();
    // SAFETY: `main` runs once and nothing else names these statics: the references are
    // unique, as the ones cortex-m-rt's `entry` makes on Cortex-M.
    unsafe {
        run(
            &mut *core::ptr::addr_of_mut!(WS),
            &mut *core::ptr::addr_of_mut!(WS32),
            &mut *core::ptr::addr_of_mut!(TRIS),
            &mut *core::ptr::addr_of_mut!(TRIS32),
        )
    }
}

/// The firmware: the same statics with and without the call, so only the library differs.
#[inline(always)]
fn run(
    ws: &'static mut Workspace<u16, 512, 1024>,
    ws32: &'static mut Workspace<u32, 512, 1024>,
    tris: &'static mut [[u16; 3]; 8],
    tris32: &'static mut [[u32; 3]; 8],
) -> ! {
    let (ws, ws32) = (black_box(ws), black_box(ws32));
    let (tris, tris32) = (black_box(tris), black_box(tris32));
    black_box(&POSITIONS);
    #[cfg(feature = "grid")]
    black_box(&GRID_POSITIONS);

    #[cfg(feature = "call")]
    {
        // What firmware does with the result: use the triangle count, or the error.
        #[cfg(not(any(
            feature = "fast",
            feature = "lean",
            feature = "fast-integer",
            feature = "lean-integer"
        )))]
        let result = ws.simplify(&POSITIONS, &mut *tris, &CONFIG);
        // The fast mode's workspace instead (on the stack: this firmware is only linked).
        #[cfg(feature = "fast")]
        let result = black_box(tinydecimate::pipeline::FastWorkspace::<u16, 512, 1024>::new())
            .simplify(&POSITIONS, &mut *tris, &CONFIG);
        // The lean mode's workspace instead (likewise).
        #[cfg(all(feature = "lean", not(feature = "fast")))]
        let result = black_box(tinydecimate::pipeline::LeanWorkspace::<u16, 512, 1024>::new())
            .simplify(&POSITIONS, &mut *tris, &CONFIG);
        // The fast mode in the integer arithmetic instead, on the grid positions (likewise).
        #[cfg(all(feature = "fast-integer", not(any(feature = "fast", feature = "lean"))))]
        let result = black_box(tinydecimate::pipeline::FastWorkspace::<
            u16,
            512,
            1024,
            tinydecimate::pipeline::Integer,
        >::new())
        .simplify(&GRID_POSITIONS, &mut *tris, &CONFIG);
        // The lean mode in the integer arithmetic instead (likewise).
        #[cfg(all(
            feature = "lean-integer",
            not(any(feature = "fast", feature = "lean", feature = "fast-integer"))
        ))]
        let result = black_box(tinydecimate::pipeline::LeanWorkspace::<
            u16,
            512,
            1024,
            tinydecimate::pipeline::Integer,
        >::new())
        .simplify(&GRID_POSITIONS, &mut *tris, &CONFIG);
        let n = match result {
            Ok(report) => report.triangles_out,
            Err(_) => usize::MAX,
        };
        black_box(n);
        #[cfg(feature = "u32-triangles")]
        black_box(match ws.simplify(&POSITIONS, &mut *tris32, &CONFIG) {
            Ok(report) => report.triangles_out,
            Err(_) => usize::MAX,
        });
        #[cfg(feature = "u32-links")]
        black_box(match ws32.simplify(&POSITIONS, &mut *tris32, &CONFIG) {
            Ok(report) => report.triangles_out,
            Err(_) => usize::MAX,
        });
    }
    black_box((ws, ws32, tris, tris32));
    loop {
        core::sync::atomic::compiler_fence(core::sync::atomic::Ordering::SeqCst);
    }
}
