//! One clustering pass over the stream: cells in the hash table, representatives offered,
//! output triangles gathered (deduplicated) in the caller's buffer; and its report.

use super::cache::{FINAL, KEY_LANES};
use super::grid::{quantised, Grid};
use super::source::{corners, PositionSource, SourcePositions};
use super::{ClusterError, ClusterReport, Slot, Source, CHUNK, EMPTY};
use crate::index::Index;
use crate::math::{self, V3};
use crate::quadric;

/// One pass: the table, the output hash set and the counts.
pub(super) struct Pass<'a, I: Index> {
    pub(super) grid: Grid,
    pub(super) slots: &'a mut [Slot],
    pub(super) quad: Option<&'a mut [[f32; 10]]>,
    pub(super) out: &'a mut [[I; 3]],
    pub(super) cells: usize,
    pub(super) stored: usize,
    pub(super) read: usize,
    pub(super) collapsed: usize,
    pub(super) duplicates: usize,
    pub(super) opposite: usize,
    /// Second pass of the quadric representative: only choose representatives.
    pub(super) choose: bool,
    /// Failures counted past a full table or buffer (for the `needed_at_least` figures).
    pub(super) cells_missed: usize,
    pub(super) out_missed: usize,
    pub(super) slivers: usize,
    pub(super) flipped: usize,
    /// The caller's per-vertex cache of quantised coordinates ([`Scratch::cache`]);
    /// empty without.
    pub(super) cache: &'a mut [u64],
    /// The caller's key entries ([`Scratch::keys`](super::Scratch::keys)): lane 6 holds the vertex's
    /// cell on this pass's grid where lane [`STAMP`] is [`FINAL`], and lane 0 the cell's slot
    /// + 1 once it is known (0 before); empty without.
    pub(super) keys: &'a mut [[u32; KEY_LANES]],
    /// A corner's vertex was beyond the cache (in a pass that reads the cache).
    pub(super) beyond: bool,
}

#[inline]
pub(super) fn slot_of(h: u32, n: usize) -> usize {
    // Lemire's multiply-shift range reduction: in 0..n for any n, no division.
    ((u64::from(h) * n as u64) >> 32) as usize
}

#[inline]
pub(super) fn hash_key(k: u32) -> u32 {
    let h = k.wrapping_mul(0x9E37_79B1);
    h ^ (h >> 15)
}

#[inline]
pub(super) fn sorted3(t: [u32; 3]) -> [u32; 3] {
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
pub(super) fn same_winding(t: [u32; 3], u: [u32; 3]) -> bool {
    t == u || t == [u[1], u[2], u[0]] || t == [u[2], u[0], u[1]]
}

impl<I: Index> Pass<'_, I> {
    /// The slot of cell `k`, inserted if new; `None` when the table is full.
    #[inline]
    pub(super) fn cell(&mut self, k: u32) -> Option<usize> {
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
    pub(super) fn cell_of_vertex(&mut self, k: u32, hint: u32, v: u32) -> Option<usize> {
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
    pub(super) fn offer(&mut self, s: usize, k: u32, v: u32, p: V3) {
        let score = if let Some(q) = self.quad.as_deref().and_then(|q| q.get(s)) {
            if !self.choose {
                return;
            }
            // NaN as infinity: the choice is the least (score, vertex) in any order of
            // offers (`choose_by_vertex` offers in vertex order).
            let e = quadric::form_by_terms(q, math::sub(p, self.grid.corner(k)));
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

    pub(super) fn push<P: PositionSource>(
        &mut self,
        chunk: &[[u32; 3]],
        pos: &mut P,
    ) -> Result<(), ClusterError> {
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
    pub(super) fn emit(&mut self, t: [u32; 3]) {
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

    pub(super) fn check_full(&self, total: Option<usize>) -> Result<(), ClusterError> {
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
    pub(super) fn finish(
        &mut self,
        mut map: impl FnMut(usize) -> Option<u32>,
    ) -> Result<usize, ClusterError> {
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

/// A single-pass clustering of a stream that may be read only once (a UART, a radio), with a
/// grid fixed in advance and the nearest-to-centre representative. From
/// [`Clusterer::stream`](super::Clusterer::stream): [`Stream::push`] the chunks, then [`Stream::finish`].
pub struct Stream<'a, I: Index> {
    pub(super) pass: Pass<'a, I>,
}

impl<I: Index> Stream<'_, I> {
    /// Clusters the next chunk of triangles; positions through `positions`. A full table or
    /// output buffer is reported by [`Stream::finish`] (the rest of the stream is still counted,
    /// so its error says how much is missing); bad input at once.
    pub fn push<P: PositionSource>(
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

pub(super) fn finish_report<I: Index>(
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
pub(super) fn finish_compact<I: Index>(
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

/// Runs one pass over the source; returns the triangles read.
pub(super) fn run<S: Source, I: Index>(
    pass: &mut Pass<'_, I>,
    source: &mut S,
) -> Result<usize, ClusterError> {
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
