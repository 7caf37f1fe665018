//! The simplification cases of `tests/golden/cases.toml`: the manifest ([`CaseSpec`]), the
//! mesh and configuration each one builds ([`Case`]), and the host's run of a case exactly as
//! the firmware makes it ([`fn@reference`]).

use std::fmt::Write as _;
use std::path::Path;

use anyhow::{anyhow, bail, Context, Result};
use meshfmt::file::{decode_result, encode_case, encode_result};
use meshfmt::{Board, Entry, IndexType, MethodCode, ResultHeader};
use serde::Deserialize;
use tinydecimate::bound::{Controls, Envelope};
use tinydecimate::cost::Energy;
use tinydecimate::{
    Builtin, Config, EdgeCollapse, FeatureMode, NoBound, Placement, Positions, Schedule,
    StoredQuadric, VertexDecimation,
};

use super::MANIFEST;
use crate::repo_root;
use crate::workspace::HostWorkspace;

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

/// A plug-in as written in the manifest (`method = "vertex-decimation"`): the operator or the
/// cost instead of the edge collapse with the config's cost.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "kebab-case")]
pub enum MethodName {
    /// The operator `VertexDecimation::new()` with the built-in cost.
    VertexDecimation,
    /// The cost `cost::Energy::new` (Hoppe's energy), edge collapse.
    Energy,
    /// The fast mode (`pipeline::FastWorkspace::simplify`): meshoptimizer's pipeline, its own
    /// quadrics and workspace.
    Fast,
    /// The lean mode (`pipeline::LeanWorkspace::simplify`): the fast mode's pipeline without
    /// stored quadrics, its own workspace.
    Lean,
    /// The fast mode on the mesh welded by position with its wedges
    /// (`FastWorkspace::simplify_with_wedges`): the host welds (`seam::weld`), the case file
    /// carries the welded triangles and the wedges.
    FastWedges,
    /// The lean mode with wedges (`LeanWorkspace::simplify_with_wedges`), as `FastWedges`.
    LeanWedges,
    /// The fast mode in integers (`FastWorkspace<_, _, _, pipeline::Integer>::simplify`): the
    /// host puts the mesh on the 15-bit grid (`pipeline::quantise`), the case file carries the
    /// grid coordinates.
    FastInteger,
    /// The lean mode in integers (`LeanWorkspace<_, _, _, pipeline::Integer>::simplify`), as
    /// `FastInteger`.
    LeanInteger,
    /// The built-in cost with the edge collapse under the envelope bound (`bound::Envelope`),
    /// `max_error` its `ε`.
    Envelope,
    /// `VertexDecimation::new()` under the envelope bound, `max_error` its `ε`.
    EnvelopeDecimation,
}

impl MethodName {
    /// The case file's method code.
    pub fn code(self) -> MethodCode {
        match self {
            MethodName::VertexDecimation => MethodCode::VertexDecimation,
            MethodName::Energy => MethodCode::Energy,
            MethodName::Fast => MethodCode::Fast,
            MethodName::Lean => MethodCode::Lean,
            MethodName::FastWedges => MethodCode::FastWedges,
            MethodName::LeanWedges => MethodCode::LeanWedges,
            MethodName::FastInteger => MethodCode::FastInteger,
            MethodName::LeanInteger => MethodCode::LeanInteger,
            MethodName::Envelope => MethodCode::Envelope,
            MethodName::EnvelopeDecimation => MethodCode::EnvelopeDecimation,
        }
    }

    /// Whether the method runs in integers on grid positions.
    pub fn integer(self) -> bool {
        matches!(self, MethodName::FastInteger | MethodName::LeanInteger)
    }

    /// The pipeline's mode of a fast or lean method (`None` for the other methods).
    pub fn pipeline(self) -> Option<crate::simplify::Pipeline> {
        use crate::simplify::Pipeline;
        match self {
            MethodName::Fast | MethodName::FastWedges | MethodName::FastInteger => {
                Some(Pipeline::Fast)
            }
            MethodName::Lean | MethodName::LeanWedges | MethodName::LeanInteger => {
                Some(Pipeline::Lean)
            }
            MethodName::VertexDecimation
            | MethodName::Energy
            | MethodName::Envelope
            | MethodName::EnvelopeDecimation => None,
        }
    }
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
    /// Optional: `vertex-decimation` (the operator `VertexDecimation`), `energy` (the cost
    /// `cost::Energy`), `fast` (the fast mode, `pipeline::FastWorkspace`), `lean` (the lean
    /// mode, `pipeline::LeanWorkspace`), `fast-wedges` / `lean-wedges` (either on the mesh
    /// welded by position with its wedges), or `fast-integer` / `lean-integer` (either in
    /// integers, on the mesh put on the 15-bit grid); none with `quadric` or `max_error`.
    #[serde(default)]
    pub method: Option<MethodName>,
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
        .with_target(meshfmt::lib::target(
            self.ratio,
            meshfmt::narrow(self.target_triangles),
        ))
        .with_lambda(self.lambda);
        match self.features {
            Features::Off => c = c.with_features(false),
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
    /// Progressive-stream cases (host-sim/src/golden/stream.rs).
    #[serde(default)]
    stream: Vec<super::stream::StreamSpec>,
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

/// `positions` put on the 15-bit grid (`pipeline::quantise`), each grid coordinate as the
/// `f32` an integer case file carries (exact: below 2¹⁵).
pub fn grid_positions(positions: &[[f32; 3]]) -> Result<Vec<[f32; 3]>> {
    let mut grid = vec![[0u16; 3]; positions.len()];
    tinydecimate::pipeline::quantise(positions, &mut grid).map_err(|e| anyhow!("quantise: {e}"))?;
    Ok(grid.iter().map(|q| q.map(f32::from)).collect())
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
    /// Triangles (written with `index_type`); welded by position for a wedge method.
    pub triangles: Vec<[u32; 3]>,
    /// A wedge method's wedges: the mesh's own triangles, one per welded triangle (else empty).
    pub wedges: Vec<[u32; 3]>,
    /// Width of the triangle indices the library is called with.
    pub index_type: IndexType,
    /// Simplification settings.
    pub config: Config,
    /// Stored quadrics with this placement instead of `config.cost` (`None`: `simplify`).
    pub stored: Option<tinydecimate::cost::Placement>,
    /// A plug-in instead of the edge collapse with `config.cost` (`None`: as `stored` says).
    pub method: Option<MethodName>,
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
        let envelope = matches!(
            spec.method,
            Some(MethodName::Envelope | MethodName::EnvelopeDecimation)
        );
        if envelope && (spec.quadric.is_some() || spec.max_error.is_none()) {
            bail!("case {name}: an envelope method takes `max_error` and no `quadric`");
        }
        if !envelope
            && spec.method.is_some()
            && (spec.quadric.is_some() || spec.max_error.is_some())
        {
            bail!("case {name}: `method` goes with neither `quadric` nor `max_error`");
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
        // A wedge method gets the mesh welded by position, its own triangles as the wedges.
        let mut wedges = Vec::new();
        if matches!(
            spec.method,
            Some(MethodName::FastWedges | MethodName::LeanWedges)
        ) {
            wedges = vec![[0u32; 3]; mesh.triangles.len()];
            let mut order = vec![0u32; mesh.positions.len()];
            tinydecimate::seam::weld(
                &mesh.positions,
                &mut mesh.triangles,
                &mut wedges,
                &mut order,
            )
            .map_err(|e| anyhow!("case {name}: weld: {e}"))?;
            let _ = write!(desc, ", welded by position with its wedges");
        }
        // An integer method gets the mesh on the 15-bit grid, each grid coordinate written as an
        // `f32` (exact): the case file keeps its layout and the firmware converts in place
        // (`meshfmt::grid_position`). The configuration carries no error limit, so none needs
        // converting to grid cells.
        if spec.method.is_some_and(MethodName::integer) {
            mesh.positions =
                grid_positions(&mesh.positions).with_context(|| format!("case {name}"))?;
            let _ = write!(desc, ", on the 15-bit grid (pipeline::quantise)");
        }
        Ok(Case {
            name: name.clone(),
            mesh: desc,
            positions: mesh.positions,
            triangles: mesh.triangles,
            wedges,
            index_type: spec.index_type(),
            config,
            stored: spec.quadric.map(|q| match q {
                QuadricName::StoredSubset => tinydecimate::cost::Placement::Subset,
                QuadricName::StoredOptimal => tinydecimate::cost::Placement::Optimal,
            }),
            method: spec.method,
        })
    }

    /// The case file the firmware reads.
    pub fn encode(&self) -> Result<Vec<u8>> {
        let h = self.header();
        encode_case(&h, &self.positions, &self.triangles, &self.wedges)
            .map_err(|e| anyhow!("case {}: {e:?}", self.name))
    }

    /// The case file's header: the configuration, and the stored-quadric or plug-in code if
    /// any.
    pub fn header(&self) -> meshfmt::CaseHeader {
        let mut h = meshfmt::lib::case_header(&self.config, self.index_type);
        match self.stored {
            Some(tinydecimate::cost::Placement::Subset) => h.method = MethodCode::StoredSubset,
            Some(tinydecimate::cost::Placement::Optimal) => h.method = MethodCode::StoredOptimal,
            None => {}
        }
        if let Some(m) = self.method {
            h.method = m.code();
        }
        h
    }

    /// A case of the pipeline in integers stands beside the float case of the same mesh,
    /// target and mode: its name without "-integer" (`cow-fast-integer-u16` beside
    /// `cow-fast-u16`). `None` for any other case.
    pub fn float_twin(&self) -> Option<String> {
        if !self.method.is_some_and(MethodName::integer) {
            return None;
        }
        let (head, tail) = self.name.split_once("-integer")?;
        Some(format!("{head}{tail}"))
    }

    /// Whether the run borrows one `[f32; 10]` per vertex (stored quadrics, the energy's
    /// samples): the firmware's quadric storage, `board::QUADRIC_VERTICES` of them.
    pub fn per_vertex_storage(&self) -> bool {
        self.header().entry().per_vertex_storage()
    }

    /// Bytes of RAM the firmware needs for this case's buffers (positions + triangles, and
    /// the wedges after the triangles).
    pub fn buffer_bytes(&self) -> usize {
        self.positions.len() * 12
            + (self.triangles.len() + self.wedges.len()) * self.index_type.triangle_bytes()
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
pub fn load_stream_specs(dir: &Path) -> Result<Vec<super::stream::StreamSpec>> {
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
    let entry = h.entry();
    let mut positions = case.positions.clone();
    let narrow = |tris: &[[u32; 3]]| -> Result<Vec<[u16; 3]>> {
        tris.iter()
            .map(|t| t.map(|i| u16::try_from(i).map_err(|_| anyhow!("{}: index {i}", case.name))))
            .map(|[a, b, c]| Ok([a?, b?, c?]))
            .collect()
    };
    // An integer case's positions as the firmware converts them.
    let grid: Vec<[u16; 3]> = if entry.integer() {
        positions
            .iter()
            .map(|&p| meshfmt::grid_position(p))
            .collect()
    } else {
        Vec::new()
    };
    let (outcome, tris): (_, Vec<[u32; 3]>) = match case.index_type {
        IndexType::U16 => {
            let (mut t, mut w) = (narrow(&case.triangles)?, narrow(&case.wedges)?);
            let r = run_reference(
                ws,
                (&mut positions, &grid),
                (&mut t, &mut w),
                &config,
                entry,
            );
            let n = r.as_ref().map_or(0, |r| r.triangles_out);
            (r, t[..n].iter().map(|t| t.map(u32::from)).collect())
        }
        IndexType::U32 => {
            let (mut t, mut w) = (case.triangles.clone(), case.wedges.clone());
            let r = run_reference(
                ws,
                (&mut positions, &grid),
                (&mut t, &mut w),
                &config,
                entry,
            );
            let n = r.as_ref().map_or(0, |r| r.triangles_out);
            t.truncate(n);
            (r, t)
        }
    };
    let mut header = meshfmt::lib::result_header(case.index_type, &outcome, Board::Host);
    if entry == Entry::StoredOptimal {
        header.positions_hash = meshfmt::positions_hash(&positions);
    }
    Ok(Outcome {
        header,
        triangles: tris,
    })
}

/// The library call a case asks for, as the firmware makes it (`grid`: an integer case's
/// positions).
fn run_reference<I: tinydecimate::Index>(
    ws: &mut HostWorkspace,
    (positions, grid): (&mut [[f32; 3]], &[[u16; 3]]),
    (triangles, wedges): (&mut [[I; 3]], &mut [[I; 3]]),
    config: &Config,
    entry: Entry,
) -> Result<tinydecimate::Report, tinydecimate::Error> {
    let mut storage = ws.storage();
    // The firmware lends its quadric storage to the stored quadrics, the energy's samples and
    // the bound's original triangles and links (`board::BOUND_BYTES`).
    let mut quadrics = vec![[0.0f32; 10]; positions.len()];
    Ok(match entry {
        Entry::Simplify => storage.simplify(positions, triangles, config)?,
        Entry::Bounded => {
            let original = triangles.to_vec();
            let mut links =
                vec![0u32; tinydecimate::bound::control_len(triangles.len(), positions.len())];
            let bound = Controls::new(&original, &mut links);
            let p = Positions::Read(positions);
            storage
                .start(p, triangles, config, Builtin::new(), bound, EdgeCollapse)?
                .run()
        }
        Entry::Envelope | Entry::EnvelopeDecimation => {
            // The grid's words are `u32` here and the board's `Link` there: the outcome does
            // not depend on the grid (its tests are exact, each pair once).
            let original = triangles.to_vec();
            let mut shell = vec![[[0.0f32; 3]; 2]; positions.len()];
            let mut index = vec![0u32; tinydecimate::bound::index_len(triangles.len())];
            let bound = Envelope::new(&original, &mut shell, &mut index);
            let p = Positions::Read(positions);
            if entry == Entry::Envelope {
                storage
                    .start(p, triangles, config, Builtin::new(), bound, EdgeCollapse)?
                    .run()
            } else {
                storage
                    .start(
                        p,
                        triangles,
                        config,
                        Builtin::new(),
                        bound,
                        VertexDecimation::new(),
                    )?
                    .run()
            }
        }
        Entry::StoredSubset => storage
            .start(
                Positions::Read(positions),
                triangles,
                config,
                StoredQuadric::new(&mut quadrics, Placement::Subset),
                NoBound,
                EdgeCollapse,
            )?
            .run(),
        Entry::StoredOptimal => storage
            .start(
                Positions::Write(positions),
                triangles,
                config,
                StoredQuadric::new(&mut quadrics, Placement::Optimal),
                NoBound,
                EdgeCollapse,
            )?
            .run(),
        Entry::VertexDecimation => storage
            .start(
                Positions::Read(positions),
                triangles,
                config,
                Builtin::new(),
                NoBound,
                VertexDecimation::new(),
            )?
            .run(),
        Entry::Energy => storage
            .start(
                Positions::Read(positions),
                triangles,
                config,
                Energy::new(&mut quadrics),
                NoBound,
                EdgeCollapse,
            )?
            .run(),
        Entry::Fast | Entry::Lean => {
            crate::simplify::pipeline_run(pipeline_of(entry), positions, triangles, config)?
        }
        Entry::FastWedges | Entry::LeanWedges => crate::simplify::pipeline_run_wedges(
            pipeline_of(entry),
            positions,
            (triangles, wedges),
            config,
        )?,
        Entry::FastInteger | Entry::LeanInteger => {
            crate::simplify::pipeline_run_grid(pipeline_of(entry), grid, triangles, config)?
        }
    })
}

/// The pipeline mode of a fast or lean entry (float, with wedges or in integers); the lean
/// mode for any other.
fn pipeline_of(entry: Entry) -> crate::simplify::Pipeline {
    match entry {
        Entry::Fast | Entry::FastWedges | Entry::FastInteger => crate::simplify::Pipeline::Fast,
        _ => crate::simplify::Pipeline::Lean,
    }
}
