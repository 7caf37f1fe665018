//! The golden files of one case ([`Golden`]: the readable `.txt` and the exact `.bin`), and how
//! an outcome compares with them ([`Verdict`], [`judge`], [`diff`]).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use meshfmt::{ErrorKind, IndexType, ResultHeader, Status};
use sha2::{Digest, Sha256};
use tinydecimate::{Config, FeatureMode, Schedule};

use super::case::{Case, Outcome};
use crate::backend::Backend;

/// The golden files of one case: the readable `.txt` and the exact `.bin`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Golden {
    /// `<case>.txt`.
    pub txt: String,
    /// `<case>.bin`: the output triangles, little-endian, in the case's index type.
    pub bin: Vec<u8>,
}

/// Lower-case hex SHA-256.
pub fn sha256_hex(bytes: &[u8]) -> String {
    Sha256::digest(bytes)
        .iter()
        .fold(String::with_capacity(64), |mut s, b| {
            let _ = write!(s, "{b:02x}");
            s
        })
}

/// Triangles as the firmware and the library's caller hold them: little-endian indices of
/// `it`.
pub fn triangle_bytes(it: IndexType, triangles: &[[u32; 3]]) -> Vec<u8> {
    let mut out = Vec::with_capacity(triangles.len() * it.triangle_bytes());
    for &i in triangles.iter().flatten() {
        match it {
            // Board outputs come from u16 buffers; host ones were checked on the way in.
            IndexType::U16 => out.extend_from_slice(&(i as u16).to_le_bytes()),
            IndexType::U32 => out.extend_from_slice(&i.to_le_bytes()),
        }
    }
    out
}

fn triangles_of(it: IndexType, bytes: &[u8]) -> Vec<[u32; 3]> {
    let w = it.bytes();
    bytes
        .chunks_exact(3 * w)
        .map(|c| {
            let f = |k: usize| match it {
                IndexType::U16 => u32::from(u16::from_le_bytes([c[2 * k], c[2 * k + 1]])),
                IndexType::U32 => {
                    u32::from_le_bytes([c[4 * k], c[4 * k + 1], c[4 * k + 2], c[4 * k + 3]])
                }
            };
            [f(0), f(1), f(2)]
        })
        .collect()
}

fn config_line(c: &Config) -> String {
    let features = match (c.features(), c.feature_mode()) {
        (false, _) => "off",
        (true, FeatureMode::Paper) => "paper",
        (true, FeatureMode::ValenceNormalized) => "valence",
    };
    let (ratio, target) = meshfmt::lib::target_fields(c.target());
    format!(
        "schedule {}, cost {}, ratio {}, target {}, lambda {}, features {features}, \
         feature_targets {}, max_passes {}, max_cost {}, max_normal_turn_deg {}, min_quality {}, \
         boundary_weight {}",
        match c.schedule() {
            Schedule::Greedy => "greedy",
            Schedule::Passes => "passes",
            Schedule::Batched => "batched",
        },
        match c.cost() {
            tinydecimate::CostKind::Quadric => "quadric",
            tinydecimate::CostKind::NormalVariation => "normal",
        },
        ratio,
        target,
        c.lambda(),
        c.feature_targets(),
        c.max_passes(),
        c.max_cost(),
        c.max_normal_turn_deg(),
        c.min_quality(),
        c.boundary_weight()
    )
}

fn error_text(h: &ResultHeader) -> String {
    let (a, b) = (h.error_a, h.error_b);
    match h.error_kind {
        ErrorKind::None => String::new(),
        ErrorKind::CapacityVertices => format!("capacity: {a} vertices needed, {b} available"),
        ErrorKind::CapacityTriangles => format!("capacity: {a} triangles needed, {b} available"),
        ErrorKind::IndexOutOfRange => format!("index out of range: triangle {a}, index {b}"),
        ErrorKind::NonFinitePosition => format!("non-finite position: vertex {a}"),
        ErrorKind::InvalidConfig => format!("invalid config: field {a}"),
        ErrorKind::CapacityQuadrics => format!("capacity: {a} quadrics needed, {b} available"),
        ErrorKind::CapacityControls => format!("capacity: {a} control links needed, {b} available"),
        ErrorKind::CapacityEnvelope => {
            format!("capacity: {a} envelope words needed, {b} available")
        }
        ErrorKind::OriginalMismatch => format!("original triangle {a} differs"),
        ErrorKind::OffGrid => format!("off the grid: vertex {a}"),
    }
}

impl Golden {
    /// The golden files `outcome` gives for `case` under `backend`. The measurement block of a
    /// board's result (ticks, stack, capacity) does not enter them.
    pub fn from_outcome(case: &Case, backend: Backend, outcome: &Outcome) -> Result<Golden> {
        let h = &outcome.header;
        let bin = triangle_bytes(case.index_type, &outcome.triangles);
        let it = match case.index_type {
            IndexType::U16 => "u16",
            IndexType::U32 => "u32",
        };
        let mut t = String::new();
        let w = &mut t;
        writeln!(
            w,
            "# Golden result of case {:?} with the {backend} backend: written by\n\
             # `host-sim golden --bless`, checked by `host-sim golden --check` (host) and\n\
             # `host-sim qemu --check` (every board). {}.bin holds the output triangles.",
            case.name, case.name
        )?;
        writeln!(w, "case = {:?}", case.name)?;
        writeln!(w, "backend = \"{backend}\"")?;
        writeln!(w, "mesh = {:?}", case.mesh)?;
        writeln!(w, "index = \"{it}\"")?;
        writeln!(w, "config = {:?}", config_line(&case.config))?;
        if let Some(p) = case.stored {
            writeln!(w, "quadric = \"stored, {p:?} placement\"")?;
        }
        match case.method {
            Some(super::case::MethodName::VertexDecimation) => {
                writeln!(w, "method = \"vertex decimation, the built-in cost\"")?
            }
            Some(super::case::MethodName::Energy) => {
                writeln!(w, "method = \"Hoppe's energy, edge collapse\"")?
            }
            Some(super::case::MethodName::Fast) => {
                writeln!(w, "method = \"the fast mode (pipeline::FastWorkspace)\"")?
            }
            Some(super::case::MethodName::Lean) => {
                writeln!(w, "method = \"the lean mode (pipeline::LeanWorkspace)\"")?
            }
            Some(super::case::MethodName::FastWedges) => writeln!(
                w,
                "method = \"the fast mode with wedges (FastWorkspace::simplify_with_wedges)\""
            )?,
            Some(super::case::MethodName::LeanWedges) => writeln!(
                w,
                "method = \"the lean mode with wedges (LeanWorkspace::simplify_with_wedges)\""
            )?,
            Some(super::case::MethodName::FastInteger) => writeln!(
                w,
                "method = \"the fast mode in integers (FastWorkspace<_, _, _, Integer>)\""
            )?,
            Some(super::case::MethodName::LeanInteger) => writeln!(
                w,
                "method = \"the lean mode in integers (LeanWorkspace<_, _, _, Integer>)\""
            )?,
            Some(super::case::MethodName::Envelope) => writeln!(
                w,
                "method = \"edge collapse under the envelope bound (bound::Envelope)\""
            )?,
            Some(super::case::MethodName::EnvelopeDecimation) => writeln!(
                w,
                "method = \"vertex decimation under the envelope bound (bound::Envelope)\""
            )?,
            None => {}
        }
        if case.config.max_error().is_finite() {
            writeln!(
                w,
                "max_error = {:e}  # the guaranteed bound, input units",
                case.config.max_error()
            )?;
        }
        writeln!(w, "input_vertices = {}", case.positions.len())?;
        writeln!(w, "input_triangles = {}", case.triangles.len())?;
        writeln!(
            w,
            "input_sha256 = \"{}\"  # the case file: mesh and configuration",
            sha256_hex(&case.encode()?)
        )?;
        writeln!(w)?;
        let status = match h.status {
            Status::Ok => "ok",
            Status::LibraryError => "library error",
            Status::BadCase => "bad case file",
            Status::TooBig => "too big for the board",
        };
        writeln!(w, "status = {status:?}")?;
        if h.status == Status::LibraryError {
            writeln!(w, "error = {:?}", error_text(h))?;
        }
        writeln!(w, "triangles_in = {}", h.triangles_in)?;
        writeln!(w, "degenerate_dropped = {}", h.degenerate_dropped)?;
        writeln!(w, "duplicates_dropped = {}", h.duplicates_dropped)?;
        writeln!(w, "triangles_out = {}", h.triangles_out)?;
        writeln!(w, "target_triangles = {}", h.target_triangles)?;
        writeln!(w, "target_reached = {}", h.target_reached)?;
        let stop = match h.stop {
            0 => "running",
            1 => "target",
            2 => "no legal collapse",
            3 => "max cost",
            4 => "max passes",
            5 => "log full",
            6 => "error limit",
            _ => "?",
        };
        writeln!(w, "stop = {stop:?}")?;
        writeln!(w, "collapses = {}", h.collapses)?;
        writeln!(w, "vertices_removed = {}", h.vertices_removed)?;
        writeln!(w, "locked_vertices = {}", h.locked_vertices)?;
        writeln!(w, "feature_vertices = {}", h.feature_vertices)?;
        writeln!(w, "passes = {}", h.passes)?;
        let rejected: Vec<String> = tinydecimate::RULES
            .iter()
            .zip(h.rejected)
            .map(|(rule, n)| format!("{} = {n}", rule.name))
            .collect();
        writeln!(w, "rejected = {{ {} }}", rejected.join(", "))?;
        writeln!(
            w,
            "pass_triangles = {:?}",
            &h.pass_triangles[..usize::from(h.pass_log_len).min(h.pass_triangles.len())]
        )?;
        writeln!(w)?;
        writeln!(
            w,
            "bin_bytes = {}  # triangles_out x 3 x {} bytes, little-endian",
            bin.len(),
            case.index_type.bytes()
        )?;
        writeln!(w, "bin_sha256 = \"{}\"", sha256_hex(&bin))?;
        if case.stored == Some(tinydecimate::cost::Placement::Optimal) {
            writeln!(
                w,
                "positions_fnv1a = \"{:08x}\"  # every position after the run (optimal placement moves them)",
                h.positions_hash
            )?;
        }
        Ok(Golden { txt: t, bin })
    }

    fn paths(dir: &Path, backend: Backend, name: &str) -> (PathBuf, PathBuf) {
        let d = dir.join(backend.name());
        (d.join(format!("{name}.txt")), d.join(format!("{name}.bin")))
    }

    /// Reads `dir/<backend>/<name>.txt|.bin`; `None` if neither exists.
    pub fn load(dir: &Path, backend: Backend, name: &str) -> Result<Option<Golden>> {
        let (t, b) = Self::paths(dir, backend, name);
        if !t.exists() && !b.exists() {
            return Ok(None);
        }
        let txt = std::fs::read_to_string(&t).with_context(|| format!("{}", t.display()))?;
        let bin = std::fs::read(&b).with_context(|| format!("{}", b.display()))?;
        Ok(Some(Golden { txt, bin }))
    }

    /// Writes `dir/<backend>/<name>.txt|.bin`.
    pub fn save(&self, dir: &Path, backend: Backend, name: &str) -> Result<()> {
        let (t, b) = Self::paths(dir, backend, name);
        std::fs::create_dir_all(t.parent().expect("has a parent"))?;
        std::fs::write(&t, &self.txt).with_context(|| format!("{}", t.display()))?;
        std::fs::write(&b, &self.bin).with_context(|| format!("{}", b.display()))?;
        Ok(())
    }

    /// `sha256 <first 16 hex>, <triangles_out> triangles, <collapses> collapses`, from the text.
    pub fn summary(&self) -> String {
        let t: toml::Table = self.txt.parse().unwrap_or_default();
        let get = |k: &str| t.get(k).map(|v| v.to_string()).unwrap_or("?".into());
        let sha = sha256_hex(&self.bin);
        format!(
            "sha256 {}, {} triangles out, {} collapses, status {}",
            &sha[..16],
            get("triangles_out"),
            get("collapses"),
            get("status")
        )
    }
}

/// How an outcome relates to its golden.
#[derive(Clone, Debug, PartialEq)]
pub enum Verdict {
    /// Same bytes, same counts.
    Identical,
    /// The board cannot hold the mesh; the case is skipped there. Says why.
    Skipped(String),
    /// Differences, the first differing triangle first.
    Diff(Vec<String>),
    /// No outcome (crash, timeout, no golden file ...). Says why.
    Failed(String),
}

impl Verdict {
    /// Table cell.
    pub fn cell(&self) -> &'static str {
        match self {
            Verdict::Identical => "identical",
            Verdict::Skipped(_) => "skipped",
            Verdict::Diff(_) => "DIFF",
            Verdict::Failed(_) => "FAILED",
        }
    }

    /// DIFF or FAILED.
    pub fn is_failure(&self) -> bool {
        matches!(self, Verdict::Diff(_) | Verdict::Failed(_))
    }
}

/// Compares an outcome of `case` with the expected golden files.
pub fn judge(
    case: &Case,
    backend: Backend,
    expected: &Golden,
    actual: &Outcome,
) -> Result<Verdict> {
    let h = &actual.header;
    if h.status == Status::TooBig {
        return Ok(Verdict::Skipped(format!(
            "too big for this board: {} vertices, {} {} triangles; it holds {} vertices, {} triangles{}",
            h.error_a,
            h.error_b,
            if case.index_type == IndexType::U16 { "u16" } else { "u32" },
            h.capacity_vertices,
            h.capacity_triangles,
            if case.per_vertex_storage() {
                " (stored quadrics or energy samples: the firmware's QUADRIC_VERTICES may be lower)"
            } else if case.method == Some(super::case::MethodName::VertexDecimation) {
                " (vertex decimation: the firmware's VERTEX_DECIMATION, stack for a removal's buffers)"
            } else if case.method == Some(super::case::MethodName::Fast) {
                " (the fast mode's workspace: the firmware's FAST_VERTICES and FAST_TRIANGLES, 0 without it)"
            } else if case.method == Some(super::case::MethodName::Lean) {
                " (the lean mode's workspace: the firmware's FAST_VERTICES and FAST_TRIANGLES, 0 without it)"
            } else if case.method == Some(super::case::MethodName::FastInteger) {
                " (the integer fast mode's workspace: the firmware's INT_FAST_VERTICES and INT_FAST_TRIANGLES, 0 without it)"
            } else if case.method == Some(super::case::MethodName::LeanInteger) {
                " (the integer lean mode's workspace: the firmware's INT_LEAN_VERTICES and INT_LEAN_TRIANGLES, 0 without it)"
            } else if matches!(
                case.method,
                Some(super::case::MethodName::Envelope | super::case::MethodName::EnvelopeDecimation)
            ) {
                " (envelope: shell, index words and original triangles in the firmware's BOUND_BYTES; vertex decimation also its VERTEX_DECIMATION)"
            } else if case.config.max_error().is_finite() {
                " (error bound: original triangles and control links in the firmware's BOUND_BYTES)"
            } else {
                ""
            }
        )));
    }
    let got = Golden::from_outcome(case, backend, actual)?;
    Ok(diff(case.index_type, expected, &got))
}

/// The differences between two goldens of the same case: the first differing triangle, then
/// the differing lines of the text.
pub fn diff(it: IndexType, expected: &Golden, got: &Golden) -> Verdict {
    let mut d = Vec::new();
    if expected.bin != got.bin {
        let (e, g) = (triangles_of(it, &expected.bin), triangles_of(it, &got.bin));
        match e.iter().zip(&g).position(|(a, b)| a != b) {
            Some(i) => d.push(format!(
                "first differing triangle: #{i}: expected {:?}, got {:?} ({} vs {} triangles)",
                e[i],
                g[i],
                e.len(),
                g.len()
            )),
            None => d.push(format!(
                "first differing triangle: #{}: expected {}, got {} (the first {} are equal)",
                e.len().min(g.len()),
                e.get(g.len()).map_or("none".into(), |t| format!("{t:?}")),
                g.get(e.len()).map_or("none".into(), |t| format!("{t:?}")),
                e.len().min(g.len())
            )),
        }
    }
    text_diff(&expected.txt, &got.txt, &mut d);
    if d.is_empty() {
        Verdict::Identical
    } else {
        Verdict::Diff(d)
    }
}

/// Appends the lines of `got` that differ from `expected` to `d`, and `...` once it holds 8.
pub fn text_diff(expected: &str, got: &str, d: &mut Vec<String>) {
    let (el, gl): (Vec<_>, Vec<_>) = (expected.lines().collect(), got.lines().collect());
    for i in 0..el.len().max(gl.len()) {
        let (a, b) = (el.get(i).copied(), gl.get(i).copied());
        if a != b {
            d.push(format!(
                "expected `{}`, got `{}`",
                a.unwrap_or("<end>"),
                b.unwrap_or("<end>")
            ));
        }
        if d.len() >= 8 {
            d.push("...".into());
            break;
        }
    }
}
