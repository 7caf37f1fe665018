//! Bit packing, least significant bit first, and the positions written with it.

use super::Header;

/// Bits needed for a number below `n`.
pub(super) fn bits(n: usize) -> u32 {
    if n <= 1 {
        0
    } else {
        usize::BITS - (n - 1).leading_zeros()
    }
}

/// Bit writer into a fixed buffer.
pub(super) struct BitWriter<'a> {
    pub(super) out: &'a mut [u8],
    pub(super) bit: usize,
    pub(super) full: bool,
}

impl BitWriter<'_> {
    pub(super) fn put(&mut self, v: u64, n: u32) {
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
pub(super) struct BitReader<'a> {
    pub(super) data: &'a [u8],
    pub(super) bit: usize,
}

impl BitReader<'_> {
    pub(super) fn get(&mut self, n: u32) -> Option<u64> {
        let mut v = 0u64;
        for i in 0..n {
            let b = *self.data.get(self.bit >> 3)?;
            v |= (((b >> (self.bit & 7)) & 1) as u64) << (i & 63);
            self.bit += 1;
        }
        Some(v)
    }
}

/// Writes a position: 3 × f32, or 3 × 16 bits quantised over the header's box.
pub(super) fn put_position(w: &mut BitWriter<'_>, h: &Header, p: [f32; 3]) {
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

/// Reads a position written by [`put_position`].
pub(super) fn get_position(r: &mut BitReader<'_>, h: &Header) -> Option<[f32; 3]> {
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
