//! Golden results: the library run on the host is the reference every emulated board must
//! reproduce bit for bit (same report counts, same triangles in the same order).
//!
//! A [`Case`] is a mesh plus a configuration; it travels to the firmware as a case file and
//! comes back as a result file (both in `meshfmt`, shared with the firmware). [`reference()`]
//! runs the same case through the library on the host and produces the same result format, so
//! [`compare`] can check a board's output against it, ignoring the per-board measurement block
//! (ticks, stack, capacity). Goldens can also be stored as files ([`save`], [`load_dir`]) to
//! notice when the library's output changes between versions.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use meshfmt::file::{decode_result, encode_case, encode_result};
use meshfmt::{Board, IndexType, ResultHeader, Status};
use tinydecimate::{Config, FeatureMode, Schedule, Workspace};

/// A mesh and how to simplify it.
#[derive(Clone, Debug)]
pub struct Case {
    /// File-name friendly name.
    pub name: String,
    /// Vertex positions.
    pub positions: Vec<[f32; 3]>,
    /// Triangles (written with `index_type`).
    pub triangles: Vec<[u32; 3]>,
    /// Width of the triangle indices the library is called with.
    pub index_type: IndexType,
    /// Simplification settings.
    pub config: Config,
}

/// A simplification outcome, as the result file carries it.
#[derive(Clone, Debug, PartialEq)]
pub struct Outcome {
    /// Status, report counts, and (from a board) the measurements.
    pub header: ResultHeader,
    /// The simplified triangles (`header.triangles_out` of them), widened to `u32`.
    pub triangles: Vec<[u32; 3]>,
}

impl Case {
    /// The case file the firmware reads.
    pub fn encode(&self) -> Result<Vec<u8>> {
        let h = meshfmt::lib::case_header(&self.config, self.index_type);
        encode_case(&h, &self.positions, &self.triangles)
            .map_err(|e| anyhow::anyhow!("case {}: {e:?}", self.name))
    }

    /// Bytes of RAM the firmware needs for this case's buffers (positions + triangles).
    pub fn buffer_bytes(&self) -> usize {
        self.positions.len() * 12 + self.triangles.len() * self.index_type.triangle_bytes()
    }
}

impl Outcome {
    /// Decodes a result file.
    pub fn decode(bytes: &[u8]) -> Result<Self> {
        let (header, triangles) =
            decode_result(bytes).map_err(|e| anyhow::anyhow!("result file: {e:?}"))?;
        Ok(Outcome { header, triangles })
    }

    /// Encodes a result file.
    pub fn encode(&self) -> Result<Vec<u8>> {
        encode_result(&self.header, &self.triangles).map_err(|e| anyhow::anyhow!("{e:?}"))
    }
}

/// Workspace capacity of the host reference run. Larger than any board's.
pub const HOST_MAX_VERTICES: usize = 1 << 18;
/// See [`HOST_MAX_VERTICES`].
pub const HOST_MAX_TRIANGLES: usize = 1 << 19;
type HostWorkspace = Workspace<u32, HOST_MAX_VERTICES, HOST_MAX_TRIANGLES>;

/// Runs the case through the library on the host, exactly as the firmware does
/// (`Workspace::simplify` with the case's index type).
pub fn reference(case: &Case) -> Result<Outcome> {
    let case = case.clone();
    // The workspace is ~11 MB; build it on a thread with room for it even in debug builds,
    // where `Box::new` may construct it on the stack first.
    std::thread::Builder::new()
        .stack_size(64 << 20)
        .spawn(move || {
            let mut ws: Box<HostWorkspace> = Box::new(Workspace::new());
            reference_with(&mut ws, &case)
        })?
        .join()
        .map_err(|_| anyhow::anyhow!("reference run panicked"))?
}

fn reference_with(ws: &mut HostWorkspace, case: &Case) -> Result<Outcome> {
    let config = meshfmt::lib::config(&meshfmt::lib::case_header(&case.config, case.index_type));
    let (outcome, tris): (_, Vec<[u32; 3]>) = match case.index_type {
        IndexType::U16 => {
            let mut t: Vec<[u16; 3]> = case
                .triangles
                .iter()
                .map(|t| t.map(|i| u16::try_from(i).unwrap_or(u16::MAX)))
                .collect();
            let r = ws.simplify(&case.positions, &mut t, &config);
            let n = r.as_ref().map_or(0, |r| r.triangles_out);
            (r, t[..n].iter().map(|t| t.map(u32::from)).collect())
        }
        IndexType::U32 => {
            let mut t = case.triangles.clone();
            let r = ws.simplify(&case.positions, &mut t, &config);
            let n = r.as_ref().map_or(0, |r| r.triangles_out);
            t.truncate(n);
            (r, t)
        }
    };
    let header = meshfmt::lib::result_header(case.index_type, &outcome, Board::Host);
    Ok(Outcome {
        header,
        triangles: tris,
    })
}

/// How a board's outcome relates to the reference.
#[derive(Clone, Debug, PartialEq)]
pub enum Verdict {
    /// Same status, report and triangles.
    Match,
    /// The board could not hold the mesh (not a failure of the library).
    TooBig,
    /// Differences, described.
    Mismatch(Vec<String>),
}

/// Compares a board's outcome with the reference, ignoring the measurement block.
pub fn compare(expected: &Outcome, actual: &Outcome) -> Verdict {
    if actual.header.status == Status::TooBig {
        return Verdict::TooBig;
    }
    let mut diffs = Vec::new();
    let (e, a) = (&expected.header, &actual.header);
    macro_rules! field {
        ($($f:ident),*) => {$(
            if e.$f != a.$f {
                diffs.push(format!("{}: expected {:?}, got {:?}", stringify!($f), e.$f, a.$f));
            }
        )*};
    }
    field!(
        index_type,
        status,
        error_kind,
        error_a,
        error_b,
        triangles_in,
        degenerate_dropped,
        duplicates_dropped,
        triangles_out,
        target_triangles,
        target_reached,
        stop,
        pass_log_len,
        collapses,
        vertices_removed,
        locked_vertices,
        feature_vertices,
        passes,
        rejected,
        pass_triangles
    );
    debug_assert_eq!(diffs.is_empty(), e.same_outcome(a));
    if expected.triangles.len() != actual.triangles.len() {
        diffs.push(format!(
            "triangle count: expected {}, got {}",
            expected.triangles.len(),
            actual.triangles.len()
        ));
    }
    if let Some(i) = expected
        .triangles
        .iter()
        .zip(&actual.triangles)
        .position(|(x, y)| x != y)
    {
        diffs.push(format!(
            "triangle {i}: expected {:?}, got {:?}",
            expected.triangles[i], actual.triangles[i]
        ));
    }
    if diffs.is_empty() {
        Verdict::Match
    } else {
        Verdict::Mismatch(diffs)
    }
}

/// Writes `<dir>/<name>.case` and `<dir>/<name>.golden` (the reference result).
pub fn save(dir: &Path, case: &Case, golden: &Outcome) -> Result<()> {
    std::fs::create_dir_all(dir)?;
    std::fs::write(dir.join(format!("{}.case", case.name)), case.encode()?)?;
    std::fs::write(dir.join(format!("{}.golden", case.name)), golden.encode()?)?;
    Ok(())
}

/// A stored golden: the case file bytes and the expected outcome.
pub struct Stored {
    /// Case name (file stem).
    pub name: String,
    /// The `.case` file.
    pub case_path: PathBuf,
    /// Its bytes.
    pub case_bytes: Vec<u8>,
    /// The `.golden` result.
    pub golden: Outcome,
}

impl Stored {
    /// The case, decoded again (to rerun the reference on the host).
    pub fn case(&self) -> Result<Case> {
        let (h, positions, triangles) = meshfmt::file::decode_case(&self.case_bytes)
            .map_err(|e| anyhow::anyhow!("{}: {e:?}", self.case_path.display()))?;
        Ok(Case {
            name: self.name.clone(),
            positions,
            triangles,
            index_type: h.index_type,
            config: meshfmt::lib::config(&h),
        })
    }
}

/// Reads every `<name>.case` with its `<name>.golden` from `dir`, sorted by name.
pub fn load_dir(dir: &Path) -> Result<Vec<Stored>> {
    let mut out = Vec::new();
    for entry in std::fs::read_dir(dir).with_context(|| format!("{}", dir.display()))? {
        let path = entry?.path();
        if path.extension().and_then(|e| e.to_str()) != Some("case") {
            continue;
        }
        let name = path
            .file_stem()
            .unwrap_or_default()
            .to_string_lossy()
            .into_owned();
        let golden_path = path.with_extension("golden");
        let case_bytes = std::fs::read(&path)?;
        let golden = Outcome::decode(
            &std::fs::read(&golden_path).with_context(|| format!("{}", golden_path.display()))?,
        )
        .with_context(|| format!("{}", golden_path.display()))?;
        out.push(Stored {
            name,
            case_path: path,
            case_bytes,
            golden,
        });
    }
    out.sort_by(|a, b| a.name.cmp(&b.name));
    if out.is_empty() {
        bail!("no .case files in {}", dir.display());
    }
    Ok(out)
}

// ---------------------------------------------------------------------------------------------
// Built-in meshes and cases: small enough for the 16 KB micro:bit (≤ 240 vertices and ≤ 440 u16
// or 220 u32 triangles), chosen to exercise both schedules, both index types, both feature
// modes, boundaries, dropped input triangles and a library error.

/// A bumpy `n × n` grid of quads on z = height(x, y): `(n+1)²` vertices, `2n²` triangles, with
/// a boundary. Coordinates are small multiples of 1/8, exact in `f32`.
pub fn bumpy_grid(n: u32) -> (Vec<[f32; 3]>, Vec<[u32; 3]>) {
    let w = n + 1;
    let mut p = Vec::new();
    for y in 0..w {
        for x in 0..w {
            let h = ((x * 7 + y * 3) % 5) as f32 * 0.125 + if x > n / 2 { 1.0 } else { 0.0 };
            p.push([x as f32, y as f32, h]);
        }
    }
    let mut t = Vec::new();
    for y in 0..n {
        for x in 0..n {
            let v = y * w + x;
            t.push([v, v + 1, v + w + 1]);
            t.push([v, v + w + 1, v + w]);
        }
    }
    (p, t)
}

/// An icosphere (closed, no boundary): 12 vertices / 20 triangles, each subdivision ×4.
pub fn icosphere(subdivisions: u32) -> (Vec<[f32; 3]>, Vec<[u32; 3]>) {
    let g = (1.0 + 5f64.sqrt()) / 2.0;
    let mut p: Vec<[f64; 3]> = vec![
        [-1.0, g, 0.0],
        [1.0, g, 0.0],
        [-1.0, -g, 0.0],
        [1.0, -g, 0.0],
        [0.0, -1.0, g],
        [0.0, 1.0, g],
        [0.0, -1.0, -g],
        [0.0, 1.0, -g],
        [g, 0.0, -1.0],
        [g, 0.0, 1.0],
        [-g, 0.0, -1.0],
        [-g, 0.0, 1.0],
    ];
    let mut t: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..subdivisions {
        let mut mid = std::collections::HashMap::new();
        let mut next = Vec::new();
        let mut midpoint = |a: u32, b: u32, p: &mut Vec<[f64; 3]>| -> u32 {
            *mid.entry((a.min(b), a.max(b))).or_insert_with(|| {
                let (pa, pb) = (p[a as usize], p[b as usize]);
                p.push([
                    (pa[0] + pb[0]) / 2.0,
                    (pa[1] + pb[1]) / 2.0,
                    (pa[2] + pb[2]) / 2.0,
                ]);
                (p.len() - 1) as u32
            })
        };
        for [a, b, c] in t {
            let ab = midpoint(a, b, &mut p);
            let bc = midpoint(b, c, &mut p);
            let ca = midpoint(c, a, &mut p);
            next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        t = next;
    }
    let p = p
        .into_iter()
        .map(|v| {
            let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            [(v[0] / l) as f32, (v[1] / l) as f32, (v[2] / l) as f32]
        })
        .collect();
    (p, t)
}

/// The built-in cases (all fit every board).
pub fn builtin_cases() -> Vec<Case> {
    let (gp, gt) = bumpy_grid(12); // 169 vertices, 288 triangles
    let (sp, st) = icosphere(2); // 162 vertices, 320 triangles
    let (tp, tt) = bumpy_grid(8); // 81 vertices, 128 triangles
    let mut dirty = tt.clone();
    dirty.extend([[3, 3, 4], [0, 1, 10], [5, 6, 6]]); // two degenerate, one duplicate
    let mut bad = tt.clone();
    bad[7][1] = 81; // one past the last vertex
    let case = |name: &str, p: &Vec<[f32; 3]>, t: &Vec<[u32; 3]>, it, config| Case {
        name: name.into(),
        positions: p.clone(),
        triangles: t.clone(),
        index_type: it,
        config,
    };
    let base = Config::new();
    vec![
        case(
            "grid12-greedy-u16",
            &gp,
            &gt,
            IndexType::U16,
            base.with_ratio(0.25).with_schedule(Schedule::Greedy),
        ),
        case(
            "grid12-passes-u16",
            &gp,
            &gt,
            IndexType::U16,
            base.with_ratio(0.5)
                .with_schedule(Schedule::Passes)
                .with_lambda(1.0),
        ),
        case(
            "sphere2-greedy-u16",
            &sp,
            &st,
            IndexType::U16,
            base.with_ratio(0.2).with_schedule(Schedule::Greedy),
        ),
        case(
            "sphere2-passes-valence-u16",
            &sp,
            &st,
            IndexType::U16,
            base.with_ratio(0.3)
                .with_schedule(Schedule::Passes)
                .with_feature_mode(FeatureMode::ValenceNormalized)
                .with_lambda(1.5),
        ),
        case(
            "grid8-greedy-u32",
            &tp,
            &tt,
            IndexType::U32,
            base.with_ratio(0.3).with_schedule(Schedule::Greedy),
        ),
        case(
            "grid8-dirty-passes-u32",
            &tp,
            &dirty,
            IndexType::U32,
            base.with_ratio(0.4).with_schedule(Schedule::Passes),
        ),
        case(
            "grid8-target-count-u16",
            &tp,
            &tt,
            IndexType::U16,
            base.with_ratio(0.0).with_target_triangles(40),
        ),
        case(
            "grid8-bad-index-u16",
            &tp,
            &bad,
            IndexType::U16,
            base.with_ratio(0.5),
        ),
    ]
}

/// A grid case as large as `max_vertices` / `max_triangles` allow (for capacity runs).
pub fn largest_grid_case(max_vertices: usize, max_triangles: usize, index_type: IndexType) -> Case {
    let mut n = 1u32;
    while ((n + 2) * (n + 2)) as usize <= max_vertices
        && (2 * (n + 1) * (n + 1)) as usize <= max_triangles
    {
        n += 1;
    }
    let (positions, triangles) = bumpy_grid(n);
    Case {
        name: format!("grid{n}-capacity"),
        positions,
        triangles,
        index_type,
        config: Config::new()
            .with_ratio(0.25)
            .with_schedule(Schedule::Greedy),
    }
}

/// The directory of stored goldens: `host-sim/golden`.
pub fn default_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("golden")
}

/// Recomputes the reference of every built-in case and stores it in `dir`.
pub fn bless(dir: &Path) -> Result<usize> {
    let cases = builtin_cases();
    for c in &cases {
        save(dir, c, &reference(c)?)?;
    }
    Ok(cases.len())
}

/// Checks the stored goldens in `dir` against the library on the host: the stored case files
/// still decode and the library still gives the stored results. Returns the names that differ.
pub fn check_host(dir: &Path) -> Result<Vec<(String, Vec<String>)>> {
    let mut bad = Vec::new();
    for s in load_dir(dir)? {
        let now = reference(&s.case()?)?;
        if let Verdict::Mismatch(d) = compare(&s.golden, &now) {
            bad.push((s.name.clone(), d));
        }
    }
    Ok(bad)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn builtin_cases_fit_the_microbit_and_round_trip() {
        for c in builtin_cases() {
            assert!(c.positions.len() <= 240, "{}", c.name);
            let cap = 440 * 6 / c.index_type.triangle_bytes();
            assert!(c.triangles.len() <= cap, "{}", c.name);
            let bytes = c.encode().unwrap();
            let (h, p, t) = meshfmt::file::decode_case(&bytes).unwrap();
            assert_eq!(p, c.positions);
            assert_eq!(t, c.triangles);
            assert_eq!(meshfmt::lib::config(&h), c.config);
        }
    }

    #[test]
    fn reference_is_deterministic_and_round_trips() {
        for c in builtin_cases() {
            let a = reference(&c).unwrap();
            let b = reference(&c).unwrap();
            assert_eq!(compare(&a, &b), Verdict::Match, "{}", c.name);
            let again = Outcome::decode(&a.encode().unwrap()).unwrap();
            assert_eq!(again, a);
        }
    }

    #[test]
    fn bad_index_is_a_library_error() {
        let c = builtin_cases()
            .into_iter()
            .find(|c| c.name == "grid8-bad-index-u16")
            .unwrap();
        let r = reference(&c).unwrap();
        assert_eq!(r.header.status, Status::LibraryError);
        assert_eq!(r.header.error_kind, meshfmt::ErrorKind::IndexOutOfRange);
    }

    #[test]
    fn compare_reports_differences() {
        let c = &builtin_cases()[0];
        let a = reference(c).unwrap();
        let mut b = a.clone();
        b.header.ticks = 99; // measurement: ignored
        assert_eq!(compare(&a, &b), Verdict::Match);
        b.header.collapses += 1;
        b.triangles[0][0] += 1;
        match compare(&a, &b) {
            Verdict::Mismatch(d) => assert_eq!(d.len(), 2, "{d:?}"),
            v => panic!("{v:?}"),
        }
    }
}
