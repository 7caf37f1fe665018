//! `host-sim qemu --measure`: per board the image sizes (firmware, library alone, one
//! instantiation), the calibrated timer, instructions and stack per case and per progressive
//! stream, and the largest mesh it simplifies (bisection).

use std::path::Path;
use std::time::{Duration, Instant};

use anyhow::{anyhow, bail, Result};
use meshfmt::{IndexType, Status};

use super::build::{build, one_instantiation, ONE_INSTANTIATION};
use super::elf::{elf_sizes, Sizes};
use super::run::{run_case, run_in, run_stream_bytes, scratch_dir};
use super::Board;
use crate::backend::Backend;
use crate::golden::stream::StreamCase;
use crate::golden::{self, Case, Golden, Outcome, Verdict};

/// Runs the firmware's calibration loop (2 × 5 000 001 instructions) and returns the measured
/// instructions per tick. With `-icount shift=0` it equals `1e9 / clock_hz` up to rounding.
pub fn calibrate(board: &Board, elf: &Path) -> Result<f64> {
    let dir = scratch_dir("calibrate")?;
    let run = run_in(
        board,
        elf,
        &dir,
        &["calibrate", "cal.bin"],
        Some("cal.bin"),
        Duration::from_secs(60),
    )?;
    let _ = std::fs::remove_dir_all(&dir);
    let bytes = run
        .result
        .as_ref()
        .filter(|_| run.ok())
        .ok_or_else(|| anyhow!("calibration on {} failed: {}", board.name, run.describe()))?;
    let o = Outcome::decode(bytes)?;
    if o.header.ticks == 0 {
        bail!("the timer did not count on {}", board.name);
    }
    Ok(f64::from(o.header.error_a) / o.header.ticks as f64)
}

/// What `host-sim qemu --measure` reports for one board.
#[derive(Clone, Debug)]
pub struct Measurement {
    /// Board.
    pub board: &'static Board,
    /// Math backend.
    pub backend: Backend,
    /// Image sizes of the firmware with the library.
    pub sizes: Sizes,
    /// Image sizes of the same firmware without the library (it echoes its input).
    pub sizes_without: Sizes,
    /// Flash of one instantiation on the board's target ([`one_instantiation`]): `.text +
    /// .rodata` of the minimal firmware without and with the call.
    pub instantiation: (u64, u64),
    /// Measured instructions per timer tick.
    pub instructions_per_tick: f64,
    /// Workspace bytes (the library's static RAM on this board).
    pub workspace_bytes: u32,
    /// Capacity: vertices, u16 triangles, u32 triangles.
    pub capacity: (u32, u32, u32),
    /// Per case.
    pub cases: Vec<CaseMeasurement>,
    /// The largest mesh, per index type.
    pub largest: Vec<Largest>,
    /// The golden progressive streams, decoded on the board.
    pub streams: Vec<StreamMeasurement>,
}

/// One golden stream decoded on a board (`meshfmt::pm::run`).
#[derive(Clone, Debug)]
pub struct StreamMeasurement {
    /// Case name.
    pub name: String,
    /// Vertex splits received, and the trailer's tick counts converted to instructions:
    /// decoding, coarsening every level, refining every level.
    pub splits: u32,
    /// See `splits`.
    pub decode: u64,
    /// See `splits`.
    pub coarsen: u64,
    /// See `splits`.
    pub refine: u64,
    /// Stack of the run.
    pub stack_bytes: u32,
    /// identical / skipped / DIFF / FAILED against the golden files.
    pub verdict: &'static str,
}

/// One measured case.
#[derive(Clone, Debug)]
pub struct CaseMeasurement {
    /// Case name.
    pub name: String,
    /// Triangles in.
    pub triangles_in: u32,
    /// Triangles out.
    pub triangles_out: u32,
    /// Collapses.
    pub collapses: u32,
    /// Instructions inside `Workspace::simplify`.
    pub instructions: u64,
    /// Stack used by the library (below its caller's frame).
    pub stack_bytes: u32,
    /// Deepest stack use of the whole firmware, from the top of the stack.
    pub stack_high_water: u32,
    /// `identical` to the host, `skipped` (too big), `DIFF` or `FAILED`.
    pub verdict: &'static str,
    /// Why it was skipped or failed.
    pub note: String,
    /// For a case of the pipeline in integers, the float case it stands beside
    /// ([`Case::float_twin`]).
    pub float_twin: Option<String>,
}

/// The largest mesh a board simplifies, found by bisection.
#[derive(Clone, Debug)]
pub struct Largest {
    /// Index type of the probes.
    pub index_type: IndexType,
    /// Largest success: vertices, triangles, instructions.
    pub ok: Option<(usize, usize, u64)>,
    /// Smallest failure: vertices, triangles, why.
    pub fail: Option<(usize, usize, String)>,
    /// QEMU runs.
    pub probes: u32,
    /// Host time of the search.
    pub wall: Duration,
}

/// The generated mesh of the capacity search: `strip T` (exactly `t` triangles, ≈ t/2
/// vertices), simplified with `Config::new()`.
pub fn probe_case(t: usize, index_type: IndexType) -> Case {
    let m = meshfmt::golden::strip(t);
    Case {
        name: format!("strip-{t}"),
        mesh: format!("strip {t}"),
        positions: m.positions,
        triangles: m.triangles,
        wedges: Vec::new(),
        index_type,
        config: tinydecimate::Config::new(),
        stored: None,
        method: None,
    }
}

/// One capacity probe: `Ok((vertices, triangles, instructions))` if the board simplified
/// it, `Err((vertices, why))` if not.
type Probe = std::result::Result<(usize, usize, u64), (usize, String)>;

/// Bisects the triangle count of [`probe_case`] until a run fails (the mesh does not fit, the
/// library reports an error, or the firmware crashes or times out). Nothing is assumed about
/// the board's capacity: doubling from 64 triangles finds a failure, bisection the boundary.
pub fn largest_mesh(
    board: &Board,
    elf: &Path,
    index_type: IndexType,
    timeout: Duration,
) -> Result<Largest> {
    const LIMIT: usize = 4_000_000;
    let t0 = Instant::now();
    let mut probes = 0;
    let mut probe = |t: usize| -> Result<Probe> {
        probes += 1;
        let case = probe_case(t, index_type);
        let v = case.positions.len();
        if index_type == IndexType::U16 && v > 1 << 16 {
            return Ok(Err((v, "more vertices than u16 indices reach".into())));
        }
        let (outcome, run) = run_case(board, elf, &case, timeout)?;
        Ok(match outcome {
            Some(o) if o.header.status == Status::Ok => {
                Ok((v, t, board.instructions(o.header.ticks)))
            }
            Some(o) if o.header.status == Status::TooBig => Err((
                v,
                format!(
                    "too big for the buffers (holds {} vertices, {} triangles)",
                    o.header.capacity_vertices, o.header.capacity_triangles
                ),
            )),
            Some(o) => Err((
                v,
                format!("{:?} {:?}", o.header.status, o.header.error_kind),
            )),
            None => Err((
                v,
                format!(
                    "firmware exit {:?}{}",
                    run.exit_code,
                    if run.timed_out { " (timed out)" } else { "" }
                ),
            )),
        })
    };
    let (mut ok, mut lo) = (None, 0usize);
    let mut fail = None;
    let mut t = 64usize;
    loop {
        match probe(t)? {
            Ok(r) => {
                ok = Some(r);
                lo = t;
                if t >= LIMIT {
                    break;
                }
                t = (t * 2).min(LIMIT);
            }
            Err((v, why)) => {
                fail = Some((v, t, why));
                break;
            }
        }
    }
    if let Some((_, mut hi, _)) = fail {
        while hi - lo > 1 {
            let mid = lo + (hi - lo) / 2;
            match probe(mid)? {
                Ok(r) => {
                    ok = Some(r);
                    lo = mid;
                }
                Err((v, why)) => {
                    fail = Some((v, mid, why));
                    hi = mid;
                }
            }
        }
    }
    Ok(Largest {
        index_type,
        ok,
        fail,
        probes,
        wall: t0.elapsed(),
    })
}

/// Measures a board: image sizes with and without the library, calibration, every case of the
/// manifest (compared with a fresh host run), and the largest mesh per index type.
pub fn measure(
    board: &'static Board,
    backend: Backend,
    cases: &[Case],
    stream_cases: &[StreamCase],
    timeout: Duration,
) -> Result<Measurement> {
    let without = build(board, backend, false)?;
    let sizes_without = elf_sizes(&std::fs::read(&without)?)?;
    let elf = build(board, backend, true)?;
    let sizes = elf_sizes(&std::fs::read(&elf)?)?;
    let instantiation = one_instantiation(board.target, backend)?;
    // The calibration loop carries a few instructions of overhead, so it measures slightly
    // over the exact figure; it only has to confirm the board's clock.
    let measured = calibrate(board, &elf)?;
    let ipt = board.instructions_per_tick();
    if (measured - ipt).abs() > ipt * 1e-3 {
        bail!(
            "{}: the timer counts {measured:.4} instructions per tick, expected {ipt} \
             (QEMU not run with -icount shift=0, or another clock?)",
            board.name
        );
    }
    let mut out = Vec::new();
    let (mut workspace_bytes, mut capacity) = (0, (0, 0, 0));
    for case in cases {
        let expected = Golden::from_outcome(case, backend, &golden::reference(case)?)?;
        let (outcome, run) = run_case(board, &elf, case, timeout)?;
        let Some(o) = outcome else {
            out.push(CaseMeasurement {
                name: case.name.clone(),
                triangles_in: case.triangles.len() as u32,
                triangles_out: 0,
                collapses: 0,
                instructions: 0,
                stack_bytes: 0,
                stack_high_water: 0,
                verdict: "FAILED",
                note: run.describe(),
                float_twin: case.float_twin(),
            });
            continue;
        };
        let h = &o.header;
        if h.status != Status::TooBig {
            workspace_bytes = h.workspace_bytes;
        }
        let it_cap = h.capacity_triangles;
        match case.index_type {
            IndexType::U16 => capacity = (h.capacity_vertices, it_cap, capacity.2),
            IndexType::U32 => capacity = (h.capacity_vertices, capacity.1, it_cap),
        }
        let v = golden::judge(case, backend, &expected, &o)?;
        out.push(CaseMeasurement {
            name: case.name.clone(),
            triangles_in: h.triangles_in,
            triangles_out: h.triangles_out,
            collapses: h.collapses,
            instructions: board.instructions(h.ticks),
            stack_bytes: h.stack_bytes,
            stack_high_water: h.stack_high_water,
            verdict: v.cell(),
            note: match &v {
                Verdict::Skipped(w) | Verdict::Failed(w) => w.clone(),
                Verdict::Diff(d) => d.join("; "),
                Verdict::Identical => String::new(),
            },
            float_twin: case.float_twin(),
        });
    }
    let mut largest = Vec::new();
    for it in [IndexType::U16, IndexType::U32] {
        let l = largest_mesh(board, &elf, it, timeout)?;
        eprintln!(
            "{}: largest {} mesh found in {} QEMU runs, {:.1} s",
            board.name,
            if it == IndexType::U16 { "u16" } else { "u32" },
            l.probes,
            l.wall.as_secs_f64()
        );
        largest.push(l);
    }
    let mut streams = Vec::new();
    for sc in stream_cases {
        let expected = crate::golden::stream::golden_from_output(
            sc,
            backend,
            &crate::golden::stream::reference(sc),
        )?;
        let run = run_stream_bytes(board, &elf, &sc.stream, timeout)?;
        let (verdict, summary) = match (&run.result, run.ok()) {
            (Some(o), true) => (
                crate::golden::stream::judge(sc, backend, &expected, o).cell(),
                meshfmt::pm::parse(o).map(|(_, s)| s),
            ),
            _ => ("FAILED", None),
        };
        let s = summary.unwrap_or_default();
        streams.push(StreamMeasurement {
            name: sc.name().to_string(),
            splits: s.splits,
            decode: board.instructions(s.decode_ticks),
            coarsen: board.instructions(s.coarsen_ticks),
            refine: board.instructions(s.refine_ticks),
            stack_bytes: s.stack_bytes,
            verdict,
        });
    }
    Ok(Measurement {
        board,
        backend,
        sizes,
        sizes_without,
        instantiation,
        instructions_per_tick: measured,
        workspace_bytes,
        capacity,
        cases: out,
        largest,
        streams,
    })
}

/// Signed difference of two sizes.
fn delta(a: u64, b: u64) -> i64 {
    a as i64 - b as i64
}

/// Prints a measurement: sizes, then one line per case, then the largest meshes.
pub fn print_measurement(m: &Measurement) {
    let b = m.board;
    let (s, w) = (&m.sizes, &m.sizes_without);
    crate::outln!(
        "\n== {} ({}, {}), {} backend",
        b.name,
        b.core,
        b.target,
        m.backend
    );
    crate::outln!(
        "firmware:      flash {:>8} B (text {}, rodata {}, .data image {}), static RAM {:>8} B of {} KB, stack {} B",
        s.flash,
        s.text,
        s.rodata,
        s.data,
        s.static_ram,
        b.ram >> 10,
        u64::from(b.ram).saturating_sub(s.static_ram)
    );
    let lib_stack = m.cases.iter().map(|c| c.stack_bytes).max().unwrap_or(0);
    crate::outln!(
        "library alone: flash {:>8} B (text {:+}, rodata {:+}), static RAM {:>8} B (workspace {} B) + stack <= {} B \
         [image with the library - image without]",
        delta(s.flash, w.flash),
        delta(s.text, w.text),
        delta(s.rodata, w.rodata),
        delta(s.static_ram, w.static_ram),
        m.workspace_bytes,
        lib_stack
    );
    let (without, with) = m.instantiation;
    crate::outln!(
        "instantiation: flash {:>8} B ({:.1} KB; text + rodata {with} with the call - {without} without) \
         [tests/flash as scripts/flash.sh builds it: {ONE_INSTANTIATION}]",
        delta(with, without),
        delta(with, without) as f64 / 1024.0,
    );
    crate::outln!(
        "capacity:      {} vertices, {} u16 / {} u32 triangles; {:.4} instructions per timer tick (calibrated)",
        m.capacity.0, m.capacity.1, m.capacity.2, m.instructions_per_tick
    );
    crate::outln!(
        "  {:<26} {:>6} {:>6} {:>9} {:>13} {:>11} {:>9} {:>10}  vs host",
        "case",
        "in",
        "out",
        "collapses",
        "instructions",
        "instr/coll",
        "stack lib",
        "high-water"
    );
    for c in &m.cases {
        if c.verdict == "skipped" || c.verdict == "FAILED" {
            crate::outln!(
                "  {:<26} {:>6}  {}: {}",
                c.name,
                c.triangles_in,
                c.verdict,
                c.note
            );
            continue;
        }
        let per = if c.collapses > 0 {
            format!("{}", c.instructions / u64::from(c.collapses))
        } else {
            "-".into()
        };
        crate::outln!(
            "  {:<26} {:>6} {:>6} {:>9} {:>13} {:>11} {:>9} {:>10}  {}",
            c.name,
            c.triangles_in,
            c.triangles_out,
            c.collapses,
            c.instructions,
            per,
            c.stack_bytes,
            c.stack_high_water,
            c.verdict
        );
    }
    for (integer, float) in integer_beside_float(m) {
        crate::outln!(
            "  {:<26} {:>11} instr/coll in integers; {} {}",
            integer.name,
            per_collapse_of(integer).map_or("-".into(), |p| p.to_string()),
            float.map_or("-", |f| f.name.as_str()),
            float
                .and_then(per_collapse_of)
                .map_or("not run here".into(), |p| format!("{p} in floats"))
        );
    }
    for l in &m.largest {
        let it = if l.index_type == IndexType::U16 {
            "u16"
        } else {
            "u32"
        };
        let ok = match l.ok {
            Some((v, t, i)) => format!("{t} triangles / {v} vertices simplify ({i} instructions)"),
            None => "nothing simplifies".into(),
        };
        let fail = match &l.fail {
            Some((v, t, why)) => format!("{t} / {v} fail: {why}"),
            None => "no failure up to the search limit".into(),
        };
        crate::outln!(
            "largest {it} mesh (bisecting `strip T`, Config::new()): {ok}; {fail} [{} runs, {:.1} s]",
            l.probes,
            l.wall.as_secs_f64()
        );
    }
    crate::outln!(
        "  {:<26} {:>6} {:>13} {:>13} {:>13} {:>9}  vs host   [progressive streams, instructions per split]",
        "stream",
        "splits",
        "decode",
        "collapse",
        "split",
        "stack"
    );
    for st in &m.streams {
        if st.verdict != "identical" {
            crate::outln!("  {:<26} {}", st.name, st.verdict);
            continue;
        }
        let per = |x: u64| format!("{:.0}", x as f64 / f64::from(st.splits.max(1)));
        crate::outln!(
            "  {:<26} {:>6} {:>13} {:>13} {:>13} {:>9}  {}",
            st.name,
            st.splits,
            per(st.decode),
            per(st.coarsen),
            per(st.refine),
            st.stack_bytes,
            st.verdict
        );
    }
}

/// The summary table of several boards' measurements.
pub fn print_summary(ms: &[Measurement]) {
    if ms.is_empty() {
        return;
    }
    crate::outln!(
        "\nsummary ({} backend); sizes in bytes; lib = firmware image with - without the library; \
         1-inst = one instantiation ({ONE_INSTANTIATION}; scripts/flash.sh); \
         instr/collapse over the cases run (min..max)",
        ms[0].backend
    );
    crate::outln!(
        "{:<20} {:>9} {:>9} {:>9} {:>12} {:>9} {:>9} {:>17} {:>10} {:>15} {:>15}",
        "board",
        "fw flash",
        "fw RAM",
        "lib flash",
        "1-inst flash",
        "lib RAM",
        "lib stack",
        "instr/collapse",
        "high-water",
        "largest u16",
        "largest u32"
    );
    for m in ms {
        let range = per_collapse(m).map_or("-".into(), |(a, b)| format!("{a}..{b}"));
        let largest = |i: usize| {
            m.largest
                .get(i)
                .and_then(|l| l.ok)
                .map_or("-".into(), |(v, t, _)| format!("{t} T/{v} V"))
        };
        crate::outln!(
            "{:<20} {:>9} {:>9} {:>9} {:>12} {:>9} {:>9} {:>17} {:>10} {:>15} {:>15}",
            m.board.name,
            m.sizes.flash,
            m.sizes.static_ram,
            delta(m.sizes.flash, m.sizes_without.flash),
            delta(m.instantiation.1, m.instantiation.0),
            delta(m.sizes.static_ram, m.sizes_without.static_ram),
            m.cases.iter().map(|c| c.stack_bytes).max().unwrap_or(0),
            range,
            m.cases
                .iter()
                .map(|c| c.stack_high_water)
                .max()
                .unwrap_or(0),
            largest(0),
            largest(1)
        );
    }
}

/// Instructions per collapse of a case the board ran identically (`None`: skipped, failed,
/// or no collapse).
fn per_collapse_of(c: &CaseMeasurement) -> Option<u64> {
    (c.verdict == "identical" && c.collapses > 0).then(|| c.instructions / u64::from(c.collapses))
}

/// The board's integer cases, each with its float case's measurement on the same board (if the
/// manifest has it).
fn integer_beside_float(m: &Measurement) -> Vec<(&CaseMeasurement, Option<&CaseMeasurement>)> {
    m.cases
        .iter()
        .filter_map(|c| {
            let twin = c.float_twin.as_deref()?;
            Some((c, m.cases.iter().find(|f| f.name == twin)))
        })
        .collect()
}

/// The least and the most instructions per collapse over the cases a board ran.
fn per_collapse(m: &Measurement) -> Option<(u64, u64)> {
    let per = m
        .cases
        .iter()
        .filter(|c| c.collapses > 0)
        .map(|c| c.instructions / u64::from(c.collapses));
    Some((per.clone().min()?, per.max()?))
}

/// A number with a space between thousands, as the docs write them (`34 846`).
pub fn spaced(n: u64) -> String {
    let d = n.to_string();
    let mut out = String::new();
    for (i, c) in d.chars().enumerate() {
        if i > 0 && (d.len() - i).is_multiple_of(3) {
            out.push(' ');
        }
        out.push(c);
    }
    out
}

/// The measurements as the Markdown tables of bench/DEVICES.md: per board, per case that
/// ran, per progressive stream. The docs quote these figures; a docs test checks the quotes.
pub fn markdown(ms: &[Measurement]) -> String {
    use std::fmt::Write;
    let mut s = String::new();
    let backend = ms.first().map_or(String::new(), |m| m.backend.to_string());
    let _ = write!(
        s,
        "# Device measurements\n\nWritten by `cargo run -p host-sim --release -- qemu --measure \
         --out bench/DEVICES.md` ({backend} backend); do not edit. Sizes in bytes. Instructions \
         are exact (QEMU `-icount shift=0`, SysTick or `mcycle` read around the call). Library \
         flash and RAM: the test firmware with the library minus without it; 1-inst flash: one \
         instantiation ({ONE_INSTANTIATION}, as `scripts/flash.sh` measures it). \
         [docs/devices.md](../docs/devices.md) says what each column means.\n\n## Boards\n\n\
         | board | firmware flash | firmware RAM | library flash | 1-inst flash | library RAM | \
         library stack | stack high-water | instructions per collapse | largest mesh u16 | \
         largest mesh u32 |\n|---|---:|---:|---:|---:|---:|---:|---:|---|---|---|\n"
    );
    for m in ms {
        let range = per_collapse(m).map_or("-".into(), |(a, b)| {
            format!("{} – {}", spaced(a), spaced(b))
        });
        let largest = |i: usize| {
            m.largest
                .get(i)
                .and_then(|l| l.ok)
                .map_or("-".into(), |(_, t, _)| {
                    format!("{} triangles", spaced(t as u64))
                })
        };
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
            m.board.name,
            spaced(m.sizes.flash),
            spaced(m.sizes.static_ram),
            spaced(delta(m.sizes.flash, m.sizes_without.flash).max(0) as u64),
            spaced(delta(m.instantiation.1, m.instantiation.0).max(0) as u64),
            spaced(delta(m.sizes.static_ram, m.sizes_without.static_ram).max(0) as u64),
            spaced(u64::from(
                m.cases.iter().map(|c| c.stack_bytes).max().unwrap_or(0)
            )),
            spaced(u64::from(
                m.cases
                    .iter()
                    .map(|c| c.stack_high_water)
                    .max()
                    .unwrap_or(0)
            )),
            range,
            largest(0),
            largest(1)
        );
    }
    s += "\n## Cases\n\nEvery golden case a board ran (a case too big for a board is skipped).\n\n\
          | board | case | triangles in → out | collapses | instructions | per collapse | \
          library stack |\n|---|---|---|---:|---:|---:|---:|\n";
    for m in ms {
        for c in m.cases.iter().filter(|c| c.verdict == "identical") {
            let per = c.instructions / u64::from(c.collapses.max(1));
            let _ = writeln!(
                s,
                "| {} | {} | {} → {} | {} | {} | {} | {} |",
                m.board.name,
                c.name,
                spaced(u64::from(c.triangles_in)),
                spaced(u64::from(c.triangles_out)),
                spaced(u64::from(c.collapses)),
                spaced(c.instructions),
                spaced(per),
                spaced(u64::from(c.stack_bytes))
            );
        }
    }
    // The integer path beside the float path: per integer case its float case on the same
    // board (the boards without an FPU run both in software) and on the reference board.
    let reference = ms.iter().find(|m| m.board.name == super::REFERENCE_BOARD);
    let _ = write!(
        s,
        "\n## Integer path\n\nEvery case of the pipeline in integers (`pipeline::Integer`, the mesh \
         on the 15-bit grid) beside its float case (the same mesh and target): instructions per \
         collapse on the board, of the float case on the same board (- where the board has no \
         float mode or skips it) and on {} (Cortex-M4F, FPU).\n\n\
         | board | integer case | per collapse | float case | float per collapse | float on {} |\n\
         |---|---|---:|---|---:|---:|\n",
        super::REFERENCE_BOARD,
        super::REFERENCE_BOARD
    );
    for m in ms {
        for (integer, float) in integer_beside_float(m) {
            let Some(per) = per_collapse_of(integer) else {
                continue;
            };
            let twin = integer.float_twin.as_deref().unwrap_or("-");
            let cell = |c: Option<&CaseMeasurement>| {
                c.and_then(per_collapse_of).map_or("-".into(), spaced)
            };
            let on_reference = reference.and_then(|r| r.cases.iter().find(|f| f.name == twin));
            let _ = writeln!(
                s,
                "| {} | {} | {} | {} | {} | {} |",
                m.board.name,
                integer.name,
                spaced(per),
                twin,
                cell(float),
                cell(on_reference)
            );
        }
    }
    s += "\n## Progressive streams\n\nEach golden stream decoded on the board; instructions per \
          split (decoding, coarsening every level, refining every level).\n\n\
          | board | stream | splits | decode | coarsen | refine |\n|---|---|---:|---:|---:|---:|\n";
    for m in ms {
        for st in &m.streams {
            let per = |x: u64| spaced(x / u64::from(st.splits.max(1)));
            let _ = writeln!(
                s,
                "| {} | {} | {} | {} | {} | {} |",
                m.board.name,
                st.name,
                spaced(u64::from(st.splits)),
                per(st.decode),
                per(st.coarsen),
                per(st.refine)
            );
        }
    }
    s
}

#[cfg(test)]
mod tests {
    #[test]
    fn thousands_are_spaced_as_the_docs_write_them() {
        assert_eq!(super::spaced(0), "0");
        assert_eq!(super::spaced(999), "999");
        assert_eq!(super::spaced(34_846), "34 846");
        assert_eq!(super::spaced(91_018_440), "91 018 440");
    }
}
