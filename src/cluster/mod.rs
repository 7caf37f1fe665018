//! Streaming vertex clustering: meshes larger than RAM, read as a stream of triangles.
//!
//! A second operator beside edge collapse. The bounding box is cut into a uniform grid of
//! cubic cells; every vertex falls into one cell; each occupied cell keeps one
//! *representative*, an existing input vertex; a triangle whose three corners fall into three
//! distinct cells becomes a triangle of the representatives, all others vanish. This is the
//! box filter of the simplification survey ("基于长方体滤波的多面体简化": the bounding box cut
//! into small boxes, the vertices of each box merged into one representative vertex, the
//! triangles rebuilt from the original topology; its stated drawback is the loss of
//! high-frequency detail), an operator due to Rossignac and Borrel (1993; the survey names no
//! author). Following Lindstrom's out-of-core simplification (SIGGRAPH 2000), the memory is
//! proportional to the *output*: one entry per occupied cell and one per output triangle,
//! never one per input vertex or triangle, and the input is read as a stream, chunk by chunk.
//! Unlike Lindstrom, the representative is an existing vertex, not a computed position, so the
//! positions stay read-only (in flash, or behind an accessor) and output indices refer to
//! input vertices.
//!
//! Two representatives:
//!
//! * **nearest** (no [`Quadrics`]): the vertex nearest the cell's centre, ties to the lower
//!   index. One pass; [`Clusterer::BYTES_PER_CELL`] = 12 bytes per cell.
//! * **quadric** (with [`Quadrics`]): Lindstrom's one plane quadric per cell (the area-weighted
//!   plane of each triangle that survives, i.e. whose corners fall into three distinct cells,
//!   added to those three cells; Lindstrom also adds the planes of the triangles that vanish,
//!   this does not), then, in a second pass, the
//!   vertex of the cell with the least quadric error, ties to the lower index.
//!   12 + [`Quadrics::BYTES_PER_CELL`] = 52 bytes per cell.
//!
//! Output triangles are gathered in the caller's buffer, which doubles as an open-addressing
//! hash set while the stream runs: `size_of::<[I; 3]>()` bytes (6 with `u16`) per slot, and
//! the buffer should be about 1.3x the output for short probes. Duplicates are dropped in any
//! rotation **and in the opposite winding** (the first triangle seen is kept, with its
//! winding): two coincident faces of opposite orientation are a zero-volume double sheet,
//! which renderers show as z-fighting, and the repository's checker (`meshcheck`) counts them
//! as duplicates. Winding is kept otherwise: an output triangle is its input triangle with
//! each corner replaced by the corner's representative.
//!
//! Determinism: only `+ - * /`, comparisons and float-to-integer `as` casts (defined by Rust
//! as truncation with saturation, which is `floor` for the non-negative values used here), and
//! the library's own `rsqrt`; integer hashing. The output bytes are the same on the host and on
//! every Cortex-M core.
//!
//! ```
//! use tinydecimate::cluster::{ClusterConfig, Clusterer, Scratch, SliceSource};
//!
//! // A 16x16 grid of quads on z = 0: 512 triangles.
//! let n = 17;
//! // Fixed arrays, as on a device (no heap anywhere).
//! let mut positions = [[0.0f32; 3]; 17 * 17];
//! for (i, p) in positions.iter_mut().enumerate() {
//!     *p = [(i % n) as f32, (i / n) as f32, 0.0];
//! }
//! let mut triangles = [[0u32; 3]; 512];
//! for y in 0..16u32 {
//!     for x in 0..16u32 {
//!         let v = y * 17 + x;
//!         let q = ((y * 16 + x) * 2) as usize;
//!         triangles[q] = [v, v + 1, v + 18];
//!         triangles[q + 1] = [v, v + 18, v + 17];
//!     }
//! }
//! let mut table = Clusterer::<256>::new();
//! let mut out = [[0u16; 3]; 160];
//! let mut source = SliceSource::new(&positions, &triangles);
//! // No optional buffers (`Scratch` holds the quadric table and the per-vertex memories).
//! let config = ClusterConfig::target(100);
//! let report = table.cluster(&mut source, &config, &mut out, Scratch::new())?;
//! assert!(report.triangles_out <= 100 && report.triangles_out > 0);
//! # Ok::<(), tinydecimate::cluster::ClusterError>(())
//! ```

use crate::index::Index;
use crate::math::{self, V3};

/// Largest number of cells along one axis (keys pack 10 bits per axis).
pub const MAX_RESOLUTION: u32 = 1024;

/// Triangles read from a [`Source`] at a time (a stack buffer of 12 bytes per triangle).
pub const CHUNK: usize = 32;

const EMPTY: u32 = u32::MAX;

/// Why clustering failed. Nothing in the caller's output buffer is meaningful after an error.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ClusterError {
    /// More occupied cells than the table holds. `needed_at_least` is certain; `estimate`
    /// extrapolates from the part of the stream read (equal to `needed_at_least` when the
    /// stream's length is unknown). Use a table of at least `estimate` cells (about 1.3x for
    /// short probes), or a coarser grid.
    TableFull {
        /// Cells in the table.
        capacity: usize,
        /// Cells needed, at least.
        needed_at_least: usize,
        /// Cells needed, extrapolated.
        estimate: usize,
    },
    /// More distinct output triangles than the output buffer holds; same fields as
    /// [`ClusterError::TableFull`], in triangles.
    OutputFull {
        /// Triangles the buffer holds.
        capacity: usize,
        /// Triangles needed, at least.
        needed_at_least: usize,
        /// Triangles needed, extrapolated.
        estimate: usize,
    },
    /// More output vertices than the caller's vertex buffer holds
    /// ([`cluster_then_collapse`]).
    VerticesFull {
        /// Vertices the buffer holds.
        capacity: usize,
    },
    /// The table (the part of it in use: [`ClusterConfig::table_cells`]) has more cells than
    /// the output index type can number (cell numbers are stored in the output buffer while
    /// the stream runs).
    TableTooWide {
        /// Cells in the table.
        cells: usize,
        /// Largest count the index type numbers.
        index_count: usize,
    },
    /// An output vertex number does not fit the output index type.
    VertexTooWide {
        /// The vertex.
        vertex: usize,
    },
    /// A triangle refers to a vertex the position accessor does not have.
    IndexOutOfRange {
        /// The triangle (its number in the stream).
        triangle: usize,
        /// The offending index.
        index: usize,
    },
    /// A vertex used by a triangle has a NaN or infinite coordinate.
    NonFinitePosition {
        /// The vertex.
        vertex: usize,
    },
    /// The cell size is not positive and finite, the bounding box is not finite, or the grid
    /// would need more than [`MAX_RESOLUTION`] cells along an axis.
    InvalidGrid,
    /// The chosen grid needs another pass over the input, and the source cannot be re-read.
    NotRereadable,
    /// The stream has no triangle, so there is no bounding box.
    EmptyInput,
}

impl core::fmt::Display for ClusterError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            ClusterError::TableFull {
                capacity,
                needed_at_least,
                estimate,
            } => write!(
                f,
                "cell table of {capacity} is full: needs at least {needed_at_least}, about {estimate}"
            ),
            ClusterError::OutputFull {
                capacity,
                needed_at_least,
                estimate,
            } => write!(
                f,
                "output buffer of {capacity} triangles is full: needs at least {needed_at_least}, about {estimate}"
            ),
            ClusterError::TableTooWide { cells, index_count } => write!(
                f,
                "table of {cells} cells is too wide for an index type of {index_count} values"
            ),
            ClusterError::VerticesFull { capacity } => {
                write!(f, "vertex buffer of {capacity} is full")
            }
            ClusterError::VertexTooWide { vertex } => {
                write!(f, "vertex {vertex} does not fit the output index type")
            }
            ClusterError::IndexOutOfRange { triangle, index } => {
                write!(f, "triangle {triangle} refers to missing vertex {index}")
            }
            ClusterError::NonFinitePosition { vertex } => {
                write!(f, "vertex {vertex} has a non-finite coordinate")
            }
            ClusterError::InvalidGrid => write!(f, "invalid grid"),
            ClusterError::NotRereadable => write!(f, "the source cannot be read again"),
            ClusterError::EmptyInput => write!(f, "no triangles"),
        }
    }
}

/// Read access to vertex positions: a slice, or any accessor (flash, a file, a link) through
/// [`PositionFn`]. `None` means the vertex does not exist.
pub trait Positions {
    /// The position of `vertex`.
    fn position(&mut self, vertex: usize) -> Option<[f32; 3]>;
}

impl Positions for &[[f32; 3]] {
    #[inline]
    fn position(&mut self, vertex: usize) -> Option<[f32; 3]> {
        self.get(vertex).copied()
    }
}

/// A closure as a [`Positions`] accessor.
pub struct PositionFn<F>(pub F);

impl<F: FnMut(usize) -> Option<[f32; 3]>> Positions for PositionFn<F> {
    #[inline]
    fn position(&mut self, vertex: usize) -> Option<[f32; 3]> {
        (self.0)(vertex)
    }
}

/// A stream of triangles that can be read again from the start, with their positions: what
/// [`Clusterer::cluster`] needs for the bounding box, the search for a target count and the
/// quadric representative. A stream that can be read only once goes through
/// [`Clusterer::stream`] instead.
pub trait Source {
    /// Goes back to the first triangle; `false` if the source cannot.
    fn rewind(&mut self) -> bool;
    /// Copies the next triangles into `buf`; returns how many (0: the end).
    fn read(&mut self, buf: &mut [[u32; 3]]) -> usize;
    /// The position of `vertex` (`None`: no such vertex).
    fn position(&mut self, vertex: usize) -> Option<[f32; 3]>;
}

/// A [`Source`] over triangles and positions in memory (or flash).
pub struct SliceSource<'a, I: Index> {
    positions: &'a [[f32; 3]],
    triangles: &'a [[I; 3]],
    at: usize,
}

impl<'a, I: Index> SliceSource<'a, I> {
    /// A source reading `triangles` from the start.
    pub fn new(positions: &'a [[f32; 3]], triangles: &'a [[I; 3]]) -> Self {
        SliceSource {
            positions,
            triangles,
            at: 0,
        }
    }
}

impl<I: Index> Source for SliceSource<'_, I> {
    fn rewind(&mut self) -> bool {
        self.at = 0;
        true
    }
    fn read(&mut self, buf: &mut [[u32; 3]]) -> usize {
        let rest = self.triangles.get(self.at..).unwrap_or(&[]);
        let mut n = 0;
        for (d, s) in buf.iter_mut().zip(rest) {
            *d = [
                to_u32(s[0].to_usize()),
                to_u32(s[1].to_usize()),
                to_u32(s[2].to_usize()),
            ];
            n += 1;
        }
        self.at += n;
        n
    }
    #[inline]
    fn position(&mut self, vertex: usize) -> Option<[f32; 3]> {
        self.positions.get(vertex).copied()
    }
}

#[inline]
fn to_u32(v: usize) -> u32 {
    u32::try_from(v).unwrap_or(u32::MAX)
}

/// Fixed-point bits of a position inside the box (per axis, along the longest side).
const QBITS: u32 = 20;
const QMAX: u32 = (1 << QBITS) - 1;

/// A uniform grid of cubic cells: `n` cells along the longest side of the bounding box.
///
/// A position is first quantised to 20-bit fixed point along the box's longest side
/// (`q = floor((p - origin) · 2^20 / extent)`, one multiplication per axis), then its cell is
/// `(q · n) >> 20`, in integers. So the counting passes of the target search test many
/// resolutions for the price of one float conversion per corner, and every grid's cells are
/// exactly `extent / n` wide: a requested cell size is rounded down to the next such width.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Grid {
    /// The corner of cell (0, 0, 0): the bounding box's minimum.
    pub origin: [f32; 3],
    /// Edge length of a cell (`extent / n`).
    pub cell: f32,
    /// Cells along each axis (each at most [`MAX_RESOLUTION`]).
    pub dims: [u32; 3],
    /// Cells along the longest side.
    pub n: u32,
    /// `2^20 / extent`.
    scale: f32,
}

impl Grid {
    /// The grid of cells of edge at most `cell` over the box `min`..`max` (the edge is
    /// rounded down so that a whole number of cells spans the longest side).
    pub fn with_cell_size(min: [f32; 3], max: [f32; 3], cell: f32) -> Result<Grid, ClusterError> {
        if !(cell > 0.0 && cell.is_finite()) {
            return Err(ClusterError::InvalidGrid);
        }
        let ext = extent(min, max)?;
        let t = ext / cell;
        if !(t.is_finite() && t <= MAX_RESOLUTION as f32) {
            return Err(ClusterError::InvalidGrid);
        }
        // ceil(t), written out (`as` truncates).
        let mut n = t as u32;
        if (n as f32) < t {
            n += 1;
        }
        Grid::with_resolution(min, max, n)
    }

    /// The grid with `n` cells (clamped to 1..=[`MAX_RESOLUTION`]) along the longest side of
    /// the box.
    pub fn with_resolution(min: [f32; 3], max: [f32; 3], n: u32) -> Result<Grid, ClusterError> {
        let n = n.clamp(1, MAX_RESOLUTION);
        let ext = extent(min, max)?;
        let scale = (1u32 << QBITS) as f32 / ext;
        if !(scale.is_finite() && scale > 0.0) {
            return Err(ClusterError::InvalidGrid);
        }
        let mut g = Grid {
            origin: min,
            cell: ext / n as f32,
            dims: [1; 3],
            n,
            scale,
        };
        let q = g.quantise(max);
        g.dims = [
            g.cell_of(q[0]) + 1,
            g.cell_of(q[1]) + 1,
            g.cell_of(q[2]) + 1,
        ];
        Ok(g)
    }

    /// Cells along the longest axis.
    pub fn resolution(&self) -> u32 {
        self.n
    }

    /// 20-bit fixed-point coordinates of `p` in the box (clamped to it; NaN to 0).
    #[inline]
    fn quantise(&self, p: V3) -> [u32; 3] {
        // `as` saturates (NaN and t <= 0 to 0, t >= 2^32 to u32::MAX) and truncates, which
        // is floor for t > 0; then the clamp to QMAX.
        let q = |a: usize| (((get3(p, a) - get3(self.origin, a)) * self.scale) as u32).min(QMAX);
        [q(0), q(1), q(2)]
    }

    #[inline]
    fn cell_of(&self, q: u32) -> u32 {
        (q.min(QMAX) * self.n) >> QBITS
    }

    /// The key of the cell of quantised coordinates `q`.
    #[inline]
    fn key_q(&self, q: [u32; 3]) -> u32 {
        self.cell_of(q[0]) | (self.cell_of(q[1]) << 10) | (self.cell_of(q[2]) << 20)
    }

    /// The key of the cell holding `p`: cell coordinates `x | y << 10 | z << 20` (positions
    /// outside the box go to the nearest cell).
    #[inline]
    pub fn key(&self, p: [f32; 3]) -> u32 {
        self.key_q(self.quantise(p))
    }

    /// Centre of the cell with key `k`.
    #[inline]
    fn centre(&self, k: u32) -> V3 {
        let c = self.corner(k);
        let h = 0.5 * self.cell;
        [c[0] + h, c[1] + h, c[2] + h]
    }

    /// Minimum corner of the cell with key `k`.
    #[inline]
    fn corner(&self, k: u32) -> V3 {
        let f = |a: usize| ((k >> (10 * a)) & 1023) as f32 * self.cell;
        [
            self.origin[0] + f(0),
            self.origin[1] + f(1),
            self.origin[2] + f(2),
        ]
    }
}

/// The longest side of the box (1 for a single point), or an error for a box that is not
/// finite.
fn extent(min: [f32; 3], max: [f32; 3]) -> Result<f32, ClusterError> {
    let d = math::sub(max, min);
    if !(d[0] >= 0.0 && d[1] >= 0.0 && d[2] >= 0.0) {
        return Err(ClusterError::InvalidGrid);
    }
    let ext = math::max_abs(d);
    if !ext.is_finite() {
        return Err(ClusterError::InvalidGrid);
    }
    Ok(if ext > 0.0 { ext } else { 1.0 })
}

#[inline]
fn get3(v: [f32; 3], a: usize) -> f32 {
    match a {
        0 => v[0],
        1 => v[1],
        _ => v[2],
    }
}

/// How [`Clusterer::cluster`] chooses the grid.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum GridChoice {
    /// Cells of this edge length.
    CellSize(f32),
    /// The finest grid (cells along the longest side) whose output has at most this many
    /// triangles, found in at most [`ClusterConfig::refine_passes`] extra passes.
    TargetTriangles(usize),
    /// This many cells along the longest side.
    Resolution(u32),
}

/// Settings of [`Clusterer::cluster`].
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ClusterConfig {
    /// The grid.
    pub grid: GridChoice,
    /// The bounding box `(min, max)` if known: saves the first pass.
    pub bbox: Option<([f32; 3], [f32; 3])>,
    /// Counting passes of the search for [`GridChoice::TargetTriangles`], each probing [`PROBES`]
    /// resolutions (meshoptimizer's `simplifySloppy` makes 5 passes of one each).
    pub refine_passes: u32,
    /// Use only the first `table_cells` cells of the table (0: all of it). The output depends
    /// on the table's length (hash slots), so a device and a host with tables of different
    /// sizes give the same bytes when both use the same `table_cells`.
    pub table_cells: usize,
    /// Remove what a renderer shows as defects, after the representatives are chosen: output
    /// triangles of zero area (their three representatives collinear: height below 1e-6 of
    /// the longest edge) and, with the quadric representative, triangles flipped against
    /// their cells' surface (normal opposite the sum of the area-weighted normals of the
    /// input triangles touching their three cells; one more pass, accumulated in the quadric
    /// table, which is free by then). No memory beyond the table.
    pub cleanup: bool,
}

impl ClusterConfig {
    /// Aim for at most `triangles` output triangles.
    pub const fn target(triangles: usize) -> Self {
        ClusterConfig {
            grid: GridChoice::TargetTriangles(triangles),
            bbox: None,
            refine_passes: 2,
            table_cells: 0,
            cleanup: false,
        }
    }
    /// Cells of edge `size`.
    pub const fn cell_size(size: f32) -> Self {
        ClusterConfig {
            grid: GridChoice::CellSize(size),
            bbox: None,
            refine_passes: 0,
            table_cells: 0,
            cleanup: false,
        }
    }
    /// With a known bounding box.
    pub const fn with_bbox(mut self, min: [f32; 3], max: [f32; 3]) -> Self {
        self.bbox = Some((min, max));
        self
    }
    /// With the cleanup of zero-area and flipped triangles ([`ClusterConfig::cleanup`]).
    pub const fn with_cleanup(mut self) -> Self {
        self.cleanup = true;
        self
    }
    /// Using only the first `cells` cells of the table (0: all).
    pub const fn with_table_cells(mut self, cells: usize) -> Self {
        self.table_cells = cells;
        self
    }
}

/// What a clustering run did.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ClusterReport {
    /// Triangles read in the final pass.
    pub triangles_in: usize,
    /// Output triangles (the prefix of the caller's buffer).
    pub triangles_out: usize,
    /// Triangles dropped because two corners fell into one cell.
    pub collapsed: usize,
    /// Triangles dropped as duplicates of an earlier output triangle (any rotation or winding).
    pub duplicates: usize,
    /// Of those, duplicates in the opposite winding.
    pub opposite_duplicates: usize,
    /// Occupied cells.
    pub cells: usize,
    /// The grid used.
    pub grid: Grid,
    /// Passes over the stream (bounding box, search, accumulation, representative choice).
    pub passes: u32,
    /// The target of [`GridChoice::TargetTriangles`] (0: none).
    pub target_triangles: usize,
    /// Output triangles removed by [`ClusterConfig::cleanup`] for zero area.
    pub slivers_removed: usize,
    /// Output triangles removed by [`ClusterConfig::cleanup`] as flipped.
    pub flipped_removed: usize,
}

/// Plane quadrics per cell, for the quadric representative: 40 bytes per cell.
pub struct Quadrics<const CELLS: usize> {
    q: [[f32; 10]; CELLS],
}

impl<const CELLS: usize> Quadrics<CELLS> {
    /// Bytes per cell.
    pub const BYTES_PER_CELL: usize = 40;
    /// Empty (all zero: a `static` goes to `.bss`).
    pub const fn new() -> Self {
        Quadrics {
            q: [[0.0; 10]; CELLS],
        }
    }
}

impl<const CELLS: usize> Default for Quadrics<CELLS> {
    fn default() -> Self {
        Self::new()
    }
}

/// The optional buffers of [`Clusterer::cluster`] and [`cluster_then_collapse`], all empty by
/// default (the table and the output only). Contents on entry do not matter.
///
/// * `quadrics`: the quadric representative (two passes) instead of the nearest to the cell's
///   centre.
/// * `seen`: a bit per input vertex (vertex `v` is bit `v % 32` of word `v / 32`): the quadric
///   representative's second pass scores each vertex once instead of once per corner (about
///   6 times), most of that pass's time. `vertices / 8` bytes (4.5 KB for the bunny's 35 947
///   vertices).
/// * `cache`: 8 bytes per input vertex: each position is read and quantised once for the grid
///   search and the first pass instead of once per corner and pass, and the second pass
///   scores each vertex once (as `seen`). 288 KB for the bunny: a host's or a large device's
///   option.
/// * `keys`: a further 32 bytes per input vertex: each counting pass of the target search
///   computes a vertex's cells at all its probed resolutions once, and counts a triangle with
///   one comparison of its corners' keys (with `cache`, 1.4 MB for the bunny).
/// * `vertices`, `positions`: [`cluster_then_collapse`]'s compacted mesh (4 and 12 bytes per
///   vertex it keeps); unused by [`Clusterer::cluster`].
///
/// Vertices beyond any buffer take the path without it.
pub struct Scratch<'a, const CELLS: usize> {
    /// See the type.
    pub quadrics: Option<&'a mut Quadrics<CELLS>>,
    /// See the type.
    pub seen: &'a mut [u32],
    /// See the type.
    pub cache: &'a mut [u64],
    /// See the type.
    pub keys: &'a mut [[u32; KEY_LANES]],
    /// See the type.
    pub vertices: &'a mut [u32],
    /// See the type.
    pub positions: &'a mut [[f32; 3]],
}

impl<'a, const CELLS: usize> Scratch<'a, CELLS> {
    /// No buffers.
    pub fn new() -> Self {
        Scratch {
            quadrics: None,
            seen: &mut [],
            cache: &mut [],
            keys: &mut [],
            vertices: &mut [],
            positions: &mut [],
        }
    }

    /// With the quadric representative.
    pub fn with_quadrics(mut self, quadrics: &'a mut Quadrics<CELLS>) -> Self {
        self.quadrics = Some(quadrics);
        self
    }
}

impl<const CELLS: usize> Default for Scratch<'_, CELLS> {
    fn default() -> Self {
        Self::new()
    }
}

/// The cell table: a fixed-capacity open-addressing hash table from occupied cells to their
/// representative vertex. 12 bytes per cell ([`Clusterer::BYTES_PER_CELL`]); keep it about
/// 1.3x the occupied cells for short probes (it works up to completely full).
pub struct Clusterer<const CELLS: usize> {
    slots: [Slot; CELLS],
}

/// One cell of the table: 12 bytes, in one place so that a probe touches one cache line.
#[derive(Clone, Copy)]
struct Slot {
    /// Cell key ([`EMPTY`]: free).
    key: u32,
    /// Representative vertex.
    rep: u32,
    /// Its score (squared distance to the centre, or quadric error).
    best: f32,
}

impl<const CELLS: usize> Default for Clusterer<CELLS> {
    fn default() -> Self {
        Self::new()
    }
}

/// One pass: the table, the output hash set and the counts.
struct Pass<'a, I: Index> {
    grid: Grid,
    slots: &'a mut [Slot],
    quad: Option<&'a mut [[f32; 10]]>,
    out: &'a mut [[I; 3]],
    cells: usize,
    stored: usize,
    read: usize,
    collapsed: usize,
    duplicates: usize,
    opposite: usize,
    /// Second pass of the quadric representative: only choose representatives.
    choose: bool,
    /// Failures counted past a full table or buffer (for the `needed_at_least` figures).
    cells_missed: usize,
    out_missed: usize,
    slivers: usize,
    flipped: usize,
    /// The caller's per-vertex cache of quantised coordinates ([`Scratch::cache`]);
    /// empty without.
    cache: &'a mut [u64],
    /// The caller's key entries ([`Scratch::keys`]): lane 6 holds the vertex's
    /// cell on this pass's grid where lane [`STAMP`] is [`FINAL`], and lane 0 the cell's slot
    /// + 1 once it is known (0 before); empty without.
    keys: &'a mut [[u32; KEY_LANES]],
    /// A corner's vertex was beyond the cache (in a pass that reads the cache).
    beyond: bool,
}

/// A cache entry not yet filled (valid entries have bit 63 clear).
const NO_Q: u64 = u64::MAX;
/// In a valid cache entry: the vertex was offered in the choosing pass.
const OFFERED: u64 = 1 << 62;

#[inline]
fn pack_q(q: [u32; 3]) -> u64 {
    u64::from(q[0]) | (u64::from(q[1]) << 20) | (u64::from(q[2]) << 40)
}

#[inline]
fn unpack_q(e: u64) -> [u32; 3] {
    [
        (e & u64::from(QMAX)) as u32,
        ((e >> 20) & u64::from(QMAX)) as u32,
        ((e >> 40) & u64::from(QMAX)) as u32,
    ]
}

/// The quantised coordinates of vertex `v` (a corner of triangle number `index`), from the
/// cache when it has them (then the position was checked when they were stored), else from
/// the checked position, stored in the cache when it has room for `v`.
#[inline]
fn quantised<P: Positions + ?Sized>(
    cache: &mut [u64],
    pos: &mut P,
    grid: &Grid,
    v: u32,
    index: usize,
) -> Result<[u32; 3], ClusterError> {
    match cache.get_mut(v as usize) {
        Some(e) if *e >> 63 == 0 => Ok(unpack_q(*e)),
        Some(e) => {
            let q = grid.quantise(checked_position(pos, v, index)?);
            *e = pack_q(q);
            Ok(q)
        }
        None => Ok(grid.quantise(checked_position(pos, v, index)?)),
    }
}

#[inline]
fn slot_of(h: u32, n: usize) -> usize {
    // Lemire's multiply-shift range reduction: in 0..n for any n, no division.
    ((u64::from(h) * n as u64) >> 32) as usize
}

#[inline]
fn hash_key(k: u32) -> u32 {
    let h = k.wrapping_mul(0x9E37_79B1);
    h ^ (h >> 15)
}

#[inline]
fn sorted3(t: [u32; 3]) -> [u32; 3] {
    let [mut a, mut b, mut c] = t;
    if a > b {
        core::mem::swap(&mut a, &mut b);
    }
    if b > c {
        core::mem::swap(&mut b, &mut c);
    }
    if a > b {
        core::mem::swap(&mut a, &mut b);
    }
    [a, b, c]
}

/// Whether `t` (distinct entries) is `u` read in the same cyclic order.
#[inline]
fn same_winding(t: [u32; 3], u: [u32; 3]) -> bool {
    t == u || t == [u[1], u[2], u[0]] || t == [u[2], u[0], u[1]]
}

impl<I: Index> Pass<'_, I> {
    /// The slot of cell `k`, inserted if new; `None` when the table is full.
    #[inline]
    fn cell(&mut self, k: u32) -> Option<usize> {
        let n = self.slots.len();
        let mut s = slot_of(hash_key(k), n);
        for _ in 0..n {
            match self.slots.get(s).map(|x| x.key) {
                Some(EMPTY) => {
                    if self.choose {
                        return None;
                    }
                    if let Some(x) = self.slots.get_mut(s) {
                        *x = Slot {
                            key: k,
                            rep: EMPTY,
                            best: f32::INFINITY,
                        };
                    }
                    if let Some(q) = self.quad.as_deref_mut().and_then(|q| q.get_mut(s)) {
                        *q = [0.0; 10];
                    }
                    self.cells += 1;
                    return Some(s);
                }
                Some(x) if x == k => return Some(s),
                Some(_) => {}
                None => return None,
            }
            s += 1;
            if s >= n {
                s = 0;
            }
        }
        None
    }

    /// The slot of cell `k` of vertex `v`, as [`Pass::cell`]: from `hint` (slot + 1, from the
    /// vertex's key entry) when not 0; else looked up, and a slot found is stored in the
    /// vertex's key entry (lane 0) for its later corners. A slot never moves once its cell is
    /// in the table, so the hint gives the lookup's answer; a table without room for the cell
    /// stores nothing, and the next corner looks again (and fails again).
    #[inline]
    fn cell_of_vertex(&mut self, k: u32, hint: u32, v: u32) -> Option<usize> {
        if hint != 0 {
            return Some(hint as usize - 1);
        }
        let s = self.cell(k);
        if let (Some(s), Some(e)) = (s, self.keys.get_mut(v as usize)) {
            if let (Ok(h), [h0, .., FINAL]) = (u32::try_from(s + 1), e) {
                *h0 = h;
            }
        }
        s
    }

    /// Offers vertex `v` at `p` as representative of the cell in slot `s`.
    #[inline]
    fn offer(&mut self, s: usize, k: u32, v: u32, p: V3) {
        let score = if let Some(q) = self.quad.as_deref().and_then(|q| q.get(s)) {
            if !self.choose {
                return;
            }
            // NaN as infinity: the choice is the least (score, vertex) in any order of
            // offers (`choose_by_vertex` offers in vertex order).
            let e = quadric_error(q, math::sub(p, self.grid.corner(k)));
            if e.is_nan() {
                f32::INFINITY
            } else {
                e
            }
        } else {
            // Never NaN (finite positions: a square of a difference is finite or infinite).
            let d = math::sub(p, self.grid.centre(k));
            math::dot(d, d)
        };
        if let Some(x) = self.slots.get_mut(s) {
            if score < x.best || (score == x.best && v < x.rep) || x.rep == EMPTY {
                x.best = score;
                x.rep = v;
            }
        }
    }

    fn push<P: Positions>(&mut self, chunk: &[[u32; 3]], pos: &mut P) -> Result<(), ClusterError> {
        for t in chunk {
            let index = self.read;
            self.read += 1;
            // The nearest representative offers every corner's position; the quadric one's
            // first pass needs positions only for the triangles that survive, and takes the
            // cells from the cache when there is one.
            let offers = self.quad.is_none() || self.choose;
            // Each corner's slot + 1 when its key entry has it (0: look the cell up).
            let mut hint = [0u32; 3];
            let (k, mut p) = if offers || self.cache.is_empty() {
                let p = corners(pos, t, index)?;
                let k = [
                    self.grid.key(p[0]),
                    self.grid.key(p[1]),
                    self.grid.key(p[2]),
                ];
                (k, Some(p))
            } else {
                let mut k = [0u32; 3];
                let top = t[0].max(t[1]).max(t[2]);
                self.beyond |= top as usize >= self.cache.len();
                if self.keys.is_empty() {
                    for (kc, &v) in k.iter_mut().zip(t) {
                        *kc = self
                            .grid
                            .key_q(quantised(self.cache, pos, &self.grid, v, index)?);
                    }
                } else {
                    for ((kc, hc), &v) in k.iter_mut().zip(&mut hint).zip(t) {
                        let e = self.keys.get_mut(v as usize);
                        match e {
                            Some(&mut [h, .., key, FINAL]) => (*kc, *hc) = (key, h),
                            e => {
                                *kc = self
                                    .grid
                                    .key_q(quantised(self.cache, pos, &self.grid, v, index)?);
                                if let Some(e) = e {
                                    *e = [0, 0, 0, 0, 0, 0, *kc, FINAL];
                                }
                            }
                        }
                    }
                }
                (k, None)
            };
            // A corner in the same cell as an earlier corner has that corner's slot (the
            // lookup would give the same answer, found or not).
            let s0 = self.cell_of_vertex(k[0], hint[0], t[0]);
            let s1 = if k[1] == k[0] {
                s0
            } else {
                self.cell_of_vertex(k[1], hint[1], t[1])
            };
            let s2 = if k[2] == k[0] {
                s0
            } else if k[2] == k[1] {
                s1
            } else {
                self.cell_of_vertex(k[2], hint[2], t[2])
            };
            // The quadric representative is chosen in the second pass only.
            if let (true, Some(p)) = (offers, &p) {
                for (((sc, &kc), &v), &pc) in [s0, s1, s2].iter().zip(&k).zip(t).zip(p) {
                    if let Some(slot) = *sc {
                        self.offer(slot, kc, v, pc);
                    }
                }
            }
            let (Some(s0), Some(s1), Some(s2)) = (s0, s1, s2) else {
                if !self.choose {
                    self.cells_missed += 1;
                }
                continue;
            };
            let s = [s0, s1, s2];
            if k[0] == k[1] || k[1] == k[2] || k[0] == k[2] {
                self.collapsed += 1;
                continue;
            }
            if self.choose {
                continue;
            }
            if let Some(q) = self.quad.as_deref_mut() {
                let p = match p.take() {
                    Some(p) => p,
                    None => corners(pos, t, index)?,
                };
                add_plane(q, &self.grid, s, k, p);
            }
            self.emit([s[0] as u32, s[1] as u32, s[2] as u32]);
        }
        Ok(())
    }

    /// Adds the cell triangle `t` to the output set unless it is there already.
    #[inline]
    fn emit(&mut self, t: [u32; 3]) {
        let n = self.out.len();
        let st = sorted3(t);
        let h = st[0]
            .wrapping_mul(0x9E37_79B1)
            .wrapping_add(st[1].wrapping_mul(0x85EB_CA77))
            .wrapping_add(st[2].wrapping_mul(0xC2B2_AE3D));
        let mut s = slot_of(h ^ (h >> 16), n);
        for _ in 0..n {
            let Some(e) = self.out.get_mut(s) else { break };
            if e[0] == I::NIL {
                *e = [
                    I::narrow(t[0] as usize),
                    I::narrow(t[1] as usize),
                    I::narrow(t[2] as usize),
                ];
                self.stored += 1;
                return;
            }
            let u = [
                e[0].to_usize() as u32,
                e[1].to_usize() as u32,
                e[2].to_usize() as u32,
            ];
            if sorted3(u) == st {
                self.duplicates += 1;
                if !same_winding(t, u) {
                    self.opposite += 1;
                }
                return;
            }
            s += 1;
            if s >= n {
                s = 0;
            }
        }
        self.out_missed += 1;
    }

    fn check_full(&self, total: Option<usize>) -> Result<(), ClusterError> {
        let extrapolate = |have: usize, missed: usize| -> usize {
            // Failures show up per triangle; scale what was seen by the share of the stream
            // read before the first failure is unknown, so scale by the whole stream.
            let at_least = have + 1;
            match total {
                Some(t) if self.read > 0 && missed > 0 => {
                    let e = (have as u64 + missed as u64).min(have as u64 * 2 + 1);
                    let e = e.max(have as u64 * t as u64 / self.read as u64);
                    (e as usize).max(at_least)
                }
                _ => at_least,
            }
        };
        if self.cells_missed > 0 {
            return Err(ClusterError::TableFull {
                capacity: self.slots.len(),
                needed_at_least: self.cells + 1,
                estimate: extrapolate(self.cells, self.cells_missed),
            });
        }
        if self.out_missed > 0 {
            return Err(ClusterError::OutputFull {
                capacity: self.out.len(),
                needed_at_least: self.stored + 1,
                estimate: extrapolate(self.stored, self.out_missed),
            });
        }
        Ok(())
    }

    /// Compacts the output set to a prefix and replaces cell slots by `map(slot)`.
    fn finish(&mut self, mut map: impl FnMut(usize) -> Option<u32>) -> Result<usize, ClusterError> {
        let mut w = 0usize;
        for r in 0..self.out.len() {
            let Some(e) = self.out.get(r).copied() else {
                break;
            };
            if e[0] == I::NIL {
                continue;
            }
            let mut t = [I::ZERO; 3];
            for (d, s) in t.iter_mut().zip(e) {
                let v = map(s.to_usize()).unwrap_or(EMPTY);
                *d = I::from_usize(v as usize)
                    .ok_or(ClusterError::VertexTooWide { vertex: v as usize })?;
            }
            if let Some(d) = self.out.get_mut(w) {
                *d = t;
            }
            w += 1;
        }
        Ok(w)
    }
}

/// The cleanup's extra pass: the sum of the area-weighted normals of the input triangles
/// touching each cell, in the first three floats of the cell's quadric (no longer needed once
/// the representatives are chosen).
fn cell_normals<S: Source, I: Index>(
    pass: &mut Pass<'_, I>,
    source: &mut S,
) -> Result<(), ClusterError> {
    if let Some(q) = pass.quad.as_deref_mut() {
        for e in q.iter_mut() {
            *e = [0.0; 10];
        }
    }
    pass.choose = true;
    let mut buf = [[0u32; 3]; CHUNK];
    let mut index = 0usize;
    loop {
        let n = source.read(&mut buf);
        let Some(chunk) = buf.get(..n) else { break };
        if chunk.is_empty() {
            break;
        }
        for t in chunk {
            let p = corners(&mut SourcePositions(&mut *source), t, index)?;
            index += 1;
            let nrm = math::cross(math::sub(p[1], p[0]), math::sub(p[2], p[0]));
            let mut last = [usize::MAX; 3];
            for (c, &pc) in p.iter().enumerate() {
                let k = pass.grid.key(pc);
                let Some(s) = pass.cell(k) else { continue };
                if last.contains(&s) {
                    continue;
                }
                if let Some(l) = last.get_mut(c) {
                    *l = s;
                }
                if let Some(e) = pass.quad.as_deref_mut().and_then(|q| q.get_mut(s)) {
                    e[0] += nrm[0];
                    e[1] += nrm[1];
                    e[2] += nrm[2];
                }
            }
        }
    }
    Ok(())
}

impl<I: Index> Pass<'_, I> {
    /// Removes zero-area output triangles and (with cell normals in the quadric table)
    /// flipped ones, before [`Pass::finish`] compacts the output.
    fn cleanup<S: Source>(&mut self, source: &mut S) {
        for e in self.out.iter_mut() {
            if e[0] == I::NIL {
                continue;
            }
            let s = [e[0].to_usize(), e[1].to_usize(), e[2].to_usize()];
            let mut p = [[0.0f32; 3]; 3];
            let mut ok = true;
            for (pp, &sc) in p.iter_mut().zip(&s) {
                match self
                    .slots
                    .get(sc)
                    .and_then(|x| source.position(x.rep as usize))
                {
                    Some(v) => *pp = v,
                    None => ok = false,
                }
            }
            if !ok {
                continue;
            }
            // In cell units (representatives lie a few cells apart), so that the products
            // below neither overflow nor underflow for coordinates near the f32 limits.
            let inv = 1.0 / self.grid.cell;
            let scaled = |v: V3| [v[0] * inv, v[1] * inv, v[2] * inv];
            let a = scaled(math::sub(p[1], p[0]));
            let b = scaled(math::sub(p[2], p[0]));
            let c = scaled(math::sub(p[2], p[1]));
            let nrm = math::cross(a, b);
            let l2 = math::dot(nrm, nrm);
            let emax = math::dot(a, a).max(math::dot(b, b)).max(math::dot(c, c));
            if !(l2.is_finite() && emax.is_finite()) {
                continue;
            }
            // |n| = 2 area = longest edge x height: height <= 1e-6 longest edge.
            if l2 <= 4e-12 * emax * emax {
                *e = [I::NIL; 3];
                self.slivers += 1;
                continue;
            }
            if let Some(q) = self.quad.as_deref() {
                let mut sum = [0.0f32; 3];
                for &sc in &s {
                    if let Some(x) = q.get(sc) {
                        sum = [sum[0] + x[0], sum[1] + x[1], sum[2] + x[2]];
                    }
                }
                if math::dot(nrm, sum) < 0.0 {
                    *e = [I::NIL; 3];
                    self.flipped += 1;
                }
            }
        }
    }
}

/// Adds the area-weighted plane of the triangle `p` to the quadrics of its three cells
/// (coordinates relative to each cell's corner, for precision).
#[inline]
fn add_plane(q: &mut [[f32; 10]], grid: &Grid, s: [usize; 3], k: [u32; 3], p: [V3; 3]) {
    let n = math::cross(math::sub(p[1], p[0]), math::sub(p[2], p[0]));
    let l2 = math::dot(n, n);
    if !(l2 > math::TINY2 && l2.is_finite()) {
        return;
    }
    // n nᵀ / |n| = area-weighted unit-normal quadric (times 2).
    let w = math::rsqrt(l2);
    for j in 0..3 {
        let (Some(&sj), Some(&kj)) = (s.get(j), k.get(j)) else {
            continue;
        };
        let o = grid.corner(kj);
        let d = -math::dot(n, math::sub(p[0], o));
        if let Some(e) = q.get_mut(sj) {
            for (x, y) in e.iter_mut().zip(crate::policy::cost::outer(n, d)) {
                *x += y * w;
            }
        }
    }
}

/// `pᵀ A p + 2 bᵀ p + c` of a plane quadric at `p`.
#[inline]
fn quadric_error(q: &[f32; 10], p: V3) -> f32 {
    let [x, y, z] = p;
    q[0] * x * x
        + 2.0 * q[1] * x * y
        + 2.0 * q[2] * x * z
        + 2.0 * q[3] * x
        + q[4] * y * y
        + 2.0 * q[5] * y * z
        + 2.0 * q[6] * y
        + q[7] * z * z
        + 2.0 * q[8] * z
        + q[9]
}

/// A single-pass clustering of a stream that may be read only once (a UART, a radio), with a
/// grid fixed in advance and the nearest-to-centre representative. From
/// [`Clusterer::stream`]: [`Stream::push`] the chunks, then [`Stream::finish`].
pub struct Stream<'a, I: Index> {
    pass: Pass<'a, I>,
}

impl<I: Index> Stream<'_, I> {
    /// Clusters the next chunk of triangles; positions through `positions`. A full table or
    /// output buffer is reported by [`Stream::finish`] (the rest of the stream is still counted,
    /// so its error says how much is missing); bad input at once.
    pub fn push<P: Positions>(
        &mut self,
        chunk: &[[u32; 3]],
        positions: &mut P,
    ) -> Result<(), ClusterError> {
        self.pass.push(chunk, positions)
    }

    /// Writes the output triangles (input vertex numbers) to the prefix of the buffer.
    pub fn finish(mut self) -> Result<ClusterReport, ClusterError> {
        self.pass.check_full(None)?;
        finish_report(&mut self.pass, 1, 0)
    }
}

fn finish_report<I: Index>(
    pass: &mut Pass<'_, I>,
    passes: u32,
    target: usize,
) -> Result<ClusterReport, ClusterError> {
    let slots = core::mem::take(&mut pass.slots);
    let out = pass.finish(|s| slots.get(s).map(|x| x.rep));
    pass.slots = slots;
    let triangles_out = out?;
    Ok(ClusterReport {
        triangles_in: pass.read,
        triangles_out,
        collapsed: pass.collapsed,
        duplicates: pass.duplicates,
        opposite_duplicates: pass.opposite,
        cells: pass.cells,
        grid: pass.grid,
        passes,
        target_triangles: target,
        slivers_removed: pass.slivers,
        flipped_removed: pass.flipped,
    })
}

/// Like [`finish_report`], but numbers the output vertices 0, 1, ... in order of first use and
/// writes each one's input vertex number to `vertices`; returns the report and the count.
fn finish_compact<I: Index>(
    pass: &mut Pass<'_, I>,
    passes: u32,
    target: usize,
    vertices: &mut [u32],
) -> Result<(ClusterReport, usize), ClusterError> {
    // The keys are no longer needed: they become the slot -> new number map.
    let slots = core::mem::take(&mut pass.slots);
    slots.iter_mut().for_each(|x| x.key = EMPTY);
    let mut nv = 0usize;
    let mut full = false;
    let out = pass.finish(|s| {
        let x = slots.get_mut(s)?;
        if x.key == EMPTY {
            let Some(slot) = vertices.get_mut(nv) else {
                full = true;
                return Some(0);
            };
            *slot = x.rep;
            x.key = nv as u32;
            nv += 1;
        }
        Some(x.key)
    });
    if full {
        return Err(ClusterError::VerticesFull {
            capacity: vertices.len(),
        });
    }
    let triangles_out = out?;
    Ok((
        ClusterReport {
            triangles_in: pass.read,
            triangles_out,
            collapsed: pass.collapsed,
            duplicates: pass.duplicates,
            opposite_duplicates: pass.opposite,
            cells: pass.cells,
            grid: pass.grid,
            passes,
            target_triangles: target,
            slivers_removed: pass.slivers,
            flipped_removed: pass.flipped,
        },
        nv,
    ))
}

impl<const CELLS: usize> Clusterer<CELLS> {
    /// Bytes per cell of the table (key, representative, its score).
    pub const BYTES_PER_CELL: usize = 12;
    /// Size in bytes.
    pub const BYTES: usize = core::mem::size_of::<Self>();

    /// An empty table (`const`, so it can be a `static`).
    pub const fn new() -> Self {
        Clusterer {
            slots: [Slot {
                key: 0,
                rep: 0,
                best: 0.0,
            }; CELLS],
        }
    }

    fn pass<'a, I: Index>(
        &'a mut self,
        grid: Grid,
        quad: Option<&'a mut [[f32; 10]]>,
        out: &'a mut [[I; 3]],
        active: usize,
    ) -> Result<Pass<'a, I>, ClusterError> {
        // Only the first `active` cells take part (fewer cache lines for a small output, or
        // the caller's `table_cells`).
        let active = if active > 0 && active < CELLS {
            active
        } else {
            CELLS
        };
        if active > I::COUNT || active > u32::MAX as usize - 1 {
            return Err(ClusterError::TableTooWide {
                cells: active,
                index_count: I::COUNT,
            });
        }
        let slots = self.slots.get_mut(..active).unwrap_or(&mut []);
        slots.iter_mut().for_each(|x| x.key = EMPTY);
        for e in out.iter_mut() {
            *e = [I::NIL; 3];
        }
        Ok(Pass {
            grid,
            slots,
            quad,
            out,
            cells: 0,
            stored: 0,
            read: 0,
            collapsed: 0,
            duplicates: 0,
            opposite: 0,
            choose: false,
            cells_missed: 0,
            out_missed: 0,
            slivers: 0,
            flipped: 0,
            cache: &mut [],
            keys: &mut [],
            beyond: false,
        })
    }

    /// Starts a single pass over a stream that may be read only once, on a fixed grid, with
    /// the nearest-to-centre representative. `out` receives the output triangles.
    pub fn stream<'a, I: Index>(
        &'a mut self,
        grid: Grid,
        out: &'a mut [[I; 3]],
    ) -> Result<Stream<'a, I>, ClusterError> {
        Ok(Stream {
            pass: self.pass(grid, None, out, CELLS)?,
        })
    }

    /// Clusters a re-readable `source` into `out`, in passes: the bounding box (unless given),
    /// the grid search (for a target count), then one pass (nearest representative) or two
    /// (`scratch.quadrics`: accumulate, then choose). On success the first `triangles_out`
    /// entries of `out` hold the result, in input vertex numbers. The optional buffers of
    /// `scratch` only make it faster (see [`Scratch`]); the output is the same.
    pub fn cluster<S: Source, I: Index>(
        &mut self,
        source: &mut S,
        config: &ClusterConfig,
        out: &mut [[I; 3]],
        scratch: Scratch<'_, CELLS>,
    ) -> Result<ClusterReport, ClusterError> {
        let Scratch {
            quadrics,
            seen,
            cache,
            keys,
            ..
        } = scratch;
        self.cluster_into(source, quadrics, config, out, None, seen, cache, keys)
            .map(|(r, _)| r)
    }

    /// Like [`Clusterer::cluster`], but the output triangles use new vertex numbers 0, 1, ...
    /// (in order of first use) and `vertices[i]` receives the input number of new vertex `i`:
    /// a compact mesh for the collapse engine. Returns the report and the number of vertices.
    /// [`ClusterError::VerticesFull`] if `vertices` is too short.
    fn cluster_compact<S: Source, I: Index>(
        &mut self,
        source: &mut S,
        quadrics: Option<&mut Quadrics<CELLS>>,
        config: &ClusterConfig,
        out: &mut [[I; 3]],
        vertices: &mut [u32],
    ) -> Result<(ClusterReport, usize), ClusterError> {
        self.cluster_into(
            source,
            quadrics,
            config,
            out,
            Some(vertices),
            &mut [],
            &mut [],
            &mut [],
        )
    }

    #[allow(clippy::too_many_arguments)]
    fn cluster_into<S: Source, I: Index>(
        &mut self,
        source: &mut S,
        quadrics: Option<&mut Quadrics<CELLS>>,
        config: &ClusterConfig,
        out: &mut [[I; 3]],
        vertices: Option<&mut [u32]>,
        seen: &mut [u32],
        cache: &mut [u64],
        keys: &mut [[u32; KEY_LANES]],
    ) -> Result<(ClusterReport, usize), ClusterError> {
        // Quantised coordinates depend only on the bounding box, the same for every grid of
        // this run: the cache is filled once (from the first counting or clustering pass).
        for e in cache.iter_mut() {
            *e = NO_Q;
        }
        // No key entry is valid for any counting pass (stamps start at 1).
        for k in keys.iter_mut() {
            *k = [0; KEY_LANES];
        }
        for w in seen.iter_mut() {
            *w = 0;
        }
        let mut passes = 0u32;
        let (min, max, top) = match config.bbox {
            Some(b) => (b.0, b.1, None),
            None => {
                passes += 1;
                let (lo, hi, top) = bbox(source, seen, cache)?;
                (lo, hi, Some(top))
            }
        };
        let mut target = 0;
        let grid = match config.grid {
            GridChoice::CellSize(c) => Grid::with_cell_size(min, max, c)?,
            GridChoice::Resolution(n) => Grid::with_resolution(min, max, n)?,
            GridChoice::TargetTriangles(t) => {
                target = t;
                let (g, p) =
                    Self::search(source, min, max, t, config.refine_passes, cache, keys, top)?;
                passes += p;
                g
            }
        };
        if passes > 0 && !source.rewind() {
            return Err(ClusterError::NotRereadable);
        }
        let mut quad = quadrics.map(|q| &mut q.q[..]);
        let mut vertices = vertices;
        // A target bounds the output (the counts bound it from above) and, loosely, the cells:
        // use a prefix of the table and of the buffer, and all of them if that fills.
        let (mut ac, mut ao) = if target > 0 {
            (
                target.saturating_mul(2).saturating_add(64),
                target.saturating_add(target / 4).saturating_add(16),
            )
        } else {
            (usize::MAX, out.len())
        };
        let out_len = out.len();
        let cells = if config.table_cells > 0 {
            config.table_cells.min(CELLS)
        } else {
            CELLS
        };
        loop {
            if passes > 0 && !source.rewind() {
                return Err(ClusterError::NotRereadable);
            }
            let (ac_now, ao_now) = (ac.min(cells), ao.min(out_len));
            let o = out.get_mut(..ao_now).unwrap_or(&mut []);
            let mut pass = self.pass(grid, quad.as_deref_mut(), o, ac_now)?;
            pass.cache = &mut *cache;
            if !keys.is_empty() {
                final_keys(&grid, pass.cache, keys);
                pass.keys = &mut *keys;
            }
            let total = run(&mut pass, source)?;
            passes += 1;
            let small_table = pass.cells_missed > 0 && ac_now < cells;
            let small_out = pass.out_missed > 0 && ao_now < out_len;
            if small_table || small_out {
                (ac, ao) = (cells, usize::MAX);
                continue;
            }
            pass.check_full(Some(total))?;
            if pass.quad.is_some() {
                if !source.rewind() {
                    return Err(ClusterError::NotRereadable);
                }
                pass.choose = true;
                if !pass.cache.is_empty() && !pass.beyond {
                    // Every vertex used is in the cache: no stream needed.
                    choose_by_vertex(&mut pass, source)?;
                } else if seen.is_empty() && pass.cache.is_empty() {
                    pass.read = 0;
                    run(&mut pass, source)?;
                    // `collapsed` was counted twice.
                    pass.collapsed /= 2;
                } else {
                    pass.read = 0;
                    choose_once(&mut pass, source, seen)?;
                }
                passes += 1;
            }
            if config.cleanup {
                if pass.quad.is_some() {
                    if !source.rewind() {
                        return Err(ClusterError::NotRereadable);
                    }
                    cell_normals(&mut pass, source)?;
                    passes += 1;
                }
                pass.cleanup(source);
            }
            return match vertices.as_deref_mut() {
                Some(v) => finish_compact(&mut pass, passes, target, v),
                None => finish_report(&mut pass, passes, target).map(|r| (r, 0)),
            };
        }
    }

    /// Search for the finest resolution (cells along the longest side) whose output fits
    /// `target`, in the spirit of meshoptimizer's `simplifySloppy` (an estimate, then passes
    /// that narrow a bracket), but each counting pass probes [`PROBES`] resolutions at once: the
    /// first around the estimate, the next ones evenly inside the bracket. A
    /// probe counts the triangles whose corners fall into three distinct cells, which needs no
    /// memory and bounds the deduplicated output from above, so the result never exceeds the
    /// target.
    #[allow(clippy::too_many_arguments)]
    fn search<S: Source>(
        source: &mut S,
        min: [f32; 3],
        max: [f32; 3],
        target: usize,
        passes: u32,
        cache: &mut [u64],
        keys: &mut [[u32; KEY_LANES]],
        top: Option<u32>,
    ) -> Result<(Grid, u32), ClusterError> {
        // Estimate: about target/2 occupied cells, and a surface filling its box occupies
        // about 3 n² cells at n cells along the longest side (integer square root: no float
        // library).
        let est = isqrt(target / 6).clamp(1, MAX_RESOLUTION);
        let (mut lo, mut hi) = (0u32, MAX_RESOLUTION + 1);
        let mut done = 0;
        for pass in 0..passes.max(1) {
            if hi - lo <= 1 {
                break;
            }
            let mut n = [0u32; PROBES];
            if pass == 0 {
                // 0.5, 0.75, 1, 1.44, 2.1 and 3 times the estimate (ratio about 1.43).
                for (slot, m) in n.iter_mut().zip([8u32, 12, 16, 23, 34, 48]) {
                    *slot = (est.saturating_mul(m) / 16).clamp(1, MAX_RESOLUTION);
                }
            } else if hi > MAX_RESOLUTION {
                // Open above: steps of 3/2 (at least 1) from the bracket's bottom.
                let mut x = u64::from(lo.max(1));
                for slot in n.iter_mut() {
                    x = (x * 3).div_ceil(2).max(x + 1);
                    *slot = x.min(u64::from(MAX_RESOLUTION)) as u32;
                }
            } else if lo == 0 {
                // Open below: steps of 2/3 (at least 1) from the top.
                let mut x = u64::from(hi);
                for slot in n.iter_mut() {
                    x = (x * 2 / 3).min(x.saturating_sub(1));
                    *slot = x.max(1) as u32;
                }
            } else {
                let span = u64::from(hi - lo);
                for (i, slot) in n.iter_mut().enumerate() {
                    let f = span * (i as u64 + 1) / (PROBES as u64 + 1);
                    *slot = (lo + f as u32).clamp(1, MAX_RESOLUTION);
                }
            }
            let mut grids = [None; PROBES];
            for (g, &r) in grids.iter_mut().zip(&n) {
                if r > lo && r < hi {
                    *g = Some(Grid::with_resolution(min, max, r)?);
                }
            }
            let counts = count(source, &grids, cache, keys, pass + 1, top)?;
            done += 1;
            for ((g, &r), &c) in grids.iter().zip(&n).zip(&counts) {
                if g.is_none() {
                    continue;
                }
                if c <= target {
                    if r > lo {
                        lo = r;
                    }
                } else if r < hi {
                    hi = r;
                }
            }
        }
        Ok((Grid::with_resolution(min, max, lo.max(1))?, done))
    }
}

/// Resolutions probed per counting pass of the target search.
pub const PROBES: usize = 6;

/// Lanes of a per-vertex key entry of [`Scratch::keys`]: the cells of the
/// [`PROBES`] resolutions of a counting pass, padded to 8 (32 bytes, two SIMD registers).
pub const KEY_LANES: usize = 8;
/// The lane of a key entry that holds the number of the counting pass it was computed for.
const STAMP: usize = KEY_LANES - 1;
/// The stamp of an entry computed for the final grid (counting passes are 1, 2, ...).
const FINAL: u32 = u32::MAX;

/// Before the accumulating pass: each vertex with quantised coordinates in the cache gets
/// its cell on the final `grid` in its key entry (the others are computed at their first
/// corner). Clears the stamps of the rest.
fn final_keys(grid: &Grid, cache: &[u64], keys: &mut [[u32; KEY_LANES]]) {
    for (v, k) in keys.iter_mut().enumerate() {
        *k = match cache.get(v) {
            Some(&e) if e >> 63 == 0 => [0, 0, 0, 0, 0, 0, grid.key_q(unpack_q(e)), FINAL],
            _ => [0; KEY_LANES],
        };
    }
}

/// The cells of quantised coordinates `q` at the resolutions `ns` (lane `i`: `ns[i]` cells
/// along the longest side; 0 gives cell 0).
#[inline]
fn probe_keys(q: [u32; 3], ns: &[u32; KEY_LANES]) -> [u32; KEY_LANES] {
    let mut k = [0u32; KEY_LANES];
    for (kc, &m) in k.iter_mut().zip(ns) {
        // Cells are below 1024 (q <= QMAX, n <= 1024): the packed keys are exact.
        *kc = (q[0].wrapping_mul(m) >> QBITS)
            | ((q[1].wrapping_mul(m) >> QBITS) << 10)
            | ((q[2].wrapping_mul(m) >> QBITS) << 20);
    }
    k
}

/// One counting pass: for each grid, the triangles whose corners fall into distinct cells.
///
/// With `keys`, each vertex's cells at all probed resolutions are computed once per pass and
/// vertex, before the stream is read, from the quantised coordinates in the cache (filled
/// from the position for a vertex the bounding-box pass marked), so a triangle costs three
/// 32-byte loads and one branch-free comparison of 8 lanes. Lane [`STAMP`] says for which
/// pass an entry was computed (`stamp`, from 1; entries are cleared to 0 first). A vertex
/// without a current entry (beyond the memory, or not yet quantised) takes the per-corner
/// path, which stores its entry for the rest of the pass: the same counts either way.
fn count<S: Source>(
    source: &mut S,
    grids: &[Option<Grid>; PROBES],
    cache: &mut [u64],
    keys: &mut [[u32; KEY_LANES]],
    stamp: u32,
    top: Option<u32>,
) -> Result<[usize; PROBES], ClusterError> {
    if !source.rewind() {
        return Err(ClusterError::NotRereadable);
    }
    if keys.is_empty() {
        return count_corners(source, grids, cache);
    }
    let mut counts = [0usize; PROBES];
    // Every probe shares the origin and scale (the same box): quantise once per corner with
    // the first grid, then each probe's cells are `(q · n) >> 20` in integers. A probe that
    // is not run has n = 0 (all its corners in cell 0: counts nothing; not reported anyway).
    let g0 = grids.iter().flatten().next().copied();
    let mut ns = [0u32; KEY_LANES];
    for (m, g) in ns.iter_mut().zip(grids) {
        *m = g.map_or(0, |g| g.n);
    }
    let entry = |q: [u32; 3]| {
        let mut k = probe_keys(q, &ns);
        if let Some(s) = k.get_mut(STAMP) {
            *s = stamp;
        }
        k
    };
    // Every vertex used has a current entry once the loop below has run: the bounding-box
    // pass saw every corner (`top`: the largest vertex number) and marked every vertex in
    // the cache. Then a triangle needs no stamp check (for a source that reads back the same
    // triangles, as every pass assumes).
    let mut complete = top.is_some_and(|t| (t as usize) < cache.len().min(keys.len()));
    if let Some(g0) = &g0 {
        for (v, (e, k)) in cache.iter_mut().zip(keys.iter_mut()).enumerate() {
            if *e == NO_Q - 1 {
                // Marked by the bounding-box pass, which checked its position. A source
                // that now answers otherwise is left to the per-corner path (the same
                // error, in stream order).
                match source.position(v) {
                    Some(p) if p[0].is_finite() && p[1].is_finite() && p[2].is_finite() => {
                        *e = pack_q(g0.quantise(p));
                    }
                    _ => {
                        complete = false;
                        continue;
                    }
                }
            }
            if *e >> 63 == 0 {
                *k = entry(unpack_q(*e));
            }
        }
    }
    let mut buf = [[0u32; 3]; CHUNK];
    let mut index = 0usize;
    loop {
        let n = source.read(&mut buf);
        let Some(chunk) = buf.get(..n) else { break };
        if chunk.is_empty() {
            break;
        }
        let mut lane = [0u32; KEY_LANES];
        for t in chunk {
            let Some(g0) = &g0 else {
                corners(&mut SourcePositions(&mut *source), t, index)?;
                index += 1;
                continue;
            };
            if complete {
                if let (Some(a), Some(b), Some(c)) = (
                    keys.get(t[0] as usize),
                    keys.get(t[1] as usize),
                    keys.get(t[2] as usize),
                ) {
                    for (((l, x), y), z) in lane.iter_mut().zip(a).zip(b).zip(c) {
                        *l += u32::from((x != y) & (y != z) & (x != z));
                    }
                    index += 1;
                    continue;
                }
            }
            let current = |keys: &[[u32; KEY_LANES]], v: u32| {
                keys.get(v as usize)
                    .filter(|k| k.get(STAMP) == Some(&stamp))
                    .copied()
            };
            let k = match (
                current(keys, t[0]),
                current(keys, t[1]),
                current(keys, t[2]),
            ) {
                (Some(a), Some(b), Some(c)) => [a, b, c],
                _ => {
                    let mut k = [[0u32; KEY_LANES]; 3];
                    for (kc, &v) in k.iter_mut().zip(t) {
                        if let Some(e) = current(keys, v) {
                            *kc = e;
                            continue;
                        }
                        let mut pos = SourcePositions(&mut *source);
                        let q = quantised(cache, &mut pos, g0, v, index)?;
                        *kc = entry(q);
                        if let Some(e) = keys.get_mut(v as usize) {
                            *e = *kc;
                        }
                    }
                    k
                }
            };
            index += 1;
            let [a, b, c] = k;
            for i in 0..KEY_LANES {
                let (x, y, z) = (a[i], b[i], c[i]);
                lane[i] += u32::from((x != y) & (y != z) & (x != z));
            }
        }
        for (cnt, l) in counts.iter_mut().zip(lane) {
            *cnt += l as usize;
        }
    }
    Ok(counts)
}

/// [`count`] without key entries: each corner quantised (or read from the cache) and its
/// cells at every probed resolution computed at the corner.
fn count_corners<S: Source>(
    source: &mut S,
    grids: &[Option<Grid>; PROBES],
    cache: &mut [u64],
) -> Result<[usize; PROBES], ClusterError> {
    let mut counts = [0usize; PROBES];
    // Every probe shares the origin and scale (the same box): quantise once per corner with
    // the first grid, then each probe's cells are `(q · n) >> 20` in integers. A probe that
    // is not run has n = 0 (all its corners in cell 0: counts nothing; not reported anyway).
    let g0 = grids.iter().flatten().next().copied();
    let mut ns = [0u32; PROBES];
    for (m, g) in ns.iter_mut().zip(grids) {
        *m = g.map_or(0, |g| g.n);
    }
    let mut buf = [[0u32; 3]; CHUNK];
    let mut index = 0usize;
    loop {
        let n = source.read(&mut buf);
        let Some(chunk) = buf.get(..n) else { break };
        if chunk.is_empty() {
            break;
        }
        for t in chunk {
            let Some(g0) = &g0 else {
                corners(&mut SourcePositions(&mut *source), t, index)?;
                index += 1;
                continue;
            };
            let mut pos = SourcePositions(&mut *source);
            let a = quantised(cache, &mut pos, g0, t[0], index)?;
            let b = quantised(cache, &mut pos, g0, t[1], index)?;
            let c = quantised(cache, &mut pos, g0, t[2], index)?;
            index += 1;
            for (cnt, &m) in counts.iter_mut().zip(&ns) {
                // Cells are below 1024 (q <= QMAX, n <= 1024): the packed keys are exact.
                let key = |q: [u32; 3]| {
                    (q[0].wrapping_mul(m) >> QBITS)
                        | ((q[1].wrapping_mul(m) >> QBITS) << 10)
                        | ((q[2].wrapping_mul(m) >> QBITS) << 20)
                };
                let (ka, kb, kc) = (key(a), key(b), key(c));
                *cnt += usize::from((ka != kb) & (kb != kc) & (ka != kc));
            }
        }
    }
    Ok(counts)
}

/// The three corners' positions of triangle number `index`, checked.
#[inline]
fn corners<P: Positions + ?Sized>(
    pos: &mut P,
    t: &[u32; 3],
    index: usize,
) -> Result<[V3; 3], ClusterError> {
    Ok([
        checked_position(pos, t[0], index)?,
        checked_position(pos, t[1], index)?,
        checked_position(pos, t[2], index)?,
    ])
}

/// The position of vertex `v` (a corner of triangle number `index`), checked.
#[inline]
fn checked_position<P: Positions + ?Sized>(
    pos: &mut P,
    v: u32,
    index: usize,
) -> Result<V3, ClusterError> {
    let p = pos
        .position(v as usize)
        .ok_or(ClusterError::IndexOutOfRange {
            triangle: index,
            index: v as usize,
        })?;
    if !(p[0].is_finite() && p[1].is_finite() && p[2].is_finite()) {
        return Err(ClusterError::NonFinitePosition { vertex: v as usize });
    }
    Ok(p)
}

/// Why [`cluster_then_collapse`] failed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ThenCollapseError {
    /// The clustering step failed.
    Cluster(ClusterError),
    /// The collapse step failed.
    Collapse(crate::Error),
}

impl core::fmt::Display for ThenCollapseError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            ThenCollapseError::Cluster(e) => write!(f, "clustering: {e}"),
            ThenCollapseError::Collapse(e) => write!(f, "collapse: {e}"),
        }
    }
}

/// Cluster, then collapse: clusters `source` down to what fits `storage` (at most its
/// triangle capacity, `out.len()` and twice `scratch.vertices.len()` and
/// `scratch.positions.len()` triangles; the grid is searched as for
/// [`GridChoice::TargetTriangles`] unless `cluster_config` fixes it), copies the surviving
/// vertices' positions into `scratch.positions` (RAM: 12 bytes per vertex), then runs the
/// collapse engine with `config` (give it an absolute target with
/// [`Config::with_target_triangles`](crate::Config::with_target_triangles)). On success the
/// first `collapse.triangles_out` entries of `out` hold the result **in input vertex
/// numbers**. A small device thus gets collapse quality from a mesh it could never hold.
pub fn cluster_then_collapse<S: Source, I: Index, L: Index, const CELLS: usize>(
    table: &mut Clusterer<CELLS>,
    source: &mut S,
    cluster_config: &ClusterConfig,
    config: &crate::Config,
    out: &mut [[I; 3]],
    mut storage: crate::Storage<'_, L>,
    scratch: Scratch<'_, CELLS>,
) -> Result<(ClusterReport, crate::Report), ThenCollapseError> {
    let Scratch {
        quadrics,
        vertices,
        positions,
        ..
    } = scratch;
    let mut cc = *cluster_config;
    let (cap_v, cap_t) = storage.capacity();
    if let GridChoice::TargetTriangles(t) = cc.grid {
        let fit = cap_t
            .min(out.len())
            .min(vertices.len().saturating_mul(2))
            .min(positions.len().saturating_mul(2))
            .min(cap_v.saturating_mul(2));
        cc.grid = GridChoice::TargetTriangles(t.min(fit));
    }
    let nv_cap = vertices.len().min(positions.len());
    let vbuf = vertices.get_mut(..nv_cap).unwrap_or(&mut []);
    let (cr, nv) = table
        .cluster_compact(source, quadrics, &cc, out, vbuf)
        .map_err(ThenCollapseError::Cluster)?;
    let (Some(vs), Some(ps), Some(tris)) = (
        vertices.get(..nv),
        positions.get_mut(..nv),
        out.get_mut(..cr.triangles_out),
    ) else {
        return Err(ThenCollapseError::Cluster(ClusterError::VerticesFull {
            capacity: nv_cap,
        }));
    };
    for (p, &v) in ps.iter_mut().zip(vs) {
        *p = source
            .position(v as usize)
            .ok_or(ThenCollapseError::Cluster(ClusterError::IndexOutOfRange {
                triangle: 0,
                index: v as usize,
            }))?;
    }
    let report = storage
        .simplify(ps, tris, config)
        .map_err(ThenCollapseError::Collapse)?;
    let done = tris.get_mut(..report.triangles_out).unwrap_or(&mut []);
    for t in done.iter_mut() {
        for i in t.iter_mut() {
            let v = vs.get(i.to_usize()).copied().unwrap_or(u32::MAX);
            *i = I::from_usize(v as usize).ok_or(ThenCollapseError::Cluster(
                ClusterError::VertexTooWide { vertex: v as usize },
            ))?;
        }
    }
    Ok((cr, report))
}

/// Runs one pass over the source; returns the triangles read.
fn run<S: Source, I: Index>(pass: &mut Pass<'_, I>, source: &mut S) -> Result<usize, ClusterError> {
    let mut buf = [[0u32; 3]; CHUNK];
    let mut total = 0usize;
    loop {
        let n = source.read(&mut buf);
        let Some(chunk) = buf.get(..n) else { break };
        if chunk.is_empty() {
            break;
        }
        total += n;
        let mut acc = SourcePositions(source);
        pass.push(chunk, &mut acc)?;
    }
    Ok(total)
}

/// The quadric representative's second pass with a bit per vertex: each vertex is offered
/// to its cell once, at its first corner in the stream (a later offer of the same vertex
/// has the same score and never changes the cell's choice, so the result is the same as
/// offering at every corner). Vertices beyond `seen` are offered at every corner.
fn choose_once<S: Source, I: Index>(
    pass: &mut Pass<'_, I>,
    source: &mut S,
    seen: &mut [u32],
) -> Result<(), ClusterError> {
    for w in seen.iter_mut() {
        *w = 0;
    }
    let grid = pass.grid;
    let mut buf = [[0u32; 3]; CHUNK];
    loop {
        let n = source.read(&mut buf);
        let Some(chunk) = buf.get(..n) else { break };
        if chunk.is_empty() {
            break;
        }
        for t in chunk {
            let index = pass.read;
            pass.read += 1;
            for &v in t {
                if let Some(e) = pass.cache.get_mut(v as usize) {
                    // Filled by the first pass (else: fill it now).
                    if *e >> 63 != 0 {
                        let p = checked_position(&mut SourcePositions(&mut *source), v, index)?;
                        *e = pack_q(grid.quantise(p));
                    }
                    if *e & OFFERED != 0 {
                        continue;
                    }
                    *e |= OFFERED;
                } else if let Some(w) = seen.get_mut((v >> 5) as usize) {
                    let bit = 1u32 << (v & 31);
                    if *w & bit != 0 {
                        continue;
                    }
                    *w |= bit;
                }
                let p = checked_position(&mut SourcePositions(&mut *source), v, index)?;
                let k = pass.grid.key(p);
                if let Some(slot) = pass.cell(k) {
                    pass.offer(slot, k, v, p);
                }
            }
        }
    }
    Ok(())
}

/// The quadric representative's second pass when the cache holds every vertex used (the
/// first pass met none beyond it): each vertex with quantised coordinates is offered once,
/// in vertex order, without reading the stream. The choice (least score, then least vertex
/// number) does not depend on the order of the offers.
fn choose_by_vertex<S: Source, I: Index>(
    pass: &mut Pass<'_, I>,
    source: &mut S,
) -> Result<(), ClusterError> {
    let grid = pass.grid;
    for v in 0..pass.cache.len() {
        let Some(&e) = pass.cache.get(v) else { break };
        if e >> 63 != 0 {
            continue;
        }
        let (k, hint) = match pass.keys.get(v) {
            Some(&[h, .., key, FINAL]) => (key, h),
            _ => (grid.key_q(unpack_q(e)), 0),
        };
        // Checked in an earlier pass already (the vertex was quantised).
        let p = checked_position(&mut SourcePositions(&mut *source), to_u32(v), 0)?;
        if let Some(slot) = pass.cell_of_vertex(k, hint, to_u32(v)) {
            pass.offer(slot, k, to_u32(v), p);
        }
    }
    Ok(())
}

struct SourcePositions<'s, S>(&'s mut S);

impl<S: Source> Positions for SourcePositions<'_, S> {
    #[inline]
    fn position(&mut self, vertex: usize) -> Option<[f32; 3]> {
        self.0.position(vertex)
    }
}

/// Bounding box of the used vertices and, with per-vertex memory, the largest vertex number
/// (0 without: then there is no memory for `count` to rely on).
/// With per-vertex memory (a cache entry still [`NO_Q`], then marked `NO_Q - 1`, which is
/// still unfilled for [`quantised`]; or a clear bit, then set), only each vertex's first
/// corner is read: the same box, and the same first error.
fn bbox<S: Source>(
    source: &mut S,
    seen: &mut [u32],
    cache: &mut [u64],
) -> Result<([f32; 3], [f32; 3], u32), ClusterError> {
    if !source.rewind() {
        return Err(ClusterError::NotRereadable);
    }
    let mut buf = [[0u32; 3]; CHUNK];
    let mut min = [f32::INFINITY; 3];
    let mut max = [f32::NEG_INFINITY; 3];
    let mut index = 0usize;
    let mut top = 0u32;
    let memory = !(cache.is_empty() && seen.is_empty());
    loop {
        let n = source.read(&mut buf);
        let Some(chunk) = buf.get(..n) else { break };
        if chunk.is_empty() {
            break;
        }
        for t in chunk {
            for &v in t {
                if !memory {
                    // No per-vertex memory: every corner (and `top` is not needed).
                } else if let Some(e) = cache.get_mut(v as usize) {
                    top = top.max(v);
                    if *e != NO_Q {
                        continue;
                    }
                    *e = NO_Q - 1;
                } else {
                    // Beyond the cache: `top` says so.
                    top = top.max(v);
                    if let Some(w) = seen.get_mut((v >> 5) as usize) {
                        let bit = 1u32 << (v & 31);
                        if *w & bit != 0 {
                            continue;
                        }
                        *w |= bit;
                    }
                }
                let p = source
                    .position(v as usize)
                    .ok_or(ClusterError::IndexOutOfRange {
                        triangle: index,
                        index: v as usize,
                    })?;
                for a in 0..3 {
                    let x = get3(p, a);
                    if !x.is_finite() {
                        return Err(ClusterError::NonFinitePosition { vertex: v as usize });
                    }
                    if let (Some(lo), Some(hi)) = (min.get_mut(a), max.get_mut(a)) {
                        if x < *lo {
                            *lo = x;
                        }
                        if x > *hi {
                            *hi = x;
                        }
                    }
                }
            }
            index += 1;
        }
    }
    if index == 0 {
        return Err(ClusterError::EmptyInput);
    }
    Ok((min, max, top))
}

/// Integer square root (floor), by Newton's method on integers.
fn isqrt(n: usize) -> u32 {
    if n < 2 {
        return n as u32;
    }
    let mut x = n;
    let mut y = x.div_ceil(2);
    while y < x {
        x = y;
        // `checked_div`: x >= 1 here, but no division-by-zero path may link.
        y = (x + n.checked_div(x).unwrap_or(n)) / 2;
    }
    x.min(u32::MAX as usize) as u32
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn integer_square_root() {
        for n in 0..10_000usize {
            let r = isqrt(n) as usize;
            assert!(r * r <= n && (r + 1) * (r + 1) > n, "{n}");
        }
    }

    #[test]
    fn keys_floor_and_clamp() -> Result<(), ClusterError> {
        let g = Grid::with_cell_size([0.0; 3], [10.0; 3], 1.0)?;
        assert_eq!((g.n, g.dims), (10, [10; 3]));
        assert_eq!(g.key([0.5, 1.5, 2.5]), (2 << 20) | (1 << 10));
        assert_eq!(g.key([-5.0, 99.0, 10.0]), (9 << 20) | (9 << 10));
        let g = Grid::with_resolution([0.0; 3], [1.0, 2.0, 0.0], 8)?;
        assert_eq!(g.dims, [5, 8, 1]);
        let g = Grid::with_cell_size([0.0; 3], [1.0, 2.0, 0.0], 0.3)?;
        assert_eq!(g.n, 7);
        Ok(())
    }

    #[test]
    fn bad_grid() {
        assert_eq!(
            Grid::with_cell_size([0.0; 3], [1.0; 3], 0.0),
            Err(ClusterError::InvalidGrid)
        );
        assert_eq!(
            Grid::with_cell_size([0.0; 3], [1.0; 3], 1e-4),
            Err(ClusterError::InvalidGrid)
        );
        assert_eq!(
            Grid::with_resolution([0.0; 3], [f32::INFINITY; 3], 4),
            Err(ClusterError::InvalidGrid)
        );
    }
}
