//! The grid search for a target triangle count: counting passes that probe several resolutions
//! at once.

use super::cache::{pack_q, unpack_q, FINAL, KEY_LANES, NO_Q, QBITS, STAMP};
use super::grid::{quantised, Grid};
use super::source::{corners, SourcePositions};
use super::{ClusterError, Clusterer, Source, CHUNK, MAX_RESOLUTION};

/// Resolutions probed per counting pass of the target search.
pub(crate) const PROBES: usize = 6;

/// Before the accumulating pass: each vertex with quantised coordinates in the cache gets
/// its cell on the final `grid` in its key entry (the others are computed at their first
/// corner). Clears the stamps of the rest.
pub(super) fn final_keys(grid: &Grid, cache: &[u64], keys: &mut [[u32; KEY_LANES]]) {
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
pub(super) fn probe_keys(q: [u32; 3], ns: &[u32; KEY_LANES]) -> [u32; KEY_LANES] {
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
pub(super) fn count<S: Source>(
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
        if !key_cached(source, g0, cache, keys, &entry) {
            complete = false;
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
            let k = corner_keys(source, g0, cache, keys, *t, index, stamp, &entry)?;
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

/// [`count`]'s key entries of every vertex the bounding-box pass marked in the cache, before
/// the stream is read; `false` if a source now answers otherwise for one of them.
fn key_cached<S: Source>(
    source: &mut S,
    g0: &Grid,
    cache: &mut [u64],
    keys: &mut [[u32; KEY_LANES]],
    entry: &impl Fn([u32; 3]) -> [u32; KEY_LANES],
) -> bool {
    let mut complete = true;
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
    complete
}

/// The key entries of triangle `t`'s corners for counting pass `stamp`: the current ones, and
/// for a corner without one, computed from its (cached or read) position and stored.
#[allow(clippy::too_many_arguments)]
fn corner_keys<S: Source>(
    source: &mut S,
    g0: &Grid,
    cache: &mut [u64],
    keys: &mut [[u32; KEY_LANES]],
    t: [u32; 3],
    index: usize,
    stamp: u32,
    entry: &impl Fn([u32; 3]) -> [u32; KEY_LANES],
) -> Result<[[u32; KEY_LANES]; 3], ClusterError> {
    let current = |keys: &[[u32; KEY_LANES]], v: u32| {
        keys.get(v as usize)
            .filter(|k| k.get(STAMP) == Some(&stamp))
            .copied()
    };
    Ok(
        match (
            current(keys, t[0]),
            current(keys, t[1]),
            current(keys, t[2]),
        ) {
            (Some(a), Some(b), Some(c)) => [a, b, c],
            _ => {
                let mut k = [[0u32; KEY_LANES]; 3];
                for (kc, &v) in k.iter_mut().zip(&t) {
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
        },
    )
}

/// [`count`] without key entries: each corner quantised (or read from the cache) and its
/// cells at every probed resolution computed at the corner.
pub(super) fn count_corners<S: Source>(
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

/// Integer square root (floor), by Newton's method on integers.
pub(super) fn isqrt(n: usize) -> u32 {
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

impl<const CELLS: usize> Clusterer<CELLS> {
    /// Search for the finest resolution (cells along the longest side) whose output fits
    /// `target`, in the spirit of meshoptimizer's `simplifySloppy` (an estimate, then passes
    /// that narrow a bracket), but each counting pass probes [`PROBES`] resolutions at once: the
    /// first around the estimate, the next ones evenly inside the bracket. A
    /// probe counts the triangles whose corners fall into three distinct cells, which needs no
    /// memory and bounds the deduplicated output from above, so the result never exceeds the
    /// target.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn search<S: Source>(
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
