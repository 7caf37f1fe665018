//! The stream's 56-byte header (see the format in the module documentation).

use super::{crc32, StreamError, HEADER, MAGIC, VERSION};

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
    pub(super) fn write(&self, out: &mut [u8; HEADER]) {
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

    pub(super) fn read(b: &[u8; HEADER]) -> Result<Self, StreamError> {
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
    pub(super) fn position_bits(&self) -> u32 {
        if self.quantised {
            48
        } else {
            96
        }
    }

    /// `q = round((x − min) / (max − min) · 65535)`. A box wider than the largest f32 (say
    /// −3e38 to 3e38) is measured in halves, so its span does not overflow to infinity.
    pub(super) fn quantise(&self, p: [f32; 3]) -> [u32; 3] {
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
    pub(super) fn dequantise(&self, q: [u32; 3]) -> [f32; 3] {
        let mut p = [0.0; 3];
        for (((p, &q), &lo), &hi) in p.iter_mut().zip(&q).zip(&self.min).zip(&self.max) {
            let f = q as f32 / 65535.0;
            *p = lo * (1.0 - f) + hi * f;
        }
        p
    }
}
