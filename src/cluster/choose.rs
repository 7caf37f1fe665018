//! The quadric representative's choice: the vertex of each cell with the least error under
//! the cell's plane quadric (accumulated by the pass, `pass::add_plane`).

use super::cache::{pack_q, unpack_q, FINAL, OFFERED};
use super::pass::Pass;
use super::source::{checked_position, SourcePositions};
use super::{to_u32, ClusterError, Source, CHUNK};
use crate::index::Index;

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
