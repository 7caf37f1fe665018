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

mod cache;
mod choose;
mod cleanup;
mod grid;
mod pass;
mod search;
mod source;
mod then_collapse;

use cache::NO_Q;
use choose::{choose_by_vertex, choose_once};
use cleanup::cell_normals;
use grid::bbox;
use pass::{finish_compact, finish_report, run, Pass};
use search::final_keys;

pub use cache::KEY_LANES;
pub use grid::Grid;
pub use pass::Stream;
pub use source::{PositionFn, PositionSource, SliceSource, Source};
pub use then_collapse::{cluster_then_collapse, ThenCollapseError};

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

#[inline]
fn to_u32(v: usize) -> u32 {
    u32::try_from(v).unwrap_or(u32::MAX)
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
    /// Counting passes of the search for [`GridChoice::TargetTriangles`], each probing six
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
pub(super) struct Slot {
    /// Cell key ([`EMPTY`]: free).
    pub(super) key: u32,
    /// Representative vertex.
    pub(super) rep: u32,
    /// Its score (squared distance to the centre, or quadric error).
    pub(super) best: f32,
}

impl<const CELLS: usize> Default for Clusterer<CELLS> {
    fn default() -> Self {
        Self::new()
    }
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
        self.cluster_into(source, config, out, scratch, None)
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
        let scratch = Scratch {
            quadrics,
            ..Scratch::new()
        };
        self.cluster_into(source, config, out, scratch, Some(vertices))
    }

    /// [`Clusterer::cluster`], with the compacted vertex numbers written to `vertices` if
    /// given (then the second value is their count).
    fn cluster_into<S: Source, I: Index>(
        &mut self,
        source: &mut S,
        config: &ClusterConfig,
        out: &mut [[I; 3]],
        scratch: Scratch<'_, CELLS>,
        mut vertices: Option<&mut [u32]>,
    ) -> Result<(ClusterReport, usize), ClusterError> {
        let Scratch {
            quadrics,
            seen,
            cache,
            keys,
            ..
        } = scratch;
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
        let (grid, target, mut passes) = Self::choose_grid(source, config, seen, cache, keys)?;
        let mut quad = quadrics.map(|q| &mut q.q[..]);
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
            passes += after_first_pass(&mut pass, source, config, seen)?;
            return match vertices.as_deref_mut() {
                Some(v) => finish_compact(&mut pass, passes, target, v),
                None => finish_report(&mut pass, passes, target).map(|r| (r, 0)),
            };
        }
    }

    /// The grid of a run: the bounding box (read from `source` unless the configuration gives
    /// it), then the grid the configuration names or the search for its target. Returns the
    /// grid, the target (0: none) and the passes read so far; `source` is rewound if any was.
    fn choose_grid<S: Source>(
        source: &mut S,
        config: &ClusterConfig,
        seen: &mut [u32],
        cache: &mut [u64],
        keys: &mut [[u32; KEY_LANES]],
    ) -> Result<(Grid, usize, u32), ClusterError> {
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
        Ok((grid, target, passes))
    }
}

/// The passes after the first of a run: choosing the quadric representatives (with
/// [`Quadrics`]), then the cleanup (if configured). Returns how many passes read the stream.
fn after_first_pass<S: Source, I: Index>(
    pass: &mut Pass<'_, I>,
    source: &mut S,
    config: &ClusterConfig,
    seen: &mut [u32],
) -> Result<u32, ClusterError> {
    let mut passes = 0;
    if pass.quad.is_some() {
        if !source.rewind() {
            return Err(ClusterError::NotRereadable);
        }
        pass.choose = true;
        if !pass.cache.is_empty() && !pass.beyond {
            // Every vertex used is in the cache: no stream needed.
            choose_by_vertex(pass, source)?;
        } else if seen.is_empty() && pass.cache.is_empty() {
            pass.read = 0;
            run(pass, source)?;
            // `collapsed` was counted twice.
            pass.collapsed /= 2;
        } else {
            pass.read = 0;
            choose_once(pass, source, seen)?;
        }
        passes += 1;
    }
    if config.cleanup {
        if pass.quad.is_some() {
            if !source.rewind() {
                return Err(ClusterError::NotRereadable);
            }
            cell_normals(pass, source)?;
            passes += 1;
        }
        pass.cleanup(source);
    }
    Ok(passes)
}

#[cfg(test)]
mod tests {
    use super::search::isqrt;
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
