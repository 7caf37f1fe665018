//! [`ClusterConfig::cleanup`](super::ClusterConfig::cleanup): output triangles of zero area or
//! flipped against their cells' surface are removed.

use super::pass::Pass;
use super::source::{corners, SourcePositions};
use super::{ClusterError, Source, CHUNK};
use crate::index::Index;
use crate::math::{self, V3};

/// The cleanup's extra pass: the sum of the area-weighted normals of the input triangles
/// touching each cell, in the first three floats of the cell's quadric (no longer needed once
/// the representatives are chosen).
pub(super) fn cell_normals<S: Source, I: Index>(
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
    pub(super) fn cleanup<S: Source>(&mut self, source: &mut S) {
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
