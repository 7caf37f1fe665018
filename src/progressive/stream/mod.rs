//! The progressive transmission stream: a base mesh, then vertex splits with the positions of
//! their new vertices, in checksummed chunks, decoded incrementally as bytes arrive.
//!
//! Why (Lin 2007 §1-2): a small screen at the end of a slow link must show something at once
//! and refine as bytes arrive. The splits are those of [`Progressive`](crate::Progressive) (Cheng, Pan and Shi 1998
//! §2.1-2.2); a split names its corners by their places in the kept vertex's list, so its
//! connectivity costs a few bits per neighbour, and it is only applied once its whole chunk has
//! arrived and its checksum matches, so a bad stream never leaves a broken mesh behind.
//!
//! # Format (version 1, little-endian)
//! Header, 56 bytes:
//!
//! | offset | field |
//! |---:|---|
//! | 0 | magic `TDPM` |
//! | 4 | version, `1` |
//! | 5 | index width in bytes the decoder needs (2: all vertex numbers fit `u16`; else 4) |
//! | 6 | flags: bit 0, positions quantised to 16 bits per coordinate over the bounding box |
//! | 7 | 0 |
//! | 8 | vertices of the full mesh (u32) |
//! | 12 | vertices of the base mesh `m₀` (u32) |
//! | 16 | triangles of the base mesh (u32) |
//! | 20 | triangles of the full mesh (u32) |
//! | 24 | largest chunk payload in bytes (u16), then 2 bytes 0 |
//! | 28 | bounding box: min x, y, z, max x, y, z (6 × f32) |
//! | 52 | CRC-32 (IEEE) of bytes 0..52 |
//!
//! Then chunks: `len` (u16, payload bytes), `kind` (u8), `count` (u16, items), the payload,
//! and the CRC-32 of all of that. Kinds, in this order: 1 base positions, 2 base triangles,
//! 3 vertex splits. Payloads are bit-packed, least significant bit first; `bits(n)` is the
//! width of a number below `n`.
//! - **Position**: 3 × f32, or 3 × 16-bit `q` with `p = min·(1 − f) + max·f`, `f = q/65535`.
//! - **Base triangle**: 3 vertex numbers, `bits(m₀)` each.
//! - **Vertex split** creating vertex `t = m₀ + j`: a mode bit, the kept vertex `s`
//!   (`bits(t)`), restored triangles − 1 (1 bit); `L` is the length of `s`'s list, known to
//!   the decoder (at most 64).
//!   - *Mode 0, fan run* (Cheng, Pan and Shi 1998 §2.2's `vsplit(s, l, r)`: the removed
//!     vertex's fan sits between its two wings): the first restored triangle's slot of `s`
//!     (2 bits) and whether `t` follows `s` in it (1 bit); the place among `s`'s triangles of
//!     the one across edge `s-w₁` (`bits(L)`; it runs the edge the other way, which names
//!     `w₁`); the number `k` of
//!     triangles that move (`bits(L + 1)`), found by walking around `s` from `s-w₁`; for a
//!     second restored triangle, its slot of `s` (2 bits): its `w₂` is where the walk ended
//!     and its winding is the first one's reversed.
//!   - *Mode 1, explicit* (whatever mode 0 cannot say): the moved mask (`L` bits, one per
//!     triangle of `s`'s list), then per restored triangle the slot of `s`, whether `t`
//!     follows `s`, and `w`: a 0 bit and the place, among the triangles staying with `s`, of
//!     the one across edge `s-w` (`bits(staying)`), or a 1 bit and `w` itself (`bits(t)`).
//!
//!   Then `t`'s position.

mod bits;
mod decode;
mod encode;
mod header;
mod split;

pub use decode::Decoder;
pub use encode::{encode, Encoded};
pub use header::Header;

/// Header length in bytes.
pub const HEADER: usize = 56;
/// Chunk header (`len`, `kind`, `count`) plus checksum: bytes around each payload.
pub const CHUNK_OVERHEAD: usize = 9;
/// The smallest chunk payload [`encode`] writes with: an upper bound on one record (a vertex
/// split in explicit mode with 32-bit vertex numbers and an f32 position is at most 34 bytes).
/// A smaller `max_payload` would let a record overflow its chunk.
pub const MIN_PAYLOAD: u16 = 48;
pub(super) const MAGIC: [u8; 4] = *b"TDPM";
pub(super) const VERSION: u8 = 1;
pub(super) const KIND_POSITIONS: u8 = 1;
pub(super) const KIND_TRIANGLES: u8 = 2;
pub(super) const KIND_SPLITS: u8 = 3;

/// What is wrong with a stream, or with the storage given to decode it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum StreamError {
    /// Not a tinydecimate progressive stream.
    BadMagic,
    /// A version this decoder does not read.
    BadVersion(u8),
    /// The header's or a chunk's checksum does not match (chunk `0` is the header).
    Checksum {
        /// 0 for the header, then chunks counted from 1.
        chunk: u32,
    },
    /// A count in the header exceeds the decoder's storage.
    Capacity {
        /// Which storage (`"vertices"`, `"triangles"`, `"splits"`, `"chunk buffer"`).
        what: &'static str,
        /// Needed.
        needed: usize,
        /// Given.
        available: usize,
    },
    /// The header's counts contradict each other.
    BadHeader,
    /// A chunk of the wrong kind or count at this point, or whose payload ends early.
    BadChunk {
        /// Chunks counted from 1.
        chunk: u32,
    },
    /// A vertex split refers to a vertex that does not exist yet, or does not fit the kept
    /// vertex's current fan.
    BadSplit {
        /// The split (its new vertex is `m₀ + split`).
        split: usize,
    },
    /// Bytes after the last chunk.
    TrailingData,
    /// The stream ended before the full mesh ([`Decoder::finish`]).
    Truncated,
    /// The encoder's output buffer is too small.
    OutputFull,
}

impl core::fmt::Display for StreamError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            StreamError::BadMagic => write!(f, "not a progressive mesh stream (bad magic)"),
            StreamError::BadVersion(v) => write!(f, "stream version {v} is not supported"),
            StreamError::Checksum { chunk: 0 } => write!(f, "header checksum mismatch"),
            StreamError::Checksum { chunk } => write!(f, "chunk {chunk}: checksum mismatch"),
            StreamError::Capacity {
                what,
                needed,
                available,
            } => write!(
                f,
                "{what}: stream needs {needed}, storage holds {available}"
            ),
            StreamError::BadHeader => write!(f, "header counts are inconsistent"),
            StreamError::BadChunk { chunk } => write!(f, "chunk {chunk} is malformed"),
            StreamError::BadSplit { split } => {
                write!(f, "vertex split {split} does not fit the mesh")
            }
            StreamError::TrailingData => write!(f, "bytes after the end of the stream"),
            StreamError::Truncated => write!(f, "stream ends before the full mesh"),
            StreamError::OutputFull => write!(f, "output buffer too small"),
        }
    }
}

/// CRC-32 (IEEE 802.3, reflected), bit by bit: no table in flash.
pub fn crc32(bytes: &[u8]) -> u32 {
    let mut c = !0u32;
    for &b in bytes {
        c ^= b as u32;
        for _ in 0..8 {
            c = (c >> 1) ^ (0xEDB8_8320 & (c & 1).wrapping_neg());
        }
    }
    !c
}
