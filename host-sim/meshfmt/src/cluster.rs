//! The clustering case and result files (`host-sim qemu --cluster` and the firmware's
//! `tinydecimate-cluster` image): streaming vertex clustering of a mesh that the device never
//! holds. The firmware reads the triangles in chunks and each corner's position on demand
//! (seek + read), both through semihosting, from the case file.
//!
//! # Cluster case file (host → firmware), [`CLUSTER_CASE_LEN`] = 64 bytes of header
//!
//! | offset | type    | field                                                        |
//! |-------:|---------|--------------------------------------------------------------|
//! |      0 | [u8; 4] | magic `TDCL`                                                 |
//! |      4 | u16     | version ([`CLUSTER_VERSION`])                                |
//! |      6 | u8      | output index type: 2 = `u16`, 4 = `u32`                      |
//! |      7 | u8      | representative: 0 = nearest the cell centre, 1 = quadric     |
//! |      8 | u32     | vertex count V                                               |
//! |     12 | u32     | triangle count T                                             |
//! |     16 | u32     | target triangles (0: `resolution` instead)                   |
//! |     20 | u32     | resolution (cells along the longest side) when no target     |
//! |     24 | u32     | table cells used (`ClusterConfig::table_cells`, 0: all)      |
//! |     28 | u32     | output buffer slots                                          |
//! |     32 | u32     | refine passes of the target search                           |
//! |     36 | u8      | source: 0 = streamed through semihosting, 1 = loaded into RAM first |
//! |     37 | [u8;27] | reserved, 0                                                  |
//! |     64 | f32     | positions: V × 3                                             |
//! |        | u32     | triangles: T × 3 (always `u32`: the input's numbering)       |
//!
//! # Cluster result file (firmware → host), [`CLUSTER_RESULT_LEN`] = 128 bytes of header
//!
//! Bytes `0..CLUSTER_COMPARED_LEN` and the triangles are compared with the golden files; the
//! measurement block after them differs per board.
//!
//! | offset | type     | field                                                     |
//! |-------:|----------|-----------------------------------------------------------|
//! |      0 | [u8; 4]  | magic `TDCR`                                              |
//! |      4 | u16      | version                                                   |
//! |      6 | u8       | index type of the triangles that follow                   |
//! |      7 | u8       | [`Status`]                                                |
//! |      8 | u8       | [`ClusterErrorKind`] (status 1) or 0                      |
//! |      9 | [u8; 3]  | reserved                                                  |
//! |     12 | u32 × 3  | error details (capacity, needed at least, estimate / triangle, index / vertex) |
//! |     24 | u32 × 8  | triangles in, triangles out, collapsed, duplicates, opposite duplicates, cells, passes, target |
//! |     56 | u32 × 4  | grid: n, dims x, y, z                                     |
//! |     72 | f32 × 4  | grid: cell, origin x, y, z                                |
//! |     88 | [u8; 8]  | reserved                                                  |
//! |     96 | u64      | SysTick ticks around the library call (measurement)       |
//! |    104 | u32      | stack bytes used below the caller's frame                 |
//! |    108 | u32      | stack high-water mark from the stack top                  |
//! |    112 | u32      | table bytes (static)                                      |
//! |    116 | u32      | output buffer bytes (static)                              |
//! |    120 | u32      | position reads through semihosting (cache misses)         |
//! |    124 | u8       | board id                                                  |
//! |    125 | [u8; 3]  | reserved                                                  |
//! |    128 | u16/u32  | triangles: triangles out × 3                              |

use super::{Board, FormatError, IndexType, Status, R, W};

/// Cluster case magic.
pub const CLUSTER_MAGIC: [u8; 4] = *b"TDCL";
/// Cluster result magic.
pub const CLUSTER_RESULT_MAGIC: [u8; 4] = *b"TDCR";
/// Version of both cluster files.
pub const CLUSTER_VERSION: u16 = 1;
/// Size of the cluster case header.
pub const CLUSTER_CASE_LEN: usize = 64;
/// Size of the cluster result header.
pub const CLUSTER_RESULT_LEN: usize = 128;
/// The result header bytes that must match a golden result exactly.
pub const CLUSTER_COMPARED_LEN: usize = 96;

/// The cluster case header.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ClusterCase {
    pub index_type: IndexType,
    /// Quadric representative (else nearest the cell centre).
    pub quadric: bool,
    pub vertices: u32,
    pub triangles: u32,
    pub target_triangles: u32,
    pub resolution: u32,
    pub table_cells: u32,
    pub output_slots: u32,
    pub refine_passes: u32,
    /// Load the whole mesh into RAM first and cluster it from there (measures the library
    /// alone, without the semihosting reads); only on boards with the RAM for it.
    pub in_ram: bool,
}

impl ClusterCase {
    /// Encodes the header.
    pub fn to_bytes(&self) -> [u8; CLUSTER_CASE_LEN] {
        let mut b = [0u8; CLUSTER_CASE_LEN];
        let mut w = W { b: &mut b, at: 0 };
        w.bytes(&CLUSTER_MAGIC);
        w.u16(CLUSTER_VERSION);
        w.u8(self.index_type as u8);
        w.u8(self.quadric as u8);
        for v in [
            self.vertices,
            self.triangles,
            self.target_triangles,
            self.resolution,
            self.table_cells,
            self.output_slots,
            self.refine_passes,
        ] {
            w.u32(v);
        }
        w.u8(self.in_ram as u8);
        b
    }

    /// Decodes the header.
    pub fn from_bytes(b: &[u8; CLUSTER_CASE_LEN]) -> Result<Self, FormatError> {
        let mut r = R { b, at: 0 };
        if r.take::<4>() != CLUSTER_MAGIC {
            return Err(FormatError::Magic);
        }
        if r.u16() != CLUSTER_VERSION {
            return Err(FormatError::Version);
        }
        let index_type = IndexType::from_code(r.u8()).ok_or(FormatError::Code)?;
        let quadric = match r.u8() {
            0 => false,
            1 => true,
            _ => return Err(FormatError::Code),
        };
        Ok(ClusterCase {
            index_type,
            quadric,
            vertices: r.u32(),
            triangles: r.u32(),
            target_triangles: r.u32(),
            resolution: r.u32(),
            table_cells: r.u32(),
            output_slots: r.u32(),
            refine_passes: r.u32(),
            in_ram: match r.u8() {
                0 => false,
                1 => true,
                _ => return Err(FormatError::Code),
            },
        })
    }

    /// Offset of the position array.
    pub const fn positions_at(&self) -> u64 {
        CLUSTER_CASE_LEN as u64
    }

    /// Offset of the triangle array.
    pub const fn triangles_at(&self) -> u64 {
        CLUSTER_CASE_LEN as u64 + self.vertices as u64 * 12
    }
}

/// Which clustering error (`tinydecimate::cluster::ClusterError`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ClusterErrorKind {
    None = 0,
    TableFull = 1,
    OutputFull = 2,
    VerticesFull = 3,
    TableTooWide = 4,
    VertexTooWide = 5,
    IndexOutOfRange = 6,
    NonFinitePosition = 7,
    InvalidGrid = 8,
    NotRereadable = 9,
    EmptyInput = 10,
}

impl ClusterErrorKind {
    fn from_code(c: u8) -> Option<Self> {
        use ClusterErrorKind::*;
        [
            None,
            TableFull,
            OutputFull,
            VerticesFull,
            TableTooWide,
            VertexTooWide,
            IndexOutOfRange,
            NonFinitePosition,
            InvalidGrid,
            NotRereadable,
            EmptyInput,
        ]
        .get(c as usize)
        .copied()
    }
}

/// The cluster result header.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClusterResult {
    pub index_type: IndexType,
    pub status: Status,
    pub error_kind: ClusterErrorKind,
    pub error: [u32; 3],
    pub triangles_in: u32,
    pub triangles_out: u32,
    pub collapsed: u32,
    pub duplicates: u32,
    pub opposite_duplicates: u32,
    pub cells: u32,
    pub passes: u32,
    pub target_triangles: u32,
    pub grid_n: u32,
    pub grid_dims: [u32; 3],
    pub grid_cell: f32,
    pub grid_origin: [f32; 3],
    // ---- measurement block, not compared ----
    pub ticks: u64,
    pub stack_bytes: u32,
    pub stack_high_water: u32,
    pub table_bytes: u32,
    pub output_bytes: u32,
    pub position_reads: u32,
    pub board: Board,
}

impl ClusterResult {
    /// A header with the given status and everything else zero.
    pub const fn empty(index_type: IndexType, status: Status, board: Board) -> Self {
        ClusterResult {
            index_type,
            status,
            error_kind: ClusterErrorKind::None,
            error: [0; 3],
            triangles_in: 0,
            triangles_out: 0,
            collapsed: 0,
            duplicates: 0,
            opposite_duplicates: 0,
            cells: 0,
            passes: 0,
            target_triangles: 0,
            grid_n: 0,
            grid_dims: [0; 3],
            grid_cell: 0.0,
            grid_origin: [0.0; 3],
            ticks: 0,
            stack_bytes: 0,
            stack_high_water: 0,
            table_bytes: 0,
            output_bytes: 0,
            position_reads: 0,
            board,
        }
    }

    /// Bytes of the triangles that follow the header.
    pub fn triangles_len(&self) -> usize {
        if self.status == Status::Ok {
            self.triangles_out as usize * self.index_type.triangle_bytes()
        } else {
            0
        }
    }

    /// Encodes the header.
    pub fn to_bytes(&self) -> [u8; CLUSTER_RESULT_LEN] {
        let mut b = [0u8; CLUSTER_RESULT_LEN];
        let mut w = W { b: &mut b, at: 0 };
        w.bytes(&CLUSTER_RESULT_MAGIC);
        w.u16(CLUSTER_VERSION);
        w.u8(self.index_type as u8);
        w.u8(self.status as u8);
        w.u8(self.error_kind as u8);
        w.skip(3);
        for v in self.error {
            w.u32(v);
        }
        for v in [
            self.triangles_in,
            self.triangles_out,
            self.collapsed,
            self.duplicates,
            self.opposite_duplicates,
            self.cells,
            self.passes,
            self.target_triangles,
            self.grid_n,
            self.grid_dims[0],
            self.grid_dims[1],
            self.grid_dims[2],
        ] {
            w.u32(v);
        }
        w.f32(self.grid_cell);
        for v in self.grid_origin {
            w.f32(v);
        }
        w.skip(8);
        w.bytes(&self.ticks.to_le_bytes());
        for v in [
            self.stack_bytes,
            self.stack_high_water,
            self.table_bytes,
            self.output_bytes,
            self.position_reads,
        ] {
            w.u32(v);
        }
        w.u8(self.board as u8);
        b
    }

    /// Decodes the header.
    pub fn from_bytes(b: &[u8; CLUSTER_RESULT_LEN]) -> Result<Self, FormatError> {
        let mut r = R { b, at: 0 };
        if r.take::<4>() != CLUSTER_RESULT_MAGIC {
            return Err(FormatError::Magic);
        }
        if r.u16() != CLUSTER_VERSION {
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
        let error_kind = ClusterErrorKind::from_code(r.u8()).ok_or(FormatError::Code)?;
        r.skip(3);
        let error = [r.u32(), r.u32(), r.u32()];
        let mut h = ClusterResult::empty(index_type, status, Board::Host);
        h.error_kind = error_kind;
        h.error = error;
        h.triangles_in = r.u32();
        h.triangles_out = r.u32();
        h.collapsed = r.u32();
        h.duplicates = r.u32();
        h.opposite_duplicates = r.u32();
        h.cells = r.u32();
        h.passes = r.u32();
        h.target_triangles = r.u32();
        h.grid_n = r.u32();
        h.grid_dims = [r.u32(), r.u32(), r.u32()];
        h.grid_cell = r.f32();
        h.grid_origin = [r.f32(), r.f32(), r.f32()];
        r.skip(8);
        h.ticks = r.u64();
        h.stack_bytes = r.u32();
        h.stack_high_water = r.u32();
        h.table_bytes = r.u32();
        h.output_bytes = r.u32();
        h.position_reads = r.u32();
        h.board = match r.u8() {
            0 => Board::Host,
            1 => Board::Microbit,
            2 => Board::Lm3s6965evb,
            3 => Board::Mps2An386,
            4 => Board::Mps2An500,
            5 => Board::Mps2An505,
            6 => Board::Riscv32ImcVirt400k,
            7 => Board::Riscv32ImacVirt32k,
            _ => return Err(FormatError::Code),
        };
        Ok(h)
    }
}

/// Conversions to and from the library's clustering types (firmware and host reference run).
#[cfg(feature = "tinydecimate")]
pub mod lib {
    use super::*;
    use crate::narrow;
    use tinydecimate::cluster::{ClusterConfig, ClusterError, ClusterReport, GridChoice};

    /// The configuration a cluster case asks for.
    pub fn config(c: &ClusterCase) -> ClusterConfig {
        let base = if c.target_triangles > 0 {
            ClusterConfig::target(c.target_triangles as usize)
        } else {
            ClusterConfig {
                grid: GridChoice::Resolution(c.resolution),
                ..ClusterConfig::target(0)
            }
        };
        ClusterConfig {
            refine_passes: c.refine_passes,
            ..base
        }
        .with_table_cells(c.table_cells as usize)
    }

    /// The result header of a clustering's outcome (measurement block left zero).
    pub fn result(
        index_type: IndexType,
        outcome: &Result<ClusterReport, ClusterError>,
        board: Board,
    ) -> ClusterResult {
        match outcome {
            Ok(r) => {
                let mut h = ClusterResult::empty(index_type, Status::Ok, board);
                h.triangles_in = narrow(r.triangles_in);
                h.triangles_out = narrow(r.triangles_out);
                h.collapsed = narrow(r.collapsed);
                h.duplicates = narrow(r.duplicates);
                h.opposite_duplicates = narrow(r.opposite_duplicates);
                h.cells = narrow(r.cells);
                h.passes = r.passes;
                h.target_triangles = narrow(r.target_triangles);
                h.grid_n = r.grid.n;
                h.grid_dims = r.grid.dims;
                h.grid_cell = r.grid.cell;
                h.grid_origin = r.grid.origin;
                h
            }
            Err(e) => {
                let mut h = ClusterResult::empty(index_type, Status::LibraryError, board);
                use ClusterErrorKind as K;
                let (k, d) = match *e {
                    ClusterError::TableFull {
                        capacity,
                        needed_at_least,
                        estimate,
                    } => (K::TableFull, [capacity, needed_at_least, estimate]),
                    ClusterError::OutputFull {
                        capacity,
                        needed_at_least,
                        estimate,
                    } => (K::OutputFull, [capacity, needed_at_least, estimate]),
                    ClusterError::VerticesFull { capacity } => (K::VerticesFull, [capacity, 0, 0]),
                    ClusterError::TableTooWide { cells, index_count } => {
                        (K::TableTooWide, [cells, index_count, 0])
                    }
                    ClusterError::VertexTooWide { vertex } => (K::VertexTooWide, [vertex, 0, 0]),
                    ClusterError::IndexOutOfRange { triangle, index } => {
                        (K::IndexOutOfRange, [triangle, index, 0])
                    }
                    ClusterError::NonFinitePosition { vertex } => {
                        (K::NonFinitePosition, [vertex, 0, 0])
                    }
                    ClusterError::InvalidGrid => (K::InvalidGrid, [0; 3]),
                    ClusterError::NotRereadable => (K::NotRereadable, [0; 3]),
                    ClusterError::EmptyInput => (K::EmptyInput, [0; 3]),
                };
                h.error_kind = k;
                h.error = [narrow(d[0]), narrow(d[1]), narrow(d[2])];
                h
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn headers_round_trip() {
        let c = ClusterCase {
            index_type: IndexType::U16,
            quadric: true,
            vertices: 35_947,
            triangles: 69_451,
            target_triangles: 700,
            resolution: 0,
            table_cells: 500,
            output_slots: 900,
            refine_passes: 2,
            in_ram: true,
        };
        assert_eq!(ClusterCase::from_bytes(&c.to_bytes()), Ok(c));
        let mut r = ClusterResult::empty(IndexType::U32, Status::Ok, Board::Microbit);
        r.error = [1, 2, 3];
        r.triangles_out = 640;
        r.grid_dims = [20, 19, 16];
        r.grid_origin = [-0.1, 0.03, -0.06];
        r.ticks = 1 << 40;
        r.position_reads = 77;
        assert_eq!(ClusterResult::from_bytes(&r.to_bytes()), Ok(r));
    }
}
