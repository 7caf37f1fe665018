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
use crate::simplify::HostWorkspace;

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
    #[arg(long, value_enum, default_value_t = crate::golden::Backend::compiled())]
    pub backend: crate::golden::Backend,
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
    /// The header.
    pub header: stream::Header,
    /// Positions of every vertex of the full mesh.
    pub positions: Vec<[f32; 3]>,
    /// The level's triangles.
    pub triangles: Vec<[u32; 3]>,
    /// Triangles of every level, base first (only when asked for).
    pub levels: Vec<Vec<[u32; 3]>>,
}

/// Feeds `bytes` to the library's decoder `piece` bytes at a time; goes to `level` (finest
/// with at most that many triangles) at the end.
pub fn decode_bytes(bytes: &[u8], piece: usize, level: Option<usize>) -> Result<Decoded> {
    decode_with(bytes, piece, level, false)
}

fn decode_with(bytes: &[u8], piece: usize, level: Option<usize>, keep: bool) -> Result<Decoded> {
    if bytes.len() < HEADER {
        bail!(
            "stream: {} bytes, shorter than its {HEADER}-byte header",
            bytes.len()
        );
    }
    let u32_at =
        |o: usize| u32::from_le_bytes([bytes[o], bytes[o + 1], bytes[o + 2], bytes[o + 3]]);
    // Storage sized from the header's counts (the decoder checks them against it).
    let (v, t) = (u32_at(8) as usize, u32_at(20) as usize);
    if v > 1 << 26 || t > 1 << 27 {
        bail!("stream: header claims {v} vertices and {t} triangles");
    }
    let mut store = Store::new(v, t);
    let mut positions = vec![[0f32; 3]; v];
    let mut buf = vec![0u8; 65_535 + stream::CHUNK_OVERHEAD];
    let mut d = Decoder::new(store.storage(), &mut positions, &mut buf);
    for p in bytes.chunks(piece.max(1)) {
        d.push(p).map_err(|e| anyhow!("stream: {e}"))?;
    }
    d.finish().map_err(|e| anyhow!("stream: {e}"))?;
    let header = d.header().ok_or_else(|| anyhow!("stream: no header"))?;
    let pm = d.progressive();
    let mut levels = Vec::new();
    if keep {
        pm.set_level(0);
        levels.push(pm.triangles().to_vec());
        while pm.refine(1) == 1 {
            levels.push(pm.triangles().to_vec());
        }
    }
    pm.set_level(level.unwrap_or(usize::MAX));
    let triangles = pm.triangles().to_vec();
    let positions = d.positions().to_vec();
    Ok(Decoded {
        header,
        positions,
        triangles,
        levels,
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
    crate::outln!(
        "wrote {} triangles to {} ({:.1} ms)",
        d.triangles.len(),
        a.output.display(),
        took.as_secs_f64() * 1e3
    );
    Ok(())
}

fn levels(a: &LevelsArgs) -> Result<ExitCode> {
    let bytes =
        std::fs::read(&a.input).with_context(|| format!("reading {}", a.input.display()))?;
    let d = decode_with(&bytes, bytes.len(), None, true)?;
    let full = MeshData {
        positions: d.positions.clone(),
        triangles: d.triangles.clone(),
    };
    let nt = d.triangles.len();
    let mut picks: Vec<usize> = vec![0];
    for f in &a.ladder {
        if !(0.0..=1.0).contains(f) {
            bail!("--ladder {f}: fractions must be in [0, 1]");
        }
        let n = (f * nt as f64).floor() as usize;
        // The finest level with at most n triangles.
        let lvl = d.levels.iter().rposition(|l| l.len() <= n).unwrap_or(0);
        if !picks.contains(&lvl) {
            picks.push(lvl);
        }
    }
    crate::outln!("| level (splits) | triangles | mean error (% diag) | Hausdorff (% diag) |");
    crate::outln!("|---:|---:|---:|---:|");
    let mut meshes = Vec::new();
    for &lvl in &picks {
        let m = MeshData {
            positions: d.positions.clone(),
            triangles: d.levels[lvl].clone(),
        };
        let r = metro(&full, &m, &MetroOptions::default());
        crate::outln!(
            "| {lvl} | {} | {:.4} | {:.4} |",
            m.triangles.len(),
            r.symmetric_mean_pct,
            r.hausdorff_pct
        );
        meshes.push(m);
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
