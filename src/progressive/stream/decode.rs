//! The incremental decoder.

use super::bits::{bits, get_position, BitReader};
use super::split::{arrange, fan_run, staying, wing};
use super::{
    crc32, Header, StreamError, CHUNK_OVERHEAD, HEADER, KIND_POSITIONS, KIND_SPLITS, KIND_TRIANGLES,
};
use crate::index::Index;
use crate::progressive::{Progressive, Split, Storage};

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
