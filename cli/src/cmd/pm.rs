//! `tinydecimate pm`: progressive meshes. `encode` simplifies a mesh with a collapse log and writes
//! the library's progressive stream; `decode` feeds a stream to the library's incremental
//! decoder and writes a level; `levels` measures (and can draw) a ladder of levels; `stream`
//! feeds a stream to an emulated board. The work is the library's, through [`crate::pm`]; this
//! is only files and printing.

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

use anyhow::{anyhow, bail, Context, Result};
use tinydecimate::{Config, Target};

use crate::io::{self, MeshData};
use crate::metro::{metro, MetroOptions};
use crate::pm::{decode_bytes, decode_with, encode_mesh_reporting, Extent};

/// `tinydecimate pm …`
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
}

/// `tinydecimate pm encode IN OUT.tdpm`
#[derive(Clone, Debug, clap::Args)]
pub struct EncodeArgs {
    /// Input mesh (OBJ, PLY, STL or glTF).
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
    /// Largest normal turn of a triangle in one collapse, degrees (60 by default), as in
    /// `simplify`: a larger one lets the base get smaller.
    #[arg(long, allow_negative_numbers = true)]
    pub max_turn: Option<f32>,
    /// Smallest triangle quality a collapse may create (0.05 by default), as in `simplify`.
    #[arg(long, allow_negative_numbers = true)]
    pub min_quality: Option<f32>,
    /// Turn feature detection off (every vertex may be collapsed), as in `simplify`.
    #[arg(long)]
    pub no_features: bool,
}

/// `tinydecimate pm decode IN.tdpm OUT`
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

/// `tinydecimate pm levels IN.tdpm`
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

/// `tinydecimate pm`.
pub fn run(args: &Args) -> Result<ExitCode> {
    match &args.command {
        Command::Encode(a) => encode(a),
        Command::Decode(a) => decode(a).map(|_| ExitCode::SUCCESS),
        Command::Levels(a) => levels(a),
    }
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
    let mesh = io::load_noting(&a.input)?;
    let mut config = match a.base_triangles {
        Some(n) => Config::new().with_target(Target::Triangles(n)),
        None => Config::new().with_ratio(a.base_ratio),
    };
    if let Some(x) = a.max_turn {
        config = config.with_max_normal_turn(x);
    }
    if let Some(x) = a.min_quality {
        config = config.with_min_quality(x);
    }
    config = config.with_features(!a.no_features);
    config
        .validate()
        .map_err(|e| anyhow!("configuration: {e}"))?;
    let start = Instant::now();
    let (bytes, e, order, report) = encode_mesh_reporting(&mesh, &config, quantised, a.chunk)?;
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
    if let Some(line) = base_shortfall(&report, &config) {
        eprintln!("{line}");
    }
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

/// One line when the base mesh is larger than asked: what stopped the simplification (as
/// `simplify`'s advice reads it) and what relaxes it; `None` when the base reached its target.
fn base_shortfall(r: &tinydecimate::Report, config: &Config) -> Option<String> {
    use crate::cmd::simplify::advice::{advise, Outcome};
    let a = advise(&Outcome::from(r).in_use(config), "", "")?;
    // `pm encode` has these options of `simplify`'s and no other.
    let ours = ["--max-turn", "--min-quality", "--no-features"];
    let relax: Vec<&str> = a
        .relax
        .iter()
        .filter(|x| ours.contains(&x.option))
        .map(|x| x.example)
        .collect();
    Some(format!(
        "warning: base mesh {} triangles, more than the {} asked for: the collapses stopped \
         ({:?}), {} refused most{}; {}",
        r.triangles_out,
        r.target_triangles,
        r.stop,
        a.limit,
        if a.count > 0 {
            format!(" ({} {})", a.count, a.unit)
        } else {
            String::new()
        },
        if relax.is_empty() {
            "no option of pm encode relaxes it: this is the smallest base it makes".to_string()
        } else {
            format!("relax with {}: each lets it go further", relax.join(", "))
        }
    ))
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
