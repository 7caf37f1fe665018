//! `host-sim demo [MESH]`: the first impression. Simplifies one mesh (default
//! `tests/fixtures/cow.obj`, 5804 triangles) with the library on the host and on an emulated
//! Cortex-M4F (QEMU `mps2-an386`, 4 MB), prints both reports side by side and whether the two
//! outputs are byte-identical (exit 1 if not). Then the same mesh and target with the fast mode
//! (`pipeline::FastWorkspace`, case method `Fast`) on both: its rows say "fast mode", with its
//! emulated instructions per collapse, and its outputs must be byte-identical too (exit 1 if
//! not). A board without the fast mode, or whose fast workspace the mesh does not fit, says so
//! in its row instead. Then the same again with the lean mode (`pipeline::LeanWorkspace`, case
//! method `Lean`): its rows say "lean mode". Then both modes in integers (`pipeline::Integer`,
//! case methods `FastInteger` and `LeanInteger`, the mesh put on the 15-bit grid): their rows
//! say "fast mode, integer" and "lean mode, integer", their outputs must be byte-identical
//! too, and a mesh beyond the board's integer workspace is cut to its first triangles that fit
//! it (and says so). Last, one line per path with its instructions per collapse on the board,
//! float and integer; a board without the float modes says so and prints the integer lines.
//!
//! On a fresh machine it first makes sure the tools are there ([`qemu::preflight`]): a missing
//! Rust target is installed with `rustup target add`; a missing `qemu-system-arm` is installed
//! with apt-get only when running as root with `CI` set, otherwise the exact install command is
//! printed and the exit status is 2.

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::{Duration, Instant};

use anyhow::Result;
use meshfmt::{IndexType, Status};
use tinydecimate::Config;

use crate::backend::Backend;
use crate::golden::case::MethodName;
use crate::golden::{self, Case, Golden, Outcome, Verdict};
use crate::qemu;
use crate::simplify::Pipeline;

/// `host-sim demo`.
#[derive(Clone, Debug, clap::Args)]
pub struct Args {
    /// Mesh file (.obj, .ply, .stl). Default: tests/fixtures/cow.obj. A mesh larger than the
    /// board holds is cut to its first triangles that fit (and says so).
    pub mesh: Option<PathBuf>,
    /// Board (QEMU machine).
    #[arg(long, default_value = qemu::REFERENCE_BOARD, value_name = "MACHINE")]
    pub board: String,
    /// Target ratio (default: the configuration's, 0.1).
    #[arg(long)]
    pub ratio: Option<f32>,
    /// `Config::paper()` (passes, λ = 1) instead of `Config::new()`.
    #[arg(long)]
    pub paper: bool,
    /// u32 triangles (default u16; u32 anyway above 65535 vertices).
    #[arg(long)]
    pub u32: bool,
    /// Math backend of the library (default: the one host-sim was built with).
    #[arg(long, value_enum)]
    pub backend: Option<Backend>,
    /// Seconds before the QEMU run is killed.
    #[arg(long, default_value_t = 600)]
    pub timeout: u64,
    /// Print the firmware's decoded defmt log.
    #[arg(long, short)]
    pub verbose: bool,
}

/// The first triangles of `case` that fit `max_vertices` / `max_triangles`, unused vertices
/// dropped.
pub fn subset_that_fits(case: &Case, max_vertices: usize, max_triangles: usize) -> Case {
    let mut seen = std::collections::HashSet::new();
    let mut k = 0;
    for t in case.triangles.iter().take(max_triangles) {
        let new = t.iter().filter(|i| !seen.contains(*i)).count();
        if seen.len() + new > max_vertices {
            break;
        }
        seen.extend(t.iter().copied());
        k += 1;
    }
    let mut m = meshfmt::golden::Mesh {
        positions: case.positions.clone(),
        triangles: case.triangles[..k].to_vec(),
    };
    meshfmt::golden::compact(&mut m);
    Case {
        name: format!("{}-first{k}", case.name),
        mesh: format!("{}, first {k} triangles", case.mesh),
        positions: m.positions,
        triangles: m.triangles,
        wedges: Vec::new(),
        index_type: case.index_type,
        config: case.config,
        stored: case.stored,
        method: case.method,
    }
}

/// The stop reason of a result header's code (`meshfmt::ResultHeader::stop`).
pub fn stop_reason(code: u8) -> &'static str {
    match code {
        0 => "still running",
        1 => "target reached",
        2 => "no legal collapse left",
        3 => "every collapse left costs more than max_cost",
        4 => "max passes run",
        5 => "collapse log full",
        6 => "every collapse left is over the error limit",
        _ => "unknown",
    }
}

/// A run's status: `ok` only when it ran without error and reached its target; a run that
/// stopped short says so and why.
pub fn status_text(h: &meshfmt::ResultHeader) -> String {
    match h.status {
        Status::Ok if h.target_reached => "ok".to_string(),
        Status::Ok => format!("target MISSED ({})", stop_reason(h.stop)),
        s => format!("{s:?} {:?}", h.error_kind),
    }
}

/// The target row: the target, as a share of the input, and whether it was reached.
pub fn target_text(h: &meshfmt::ResultHeader) -> String {
    let pct = |n: u32| 100.0 * f64::from(n) / f64::from(h.triangles_in.max(1));
    format!(
        "{} ({:.1} %): {}",
        crate::qemu::measure::spaced(h.target_triangles.into()),
        pct(h.target_triangles),
        if h.target_reached {
            "reached".to_string()
        } else {
            format!("NOT reached, stopped at {:.1} %", pct(h.triangles_out))
        }
    )
}

/// Runs `host-sim demo`.
pub fn run(a: &Args) -> Result<ExitCode> {
    let backend = a.backend.unwrap_or(Backend::compiled());
    if backend != Backend::compiled() {
        return crate::backend::reinvoke(backend);
    }
    let board = qemu::board(&a.board)?;
    if let Some(code) = qemu::preflight(&[board])? {
        return Ok(code);
    }
    // 1. The case: the mesh, its index type and the configuration.
    let mut case = demo_case(a)?;
    // 2. The device's run (of the part of the mesh that fits it).
    let (elf, (device, run)) = run_on_board(a, board, backend, &mut case)?;
    if a.verbose {
        crate::outln!("{}", run.describe());
    }
    let Some(device) = device else {
        crate::outln!(
            "the firmware on {} gave no result: {}",
            board.name,
            run.describe()
        );
        return Ok(ExitCode::from(1));
    };
    // 3. The host's run, then both side by side and whether they are the same bytes.
    let t0 = Instant::now();
    let host = golden::reference(&case)?;
    let host_wall = t0.elapsed();
    side_by_side(
        a,
        board,
        backend,
        &case,
        (&host, host_wall),
        (&device, &run),
    );
    let exact = compare(&case, backend, &host, &device)?;
    sha_row("output sha256", &exact);
    // 4. The fast mode, then the lean mode, in floats and then in integers: the same mesh,
    // target and board.
    let mut modes = Vec::new();
    for integer in [false, true] {
        for mode in [Pipeline::Fast, Pipeline::Lean] {
            let path = Path { mode, integer };
            let mut mode_case = if integer {
                integer_case(&case, mode)?
            } else {
                pipeline_case(&case, mode)
            };
            let timeout = Duration::from_secs(a.timeout);
            let (mut mode_device, mut mode_run) = qemu::run_case(board, &elf, &mode_case, timeout)?;
            // An integer workspace smaller than the mesh: its first triangles that fit.
            if let (true, Some(d)) = (integer, &mode_device) {
                let (v, t) = (
                    d.header.capacity_vertices as usize,
                    d.header.capacity_triangles as usize,
                );
                if d.header.status == Status::TooBig && v > 0 {
                    mode_case = subset_that_fits(&mode_case, v, t);
                    crate::outln!(
                        "\n{}: the workspace of the {} holds {v} / {t}: its first {} triangles ({} vertices)",
                        board.name,
                        path.noun(),
                        mode_case.triangles.len(),
                        mode_case.positions.len()
                    );
                    (mode_device, mode_run) = qemu::run_case(board, &elf, &mode_case, timeout)?;
                }
            }
            if a.verbose {
                crate::outln!("{}", mode_run.describe());
            }
            let t0 = Instant::now();
            let mode_host = golden::reference(&mode_case)?;
            let mode_wall = t0.elapsed();
            let c = pipeline_rows(
                board,
                backend,
                &mode_case,
                path,
                (&mode_host, mode_wall),
                (mode_device.as_ref(), &mode_run),
            )?;
            let line = per_collapse_line(board, &mode_case, path, mode_device.as_ref());
            modes.push((path, c, line));
        }
    }
    crate::outln!();
    per_collapse_lines(board, &modes);
    crate::outln!();
    let ok = verdict("byte-identical", &exact);
    let mut modes_ok = true;
    for (path, c, _) in &modes {
        if let Some(c) = c {
            modes_ok &= verdict(&format!("byte-identical, {}", path.label()), c);
        }
    }
    Ok(if ok && modes_ok {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}

/// The case `host-sim demo` runs: the mesh (the cow by default), `u32` triangles when asked
/// or needed, and the configuration.
fn demo_case(a: &Args) -> Result<Case> {
    let path = a
        .mesh
        .clone()
        .unwrap_or_else(|| crate::repo_root().join("tests/fixtures/cow.obj"));
    let m = crate::io::load(&path)?;
    let index_type = if a.u32 || m.positions.len() > usize::from(u16::MAX) {
        IndexType::U32
    } else {
        IndexType::U16
    };
    let mut config = if a.paper {
        Config::paper()
    } else {
        Config::new()
    };
    if let Some(r) = a.ratio {
        config = config.with_ratio(r);
    }
    Ok(Case {
        name: path
            .file_stem()
            .unwrap_or_default()
            .to_string_lossy()
            .into_owned(),
        mesh: path.display().to_string(),
        positions: m.positions,
        triangles: m.triangles,
        wedges: Vec::new(),
        index_type,
        config,
        stored: None,
        method: None,
    })
}

/// The run of `case` in the pipeline's `mode`: the same mesh, index type and configuration,
/// method `Fast` or `Lean`.
fn pipeline_case(case: &Case, mode: Pipeline) -> Case {
    Case {
        name: format!("{}-{}", case.name, mode.name()),
        method: Some(match mode {
            Pipeline::Fast => MethodName::Fast,
            Pipeline::Lean => MethodName::Lean,
        }),
        ..case.clone()
    }
}

/// The run of `case` in the pipeline's `mode` in integers: the same mesh put on the 15-bit
/// grid, index type and configuration, method `FastInteger` or `LeanInteger`.
fn integer_case(case: &Case, mode: Pipeline) -> Result<Case> {
    Ok(Case {
        name: format!("{}-{}-integer", case.name, mode.name()),
        mesh: format!("{}, on the 15-bit grid", case.mesh),
        positions: crate::golden::case::grid_positions(&case.positions)?,
        method: Some(match mode {
            Pipeline::Fast => MethodName::FastInteger,
            Pipeline::Lean => MethodName::LeanInteger,
        }),
        ..case.clone()
    })
}

/// A path of the pipeline the demo runs: a mode, in floats or in integers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Path {
    mode: Pipeline,
    integer: bool,
}

impl Path {
    /// "fast mode" or "fast mode, integer": the end of its rows' labels.
    fn label(self) -> String {
        if self.integer {
            format!("{} mode, integer", self.mode.name())
        } else {
            format!("{} mode", self.mode.name())
        }
    }

    /// "fast mode" or "fast mode in integers": the path in a sentence.
    fn noun(self) -> String {
        if self.integer {
            format!("{} mode in integers", self.mode.name())
        } else {
            format!("{} mode", self.mode.name())
        }
    }
}

/// The line of the last block for one path's device run: its instructions per collapse and
/// the mesh it ran on, or why there is none. `None`: the board has no such mode at all.
fn per_collapse_line(
    board: &qemu::Board,
    case: &Case,
    path: Path,
    device: Option<&Outcome>,
) -> Option<String> {
    let Some(d) = device.map(|o| &o.header) else {
        return Some("no result from the firmware".into());
    };
    if d.status == Status::TooBig {
        return (d.capacity_vertices > 0).then(|| {
            format!(
                "- (the mesh does not fit the workspace of the {}: {} V / {} T)",
                path.noun(),
                d.capacity_vertices,
                d.capacity_triangles
            )
        });
    }
    if d.status != Status::Ok || d.collapses == 0 {
        return Some(format!("- ({})", status_text(d)));
    }
    let instr = board.instructions(d.ticks);
    Some(format!(
        "{} ({} instructions, {} collapses; {} vertices, {} triangles)",
        crate::qemu::measure::spaced(instr / u64::from(d.collapses)),
        crate::qemu::measure::spaced(instr),
        crate::qemu::measure::spaced(d.collapses.into()),
        crate::qemu::measure::spaced(case.positions.len() as u64),
        crate::qemu::measure::spaced(case.triangles.len() as u64)
    ))
}

/// The last block: per path, one line of instructions per collapse on the board, each integer
/// one saying "integer"; a mode the board lacks is said once instead of its line.
fn per_collapse_lines(board: &qemu::Board, modes: &[(Path, Option<Comparison>, Option<String>)]) {
    crate::outln!(
        "instructions per collapse on {} ({}):",
        board.name,
        board.core
    );
    let lacks = |integer: bool| {
        modes
            .iter()
            .filter(|(p, _, l)| p.integer == integer && l.is_none())
            .map(|(p, _, _)| p.mode.name())
            .collect::<Vec<_>>()
    };
    let float = lacks(false);
    if !float.is_empty() {
        crate::outln!(
            "  {} has no float {} mode: the integer path only",
            board.name,
            float.join(" or ")
        );
    }
    let integer = lacks(true);
    if !integer.is_empty() {
        crate::outln!(
            "  {} has no {} mode in integers",
            board.name,
            integer.join(" or ")
        );
    }
    for (path, _, line) in modes {
        if let Some(line) = line {
            crate::outln!("  {:<20} {line}", path.label());
        }
    }
}

/// Builds the firmware and runs `case` on `board`; a mesh too big for the board is cut to
/// the triangles that fit (`case` becomes that part) and run again. Returns the image too.
fn run_on_board(
    a: &Args,
    board: &'static qemu::Board,
    backend: Backend,
    case: &mut Case,
) -> Result<(PathBuf, (Option<Outcome>, qemu::Run))> {
    let timeout = Duration::from_secs(a.timeout);
    eprintln!(
        "building the firmware for {} ({}, {backend}) ...",
        board.name, board.core
    );
    let elf = qemu::build(board, backend, true)?;
    let mut ran = qemu::run_case(board, &elf, case, timeout)?;
    if let (Some(o), _) = &ran {
        if o.header.status == Status::TooBig {
            let (v, t) = (
                o.header.capacity_vertices as usize,
                o.header.capacity_triangles as usize,
            );
            let sub = subset_that_fits(case, v, t);
            crate::outln!(
                "{} has {} vertices / {} triangles; {} holds {v} / {t}: using its first {} triangles ({} vertices)",
                case.mesh,
                case.positions.len(),
                case.triangles.len(),
                board.name,
                sub.triangles.len(),
                sub.positions.len()
            );
            *case = sub;
            ran = qemu::run_case(board, &elf, case, timeout)?;
        }
    }
    Ok((elf, ran))
}

/// The host's and the device's runs side by side: report, instructions, time, memory.
fn side_by_side(
    a: &Args,
    board: &qemu::Board,
    backend: Backend,
    case: &Case,
    (host, host_wall): (&Outcome, Duration),
    (device, run): (&Outcome, &qemu::Run),
) {
    let index_type = case.index_type;
    let (h, d) = (&host.header, &device.header);
    let it = if index_type == IndexType::U16 {
        "u16"
    } else {
        "u32"
    };
    crate::outln!(
        "\ntinydecimate demo: {} ({} vertices, {} {it} triangles)\nconfig: {} ({:?}, ratio {}, lambda {}), {backend} backend\n",
        case.mesh,
        case.positions.len(),
        case.triangles.len(),
        if a.paper {
            "Config::paper()"
        } else {
            "Config::new()"
        },
        case.config.schedule(),
        meshfmt::lib::target_fields(case.config.target()).0,
        case.config.lambda()
    );
    let host_col = format!("host ({}, std)", std::env::consts::ARCH);
    let dev_col = format!("{} ({}, QEMU)", board.name, board.core);
    row("", host_col, dev_col);
    let status = |o: &Outcome| status_text(&o.header);
    row("status", status(host), status(device));
    row("target", target_text(h), target_text(d));
    row(
        "stop",
        stop_reason(h.stop).to_string(),
        stop_reason(d.stop).to_string(),
    );
    row(
        "triangles in",
        crate::qemu::measure::spaced(h.triangles_in.into()),
        crate::qemu::measure::spaced(d.triangles_in.into()),
    );
    run_rows("", board, (h, d), host_wall, run.wall);
    row(
        "workspace RAM",
        format!(
            "{} B (u32 links, sized to the mesh)",
            crate::qemu::measure::spaced(tinydecimate::Storage::<u32>::bytes(
                case.positions.len(),
                case.triangles.len()
            ) as u64),
        ),
        format!(
            "{} B ({} V / {} T capacity)",
            crate::qemu::measure::spaced(d.workspace_bytes.into()),
            d.capacity_vertices,
            d.capacity_triangles
        ),
    );
    row(
        "stack high-water",
        "-".into(),
        format!(
            "{} B (library: {} B)",
            crate::qemu::measure::spaced(d.stack_high_water.into()),
            crate::qemu::measure::spaced(d.stack_bytes.into())
        ),
    );
}

/// The emulated instructions of a device run, and per collapse when it made any.
/// The rows both runs print: triangles out, collapses, emulated instructions and time, each
/// label followed by `suffix`.
fn run_rows(
    suffix: &str,
    board: &qemu::Board,
    (h, d): (&meshfmt::ResultHeader, &meshfmt::ResultHeader),
    host_wall: Duration,
    device_wall: Duration,
) {
    row(
        &format!("triangles out{suffix}"),
        crate::qemu::measure::spaced(h.triangles_out.into()),
        crate::qemu::measure::spaced(d.triangles_out.into()),
    );
    row(
        &format!("collapses{suffix}"),
        crate::qemu::measure::spaced(h.collapses.into()),
        crate::qemu::measure::spaced(d.collapses.into()),
    );
    row(
        &format!("emulated instructions{suffix}"),
        "-".into(),
        instructions_text(board, d),
    );
    row(
        &format!("time{suffix}"),
        format!("{:.1} ms wall", host_wall.as_secs_f64() * 1e3),
        format!("{:.2} s wall under QEMU", device_wall.as_secs_f64()),
    );
}

fn instructions_text(board: &qemu::Board, d: &meshfmt::ResultHeader) -> String {
    let instr = board.instructions(d.ticks);
    format!(
        "{}{}",
        crate::qemu::measure::spaced(instr),
        if d.collapses > 0 {
            format!(
                " ({} per collapse)",
                crate::qemu::measure::spaced(instr / u64::from(d.collapses))
            )
        } else {
            String::new()
        }
    )
}

/// The rows of a path of the pipeline (the fast or the lean mode, in floats or in integers):
/// the host's and the device's run of `case` (method `Fast`, `Lean`, `FastInteger` or
/// `LeanInteger`), each label ending in the path's ("fast mode", "lean mode, integer").
/// Returns their comparison, or `None` when the device did not run it because the mesh does
/// not fit the mode's workspace or the board has none (the row says which).
fn pipeline_rows(
    board: &qemu::Board,
    backend: Backend,
    case: &Case,
    path: Path,
    (host, host_wall): (&Outcome, Duration),
    (device, run): (Option<&Outcome>, &qemu::Run),
) -> Result<Option<Comparison>> {
    crate::outln!();
    let name = path.label();
    let h = &host.header;
    let Some(device) = device else {
        row(
            &name,
            status_text(h),
            format!("no result: {}", run.describe()),
        );
        return Ok(Some(Comparison {
            host: Golden::from_outcome(case, backend, host)?,
            device: None,
            verdict: Verdict::Failed(format!("the firmware gave no result: {}", run.describe())),
        }));
    };
    let d = &device.header;
    if d.status == Status::TooBig {
        let why = if d.capacity_vertices == 0 {
            format!("{} has no {}", board.name, path.noun())
        } else {
            format!(
                "does not fit the workspace of the {} ({} V / {} T)",
                path.noun(),
                d.capacity_vertices,
                d.capacity_triangles
            )
        };
        row(&name, status_text(h), why);
        return Ok(None);
    }
    row(&format!("status, {name}"), status_text(h), status_text(d));
    run_rows(&format!(", {name}"), board, (h, d), host_wall, run.wall);
    row(
        &format!("workspace RAM, {name}"),
        format!(
            // An integer workspace takes the float one's bytes: its quadric is 24 B too.
            "{} B (sized to the mesh)",
            crate::qemu::measure::spaced(crate::simplify::pipeline_bytes(
                path.mode,
                case.positions.len(),
                case.triangles.len()
            ) as u64),
        ),
        format!(
            "{} B ({} V / {} T capacity)",
            crate::qemu::measure::spaced(d.workspace_bytes.into()),
            d.capacity_vertices,
            d.capacity_triangles
        ),
    );
    row(
        &format!("stack high-water, {name}"),
        "-".into(),
        format!(
            "{} B (library: {} B)",
            crate::qemu::measure::spaced(d.stack_high_water.into()),
            crate::qemu::measure::spaced(d.stack_bytes.into())
        ),
    );
    let c = compare(case, backend, host, device)?;
    sha_row(&format!("output sha256, {name}"), &c);
    Ok(Some(c))
}

/// One line of the side-by-side table (the longest label: an integer path's instructions).
fn row(k: &str, x: String, y: String) {
    crate::outln!("{k:<41} {x:<46} {y}");
}

/// The host's and the device's outputs of one case, as golden files, and how they compare.
struct Comparison {
    host: Golden,
    device: Option<Golden>,
    verdict: Verdict,
}

/// Compares the host's and the device's outputs of `case`.
fn compare(case: &Case, backend: Backend, host: &Outcome, device: &Outcome) -> Result<Comparison> {
    let (gh, gd) = (
        Golden::from_outcome(case, backend, host)?,
        Golden::from_outcome(case, backend, device)?,
    );
    let verdict = golden::diff(case.index_type, &gh, &gd);
    Ok(Comparison {
        host: gh,
        device: Some(gd),
        verdict,
    })
}

/// The row of the outputs' hashes.
fn sha_row(k: &str, c: &Comparison) {
    let sha = |g: &Golden| golden::sha256_hex(&g.bin)[..16].to_string();
    row(k, sha(&c.host), c.device.as_ref().map_or("-".into(), sha));
}

/// Prints whether the outputs are the same bytes (`what: yes` or `what: NO` and the
/// differences); true if they are.
fn verdict(what: &str, c: &Comparison) -> bool {
    match &c.verdict {
        Verdict::Identical => {
            crate::outln!(
                "{what}: yes ({} bytes of output triangles, same report)",
                c.host.bin.len()
            );
            true
        }
        v => {
            crate::outln!("{what}: NO");
            match v {
                Verdict::Diff(d) => {
                    for l in d {
                        crate::outln!("  {l}");
                    }
                }
                Verdict::Failed(why) | Verdict::Skipped(why) => crate::outln!("  {why}"),
                Verdict::Identical => {}
            }
            false
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A run that stopped at 47 % of a 10 % target is not `ok`: the status says the target
    /// was missed and why, the target row says how far it got. A reached target is `ok`.
    #[test]
    fn a_missed_target_is_not_ok() {
        let mut h = meshfmt::ResultHeader::empty(IndexType::U32, Status::Ok, meshfmt::Board::Host);
        h.triangles_in = 1000;
        h.target_triangles = 100;
        h.triangles_out = 470;
        h.target_reached = false;
        h.stop = 2;
        let s = status_text(&h);
        assert!(!s.contains("ok"), "{s}");
        assert_eq!(s, "target MISSED (no legal collapse left)");
        assert_eq!(
            target_text(&h),
            "100 (10.0 %): NOT reached, stopped at 47.0 %"
        );
        h.triangles_out = 100;
        h.target_reached = true;
        h.stop = 1;
        assert_eq!(status_text(&h), "ok");
        assert_eq!(target_text(&h), "100 (10.0 %): reached");
        assert_eq!(stop_reason(h.stop), "target reached");
        let e = meshfmt::ResultHeader::empty(IndexType::U32, Status::TooBig, meshfmt::Board::Host);
        assert!(status_text(&e).starts_with("TooBig"));
    }

    /// A bumpy 10 x 10 grid as a plain case (u16, `Config::new()`).
    fn grid_case() -> Case {
        let m = meshfmt::golden::bumpy_grid(10);
        Case {
            name: "g".into(),
            mesh: "grid 10".into(),
            positions: m.positions,
            triangles: m.triangles,
            wedges: Vec::new(),
            index_type: IndexType::U16,
            config: Config::new(),
            stored: None,
            method: None,
        }
    }

    /// The demo's fast run is a case of method `Fast` (code 6 in the case file) whose host
    /// reference is the library's fast mode, its lean run one of method `Lean` (code 7) with
    /// the lean mode; the instructions row divides by the collapses.
    #[test]
    fn the_fast_and_lean_runs_are_those_modes() {
        let case = grid_case();
        let fast = pipeline_case(&case, Pipeline::Fast);
        assert_eq!(fast.header().method, meshfmt::MethodCode::Fast);
        assert_eq!(fast.encode().unwrap()[30], 6);
        assert_eq!(fast.positions, case.positions);
        assert_eq!(fast.triangles, case.triangles);
        let host = golden::reference(&fast).unwrap();
        let mut t = case.triangles.clone();
        let r = crate::simplify::pipeline_run(
            crate::simplify::Pipeline::Fast,
            &case.positions,
            &mut t,
            &case.config,
        )
        .unwrap();
        t.truncate(r.triangles_out);
        assert_eq!(host.triangles, t);
        assert_eq!(host.header.collapses as usize, r.collapses);
        // The lean run likewise: method `Lean` (code 7), the library's lean mode.
        let lean = pipeline_case(&case, Pipeline::Lean);
        assert_eq!(lean.header().method, meshfmt::MethodCode::Lean);
        assert_eq!(lean.encode().unwrap()[30], 7);
        assert_eq!(lean.name, "g-lean");
        let host = golden::reference(&lean).unwrap();
        let mut t = case.triangles.clone();
        let r = crate::simplify::pipeline_run(
            crate::simplify::Pipeline::Lean,
            &case.positions,
            &mut t,
            &case.config,
        )
        .unwrap();
        t.truncate(r.triangles_out);
        assert_eq!(host.triangles, t);
        assert_eq!(host.header.collapses as usize, r.collapses);
        let board = qemu::board(qemu::REFERENCE_BOARD).unwrap();
        let mut d = meshfmt::ResultHeader::empty(IndexType::U16, Status::Ok, meshfmt::Board::Host);
        d.ticks = 1_000_000;
        d.collapses = 40;
        let instr = board.instructions(d.ticks);
        assert_eq!(
            instructions_text(board, &d),
            format!(
                "{} ({} per collapse)",
                crate::qemu::measure::spaced(instr),
                crate::qemu::measure::spaced(instr / 40)
            )
        );
        d.collapses = 0;
        assert_eq!(
            instructions_text(board, &d),
            crate::qemu::measure::spaced(instr)
        );
    }

    /// The demo's integer runs are cases of method `FastInteger` (code 10) and `LeanInteger`
    /// (code 11) on the mesh put on the grid, whose host reference is the library's integer
    /// workspace on those grid positions; their labels say "integer".
    #[test]
    fn the_integer_runs_are_the_integer_modes() {
        let case = grid_case();
        let mut want = vec![[0u16; 3]; case.positions.len()];
        tinydecimate::pipeline::quantise(&case.positions, &mut want).unwrap();
        for (mode, code) in [(Pipeline::Fast, 10), (Pipeline::Lean, 11)] {
            let c = integer_case(&case, mode).unwrap();
            assert_eq!(c.encode().unwrap()[30], code);
            assert_eq!(c.triangles, case.triangles);
            let grid: Vec<[u16; 3]> = c
                .positions
                .iter()
                .map(|&p| meshfmt::grid_position(p))
                .collect();
            assert_eq!(grid, want);
            let host = golden::reference(&c).unwrap();
            let mut t = case.triangles.clone();
            let r = crate::simplify::pipeline_run_grid(mode, &grid, &mut t, &case.config).unwrap();
            t.truncate(r.triangles_out);
            assert_eq!(host.triangles, t);
            assert_eq!(host.header.collapses as usize, r.collapses);
            let label = Path {
                mode,
                integer: true,
            }
            .label();
            assert_eq!(label, format!("{} mode, integer", mode.name()));
        }
    }

    #[test]
    fn subset_fits_and_is_compact() {
        let case = grid_case();
        let s = subset_that_fits(&case, 30, 1000);
        assert!(s.positions.len() <= 30);
        assert!(!s.triangles.is_empty());
        assert_eq!(
            s.triangles.iter().flatten().max().map(|&i| i as usize + 1),
            Some(s.positions.len())
        );
        let s = subset_that_fits(&case, 1000, 7);
        assert_eq!(s.triangles.len(), 7);
        assert_eq!(crate::qemu::measure::spaced(1234567), "1 234 567");
        assert_eq!(crate::qemu::measure::spaced(12), "12");
    }
}
