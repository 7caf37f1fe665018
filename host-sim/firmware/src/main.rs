//! tinydecimate on an emulated Cortex-M or RISC-V core (the differences: src/arch.rs).
//!
//! The host (`host-sim qemu`) starts QEMU with three semihosting arguments,
//! `<program> <case file> <result file>`: the firmware reads the case (mesh + configuration,
//! format in host-sim/meshfmt) through semihosting file I/O into static buffers sized per board
//! (src/board.rs), simplifies it, and writes the result file. One image per board serves every
//! case. A progressive stream (`.tdpm`, magic `TDPM`) instead of a case is decoded as it is
//! read, in small pieces, and the mesh written out as it refines (`meshfmt::pm`). Without
//! arguments it simplifies a built-in grid (self-test, e.g. under `cargo run`).
//!
//! Logs are defmt frames on semihosting stdout (defmt-semihosting), decoded by the host with
//! the image's ELF. Nothing else writes to stdout. Exit status through SYS_EXIT_EXTENDED:
//! 0 done (the result file says how the case went), 2 host file I/O failed, 101 panic,
//! 102 HardFault or unexpected exception (RISC-V: any trap).

#![no_std]
#![no_main]

mod arch;
mod board;
mod hostio;
mod measure;

use core::sync::atomic::{AtomicBool, Ordering};

#[cfg(target_arch = "arm")]
use cortex_m_rt::{entry, exception, ExceptionFrame};
use defmt_semihosting as _;
use meshfmt::{CaseHeader, IndexType, ResultHeader, Status, CASE_HEADER_LEN};
#[cfg(target_arch = "riscv32")]
use riscv_rt::entry;
use static_cell::ConstStaticCell;

use arch::Timer;
use hostio::IoError;

#[cfg(target_endian = "big")]
compile_error!("the case file is read straight into memory: little-endian only");

const EXIT_IO: i32 = 2;
const EXIT_PANIC: i32 = 101;
const EXIT_FAULT: i32 = 102;

/// Positions of the current case (all zero: in .bss).
static POSITIONS: ConstStaticCell<[[f32; 3]; board::MAX_VERTICES]> =
    ConstStaticCell::new([[0.0; 3]; board::MAX_VERTICES]);
/// The result header (a static rather than a local: ~300 bytes off the stack while the
/// library runs).
static RESULT: ConstStaticCell<ResultHeader> = ConstStaticCell::new(ResultHeader::empty(
    IndexType::U16,
    Status::Ok,
    board::BOARD,
));
/// Stored quadrics or the energy's samples of the current case; bounded cases borrow its bytes.
#[cfg(feature = "lib")]
static QUADRICS: ConstStaticCell<[[f32; 10]; board::QUADRIC_VERTICES]> =
    ConstStaticCell::new([[0.0; 10]; board::QUADRIC_VERTICES]);
/// Triangles of the current case, in the file's index type.
static TRIANGLES: ConstStaticCell<board::TriangleBytes> =
    ConstStaticCell::new(board::TriangleBytes([0; board::TRIANGLE_BYTES]));
/// The working memory of the run: the exact engine's workspace, one of the pipeline's, or a
/// stream's arena (`board::Engine`). `Workspace::new` is `const`, so the workspace is
/// initialised at compile time. (Building it at run time,
/// `StaticCell::uninit().write(Workspace::new())`, assembles it on the stack first: a 1.6 MB
/// frame on the 4 MB boards.) A run takes it once, for its case or its stream.
#[cfg(feature = "lib")]
static ENGINE: ConstStaticCell<board::Engine> =
    ConstStaticCell::new(board::Engine::Exact(board::Workspace::new()));

#[entry]
fn main() -> ! {
    let Some(mut timer) = arch::timer() else {
        semihosting::process::exit(EXIT_FAULT)
    };
    let args = hostio::args();
    defmt::info!(
        "{=str}: capacity {=usize} vertices, {=usize} u16 / {=usize} u32 triangles; stack {=usize} B",
        board::NAME,
        board::MAX_VERTICES,
        board::triangle_capacity(IndexType::U16),
        board::triangle_capacity(IndexType::U32),
        measure::stack_size()
    );
    let positions = POSITIONS.take();
    let triangles = &mut TRIANGLES.take().0;
    let result = RESULT.take();
    let code = match (args.get(1), args.get(2)) {
        (Some("calibrate"), Some(out)) => match calibrate(&mut timer, out) {
            Ok(()) => 0,
            Err(e) => {
                defmt::error!("host file I/O failed: {}", e);
                EXIT_IO
            }
        },
        (Some(case), Some(out)) => {
            let run = match hostio::magic(case) {
                Ok(m) if m == *b"TDPM" => run_stream(&mut timer, case, out, positions, triangles),
                Ok(_) => run_case(&mut timer, case, out, positions, triangles, result),
                Err(e) => Err(e),
            };
            match run {
                Ok(()) => 0,
                Err(e) => {
                    defmt::error!("host file I/O failed: {}", e);
                    EXIT_IO
                }
            }
        }
        // Checks that a panic and a fault end QEMU with a failure status.
        (Some("panic"), _) => defmt::panic!("panic requested"),
        // An undefined instruction: HardFault on Cortex-M, an exception on RISC-V (arch.rs).
        (Some("fault"), _) => arch::fault(),
        _ => selftest(&mut timer, positions, triangles, result),
    };
    semihosting::process::exit(code)
}

/// Reads the case, simplifies, writes the result.
///
/// Reading and writing happen in their own (never inlined) functions, so their buffers (the
/// header, the NUL-terminated paths, the encoded result header) are off the stack while the
/// library runs: on the micro:bit every byte of stack is mesh capacity.
fn run_case(
    syst: &mut Timer,
    case_path: &str,
    out_path: &str,
    positions: &mut [[f32; 3]],
    triangles: &mut [u8],
    result: &mut ResultHeader,
) -> Result<(), IoError> {
    let entry = match read_case(case_path, positions, triangles, result)? {
        Ok(h) => {
            simplify(
                syst,
                &h,
                &mut positions[..h.vertices as usize],
                &mut triangles[..h.triangles_len() + h.wedges_len()],
                result,
            );
            h.entry()
        }
        Err(entry) => entry,
    };
    let (v, t) = board::capacity(result.index_type, entry);
    result.capacity_vertices = v as u32;
    result.capacity_triangles = t as u32;
    let out_bytes = result.triangles_len();
    write_result(out_path, result, &triangles[..out_bytes])
}

/// Reads the case file into the buffers. `Ok(Err(entry))`: the case is rejected (not a case
/// file, or too big for this board) and `result` says so; `entry` is the one it asked for
/// (`Simplify` when the file is not a case), whose capacity the result reports.
#[inline(never)]
fn read_case(
    case_path: &str,
    positions: &mut [[f32; 3]],
    triangles: &mut [u8],
    result: &mut ResultHeader,
) -> Result<Result<CaseHeader, meshfmt::Entry>, IoError> {
    let mut file = hostio::open(case_path)?;
    let mut head = [0u8; CASE_HEADER_LEN];
    hostio::read_exact(&mut file, &mut head)?;
    let h = match CaseHeader::from_bytes(&head) {
        Ok(h) => h,
        Err(e) => {
            defmt::error!(
                "{=str}: not a case file ({})",
                case_path,
                defmt::Debug2Format(&e)
            );
            *result = ResultHeader::empty(IndexType::U16, Status::BadCase, board::BOARD);
            return Ok(Err(meshfmt::Entry::Simplify));
        }
    };
    let nv = h.vertices as usize;
    let nt = h.triangles as usize;
    defmt::info!(
        "case {=str}: {=usize} vertices, {=usize} triangles (u{=usize})",
        case_path,
        nv,
        nt,
        h.index_type.bytes() * 8
    );
    // A board without quadric storage skips every case that borrows it (an empty one too), a
    // board without the stack for vertex decimation every vertex-decimation case, a board
    // without a mode of the pipeline (float, integer fast, integer lean) every case of it:
    // `run_library`, `run_pipeline` and `run_grid` leave their code out of the image.
    let entry = h.entry();
    let (cv, ct) = board::capacity(h.index_type, entry);
    if nv > cv
        || nt > ct
        || !board::has_mode(entry)
        || (entry.per_vertex_storage() && (nv > board::QUADRIC_VERTICES || !board::HAS_QUADRICS))
        || (entry == meshfmt::Entry::VertexDecimation && !board::VERTEX_DECIMATION)
        || (entry == meshfmt::Entry::Bounded
            && (board::bound_bytes(nv, nt, h.index_type.bytes()) > board::BOUND_BYTES
                || !board::HAS_QUADRICS))
        || (entry.envelope()
            && (meshfmt::envelope_bytes(
                nv,
                nt,
                h.index_type.bytes(),
                core::mem::size_of::<board::Link>(),
            ) > board::BOUND_BYTES
                || !board::HAS_QUADRICS))
        || (entry == meshfmt::Entry::EnvelopeDecimation && !board::VERTEX_DECIMATION)
    {
        if !board::has_mode(entry) {
            defmt::warn!("no such mode of the pipeline on this board");
        } else {
            defmt::warn!("the mesh does not fit this board");
        }
        *result = ResultHeader::empty(h.index_type, Status::TooBig, board::BOARD);
        result.error_a = h.vertices;
        result.error_b = h.triangles;
        return Ok(Err(entry));
    }
    hostio::read_exact(&mut file, bytemuck::cast_slice_mut(&mut positions[..nv]))?;
    // A wedge case's wedges follow its triangles (`board::capacity` leaves room for them).
    hostio::read_exact(
        &mut file,
        &mut triangles[..h.triangles_len() + h.wedges_len()],
    )?;
    Ok(Ok(h))
}

/// Writes the result file: header, then the triangles (already in the file's byte order).
#[inline(never)]
fn write_result(out_path: &str, result: &ResultHeader, triangles: &[u8]) -> Result<(), IoError> {
    let mut out = hostio::create(out_path)?;
    hostio::write_all(&mut out, &result.to_bytes())?;
    hostio::write_all(&mut out, triangles)?;
    defmt::info!("wrote {=str}", out_path);
    Ok(())
}

/// Decodes the progressive stream in `in_path` as it is read (pieces of 1 to 128 bytes), and
/// writes the meshes along the way, the slider's round trip and the trailer to `out_path`
/// (`meshfmt::pm::run`, the same code the host runs). The triangle buffer lends its bytes to
/// the list heads, the triangles and their links; the positions buffer holds the positions.
#[cfg(feature = "lib")]
fn run_stream(
    syst: &mut Timer,
    in_path: &str,
    out_path: &str,
    positions: &mut [[f32; 3]],
    triangles: &mut [u8],
) -> Result<(), IoError> {
    let Some(arena) = stream_arena(ENGINE.take()) else {
        return Err(IoError::Read);
    };
    let (heads, rest) = triangles.split_at_mut(board::PM_HEAD_BYTES);
    let tri_bytes = board::PM_TRIANGLES * 3 * core::mem::size_of::<board::Link>();
    let (tris, rest) = rest.split_at_mut(tri_bytes);
    let links = rest.get_mut(..tri_bytes).ok_or(IoError::Read)?;
    let heads =
        bytemuck::try_cast_slice_mut::<u8, board::Link>(heads).map_err(|_| IoError::Read)?;
    let tris =
        bytemuck::try_cast_slice_mut::<u8, [board::Link; 3]>(tris).map_err(|_| IoError::Read)?;
    let links =
        bytemuck::try_cast_slice_mut::<u8, [board::Link; 3]>(links).map_err(|_| IoError::Read)?;
    let half = tris.len();
    let storage = tinydecimate::progressive::Storage {
        triangles: tris,
        links,
        heads,
        splits: &mut arena.splits,
    };
    let mut dev = StreamDevice {
        input: hostio::open(in_path)?,
        output: hostio::create(out_path)?,
        syst,
    };
    defmt::info!(
        "stream {=str}: room for {=usize} vertices, {=usize} triangles, chunks of {=usize} B",
        in_path,
        board::PM_VERTICES.min(positions.len()),
        half,
        board::PM_BUFFER - tinydecimate::stream::CHUNK_OVERHEAD
    );
    let sp = measure::paint();
    let mut s = meshfmt::pm::run(&mut dev, storage, positions, &mut arena.buffer)?;
    let low = measure::lowest_touched();
    if measure::overflowed(low) {
        defmt::panic!("stack overflow: no painted word left below the decoder's frames");
    }
    s.stack_bytes = sp.saturating_sub(low) as u32;
    s.board = board::BOARD as u8;
    match s.error {
        None => defmt::info!(
            "complete: {=u32} triangles, {=u32} vertices from {=u32} B",
            s.triangles,
            s.vertices,
            s.bytes
        ),
        Some(e) => defmt::warn!(
            "stream error {=u8} ({=u32}, {=u32}) after {=u32} B: the mesh stays at {=u32} triangles",
            e.code,
            e.a,
            e.b,
            s.bytes,
            s.triangles
        ),
    }
    defmt::info!(
        "{=u64} ticks decoding, {=u64} coarsening and {=u64} refining {=u32} levels; stack {=u32} B",
        s.decode_ticks,
        s.coarsen_ticks,
        s.refine_ticks,
        s.splits,
        s.stack_bytes
    );
    hostio::write_all(&mut dev.output, &s.to_bytes())?;
    defmt::info!("wrote {=str}", out_path);
    Ok(())
}

/// Turns the run's working memory into the stream arena (zeroed), in place, as
/// [`fast_workspace`] does for the fast mode; before the stack is painted, so that the stream's
/// measured stack is the decoder's alone.
#[cfg(feature = "lib")]
#[inline(never)]
fn stream_arena(engine: &mut board::Engine) -> Option<&mut board::PmArena> {
    const ZEROED: board::PmArena = board::PmArena::new();
    if !matches!(engine, board::Engine::Stream(_)) {
        *engine = board::Engine::Stream(ZEROED);
    }
    match engine {
        board::Engine::Stream(arena) => Some(arena),
        _ => None,
    }
}

#[cfg(not(feature = "lib"))]
fn run_stream(
    _syst: &mut Timer,
    _in_path: &str,
    _out_path: &str,
    _positions: &mut [[f32; 3]],
    _triangles: &mut [u8],
) -> Result<(), IoError> {
    defmt::error!("no library linked: cannot decode a progressive stream");
    Err(IoError::Read)
}

/// The stream's source, the output file and the timer, for `meshfmt::pm::run`.
#[cfg(feature = "lib")]
struct StreamDevice<'a> {
    input: semihosting::fs::File,
    output: semihosting::fs::File,
    syst: &'a mut Timer,
}

#[cfg(feature = "lib")]
impl meshfmt::pm::Device for StreamDevice<'_> {
    type Error = IoError;
    fn read(&mut self, buf: &mut [u8]) -> Result<usize, IoError> {
        hostio::read_some(&mut self.input, buf)
    }
    fn write(&mut self, bytes: &[u8]) -> Result<(), IoError> {
        hostio::write_all(&mut self.output, bytes)
    }
    fn start(&mut self) {
        measure::start(self.syst);
    }
    fn stop(&mut self) -> u64 {
        measure::stop(self.syst)
    }
    fn arrived(&mut self, bytes: usize, triangles: usize, vertices: usize) {
        defmt::info!(
            "{=usize} B in: {=usize} triangles, {=usize} vertices",
            bytes,
            triangles,
            vertices
        );
    }
}

/// Passes of [`calibrate`]'s loop (`arch::delay`).
const CALIBRATION_LOOPS: u32 = 5_000_000;

/// Times a loop of a known number of instructions (about 10 million), so the host can check
/// how many instructions one timer tick is on this board. Writes a result file with only the
/// ticks and the instructions.
fn calibrate(syst: &mut Timer, out_path: &str) -> Result<(), IoError> {
    measure::start(syst);
    let instructions = arch::delay(CALIBRATION_LOOPS);
    let ticks = measure::stop(syst);
    defmt::info!(
        "calibration: {=u32} instructions in {=u64} ticks",
        instructions,
        ticks
    );
    let mut r = ResultHeader::empty(IndexType::U16, Status::Ok, board::BOARD);
    r.ticks = ticks;
    r.error_a = instructions;
    let mut out = hostio::create(out_path)?;
    hostio::write_all(&mut out, &r.to_bytes())
}

/// Simplifies the mesh in the buffers, measuring instructions and stack.
#[cfg(feature = "lib")]
fn simplify(
    syst: &mut Timer,
    h: &CaseHeader,
    pos: &mut [[f32; 3]],
    tri: &mut [u8],
    r: &mut ResultHeader,
) {
    let engine = ENGINE.take();
    let quadrics = QUADRICS.take();
    let config = meshfmt::lib::config(h);
    let entry = h.entry();

    let sp = measure::paint();
    // Not counted: the exact engine's workspace is ready at boot, the pipeline's are zeroed
    // here.
    if matches!(entry, meshfmt::Entry::Fast | meshfmt::Entry::FastWedges) && board::FAST {
        fast_workspace(engine);
    }
    if matches!(entry, meshfmt::Entry::Lean | meshfmt::Entry::LeanWedges) && board::FAST {
        lean_workspace(engine);
    }
    if entry == meshfmt::Entry::FastInteger && board::INT_FAST {
        fast_integer_workspace(engine);
    }
    if entry == meshfmt::Entry::LeanInteger && board::INT_LEAN {
        lean_integer_workspace(engine);
    }
    // Not counted either: an integer case's grid coordinates become `[u16; 3]` in place (the
    // float positions are not read after that).
    let (pos, grid): (&mut [[f32; 3]], &[[u16; 3]]) = if entry.integer() {
        (&mut [], on_grid(pos))
    } else {
        (pos, &[])
    };
    // The triangles, and after them a wedge case's wedges.
    let (tri, wedges) = tri.split_at_mut(h.triangles_len());
    measure::start(syst);
    let outcome =
        match engine {
            board::Engine::Exact(ws) => match h.index_type {
                IndexType::U16 => triangles_as::<u16>(tri)
                    .map(|t| run_library(ws, pos, t, &config, entry, quadrics)),
                IndexType::U32 => triangles_as::<u32>(tri)
                    .map(|t| run_library(ws, pos, t, &config, entry, quadrics)),
            },
            board::Engine::Fast(ws) => run_either(ws, h.index_type, pos, tri, wedges, &config),
            board::Engine::Lean(ws) => run_either(ws, h.index_type, pos, tri, wedges, &config),
            board::Engine::FastInteger(ws) => run_grid(ws, h.index_type, grid, tri, &config),
            board::Engine::LeanInteger(ws) => run_grid(ws, h.index_type, grid, tri, &config),
            // Not reached: a case never turns the engine into the stream arena.
            board::Engine::Stream(_) => None,
        };
    let Some(outcome) = outcome else {
        *r = ResultHeader::empty(h.index_type, Status::BadCase, board::BOARD);
        return;
    };
    let ticks = measure::stop(syst);
    let low = measure::lowest_touched();
    write_header(h, &outcome, pos, ticks, sp, low, r);
}

/// A fast or lean case on workspace `ws`, with wedges when `wedges` holds any, in the case's
/// index type (`None`: the bytes are not whole triangles). Inlined into [`simplify`], as its
/// match arms were, so that no frame of its own lies above the measured call.
#[cfg(feature = "lib")]
#[inline(always)]
fn run_either<P: Pipeline<Position = [f32; 3]>>(
    ws: &mut P,
    index_type: IndexType,
    pos: &[[f32; 3]],
    tri: &mut [u8],
    wedges: &mut [u8],
    config: &tinydecimate::Config,
) -> Option<Result<tinydecimate::Report, tinydecimate::Error>> {
    match (index_type, wedges.is_empty()) {
        (IndexType::U16, true) => {
            triangles_as::<u16>(tri).map(|t| run_pipeline(ws, pos, t, config))
        }
        (IndexType::U32, true) => {
            triangles_as::<u32>(tri).map(|t| run_pipeline(ws, pos, t, config))
        }
        (IndexType::U16, false) => triangles_as::<u16>(tri)
            .zip(triangles_as::<u16>(wedges))
            .map(|(t, w)| run_pipeline_wedges(ws, pos, t, w, config)),
        (IndexType::U32, false) => triangles_as::<u32>(tri)
            .zip(triangles_as::<u32>(wedges))
            .map(|(t, w)| run_pipeline_wedges(ws, pos, t, w, config)),
    }
}

/// An integer case on workspace `ws` (`FastIntWorkspace` or `LeanIntWorkspace`), on the grid
/// positions, in the case's index type (`None`: the bytes are not whole triangles). No wedges:
/// no integer case has them. Inlined into [`simplify`], as [`run_either`] is.
#[cfg(feature = "lib")]
#[inline(always)]
fn run_grid<P: Pipeline<Position = [u16; 3]>>(
    ws: &mut P,
    index_type: IndexType,
    grid: &[[u16; 3]],
    tri: &mut [u8],
    config: &tinydecimate::Config,
) -> Option<Result<tinydecimate::Report, tinydecimate::Error>> {
    match index_type {
        IndexType::U16 => triangles_as::<u16>(tri).map(|t| run_pipeline(ws, grid, t, config)),
        IndexType::U32 => triangles_as::<u32>(tri).map(|t| run_pipeline(ws, grid, t, config)),
    }
}

/// An integer case's positions, read as the case file carries them (grid coordinates as
/// `f32`), turned into `[u16; 3]` in the same buffer (`meshfmt::grid_in_place`): the first
/// half of its bytes. Empty if the buffer is not 2-aligned, which a `f32` buffer always is.
#[cfg(feature = "lib")]
#[inline(never)]
fn on_grid(pos: &mut [[f32; 3]]) -> &[[u16; 3]] {
    let n = pos.len();
    let bytes: &mut [u8] = bytemuck::cast_slice_mut(pos);
    meshfmt::grid_in_place(bytes);
    let bytes: &[u8] = bytes;
    bytes
        .get(..6 * n)
        .and_then(|b| bytemuck::try_cast_slice(b).ok())
        .unwrap_or(&[])
}

/// The triangle bytes as triangles of `I` (`None`: misaligned or not a whole number of them).
#[cfg(feature = "lib")]
fn triangles_as<I: bytemuck::Pod>(tri: &mut [u8]) -> Option<&mut [[I; 3]]> {
    bytemuck::try_cast_slice_mut::<u8, [I; 3]>(tri).ok()
}

/// The result header of a library call and its log lines. Never inlined: its temporaries
/// (the header, the report's formatting) stay out of the frame that lies above the library's
/// during the call, so the board's stack holds larger meshes.
#[cfg(feature = "lib")]
#[inline(never)]
fn write_header(
    h: &CaseHeader,
    outcome: &Result<tinydecimate::Report, tinydecimate::Error>,
    pos: &[[f32; 3]],
    ticks: u64,
    sp: usize,
    low: usize,
    r: &mut ResultHeader,
) {
    let entry = h.entry();
    *r = meshfmt::lib::result_header(h.index_type, outcome, board::BOARD);
    if entry == meshfmt::Entry::StoredOptimal {
        r.positions_hash = meshfmt::positions_hash(pos);
    }
    r.ticks = ticks;
    r.stack_bytes = sp.saturating_sub(low) as u32;
    r.stack_high_water = measure::depth(low) as u32;
    r.workspace_bytes = match entry {
        meshfmt::Entry::Fast | meshfmt::Entry::FastWedges => board::FastWorkspace::BYTES as u32,
        meshfmt::Entry::Lean | meshfmt::Entry::LeanWedges => board::LeanWorkspace::BYTES as u32,
        meshfmt::Entry::FastInteger => board::FastIntWorkspace::BYTES as u32,
        meshfmt::Entry::LeanInteger => board::LeanIntWorkspace::BYTES as u32,
        _ => board::Workspace::BYTES as u32,
    };
    match outcome {
        Ok(report) => defmt::info!("{}", report),
        Err(e) => defmt::warn!("simplify failed: {}", e),
    }
    defmt::info!(
        "{=u64} SysTick ticks; stack {=u32} B in simplify, high-water {=u32} of {=usize} B; workspace {=u32} B",
        ticks,
        r.stack_bytes,
        r.stack_high_water,
        measure::stack_size(),
        r.workspace_bytes
    );
    if measure::overflowed(low) {
        // The stack ran down into .bss: the buffers may be corrupt, so is the result.
        defmt::panic!("stack overflow: no painted word left below the library's frames");
    }
}

/// The library call, never inlined: its whole frame then lies below the stack pointer at which
/// [`measure::paint`] stopped, so the painted stack measures all of it.
#[cfg(feature = "lib")]
#[inline(never)]
fn run_library<I: tinydecimate::Index + bytemuck::Pod>(
    ws: &mut board::Workspace,
    positions: &mut [[f32; 3]],
    triangles: &mut [[I; 3]],
    config: &tinydecimate::Config,
    entry: meshfmt::Entry,
    quadrics: &mut [[f32; 10]],
) -> Result<tinydecimate::Report, tinydecimate::Error> {
    use meshfmt::Entry;
    use tinydecimate::Placement;
    // A board leaves out the entry points it cannot run (`read_case` skips their cases): the
    // ones that borrow the quadric storage where there is none, vertex decimation where the
    // stack is too small. With all of them the micro:bit's and the lm3s6965evb's images
    // overflow their 256 KB of flash. A case of the pipeline runs on its own workspace
    // (`run_pipeline`, `run_pipeline_wedges`), never here.
    let left_out = match entry {
        Entry::Simplify => false,
        Entry::VertexDecimation => !board::VERTEX_DECIMATION,
        Entry::EnvelopeDecimation => !board::VERTEX_DECIMATION || !board::HAS_QUADRICS,
        Entry::Fast
        | Entry::Lean
        | Entry::FastWedges
        | Entry::LeanWedges
        | Entry::FastInteger
        | Entry::LeanInteger => true,
        _ => !board::HAS_QUADRICS,
    };
    if left_out {
        return Err(left_out_error(positions.len()));
    }
    match entry {
        Entry::Simplify => ws.simplify(positions, triangles, config),
        Entry::Bounded => run_bounded(ws, positions, triangles, config, quadrics),
        Entry::StoredSubset => run_stored(
            ws,
            positions,
            triangles,
            config,
            Placement::Subset,
            quadrics,
        ),
        Entry::StoredOptimal => run_stored(
            ws,
            positions,
            triangles,
            config,
            Placement::Optimal,
            quadrics,
        ),
        Entry::VertexDecimation => run_decimation(ws, positions, triangles, config),
        Entry::Energy => run_energy(ws, positions, triangles, config, quadrics),
        Entry::Envelope => run_envelope(ws, positions, triangles, config, quadrics, false),
        Entry::EnvelopeDecimation => run_envelope(ws, positions, triangles, config, quadrics, true),
        Entry::Fast
        | Entry::Lean
        | Entry::FastWedges
        | Entry::LeanWedges
        | Entry::FastInteger
        | Entry::LeanInteger => Err(left_out_error(positions.len())),
    }
}

/// The error of an entry point the image leaves out (not reached: `read_case` skips its cases).
#[cfg(feature = "lib")]
fn left_out_error(vertices: usize) -> tinydecimate::Error {
    tinydecimate::Error::Capacity {
        what: tinydecimate::Capacity::Quadrics,
        needed: vertices,
        available: 0,
    }
}

/// Turns the run's working memory into the fast mode's workspace (zeroed), in place. Never
/// inlined; called on the painted stack but before the counter starts, so a copy through the
/// stack (which would run into `.bss`) ends in the stack-overflow panic, and the zeroing is
/// not counted as the library's instructions.
#[cfg(feature = "lib")]
#[inline(never)]
fn fast_workspace(engine: &mut board::Engine) {
    // A constant operand, not a call: the variant is then written straight into the static
    // from an all-zero constant, which the compiler turns into a memset (a call's result is
    // built on the stack and copied, a frame twice the workspace's size).
    const ZEROED: board::FastWorkspace = board::FastWorkspace::new();
    if !matches!(engine, board::Engine::Fast(_)) {
        *engine = board::Engine::Fast(ZEROED);
    }
}

/// The pipeline's workspaces (the fast and the lean mode, in floats or in integers) as the
/// firmware calls them.
#[cfg(feature = "lib")]
trait Pipeline {
    /// A position as the workspace's arithmetic takes it.
    type Position;
    /// Whether the board has this mode (`board::FAST`, `INT_FAST`, `INT_LEAN`): without it
    /// the calls return at once and the mode's code is left out of the image.
    const ON: bool;
    fn plain<I: tinydecimate::Index>(
        &mut self,
        positions: &[Self::Position],
        triangles: &mut [[I; 3]],
        config: &tinydecimate::Config,
    ) -> Result<tinydecimate::Report, tinydecimate::Error>;
    fn welded<I: tinydecimate::Index>(
        &mut self,
        positions: &[Self::Position],
        triangles: &mut [[I; 3]],
        wedges: &mut [[I; 3]],
        config: &tinydecimate::Config,
    ) -> Result<tinydecimate::Report, tinydecimate::Error>;
}

/// Implements [`Pipeline`] for a workspace type by its inherent methods.
macro_rules! pipeline {
    ($ws:ty, $position:ty, $on:expr) => {
        #[cfg(feature = "lib")]
        impl Pipeline for $ws {
            type Position = $position;
            const ON: bool = $on;
            #[inline(always)]
            fn plain<I: tinydecimate::Index>(
                &mut self,
                positions: &[$position],
                triangles: &mut [[I; 3]],
                config: &tinydecimate::Config,
            ) -> Result<tinydecimate::Report, tinydecimate::Error> {
                self.simplify(positions, triangles, config)
            }
            #[inline(always)]
            fn welded<I: tinydecimate::Index>(
                &mut self,
                positions: &[$position],
                triangles: &mut [[I; 3]],
                wedges: &mut [[I; 3]],
                config: &tinydecimate::Config,
            ) -> Result<tinydecimate::Report, tinydecimate::Error> {
                self.simplify_with_wedges(positions, triangles, wedges, config)
            }
        }
    };
}
pipeline!(board::FastWorkspace, [f32; 3], board::FAST);
pipeline!(board::LeanWorkspace, [f32; 3], board::FAST);
pipeline!(board::FastIntWorkspace, [u16; 3], board::INT_FAST);
pipeline!(board::LeanIntWorkspace, [u16; 3], board::INT_LEAN);

/// A fast or lean case, in floats or in integers (`MethodCode::Fast`, `Lean`, `FastInteger`,
/// `LeanInteger`): `simplify`, positions read. Never inlined, for the same reason as
/// [`run_bounded`]; a board without the mode never runs it (`read_case` skips its cases), and
/// the constant leaves the mode out of its image.
#[cfg(feature = "lib")]
#[inline(never)]
fn run_pipeline<P: Pipeline, I: tinydecimate::Index>(
    ws: &mut P,
    positions: &[P::Position],
    triangles: &mut [[I; 3]],
    config: &tinydecimate::Config,
) -> Result<tinydecimate::Report, tinydecimate::Error> {
    if !P::ON {
        return Err(left_out_error(positions.len()));
    }
    ws.plain(positions, triangles, config)
}

/// A case with wedges (`MethodCode::FastWedges`, `LeanWedges`): `simplify_with_wedges` on the
/// welded triangles, the wedges behind them in the triangle buffer. Its own function, so that
/// [`run_pipeline`]'s image is the same with or without it.
#[cfg(feature = "lib")]
#[inline(never)]
fn run_pipeline_wedges<P: Pipeline, I: tinydecimate::Index>(
    ws: &mut P,
    positions: &[P::Position],
    triangles: &mut [[I; 3]],
    wedges: &mut [[I; 3]],
    config: &tinydecimate::Config,
) -> Result<tinydecimate::Report, tinydecimate::Error> {
    if !P::ON {
        return Err(left_out_error(positions.len()));
    }
    ws.welded(positions, triangles, wedges, config)
}

/// Turns the run's working memory into the lean mode's workspace (zeroed), in place, as
/// [`fast_workspace`] does for the fast mode.
#[cfg(feature = "lib")]
#[inline(never)]
fn lean_workspace(engine: &mut board::Engine) {
    const ZEROED: board::LeanWorkspace = board::LeanWorkspace::new();
    if !matches!(engine, board::Engine::Lean(_)) {
        *engine = board::Engine::Lean(ZEROED);
    }
}

/// Turns the run's working memory into the fast mode's workspace in integers (zeroed), in
/// place, as [`fast_workspace`] does.
#[cfg(feature = "lib")]
#[inline(never)]
fn fast_integer_workspace(engine: &mut board::Engine) {
    const ZEROED: board::FastIntWorkspace = board::FastIntWorkspace::new();
    if !matches!(engine, board::Engine::FastInteger(_)) {
        *engine = board::Engine::FastInteger(ZEROED);
    }
}

/// Turns the run's working memory into the lean mode's workspace in integers (zeroed), in
/// place, as [`fast_workspace`] does.
#[cfg(feature = "lib")]
#[inline(never)]
fn lean_integer_workspace(engine: &mut board::Engine) {
    const ZEROED: board::LeanIntWorkspace = board::LeanIntWorkspace::new();
    if !matches!(engine, board::Engine::LeanInteger(_)) {
        *engine = board::Engine::LeanInteger(ZEROED);
    }
}

/// A stored-quadric case (`StoredQuadric`). Never inlined, for the same reason as
/// [`run_bounded`].
#[cfg(feature = "lib")]
#[inline(never)]
fn run_stored<I: tinydecimate::Index>(
    ws: &mut board::Workspace,
    positions: &mut [[f32; 3]],
    triangles: &mut [[I; 3]],
    config: &tinydecimate::Config,
    placement: tinydecimate::Placement,
    quadrics: &mut [[f32; 10]],
) -> Result<tinydecimate::Report, tinydecimate::Error> {
    use tinydecimate::{EdgeCollapse, NoBound, Placement, Positions, StoredQuadric};
    let p = match placement {
        Placement::Subset => Positions::Read(positions),
        Placement::Optimal => Positions::Write(positions),
    };
    let cost = StoredQuadric::new(quadrics, placement);
    Ok(ws
        .start(p, triangles, config, cost, NoBound, EdgeCollapse)?
        .run())
}

/// A vertex decimation case (`VertexDecimation`, the built-in cost). Never inlined, for the
/// same reason as [`run_bounded`].
#[cfg(feature = "lib")]
#[inline(never)]
fn run_decimation<I: tinydecimate::Index>(
    ws: &mut board::Workspace,
    positions: &[[f32; 3]],
    triangles: &mut [[I; 3]],
    config: &tinydecimate::Config,
) -> Result<tinydecimate::Report, tinydecimate::Error> {
    use tinydecimate::{Builtin, NoBound, Positions, VertexDecimation};
    let (p, op) = (Positions::Read(positions), VertexDecimation::new());
    Ok(ws
        .start(p, triangles, config, Builtin::new(), NoBound, op)?
        .run())
}

/// A case of Hoppe's energy (`cost::Energy`, its samples in the quadric storage). Never
/// inlined, for the same reason as [`run_bounded`].
#[cfg(feature = "lib")]
#[inline(never)]
fn run_energy<I: tinydecimate::Index>(
    ws: &mut board::Workspace,
    positions: &[[f32; 3]],
    triangles: &mut [[I; 3]],
    config: &tinydecimate::Config,
    samples: &mut [[f32; 10]],
) -> Result<tinydecimate::Report, tinydecimate::Error> {
    use tinydecimate::{EdgeCollapse, NoBound, Positions};
    let (p, cost) = (
        Positions::Read(positions),
        tinydecimate::cost::Energy::new(samples),
    );
    Ok(ws
        .start(p, triangles, config, cost, NoBound, EdgeCollapse)?
        .run())
}

/// A bounded case (`Controls`). Never inlined: its locals would deepen
/// [`run_library`]'s frame for every case, and the micro:bit has no stack to spare.
#[cfg(feature = "lib")]
#[inline(never)]
fn run_bounded<I: tinydecimate::Index + bytemuck::Pod>(
    ws: &mut board::Workspace,
    positions: &mut [[f32; 3]],
    triangles: &mut [[I; 3]],
    config: &tinydecimate::Config,
    quadrics: &mut [[f32; 10]],
) -> Result<tinydecimate::Report, tinydecimate::Error> {
    // The quadric storage lends its bytes: the input triangles' read-only copy, then the
    // control-point links (`read_case` checked that they fit).
    let bytes: &mut [u8] = bytemuck::cast_slice_mut(quadrics);
    let (orig, rest) =
        bytes.split_at_mut((triangles.len() * 3 * core::mem::size_of::<I>()).min(bytes.len()));
    let nc = tinydecimate::bound::control_len(triangles.len(), positions.len());
    let links = rest.get_mut(..nc * core::mem::size_of::<board::Link>());
    let (Ok(orig), Some(Ok(controls))) = (
        bytemuck::try_cast_slice_mut::<u8, [I; 3]>(orig),
        links.map(bytemuck::try_cast_slice_mut::<u8, board::Link>),
    ) else {
        return Err(tinydecimate::Error::OriginalMismatch { triangle: 0 });
    };
    if orig.len() != triangles.len() {
        return Err(tinydecimate::Error::OriginalMismatch { triangle: 0 });
    }
    orig.copy_from_slice(triangles);
    let (p, bound) = (
        tinydecimate::Positions::Read(positions),
        tinydecimate::Controls::new(orig, controls),
    );
    let cost = tinydecimate::Builtin::new();
    Ok(ws
        .start(
            p,
            triangles,
            config,
            cost,
            bound,
            tinydecimate::EdgeCollapse,
        )?
        .run())
}

/// An envelope case (`bound::Envelope`), with the edge collapse or with vertex decimation
/// (`removal`). Never inlined, for the same reason as [`run_bounded`].
#[cfg(feature = "lib")]
#[inline(never)]
fn run_envelope<I: tinydecimate::Index + bytemuck::Pod>(
    ws: &mut board::Workspace,
    positions: &mut [[f32; 3]],
    triangles: &mut [[I; 3]],
    config: &tinydecimate::Config,
    quadrics: &mut [[f32; 10]],
    removal: bool,
) -> Result<tinydecimate::Report, tinydecimate::Error> {
    // The quadric storage lends its bytes (`meshfmt::envelope_bytes`, checked by
    // `read_case`): the shell, the index words, then the input triangles' read-only copy.
    let bytes: &mut [u8] = bytemuck::cast_slice_mut(quadrics);
    let (shell, rest) = bytes.split_at_mut((positions.len() * 24).min(bytes.len()));
    let words =
        tinydecimate::bound::index_len(triangles.len()) * core::mem::size_of::<board::Link>();
    let (index, rest) = rest.split_at_mut(words.min(rest.len()));
    let orig = rest.get_mut(..triangles.len() * 3 * core::mem::size_of::<I>());
    let (Ok(shell), Ok(index), Some(Ok(orig))) = (
        bytemuck::try_cast_slice_mut::<u8, [[f32; 3]; 2]>(shell),
        bytemuck::try_cast_slice_mut::<u8, board::Link>(index),
        orig.map(bytemuck::try_cast_slice_mut::<u8, [I; 3]>),
    ) else {
        return Err(tinydecimate::Error::OriginalMismatch { triangle: 0 });
    };
    if orig.len() != triangles.len() {
        return Err(tinydecimate::Error::OriginalMismatch { triangle: 0 });
    }
    orig.copy_from_slice(triangles);
    let p = tinydecimate::Positions::Read(positions);
    let bound = tinydecimate::Envelope::new(orig, shell, index);
    let cost = tinydecimate::Builtin::new();
    Ok(if removal {
        ws.start(
            p,
            triangles,
            config,
            cost,
            bound,
            tinydecimate::VertexDecimation::new(),
        )?
        .run()
    } else {
        ws.start(
            p,
            triangles,
            config,
            cost,
            bound,
            tinydecimate::EdgeCollapse,
        )?
        .run()
    })
}

/// Without the library: the output is the input (boot + semihosting + defmt smoke test).
#[cfg(not(feature = "lib"))]
fn simplify(
    syst: &mut Timer,
    h: &CaseHeader,
    _pos: &mut [[f32; 3]],
    _tri: &mut [u8],
    r: &mut ResultHeader,
) {
    let sp = measure::paint();
    measure::start(syst);
    let ticks = measure::stop(syst);
    let low = measure::lowest_touched();
    *r = ResultHeader::empty(h.index_type, Status::Ok, board::BOARD);
    r.triangles_in = h.triangles;
    r.triangles_out = h.triangles;
    r.target_triangles = h.triangles;
    r.ticks = ticks;
    r.stack_bytes = sp.saturating_sub(low) as u32;
    r.stack_high_water = measure::depth(low) as u32;
    defmt::info!("no library linked: echoing {=u32} triangles", h.triangles);
}

/// No case given: simplify a bumpy grid of (n × n) quads that fits the board.
fn selftest(
    syst: &mut Timer,
    positions: &mut [[f32; 3]],
    triangles: &mut [u8],
    r: &mut ResultHeader,
) -> i32 {
    let mut n = 2usize;
    while (n + 2) * (n + 2) <= board::MAX_VERTICES
        && 2 * (n + 1) * (n + 1) <= board::triangle_capacity(IndexType::U16)
        && n < 24
    {
        n += 1;
    }
    let nv = (n + 1) * (n + 1);
    for (i, p) in positions[..nv].iter_mut().enumerate() {
        let (x, y) = (i % (n + 1), i / (n + 1));
        *p = [x as f32, y as f32, ((x * 7 + y * 3) % 5) as f32 * 0.1];
    }
    let mut nt = 0;
    for y in 0..n {
        for x in 0..n {
            let v = (y * (n + 1) + x) as u16;
            let w = (n + 1) as u16;
            for t in [[v, v + 1, v + w + 1], [v, v + w + 1, v + w]] {
                for (k, i) in t.iter().enumerate() {
                    let at = (nt * 3 + k) * 2;
                    triangles[at..at + 2].copy_from_slice(&i.to_le_bytes());
                }
                nt += 1;
            }
        }
    }
    defmt::info!(
        "self-test: {=usize}x{=usize} grid, {=usize} triangles",
        n,
        n,
        nt
    );
    // Greedy, 25 %, λ = 1, the library's defaults otherwise.
    let h = CaseHeader {
        index_type: IndexType::U16,
        schedule: meshfmt::ScheduleCode::Greedy,
        method: meshfmt::MethodCode::Quadric,
        vertices: nv as u32,
        triangles: nt as u32,
        target_ratio: 0.25,
        target_triangles: 0,
        lambda: 1.0,
        feature_mode: meshfmt::FeatureCode::Paper,
        feature_targets: false,
        max_passes: 32,
        max_cost: f32::INFINITY,
        max_normal_turn_deg: 60.0,
        min_quality: 0.05,
        boundary_weight: 1.0,
        max_error: 0.0,
    };
    simplify(syst, &h, &mut positions[..nv], &mut triangles[..nt * 6], r);
    if r.status == Status::Ok && r.triangles_out > 0 && r.triangles_out <= r.triangles_in {
        defmt::info!(
            "self-test passed: {=u32} -> {=u32} triangles",
            r.triangles_in,
            r.triangles_out
        );
        0
    } else {
        defmt::error!("self-test failed");
        1
    }
}

static PANICKED: AtomicBool = AtomicBool::new(false);

#[panic_handler]
fn panic(info: &core::panic::PanicInfo) -> ! {
    // Log once: a panic inside the logger must not recurse.
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
