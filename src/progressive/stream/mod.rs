//! The progressive transmission stream: a base mesh, then vertex splits with the positions of
//! their new vertices, in checksummed chunks, decoded incrementally as bytes arrive.
//!
//! Why (Lin 2007 §1-2): a small screen at the end of a slow link must show something at once
//! and refine as bytes arrive. The splits are those of [`Progressive`] (Cheng, Pan and Shi 1998
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

use crate::index::Index;
use crate::progressive::{Progressive, Split, Storage};

/// Header length in bytes.
pub const HEADER: usize = 56;
/// Chunk header (`len`, `kind`, `count`) plus checksum: bytes around each payload.
pub const CHUNK_OVERHEAD: usize = 9;
/// The smallest chunk payload [`encode`] writes with: an upper bound on one record (a vertex
/// split in explicit mode with 32-bit vertex numbers and an f32 position is at most 34 bytes).
/// A smaller `max_payload` would let a record overflow its chunk.
pub const MIN_PAYLOAD: u16 = 48;
const MAGIC: [u8; 4] = *b"TDPM";
const VERSION: u8 = 1;
const KIND_POSITIONS: u8 = 1;
const KIND_TRIANGLES: u8 = 2;
const KIND_SPLITS: u8 = 3;

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

/// Bits needed for a number below `n`.
fn bits(n: usize) -> u32 {
    if n <= 1 {
        0
    } else {
        usize::BITS - (n - 1).leading_zeros()
    }
}

/// The slot after / before `k` in winding order (always below 3, so indexing needs no check).
#[inline(always)]
fn next3(k: usize) -> usize {
    match k {
        0 => 1,
        1 => 2,
        _ => 0,
    }
}
#[inline(always)]
fn prev3(k: usize) -> usize {
    match k {
        1 => 0,
        2 => 1,
        _ => 2,
    }
}

/// The triangles of `s`'s list that stay with `s` in a split moving the `moved` ones.
fn staying<'l, I: Index>(
    lists: &'l crate::progressive::Lists<'_, I>,
    s: usize,
    moved: u64,
) -> impl Iterator<Item = [usize; 3]> + 'l {
    let mut c = lists.first(s);
    let mut p = 0u32;
    core::iter::from_fn(move || {
        while c != usize::MAX && p as usize <= lists.tris.len() {
            let here = c;
            let pos = p;
            c = lists.after(c, s);
            p += 1;
            if pos < 64 && moved & (1u64 << (pos & 63)) != 0 {
                continue;
            }
            return lists.tris.get(here).map(|x| x.map(|i| i.to_usize()));
        }
        None
    })
}

/// The wing `w` that triangle `ct` (holding `s`) offers a restored triangle whose `t` follows
/// `s` (`t_next`) or precedes it: the neighbour across edge `s-w` runs it the other way.
fn wing(ct: [usize; 3], s: usize, t_next: bool) -> Option<usize> {
    let k = ct.iter().position(|&x| x == s)?;
    Some(if t_next { ct[next3(k)] } else { ct[prev3(k)] })
}

/// Marks "no vertex".
const NONE: usize = usize::MAX;

/// Restored triangle with `s` in slot `ks`, `t` after it (`t_next`) or before it, and `w` in
/// the third slot; `None` if that is not a triangle of three distinct vertices below `t + 1`.
fn arrange<I: Index>(ks: usize, t_next: bool, s: usize, t: usize, w: usize) -> Option<[I; 3]> {
    if ks > 2 || w >= t || w == s || s >= t {
        return None;
    }
    let (kt, kw) = if t_next {
        (next3(ks), prev3(ks))
    } else {
        (prev3(ks), next3(ks))
    };
    let mut v = [0usize; 3];
    for (k, x) in v.iter_mut().enumerate() {
        *x = if k == ks {
            s
        } else if k == kt {
            t
        } else if k == kw {
            w
        } else {
            0
        };
    }
    Some(v.map(I::narrow))
}

/// The fan run (mode 0 of a split): the staying triangle at place `q1` of `s`'s list names the
/// wing `w1`; the `k` moved triangles are the ones met walking around `s` from edge `s-w1`
/// away from that triangle (a collapse put the removed vertex's fan there, between its two
/// wings). Returns the moved mask, `w1`, and the far vertex of the last moved triangle (the
/// second wing). `None` if the walk leaves the list or passes position 63.
fn fan_run<I: Index>(
    lists: &crate::progressive::Lists<'_, I>,
    s: usize,
    q1: usize,
    t_next: bool,
    k: usize,
) -> Option<(u64, usize, Option<usize>)> {
    let w1 = wing(staying(lists, s, 0).nth(q1)?, s, t_next)?;
    let mut mask = 0u64;
    let mut x = w1;
    let mut last = None;
    for _ in 0..k {
        let (p, ct, ks) = staying(lists, s, 0).enumerate().find_map(|(p, ct)| {
            let ks = ct.iter().position(|&v| v == s)?;
            let near = if t_next { ct[prev3(ks)] } else { ct[next3(ks)] };
            let free = p < 64 && mask & (1u64 << (p & 63)) == 0;
            (near == x && free).then_some((p, ct, ks))
        })?;
        mask |= 1u64 << (p & 63);
        x = if t_next { ct[next3(ks)] } else { ct[prev3(ks)] };
        last = Some(x);
    }
    Some((mask, w1, last))
}

/// The stream's header.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Header {
    /// Vertex numbers fit `u16` (2) or need `u32` (4).
    pub index_width: u8,
    /// Positions quantised to 16 bits per coordinate.
    pub quantised: bool,
    /// Vertices of the full mesh.
    pub vertices: u32,
    /// Vertices of the base mesh.
    pub base_vertices: u32,
    /// Triangles of the base mesh.
    pub base_triangles: u32,
    /// Triangles of the full mesh.
    pub triangles: u32,
    /// Largest chunk payload.
    pub max_payload: u16,
    /// Bounding box of the positions.
    pub min: [f32; 3],
    /// Bounding box of the positions.
    pub max: [f32; 3],
}

impl Header {
    fn write(&self, out: &mut [u8; HEADER]) {
        out.fill(0);
        let mut put = |o: usize, bytes: &[u8]| {
            for (k, &x) in bytes.iter().enumerate() {
                if let Some(d) = out.get_mut(o + k) {
                    *d = x;
                }
            }
        };
        put(0, &MAGIC);
        put(4, &[VERSION, self.index_width, self.quantised as u8]);
        put(8, &self.vertices.to_le_bytes());
        put(12, &self.base_vertices.to_le_bytes());
        put(16, &self.base_triangles.to_le_bytes());
        put(20, &self.triangles.to_le_bytes());
        put(24, &self.max_payload.to_le_bytes());
        for (a, (lo, hi)) in self.min.iter().zip(&self.max).enumerate() {
            put(28 + 4 * a, &lo.to_le_bytes());
            put(40 + 4 * a, &hi.to_le_bytes());
        }
        let c = crc32(out.get(..52).unwrap_or(&[]));
        for (d, x) in out.iter_mut().skip(52).zip(c.to_le_bytes()) {
            *d = x;
        }
    }

    fn read(b: &[u8; HEADER]) -> Result<Self, StreamError> {
        if b[0..4] != MAGIC {
            return Err(StreamError::BadMagic);
        }
        if b[4] != VERSION {
            return Err(StreamError::BadVersion(b[4]));
        }
        let u32_at = |o: usize| {
            let mut w = [0u8; 4];
            for (k, d) in w.iter_mut().enumerate() {
                *d = b.get(o + k).copied().unwrap_or(0);
            }
            u32::from_le_bytes(w)
        };
        if crc32(b.get(..52).unwrap_or(&[])) != u32_at(52) {
            return Err(StreamError::Checksum { chunk: 0 });
        }
        let f32_at = |o: usize| f32::from_bits(u32_at(o));
        let h = Header {
            index_width: b[5],
            quantised: b[6] & 1 != 0,
            vertices: u32_at(8),
            base_vertices: u32_at(12),
            base_triangles: u32_at(16),
            triangles: u32_at(20),
            max_payload: u16::from_le_bytes([b[24], b[25]]),
            min: [f32_at(28), f32_at(32), f32_at(36)],
            max: [f32_at(40), f32_at(44), f32_at(48)],
        };
        let ok = (h.index_width == 2 || h.index_width == 4)
            && b[6] & !1 == 0
            && h.base_vertices <= h.vertices
            && h.base_triangles <= h.triangles
            && h.max_payload >= 16
            && h.min.iter().chain(h.max.iter()).all(|x| x.is_finite());
        if ok {
            Ok(h)
        } else {
            Err(StreamError::BadHeader)
        }
    }

    /// Bytes of one position.
    fn position_bits(&self) -> u32 {
        if self.quantised {
            48
        } else {
            96
        }
    }

    /// `q = round((x − min) / (max − min) · 65535)`. A box wider than the largest f32 (say
    /// −3e38 to 3e38) is measured in halves, so its span does not overflow to infinity.
    fn quantise(&self, p: [f32; 3]) -> [u32; 3] {
        let mut q = [0; 3];
        for (((q, &x), &lo), &hi) in q.iter_mut().zip(&p).zip(&self.min).zip(&self.max) {
            let span = hi - lo;
            let f = if span.is_finite() {
                (x - lo) / span
            } else {
                (x * 0.5 - lo * 0.5) / (hi * 0.5 - lo * 0.5)
            };
            if span > 0.0 {
                let x = f * 65535.0 + 0.5;
                *q = if x >= 65535.0 {
                    65535
                } else if x > 0.0 {
                    x as u32
                } else {
                    0
                };
            }
        }
        q
    }

    /// The position a decoder sees for quantised `q`: `min·(1 − f) + max·f`, `f = q / 65535`.
    /// The same point as `min + q·(max − min)/65535`, but exact at both ends, never an
    /// overflow for a box wider than the largest f32, and as fine as the f32 grid allows for a
    /// box of subnormal size (found by the `roundtrip` fuzz target).
    fn dequantise(&self, q: [u32; 3]) -> [f32; 3] {
        let mut p = [0.0; 3];
        for (((p, &q), &lo), &hi) in p.iter_mut().zip(&q).zip(&self.min).zip(&self.max) {
            let f = q as f32 / 65535.0;
            *p = lo * (1.0 - f) + hi * f;
        }
        p
    }
}

/// Bit writer into a fixed buffer.
struct BitWriter<'a> {
    out: &'a mut [u8],
    bit: usize,
    full: bool,
}

impl BitWriter<'_> {
    fn put(&mut self, v: u64, n: u32) {
        for i in 0..n {
            let byte = self.bit >> 3;
            match self.out.get_mut(byte) {
                Some(b) => {
                    if self.bit & 7 == 0 {
                        *b = 0;
                    }
                    *b |= (((v >> i) & 1) as u8) << (self.bit & 7);
                }
                None => self.full = true,
            }
            self.bit += 1;
        }
    }
}

/// Bit reader over a payload.
struct BitReader<'a> {
    data: &'a [u8],
    bit: usize,
}

impl BitReader<'_> {
    fn get(&mut self, n: u32) -> Option<u64> {
        let mut v = 0u64;
        for i in 0..n {
            let b = *self.data.get(self.bit >> 3)?;
            v |= (((b >> (self.bit & 7)) & 1) as u64) << (i & 63);
            self.bit += 1;
        }
        Some(v)
    }
}

/// One split's bits, as both ends derive them.
fn put_position(w: &mut BitWriter<'_>, h: &Header, p: [f32; 3]) {
    if h.quantised {
        for q in h.quantise(p) {
            w.put(q as u64, 16);
        }
    } else {
        for x in p {
            w.put(x.to_bits() as u64, 32);
        }
    }
}

fn get_position(r: &mut BitReader<'_>, h: &Header) -> Option<[f32; 3]> {
    if h.quantised {
        let q = [r.get(16)? as u32, r.get(16)? as u32, r.get(16)? as u32];
        Some(h.dequantise(q))
    } else {
        let p = [
            f32::from_bits(r.get(32)? as u32),
            f32::from_bits(r.get(32)? as u32),
            f32::from_bits(r.get(32)? as u32),
        ];
        Some(p)
    }
}

/// Sizes of an encoded stream.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Encoded {
    /// Bytes written in all.
    pub bytes: usize,
    /// Header, base positions and base triangles, chunk framing included.
    pub base_bytes: usize,
    /// Bits of connectivity in all vertex splits (everything but positions and framing).
    pub split_connectivity_bits: u64,
    /// Bits of positions in all vertex splits.
    pub split_position_bits: u64,
    /// Vertex splits.
    pub splits: usize,
}

/// Writes `pm`'s progressive stream into `out` and returns its sizes. `positions` are the
/// input's, `order` maps new vertex numbers to them (both as [`Progressive::from_log`] left
/// them). `max_payload` bounds each chunk's payload; it is raised to [`MIN_PAYLOAD`], the
/// largest single record, so every record fits a chunk. `pm` ends at full resolution.
pub fn encode<I: Index>(
    pm: &mut Progressive<'_, I>,
    positions: &[[f32; 3]],
    order: &[I],
    quantised: bool,
    max_payload: u16,
    out: &mut [u8],
) -> Result<Encoded, StreamError> {
    let full_vertices = pm.base_vertices() + pm.levels();
    let pos = |v: usize| -> [f32; 3] {
        order
            .get(v)
            .and_then(|&o| positions.get(o.to_usize()))
            .copied()
            .unwrap_or([0.0; 3])
    };
    let mut h = Header {
        index_width: if full_vertices <= u16::MAX as usize {
            2
        } else {
            4
        },
        quantised,
        vertices: full_vertices as u32,
        base_vertices: pm.base_vertices() as u32,
        base_triangles: pm.base_triangles() as u32,
        triangles: pm.full_triangles() as u32,
        max_payload: max_payload.max(MIN_PAYLOAD),
        min: [f32::INFINITY; 3],
        max: [f32::NEG_INFINITY; 3],
    };
    for v in 0..full_vertices {
        for ((lo, hi), x) in h.min.iter_mut().zip(h.max.iter_mut()).zip(pos(v)) {
            *lo = lo.min(x);
            *hi = hi.max(x);
        }
    }
    if full_vertices == 0 {
        h.min = [0.0; 3];
        h.max = [0.0; 3];
    }
    let mut head = [0u8; HEADER];
    h.write(&mut head);
    let mut e = Encoded::default();
    let mut chunks = Chunks {
        out,
        at: 0,
        start: 0,
        kind: 0,
        count: 0,
        bits: 0,
        max_bits: h.max_payload as usize * 8,
    };
    chunks.put_bytes(&head)?;
    pm.set_level(0);
    // Base positions and triangles.
    let mut rec = [0u8; MIN_PAYLOAD as usize];
    for v in 0..pm.base_vertices() {
        let mut w = BitWriter {
            out: &mut rec,
            bit: 0,
            full: false,
        };
        put_position(&mut w, &h, pos(v));
        let n = w.bit;
        chunks.item(KIND_POSITIONS, &rec, n)?;
    }
    let vb = bits(pm.base_vertices());
    for u in 0..pm.base_triangles() {
        let tri = pm.triangles().get(u).copied().unwrap_or([I::ZERO; 3]);
        let mut w = BitWriter {
            out: &mut rec,
            bit: 0,
            full: false,
        };
        for x in tri {
            w.put(x.to_usize() as u64, vb);
        }
        let n = w.bit;
        chunks.item(KIND_TRIANGLES, &rec, n)?;
    }
    chunks.close()?;
    e.base_bytes = chunks.at;
    // Vertex splits, each from the state the decoder will have.
    for j in 0..pm.levels() {
        let t = pm.base_vertices() + j;
        let Some(&sp) = pm.splits().get(j) else {
            break;
        };
        let s = sp.kept.to_usize();
        let lists = &pm.lists;
        let len = lists.len(s);
        let live = pm.live;
        let mut w = BitWriter {
            out: &mut rec,
            bit: 0,
            full: false,
        };
        let restored: [[usize; 3]; 2] = [live, live + 1].map(|u| {
            lists
                .tris
                .get(u)
                .map_or([NONE; 3], |x| x.map(|i| i.to_usize()))
        });
        // (slot of s, whether t follows s, the wing) of each restored triangle.
        let shape = |tri: [usize; 3]| {
            let ks = tri.iter().position(|&x| x == s).unwrap_or(0);
            let t_next = tri[next3(ks)] == t;
            let wv = if t_next {
                tri[prev3(ks)]
            } else {
                tri[next3(ks)]
            };
            (ks, t_next, wv)
        };
        let r = sp.restored as usize;
        let (ks1, tn1, w1) = shape(restored[0]);
        // Mode 0, the fan run, when it describes this split exactly.
        let k = sp.moved.count_ones() as usize;
        let q1 = staying(lists, s, 0).position(|ct| wing(ct, s, tn1) == Some(w1));
        let run = q1.and_then(|q1| {
            let (mask, w1r, last) = fan_run(lists, s, q1, tn1, k)?;
            let (ks2, tn2, w2) = shape(restored[1]);
            let second_ok = r == 1 || (tn2 != tn1 && last == Some(w2));
            (mask == sp.moved && w1r == w1 && second_ok).then_some((q1, ks2))
        });
        w.put(run.is_none() as u64, 1);
        w.put(s as u64, bits(t));
        w.put(sp.restored.saturating_sub(1) as u64, 1);
        if let Some((q1, ks2)) = run {
            w.put(ks1 as u64, 2);
            w.put(tn1 as u64, 1);
            w.put(q1 as u64, bits(len));
            w.put(k as u64, bits(len + 1));
            if r == 2 {
                w.put(ks2 as u64, 2);
            }
        } else {
            w.put(sp.moved, len.min(64) as u32);
            for &tri in restored.iter().take(r) {
                let (ks, t_next, wv) = shape(tri);
                w.put(ks as u64, 2);
                w.put(t_next as u64, 1);
                // The wing: the triangle across edge s-w stays with s and (in a consistently
                // wound mesh) runs that edge the other way, so its place among the staying
                // triangles names w; else w by number.
                let stay = len - sp.moved.count_ones() as usize;
                let found =
                    staying(lists, s, sp.moved).position(|ct| wing(ct, s, t_next) == Some(wv));
                match found {
                    Some(q) => {
                        w.put(0, 1);
                        w.put(q as u64, bits(stay));
                    }
                    None => {
                        w.put(1, 1);
                        w.put(wv as u64, bits(t));
                    }
                }
            }
        }
        e.split_connectivity_bits += w.bit as u64;
        put_position(&mut w, &h, pos(t));
        e.split_position_bits += h.position_bits() as u64;
        let n = w.bit;
        chunks.item(KIND_SPLITS, &rec, n)?;
        pm.refine(1);
    }
    chunks.close()?;
    e.bytes = chunks.at;
    e.splits = pm.levels();
    Ok(e)
}

/// Chunk writer for [`encode`].
struct Chunks<'a> {
    out: &'a mut [u8],
    at: usize,
    start: usize,
    kind: u8,
    count: u16,
    bits: usize,
    max_bits: usize,
}

impl Chunks<'_> {
    fn put_bytes(&mut self, b: &[u8]) -> Result<(), StreamError> {
        let dst = self.out.get_mut(self.at..).ok_or(StreamError::OutputFull)?;
        if dst.len() < b.len() {
            return Err(StreamError::OutputFull);
        }
        for (d, &x) in dst.iter_mut().zip(b) {
            *d = x;
        }
        self.at += b.len();
        Ok(())
    }

    /// Appends an item of `n` bits (in `rec`) to the open chunk of `kind`, opening one first
    /// if needed.
    fn item(&mut self, kind: u8, rec: &[u8], n: usize) -> Result<(), StreamError> {
        if self.kind != kind || self.bits + n > self.max_bits || self.count == u16::MAX {
            self.close()?;
            self.kind = kind;
            self.start = self.at;
            self.put_bytes(&[0, 0, kind, 0, 0])?;
        }
        let base = self.start + 5;
        let payload = self.out.get_mut(base..).ok_or(StreamError::OutputFull)?;
        let mut w = BitWriter {
            out: payload,
            bit: self.bits,
            full: false,
        };
        let mut r = BitReader { data: rec, bit: 0 };
        let mut left = n;
        while left > 0 {
            let k = left.min(32) as u32;
            let v = r.get(k).unwrap_or(0);
            w.put(v, k);
            left -= k as usize;
        }
        if w.full {
            return Err(StreamError::OutputFull);
        }
        self.bits = w.bit;
        self.count += 1;
        Ok(())
    }

    fn close(&mut self) -> Result<(), StreamError> {
        if self.kind == 0 {
            return Ok(());
        }
        let len = self.bits.div_ceil(8);
        let end = self.start + 5 + len;
        let chunk = self
            .out
            .get_mut(self.start..end)
            .ok_or(StreamError::OutputFull)?;
        let [l0, l1] = (len as u16).to_le_bytes();
        let [c0, c1] = self.count.to_le_bytes();
        for (k, v) in [(0, l0), (1, l1), (3, c0), (4, c1)] {
            if let Some(x) = chunk.get_mut(k) {
                *x = v;
            }
        }
        let c = crc32(chunk);
        self.at = end;
        self.put_bytes(&c.to_le_bytes())?;
        self.kind = 0;
        self.count = 0;
        self.bits = 0;
        Ok(())
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Phase {
    Header,
    Chunks,
    Done,
    Failed(StreamError),
}

/// Incremental decoder: feed it bytes in chunks of any size as they arrive ([`Decoder::push`]);
/// after every complete, verified chunk [`Decoder::progressive`] holds a valid mesh one level
/// finer, whose vertices are in [`Decoder::positions`].
///
/// Memory: the [`Storage`] of a [`Progressive`] for the full mesh, its positions (12 bytes per
/// vertex) and a chunk buffer of the stream's largest chunk plus
/// [`CHUNK_OVERHEAD`] bytes (at least [`HEADER`]).
pub struct Decoder<'a, I: Index> {
    pm: Progressive<'a, I>,
    positions: &'a mut [[f32; 3]],
    buf: &'a mut [u8],
    have: usize,
    phase: Phase,
    header: Header,
    chunk: u32,
    /// Base positions received.
    base_read: usize,
}

impl<'a, I: Index> Decoder<'a, I> {
    /// A decoder over caller-provided storage.
    pub fn new(storage: Storage<'a, I>, positions: &'a mut [[f32; 3]], buf: &'a mut [u8]) -> Self {
        Decoder {
            pm: Progressive::empty(storage),
            positions,
            buf,
            have: 0,
            phase: Phase::Header,
            header: Header::default(),
            chunk: 0,
            base_read: 0,
        }
    }

    /// The header, once read.
    pub fn header(&self) -> Option<Header> {
        (self.phase != Phase::Header).then_some(self.header)
    }

    /// The mesh so far (and the slider over it).
    pub fn progressive(&mut self) -> &mut Progressive<'a, I> {
        &mut self.pm
    }

    /// The mesh so far, read-only.
    pub fn mesh(&self) -> &Progressive<'a, I> {
        &self.pm
    }

    /// Positions received so far, in the stream's vertex numbers.
    pub fn positions(&self) -> &[[f32; 3]] {
        let n = if self.pm.levels() > 0 {
            self.pm.base_vertices() + self.pm.levels()
        } else {
            self.base_read
        };
        self.positions.get(..n).unwrap_or(&[])
    }

    /// Whether the full mesh has arrived.
    pub fn is_complete(&self) -> bool {
        self.phase == Phase::Done
    }

    /// `Ok` once the full mesh has arrived; [`StreamError::Truncated`] before; the error that
    /// stopped the decoder after one.
    pub fn finish(&self) -> Result<(), StreamError> {
        match self.phase {
            Phase::Done => Ok(()),
            Phase::Failed(e) => Err(e),
            _ => Err(StreamError::Truncated),
        }
    }

    /// Takes the next bytes of the stream. Each chunk is checked, then applied whole; on an
    /// error the decoder stops for good and the mesh stays the last valid level.
    pub fn push(&mut self, mut bytes: &[u8]) -> Result<(), StreamError> {
        while !bytes.is_empty() {
            match self.phase {
                Phase::Failed(e) => return Err(e),
                Phase::Done => return self.fail(StreamError::TrailingData),
                Phase::Header | Phase::Chunks => {}
            }
            // How many bytes the current unit needs.
            let need = if self.phase == Phase::Header {
                HEADER
            } else if self.have < 2 {
                2
            } else {
                let len = self.buf.first().copied().unwrap_or(0) as usize
                    | (self.buf.get(1).copied().unwrap_or(0) as usize) << 8;
                if len > self.header.max_payload as usize {
                    return self.fail(StreamError::BadChunk {
                        chunk: self.chunk + 1,
                    });
                }
                len + CHUNK_OVERHEAD
            };
            let take = (need - self.have).min(bytes.len());
            let Some(dst) = self.buf.get_mut(self.have..self.have + take) else {
                return self.fail(StreamError::Capacity {
                    what: "chunk buffer",
                    needed: need,
                    available: self.buf.len(),
                });
            };
            for (d, &x) in dst.iter_mut().zip(bytes) {
                *d = x;
            }
            bytes = bytes.get(take..).unwrap_or(&[]);
            self.have += take;
            if self.have < need || need == 2 {
                continue;
            }
            self.have = 0;
            let r = if self.phase == Phase::Header {
                self.read_header()
            } else {
                self.chunk += 1;
                self.read_chunk(need)
            };
            if let Err(e) = r {
                return self.fail(e);
            }
        }
        Ok(())
    }

    fn fail(&mut self, e: StreamError) -> Result<(), StreamError> {
        self.phase = Phase::Failed(e);
        Err(e)
    }

    fn read_header(&mut self) -> Result<(), StreamError> {
        let mut b = [0u8; HEADER];
        for (d, &x) in b.iter_mut().zip(self.buf.iter()) {
            *d = x;
        }
        let h = Header::read(&b)?;
        let cap = |what, needed: usize, available: usize| {
            if needed > available {
                Err(StreamError::Capacity {
                    what,
                    needed,
                    available,
                })
            } else {
                Ok(())
            }
        };
        let nv = h.vertices as usize;
        cap(
            "vertices",
            nv,
            self.positions.len().min(self.pm.vertex_capacity()),
        )?;
        cap(
            "triangles",
            h.triangles as usize,
            self.pm.triangle_capacity(),
        )?;
        cap(
            "splits",
            nv - h.base_vertices as usize,
            self.pm.split_capacity(),
        )?;
        cap(
            "chunk buffer",
            h.max_payload as usize + CHUNK_OVERHEAD,
            self.buf.len(),
        )?;
        self.pm.start(h.base_vertices as usize);
        self.header = h;
        self.phase = Phase::Chunks;
        self.check_done();
        Ok(())
    }

    fn check_done(&mut self) {
        let h = &self.header;
        if self.base_read == h.base_vertices as usize
            && self.pm.base_triangles() == h.base_triangles as usize
            && self.pm.base_vertices() + self.pm.levels() == h.vertices as usize
        {
            self.phase = Phase::Done;
        }
    }

    fn read_chunk(&mut self, total: usize) -> Result<(), StreamError> {
        // The buffer is lent out while the chunk's items are applied to the mesh.
        let buf = core::mem::take(&mut self.buf);
        let r = self.apply_chunk(buf, total);
        self.buf = buf;
        r
    }

    fn apply_chunk(&mut self, buf: &[u8], total: usize) -> Result<(), StreamError> {
        let chunk = self.chunk;
        let bad = StreamError::BadChunk { chunk };
        let data = buf.get(..total).ok_or(bad)?;
        let (Some(body), Some(&[s0, s1, s2, s3])) = (
            data.get(..total.saturating_sub(4)),
            data.get(total.saturating_sub(4)..),
        ) else {
            return Err(bad);
        };
        if crc32(body) != u32::from_le_bytes([s0, s1, s2, s3]) {
            return Err(StreamError::Checksum { chunk });
        }
        let Some(&[_, _, kind, c0, c1]) = body.get(..5) else {
            return Err(bad);
        };
        let count = u16::from_le_bytes([c0, c1]) as usize;
        let h = self.header;
        let base_v = h.base_vertices as usize;
        let base_t = h.base_triangles as usize;
        let mut r = BitReader {
            data: body.get(5..).unwrap_or(&[]),
            bit: 0,
        };
        match kind {
            KIND_POSITIONS if self.base_read + count <= base_v => {
                for _ in 0..count {
                    let p = get_position(&mut r, &h).ok_or(bad)?;
                    let slot = self.positions.get_mut(self.base_read).ok_or(bad)?;
                    *slot = p;
                    self.base_read += 1;
                }
            }
            KIND_TRIANGLES
                if self.base_read == base_v && self.pm.base_triangles() + count <= base_t =>
            {
                let vb = bits(base_v);
                for _ in 0..count {
                    let mut tri = [I::ZERO; 3];
                    for x in tri.iter_mut() {
                        let v = r.get(vb).ok_or(bad)? as usize;
                        if v >= base_v {
                            return Err(bad);
                        }
                        *x = I::narrow(v);
                    }
                    if !self.pm.push_base(tri) {
                        return Err(bad);
                    }
                }
            }
            KIND_SPLITS
                if self.base_read == base_v
                    && self.pm.base_triangles() == base_t
                    && self.pm.base_vertices() + self.pm.levels() + count
                        <= h.vertices as usize =>
            {
                for _ in 0..count {
                    self.read_split(&mut r, &h)?;
                }
            }
            _ => return Err(bad),
        }
        self.check_done();
        Ok(())
    }

    fn read_split(&mut self, r: &mut BitReader<'_>, h: &Header) -> Result<(), StreamError> {
        let j = self.pm.levels();
        let bad = StreamError::BadSplit { split: j };
        let short = StreamError::BadChunk { chunk: self.chunk };
        self.pm.refine(usize::MAX);
        let t = self.pm.base_vertices() + j;
        let explicit = r.get(1).ok_or(short)? == 1;
        let s = r.get(bits(t)).ok_or(short)? as usize;
        if s >= t {
            return Err(bad);
        }
        let restored = r.get(1).ok_or(short)? as u8 + 1;
        let lists = &self.pm.lists;
        // A kept vertex may have more than 64 triangles; the split's moved ones lie among the
        // first 64 of its list (`Progressive::from_log` refuses a log where they do not), and
        // the explicit mask has min(L, 64) bits, as the encoder writes it.
        let len = lists.len(s);
        let mut tris = [[I::ZERO; 3]; 2];
        let moved;
        if !explicit {
            let ks1 = r.get(2).ok_or(short)? as usize;
            let tn1 = r.get(1).ok_or(short)? == 1;
            let q1 = r.get(bits(len)).ok_or(short)? as usize;
            let k = r.get(bits(len + 1)).ok_or(short)? as usize;
            let (mask, w1, last) = fan_run(lists, s, q1, tn1, k).ok_or(bad)?;
            moved = mask;
            tris[0] = arrange(ks1, tn1, s, t, w1).ok_or(bad)?;
            if restored == 2 {
                let ks2 = r.get(2).ok_or(short)? as usize;
                tris[1] = arrange(ks2, !tn1, s, t, last.ok_or(bad)?).ok_or(bad)?;
            }
        } else {
            moved = r.get(len.min(64) as u32).ok_or(short)?;
            for tri in tris.iter_mut().take(restored as usize) {
                let ks = r.get(2).ok_or(short)? as usize;
                let t_next = r.get(1).ok_or(short)? == 1;
                let w = if r.get(1).ok_or(short)? == 0 {
                    let stay = len - (moved.count_ones() as usize).min(len);
                    let q = r.get(bits(stay)).ok_or(short)? as usize;
                    let ct = staying(lists, s, moved).nth(q).ok_or(bad)?;
                    wing(ct, s, t_next).ok_or(bad)?
                } else {
                    r.get(bits(t)).ok_or(short)? as usize
                };
                *tri = arrange(ks, t_next, s, t, w).ok_or(bad)?;
            }
        }
        let p = get_position(r, h).ok_or(short)?;
        let slot = self.positions.get_mut(t).ok_or(bad)?;
        let split = Split {
            kept: I::narrow(s),
            restored,
            moved,
        };
        if !self
            .pm
            .push_split(split, tris.get(..restored as usize).unwrap_or(&[]))
        {
            return Err(bad);
        }
        *slot = p;
        Ok(())
    }
}
