//! `host-sim golden`: checks the golden files of `tests/golden` against the library on the
//! host, or rewrites them (`--bless`).

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Result;
use meshfmt::IndexType;

use crate::backend::{reinvoke, Backend};
use crate::golden::{bless, check_host, default_dir, stream, Verdict};

/// `host-sim golden`: checks or rewrites the golden files.
#[derive(Clone, Debug, clap::Args)]
pub struct Args {
    /// Run every case on the host and compare with the golden files (the default). Exit 1 on
    /// any difference, printing the first differing triangle.
    #[arg(long, conflicts_with = "bless")]
    pub check: bool,
    /// Recompute every case on the host and rewrite the golden files; print per case the old
    /// and new hash and counts.
    #[arg(long)]
    pub bless: bool,
    /// Math backend of the library (default: the one host-sim was built with). Another one
    /// re-runs host-sim through `cargo run` with or without `--features micromath`.
    #[arg(long, value_enum)]
    pub backend: Option<Backend>,
    /// The golden directory (`cases.toml`, `libm/`, `micromath/`).
    #[arg(long, value_name = "DIR", default_value_os_t = default_dir())]
    pub dir: PathBuf,
}

/// Runs `host-sim golden`.
pub fn run(a: &Args) -> Result<ExitCode> {
    let backend = a.backend.unwrap_or(Backend::compiled());
    if backend != Backend::compiled() {
        return reinvoke(backend);
    }
    if a.bless {
        crate::outln!(
            "blessing {} with the {backend} backend:",
            a.dir.join(backend.name()).display()
        );
        for l in bless(&a.dir, backend)? {
            crate::outln!("  {l}");
        }
        for l in stream::bless(&a.dir, backend)? {
            crate::outln!("  {l}");
        }
        return Ok(ExitCode::SUCCESS);
    }
    crate::outln!(
        "checking {} against the library on the host ({backend}):",
        a.dir.join(backend.name()).display()
    );
    let results = check_host(&a.dir, backend)?;
    let mut failed = 0;
    for (case, v) in &results {
        crate::outln!(
            "  {:<28} {:>4} V {:>5} T {:<3}  {}",
            case.name,
            case.positions.len(),
            case.triangles.len(),
            if case.index_type == IndexType::U16 {
                "u16"
            } else {
                "u32"
            },
            v.cell()
        );
        match v {
            Verdict::Diff(d) => d.iter().for_each(|l| crate::outln!("      {l}")),
            Verdict::Failed(why) | Verdict::Skipped(why) => crate::outln!("      {why}"),
            Verdict::Identical => {}
        }
        failed += usize::from(v.is_failure());
    }
    let streams = stream::check_host(&a.dir, backend)?;
    for (case, v) in &streams {
        crate::outln!(
            "  {:<28} {:>4} V {:>5} T tdpm  {}",
            case.name(),
            case.vertices,
            case.triangles,
            v.cell()
        );
        match v {
            Verdict::Diff(d) => d.iter().for_each(|l| crate::outln!("      {l}")),
            Verdict::Failed(why) | Verdict::Skipped(why) => crate::outln!("      {why}"),
            Verdict::Identical => {}
        }
        failed += usize::from(v.is_failure());
    }
    let total = results.len() + streams.len();
    if failed == 0 {
        crate::outln!("{total} cases identical");
        Ok(ExitCode::SUCCESS)
    } else {
        crate::outln!(
            "{failed} of {total} cases differ; if the change is intended: host-sim golden --bless --backend {backend}"
        );
        Ok(ExitCode::from(1))
    }
}
