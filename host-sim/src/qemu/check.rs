//! `host-sim qemu [--check]`: every case and progressive stream on the host and on each board,
//! compared with the golden files or a fresh host run, printed as a table cases x boards.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use anyhow::{bail, Result};

use super::build::build;
use super::run::{run_case, run_stream_bytes};
use super::{against_expected_skips, Board};
use crate::backend::Backend;
use crate::golden::stream::StreamCase;
use crate::golden::{self, Case, Golden, Verdict};

/// What the boards' outputs are compared with.
#[derive(Clone, Debug)]
pub enum Expected {
    /// The golden files in this directory (`<backend>/<case>.txt|.bin`); the host is checked
    /// against them too.
    Golden(PathBuf),
    /// A fresh run of the library on the host.
    Host,
}

/// Runs `cases` and the progressive `streams` on the host and on every board in `boards` and
/// compares each output with the expectation. Prints a table cases × (host, boards) of identical / skipped / DIFF / FAILED,
/// then a line for every cell that is not identical (board, case, first differing triangle or
/// why it was skipped). Returns how many cells are DIFF or FAILED.
pub fn check_boards(
    boards: &[&'static Board],
    backend: Backend,
    cases: &[Case],
    streams: &[StreamCase],
    expected: &Expected,
    timeout: Duration,
    verbose: bool,
) -> Result<usize> {
    // 1. The host: its verdicts and what every board is compared with.
    let (host, expect, stream_expect) = expectations(backend, cases, streams, expected)?;
    let names: Vec<&str> = cases
        .iter()
        .map(|c| c.name.as_str())
        .chain(streams.iter().map(|c| c.name()))
        .collect();
    let mut columns: Vec<(String, Vec<Verdict>)> = vec![("host".into(), host)];
    // 2. One column per board.
    for b in boards {
        let t0 = Instant::now();
        // A failed build fails this board's column, not the whole check.
        let col = match build(b, backend, true) {
            Ok(elf) => board_column(
                b,
                &elf,
                t0,
                backend,
                cases,
                streams,
                (&expect, &stream_expect),
                timeout,
                verbose,
            )?,
            Err(e) => {
                let why = format!("firmware build failed: {e:#}");
                eprintln!("{:<20} {why}", b.name);
                names.iter().map(|_| Verdict::Failed(why.clone())).collect()
            }
        };
        columns.push((b.name.to_string(), col));
    }
    // 3. The table and a line for every cell that is not identical.
    print_table(backend, expected, &names, &columns)
}

/// The goldens a run is compared with (`None`: no golden file), per case and per stream, and
/// the host's own verdicts.
#[allow(clippy::type_complexity)]
fn expectations(
    backend: Backend,
    cases: &[Case],
    streams: &[StreamCase],
    expected: &Expected,
) -> Result<(Vec<Verdict>, Vec<Option<Golden>>, Vec<Option<Golden>>)> {
    let mut expect: Vec<Option<Golden>> = Vec::new();
    let mut host = Vec::new();
    for case in cases {
        let now = golden::reference(case)?;
        match expected {
            Expected::Golden(dir) => match Golden::load(dir, backend, &case.name)? {
                Some(g) => {
                    host.push(golden::judge(case, backend, &g, &now)?);
                    expect.push(Some(g));
                }
                None => {
                    host.push(Verdict::Failed(format!(
                        "no golden files {}/{backend}/{}.txt|.bin",
                        dir.display(),
                        case.name
                    )));
                    expect.push(None);
                }
            },
            Expected::Host => {
                host.push(Verdict::Identical);
                expect.push(Some(Golden::from_outcome(case, backend, &now)?));
            }
        }
    }
    // Stream cases: golden files only.
    let mut stream_expect: Vec<Option<Golden>> = Vec::new();
    for sc in streams {
        let now = crate::golden::stream::reference(sc);
        let dir = match expected {
            Expected::Golden(dir) => dir,
            Expected::Host => bail!("stream cases are checked against golden files only"),
        };
        match Golden::load(dir, backend, sc.name())? {
            Some(g) => {
                host.push(crate::golden::stream::judge(sc, backend, &g, &now));
                stream_expect.push(Some(g));
            }
            None => {
                host.push(Verdict::Failed(format!(
                    "no golden files {}/{backend}/{}.txt|.bin",
                    dir.display(),
                    sc.name()
                )));
                stream_expect.push(None);
            }
        }
    }
    Ok((host, expect, stream_expect))
}

/// One board's column: every case and stream run on it (the image `elf`, built since `t0`),
/// judged.
#[allow(clippy::too_many_arguments)]
fn board_column(
    b: &'static Board,
    elf: &Path,
    t0: Instant,
    backend: Backend,
    cases: &[Case],
    streams: &[StreamCase],
    (expect, stream_expect): (&[Option<Golden>], &[Option<Golden>]),
    timeout: Duration,
    verbose: bool,
) -> Result<Vec<Verdict>> {
    let built = t0.elapsed();
    let mut col = Vec::new();
    for (case, exp) in cases.iter().zip(expect) {
        let v = match (run_case(b, elf, case, timeout), exp) {
            (Err(e), _) => Verdict::Failed(format!("{e:#}")),
            (Ok((None, run)), _) => Verdict::Failed(format!("no result: {}", run.describe())),
            (Ok((Some(o), run)), Some(g)) => {
                if verbose {
                    crate::outln!("{} / {}: {}", b.name, case.name, run.describe());
                }
                golden::judge(case, backend, g, &o)?
            }
            (Ok(_), None) => Verdict::Failed("no golden files".into()),
        };
        col.push(against_expected_skips(b.name, &case.name, v));
    }
    for (sc, exp) in streams.iter().zip(stream_expect) {
        let v = match (run_stream_bytes(b, elf, &sc.stream, timeout), exp) {
            (Err(e), _) => Verdict::Failed(format!("{e:#}")),
            (Ok(run), Some(g)) => match (&run.result, run.ok()) {
                (Some(out), true) => {
                    if verbose {
                        crate::outln!("{} / {}: {}", b.name, sc.name(), run.describe());
                    }
                    crate::golden::stream::judge(sc, backend, g, out)
                }
                _ => Verdict::Failed(format!("no result: {}", run.describe())),
            },
            (Ok(_), None) => Verdict::Failed("no golden files".into()),
        };
        col.push(against_expected_skips(b.name, sc.name(), v));
    }
    eprintln!(
        "{:<20} firmware ({backend}) built in {:.1} s, {} cases run in {:.1} s",
        b.name,
        built.as_secs_f64(),
        cases.len() + streams.len(),
        (t0.elapsed() - built).as_secs_f64()
    );
    Ok(col)
}

/// Prints the table cases x columns, then the cells that are not identical, then the counts.
/// Returns how many cells are DIFF or FAILED.
fn print_table(
    backend: Backend,
    expected: &Expected,
    names: &[&str],
    columns: &[(String, Vec<Verdict>)],
) -> Result<usize> {
    let what = match expected {
        Expected::Golden(dir) => format!("golden files {}/{backend}", dir.display()),
        Expected::Host => format!("the library on the host ({backend})"),
    };
    crate::outln!("\ncases x boards, compared with {what}:\n");
    let name_w = names.iter().map(|n| n.len()).max().unwrap_or(4).max(4);
    let col_w: Vec<usize> = columns.iter().map(|(n, _)| n.len().max(9)).collect();
    let mut line = format!("{:<name_w$}", "case");
    for ((n, _), w) in columns.iter().zip(&col_w) {
        line.push_str(&format!("  {n:<w$}"));
    }
    crate::outln!("{}", line.trim_end());
    for (i, name) in names.iter().enumerate() {
        let mut line = format!("{name:<name_w$}");
        for ((_, col), w) in columns.iter().zip(&col_w) {
            line.push_str(&format!("  {:<w$}", col[i].cell()));
        }
        crate::outln!("{}", line.trim_end());
    }
    let (mut same, mut skipped, mut failed) = (0, 0, 0);
    let mut details = Vec::new();
    for (n, col) in columns {
        for (case, v) in names.iter().zip(col) {
            match v {
                Verdict::Identical => same += 1,
                Verdict::Skipped(why) => {
                    skipped += 1;
                    details.push(format!("skipped  {n} / {case}: {why}"));
                }
                Verdict::Diff(d) => {
                    failed += 1;
                    details.push(format!(
                        "DIFF     {n} / {case}: {}",
                        d.join("\n           ")
                    ));
                }
                Verdict::Failed(why) => {
                    failed += 1;
                    details.push(format!(
                        "FAILED   {n} / {case}: {}",
                        why.replace('\n', "\n           ")
                    ));
                }
            }
        }
    }
    crate::outln!();
    for d in &details {
        crate::outln!("{d}");
    }
    crate::outln!(
        "{backend}: {same} identical, {skipped} skipped (too big for the board), {failed} DIFF or FAILED"
    );
    Ok(failed)
}
