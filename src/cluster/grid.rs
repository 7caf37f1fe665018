//! The uniform grid of cubic cells, and the bounding-box pass that fits it.

use super::cache::{pack_q, unpack_q, NO_Q, QBITS, QMAX};
use super::source::{checked_position, PositionSource};
use super::{ClusterError, Source, CHUNK, MAX_RESOLUTION};
use crate::math::{self, V3};

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
    pub(super) scale: f32,
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
    pub(super) fn quantise(&self, p: V3) -> [u32; 3] {
        // `as` saturates (NaN and t <= 0 to 0, t >= 2^32 to u32::MAX) and truncates, which
        // is floor for t > 0; then the clamp to QMAX.
        let q = |a: usize| (((get3(p, a) - get3(self.origin, a)) * self.scale) as u32).min(QMAX);
        [q(0), q(1), q(2)]
    }

    #[inline]
    pub(super) fn cell_of(&self, q: u32) -> u32 {
        (q.min(QMAX) * self.n) >> QBITS
    }

    /// The key of the cell of quantised coordinates `q`.
    #[inline]
    pub(super) fn key_q(&self, q: [u32; 3]) -> u32 {
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
    pub(super) fn centre(&self, k: u32) -> V3 {
        let c = self.corner(k);
        let h = 0.5 * self.cell;
        [c[0] + h, c[1] + h, c[2] + h]
    }

    /// Minimum corner of the cell with key `k`.
    #[inline]
    pub(super) fn corner(&self, k: u32) -> V3 {
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
pub(super) fn extent(min: [f32; 3], max: [f32; 3]) -> Result<f32, ClusterError> {
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
pub(super) fn get3(v: [f32; 3], a: usize) -> f32 {
    match a {
        0 => v[0],
        1 => v[1],
        _ => v[2],
    }
}

/// Bounding box of the used vertices and, with per-vertex memory, the largest vertex number
/// (0 without: then there is no memory for `count` to rely on).
/// With per-vertex memory (a cache entry still [`NO_Q`], then marked `NO_Q - 1`, which is
/// still unfilled for [`quantised`]; or a clear bit, then set), only each vertex's first
/// corner is read: the same box, and the same first error.
pub(super) fn bbox<S: Source>(
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

/// The quantised coordinates of vertex `v` (a corner of triangle number `index`), from the
/// cache when it has them (then the position was checked when they were stored), else from
/// the checked position, stored in the cache when it has room for `v`.
#[inline]
pub(super) fn quantised<P: PositionSource + ?Sized>(
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
