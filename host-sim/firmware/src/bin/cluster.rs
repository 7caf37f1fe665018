//! tinydecimate's streaming vertex clustering on an emulated Cortex-M or RISC-V core: a mesh far
//! bigger than the board's RAM, read through semihosting as it is needed.
//!
//! Semihosting arguments `<program> <case> <result>` (format in host-sim/meshfmt/src/cluster.rs).
//! The triangles are read from the case file in chunks of `tinydecimate::cluster::CHUNK`
//! through one file handle; each corner's position is read on demand (seek + 12-byte read)
//! through a second handle. Nothing of the input is held whole in RAM: RAM holds the cell table
//! and the output buffer only (sizes per board below). With the case's `in_ram` flag (4 MB
//! boards only) the mesh is first loaded into RAM and clustered from there, which measures the
//! library without the semihosting reads.
//!
//! Exit status as the collapse firmware (src/main.rs): 0 result written, 2 host file I/O
//! failed, 101 panic, 102 HardFault.

#![no_std]
#![no_main]

#[path = "../arch.rs"]
mod arch;
#[path = "../board.rs"]
mod board;
#[path = "../hostio.rs"]
mod hostio;
#[path = "../measure.rs"]
mod measure;

use core::sync::atomic::{AtomicBool, Ordering};

#[cfg(target_arch = "arm")]
use cortex_m_rt::{entry, exception, ExceptionFrame};
use defmt_semihosting as _;
use meshfmt::cluster::{ClusterCase, ClusterResult, CLUSTER_CASE_LEN};
use meshfmt::{IndexType, Status};
#[cfg(target_arch = "riscv32")]
use riscv_rt::entry;
use semihosting::fs::File;
use semihosting::io::{Read, Seek, SeekFrom};
use static_cell::ConstStaticCell;
use tinydecimate::cluster::{ClusterError, ClusterReport, Clusterer, Quadrics, Scratch, Source};

use arch::Timer;
use hostio::IoError;

#[cfg(target_endian = "big")]
compile_error!("the case file is read straight into memory: little-endian only");

const EXIT_IO: i32 = 2;
const EXIT_PANIC: i32 = 101;
const EXIT_FAULT: i32 = 102;

/// Cells of the table, bytes of the output buffer (u16 triangles: 6 B each), and whether the
/// board has room for the quadric representative (40 B more per cell) and for a mesh in RAM.
#[cfg(feature = "board-microbit")]
mod cap {
    /// 16 KB: table 6 720 B + output 6 600 B (1 100 u16 triangles); the rest (2.9 KB) is
    /// stack, of which the deepest run needs 2 356 B (measured).
    pub const CELLS: usize = 560;
    pub const OUT_BYTES: usize = 6_600;
    pub const QUADRICS: bool = false;
    pub const RAM_VERTICES: usize = 0;
    pub const RAM_TRIANGLES: usize = 0;
}
#[cfg(feature = "board-lm3s6965evb")]
mod cap {
    /// 64 KB: table 24 000 B + output 30 000 B (5 000 u16 triangles).
    pub const CELLS: usize = 2_000;
    pub const OUT_BYTES: usize = 30_000;
    pub const QUADRICS: bool = false;
    pub const RAM_VERTICES: usize = 0;
    pub const RAM_TRIANGLES: usize = 0;
}
#[cfg(any(
    feature = "board-mps2-an386",
    feature = "board-mps2-an500",
    feature = "board-mps2-an505"
))]
mod cap {
    /// 4 MB: table 196 608 B, quadrics 655 360 B, output 393 216 B (65 536 u16 / 32 768 u32
    /// triangles), and room to load a mesh of 40 000 vertices and 80 000 triangles (1.44 MB).
    pub const CELLS: usize = 16_384;
    pub const OUT_BYTES: usize = 393_216;
    pub const QUADRICS: bool = true;
    pub const RAM_VERTICES: usize = 40_000;
    pub const RAM_TRIANGLES: usize = 80_000;
}
/// RISC-V, 400 KB (an ESP32-C3-class part).
#[cfg(feature = "board-riscv32imc-virt-400k")]
mod cap {
    /// Table 49 152 B, quadrics 163 840 B, output 96 000 B (16 000 u16 / 8 000 u32 triangles);
    /// no room for a mesh in RAM.
    pub const CELLS: usize = 4_096;
    pub const OUT_BYTES: usize = 96_000;
    pub const QUADRICS: bool = true;
    pub const RAM_VERTICES: usize = 0;
    pub const RAM_TRIANGLES: usize = 0;
}
/// RISC-V, 32 KB (a GD32VF103-class part).
#[cfg(feature = "board-riscv32imac-virt-32k")]
mod cap {
    /// Table 14 400 B + output 12 000 B (2 000 u16 triangles); the rest is stack.
    pub const CELLS: usize = 1_200;
    pub const OUT_BYTES: usize = 12_000;
    pub const QUADRICS: bool = false;
    pub const RAM_VERTICES: usize = 0;
    pub const RAM_TRIANGLES: usize = 0;
}
use cap::*;

type Table = Clusterer<CELLS>;

static TABLE: ConstStaticCell<Table> = ConstStaticCell::new(Clusterer::new());
/// The quadric table (same const size as the cell table); boards without room have none.
#[cfg(any(
    feature = "board-mps2-an386",
    feature = "board-mps2-an500",
    feature = "board-mps2-an505",
    feature = "board-riscv32imc-virt-400k"
))]
fn quadrics() -> Option<&'static mut Quadrics<CELLS>> {
    static QUADS: ConstStaticCell<Quadrics<CELLS>> = ConstStaticCell::new(Quadrics::new());
    Some(QUADS.take())
}
#[cfg(not(any(
    feature = "board-mps2-an386",
    feature = "board-mps2-an500",
    feature = "board-mps2-an505",
    feature = "board-riscv32imc-virt-400k"
)))]
fn quadrics() -> Option<&'static mut Quadrics<CELLS>> {
    None
}
#[repr(C, align(4))]
struct OutBytes([u8; OUT_BYTES]);
static OUT: ConstStaticCell<OutBytes> = ConstStaticCell::new(OutBytes([0; OUT_BYTES]));
static RAM_POS: ConstStaticCell<[[f32; 3]; RAM_VERTICES]> =
    ConstStaticCell::new([[0.0; 3]; RAM_VERTICES]);
static RAM_TRI: ConstStaticCell<[[u32; 3]; RAM_TRIANGLES]> =
    ConstStaticCell::new([[0; 3]; RAM_TRIANGLES]);
static RESULT: ConstStaticCell<ClusterResult> = ConstStaticCell::new(ClusterResult::empty(
    IndexType::U16,
    Status::Ok,
    board::BOARD,
));

#[entry]
fn main() -> ! {
    let Some(mut timer) = arch::timer() else {
        semihosting::process::exit(EXIT_FAULT)
    };
    let args = hostio::args();
    defmt::info!(
        "{=str} clustering: table {=usize} cells ({=usize} B), output {=usize} B, quadrics {=bool}; stack {=usize} B",
        board::NAME,
        CELLS,
        Table::BYTES,
        OUT_BYTES,
        QUADRICS,
        measure::stack_size()
    );
    let result = RESULT.take();
    let code = match (args.get(1), args.get(2)) {
        (Some("panic"), _) => defmt::panic!("panic requested"),
        (Some(case), Some(out)) => match run(&mut timer, case, out, result) {
            Ok(()) => 0,
            Err(e) => {
                defmt::error!("host file I/O failed: {}", e);
                EXIT_IO
            }
        },
        _ => {
            defmt::error!("usage: <program> <cluster case> <result>");
            EXIT_IO
        }
    };
    semihosting::process::exit(code)
}

/// A cluster case file as a [`Source`]: triangles in chunks through one handle, positions one
/// at a time (seek + read) through another.
struct FileSource {
    tri: File,
    pos: File,
    case: ClusterCase,
    /// Triangles read since the last rewind.
    at: u32,
    /// Where the position handle stands (skips a seek when the next read follows on).
    pos_at: u64,
    /// Position reads through semihosting.
    reads: u32,
    io_failed: bool,
}

impl Source for FileSource {
    fn rewind(&mut self) -> bool {
        self.at = 0;
        let ok = self
            .tri
            .seek(SeekFrom::Start(self.case.triangles_at()))
            .is_ok();
        self.io_failed |= !ok;
        ok
    }

    fn read(&mut self, buf: &mut [[u32; 3]]) -> usize {
        let n = buf
            .len()
            .min(self.case.triangles.saturating_sub(self.at) as usize);
        let Some(b) = buf.get_mut(..n) else { return 0 };
        if self.tri.read_exact(bytemuck::cast_slice_mut(b)).is_err() {
            self.io_failed = true;
            return 0;
        }
        self.at += n as u32;
        n
    }

    fn position(&mut self, vertex: usize) -> Option<[f32; 3]> {
        if vertex >= self.case.vertices as usize {
            return None;
        }
        let at = self.case.positions_at() + vertex as u64 * 12;
        if at != self.pos_at && self.pos.seek(SeekFrom::Start(at)).is_err() {
            self.io_failed = true;
            return None;
        }
        let mut p = [0.0f32; 3];
        let ok = self
            .pos
            .read_exact(bytemuck::cast_slice_mut(&mut p))
            .is_ok();
        self.reads = self.reads.wrapping_add(1);
        if !ok {
            self.io_failed = true;
            self.pos_at = u64::MAX;
            return None;
        }
        self.pos_at = at + 12;
        Some(p)
    }
}

fn run(
    syst: &mut Timer,
    case_path: &str,
    out_path: &str,
    r: &mut ClusterResult,
) -> Result<(), IoError> {
    let mut tri = hostio::open(case_path)?;
    let pos = hostio::open(case_path)?;
    let mut head = [0u8; CLUSTER_CASE_LEN];
    hostio::read_exact(&mut tri, &mut head)?;
    let out = &mut OUT.take().0;
    let case = match ClusterCase::from_bytes(&head) {
        Ok(c) => c,
        Err(e) => {
            defmt::error!("not a cluster case ({})", defmt::Debug2Format(&e));
            *r = ClusterResult::empty(IndexType::U16, Status::BadCase, board::BOARD);
            return write_result(out_path, r, &[]);
        }
    };
    defmt::info!(
        "case {=str}: {=u32} vertices, {=u32} triangles; target {=u32}, table {=u32} cells, output {=u32} slots, quadric {=bool}, in RAM {=bool}",
        case_path,
        case.vertices,
        case.triangles,
        case.target_triangles,
        case.table_cells,
        case.output_slots,
        case.quadric,
        case.in_ram
    );
    let slots = case.output_slots as usize;
    let slot_bytes = slots * case.index_type.triangle_bytes();
    let too_big = case.table_cells == 0
        || case.table_cells as usize > CELLS
        || slot_bytes > OUT_BYTES
        || (case.quadric && !QUADRICS)
        || (case.in_ram
            && (case.vertices as usize > RAM_VERTICES || case.triangles as usize > RAM_TRIANGLES));
    if too_big {
        defmt::warn!("the case does not fit this board");
        *r = ClusterResult::empty(case.index_type, Status::TooBig, board::BOARD);
        r.error = [case.table_cells, case.output_slots, 0];
        return write_result(out_path, r, &[]);
    }
    let mut src = FileSource {
        tri,
        pos,
        case,
        at: 0,
        pos_at: u64::MAX,
        reads: 0,
        io_failed: false,
    };
    let table = TABLE.take();
    let quads = if case.quadric { quadrics() } else { None };
    let config = meshfmt::cluster::lib::config(&case);
    let out = &mut out[..slot_bytes];

    let (outcome, ticks, sp, low) = if case.in_ram {
        let positions = &mut RAM_POS.take()[..case.vertices as usize];
        let triangles = &mut RAM_TRI.take()[..case.triangles as usize];
        let f = &mut src.pos;
        f.seek(SeekFrom::Start(case.positions_at()))
            .map_err(|_| IoError::Read)?;
        hostio::read_exact(f, bytemuck::cast_slice_mut(positions))?;
        hostio::read_exact(f, bytemuck::cast_slice_mut(triangles))?;
        let mut s = tinydecimate::cluster::SliceSource::new(positions, triangles);
        let sp = measure::paint();
        measure::start(syst);
        let o = call(table, quads, &mut s, &config, case.index_type, out);
        let ticks = measure::stop(syst);
        (o, ticks, sp, measure::lowest_touched())
    } else {
        let sp = measure::paint();
        measure::start(syst);
        let o = call(table, quads, &mut src, &config, case.index_type, out);
        let ticks = measure::stop(syst);
        (o, ticks, sp, measure::lowest_touched())
    };
    if src.io_failed {
        return Err(IoError::Read);
    }
    *r = meshfmt::cluster::lib::result(case.index_type, &outcome, board::BOARD);
    r.ticks = ticks;
    r.stack_bytes = sp.saturating_sub(low) as u32;
    r.stack_high_water = measure::depth(low) as u32;
    r.table_bytes = (Table::BYTES + if case.quadric { CELLS * 40 } else { 0 }) as u32;
    r.output_bytes = OUT_BYTES as u32;
    r.position_reads = src.reads;
    match &outcome {
        Ok(rep) => defmt::info!("{}", rep),
        Err(e) => defmt::warn!("clustering failed: {}", e),
    }
    defmt::info!(
        "{=u64} SysTick ticks; {=u32} position reads; stack {=u32} B in the call, high-water {=u32} of {=usize} B",
        ticks,
        src.reads,
        r.stack_bytes,
        r.stack_high_water,
        measure::stack_size()
    );
    if measure::overflowed(low) {
        defmt::panic!("stack overflow: no painted word left below the library's frames");
    }
    let bytes = r.triangles_len();
    write_result(out_path, r, &out[..bytes])
}

/// The library call, never inlined (its whole frame is painted stack).
#[inline(never)]
fn call<S: Source>(
    table: &mut Table,
    quads: Option<&mut Quadrics<CELLS>>,
    src: &mut S,
    config: &tinydecimate::cluster::ClusterConfig,
    it: IndexType,
    out: &mut [u8],
) -> Result<ClusterReport, ClusterError> {
    match it {
        IndexType::U16 => match bytemuck::try_cast_slice_mut::<u8, [u16; 3]>(out) {
            Ok(o) => table.cluster(
                src,
                config,
                o,
                Scratch {
                    quadrics: quads,
                    ..Scratch::new()
                },
            ),
            Err(_) => Err(ClusterError::InvalidGrid),
        },
        IndexType::U32 => match bytemuck::try_cast_slice_mut::<u8, [u32; 3]>(out) {
            Ok(o) => table.cluster(
                src,
                config,
                o,
                Scratch {
                    quadrics: quads,
                    ..Scratch::new()
                },
            ),
            Err(_) => Err(ClusterError::InvalidGrid),
        },
    }
}

#[inline(never)]
fn write_result(out_path: &str, r: &ClusterResult, triangles: &[u8]) -> Result<(), IoError> {
    let mut out = hostio::create(out_path)?;
    hostio::write_all(&mut out, &r.to_bytes())?;
    hostio::write_all(&mut out, triangles)?;
    defmt::info!("wrote {=str}", out_path);
    Ok(())
}

static PANICKED: AtomicBool = AtomicBool::new(false);

#[panic_handler]
fn panic(info: &core::panic::PanicInfo) -> ! {
    if !PANICKED.load(Ordering::Relaxed) {
        PANICKED.store(true, Ordering::Relaxed);
        defmt::error!("panic: {}", defmt::Display2Format(info));
    }
    semihosting::process::exit(EXIT_PANIC)
}

#[defmt::panic_handler]
fn defmt_panic() -> ! {
    semihosting::process::exit(EXIT_PANIC)
}

#[cfg(target_arch = "arm")]
#[exception]
unsafe fn HardFault(ef: &ExceptionFrame) -> ! {
    if !PANICKED.load(Ordering::Relaxed) {
        PANICKED.store(true, Ordering::Relaxed);
        defmt::error!(
            "HardFault: pc={=u32:#010x} lr={=u32:#010x} xpsr={=u32:#010x}",
            ef.pc(),
            ef.lr(),
            ef.xpsr()
        );
    }
    semihosting::process::exit(EXIT_FAULT)
}

#[cfg(target_arch = "arm")]
#[exception]
unsafe fn DefaultHandler(irqn: i16) {
    defmt::error!("unexpected exception {=i16}", irqn);
    semihosting::process::exit(EXIT_FAULT)
}
