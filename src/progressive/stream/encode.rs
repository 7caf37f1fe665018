//! The encoder: a progressive mesh into a stream.

use super::bits::{bits, put_position, BitReader, BitWriter};
use super::split::{fan_run, staying, wing, NONE};
use super::{
    crc32, Header, StreamError, HEADER, KIND_POSITIONS, KIND_SPLITS, KIND_TRIANGLES, MIN_PAYLOAD,
};
use crate::index::Index;
use crate::progressive::{Progressive, Split};
use crate::tri::{next3, prev3};

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
    let pos = |v: usize| -> [f32; 3] {
        order
            .get(v)
            .and_then(|&o| positions.get(o.to_usize()))
            .copied()
            .unwrap_or([0.0; 3])
    };
    let h = header_of(pm, pos, quantised, max_payload);
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
    let mut rec = [0u8; MIN_PAYLOAD as usize];
    write_base(pm, &h, pos, &mut chunks, &mut rec)?;
    e.base_bytes = chunks.at;
    // Vertex splits, each from the state the decoder will have.
    for j in 0..pm.levels() {
        let Some(&sp) = pm.splits().get(j) else {
            break;
        };
        let t = pm.base_vertices() + j;
        let mut w = BitWriter {
            out: &mut rec,
            bit: 0,
            full: false,
        };
        write_split(pm, sp, t, &mut w);
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

/// The header of `pm`'s stream: counts and the bounding box of the full mesh's positions.
fn header_of<I: Index>(
    pm: &Progressive<'_, I>,
    pos: impl Fn(usize) -> [f32; 3],
    quantised: bool,
    max_payload: u16,
) -> Header {
    let full_vertices = pm.base_vertices() + pm.levels();
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
    h
}

/// The base mesh (`pm` at level 0): its positions, then its triangles, each in chunks of its
/// kind.
fn write_base<I: Index>(
    pm: &Progressive<'_, I>,
    h: &Header,
    pos: impl Fn(usize) -> [f32; 3],
    chunks: &mut Chunks<'_>,
    rec: &mut [u8; MIN_PAYLOAD as usize],
) -> Result<(), StreamError> {
    for v in 0..pm.base_vertices() {
        let mut w = BitWriter {
            out: rec,
            bit: 0,
            full: false,
        };
        put_position(&mut w, h, pos(v));
        let n = w.bit;
        chunks.item(KIND_POSITIONS, rec, n)?;
    }
    let vb = bits(pm.base_vertices());
    for u in 0..pm.base_triangles() {
        let tri = pm.triangles().get(u).copied().unwrap_or([I::ZERO; 3]);
        let mut w = BitWriter {
            out: rec,
            bit: 0,
            full: false,
        };
        for x in tri {
            w.put(x.to_usize() as u64, vb);
        }
        let n = w.bit;
        chunks.item(KIND_TRIANGLES, rec, n)?;
    }
    chunks.close()
}

/// The connectivity of split `sp` creating vertex `t`, from `pm` one level below it (the
/// state the decoder will have): mode 0 (the fan run) when it describes the split exactly,
/// else mode 1 (explicit).
fn write_split<I: Index>(pm: &Progressive<'_, I>, sp: Split<I>, t: usize, w: &mut BitWriter<'_>) {
    let s = sp.kept.to_usize();
    let lists = &pm.lists;
    let len = lists.len(s);
    let live = pm.live;
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
            let found = staying(lists, s, sp.moved).position(|ct| wing(ct, s, t_next) == Some(wv));
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
