//! The per-vertex memory of a clustering run: a cache entry holds a vertex's position in
//! fixed point inside the box (three 20-bit coordinates packed in a `u64`), and a key entry
//! the vertex's cells on the grids of a counting pass. Every other file of the clustering
//! reads these formats; this one reads none of them.

/// Fixed-point bits of a position inside the box (per axis, along the longest side).
pub(super) const QBITS: u32 = 20;

/// The largest coordinate of a cache entry.
pub(super) const QMAX: u32 = (1 << QBITS) - 1;

/// A cache entry not yet filled (valid entries have bit 63 clear).
pub(super) const NO_Q: u64 = u64::MAX;

/// In a valid cache entry: the vertex was offered in the choosing pass.
pub(super) const OFFERED: u64 = 1 << 62;

/// A cache entry of quantised coordinates `q`.
#[inline]
pub(super) fn pack_q(q: [u32; 3]) -> u64 {
    u64::from(q[0]) | (u64::from(q[1]) << 20) | (u64::from(q[2]) << 40)
}

/// The quantised coordinates of a valid cache entry.
#[inline]
pub(super) fn unpack_q(e: u64) -> [u32; 3] {
    [
        (e & u64::from(QMAX)) as u32,
        ((e >> 20) & u64::from(QMAX)) as u32,
        ((e >> 40) & u64::from(QMAX)) as u32,
    ]
}

/// Lanes of a per-vertex key entry of [`Scratch::keys`](super::Scratch::keys): the cells of the
/// six resolutions probed by a counting pass, padded to 8 (32 bytes, two SIMD registers).
pub const KEY_LANES: usize = 8;

/// The lane of a key entry that holds the number of the counting pass it was computed for.
pub(super) const STAMP: usize = KEY_LANES - 1;

/// The stamp of an entry computed for the final grid (counting passes are 1, 2, ...).
pub(super) const FINAL: u32 = u32::MAX;
