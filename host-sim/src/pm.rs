//! `host-sim pm`: progressive meshes. `encode` simplifies a mesh with a collapse log and writes
//! the library's progressive stream; `decode` feeds a stream to the library's incremental
//! decoder and writes a level; `levels` measures (and can draw) a ladder of levels. All the
//! work is the library's (`tinydecimate::progressive`, `tinydecimate::stream`); this is only
//! files and printing.

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

use anyhow::{anyhow, bail, Context, Result};
use tinydecimate::progressive::{Split, Storage};
use tinydecimate::stream::{self, Decoder, HEADER};
use tinydecimate::{Config, Progressive};

use crate::io::{self, MeshData};
use crate::metro::{metro, MetroOptions};
use crate::workspace::HostWorkspace;

/// `host-sim pm …`
#[derive(Clone, Debug, clap::Args)]
pub struct Args {
    #[command(subcommand)]
    pub command: Command,
}

/// The `pm` subcommands.
#[derive(Clone, Debug, clap::Subcommand)]
pub enum Command {
    /// Simplify with a collapse log and write the progressive stream (base mesh + vertex
    /// splits); prints its size, bytes per vertex split and the base mesh's size.
    Encode(EncodeArgs),
    /// Decode a stream (fed to the decoder in small pieces, as from a radio) and write one
    /// level of it.
    Decode(DecodeArgs),
    /// Metro error of a ladder of levels against the full mesh; optionally a picture strip.
    Levels(LevelsArgs),
    /// Stream a `.tdpm` into an emulated board through semihosting, in pieces of 1 to 128
    /// bytes, as over a radio link: print the mesh the device shows as bytes arrive and its
    /// Metro error, the emulated instructions per vertex split and per edge collapse, and
    /// check that the device's bytes equal the host's.
    Stream(StreamArgs),
}

/// `host-sim pm stream IN.tdpm`
#[derive(Clone, Debug, clap::Args)]
pub struct StreamArgs {
    /// Input stream.
    pub input: PathBuf,
    /// QEMU board (machine).
    #[arg(long, default_value = "mps2-an386")]
    pub board: String,
    /// Math backend of the firmware (the decoder's output does not depend on it).
    #[arg(long, value_enum, default_value_t = crate::backend::Backend::compiled())]
    pub backend: crate::backend::Backend,
    /// Kill QEMU after this many seconds.
    #[arg(long, default_value_t = 600)]
    pub timeout: u64,
}

/// `host-sim pm encode IN OUT.tdpm`
#[derive(Clone, Debug, clap::Args)]
pub struct EncodeArgs {
    /// Input mesh (OBJ, PLY or STL).
    pub input: PathBuf,
    /// Output stream.
    pub output: PathBuf,
    /// Triangles of the base mesh.
    #[arg(long, conflicts_with = "base_ratio")]
    pub base_triangles: Option<usize>,
    /// Base mesh as a fraction of the input's triangles, in [0, 1].
    #[arg(long, default_value_t = 0.02)]
    pub base_ratio: f32,
    /// Quantise positions to this many bits per coordinate (only 16 is supported).
    #[arg(long)]
    pub quantize: Option<u32>,
    /// Largest chunk payload in bytes (each chunk costs 9 bytes of framing and checksum).
    #[arg(long, default_value_t = 256)]
    pub chunk: u16,
}

/// `host-sim pm decode IN.tdpm OUT`
#[derive(Clone, Debug, clap::Args)]
pub struct DecodeArgs {
    /// Input stream.
    pub input: PathBuf,
    /// Output mesh (OBJ or PLY), in the stream's vertex numbering.
    pub output: PathBuf,
    /// Go to the finest level with at most this many triangles (default: full).
    #[arg(long)]
    pub triangles: Option<usize>,
    /// Feed the decoder this many bytes at a time.
    #[arg(long, default_value_t = 64)]
    pub piece: usize,
}

/// `host-sim pm levels IN.tdpm`
#[derive(Clone, Debug, clap::Args)]
pub struct LevelsArgs {
    /// Input stream.
    pub input: PathBuf,
    /// Fractions of the full mesh's triangles to measure (the base mesh is always first).
    #[arg(long, value_delimiter = ',', default_value = "0.05,0.1,0.25,0.5,1")]
    pub ladder: Vec<f64>,
    /// Write a PNG strip of the levels, side by side.
    #[arg(long)]
    pub strip: Option<PathBuf>,
}

/// `host-sim pm`.
pub fn run(args: &Args) -> Result<ExitCode> {
    match &args.command {
        Command::Encode(a) => encode(a),
        Command::Decode(a) => decode(a).map(|_| ExitCode::SUCCESS),
        Command::Levels(a) => levels(a),
        Command::Stream(a) => stream_on_board(a),
    }
}

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
        )
        .map_err(|e| anyhow!("tinydecimate: {e}"))?
        .record_into(&mut log);
    while !s.step(u32::MAX) {}
    let n = s.records().len();
    s.finish();
    log.truncate(n);
    Ok(log)
}

/// The stream of `mesh` simplified with `config`, and its sizes.
pub fn encode_mesh(
    mesh: &MeshData,
    config: &Config,
    quantised: bool,
    chunk: u16,
) -> Result<(Vec<u8>, stream::Encoded, Vec<u32>)> {
    let log = collapse_log(mesh, config)?;
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
    Ok((out, e, order))
}

fn encode(a: &EncodeArgs) -> Result<ExitCode> {
    let quantised = match a.quantize {
        None => false,
        Some(16) => true,
        Some(b) => bail!("--quantize {b}: only 16 bits per coordinate are supported"),
    };
    if !(0.0..=1.0).contains(&a.base_ratio) {
        bail!("--base-ratio {}: must be in [0, 1]", a.base_ratio);
    }
    let mesh = io::load(&a.input)?;
    let config = match a.base_triangles {
        Some(n) => Config::new().with_ratio(0.0).with_target_triangles(n),
        None => Config::new().with_ratio(a.base_ratio),
    };
    let start = Instant::now();
    let (bytes, e, order) = encode_mesh(&mesh, &config, quantised, a.chunk)?;
    let took = start.elapsed();
    std::fs::write(&a.output, &bytes).with_context(|| format!("writing {}", a.output.display()))?;
    let d = decode_bytes(&bytes, bytes.len(), None)?;
    let h = d.header;
    crate::outln!(
        "input            {} triangles, {} vertices",
        mesh.triangles.len(),
        mesh.positions.len()
    );
    crate::outln!(
        "base mesh        {} triangles, {} vertices, {} bytes (header, positions, triangles, framing)",
        h.base_triangles, h.base_vertices, e.base_bytes
    );
    crate::outln!("vertex splits    {}", e.splits);
    let per = |bits: u64| bits as f64 / 8.0 / e.splits.max(1) as f64;
    crate::outln!(
        "per split        {:.2} B connectivity + {:.1} B position ({})",
        per(e.split_connectivity_bits),
        per(e.split_position_bits),
        if quantised { "16-bit quantised" } else { "f32" }
    );
    crate::outln!(
        "stream           {} bytes ({} in all)",
        e.bytes,
        a.output.display()
    );
    if quantised {
        // Largest quantisation error, as a fraction of the diagonal.
        let diag = mesh.bbox_diagonal();
        let mut worst = 0f64;
        for (p, &old) in d.positions.iter().zip(&order) {
            let q = mesh.positions[old as usize];
            let e = (0..3)
                .map(|k| (p[k] as f64 - q[k] as f64).powi(2))
                .sum::<f64>()
                .sqrt();
            worst = worst.max(e);
        }
        crate::outln!(
            "quantisation     max {:.5} % of the diagonal",
            100.0 * worst / diag
        );
    }
    crate::outln!(
        "time             {:.1} ms (simplify, build the splits, encode)",
        took.as_secs_f64() * 1e3
    );
    Ok(ExitCode::SUCCESS)
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
            "not a progressive stream: a .tdpm file (`host-sim pm encode`) starts with `TDPM`, \
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

fn decode(a: &DecodeArgs) -> Result<()> {
    let bytes =
        std::fs::read(&a.input).with_context(|| format!("reading {}", a.input.display()))?;
    let start = Instant::now();
    let d = decode_bytes(&bytes, a.piece, a.triangles)?;
    let took = start.elapsed();
    io::save(
        &a.output,
        &MeshData {
            positions: d.positions.clone(),
            triangles: d.triangles.clone(),
        },
    )?;
    crate::outln!(
        "decoded {} bytes in {}-byte pieces: base {} triangles, full {} triangles, {} vertices",
        bytes.len(),
        a.piece,
        d.header.base_triangles,
        d.header.triangles,
        d.header.vertices
    );
    if let Some(e) = &d.partial {
        crate::outln!("{}", partial_line(e, d.finest_triangles));
    }
    crate::outln!(
        "wrote {} triangles to {} ({:.1} ms)",
        d.triangles.len(),
        a.output.display(),
        took.as_secs_f64() * 1e3
    );
    Ok(())
}

/// What a partial file decoded to, in one line.
fn partial_line(e: &Extent, triangles: usize) -> String {
    format!(
        "PARTIAL stream: the full mesh has not arrived ({} bytes of whole chunks); finest \
         complete level: {} of {} vertex splits ({triangles} of {} triangles, {} of {} vertices)",
        e.bytes,
        e.splits,
        e.total_splits(),
        e.header.triangles,
        e.header.base_vertices as usize + e.splits,
        e.header.vertices
    )
}

fn levels(a: &LevelsArgs) -> Result<ExitCode> {
    if let Some(f) = a.ladder.iter().find(|f| !(0.0..=1.0).contains(*f)) {
        bail!("--ladder {f}: fractions must be in [0, 1]");
    }
    let bytes =
        std::fs::read(&a.input).with_context(|| format!("reading {}", a.input.display()))?;
    // On a terminal, a bar once it takes over a second: decoding, then one Metro run per
    // level; the table is printed after it.
    let bar = crate::progress::Progress::new(
        "levels {bar:40} {pos}/{len} levels measured ({elapsed})",
        a.ladder.len() as u64 + 1,
    );
    bar.set(0);
    let d = decode_with(&bytes, bytes.len(), None, &a.ladder)?;
    bar.set_len(d.levels.len() as u64);
    let full = MeshData {
        positions: d.positions.clone(),
        triangles: d.triangles.clone(),
    };
    let mut rows = Vec::new();
    let mut meshes = Vec::new();
    for (lvl, tris) in &d.levels {
        let m = MeshData {
            positions: d.positions.clone(),
            triangles: tris.clone(),
        };
        let r = metro(&full, &m, &MetroOptions::default());
        rows.push(format!(
            "| {lvl} | {} | {:.4} | {:.4} |",
            m.triangles.len(),
            r.symmetric_mean_pct,
            r.hausdorff_pct
        ));
        meshes.push(m);
        bar.set(meshes.len() as u64);
    }
    bar.finish();
    if let Some(e) = &d.partial {
        crate::outln!(
            "{} (errors below are against that level)",
            partial_line(e, d.finest_triangles)
        );
    }
    crate::outln!("| level (splits) | triangles | mean error (% diag) | Hausdorff (% diag) |");
    crate::outln!("|---:|---:|---:|---:|");
    for r in rows {
        crate::outln!("{r}");
    }
    if let Some(path) = &a.strip {
        let view = crate::render::View::fit(&full);
        let images: Vec<_> = meshes
            .iter()
            .map(|m| crate::render::render(m, &view))
            .collect();
        let (w, h) = (images[0].width(), images[0].height());
        let mut strip = image::RgbImage::new(w * images.len() as u32, h);
        for (i, img) in images.iter().enumerate() {
            image::imageops::replace(&mut strip, img, (i as u32 * w) as i64, 0);
        }
        strip
            .save(path)
            .with_context(|| format!("writing {}", path.display()))?;
        crate::outln!("strip: {} ({} levels)", path.display(), images.len());
    }
    Ok(ExitCode::SUCCESS)
}

/// `host-sim pm stream`: the streaming demo on an emulated board.
fn stream_on_board(a: &StreamArgs) -> Result<ExitCode> {
    use crate::qemu;
    use meshfmt::pm::{self, Tag};
    let bytes =
        std::fs::read(&a.input).with_context(|| format!("reading {}", a.input.display()))?;
    let board = qemu::board(&a.board)?;
    // Before any build or run: is it a stream, and does the board hold it?
    let h = extent(&bytes)
        .with_context(|| a.input.display().to_string())?
        .header;
    let cap = crate::qemu::StreamCapacity::of(board.name)
        .ok_or_else(|| anyhow!("{}: no streaming firmware for this board", board.name))?;
    let buffer = usize::from(h.max_payload) + stream::CHUNK_OVERHEAD;
    if h.vertices as usize > cap.vertices
        || h.triangles as usize > cap.triangles
        || buffer > cap.buffer
    {
        bail!(
            "{}: the stream's full mesh has {} vertices and {} triangles, in chunks of up to {} \
             bytes; {} holds streams of up to {} vertices, {} triangles and chunks of up to {} \
             bytes. Encode a mesh that fits (e.g. `host-sim simplify IN small.obj \
             --target-triangles {}`, then `host-sim pm encode small.obj OUT.tdpm --chunk {}`){}",
            a.input.display(),
            h.vertices,
            h.triangles,
            h.max_payload,
            board.name,
            cap.vertices,
            cap.triangles,
            cap.buffer - stream::CHUNK_OVERHEAD,
            // A closed mesh has about twice as many triangles as vertices: a margin below.
            cap.triangles
                .min(cap.vertices * 19 / 10)
                .min(h.triangles as usize),
            usize::from(h.max_payload).min(cap.buffer - stream::CHUNK_OVERHEAD),
            if board.name.starts_with("mps2") {
                ""
            } else {
                ", or a 4 MB board (--board mps2-an386)"
            }
        );
    }
    if let Some(code) = qemu::preflight(&[board])? {
        return Ok(code);
    }
    let elf = qemu::build(board, a.backend, true)?;
    let t0 = Instant::now();
    let run = qemu::run_stream_bytes(
        board,
        &elf,
        &bytes,
        std::time::Duration::from_secs(a.timeout),
    )?;
    let took = t0.elapsed();
    let out = match (&run.result, run.ok()) {
        (Some(out), true) => out.clone(),
        _ => bail!("{}: no output: {}", board.name, run.describe()),
    };
    let (records, s) =
        pm::parse(&out).ok_or_else(|| anyhow!("{}: malformed output file", board.name))?;
    // The host's run of the same code, and the full mesh to measure against.
    let host = pm::run_in_memory(&bytes, 1 << 20, 1 << 21, 65_535 + stream::CHUNK_OVERHEAD);
    let same = pm::compared(&host) == pm::compared(&out);
    let full = decode_bytes(&bytes, bytes.len(), None).ok();
    crate::outln!(
        "{} ({}): {} bytes streamed in pieces of {:?} bytes, {:.1} s under QEMU",
        board.name,
        board.core,
        s.bytes,
        pm::FEED,
        took.as_secs_f64()
    );
    crate::outln!();
    crate::outln!("| bytes received | triangles shown | vertices | mean error (% diag) | Hausdorff (% diag) |");
    crate::outln!("|---:|---:|---:|---:|---:|");
    let positions = records
        .iter()
        .find(|r| r.tag == Tag::Positions as u32)
        .map(|r| r.positions.clone())
        .unwrap_or_default();
    for r in records
        .iter()
        .filter(|r| r.tag == Tag::Arrived as u32 || r.tag == Tag::Final as u32)
    {
        let (mean, haus) = match &full {
            Some(f) if !r.triangles.is_empty() => {
                let full = MeshData {
                    positions: f.positions.clone(),
                    triangles: f.triangles.clone(),
                };
                let m = MeshData {
                    positions: positions.clone(),
                    triangles: r.triangles.clone(),
                };
                let e = metro(&full, &m, &MetroOptions::default());
                (
                    format!("{:.4}", e.symmetric_mean_pct),
                    format!("{:.4}", e.hausdorff_pct),
                )
            }
            _ => ("-".into(), "-".into()),
        };
        crate::outln!(
            "| {}{} | {} | {} | {mean} | {haus} |",
            r.bytes,
            if r.tag == Tag::Final as u32 {
                " (end)"
            } else {
                ""
            },
            r.triangles.len(),
            r.vertices
        );
    }
    crate::outln!();
    match s.error {
        None => crate::outln!(
            "complete: {} triangles, {} vertices, {} vertex splits",
            s.triangles,
            s.vertices,
            s.splits
        ),
        Some(e) => crate::outln!(
            "stream error {} ({}, {}): the device kept {} triangles",
            e.code,
            e.a,
            e.b,
            s.triangles
        ),
    }
    let per = |ticks: u64| board.instructions(ticks) as f64 / f64::from(s.splits.max(1));
    crate::outln!(
        "emulated instructions: {:.0} per vertex split while decoding (checksums and bit unpacking included), \
         {:.0} per edge collapse and {:.0} per vertex split moving the slider (coarsen / refine all {} levels)",
        per(s.decode_ticks),
        per(s.coarsen_ticks),
        per(s.refine_ticks),
        s.splits
    );
    crate::outln!("stack of the decoder run: {} B", s.stack_bytes);
    crate::outln!(
        "device output {} the host's ({} bytes)",
        if same { "identical to" } else { "DIFFERS from" },
        out.len()
    );
    Ok(if same {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}

