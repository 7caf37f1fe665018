//! Golden results: the exact output of every case in `tests/golden/cases.toml`, per math
//! backend, checked on the host (`host-sim golden --check`) and on every emulated board
//! (`host-sim qemu --check`).
//!
//! Layout of `tests/golden/`:
//!
//! * `cases.toml`: the cases, written by hand. Each names a mesh (a generator of
//!   [`meshfmt::golden`], e.g. `grid 12`, or a file under `tests/`, optionally cut to a box and
//!   with extra positions/triangles appended), the configuration (`Config::new()` or
//!   `Config::paper()` with schedule, ratio, target, λ and feature mode spelled out) and the
//!   index type of the triangles.
//! * `<backend>/<case>.bin`: the expected output triangles, exactly as the library leaves them
//!   in the caller's buffer: `triangles_out × 3` indices of the case's index type,
//!   little-endian (the bytes the firmware writes after its result header).
//! * `<backend>/<case>.txt`: readable and TOML: the case, the hash of its input, every count of
//!   the library's report and the SHA-256 of the `.bin`. Regenerated from a run and compared as
//!   text, so any change in a count shows as a changed line.
//!
//! `<backend>` is `libm` or `micromath`, the library's two math backends (a compile-time
//! feature: host-sim's `micromath` feature forwards to `tinydecimate/micromath`).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode};

use anyhow::{anyhow, bail, Context, Result};
use meshfmt::file::{decode_result, encode_case, encode_result};
use meshfmt::{Board, CostCode, ErrorKind, IndexType, ResultHeader, Status};
use serde::Deserialize;
use sha2::{Digest, Sha256};
use tinydecimate::bound::Controls;
use tinydecimate::{
    Builtin, Config, FeatureMode, NoBound, Placement, Positions, Schedule, StoredQuadric,
};

use crate::workspace::HostWorkspace;

pub mod stream;

/// The case list inside the golden directory.
pub const MANIFEST: &str = "cases.toml";

/// The repository root (the parent of host-sim).
pub fn repo_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("host-sim lives inside the repository")
        .to_path_buf()
}

/// The golden directory: `tests/golden`.
pub fn default_dir() -> PathBuf {
    repo_root().join("tests").join("golden")
}

// ---------------------------------------------------------------------------------------------
// Math backends

/// The library's math backend (its `micromath` feature). Chosen when host-sim is compiled.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Backend {
    /// libm, the default: correctly rounded `sqrtf`.
    Libm,
    /// micromath: fast approximations.
    Micromath,
}

impl Backend {
    /// Both backends.
    pub const ALL: [Backend; 2] = [Backend::Libm, Backend::Micromath];

    /// The backend this host-sim binary was built with.
    pub const fn compiled() -> Self {
        if cfg!(feature = "micromath") {
            Backend::Micromath
        } else {
            Backend::Libm
        }
    }

    /// `libm` or `micromath`: the golden subdirectory and the cargo feature.
    pub const fn name(self) -> &'static str {
        match self {
            Backend::Libm => "libm",
            Backend::Micromath => "micromath",
        }
    }
}

impl std::fmt::Display for Backend {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// Set in the environment of a re-invoked host-sim, so it never re-invokes itself again.
const REINVOKED: &str = "HOST_SIM_REINVOKED";

/// Runs this same command line again through `cargo run -p host-sim`, built for `backend`
/// (same profile; same target directory, so both builds stay cached side by side). The host
/// side of a check must run the library with the backend being checked, and the backend is a
/// compile-time feature. Returns the child's exit code.
pub fn reinvoke(backend: Backend) -> Result<ExitCode> {
    if std::env::var_os(REINVOKED).is_some() {
        bail!(
            "host-sim built with {} was asked for {backend} again after re-invoking itself",
            Backend::compiled()
        );
    }
    let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    let mut cmd = Command::new(cargo);
    cmd.arg("run");
    if !cfg!(debug_assertions) {
        cmd.arg("--release");
    }
    cmd.args(["-p", "host-sim", "--manifest-path"])
        .arg(repo_root().join("Cargo.toml"));
    if backend == Backend::Micromath {
        cmd.args(["--features", "micromath"]);
    }
    if std::env::var_os("CARGO_TARGET_DIR").is_none() {
        // Run from its target directory by path: build the other variant next to it.
        if let Some(dir) = std::env::current_exe()
            .ok()
            .and_then(|e| Some(e.parent()?.parent()?.to_path_buf()))
            .filter(|d| d.join("CACHEDIR.TAG").exists())
        {
            cmd.arg("--target-dir").arg(dir);
        }
    }
    cmd.arg("--").args(std::env::args_os().skip(1));
    cmd.env(REINVOKED, "1");
    eprintln!(
        "host-sim: this binary runs the library with {}; re-running under `cargo run -p host-sim{}` for --backend {backend}",
        Backend::compiled(),
        if backend == Backend::Micromath {
            " --features micromath"
        } else {
            ""
        }
    );
    let status = cmd.status().context("re-running host-sim through cargo")?;
    Ok(ExitCode::from(
        status.code().map_or(2, |c| u8::try_from(c).unwrap_or(2)),
    ))
}

// ---------------------------------------------------------------------------------------------
// Cases

/// The base configuration of a case.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum Base {
    /// `Config::new()`: the measured defaults.
    New,
    /// `Config::paper()`: the paper as written.
    Paper,
}

/// Schedule as written in the manifest.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum ScheduleName {
    /// `Schedule::Greedy`.
    Greedy,
    /// `Schedule::Passes`.
    Passes,
}

/// Feature mode as written in the manifest.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum Features {
    /// `features = false`.
    Off,
    /// `FeatureMode::Paper`.
    Paper,
    /// `FeatureMode::ValenceNormalized`.
    Valence,
}

/// Stored quadrics as written in the manifest (`quadric = "stored-subset"`).
#[derive(Clone, Copy, Debug, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "kebab-case")]
pub enum QuadricName {
    /// `StoredQuadric` with `Placement::Subset`.
    StoredSubset,
    /// `StoredQuadric` with `Placement::Optimal`.
    StoredOptimal,
}

/// Index type as written in the manifest.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum IndexName {
    /// `u16` triangles.
    U16,
    /// `u32` triangles.
    U32,
}

/// One `[[case]]` of the manifest.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct CaseSpec {
    /// File name of the golden files (letters, digits, `-`).
    pub name: String,
    /// What the case checks (free text).
    #[serde(default)]
    pub about: String,
    /// A generator spec (`grid 12`, see [`meshfmt::golden::GENERATORS`]) or a mesh file
    /// relative to the repository root, under `tests/`.
    pub mesh: String,
    /// Keep only the triangles whose three vertices lie in this box
    /// `[xmin, ymin, zmin, xmax, ymax, zmax]`; unused vertices are dropped.
    #[serde(default)]
    pub cut: Option<[f32; 6]>,
    /// Positions appended after the (cut) mesh's.
    #[serde(default)]
    pub append_positions: Vec<[f32; 3]>,
    /// Triangles appended after the (cut) mesh's (degenerate, duplicate, out-of-range ...).
    #[serde(default)]
    pub append_triangles: Vec<[u32; 3]>,
    /// `new` (`Config::new()`) or `paper` (`Config::paper()`); the fields below override it.
    pub config: Base,
    /// `greedy` or `passes`.
    pub schedule: ScheduleName,
    /// Target ratio.
    pub ratio: f32,
    /// Target triangle count (0: ratio only).
    #[serde(default)]
    pub target_triangles: usize,
    /// λ of the feature test.
    pub lambda: f32,
    /// `off`, `paper` or `valence`.
    pub features: Features,
    /// `u16` or `u32`.
    pub index: IndexName,
    /// Optional: `stored-subset` or `stored-optimal` (stored quadrics instead of the config's
    /// cost; boundary planes weighted by the config's boundary weight).
    #[serde(default)]
    pub quadric: Option<QuadricName>,
    /// Optional: the guaranteed error bound (the control points of Zhu, Wang and Meng 2007,
    /// `Controls`) as a fraction of the bounding-box diagonal; the case file
    /// carries it in input units.
    #[serde(default)]
    pub max_error: Option<f32>,
}

impl CaseSpec {
    /// The library configuration.
    pub fn config(&self) -> Config {
        let mut c = match self.config {
            Base::New => Config::new(),
            Base::Paper => Config::paper(),
        }
        .with_schedule(match self.schedule {
            ScheduleName::Greedy => Schedule::Greedy,
            ScheduleName::Passes => Schedule::Passes,
        })
        .with_ratio(self.ratio)
        .with_target_triangles(self.target_triangles)
        .with_lambda(self.lambda);
        match self.features {
            Features::Off => c.features = false,
            Features::Paper => c = c.with_feature_mode(FeatureMode::Paper),
            Features::Valence => c = c.with_feature_mode(FeatureMode::ValenceNormalized),
        }
        c
    }

    /// The index type.
    pub fn index_type(&self) -> IndexType {
        match self.index {
            IndexName::U16 => IndexType::U16,
            IndexName::U32 => IndexType::U32,
        }
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Manifest {
    case: Vec<CaseSpec>,
    /// Progressive-stream cases (host-sim/src/streamcase.rs).
    #[serde(default)]
    stream: Vec<stream::StreamSpec>,
}

/// The mesh of a case: a generator spec of [`meshfmt::golden`] or a file under `tests/`.
pub fn load_mesh(name: &str, spec: &str) -> Result<meshfmt::golden::Mesh> {
    Ok(match meshfmt::golden::generate(spec) {
        Some(m) => m.map_err(|e| anyhow!("case {name}: {e:?}"))?,
        None => {
            let rel = Path::new(spec);
            if rel.is_absolute() || !rel.starts_with("tests") {
                bail!(
                    "case {name}: mesh {spec:?} is neither a generator ({}) nor a file under tests/",
                    meshfmt::golden::GENERATORS
                        .iter()
                        .map(|g| g.0)
                        .collect::<Vec<_>>()
                        .join(", ")
                );
            }
            let m =
                crate::io::load(repo_root().join(rel)).with_context(|| format!("case {name}"))?;
            meshfmt::golden::Mesh {
                positions: m.positions,
                triangles: m.triangles,
            }
        }
    })
}

/// A mesh and how to simplify it.
#[derive(Clone, Debug)]
pub struct Case {
    /// File-name friendly name.
    pub name: String,
    /// Where the mesh comes from (generator spec or file, with cut and appended parts).
    pub mesh: String,
    /// Vertex positions.
    pub positions: Vec<[f32; 3]>,
    /// Triangles (written with `index_type`).
    pub triangles: Vec<[u32; 3]>,
    /// Width of the triangle indices the library is called with.
    pub index_type: IndexType,
    /// Simplification settings.
    pub config: Config,
    /// Stored quadrics with this placement instead of `config.cost` (`None`: `simplify`).
    pub stored: Option<tinydecimate::cost::Placement>,
}

impl Case {
    /// Builds the case a manifest entry describes.
    pub fn from_spec(spec: &CaseSpec) -> Result<Case> {
        let name = &spec.name;
        if name.is_empty()
            || !name
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_')
        {
            bail!("case name {name:?}: use letters, digits, '-' and '_'");
        }
        let mut mesh = load_mesh(name, &spec.mesh)?;
        let mut desc = spec.mesh.clone();
        if let Some(b) = spec.cut {
            let inside = |i: u32| {
                mesh.positions
                    .get(i as usize)
                    .is_some_and(|p| (0..3).all(|k| p[k] >= b[k] && p[k] <= b[k + 3]))
            };
            let kept: Vec<_> = mesh
                .triangles
                .iter()
                .copied()
                .filter(|t| t.iter().all(|&i| inside(i)))
                .collect();
            mesh.triangles = kept;
            meshfmt::golden::compact(&mut mesh);
            let _ = write!(desc, ", cut to {b:?}");
        }
        mesh.positions.extend_from_slice(&spec.append_positions);
        mesh.triangles.extend_from_slice(&spec.append_triangles);
        if !spec.append_positions.is_empty() || !spec.append_triangles.is_empty() {
            let _ = write!(
                desc,
                ", + {} positions, + {} triangles",
                spec.append_positions.len(),
                spec.append_triangles.len()
            );
        }
        let config = match spec.max_error {
            Some(f) => spec.config().with_relative_max_error(f, &mesh.positions),
            None => spec.config(),
        };
        Ok(Case {
            name: name.clone(),
            mesh: desc,
            positions: mesh.positions,
            triangles: mesh.triangles,
            index_type: spec.index_type(),
            config,
            stored: spec.quadric.map(|q| match q {
                QuadricName::StoredSubset => tinydecimate::cost::Placement::Subset,
                QuadricName::StoredOptimal => tinydecimate::cost::Placement::Optimal,
            }),
        })
    }

    /// The case file the firmware reads.
    pub fn encode(&self) -> Result<Vec<u8>> {
        let h = self.header();
        encode_case(&h, &self.positions, &self.triangles)
            .map_err(|e| anyhow!("case {}: {e:?}", self.name))
    }

    /// The case file's header: the configuration, and the stored-quadric code if any.
    pub fn header(&self) -> meshfmt::CaseHeader {
        let mut h = meshfmt::lib::case_header(&self.config, self.index_type);
        match self.stored {
            Some(tinydecimate::cost::Placement::Subset) => h.cost = CostCode::StoredSubset,
            Some(tinydecimate::cost::Placement::Optimal) => h.cost = CostCode::StoredOptimal,
            None => {}
        }
        h
    }

    /// Bytes of RAM the firmware needs for this case's buffers (positions + triangles).
    pub fn buffer_bytes(&self) -> usize {
        self.positions.len() * 12 + self.triangles.len() * self.index_type.triangle_bytes()
    }
}

/// Reads the manifest `dir/cases.toml` and builds every case, in manifest order.
pub fn load_cases(dir: &Path) -> Result<Vec<Case>> {
    load_specs(dir)?.iter().map(Case::from_spec).collect()
}

/// Reads the manifest `dir/cases.toml`: its simplification cases.
pub fn load_specs(dir: &Path) -> Result<Vec<CaseSpec>> {
    Ok(manifest(dir)?.case)
}

/// Reads the manifest `dir/cases.toml`: its progressive-stream cases.
pub fn load_stream_specs(dir: &Path) -> Result<Vec<stream::StreamSpec>> {
    Ok(manifest(dir)?.stream)
}

fn manifest(dir: &Path) -> Result<Manifest> {
    let path = dir.join(MANIFEST);
    let text =
        std::fs::read_to_string(&path).with_context(|| format!("reading {}", path.display()))?;
    let m: Manifest = toml::from_str(&text).with_context(|| format!("{}", path.display()))?;
    let names: Vec<&str> = m
        .case
        .iter()
        .map(|c| c.name.as_str())
        .chain(m.stream.iter().map(|c| c.name.as_str()))
        .collect();
    for (i, n) in names.iter().enumerate() {
        if names[..i].contains(n) {
            bail!("{}: case {n:?} twice", path.display());
        }
    }
    if m.case.is_empty() {
        bail!("{}: no cases", path.display());
    }
    Ok(m)
}

// ---------------------------------------------------------------------------------------------
// Outcomes and the host reference

/// A simplification outcome, as the result file carries it.
#[derive(Clone, Debug, PartialEq)]
pub struct Outcome {
    /// Status, report counts, and (from a board) the measurements.
    pub header: ResultHeader,
    /// The simplified triangles (`header.triangles_out` of them), widened to `u32`.
    pub triangles: Vec<[u32; 3]>,
}

impl Outcome {
    /// Decodes a result file.
    pub fn decode(bytes: &[u8]) -> Result<Self> {
        let (header, triangles) =
            decode_result(bytes).map_err(|e| anyhow!("result file: {e:?}"))?;
        Ok(Outcome { header, triangles })
    }

    /// Encodes a result file.
    pub fn encode(&self) -> Result<Vec<u8>> {
        encode_result(&self.header, &self.triangles).map_err(|e| anyhow!("{e:?}"))
    }
}

/// Runs the case through the library on the host, exactly as the firmware does (the same
/// policies, the case's index type and the configuration as the case file carries it), on
/// `u32`-link storage sized to the case.
pub fn reference(case: &Case) -> Result<Outcome> {
    let mut ws = HostWorkspace::new(case.positions.len(), case.triangles.len());
    reference_with(&mut ws, case)
}

fn reference_with(ws: &mut HostWorkspace, case: &Case) -> Result<Outcome> {
    let h = case.header();
    let config = meshfmt::lib::config(&h);
    let placement = meshfmt::lib::stored_placement(&h);
    let bounded = meshfmt::lib::bounded(&h);
    let mut positions = case.positions.clone();
    let (outcome, tris): (_, Vec<[u32; 3]>) = match case.index_type {
        IndexType::U16 => {
            let mut t: Vec<[u16; 3]> = case
                .triangles
                .iter()
                .map(|t| {
                    t.map(|i| u16::try_from(i).map_err(|_| anyhow!("{}: index {i}", case.name)))
                })
                .map(|[a, b, c]| Ok([a?, b?, c?]))
                .collect::<Result<_>>()?;
            let r = run_reference(ws, &mut positions, &mut t, &config, placement, bounded);
            let n = r.as_ref().map_or(0, |r| r.triangles_out);
            (r, t[..n].iter().map(|t| t.map(u32::from)).collect())
        }
        IndexType::U32 => {
            let mut t = case.triangles.clone();
            let r = run_reference(ws, &mut positions, &mut t, &config, placement, bounded);
            let n = r.as_ref().map_or(0, |r| r.triangles_out);
            t.truncate(n);
            (r, t)
        }
    };
    let mut header = meshfmt::lib::result_header(case.index_type, &outcome, Board::Host);
    if placement == Some(Placement::Optimal) {
        header.positions_hash = meshfmt::positions_hash(&positions);
    }
    Ok(Outcome {
        header,
        triangles: tris,
    })
}

/// The library call a case asks for, as the firmware makes it.
fn run_reference<I: tinydecimate::Index>(
    ws: &mut HostWorkspace,
    positions: &mut [[f32; 3]],
    triangles: &mut [[I; 3]],
    config: &Config,
    placement: Option<Placement>,
    bounded: bool,
) -> Result<tinydecimate::Report, tinydecimate::Error> {
    let storage = ws.storage();
    if bounded {
        // The firmware lends its quadric storage to these two (`board::BOUND_BYTES`).
        let original = triangles.to_vec();
        let mut links =
            vec![0u32; tinydecimate::bound::control_len(triangles.len(), positions.len())];
        let bound = Controls::new(&original, &mut links);
        let p = Positions::Read(positions);
        return Ok(storage
            .start(p, triangles, config, Builtin::new(), bound)?
            .run());
    }
    let mut quadrics = vec![[0.0f32; 10]; positions.len()];
    let s = match placement {
        None => return ws.storage().simplify(positions, triangles, config),
        Some(Placement::Subset) => storage.start(
            Positions::Read(positions),
            triangles,
            config,
            StoredQuadric::new(&mut quadrics, Placement::Subset),
            NoBound,
        )?,
        Some(Placement::Optimal) => storage.start(
            Positions::Write(positions),
            triangles,
            config,
            StoredQuadric::new(&mut quadrics, Placement::Optimal),
            NoBound,
        )?,
    };
    Ok(s.run())
}

// ---------------------------------------------------------------------------------------------
// Golden files

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
    let features = match (c.features, c.feature_mode) {
        (false, _) => "off",
        (true, FeatureMode::Paper) => "paper",
        (true, FeatureMode::ValenceNormalized) => "valence",
    };
    format!(
        "schedule {}, cost {}, ratio {}, target {}, lambda {}, features {features}, \
         feature_targets {}, max_passes {}, max_cost {}, max_normal_turn_deg {}, min_quality {}, \
         boundary_weight {}",
        match c.schedule {
            Schedule::Greedy => "greedy",
            Schedule::Passes => "passes",
        },
        match c.cost {
            tinydecimate::CostKind::Quadric => "quadric",
            tinydecimate::CostKind::NormalVariation => "normal",
        },
        c.target_ratio,
        c.target_triangles,
        c.lambda,
        c.feature_targets,
        c.max_passes,
        c.max_cost,
        c.max_normal_turn_deg,
        c.min_quality,
        c.boundary_weight
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
        ErrorKind::OriginalMismatch => format!("original triangle {a} differs"),
    }
}

impl Golden {
    /// The golden files `outcome` gives for `case` under `backend`. The measurement block of a
    /// board's result (ticks, stack, capacity) does not enter them.
    pub fn of(case: &Case, backend: Backend, outcome: &Outcome) -> Result<Golden> {
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
        if case.config.max_error.is_finite() {
            writeln!(
                w,
                "max_error = {:e}  # the guaranteed bound, input units",
                case.config.max_error
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
            if case.stored.is_some() {
                " (stored quadrics: the firmware's QUADRIC_VERTICES may be lower)"
            } else if case.config.max_error.is_finite() {
                " (error bound: original triangles and control links in the firmware's BOUND_BYTES)"
            } else {
                ""
            }
        )));
    }
    let got = Golden::of(case, backend, actual)?;
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

/// Runs every case of `dir/cases.toml` on the host and compares with `dir/<backend>/`. The
/// backend must be the one this binary was built with.
pub fn check_host(dir: &Path, backend: Backend) -> Result<Vec<(Case, Verdict)>> {
    if backend != Backend::compiled() {
        bail!(
            "this host-sim runs the library with {}, not {backend}",
            Backend::compiled()
        );
    }
    let mut out = Vec::new();
    for case in load_cases(dir)? {
        let now = reference(&case)?;
        let v = match Golden::load(dir, backend, &case.name)? {
            Some(g) => judge(&case, backend, &g, &now)?,
            None => Verdict::Failed(format!(
                "no golden files {}/{}/{}.txt|.bin (run `host-sim golden --bless --backend {backend}`)",
                dir.display(),
                backend,
                case.name
            )),
        };
        out.push((case, v));
    }
    Ok(out)
}

/// Recomputes every case on the host and writes `dir/<backend>/`; removes the files of cases
/// no longer in the manifest. Returns one line per case saying what changed.
pub fn bless(dir: &Path, backend: Backend) -> Result<Vec<String>> {
    if backend != Backend::compiled() {
        bail!(
            "this host-sim runs the library with {}, not {backend}",
            Backend::compiled()
        );
    }
    let cases = load_cases(dir)?;
    let streams = load_stream_specs(dir)?;
    // The clustering cases (`cluster.toml`, `host-sim qemu --cluster`) share the directories.
    let clusters = crate::qemu::cluster::load_specs(dir)?;
    let mut lines = Vec::new();
    for case in &cases {
        let new = Golden::of(case, backend, &reference(case)?)?;
        let line = match Golden::load(dir, backend, &case.name)? {
            None => format!("{:<28} new      {}", case.name, new.summary()),
            Some(old) if old == new => format!("{:<28} same     {}", case.name, new.summary()),
            Some(old) => {
                let mut s = format!(
                    "{:<28} CHANGED  old {}\n{:<37}new {}",
                    case.name,
                    old.summary(),
                    "",
                    new.summary()
                );
                if let Verdict::Diff(d) = diff(case.index_type, &old, &new) {
                    for l in d {
                        let _ = write!(s, "\n{:<37}{l}", "");
                    }
                }
                s
            }
        };
        new.save(dir, backend, &case.name)?;
        lines.push(line);
    }
    let sub = dir.join(backend.name());
    let mut stale: Vec<_> = std::fs::read_dir(&sub)?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            let stem = p.file_stem().and_then(|s| s.to_str()).unwrap_or("");
            let ext = p.extension().and_then(|s| s.to_str()).unwrap_or("");
            (ext == "txt" || ext == "bin")
                && !cases.iter().any(|c| c.name == stem)
                && !streams.iter().any(|c| c.name == stem)
                && !clusters.iter().any(|c| c.name == stem)
        })
        .collect();
    stale.sort();
    for p in stale {
        std::fs::remove_file(&p)?;
        lines.push(format!("removed {} (not in {MANIFEST})", p.display()));
    }
    Ok(lines)
}

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

#[cfg(test)]
mod tests {
    use super::*;

    /// `host-sim golden --check` on the host, for the backend this test binary was built with
    /// (`cargo test -p host-sim [--features micromath]`).
    #[test]
    fn golden_check_passes_on_the_host() {
        let results = check_host(&default_dir(), Backend::compiled()).unwrap();
        let bad: Vec<_> = results
            .iter()
            .filter(|(_, v)| *v != Verdict::Identical)
            .map(|(c, v)| format!("{}: {v:?}", c.name))
            .collect();
        assert!(
            bad.is_empty(),
            "golden mismatch ({}):\n{}",
            Backend::compiled(),
            bad.join("\n")
        );
    }

    /// The backend switch is real: the two backends' goldens exist for every case, and differ.
    #[test]
    fn libm_and_micromath_goldens_differ() {
        let dir = default_dir();
        let mut differ = Vec::new();
        for spec in load_specs(&dir).unwrap() {
            let l = Golden::load(&dir, Backend::Libm, &spec.name).unwrap();
            let m = Golden::load(&dir, Backend::Micromath, &spec.name).unwrap();
            let (l, m) = (l.expect("libm golden"), m.expect("micromath golden"));
            if l.bin != m.bin {
                differ.push(spec.name);
            }
        }
        assert!(
            !differ.is_empty(),
            "libm and micromath give the same bytes in every case"
        );
    }

    /// The cases cover what the goldens promise, and the micro:bit-sized ones fit it.
    #[test]
    fn manifest_covers_the_required_cases() {
        let specs = load_specs(&default_dir()).unwrap();
        let cases: Vec<_> = specs.iter().map(|s| Case::from_spec(s).unwrap()).collect();
        let has =
            |f: &dyn Fn(&CaseSpec, &Case) -> bool| specs.iter().zip(&cases).any(|(s, c)| f(s, c));
        assert!(has(
            &|s, _| s.config == Base::New && s.config() == Config::new().with_ratio(s.ratio)
        ));
        assert!(has(
            &|s, _| s.config == Base::Paper && s.config() == Config::paper().with_ratio(s.ratio)
        ));
        assert!(has(&|s, _| s.schedule == ScheduleName::Greedy));
        assert!(has(&|s, _| s.schedule == ScheduleName::Passes));
        assert!(has(&|s, _| s.index == IndexName::U16));
        assert!(has(&|s, _| s.index == IndexName::U32));
        assert!(has(&|s, _| s.features == Features::Valence));
        assert!(has(&|s, _| s.features == Features::Off));
        assert!(has(&|s, _| s.target_triangles > 0));
        // Edge use counts: open (an edge with one triangle), non-manifold (three).
        let edge_uses = |c: &Case| {
            let mut e = std::collections::HashMap::new();
            for t in &c.triangles {
                for k in 0..3 {
                    let (a, b) = (t[k], t[(k + 1) % 3]);
                    if a != b {
                        *e.entry((a.min(b), a.max(b))).or_insert(0usize) += 1;
                    }
                }
            }
            e
        };
        assert!(
            has(&|_, c| edge_uses(c).values().any(|&n| n == 1)),
            "open mesh"
        );
        assert!(
            has(&|_, c| edge_uses(c).values().all(|&n| n == 2)),
            "closed mesh"
        );
        assert!(
            has(&|_, c| edge_uses(c).values().any(|&n| n >= 3)),
            "non-manifold edge"
        );
        assert!(
            has(&|s, _| s.mesh.starts_with("tests/fixtures/plate_holes") && s.cut.is_some()),
            "CAD cut"
        );
        assert!(
            has(&|_, c| c
                .triangles
                .iter()
                .any(|t| t[0] == t[1] || t[1] == t[2] || t[0] == t[2])),
            "degenerate"
        );
        // Micro:bit: 240 vertices, 440 u16 / 220 u32 triangles.
        let fits = |c: &Case| {
            c.positions.len() <= 240 && c.triangles.len() * c.index_type.triangle_bytes() <= 440 * 6
        };
        assert!(cases.iter().filter(|c| fits(c)).count() >= 12);
        assert!(cases.iter().any(|c| !fits(c)), "a case the micro:bit skips");
    }

    #[test]
    fn cases_round_trip_through_the_case_file() {
        for c in load_cases(&default_dir()).unwrap() {
            let bytes = c.encode().unwrap();
            let (h, p, t) = meshfmt::file::decode_case(&bytes).unwrap();
            assert_eq!(p, c.positions, "{}", c.name);
            assert_eq!(t, c.triangles, "{}", c.name);
            assert_eq!(meshfmt::lib::config(&h), c.config, "{}", c.name);
        }
    }

    #[test]
    fn diff_names_the_first_differing_triangle() {
        let spec = &load_specs(&default_dir()).unwrap()[0];
        let case = Case::from_spec(spec).unwrap();
        let a = reference(&case).unwrap();
        let ga = Golden::of(&case, Backend::compiled(), &a).unwrap();
        let mut b = a.clone();
        b.header.ticks = 99; // measurement: ignored
        b.header.stack_high_water = 7;
        b.header.board = Board::Microbit;
        assert_eq!(
            judge(&case, Backend::compiled(), &ga, &b).unwrap(),
            Verdict::Identical
        );
        b.header.collapses += 1;
        b.triangles[3][1] += 1;
        match judge(&case, Backend::compiled(), &ga, &b).unwrap() {
            Verdict::Diff(d) => {
                assert!(d[0].starts_with("first differing triangle: #3:"), "{d:?}");
                assert!(d.iter().any(|l| l.contains("collapses")), "{d:?}");
            }
            v => panic!("{v:?}"),
        }
        b.header.status = Status::TooBig;
        assert!(matches!(
            judge(&case, Backend::compiled(), &ga, &b).unwrap(),
            Verdict::Skipped(_)
        ));
    }
}
