//! A complete firmware for a Cortex-M4F board: simplifies a mesh kept in flash (`src/cow.rs`,
//! written from an OBJ file by `tinydecimate embed`) with a `static` workspace and logs the report
//! through defmt.
//!
//! In QEMU (mps2-an386), from this folder, with `qemu-system-arm` installed:
//!
//! ```text
//! cargo run --release --example simplify_in_flash
//! ```
//!
//! The runner in `.cargo/config.toml` (qemu-runner.sh) starts QEMU and decodes the defmt log
//! with defmt-print and this image's table; it exits with the firmware's exit code (0: the
//! target was reached). On a real board, switch to the commented probe-rs runner in the same
//! file and to that board's `memory.x`; with probe-rs, defmt-rtt is the usual transport instead
//! of defmt-semihosting (see Cargo.toml).

#![no_std]
#![no_main]

use core::panic::PanicInfo;

// The critical-section implementation defmt needs (cortex-m's `critical-section-single-core`).
use cortex_m as _;
use cortex_m_rt::entry;
use defmt_semihosting as _;
use static_cell::ConstStaticCell;
use tinydecimate::{Config, Workspace};
use tinydecimate_examples::cow;

/// The triangle buffer the library rewrites in place: a `static` in RAM (`.bss`), filled from
/// the copy in flash ([`cow::TRIANGLES`]) at boot, so the original stays there to start over.
static TRIANGLES: ConstStaticCell<[[u16; 3]; cow::TRIANGLES_COUNT]> =
    ConstStaticCell::new([[0; 3]; cow::TRIANGLES_COUNT]);

/// The workspace type: u16 links, sized for this mesh at compile time.
type Ws = Workspace<u16, { cow::VERTICES }, { cow::TRIANGLES_COUNT }>;

/// The workspace: a `static` in `.bss` (`Workspace::new` is a `const fn`), never on the stack.
static WORKSPACE: ConstStaticCell<Ws> = ConstStaticCell::new(Workspace::new());

#[entry]
fn main() -> ! {
    let ws = WORKSPACE.take();
    let triangles = TRIANGLES.take();
    triangles.copy_from_slice(&cow::TRIANGLES);
    // The positions are read where they are: in flash, below RAM at 0x2000_0000 (mps2-an386's
    // code memory, a real board's flash).
    let at = cow::POSITIONS.as_ptr() as usize;
    defmt::info!(
        "simplifying {} triangles over {} vertices in flash at {=usize:#x}; static workspace {} bytes",
        cow::TRIANGLES_COUNT,
        cow::VERTICES,
        at,
        Ws::BYTES
    );
    if at >= 0x2000_0000 {
        defmt::error!("the positions are not in flash");
        exit(3);
    }
    match ws.simplify(&cow::POSITIONS, triangles, &Config::new().with_ratio(0.25)) {
        Ok(report) => {
            defmt::info!("{}", report);
            defmt::info!(
                "kept {} of {} triangles; first: {}",
                report.triangles_out,
                report.triangles_in,
                triangles[0]
            );
            exit(if report.target_reached { 0 } else { 1 })
        }
        Err(e) => {
            defmt::error!("tinydecimate: {}", e);
            exit(1)
        }
    }
}

/// Ends the QEMU run (semihosting SYS_EXIT) with `code` as its exit code.
fn exit(code: i32) -> ! {
    semihosting::process::exit(code)
}

#[panic_handler]
fn panic(_: &PanicInfo) -> ! {
    exit(101)
}

#[defmt::panic_handler]
fn defmt_panic() -> ! {
    exit(101)
}
