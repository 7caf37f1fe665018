//! `host-sim stream IN.tdpm`: a progressive stream (`tinydecimate pm encode`) fed to an
//! emulated board through semihosting, in pieces of 1 to 128 bytes, as over a radio link.

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

use anyhow::{anyhow, bail, Context, Result};
use tinydecimate::stream;

use crate::io::MeshData;
use crate::metro::{metro, MetroOptions};
use crate::pm::{decode_bytes, extent};

/// `host-sim stream IN.tdpm`
#[derive(Clone, Debug, clap::Args)]
pub struct Args {
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

/// `host-sim stream`: the streaming demo on an emulated board.
pub fn run(a: &Args) -> Result<ExitCode> {
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
             bytes. Encode a mesh that fits (e.g. `tinydecimate simplify IN small.obj \
             --target-triangles {}`, then `tinydecimate pm encode small.obj OUT.tdpm --chunk {}`){}",
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
