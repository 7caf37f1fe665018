//! The progressive-stream run shared by the QEMU firmware and the host: decode a `.tdpm`
//! stream fed in pieces of varying size, record the mesh as it refines, then slide it down to
//! the base mesh and back up. The firmware runs [`run`] on each board, the host runs the same
//! function in memory, and the two outputs must be byte for byte the same (golden cases of
//! `host-sim golden` / `host-sim qemu --check`; the streaming demo of `host-sim stream`).
//!
//! # Output file (device → host)
//!
//! A sequence of records, then a [`TRAILER_LEN`]-byte trailer (written last, so a device can
//! stream its output without seeking). Everything little-endian.
//!
//! | record            | layout                                                                      |
//! |-------------------|-----------------------------------------------------------------------------|
//! | mesh ([`Tag`] 1-6) | u32 tag, u32 stream bytes taken so far, u32 triangles T, u32 vertices, T × 3 u32 |
//! | positions (tag 7) | u32 7, u32 bytes taken, u32 0, u32 vertices V, V × 3 f32                    |
//!
//! | trailer offset | type    | field                                                   |
//! |---------------:|---------|---------------------------------------------------------|
//! |              0 | [u8; 4] | magic `TDPR`                                            |
//! |              4 | u16     | version ([`VERSION`])                                   |
//! |              6 | u8      | 0: the stream decoded completely; 1: stream error       |
//! |              7 | u8      | error code ([`error_code`]), 0 if none                  |
//! |              8 | u32 × 2 | error details (see [`error_code`])                      |
//! |             16 | u32     | stream bytes taken                                      |
//! |             20 | u32     | records before the trailer                              |
//! |             24 | u32 × 4 | base triangles, triangles at the finest level reached, vertex splits received, vertices |
//! |             40 | u64 × 3 | measurement, not compared: SysTick ticks in `Decoder::push`, in coarsening all levels, in refining all levels |
//! |             64 | u32     | measurement: stack bytes below the caller                |
//! |             68 | u8      | measurement: board ([`crate::Board`])                    |

use tinydecimate::progressive::Storage;
use tinydecimate::stream::{Decoder, StreamError};
use tinydecimate::Index;

/// Trailer magic.
pub const MAGIC: [u8; 4] = *b"TDPR";
/// Output format version.
pub const VERSION: u16 = 1;
/// Trailer size.
pub const TRAILER_LEN: usize = 80;
/// Trailer bytes that must match exactly; the rest is measurement.
pub const COMPARED_LEN: usize = 40;
/// The pieces the stream is fed in, cycled: from a single byte to more than one chunk, so a
/// chunk boundary falls everywhere (as bytes arrive from a UART or a radio).
pub const FEED: [usize; 8] = [1, 7, 64, 3, 128, 29, 113, 50];
/// The largest piece.
pub const FEED_MAX: usize = 128;

/// What a record holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Tag {
    /// The mesh after a piece of the stream, each time the triangle count has doubled.
    Arrived = 1,
    /// The mesh when the stream ended (complete, or the last valid level before an error).
    Final = 2,
    /// After coarsening every level: the base mesh.
    Base = 3,
    /// After refining half the levels.
    Refined = 4,
    /// After coarsening a quarter of them again.
    Coarsened = 5,
    /// Back at the finest level (must equal [`Tag::Final`]).
    Full = 6,
    /// The positions received.
    Positions = 7,
}

/// The device side: where the stream comes from, where the output goes, and a timer.
pub trait Device {
    /// I/O error.
    type Error;
    /// Reads up to `buf.len()` bytes of the stream; 0 at its end.
    fn read(&mut self, buf: &mut [u8]) -> Result<usize, Self::Error>;
    /// Appends to the output.
    fn write(&mut self, bytes: &[u8]) -> Result<(), Self::Error>;
    /// Starts the timer.
    fn start(&mut self) {}
    /// Stops the timer; ticks since [`Device::start`].
    fn stop(&mut self) -> u64 {
        0
    }
    /// Called at every [`Tag::Arrived`] record (a device logs it).
    fn arrived(&mut self, _bytes: usize, _triangles: usize, _vertices: usize) {}
}

/// The trailer's fields.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Summary {
    /// The stream's error, if any.
    pub error: Option<StreamErrorCode>,
    /// Stream bytes taken.
    pub bytes: u32,
    /// Records written before the trailer.
    pub records: u32,
    /// Base triangles.
    pub base_triangles: u32,
    /// Triangles at the finest level reached.
    pub triangles: u32,
    /// Vertex splits received.
    pub splits: u32,
    /// Vertices at the finest level reached.
    pub vertices: u32,
    /// Ticks spent in `Decoder::push`.
    pub decode_ticks: u64,
    /// Ticks to coarsen every received level (one edge collapse each).
    pub coarsen_ticks: u64,
    /// Ticks to refine them all again (one vertex split each).
    pub refine_ticks: u64,
    /// Stack bytes (filled in by the firmware).
    pub stack_bytes: u32,
    /// Board id.
    pub board: u8,
}

/// A [`StreamError`] as three numbers: code, detail a, detail b.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct StreamErrorCode {
    /// See [`error_code`].
    pub code: u8,
    /// First detail.
    pub a: u32,
    /// Second detail.
    pub b: u32,
}

/// The code of a stream error: 1 bad magic, 2 bad version (a = version), 3 checksum (a =
/// chunk), 4 capacity (a = needed, b = available), 5 bad header, 6 bad chunk (a = chunk),
/// 7 bad split (a = split), 8 trailing data, 9 truncated, 10 output full.
pub fn error_code(e: StreamError) -> StreamErrorCode {
    let n = |v: usize| u32::try_from(v).unwrap_or(u32::MAX);
    let (code, a, b) = match e {
        StreamError::BadMagic => (1, 0, 0),
        StreamError::BadVersion(v) => (2, u32::from(v), 0),
        StreamError::Checksum { chunk } => (3, chunk, 0),
        StreamError::Capacity {
            needed, available, ..
        } => (4, n(needed), n(available)),
        StreamError::BadHeader => (5, 0, 0),
        StreamError::BadChunk { chunk } => (6, chunk, 0),
        StreamError::BadSplit { split } => (7, n(split), 0),
        StreamError::TrailingData => (8, 0, 0),
        StreamError::Truncated => (9, 0, 0),
        StreamError::OutputFull => (10, 0, 0),
    };
    StreamErrorCode { code, a, b }
}

impl Summary {
    /// Encodes the trailer.
    pub fn to_bytes(&self) -> [u8; TRAILER_LEN] {
        let mut b = [0u8; TRAILER_LEN];
        let e = self.error.unwrap_or_default();
        let fields: [(usize, &[u8]); 14] = [
            (0, &MAGIC),
            (4, &VERSION.to_le_bytes()),
            (6, &[u8::from(self.error.is_some()), e.code]),
            (8, &e.a.to_le_bytes()),
            (12, &e.b.to_le_bytes()),
            (16, &self.bytes.to_le_bytes()),
            (20, &self.records.to_le_bytes()),
            (24, &self.base_triangles.to_le_bytes()),
            (28, &self.triangles.to_le_bytes()),
            (32, &self.splits.to_le_bytes()),
            (36, &self.vertices.to_le_bytes()),
            (40, &self.decode_ticks.to_le_bytes()),
            (48, &self.coarsen_ticks.to_le_bytes()),
            (56, &self.refine_ticks.to_le_bytes()),
        ];
        for (at, v) in fields {
            if let Some(d) = b.get_mut(at..at + v.len()) {
                d.copy_from_slice(v);
            }
        }
        if let Some(d) = b.get_mut(64..68) {
            d.copy_from_slice(&self.stack_bytes.to_le_bytes());
        }
        if let Some(d) = b.get_mut(68) {
            *d = self.board;
        }
        b
    }

    /// Decodes a trailer; `None` if the magic or version is wrong.
    pub fn from_bytes(b: &[u8; TRAILER_LEN]) -> Option<Self> {
        let u32_at = |at: usize| u32::from_le_bytes([b[at], b[at + 1], b[at + 2], b[at + 3]]);
        let u64_at = |at: usize| u64::from(u32_at(at)) | u64::from(u32_at(at + 4)) << 32;
        if b[..4] != MAGIC || u16::from_le_bytes([b[4], b[5]]) != VERSION {
            return None;
        }
        Some(Summary {
            error: (b[6] != 0).then_some(StreamErrorCode {
                code: b[7],
                a: u32_at(8),
                b: u32_at(12),
            }),
            bytes: u32_at(16),
            records: u32_at(20),
            base_triangles: u32_at(24),
            triangles: u32_at(28),
            splits: u32_at(32),
            vertices: u32_at(36),
            decode_ticks: u64_at(40),
            coarsen_ticks: u64_at(48),
            refine_ticks: u64_at(56),
            stack_bytes: u32_at(64),
            board: b[68],
        })
    }
}

fn put_u32s<D: Device>(dev: &mut D, words: &[u32]) -> Result<(), D::Error> {
    // Through a small stack buffer: one host call per 48 words instead of per word.
    let mut buf = [0u8; 192];
    for part in words.chunks(48) {
        for (d, w) in buf.chunks_exact_mut(4).zip(part) {
            d.copy_from_slice(&w.to_le_bytes());
        }
        dev.write(buf.get(..part.len() * 4).unwrap_or(&[]))?;
    }
    Ok(())
}

fn record_mesh<I: Index, D: Device>(
    dev: &mut D,
    tag: Tag,
    bytes: usize,
    triangles: &[[I; 3]],
    vertices: usize,
) -> Result<(), D::Error> {
    let n = |v: usize| u32::try_from(v).unwrap_or(u32::MAX);
    put_u32s(
        dev,
        &[tag as u32, n(bytes), n(triangles.len()), n(vertices)],
    )?;
    let mut words = [0u32; 48];
    for part in triangles.chunks(16) {
        for (d, t) in words.chunks_exact_mut(3).zip(part) {
            for (w, i) in d.iter_mut().zip(t) {
                *w = n(i.to_usize());
            }
        }
        put_u32s(dev, words.get(..part.len() * 3).unwrap_or(&[]))?;
    }
    Ok(())
}

/// Decodes the stream `dev` reads into the caller's storage (as a device would: pieces of
/// [`FEED`] sizes, nothing of the stream held beyond one chunk), writing the records described
/// in the module comment. Returns the trailer's fields; the caller adds its measurements
/// (stack, board) and writes [`Summary::to_bytes`] last. A bad stream is not
/// an error here: it is reported in the trailer, and the records show the mesh it left.
pub fn run<I: Index, D: Device>(
    dev: &mut D,
    storage: Storage<'_, I>,
    positions: &mut [[f32; 3]],
    chunk_buffer: &mut [u8],
) -> Result<Summary, D::Error> {
    let mut dec = Decoder::new(storage, positions, chunk_buffer);
    let mut piece = [0u8; FEED_MAX];
    let mut s = Summary::default();
    let mut bytes = 0usize;
    let mut next = 1usize;
    let mut failed = None;
    for k in 0.. {
        let want = FEED[k % FEED.len()];
        let n = dev.read(piece.get_mut(..want).unwrap_or(&mut []))?;
        if n == 0 {
            break;
        }
        dev.start();
        let r = dec.push(piece.get(..n).unwrap_or(&[]));
        s.decode_ticks += dev.stop();
        bytes += n;
        let pm = dec.mesh();
        let t = pm.triangles().len();
        if t >= next {
            record_mesh(dev, Tag::Arrived, bytes, pm.triangles(), pm.vertices())?;
            s.records += 1;
            dev.arrived(bytes, t, pm.vertices());
            next = 2 * t;
        }
        if let Err(e) = r {
            failed = Some(e);
            break;
        }
    }
    let error = match failed {
        Some(e) => Some(e),
        None => dec.finish().err(),
    };
    s.error = error.map(error_code);
    s.bytes = u32::try_from(bytes).unwrap_or(u32::MAX);
    let pm = dec.mesh();
    record_mesh(dev, Tag::Final, bytes, pm.triangles(), pm.vertices())?;
    let nv = pm.vertices();
    s.triangles = u32::try_from(pm.triangles().len()).unwrap_or(u32::MAX);
    s.vertices = u32::try_from(nv).unwrap_or(u32::MAX);
    s.splits = u32::try_from(pm.levels()).unwrap_or(u32::MAX);
    s.base_triangles = u32::try_from(pm.base_triangles()).unwrap_or(u32::MAX);
    // Positions (bits, so a NaN would compare too).
    put_u32s(dev, &[Tag::Positions as u32, s.bytes, 0, s.vertices])?;
    for p in dec.positions().chunks(16) {
        let mut words = [0u32; 48];
        for (d, q) in words.chunks_exact_mut(3).zip(p) {
            for (w, c) in d.iter_mut().zip(q) {
                *w = c.to_bits();
            }
        }
        put_u32s(dev, words.get(..p.len() * 3).unwrap_or(&[]))?;
    }
    s.records += 2;

    // The slider: all the way down, half up, a quarter down, all the way up.
    let pm = dec.progressive();
    let levels = pm.level();
    dev.start();
    pm.coarsen(usize::MAX);
    s.coarsen_ticks = dev.stop();
    record_mesh(dev, Tag::Base, bytes, pm.triangles(), pm.vertices())?;
    pm.refine(levels / 2);
    record_mesh(dev, Tag::Refined, bytes, pm.triangles(), pm.vertices())?;
    pm.coarsen(levels / 4);
    record_mesh(dev, Tag::Coarsened, bytes, pm.triangles(), pm.vertices())?;
    pm.coarsen(usize::MAX);
    dev.start();
    pm.refine(usize::MAX);
    s.refine_ticks = dev.stop();
    record_mesh(dev, Tag::Full, bytes, pm.triangles(), pm.vertices())?;
    s.records += 4;
    Ok(s)
}

/// One record of an output file, decoded (host side).
#[cfg(feature = "std")]
#[derive(Clone, Debug, PartialEq)]
pub struct Record {
    /// What it holds.
    pub tag: u32,
    /// Stream bytes taken when it was written.
    pub bytes: u32,
    /// The mesh's vertex count.
    pub vertices: u32,
    /// Triangles (mesh records).
    pub triangles: std::vec::Vec<[u32; 3]>,
    /// Positions (the positions record).
    pub positions: std::vec::Vec<[f32; 3]>,
}

/// Splits an output file into its records and trailer; `None` if it is malformed.
#[cfg(feature = "std")]
pub fn parse(out: &[u8]) -> Option<(std::vec::Vec<Record>, Summary)> {
    let split = out.len().checked_sub(TRAILER_LEN)?;
    let (body, trailer) = out.split_at(split);
    let s = Summary::from_bytes(trailer.try_into().ok()?)?;
    let word = |at: usize| -> Option<u32> {
        Some(u32::from_le_bytes(body.get(at..at + 4)?.try_into().ok()?))
    };
    let mut at = 0;
    let mut records = std::vec::Vec::new();
    while at < body.len() {
        let (tag, bytes, t, v) = (word(at)?, word(at + 4)?, word(at + 8)?, word(at + 12)?);
        at += 16;
        let mut r = Record {
            tag,
            bytes,
            vertices: v,
            triangles: std::vec::Vec::new(),
            positions: std::vec::Vec::new(),
        };
        if tag == Tag::Positions as u32 {
            for _ in 0..v {
                let p = [word(at)?, word(at + 4)?, word(at + 8)?].map(f32::from_bits);
                r.positions.push(p);
                at += 12;
            }
        } else {
            for _ in 0..t {
                r.triangles.push([word(at)?, word(at + 4)?, word(at + 8)?]);
                at += 12;
            }
        }
        records.push(r);
    }
    (records.len() == s.records as usize).then_some((records, s))
}

/// The output with the trailer's measurement block zeroed: what golden files hold.
#[cfg(feature = "std")]
pub fn compared(out: &[u8]) -> std::vec::Vec<u8> {
    let mut v = out.to_vec();
    let n = v.len();
    if n >= TRAILER_LEN {
        for b in &mut v[n - TRAILER_LEN + COMPARED_LEN..] {
            *b = 0;
        }
    }
    v
}

/// Runs [`run`] on the host over a stream in memory, with storage for up to `max_vertices`
/// vertices and `max_triangles` triangles (`u32` indices) and a chunk buffer of `buffer`
/// bytes; returns the output file.
#[cfg(feature = "std")]
pub fn run_in_memory(
    stream: &[u8],
    max_vertices: usize,
    max_triangles: usize,
    buffer: usize,
) -> std::vec::Vec<u8> {
    use std::vec;
    use tinydecimate::progressive::Split;
    struct Mem<'a> {
        input: &'a [u8],
        out: vec::Vec<u8>,
    }
    impl Device for Mem<'_> {
        type Error = core::convert::Infallible;
        fn read(&mut self, buf: &mut [u8]) -> Result<usize, Self::Error> {
            let n = buf.len().min(self.input.len());
            buf[..n].copy_from_slice(&self.input[..n]);
            self.input = &self.input[n..];
            Ok(n)
        }
        fn write(&mut self, bytes: &[u8]) -> Result<(), Self::Error> {
            self.out.extend_from_slice(bytes);
            Ok(())
        }
    }
    let mut triangles = vec![[0u32; 3]; max_triangles];
    let mut links = vec![[0u32; 3]; max_triangles];
    let mut heads = vec![0u32; max_vertices];
    let mut splits = vec![Split::<u32>::EMPTY; max_vertices];
    let mut positions = vec![[0f32; 3]; max_vertices];
    let mut buf = vec![0u8; buffer];
    let storage = Storage {
        triangles: &mut triangles,
        links: &mut links,
        heads: &mut heads,
        splits: &mut splits,
    };
    let mut dev = Mem {
        input: stream,
        out: vec::Vec::new(),
    };
    let Ok(s) = run(&mut dev, storage, &mut positions, &mut buf);
    dev.out.extend_from_slice(&s.to_bytes());
    dev.out
}
