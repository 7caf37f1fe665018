//! The quadric representative: each cell's plane quadric, then the vertex of the cell with the
//! least error.

use super::grid::Grid;
use super::pass::{pack_q, unpack_q, Pass, OFFERED};
use super::search::FINAL;
use super::source::{checked_position, SourcePositions};
use super::{to_u32, ClusterError, Source, CHUNK};
use crate::index::Index;
use crate::math::{self, V3};
use crate::quadric;

/// Adds the area-weighted plane of the triangle `p` to the quadrics of its three cells
/// (coordinates relative to each cell's corner, for precision).
#[inline]
pub(super) fn add_plane(q: &mut [[f32; 10]], grid: &Grid, s: [usize; 3], k: [u32; 3], p: [V3; 3]) {
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
            for (x, y) in e.iter_mut().zip(quadric::outer(n, d)) {
                *x += y * w;
            }
        }
    }
}

/// The quadric representative's second pass with a bit per vertex: each vertex is offered
/// to its cell once, at its first corner in the stream (a later offer of the same vertex
/// has the same score and never changes the cell's choice, so the result is the same as
/// offering at every corner). Vertices beyond `seen` are offered at every corner.
pub(super) fn choose_once<S: Source, I: Index>(
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
pub(super) fn choose_by_vertex<S: Source, I: Index>(
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
