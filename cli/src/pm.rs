//! Progressive meshes on the host: a mesh simplified with a collapse log and encoded as the
//! library's progressive stream ([`encode_mesh`]), and a stream decoded to a level as it
//! arrives ([`decode_with`], [`extent`] of a partial stream). All the work is the library's
//! (`tinydecimate::progressive`, `tinydecimate::stream`). The command is `tinydecimate pm`
//! ([`crate::cmd::pm`]).

use anyhow::{anyhow, bail, Result};
use tinydecimate::progressive::{Split, Storage};
use tinydecimate::stream::{self, Decoder, HEADER};
use tinydecimate::{Config, Progressive};

use crate::io::MeshData;
use crate::workspace::HostWorkspace;

/// Owned storage of a `Progressive` over `u32` indices.
pub struct Store {
    tris: Vec<[u32; 3]>,
    links: Vec<[u32; 3]>,
    heads: Vec<u32>,
    splits: Vec<Split<u32>>,
}

impl Store {
    /// Storage for `v` vertices and `t` triangles.
    pub fn new(v: usize, t: usize) -> Self {
        Store {
            tris: vec![[0; 3]; t],
            links: vec![[0; 3]; t],
            heads: vec![0; v],
            splits: vec![Split::EMPTY; v],
        }
    }

    /// The library's view of it.
    pub fn storage(&mut self) -> Storage<'_, u32> {
        Storage {
            triangles: &mut self.tris,
            links: &mut self.links,
            heads: &mut self.heads,
            splits: &mut self.splits,
        }
    }
}

/// Simplifies `mesh` with `config` and a collapse log; returns the log.
pub fn collapse_log(mesh: &MeshData, config: &Config) -> Result<Vec<[u32; 2]>> {
    collapse_log_reporting(mesh, config).map(|(log, _)| log)
}

/// [`collapse_log`] and the run's report (whether the base reached its target, and why not).
pub fn collapse_log_reporting(
    mesh: &MeshData,
    config: &Config,
) -> Result<(Vec<[u32; 2]>, tinydecimate::Report)> {
    let mut ws = HostWorkspace::for_mesh(mesh);
    let mut tris = mesh.triangles.clone();
    let mut log = vec![[0u32; 2]; mesh.positions.len()];
    let p = tinydecimate::Positions::Read(&mesh.positions);
    let mut s = ws
        .storage()
        .start(
            p,
            &mut tris,
            config,
            tinydecimate::Builtin::new(),
            tinydecimate::NoBound,
            tinydecimate::EdgeCollapse,
        )
        .map_err(|e| anyhow!("tinydecimate: {e}"))?
        .record_into(&mut log);
    while !s.step(u32::MAX) {}
    let n = s.records().len();
    let report = s.finish();
    log.truncate(n);
    Ok((log, report))
}

/// The stream of `mesh` simplified with `config`, and its sizes.
pub fn encode_mesh(
    mesh: &MeshData,
    config: &Config,
    quantised: bool,
    chunk: u16,
) -> Result<(Vec<u8>, stream::Encoded, Vec<u32>)> {
    encode_mesh_reporting(mesh, config, quantised, chunk).map(|(b, e, o, _)| (b, e, o))
}

/// [`encode_mesh`] and the report of the simplification that made the base mesh.
pub fn encode_mesh_reporting(
    mesh: &MeshData,
    config: &Config,
    quantised: bool,
    chunk: u16,
) -> Result<(Vec<u8>, stream::Encoded, Vec<u32>, tinydecimate::Report)> {
    let (log, report) = collapse_log_reporting(mesh, config)?;
    let (v, t) = (mesh.positions.len(), mesh.triangles.len());
    let mut store = Store::new(v, t);
    let (mut order, mut scratch) = (vec![0u32; v], vec![0u32; t]);
    let mut pm = Progressive::from_log(
        &mesh.triangles,
        v,
        &log,
        store.storage(),
        &mut order,
        &mut scratch,
    )
    .map_err(|e| anyhow!("tinydecimate: {e}"))?;
    let mut out = vec![0u8; HEADER + 64 * (t + v) + 4096];
    let e = stream::encode(&mut pm, &mesh.positions, &order, quantised, chunk, &mut out)
        .map_err(|e| anyhow!("tinydecimate: {e}"))?;
    out.truncate(e.bytes);
    Ok((out, e, order, report))
}

/// A decoded stream, at a level.
pub struct Decoded {
    /// The header (of the whole stream, also when the file holds only part of it).
    pub header: stream::Header,
    /// Positions of every vertex decoded (the full mesh's, unless the file is partial).
    pub positions: Vec<[f32; 3]>,
    /// The level's triangles.
    pub triangles: Vec<[u32; 3]>,
    /// The levels asked for by ladder, base first: (level, its triangles).
    pub levels: Vec<(usize, Vec<[u32; 3]>)>,
    /// Triangles of the finest level decoded.
    pub finest_triangles: usize,
    /// Set when the file ends before the full mesh: what it holds.
    pub partial: Option<Extent>,
}

/// What a stream file holds, read without decoding it: the header (checked by the library's
/// decoder first: magic, version, checksum, consistent counts) and the framing of the complete
/// chunks after it. Every count here is backed by bytes of the file (a chunk's item count is
/// capped by the bits its payload has), so storage sized from it is bounded by the file's
/// size, whatever the header claims.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Extent {
    /// The stream's header.
    pub header: stream::Header,
    /// Bytes of the header and the complete chunks: the part that can be decoded.
    pub bytes: usize,
    /// Base positions in those chunks.
    pub positions: usize,
    /// Base triangles in those chunks.
    pub base_triangles: usize,
    /// Vertex splits in those chunks.
    pub splits: usize,
}

impl Extent {
    /// Whether the file holds the whole stream.
    pub fn complete(&self) -> bool {
        let h = &self.header;
        self.positions == h.base_vertices as usize
            && self.base_triangles == h.base_triangles as usize
            && self.splits == (h.vertices - h.base_vertices) as usize
    }

    /// Vertex splits of the full mesh.
    pub fn total_splits(&self) -> usize {
        (self.header.vertices - self.header.base_vertices) as usize
    }

    /// Whether the base mesh has arrived whole (else no level can be shown).
    pub fn has_base(&self) -> bool {
        self.positions == self.header.base_vertices as usize
            && self.base_triangles == self.header.base_triangles as usize
    }
}

/// Bits needed for a number below `n` (the stream's `bits(n)`).
fn bits(n: usize) -> usize {
    if n <= 1 {
        0
    } else {
        (usize::BITS - (n - 1).leading_zeros()) as usize
    }
}

/// Reads a stream file's header and chunk framing ([`Extent`]); allocates nothing that
/// depends on a count the file claims.
pub fn extent(bytes: &[u8]) -> Result<Extent> {
    if !bytes.starts_with(b"TDPM") {
        bail!(
            "not a progressive stream: a .tdpm file (`tinydecimate pm encode`) starts with `TDPM`, \
             this one with {:?}",
            String::from_utf8_lossy(&bytes[..bytes.len().min(4)])
        );
    }
    if bytes.len() < HEADER {
        bail!(
            "progressive stream cut inside its {HEADER}-byte header ({} bytes)",
            bytes.len()
        );
    }
    // The library checks the header (magic, version, checksum, counts) before anything is
    // sized from it: a decoder with no storage at all stops at its first capacity check,
    // which comes after those.
    let mut store = Store::new(0, 0);
    let mut none: [[f32; 3]; 0] = [];
    let mut buf = [0u8; HEADER];
    let mut d = Decoder::new(store.storage(), &mut none, &mut buf);
    match d.push(&bytes[..HEADER]) {
        Ok(()) | Err(stream::StreamError::Capacity { .. }) => {}
        Err(stream::StreamError::BadMagic) => bail!("not a progressive stream (bad magic)"),
        Err(e) => bail!("progressive stream header: {e}"),
    }
    let u32_at =
        |o: usize| u32::from_le_bytes([bytes[o], bytes[o + 1], bytes[o + 2], bytes[o + 3]]);
    let f32_at = |o: usize| f32::from_bits(u32_at(o));
    let header = stream::Header {
        index_width: bytes[5],
        quantised: bytes[6] & 1 != 0,
        vertices: u32_at(8),
        base_vertices: u32_at(12),
        base_triangles: u32_at(16),
        triangles: u32_at(20),
        max_payload: u16::from_le_bytes([bytes[24], bytes[25]]),
        min: [f32_at(28), f32_at(32), f32_at(36)],
        max: [f32_at(40), f32_at(44), f32_at(48)],
    };
    let mut e = Extent {
        header,
        bytes: HEADER,
        positions: 0,
        base_triangles: 0,
        splits: 0,
    };
    // Chunks: len (u16), kind (u8), count (u16), payload, CRC-32.
    let position_bits = if header.quantised { 48 } else { 96 };
    let mut at = HEADER;
    let mut chunks = 0u32;
    while let Some(head) = bytes.get(at..at + 5) {
        let len = usize::from(u16::from_le_bytes([head[0], head[1]]));
        let count = usize::from(u16::from_le_bytes([head[3], head[4]]));
        let end = at + len + stream::CHUNK_OVERHEAD;
        if len > usize::from(header.max_payload) || !(1..=3).contains(&head[2]) {
            bail!(
                "progressive stream: chunk {} (byte offset {at}) is malformed",
                chunks + 1
            );
        }
        if end > bytes.len() {
            break; // the file ends inside this chunk
        }
        chunks += 1;
        let payload_bits = 8 * len;
        let fits = |per_item: usize| count.min(payload_bits / per_item.max(1));
        match head[2] {
            1 => e.positions += fits(position_bits),
            2 => e.base_triangles += fits(3 * bits(header.base_vertices as usize)),
            // At least: mode bit, restored bit, the position.
            _ => e.splits += fits(2 + position_bits),
        }
        e.bytes = end;
        at = end;
    }
    Ok(e)
}

/// Feeds `bytes` to the library's decoder `piece` bytes at a time; goes to `level` (finest
/// with at most that many triangles) at the end.
pub fn decode_bytes(bytes: &[u8], piece: usize, level: Option<usize>) -> Result<Decoded> {
    decode_with(bytes, piece, level, &[])
}

/// [`decode_bytes`], keeping the base mesh and, for each fraction of `ladder`, the finest level
/// with at most that fraction of the finest level's triangles. A file that holds only the
/// first part of a stream (as it arrives) decodes to its finest complete level, and
/// [`Decoded::partial`] says how far it got.
pub fn decode_with(
    bytes: &[u8],
    piece: usize,
    level: Option<usize>,
    ladder: &[f64],
) -> Result<Decoded> {
    let e = extent(bytes)?;
    let h = e.header;
    // Storage from what the file holds, never from what the header claims alone.
    let (v, t, input): (usize, usize, std::borrow::Cow<'_, [u8]>) = if e.complete() {
        let t = h.triangles as usize;
        if t > h.base_triangles as usize + 2 * e.splits {
            bail!(
                "progressive stream: the header claims {t} triangles, more than its base mesh \
                 and {} vertex splits can make",
                e.splits
            );
        }
        (h.vertices as usize, t, bytes.into())
    } else {
        if !e.has_base() {
            bail!(
                "progressive stream ends before its base mesh ({} of {} positions, {} of {} \
                 triangles in {} bytes): nothing to show yet",
                e.positions,
                h.base_vertices,
                e.base_triangles,
                h.base_triangles,
                bytes.len()
            );
        }
        // The complete chunks, under a header that says they are all there is (the splits
        // of a stream do not depend on its length), so the decoder ends at the finest level
        // that arrived.
        let v = h.base_vertices as usize + e.splits;
        let t = (h.triangles as usize).min(h.base_triangles as usize + 2 * e.splits);
        let mut prefix = bytes[..e.bytes].to_vec();
        prefix[8..12].copy_from_slice(&(v as u32).to_le_bytes());
        prefix[20..24].copy_from_slice(&(t as u32).to_le_bytes());
        let c = stream::crc32(&prefix[..52]);
        prefix[52..56].copy_from_slice(&c.to_le_bytes());
        (v, t, prefix.into())
    };
    let mut store = Store::new(v, t);
    let mut positions = vec![[0f32; 3]; v];
    let mut buf = vec![0u8; usize::from(h.max_payload) + stream::CHUNK_OVERHEAD];
    let mut d = Decoder::new(store.storage(), &mut positions, &mut buf);
    for p in input.chunks(piece.max(1)) {
        d.push(p).map_err(|e| anyhow!("stream: {e}"))?;
    }
    d.finish().map_err(|e| anyhow!("stream: {e}"))?;
    let pm = d.progressive();
    let finest = pm.level();
    let finest_triangles = pm.triangles().len();
    let mut levels = Vec::new();
    if !ladder.is_empty() {
        // Triangles per level, then the picks: the base, and the finest level under each
        // fraction.
        pm.set_level(0);
        let mut counts = vec![pm.triangles().len()];
        while pm.refine(1) == 1 {
            counts.push(pm.triangles().len());
        }
        let mut picks = vec![0usize];
        for f in ladder {
            let n = (f * finest_triangles as f64).floor() as usize;
            let lvl = counts.iter().rposition(|&c| c <= n).unwrap_or(0);
            if !picks.contains(&lvl) {
                picks.push(lvl);
            }
        }
        for lvl in picks {
            pm.set_level(0);
            pm.refine(lvl);
            levels.push((lvl, pm.triangles().to_vec()));
        }
        pm.refine(finest);
    }
    pm.set_level(level.unwrap_or(usize::MAX));
    let triangles = pm.triangles().to_vec();
    let positions = d.positions().to_vec();
    Ok(Decoded {
        header: h,
        positions,
        triangles,
        levels,
        finest_triangles,
        partial: (!e.complete()).then_some(e),
    })
}
