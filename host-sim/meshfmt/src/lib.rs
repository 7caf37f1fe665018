//! The case and result files exchanged between `host-sim` and the QEMU firmware.
//!
//! One small, dependency-free `no_std` crate used by both sides, so the layout is written down
//! once. Everything is little-endian; both files start with a fixed-size header followed by
//! plain arrays. The firmware reads the arrays straight into its buffers (Cortex-M is
//! little-endian, so no conversion is needed there).
//!
//! # Case file (host → firmware), [`CASE_HEADER_LEN`] = 64 bytes of header
//!
//! | offset | type    | field                                                        |
//! |-------:|---------|--------------------------------------------------------------|
//! |      0 | [u8; 4] | magic `TDCS`                                                 |
//! |      4 | u16     | version ([`CASE_VERSION`])                                   |
//! |      6 | u8      | index type: 2 = `u16`, 4 = `u32` (the triangles' width)      |
//! |      7 | u8      | schedule: 0 = greedy, 1 = passes                             |
//! |      8 | u32     | vertex count V                                               |
//! |     12 | u32     | triangle count T                                             |
//! |     16 | f32     | target ratio (used when the count is 0)                      |
//! |     20 | u32     | target triangle count (nonzero: the target; 0: the ratio)    |
//! |     24 | f32     | lambda                                                       |
//! |     28 | u8      | feature mode: 0 = features off, 1 = paper, 2 = valence-normalized |
//! |     29 | u8      | feature targets (0/1)                                        |
//! |     30 | u8      | method ([`MethodCode`]): 0 = memoryless quadric, 1 = normal variation W (version 2), 2 = stored quadric with subset placement, 3 = stored quadric with optimal placement, 4 = vertex decimation, 5 = Hoppe's energy, 6 = the fast mode, 7 = the lean mode, 8 and 9 = either with wedges, 10 and 11 = either in integers |
//! |     31 | u8      | reserved, 0                                                  |
//! |     32 | u32     | max passes                                                   |
//! |     36 | f32     | max cost (may be +inf)                                       |
//! |     40 | f32     | max normal turn, degrees                                     |
//! |     44 | f32     | min quality                                                  |
//! |     48 | f32     | boundary weight                                              |
//! |     52 | f32     | max error: the guaranteed bound (`Config::max_error`, input units); 0 = none |
//! |     56 | [u8; 8] | reserved, 0                                                  |
//! |     64 | f32     | positions: V × 3 (an integer method's: grid coordinates, [`grid_position`]) |
//! |        | u16/u32 | triangles: T × 3                                             |
//!
//! # Result file (firmware → host), [`RESULT_HEADER_LEN`] = 288 bytes of header
//!
//! Bytes `0..COMPARED_LEN` and the triangles are what a golden comparison checks; the
//! measurement block after them differs per board and is ignored by [`ResultHeader::same_outcome`].
//!
//! | offset | type     | field                                                     |
//! |-------:|----------|-----------------------------------------------------------|
//! |      0 | [u8; 4]  | magic `TDRS`                                              |
//! |      4 | u16      | version ([`RESULT_VERSION`])                              |
//! |      6 | u8       | index type of the triangles that follow                   |
//! |      7 | u8       | [`Status`]                                                |
//! |      8 | u8       | [`ErrorKind`] (status 1) or 0                             |
//! |      9 | [u8; 3]  | bytes 0-2 of the positions hash (see offset 43)           |
//! |     12 | u32      | error detail a (needed / triangle / vertex / field)       |
//! |     16 | u32      | error detail b (available / index)                        |
//! |     20 | u32 × 5  | triangles in, degenerate dropped, duplicates dropped, triangles out, target triangles |
//! |     40 | u8 × 4   | target reached, stop code, pass log length, byte 3 of the positions hash |
//! |     44 | u32 × 5  | collapses, vertices removed, locked vertices, feature vertices, passes |
//! |     64 | u32 × 16 | rejections by rule, in the order of the library's `RULES` (`Report::rejected`); unused slots 0 |
//! |    128 | u32 × 32 | triangles after each pass (first `pass log length` used)  |
//! |    256 | u64      | SysTick ticks around the simplification (measurement)     |
//! |    264 | u32      | stack bytes used below the caller's frame (measurement)   |
//! |    268 | u32      | workspace bytes (measurement)                             |
//! |    272 | u32 × 2  | board capacity: vertices, triangles of this index type    |
//! |    280 | u32      | stack high-water mark from the stack top (measurement)    |
//! |    284 | u8       | board id, [`Board`]                                        |
//! |    285 | [u8; 3]  | reserved                                                  |
//! |    288 | u16/u32  | triangles: triangles out × 3                              |
//!
//! Result version 3 carries a count for every legality rule, the error bound's included, with
//! room for 16; version 2 had eight slots and no `bound`. Result files are read as soon as
//! the firmware writes them (the golden files keep text and triangles, not result headers),
//! so only the current version is read.
#![no_std]
#![forbid(unsafe_code)]

#[cfg(feature = "std")]
extern crate std;

/// Mesh generators of the golden cases (host side).
#[cfg(feature = "std")]
pub mod golden;

/// The clustering case and result files.
pub mod cluster;

/// Case file magic.
pub const CASE_MAGIC: [u8; 4] = *b"TDCS";
/// Result file magic.
pub const RESULT_MAGIC: [u8; 4] = *b"TDRS";
/// Format version of the case file.
pub const CASE_VERSION: u16 = 2;
/// Format version of the result file.
pub const RESULT_VERSION: u16 = 3;
/// Size of the case header.
pub const CASE_HEADER_LEN: usize = 64;
/// Size of the result header.
pub const RESULT_HEADER_LEN: usize = 288;
/// The result header bytes that must match a golden result exactly.
pub const COMPARED_LEN: usize = 256;
/// Rejection counts a result file holds: one per legality rule (the library's `RULES`, in its
/// order), the rest zero; room to add rules without changing the format.
pub const REJECTION_SLOTS: usize = 16;
/// Length of the per-pass triangle log (the library's `PASS_LOG`).
pub const PASS_LOG: usize = 32;

/// Width of the triangle indices in a file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum IndexType {
    /// `u16` triangles.
    U16 = 2,
    /// `u32` triangles.
    U32 = 4,
}

impl IndexType {
    /// Bytes per index.
    pub const fn bytes(self) -> usize {
        self as usize
    }
    /// Bytes per triangle.
    pub const fn triangle_bytes(self) -> usize {
        3 * self as usize
    }
    fn from_code(c: u8) -> Option<Self> {
        match c {
            2 => Some(IndexType::U16),
            4 => Some(IndexType::U32),
            _ => None,
        }
    }
}

/// Schedule code.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ScheduleCode {
    /// `Schedule::Greedy`.
    Greedy = 0,
    /// `Schedule::Passes`.
    Passes = 1,
    /// `Schedule::Batched`.
    Batched = 2,
}

/// Method code: the cost and operator a case runs (header byte 30). Codes 0-3 name a cost of
/// the edge collapse, 4 and 5 a plug-in, 6 to 11 the pipeline (fast and lean mode, with wedges,
/// in integers); the byte was first the cost alone, so the codes are the ones it had. A new code keeps the case version: a reader
/// that predates it refuses the case ([`FormatError::Code`]) rather than run another method.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MethodCode {
    /// `CostKind::Quadric`.
    Quadric = 0,
    /// `CostKind::NormalVariation`.
    NormalVariation = 1,
    /// Stored quadrics, subset placement (`StoredQuadric` with `Placement::Subset`).
    StoredSubset = 2,
    /// Stored quadrics, optimal placement (`StoredQuadric` with `Placement::Optimal`): positions move.
    StoredOptimal = 3,
    /// Vertex decimation (`VertexDecimation::new()`, the built-in cost, positions read): the
    /// workspace only.
    VertexDecimation = 4,
    /// Hoppe's energy (`cost::Energy::new`, edge collapse, positions read): one `[f32; 10]` of
    /// samples per vertex.
    Energy = 5,
    /// The fast mode (`pipeline::FastWorkspace::simplify`, positions read): its own workspace;
    /// of the configuration only the target, `max_passes` and `error_limit` count.
    Fast = 6,
    /// The lean mode (`pipeline::LeanWorkspace::simplify`, positions read): the fast mode's
    /// pipeline without stored quadrics, its own workspace; the configuration as for `Fast`.
    Lean = 7,
    /// The fast mode on a welded mesh with wedges (`FastWorkspace::simplify_with_wedges`): the
    /// case file's triangles are welded by position (`seam::weld`) and the wedges follow them,
    /// one triangle of the caller's vertices per triangle; the output names the wedges.
    FastWedges = 8,
    /// The lean mode on a welded mesh with wedges (`LeanWorkspace::simplify_with_wedges`), as
    /// `FastWedges`.
    LeanWedges = 9,
    /// The fast mode in integers (`FastWorkspace<_, _, _, pipeline::Integer>::simplify`): the
    /// case file's positions are grid coordinates below 32 768 written as `f32` (exact), which
    /// the runner turns into `[u16; 3]` ([`grid_position`]) before the call; the configuration
    /// as for `Fast`, an error limit in grid cells.
    FastInteger = 10,
    /// The lean mode in integers (`LeanWorkspace<_, _, _, pipeline::Integer>::simplify`), as
    /// `FastInteger`.
    LeanInteger = 11,
    /// The built-in cost under the envelope bound (`bound::Envelope`), edge collapse; the bound
    /// is the header's `max_error`.
    Envelope = 12,
    /// `VertexDecimation::new()` under the envelope bound, as `Envelope`.
    EnvelopeDecimation = 13,
}

/// The library entry point a case runs: its method and whether it is bounded, decided once
/// for the firmware and the host reference ([`CaseHeader::entry`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Entry {
    /// `Workspace::simplify` with the configuration's cost.
    Simplify,
    /// The built-in cost under the error bound (`Controls`), edge collapse.
    Bounded,
    /// `StoredQuadric` with `Placement::Subset`, positions read.
    StoredSubset,
    /// `StoredQuadric` with `Placement::Optimal`, positions written.
    StoredOptimal,
    /// `VertexDecimation::new()` with the built-in cost, no bound, positions read.
    VertexDecimation,
    /// `cost::Energy::new`, no bound, edge collapse, positions read.
    Energy,
    /// `pipeline::FastWorkspace::simplify`, positions read.
    Fast,
    /// `pipeline::LeanWorkspace::simplify`, positions read.
    Lean,
    /// `pipeline::FastWorkspace::simplify_with_wedges`, positions read.
    FastWedges,
    /// `pipeline::LeanWorkspace::simplify_with_wedges`, positions read.
    LeanWedges,
    /// `pipeline::FastWorkspace<_, _, _, Integer>::simplify`, grid positions read.
    FastInteger,
    /// `pipeline::LeanWorkspace<_, _, _, Integer>::simplify`, grid positions read.
    LeanInteger,
    /// The built-in cost under the envelope bound (`bound::Envelope`), edge collapse.
    Envelope,
    /// `VertexDecimation::new()` under the envelope bound.
    EnvelopeDecimation,
}

impl Entry {
    /// Whether the run takes one `[f32; 10]` per vertex from the caller (stored quadrics, the
    /// energy's samples): the firmware's quadric storage, `board::QUADRIC_VERTICES` of them.
    pub const fn per_vertex_storage(self) -> bool {
        matches!(
            self,
            Entry::StoredSubset | Entry::StoredOptimal | Entry::Energy
        )
    }

    /// Whether the case file carries wedges after its triangles (as many, the same index
    /// type), which the firmware reads into its triangle buffer after the triangles.
    pub const fn wedges(self) -> bool {
        matches!(self, Entry::FastWedges | Entry::LeanWedges)
    }

    /// Whether the run is the pipeline's in floats (the fast or the lean mode, with or without
    /// wedges), on its own workspace.
    pub const fn pipeline(self) -> bool {
        matches!(
            self,
            Entry::Fast | Entry::Lean | Entry::FastWedges | Entry::LeanWedges
        )
    }

    /// Whether the run is the pipeline's in integers (`pipeline::Integer`), on its own
    /// workspace: the case file's positions are grid coordinates ([`grid_position`]).
    pub const fn integer(self) -> bool {
        matches!(self, Entry::FastInteger | Entry::LeanInteger)
    }

    /// Whether the run is under the envelope bound, whose storage the firmware borrows from
    /// its quadric storage ([`envelope_bytes`]).
    pub const fn envelope(self) -> bool {
        matches!(self, Entry::Envelope | Entry::EnvelopeDecimation)
    }
}

/// Bytes an envelope case of `v` vertices and `t` triangles borrows: the shell (24 B per
/// vertex, first, for its `f32` alignment), `bound::index_len(t) = 6t + 2` words of
/// `word_bytes`, then the input triangles' read-only copy in `index_bytes` (written out: the
/// firmware image without the library must build too).
pub const fn envelope_bytes(v: usize, t: usize, index_bytes: usize, word_bytes: usize) -> usize {
    24 * v + (6 * t + 2) * word_bytes + 3 * t * index_bytes
}

/// A position of an integer case as the library takes it: the case file carries each grid
/// coordinate as an `f32`, which holds every integer below 2²⁴ exactly, so that the file keeps
/// one layout for every method; the firmware and the host turn it back with this cast alone.
#[inline]
pub fn grid_position(p: [f32; 3]) -> [u16; 3] {
    p.map(|x| x as u16)
}

/// [`grid_position`] in place on the positions of an integer case as the firmware reads them
/// (little-endian `f32`s, 12 bytes a vertex): coordinate `i` is read at byte `4i` and written
/// as a `u16` at byte `2i`, in increasing `i`, so a write never lands on a coordinate not yet
/// read and no second buffer is needed. The first half of `bytes` then holds the `[u16; 3]`
/// positions.
pub fn grid_in_place(bytes: &mut [u8]) {
    for i in 0..bytes.len() / 4 {
        let mut f = [0u8; 4];
        f.copy_from_slice(&bytes[4 * i..4 * i + 4]);
        let q = f32::from_le_bytes(f) as u16;
        bytes[2 * i..2 * i + 2].copy_from_slice(&q.to_le_bytes());
    }
}

/// Feature mode code.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FeatureCode {
    /// `features = false`.
    Off = 0,
    /// `FeatureMode::Paper`.
    Paper = 1,
    /// `FeatureMode::ValenceNormalized`.
    ValenceNormalized = 2,
}

/// Why a file could not be decoded.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FormatError {
    /// Wrong magic.
    Magic,
    /// Unknown version.
    Version,
    /// Bad index type, schedule, feature mode or status code.
    Code,
    /// The file is shorter than its header says.
    Truncated,
}

/// The case header: what to simplify, and the configuration.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CaseHeader {
    pub index_type: IndexType,
    pub schedule: ScheduleCode,
    pub method: MethodCode,
    pub vertices: u32,
    pub triangles: u32,
    pub target_ratio: f32,
    pub target_triangles: u32,
    pub lambda: f32,
    pub feature_mode: FeatureCode,
    pub feature_targets: bool,
    pub max_passes: u32,
    pub max_cost: f32,
    pub max_normal_turn_deg: f32,
    pub min_quality: f32,
    pub boundary_weight: f32,
    /// The error bound in input units (`Controls`); 0 (or anything not
    /// positive and finite): no bound, `Workspace::simplify`.
    pub max_error: f32,
}

/// Little-endian writer over a fixed array.
struct W<'a> {
    b: &'a mut [u8],
    at: usize,
}

impl W<'_> {
    fn bytes(&mut self, v: &[u8]) {
        if let Some(d) = self.b.get_mut(self.at..self.at + v.len()) {
            d.copy_from_slice(v);
        }
        self.at += v.len();
    }
    fn u8(&mut self, v: u8) {
        self.bytes(&[v]);
    }
    fn u16(&mut self, v: u16) {
        self.bytes(&v.to_le_bytes());
    }
    fn u32(&mut self, v: u32) {
        self.bytes(&v.to_le_bytes());
    }
    fn f32(&mut self, v: f32) {
        self.bytes(&v.to_bits().to_le_bytes());
    }
    fn skip(&mut self, n: usize) {
        self.at += n;
    }
}

/// Little-endian reader over a fixed array.
struct R<'a> {
    b: &'a [u8],
    at: usize,
}

impl R<'_> {
    fn take<const N: usize>(&mut self) -> [u8; N] {
        let mut out = [0u8; N];
        if let Some(s) = self.b.get(self.at..self.at + N) {
            out.copy_from_slice(s);
        }
        self.at += N;
        out
    }
    fn u8(&mut self) -> u8 {
        self.take::<1>()[0]
    }
    fn u16(&mut self) -> u16 {
        u16::from_le_bytes(self.take())
    }
    fn u32(&mut self) -> u32 {
        u32::from_le_bytes(self.take())
    }
    fn u64(&mut self) -> u64 {
        u64::from_le_bytes(self.take())
    }
    fn f32(&mut self) -> f32 {
        f32::from_bits(self.u32())
    }
    fn skip(&mut self, n: usize) {
        self.at += n;
    }
}

impl CaseHeader {
    /// Encodes the header.
    pub fn to_bytes(&self) -> [u8; CASE_HEADER_LEN] {
        let mut b = [0u8; CASE_HEADER_LEN];
        let mut w = W { b: &mut b, at: 0 };
        w.bytes(&CASE_MAGIC);
        w.u16(CASE_VERSION);
        w.u8(self.index_type as u8);
        w.u8(self.schedule as u8);
        w.u32(self.vertices);
        w.u32(self.triangles);
        w.f32(self.target_ratio);
        w.u32(self.target_triangles);
        w.f32(self.lambda);
        w.u8(self.feature_mode as u8);
        w.u8(self.feature_targets as u8);
        w.u8(self.method as u8);
        w.u8(0);
        w.u32(self.max_passes);
        w.f32(self.max_cost);
        w.f32(self.max_normal_turn_deg);
        w.f32(self.min_quality);
        w.f32(self.boundary_weight);
        w.f32(self.max_error);
        b
    }

    /// Decodes the header.
    pub fn from_bytes(b: &[u8; CASE_HEADER_LEN]) -> Result<Self, FormatError> {
        let mut r = R { b, at: 0 };
        if r.take::<4>() != CASE_MAGIC {
            return Err(FormatError::Magic);
        }
        if r.u16() != CASE_VERSION {
            return Err(FormatError::Version);
        }
        let index_type = IndexType::from_code(r.u8()).ok_or(FormatError::Code)?;
        let schedule = match r.u8() {
            0 => ScheduleCode::Greedy,
            1 => ScheduleCode::Passes,
            2 => ScheduleCode::Batched,
            _ => return Err(FormatError::Code),
        };
        let vertices = r.u32();
        let triangles = r.u32();
        let target_ratio = r.f32();
        let target_triangles = r.u32();
        let lambda = r.f32();
        let feature_mode = match r.u8() {
            0 => FeatureCode::Off,
            1 => FeatureCode::Paper,
            2 => FeatureCode::ValenceNormalized,
            _ => return Err(FormatError::Code),
        };
        let feature_targets = r.u8() != 0;
        let method = match r.u8() {
            0 => MethodCode::Quadric,
            1 => MethodCode::NormalVariation,
            2 => MethodCode::StoredSubset,
            3 => MethodCode::StoredOptimal,
            4 => MethodCode::VertexDecimation,
            5 => MethodCode::Energy,
            6 => MethodCode::Fast,
            7 => MethodCode::Lean,
            8 => MethodCode::FastWedges,
            9 => MethodCode::LeanWedges,
            10 => MethodCode::FastInteger,
            11 => MethodCode::LeanInteger,
            12 => MethodCode::Envelope,
            13 => MethodCode::EnvelopeDecimation,
            _ => return Err(FormatError::Code),
        };
        r.skip(1);
        Ok(CaseHeader {
            index_type,
            schedule,
            method,
            vertices,
            triangles,
            target_ratio,
            target_triangles,
            lambda,
            feature_mode,
            feature_targets,
            max_passes: r.u32(),
            max_cost: r.f32(),
            max_normal_turn_deg: r.f32(),
            min_quality: r.f32(),
            boundary_weight: r.f32(),
            max_error: r.f32(),
        })
    }

    /// Whether the case asks for the guaranteed error bound (`Controls`):
    /// a positive, finite `max_error`.
    pub fn bounded(&self) -> bool {
        self.max_error > 0.0 && self.max_error.is_finite()
    }

    /// The entry point the case runs: the envelope methods under their bound; else the
    /// control-point bound first (the built-in cost), else its method.
    pub fn entry(&self) -> Entry {
        match self.method {
            MethodCode::Envelope => return Entry::Envelope,
            MethodCode::EnvelopeDecimation => return Entry::EnvelopeDecimation,
            _ if self.bounded() => return Entry::Bounded,
            _ => {}
        }
        match self.method {
            MethodCode::Quadric | MethodCode::NormalVariation => Entry::Simplify,
            MethodCode::StoredSubset => Entry::StoredSubset,
            MethodCode::StoredOptimal => Entry::StoredOptimal,
            MethodCode::VertexDecimation => Entry::VertexDecimation,
            MethodCode::Energy => Entry::Energy,
            MethodCode::Fast => Entry::Fast,
            MethodCode::Lean => Entry::Lean,
            MethodCode::FastWedges => Entry::FastWedges,
            MethodCode::LeanWedges => Entry::LeanWedges,
            MethodCode::FastInteger => Entry::FastInteger,
            MethodCode::LeanInteger => Entry::LeanInteger,
            MethodCode::Envelope => Entry::Envelope,
            MethodCode::EnvelopeDecimation => Entry::EnvelopeDecimation,
        }
    }

    /// Bytes of the position array.
    pub fn positions_len(&self) -> usize {
        self.vertices as usize * 12
    }

    /// Bytes of the triangle array.
    pub fn triangles_len(&self) -> usize {
        self.triangles as usize * self.index_type.triangle_bytes()
    }

    /// Bytes of the wedge array (after the triangles; none unless [`Entry::wedges`]).
    pub fn wedges_len(&self) -> usize {
        if self.entry().wedges() {
            self.triangles_len()
        } else {
            0
        }
    }

    /// Whole file size.
    pub fn file_len(&self) -> usize {
        CASE_HEADER_LEN + self.positions_len() + self.triangles_len() + self.wedges_len()
    }
}

/// How the firmware (or the host reference run) ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Status {
    /// Simplified; the report fields and triangles are valid.
    Ok = 0,
    /// The library returned an error ([`ErrorKind`] and details set).
    LibraryError = 1,
    /// The case file could not be decoded.
    BadCase = 2,
    /// The mesh does not fit this board's buffers (details: needed, available bytes).
    TooBig = 3,
}

/// Which library error.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ErrorKind {
    None = 0,
    CapacityVertices = 1,
    CapacityTriangles = 2,
    IndexOutOfRange = 3,
    NonFinitePosition = 4,
    InvalidConfig = 5,
    CapacityQuadrics = 6,
    CapacityControls = 7,
    OriginalMismatch = 8,
    OffGrid = 9,
    CapacityEnvelope = 10,
}

/// Which board produced a result (0 for the host).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Board {
    Host = 0,
    Microbit = 1,
    Lm3s6965evb = 2,
    Mps2An386 = 3,
    Mps2An500 = 4,
    Mps2An505 = 5,
    /// RISC-V `riscv32imc`, QEMU `virt`, 400 KB of RAM (an ESP32-C3-class part).
    Riscv32ImcVirt400k = 6,
    /// RISC-V `riscv32imac`, QEMU `virt`, 32 KB of RAM (a GD32VF103-class part).
    Riscv32ImacVirt32k = 7,
}

/// The result header. Counts are `u32`, the library's `usize` narrowed (saturating).
#[derive(Clone, Debug, PartialEq)]
pub struct ResultHeader {
    pub index_type: IndexType,
    pub status: Status,
    pub error_kind: ErrorKind,
    pub error_a: u32,
    pub error_b: u32,
    pub triangles_in: u32,
    pub degenerate_dropped: u32,
    pub duplicates_dropped: u32,
    pub triangles_out: u32,
    pub target_triangles: u32,
    pub target_reached: bool,
    /// 0 running, 1 target, 2 no legal collapse, 3 max cost, 4 max passes, 5 log full, 6 error
    /// limit.
    pub stop: u8,
    pub pass_log_len: u8,
    pub collapses: u32,
    pub vertices_removed: u32,
    pub locked_vertices: u32,
    pub feature_vertices: u32,
    pub passes: u32,
    /// Refusals by legality rule, in the order of the library's `RULES`; unused slots 0.
    pub rejected: [u32; REJECTION_SLOTS],
    pub pass_triangles: [u32; PASS_LOG],
    /// FNV-1a (32 bit) of all positions after the run, little-endian f32 bytes, for cases
    /// whose positions move (stored quadrics, optimal placement); 0 otherwise. Stored in the
    /// header's reserved bytes 9-11 and 43, so it is compared.
    pub positions_hash: u32,
    // ---- measurement block, not compared ----
    pub ticks: u64,
    pub stack_bytes: u32,
    pub workspace_bytes: u32,
    pub capacity_vertices: u32,
    pub capacity_triangles: u32,
    pub stack_high_water: u32,
    pub board: Board,
}

impl ResultHeader {
    /// A header with the given status and everything else zero.
    pub const fn empty(index_type: IndexType, status: Status, board: Board) -> Self {
        ResultHeader {
            index_type,
            status,
            error_kind: ErrorKind::None,
            error_a: 0,
            error_b: 0,
            triangles_in: 0,
            degenerate_dropped: 0,
            duplicates_dropped: 0,
            triangles_out: 0,
            target_triangles: 0,
            target_reached: false,
            stop: 0,
            pass_log_len: 0,
            collapses: 0,
            vertices_removed: 0,
            locked_vertices: 0,
            feature_vertices: 0,
            passes: 0,
            rejected: [0; REJECTION_SLOTS],
            pass_triangles: [0; PASS_LOG],
            positions_hash: 0,
            ticks: 0,
            stack_bytes: 0,
            workspace_bytes: 0,
            capacity_vertices: 0,
            capacity_triangles: 0,
            stack_high_water: 0,
            board,
        }
    }

    /// Encodes the header.
    pub fn to_bytes(&self) -> [u8; RESULT_HEADER_LEN] {
        let mut b = [0u8; RESULT_HEADER_LEN];
        let mut w = W { b: &mut b, at: 0 };
        w.bytes(&RESULT_MAGIC);
        w.u16(RESULT_VERSION);
        w.u8(self.index_type as u8);
        w.u8(self.status as u8);
        w.u8(self.error_kind as u8);
        let hash = self.positions_hash.to_le_bytes();
        w.u8(hash[0]);
        w.u8(hash[1]);
        w.u8(hash[2]);
        w.u32(self.error_a);
        w.u32(self.error_b);
        w.u32(self.triangles_in);
        w.u32(self.degenerate_dropped);
        w.u32(self.duplicates_dropped);
        w.u32(self.triangles_out);
        w.u32(self.target_triangles);
        w.u8(self.target_reached as u8);
        w.u8(self.stop);
        w.u8(self.pass_log_len);
        w.u8(hash[3]);
        w.u32(self.collapses);
        w.u32(self.vertices_removed);
        w.u32(self.locked_vertices);
        w.u32(self.feature_vertices);
        w.u32(self.passes);
        for r in self.rejected {
            w.u32(r);
        }
        for p in self.pass_triangles {
            w.u32(p);
        }
        debug_assert_eq!(w.at, COMPARED_LEN);
        w.bytes(&self.ticks.to_le_bytes());
        w.u32(self.stack_bytes);
        w.u32(self.workspace_bytes);
        w.u32(self.capacity_vertices);
        w.u32(self.capacity_triangles);
        w.u32(self.stack_high_water);
        w.u8(self.board as u8);
        b
    }

    /// Decodes the header.
    pub fn from_bytes(b: &[u8; RESULT_HEADER_LEN]) -> Result<Self, FormatError> {
        let mut r = R { b, at: 0 };
        if r.take::<4>() != RESULT_MAGIC {
            return Err(FormatError::Magic);
        }
        if r.u16() != RESULT_VERSION {
            return Err(FormatError::Version);
        }
        let index_type = IndexType::from_code(r.u8()).ok_or(FormatError::Code)?;
        let status = match r.u8() {
            0 => Status::Ok,
            1 => Status::LibraryError,
            2 => Status::BadCase,
            3 => Status::TooBig,
            _ => return Err(FormatError::Code),
        };
        let error_kind = match r.u8() {
            0 => ErrorKind::None,
            1 => ErrorKind::CapacityVertices,
            2 => ErrorKind::CapacityTriangles,
            3 => ErrorKind::IndexOutOfRange,
            4 => ErrorKind::NonFinitePosition,
            5 => ErrorKind::InvalidConfig,
            6 => ErrorKind::CapacityQuadrics,
            7 => ErrorKind::CapacityControls,
            8 => ErrorKind::OriginalMismatch,
            9 => ErrorKind::OffGrid,
            10 => ErrorKind::CapacityEnvelope,
            _ => return Err(FormatError::Code),
        };
        let hash = [r.u8(), r.u8(), r.u8()];
        let mut h = ResultHeader::empty(index_type, status, Board::Host);
        h.error_kind = error_kind;
        h.error_a = r.u32();
        h.error_b = r.u32();
        h.triangles_in = r.u32();
        h.degenerate_dropped = r.u32();
        h.duplicates_dropped = r.u32();
        h.triangles_out = r.u32();
        h.target_triangles = r.u32();
        h.target_reached = r.u8() != 0;
        h.stop = r.u8();
        h.pass_log_len = r.u8();
        h.positions_hash = u32::from_le_bytes([hash[0], hash[1], hash[2], r.u8()]);
        h.collapses = r.u32();
        h.vertices_removed = r.u32();
        h.locked_vertices = r.u32();
        h.feature_vertices = r.u32();
        h.passes = r.u32();
        for x in h.rejected.iter_mut() {
            *x = r.u32();
        }
        for x in h.pass_triangles.iter_mut() {
            *x = r.u32();
        }
        h.ticks = r.u64();
        h.stack_bytes = r.u32();
        h.workspace_bytes = r.u32();
        h.capacity_vertices = r.u32();
        h.capacity_triangles = r.u32();
        h.stack_high_water = r.u32();
        h.board = match r.u8() {
            1 => Board::Microbit,
            2 => Board::Lm3s6965evb,
            3 => Board::Mps2An386,
            4 => Board::Mps2An500,
            5 => Board::Mps2An505,
            6 => Board::Riscv32ImcVirt400k,
            7 => Board::Riscv32ImacVirt32k,
            _ => Board::Host,
        };
        Ok(h)
    }

    /// Whether two results describe the same outcome: the compared part of the header (status,
    /// error, report counts) is equal. The triangles are compared separately.
    pub fn same_outcome(&self, other: &Self) -> bool {
        self.to_bytes()[..COMPARED_LEN] == other.to_bytes()[..COMPARED_LEN]
    }

    /// Bytes of the triangle array that follows.
    pub fn triangles_len(&self) -> usize {
        if self.status == Status::Ok {
            self.triangles_out as usize * self.index_type.triangle_bytes()
        } else {
            0
        }
    }
}

/// Narrows a count to the file's `u32`, saturating.
pub fn narrow(v: usize) -> u32 {
    u32::try_from(v).unwrap_or(u32::MAX)
}

/// Conversions to and from the library's types: the one place where the file fields meet
/// `Config` and `Report`, shared by the firmware and the host's reference run.
/// The progressive-stream run of the firmware and the host (`host-sim stream`, golden
/// cases `pm-*`).
#[cfg(feature = "tinydecimate")]
pub mod pm;

#[cfg(feature = "tinydecimate")]
pub mod lib {
    use super::*;
    use tinydecimate::{Config, CostKind, Error, FeatureMode, Report, Schedule, Stop, Target};

    // Every rule has its slot in a result file.
    const _: () = assert!(tinydecimate::RULES.len() <= REJECTION_SLOTS);

    /// The configuration a case asks for.
    pub fn config(h: &CaseHeader) -> Config {
        let mut c = Config::new()
            .with_schedule(match h.schedule {
                ScheduleCode::Greedy => Schedule::Greedy,
                ScheduleCode::Passes => Schedule::Passes,
                ScheduleCode::Batched => Schedule::Batched,
            })
            .with_target(target(h.target_ratio, h.target_triangles))
            .with_lambda(h.lambda)
            .with_max_passes(h.max_passes)
            .with_max_cost(h.max_cost)
            .with_cost(match h.method {
                // Stored quadrics and the plug-ins are not a `CostKind`: the runner picks the
                // entry point (`CaseHeader::entry`).
                MethodCode::Quadric
                | MethodCode::StoredSubset
                | MethodCode::StoredOptimal
                | MethodCode::VertexDecimation
                | MethodCode::Energy
                | MethodCode::Fast
                | MethodCode::Lean
                | MethodCode::FastWedges
                | MethodCode::LeanWedges
                | MethodCode::FastInteger
                | MethodCode::LeanInteger
                | MethodCode::Envelope
                | MethodCode::EnvelopeDecimation => CostKind::Quadric,
                MethodCode::NormalVariation => CostKind::NormalVariation,
            });
        c = c.with_features(h.feature_mode != FeatureCode::Off);
        if h.feature_mode == FeatureCode::ValenceNormalized {
            c = c.with_feature_mode(FeatureMode::ValenceNormalized);
        } else {
            c = c.with_feature_mode(FeatureMode::Paper);
        }
        c = c.with_feature_targets(h.feature_targets);
        c = c.with_max_normal_turn(h.max_normal_turn_deg);
        c = c.with_min_quality(h.min_quality);
        c = c.with_boundary_weight(h.boundary_weight);
        if bounded(h) {
            c = c.with_max_error(h.max_error);
        }
        c
    }

    /// The target of a case's two fields: a nonzero triangle count, else the ratio.
    pub fn target(ratio: f32, triangles: u32) -> Target {
        if triangles > 0 {
            Target::Triangles(triangles as usize)
        } else {
            Target::Ratio(ratio)
        }
    }

    /// A target as a case's two fields, `(target_ratio, target_triangles)`: the other one 0.
    pub fn target_fields(target: Target) -> (f32, u32) {
        match target {
            Target::Ratio(r) => (r, 0),
            Target::Triangles(n) => (0.0, narrow(n)),
        }
    }

    /// Whether a case asks for the guaranteed error bound (`Controls`).
    pub fn bounded(h: &CaseHeader) -> bool {
        h.bounded()
    }

    /// The stored-quadric placement a case asks for (`None`: another entry point).
    pub fn stored_placement(h: &CaseHeader) -> Option<tinydecimate::cost::Placement> {
        match h.entry() {
            Entry::StoredSubset => Some(tinydecimate::cost::Placement::Subset),
            Entry::StoredOptimal => Some(tinydecimate::cost::Placement::Optimal),
            _ => None,
        }
    }

    /// A case header carrying `config` (vertex and triangle counts zero: `encode_case` sets them).
    pub fn case_header(config: &Config, index_type: IndexType) -> CaseHeader {
        let (target_ratio, target_triangles) = target_fields(config.target());
        CaseHeader {
            index_type,
            schedule: match config.schedule() {
                Schedule::Greedy => ScheduleCode::Greedy,
                Schedule::Passes => ScheduleCode::Passes,
                Schedule::Batched => ScheduleCode::Batched,
            },
            method: match config.cost() {
                CostKind::Quadric => MethodCode::Quadric,
                CostKind::NormalVariation => MethodCode::NormalVariation,
            },
            vertices: 0,
            triangles: 0,
            target_ratio,
            target_triangles,
            lambda: config.lambda(),
            feature_mode: match (config.features(), config.feature_mode()) {
                (false, _) => FeatureCode::Off,
                (true, FeatureMode::Paper) => FeatureCode::Paper,
                (true, FeatureMode::ValenceNormalized) => FeatureCode::ValenceNormalized,
            },
            feature_targets: config.feature_targets(),
            max_passes: config.max_passes(),
            max_cost: config.max_cost(),
            max_normal_turn_deg: config.max_normal_turn_deg(),
            min_quality: config.min_quality(),
            boundary_weight: config.boundary_weight(),
            max_error: if config.max_error().is_finite() {
                config.max_error()
            } else {
                0.0
            },
        }
    }

    /// The result header of a simplification's outcome (measurement block left zero).
    pub fn result_header(
        index_type: IndexType,
        outcome: &Result<Report, Error>,
        board: Board,
    ) -> ResultHeader {
        match outcome {
            Ok(r) => {
                let mut h = ResultHeader::empty(index_type, Status::Ok, board);
                h.triangles_in = narrow(r.triangles_in);
                h.degenerate_dropped = narrow(r.degenerate_dropped);
                h.duplicates_dropped = narrow(r.duplicates_dropped);
                h.triangles_out = narrow(r.triangles_out);
                h.target_triangles = narrow(r.target_triangles);
                h.target_reached = r.target_reached;
                h.stop = match r.stop {
                    Stop::Running => 0,
                    Stop::Target => 1,
                    Stop::NoLegalCollapse => 2,
                    Stop::MaxCost => 3,
                    Stop::MaxPasses => 4,
                    Stop::LogFull => 5,
                    Stop::ErrorLimit => 6,
                };
                h.pass_log_len = r.pass_triangles.len().min(PASS_LOG) as u8;
                for (d, s) in h.pass_triangles.iter_mut().zip(r.pass_triangles.iter()) {
                    *d = *s;
                }
                h.collapses = narrow(r.collapses);
                h.vertices_removed = narrow(r.vertices_removed);
                h.locked_vertices = narrow(r.locked_vertices);
                h.feature_vertices = narrow(r.feature_vertices);
                h.passes = r.passes;
                for (d, (_, n)) in h.rejected.iter_mut().zip(r.rejected.iter()) {
                    *d = n;
                }
                h
            }
            Err(e) => {
                let mut h = ResultHeader::empty(index_type, Status::LibraryError, board);
                let (kind, a, b) = match *e {
                    Error::Capacity {
                        what,
                        needed,
                        available,
                    } => (
                        match what {
                            tinydecimate::Capacity::Vertices => ErrorKind::CapacityVertices,
                            tinydecimate::Capacity::Triangles => ErrorKind::CapacityTriangles,
                            tinydecimate::Capacity::Quadrics => ErrorKind::CapacityQuadrics,
                            tinydecimate::Capacity::Controls => ErrorKind::CapacityControls,
                            tinydecimate::Capacity::Envelope => ErrorKind::CapacityEnvelope,
                        },
                        narrow(needed),
                        narrow(available),
                    ),
                    Error::IndexOutOfRange { triangle, index } => {
                        (ErrorKind::IndexOutOfRange, narrow(triangle), narrow(index))
                    }
                    Error::NonFinitePosition { vertex } => {
                        (ErrorKind::NonFinitePosition, narrow(vertex), 0)
                    }
                    Error::OffGrid { vertex } => (ErrorKind::OffGrid, narrow(vertex), 0),
                    Error::InvalidConfig { field } => (ErrorKind::InvalidConfig, field as u32, 0),
                    Error::OriginalMismatch { triangle } => {
                        (ErrorKind::OriginalMismatch, narrow(triangle), 0)
                    }
                };
                h.error_kind = kind;
                h.error_a = a;
                h.error_b = b;
                h
            }
        }
    }
}

/// Whole-file helpers for the host.
#[cfg(feature = "std")]
pub mod file {
    use super::*;
    use std::vec::Vec;

    /// Encodes a case file. Triangles (and the wedges of a wedge method, one per triangle,
    /// else none) are written with `header.index_type`; indices that do not fit `u16` are an
    /// error (`FormatError::Code`), so is a wedge count that is not the header's.
    pub fn encode_case(
        header: &CaseHeader,
        positions: &[[f32; 3]],
        triangles: &[[u32; 3]],
        wedges: &[[u32; 3]],
    ) -> Result<Vec<u8>, FormatError> {
        let mut h = *header;
        h.vertices = narrow(positions.len());
        h.triangles = narrow(triangles.len());
        let expected = if h.entry().wedges() {
            triangles.len()
        } else {
            0
        };
        if wedges.len() != expected {
            return Err(FormatError::Code);
        }
        let mut out = Vec::with_capacity(h.file_len());
        out.extend_from_slice(&h.to_bytes());
        for p in positions {
            for c in p {
                out.extend_from_slice(&c.to_bits().to_le_bytes());
            }
        }
        push_triangles(&mut out, h.index_type, triangles)?;
        push_triangles(&mut out, h.index_type, wedges)?;
        Ok(out)
    }

    /// A decoded case file: header, positions, (widened) triangles and wedges (empty unless
    /// the method has them).
    pub type Case = (CaseHeader, Vec<[f32; 3]>, Vec<[u32; 3]>, Vec<[u32; 3]>);

    /// Decodes a case file into header, positions, (widened) triangles and wedges.
    pub fn decode_case(bytes: &[u8]) -> Result<Case, FormatError> {
        let head: &[u8; CASE_HEADER_LEN] = bytes
            .get(..CASE_HEADER_LEN)
            .and_then(|s| s.try_into().ok())
            .ok_or(FormatError::Truncated)?;
        let h = CaseHeader::from_bytes(head)?;
        if bytes.len() < h.file_len() {
            return Err(FormatError::Truncated);
        }
        let pos_bytes = &bytes[CASE_HEADER_LEN..CASE_HEADER_LEN + h.positions_len()];
        let positions = pos_bytes
            .chunks_exact(12)
            .map(|c| {
                let f = |i: usize| f32::from_le_bytes(c[i..i + 4].try_into().unwrap());
                [f(0), f(4), f(8)]
            })
            .collect();
        let at = CASE_HEADER_LEN + h.positions_len();
        let tri_bytes = &bytes[at..at + h.triangles_len()];
        let wedge_bytes = &bytes[at + h.triangles_len()..h.file_len()];
        Ok((
            h,
            positions,
            read_triangles(h.index_type, tri_bytes),
            read_triangles(h.index_type, wedge_bytes),
        ))
    }

    /// Encodes a result file.
    pub fn encode_result(
        header: &ResultHeader,
        triangles: &[[u32; 3]],
    ) -> Result<Vec<u8>, FormatError> {
        let mut out = Vec::new();
        out.extend_from_slice(&header.to_bytes());
        push_triangles(&mut out, header.index_type, triangles)?;
        Ok(out)
    }

    /// Decodes a result file into header and (widened) triangles.
    pub fn decode_result(bytes: &[u8]) -> Result<(ResultHeader, Vec<[u32; 3]>), FormatError> {
        let head: &[u8; RESULT_HEADER_LEN] = bytes
            .get(..RESULT_HEADER_LEN)
            .and_then(|s| s.try_into().ok())
            .ok_or(FormatError::Truncated)?;
        let h = ResultHeader::from_bytes(head)?;
        let end = RESULT_HEADER_LEN + h.triangles_len();
        let tri = bytes
            .get(RESULT_HEADER_LEN..end)
            .ok_or(FormatError::Truncated)?;
        let t = read_triangles(h.index_type, tri);
        Ok((h, t))
    }

    fn push_triangles(
        out: &mut Vec<u8>,
        it: IndexType,
        triangles: &[[u32; 3]],
    ) -> Result<(), FormatError> {
        for t in triangles {
            for &i in t {
                match it {
                    IndexType::U16 => {
                        let v = u16::try_from(i).map_err(|_| FormatError::Code)?;
                        out.extend_from_slice(&v.to_le_bytes());
                    }
                    IndexType::U32 => out.extend_from_slice(&i.to_le_bytes()),
                }
            }
        }
        Ok(())
    }

    fn read_triangles(it: IndexType, b: &[u8]) -> Vec<[u32; 3]> {
        let w = it.bytes();
        b.chunks_exact(3 * w)
            .map(|c| {
                let f = |k: usize| match it {
                    IndexType::U16 => u32::from(u16::from_le_bytes([c[k * 2], c[k * 2 + 1]])),
                    IndexType::U32 => u32::from_le_bytes(c[k * 4..k * 4 + 4].try_into().unwrap()),
                };
                [f(0), f(1), f(2)]
            })
            .collect()
    }
}

#[cfg(all(test, feature = "std"))]
mod tests {
    use super::file::*;
    use super::*;

    fn case() -> CaseHeader {
        CaseHeader {
            index_type: IndexType::U16,
            schedule: ScheduleCode::Passes,
            method: MethodCode::NormalVariation,
            vertices: 0,
            triangles: 0,
            target_ratio: 0.25,
            target_triangles: 7,
            lambda: 1.5,
            feature_mode: FeatureCode::ValenceNormalized,
            feature_targets: true,
            max_passes: 9,
            max_cost: f32::INFINITY,
            max_normal_turn_deg: 60.0,
            min_quality: 0.05,
            boundary_weight: 1.0,
            max_error: 0.25,
        }
    }

    #[test]
    fn case_round_trip() {
        let pos = [
            [0.0, 1.0, -2.5],
            [3.0, f32::MIN_POSITIVE, 1e30],
            [7.0, 8.0, 9.0],
        ];
        for it in [IndexType::U16, IndexType::U32] {
            let mut h = case();
            h.index_type = it;
            let tris = [[0, 1, 2], [2, 1, 0]];
            let bytes = encode_case(&h, &pos, &tris, &[]).unwrap();
            assert_eq!(bytes.len(), 64 + 36 + 2 * 3 * it.bytes());
            let (h2, p2, t2, w2) = decode_case(&bytes).unwrap();
            assert!(w2.is_empty());
            assert_eq!(h2.vertices, 3);
            assert_eq!(h2.triangles, 2);
            assert_eq!(h2.schedule, ScheduleCode::Passes);
            assert_eq!(h2.method, MethodCode::NormalVariation);
            assert_eq!(h2.max_cost, f32::INFINITY);
            assert_eq!(h2.feature_mode, FeatureCode::ValenceNormalized);
            assert!(h2.feature_targets);
            assert_eq!(p2, pos);
            assert_eq!(t2, tris);
            assert_eq!(
                decode_case(&bytes[..bytes.len() - 1]),
                Err(FormatError::Truncated)
            );
        }
        assert_eq!(
            encode_case(&case(), &pos, &[[0, 1, 70000]], &[]),
            Err(FormatError::Code)
        );
        // A wedge method carries one wedge triangle per triangle, after them.
        let mut h = case();
        h.method = MethodCode::FastWedges;
        h.max_error = 0.0;
        let (tris, wedges) = ([[0, 1, 2]], [[2, 1, 0]]);
        assert_eq!(encode_case(&h, &pos, &tris, &[]), Err(FormatError::Code));
        let bytes = encode_case(&h, &pos, &tris, &wedges).unwrap();
        assert_eq!(bytes.len(), 64 + 36 + 2 * 3 * 2);
        let (_, _, t2, w2) = decode_case(&bytes).unwrap();
        assert_eq!((t2.as_slice(), w2.as_slice()), (&tris[..], &wedges[..]));
        assert_eq!(
            decode_case(&bytes[..bytes.len() - 1]),
            Err(FormatError::Truncated)
        );
    }

    #[test]
    fn case_layout_is_fixed() {
        let b = case().to_bytes();
        assert_eq!(&b[0..4], b"TDCS");
        assert_eq!(b[6], 2);
        assert_eq!(b[7], 1);
        assert_eq!(&b[16..20], &0.25f32.to_le_bytes());
        assert_eq!(&b[24..28], &1.5f32.to_le_bytes());
        assert_eq!(b[28], 2);
        assert_eq!(&b[32..36], &9u32.to_le_bytes());
        assert_eq!(&b[48..52], &1.0f32.to_le_bytes());
        assert_eq!(b[30], 1);
    }

    #[test]
    fn method_codes_and_entries() {
        let cases = [
            (MethodCode::Quadric, 0, Entry::Simplify),
            (MethodCode::NormalVariation, 1, Entry::Simplify),
            (MethodCode::StoredSubset, 2, Entry::StoredSubset),
            (MethodCode::StoredOptimal, 3, Entry::StoredOptimal),
            (MethodCode::VertexDecimation, 4, Entry::VertexDecimation),
            (MethodCode::Energy, 5, Entry::Energy),
            (MethodCode::Fast, 6, Entry::Fast),
            (MethodCode::Lean, 7, Entry::Lean),
            (MethodCode::FastWedges, 8, Entry::FastWedges),
            (MethodCode::LeanWedges, 9, Entry::LeanWedges),
            (MethodCode::FastInteger, 10, Entry::FastInteger),
            (MethodCode::LeanInteger, 11, Entry::LeanInteger),
            (MethodCode::Envelope, 12, Entry::Envelope),
            (
                MethodCode::EnvelopeDecimation,
                13,
                Entry::EnvelopeDecimation,
            ),
        ];
        for (method, code, entry) in cases {
            let mut h = case();
            h.method = method;
            h.max_error = 0.0;
            let b = h.to_bytes();
            assert_eq!(b[30], code);
            let back = CaseHeader::from_bytes(&b).unwrap();
            assert_eq!(back.method, method);
            assert_eq!(back.entry(), entry);
            assert_eq!(
                entry.per_vertex_storage(),
                matches!(code, 2 | 3 | 5),
                "{method:?}"
            );
            assert_eq!(entry.wedges(), matches!(code, 8 | 9), "{method:?}");
            assert_eq!(entry.pipeline(), matches!(code, 6..=9), "{method:?}");
            assert_eq!(entry.integer(), matches!(code, 10 | 11), "{method:?}");
            assert_eq!(entry.envelope(), matches!(code, 12 | 13), "{method:?}");
            // The control-point bound comes first, as the firmware has always run it; the
            // envelope methods are their own bound.
            h.max_error = 0.25;
            let bounded = if entry.envelope() {
                entry
            } else {
                Entry::Bounded
            };
            assert_eq!(h.entry(), bounded);
        }
        let mut b = case().to_bytes();
        b[30] = 14;
        assert_eq!(CaseHeader::from_bytes(&b), Err(FormatError::Code));
    }

    /// The in-place conversion of an integer case's positions gives the positions the host
    /// converts one by one.
    #[test]
    fn grid_positions_convert_in_place() {
        let pos = [[0.0, 1.0, 32767.0], [5.0, 1234.0, 2.0], [7.0, 0.0, 16384.0]];
        let mut bytes: std::vec::Vec<u8> = pos
            .iter()
            .flatten()
            .flat_map(|x: &f32| x.to_le_bytes())
            .collect();
        grid_in_place(&mut bytes);
        let got: std::vec::Vec<[u16; 3]> = bytes[..18]
            .chunks_exact(6)
            .map(|c| {
                let f = |k: usize| u16::from_le_bytes([c[2 * k], c[2 * k + 1]]);
                [f(0), f(1), f(2)]
            })
            .collect();
        let want: std::vec::Vec<[u16; 3]> = pos.iter().map(|&p| grid_position(p)).collect();
        assert_eq!(got, want);
        assert_eq!(want[0], [0, 1, 32767]);
    }

    #[test]
    fn result_round_trip() {
        let mut h = ResultHeader::empty(IndexType::U32, Status::Ok, Board::Microbit);
        h.triangles_in = 10;
        h.triangles_out = 2;
        h.stop = 1;
        h.target_reached = true;
        h.pass_log_len = 3;
        h.pass_triangles[2] = 5;
        h.rejected[8] = 11;
        h.ticks = 1 << 40;
        h.stack_bytes = 1234;
        h.stack_high_water = 2000;
        let tris = [[1, 2, 3], [100000, 5, 6]];
        let bytes = encode_result(&h, &tris).unwrap();
        // The ninth rule's count (the error bound's) is at 64 + 8 × 4, inside the compared part.
        assert_eq!(&bytes[96..100], &11u32.to_le_bytes());
        assert_eq!(&bytes[4..6], &RESULT_VERSION.to_le_bytes());
        let (h2, t2) = decode_result(&bytes).unwrap();
        assert_eq!(h2, h);
        assert_eq!(t2, tris);
        let mut other = h.clone();
        other.ticks = 3;
        other.board = Board::Host;
        assert!(h.same_outcome(&other));
        other.rejected[0] = 1;
        assert!(!h.same_outcome(&other));
    }
}

/// FNV-1a (32 bit) over the little-endian bytes of `positions`: [`ResultHeader::positions_hash`].
pub fn positions_hash(positions: &[[f32; 3]]) -> u32 {
    let mut h = 0x811c_9dc5u32;
    for x in positions.iter().flatten() {
        for b in x.to_le_bytes() {
            h ^= u32::from(b);
            h = h.wrapping_mul(0x0100_0193);
        }
    }
    h
}
