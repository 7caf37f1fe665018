//! The library run on a mesh in memory, as every command makes it: [`simplify`] (the default
//! call) and [`simplify_with`] (stored quadrics, the error bound, a progress bar), and the
//! report in words ([`format_report`]) and as JSON ([`report_json`]).

use std::sync::Mutex;
use std::time::{Duration, Instant};

use anyhow::{anyhow, Result};
use tinydecimate::bound::{Controls, Envelope};
use tinydecimate::choice::{Chosen, ChosenBound, ChosenCost, ChosenOperator};
use tinydecimate::cost::{
    AttributeQuadric, AttributeState, Energy, Placement, Samples, StoredQuadric, VertexQuadric,
};
use tinydecimate::pipeline::{Arithmetic, FastWorkspace, Integer, LeanWorkspace};
use tinydecimate::{Builtin, Config, Positions, Report, VertexDecimation};

use crate::io::MeshData;
use crate::workspace::HostWorkspace;

/// Which operator, on the command line (`EdgeCollapse`, `TriangleCollapse` or
/// `VertexDecimation`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum OperatorArg {
    /// The default and the one to use: half-edge collapse (one vertex merged into a
    /// neighbour). Lower error and faster than `triangle` (`host-sim bound-table`
    /// measures both).
    #[default]
    Edge,
    /// Triangle collapse of Zhu, Wang and Meng 2007 (§3: weight of eq. 3, penalty
    /// re-insertion; greedy only): a whole triangle becomes one vertex, three vertices at a
    /// time. For comparison with that paper: on real meshes its Hausdorff error is many times
    /// the edge collapse's and it runs about twice as long.
    Triangle,
    /// Vertex decimation of Schroeder, Zarge and Lorensen 1992 (greedy, no bound): a vertex
    /// is removed and its hole filled by loop splitting or by a fan from a ring vertex,
    /// whichever fits the removed vertex best, and the best fit goes first (`Fill::Fit`).
    /// Runs without part pruning; seams welded by position without wedges (the output is
    /// positions only: new triangles have no wedges).
    VertexDecimation,
    /// Vertex decimation as the paper writes it (`Fill::Shape`): the vertex nearest its
    /// average plane (or boundary or feature line) goes first and its hole is filled by loop
    /// splitting chosen for shape; corners never go. Several times the error of
    /// `vertex-decimation` (docs/decimation.md).
    VertexDecimationShape,
}

/// Runs the library on `mesh`. The result keeps all of `mesh`'s positions (the library only
/// rewrites triangles).
/// The cost is `config.cost`; the wall time is that of `Workspace::simplify` alone.
pub fn simplify(mesh: &MeshData, config: &Config) -> Result<(MeshData, Report, Duration)> {
    let mut tris = mesh.triangles.clone();
    let mut ws = HostWorkspace::for_mesh(mesh);
    let start = Instant::now();
    let report = ws
        .storage()
        .simplify(&mesh.positions, &mut tris, config)
        .map_err(|e| anyhow!("tinydecimate: {e}"))?;
    let elapsed = start.elapsed();
    tris.truncate(report.triangles_out);
    let out = MeshData {
        positions: mesh.positions.clone(),
        triangles: tris,
    };
    Ok((out, report, elapsed))
}

/// The library's error, with the command-line options that name the refused field.
pub fn library_error(e: tinydecimate::Error) -> anyhow::Error {
    use tinydecimate::{ConfigField, Error};
    let hint = match e {
        Error::InvalidConfig {
            field: ConfigField::Placement,
        } => " (with --max-error use --placement subset with --quadric stored)",
        Error::InvalidConfig {
            field: ConfigField::Schedule,
        } => " (drop --schedule passes with --quadric stored)",
        Error::InvalidConfig {
            field: ConfigField::ErrorLimit,
        } => " (--error-limit needs --schedule greedy or batched, and not --operator triangle)",
        _ => "",
    };
    anyhow!("tinydecimate: {e}{hint}")
}

/// The policies `host-sim` runs the library with, beside the configuration.
#[derive(Clone, Copy, Debug, Default)]
pub struct Run {
    /// The operator.
    pub operator: OperatorArg,
    /// Stored quadrics with this placement; `None`: the configuration's built-in cost.
    pub placement: Option<Placement>,
    /// The error bound (control points in a `u32` link slice; the bound itself is
    /// `config.max_error`).
    pub bounded: bool,
    /// With `bounded`: the two-sided bound of simplification envelopes (`bound::Envelope`: a
    /// shell pair per position and `bound::index_len` `u32` words) instead of control points.
    pub envelope: bool,
    /// Step with a progress bar.
    pub progress: bool,
    /// Weld seams first (`tinydecimate::seam::weld`: the vertices at one position collapse
    /// together, each keeping its own wedge), when the mesh has any.
    pub weld: bool,
    /// With welded seams, lock the vertices where more than two wedges meet
    /// (`SeamCorners::Lock`, for carried attributes) instead of moving all their wedges
    /// (`SeamCorners::Move`, the default: positions only, nothing to tear).
    pub lock_seam_corners: bool,
    /// Let parts cheaper than the next collapse vanish whole (`Simplifier::with_parts`, two
    /// `u32` links per vertex) in the runs where the library prunes ([`prunes`]).
    pub prune: bool,
    /// Hoppe's energy with this κ (`tinydecimate::cost::Energy`, subset placement) instead of
    /// the configuration's built-in cost; one `Samples` per vertex.
    pub energy: Option<f32>,
    /// The fast or the lean mode (`tinydecimate::pipeline`, [`simplify_pipeline`]) instead of
    /// the exact engine: seams welded by position when `weld` (the output keeps the welded
    /// numbering), no parts, wedges, bound or other cost.
    pub pipeline: Option<Pipeline>,
    /// The pipeline in integers (`pipeline::Integer`), on the positions put on a 15-bit grid.
    pub integer: bool,
}

/// A mode of the library's pipeline (`tinydecimate::pipeline`): the same passes and rules,
/// with or without stored quadrics.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Pipeline {
    /// The fast mode, `pipeline::FastWorkspace`: stored quadrics (about 24.5 B per triangle).
    Fast,
    /// The lean mode, `pipeline::LeanWorkspace`: each quadric built from its vertex's fan
    /// whenever read (about 12.5 B per triangle).
    Lean,
}

impl Pipeline {
    /// The `--engine` value: `fast` or `lean`.
    pub fn name(self) -> &'static str {
        match self {
            Pipeline::Fast => "fast",
            Pipeline::Lean => "lean",
        }
    }

    /// The library's workspace type: `FastWorkspace` or `LeanWorkspace`.
    pub fn workspace(self) -> &'static str {
        match self {
            Pipeline::Fast => "FastWorkspace",
            Pipeline::Lean => "LeanWorkspace",
        }
    }
}

/// Whether two vertices share a position (`-0.0` is `0.0`, as `seam::weld` compares them):
/// otherwise welding renumbers nothing, and its sort is skipped.
fn shares_positions(positions: &[[f32; 3]]) -> bool {
    let mut seen = std::collections::HashSet::with_capacity(positions.len());
    positions
        .iter()
        .any(|p| !seen.insert(p.map(|x| if x == 0.0 { 0 } else { x.to_bits() })))
}

/// Whether some triangle is another turned over, by position (the back of a double-sided
/// surface; the exact engine keeps such backs as twins, the pipeline drops them).
pub fn double_sided(positions: &[[f32; 3]], triangles: &[[u32; 3]]) -> bool {
    let key = |v: u32| {
        positions.get(v as usize).map_or([u32::MAX; 3], |p| {
            p.map(|x| if x == 0.0 { 0 } else { x.to_bits() })
        })
    };
    // Each triangle as its lowest corner first, winding kept.
    let rotated = |t: [[u32; 3]; 3]| {
        let k = (0..3).min_by_key(|&i| t[i]).unwrap_or(0);
        [t[k], t[(k + 1) % 3], t[(k + 2) % 3]]
    };
    let mut seen = std::collections::HashSet::with_capacity(triangles.len());
    triangles.iter().any(|t| {
        let p = t.map(key);
        let back = rotated([p[0], p[2], p[1]]);
        if seen.contains(&back) && back != rotated(p) {
            return true;
        }
        seen.insert(rotated(p));
        false
    })
}

/// Whether a run prunes parts (`Simplifier::with_parts`): asked for, and a run the library
/// prunes in (the greedy or batched schedule, no error bound).
pub fn prunes(prune: bool, config: &Config, bounded: bool) -> bool {
    prune && !bounded && config.schedule().is_ordered()
}

/// Vertex attributes for the attribute-aware stored quadric
/// (`tinydecimate::cost::AttributeQuadric`): per vertex, texture coordinates then a normal
/// (zeros where a mesh has none), and a weight per component (zero switches it off).
#[derive(Clone, Debug, Default)]
pub struct Attributes {
    /// `[u, v, nx, ny, nz]` per vertex.
    pub values: Vec<[f32; ATTRIBUTES]>,
    /// One weight per component.
    pub weights: [f32; ATTRIBUTES],
}

/// Components per vertex in [`Attributes`]: UV and normal.
pub const ATTRIBUTES: usize = 5;

/// Runs the library on `mesh` with the policies of `run`. The library refuses combinations
/// it cannot run. The result carries the positions as the library left them (moved by optimal
/// placement). The wall time is that of the library alone (storage is allocated before).
pub fn simplify_with(
    mesh: &MeshData,
    config: &Config,
    run: &Run,
) -> Result<(MeshData, Report, Duration)> {
    simplify_with_attributes(mesh, config, run, None)
}

/// [`simplify_with`], and with `attributes` the stored quadric with their attribute term
/// (`AttributeQuadric`: stored quadrics with subset placement only, refused otherwise).
pub fn simplify_with_attributes(
    mesh: &MeshData,
    config: &Config,
    run: &Run,
    attributes: Option<&Attributes>,
) -> Result<(MeshData, Report, Duration)> {
    let Run {
        operator,
        placement,
        bounded,
        envelope,
        progress,
        weld,
        lock_seam_corners,
        prune,
        energy,
        pipeline,
        integer,
    } = *run;
    if let Some(mode) = pipeline {
        if attributes.is_some()
            || energy.is_some()
            || placement.is_some()
            || bounded
            || operator != OperatorArg::Edge
        {
            return Err(anyhow!(
                "--engine {} runs its own edge collapse on plane quadrics: it takes no \
                 --max-error, --quadric, --cost energy, --operator or attributes",
                mode.name()
            ));
        }
        let config = config.with_prune_parts(prune);
        return simplify_pipeline(mesh, &config, weld, mode, integer);
    }
    // A removal has no collapse cost to weigh a part against, nor wedges for new triangles:
    // its run is welded by position, and the output keeps the welded numbering.
    let removal = matches!(
        operator,
        OperatorArg::VertexDecimation | OperatorArg::VertexDecimationShape
    );
    let prune = prunes(prune, config, bounded) && !removal;
    let mut part_links = vec![[0u32; 2]; if prune { mesh.positions.len() } else { 0 }];
    let mut tris = mesh.triangles.clone();
    let mut positions = mesh.positions.clone();
    let n = if placement.is_some() {
        positions.len()
    } else {
        0
    };
    let mut quadrics: Vec<VertexQuadric> = vec![[0.0; 10]; n];
    let mut states =
        vec![AttributeState::<ATTRIBUTES>::ZERO; if attributes.is_some() { n } else { 0 }];
    let n = if bounded && !envelope {
        tinydecimate::bound::control_len(tris.len(), positions.len())
    } else {
        0
    };
    let mut links = vec![0u32; n];
    let (ns, ni) = if bounded && envelope {
        (positions.len(), tinydecimate::bound::index_len(tris.len()))
    } else {
        (0, 0)
    };
    let mut shell = vec![[[0.0f32; 3]; 2]; ns];
    let mut index = vec![0u32; ni];
    let mut samples: Vec<Samples> =
        vec![[0.0; 10]; if energy.is_some() { positions.len() } else { 0 }];
    let mut ws = HostWorkspace::for_mesh(mesh);
    let bar = progress.then(|| {
        crate::progress::Progress::new(
            "simplify {bar:40} {pos}/{len} triangles removed ({elapsed})",
            mesh.triangles.len() as u64,
        )
    });
    let start = Instant::now();
    // Welded seams: the wedges (one triangle per triangle) and the welded triangles, which a
    // bound's control points are taken from.
    let mut wedges: Vec<[u32; 3]> = Vec::new();
    let mut welded = Vec::new();
    if weld && shares_positions(&positions) {
        let mut w = vec![[0u32; 3]; tris.len()];
        let mut order = vec![0u32; positions.len()];
        if tinydecimate::seam::weld(&positions, &mut tris, &mut w, &mut order)
            .map_err(library_error)?
            > 0
        {
            // A removal's run takes the welded triangles alone (no wedges).
            if !removal {
                wedges = w;
            }
            welded = tris.clone();
        }
    }
    let original = if welded.is_empty() {
        &mesh.triangles
    } else {
        &welded
    };
    // The policies as the command line chose them; the library runs the combination.
    let operator = match operator {
        OperatorArg::Edge => ChosenOperator::Edge,
        OperatorArg::Triangle => ChosenOperator::Triangle,
        OperatorArg::VertexDecimation => ChosenOperator::VertexDecimation(VertexDecimation::new()),
        OperatorArg::VertexDecimationShape => ChosenOperator::VertexDecimation(
            VertexDecimation::new().with_fill(tinydecimate::Fill::Shape),
        ),
    };
    let bound = if bounded && envelope {
        ChosenBound::Envelope(Envelope::new(original, &mut shell, &mut index))
    } else if bounded {
        ChosenBound::Controls(Controls::new(original, &mut links))
    } else {
        ChosenBound::None
    };
    let cost = if let Some(a) = attributes {
        ChosenCost::Attributes(
            AttributeQuadric::new(&mut quadrics, &mut states, &a.values, a.weights)
                .with_placement(placement.unwrap_or(Placement::Optimal))
                .map_err(|e| {
                    anyhow!(
                        "{} (attribute weights need --quadric stored --placement subset)",
                        e
                    )
                })?,
        )
    } else if let Some(kappa) = energy {
        if placement.is_some() {
            return Err(anyhow!("--cost energy replaces --quadric stored"));
        }
        ChosenCost::Energy(Energy::new(&mut samples).with_weights(1.0, kappa))
    } else {
        match placement {
            None => ChosenCost::Builtin(Builtin::new()),
            Some(p) => ChosenCost::Stored(StoredQuadric::new(&mut quadrics, p)),
        }
    };
    let mut chosen =
        Chosen::new(cost, bound, operator).with_budget(if bounded { 1 << 12 } else { 1 << 14 });
    if !wedges.is_empty() {
        let corners = if lock_seam_corners {
            tinydecimate::seam::SeamCorners::Lock
        } else {
            tinydecimate::seam::SeamCorners::Move
        };
        chosen = chosen.with_wedges(&mut wedges, corners);
    }
    if prune {
        chosen = chosen.with_parts(&mut part_links);
    }
    // Optimal placement writes the positions; every other run only reads them.
    let positions_arg = if placement == Some(Placement::Optimal) && attributes.is_none() {
        Positions::Write(&mut positions)
    } else {
        Positions::Read(&positions)
    };
    let n0 = tris.len();
    let report = ws
        .storage()
        .run_chosen(positions_arg, &mut tris, config, chosen, |removed| {
            if let Some(b) = &bar {
                b.set(removed.min(n0) as u64);
            }
        })
        .map_err(library_error)?;
    let elapsed = start.elapsed();
    if let Some(b) = bar {
        b.finish();
    }
    tris.truncate(report.triangles_out);
    Ok((
        MeshData {
            positions,
            triangles: tris,
        },
        report,
        elapsed,
    ))
}

/// The fast mode's workspaces: `u16` links below 65 535 vertices and triangles, `u32` links up
/// to [`FAST_VERTICES`] and [`FAST_TRIANGLES`] (statics: zero pages until used).
static FAST_SMALL: Mutex<FastWorkspace<u16, 65_535, 65_535>> = Mutex::new(FastWorkspace::new());
static FAST_LARGE: Mutex<FastWorkspace<u32, FAST_VERTICES, FAST_TRIANGLES>> =
    Mutex::new(FastWorkspace::new());
/// The lean mode's workspaces, as the fast mode's.
static LEAN_SMALL: Mutex<LeanWorkspace<u16, 65_535, 65_535>> = Mutex::new(LeanWorkspace::new());
static LEAN_LARGE: Mutex<LeanWorkspace<u32, FAST_VERTICES, FAST_TRIANGLES>> =
    Mutex::new(LeanWorkspace::new());

/// The integer pipeline's workspaces (`--integer`), as the float ones.
static INT_FAST_SMALL: Mutex<FastWorkspace<u16, 65_535, 65_535, Integer>> =
    Mutex::new(FastWorkspace::new());
static INT_FAST_LARGE: Mutex<FastWorkspace<u32, FAST_VERTICES, FAST_TRIANGLES, Integer>> =
    Mutex::new(FastWorkspace::new());
static INT_LEAN_SMALL: Mutex<LeanWorkspace<u16, 65_535, 65_535, Integer>> =
    Mutex::new(LeanWorkspace::new());
static INT_LEAN_LARGE: Mutex<LeanWorkspace<u32, FAST_VERTICES, FAST_TRIANGLES, Integer>> =
    Mutex::new(LeanWorkspace::new());

/// The largest mesh `--engine fast` (and `lean`) takes, in vertices.
pub const FAST_VERTICES: usize = 1 << 20;
/// The largest mesh `--engine fast` (and `lean`) takes, in triangles.
pub const FAST_TRIANGLES: usize = 1 << 21;

/// A workspace of the pipeline: `FastWorkspace` or `LeanWorkspace`, whose `simplify` have one
/// signature.
trait PipelineWorkspace {
    type Position;
    fn run<I: tinydecimate::Index>(
        &mut self,
        positions: &[Self::Position],
        triangles: &mut [[I; 3]],
        wedges: Option<&mut [[I; 3]]>,
        config: &Config,
    ) -> Result<Report, tinydecimate::Error>;
}

impl<L: tinydecimate::Index, const V: usize, const T: usize, N: Arithmetic> PipelineWorkspace
    for FastWorkspace<L, V, T, N>
{
    type Position = N::Position;
    fn run<I: tinydecimate::Index>(
        &mut self,
        positions: &[N::Position],
        triangles: &mut [[I; 3]],
        wedges: Option<&mut [[I; 3]]>,
        config: &Config,
    ) -> Result<Report, tinydecimate::Error> {
        match wedges {
            Some(w) => self.simplify_with_wedges(positions, triangles, w, config),
            None => self.simplify(positions, triangles, config),
        }
    }
}

impl<L: tinydecimate::Index, const V: usize, const T: usize, N: Arithmetic> PipelineWorkspace
    for LeanWorkspace<L, V, T, N>
{
    type Position = N::Position;
    fn run<I: tinydecimate::Index>(
        &mut self,
        positions: &[N::Position],
        triangles: &mut [[I; 3]],
        wedges: Option<&mut [[I; 3]]>,
        config: &Config,
    ) -> Result<Report, tinydecimate::Error> {
        match wedges {
            Some(w) => self.simplify_with_wedges(positions, triangles, w, config),
            None => self.simplify(positions, triangles, config),
        }
    }
}

/// Runs the pipeline in `mode` on `mesh` (seams welded by position first when `weld`): the
/// library call on a workspace of the smallest link type that fits ([`pipeline_run`]). The
/// wall time is that of the weld and the library call.
pub fn simplify_pipeline(
    mesh: &MeshData,
    config: &Config,
    weld: bool,
    mode: Pipeline,
    integer: bool,
) -> Result<(MeshData, Report, Duration)> {
    pipeline_welded(mesh, config, (mode, integer), weld, false)
}

/// The library call of `mode` (`FastWorkspace::simplify` or `LeanWorkspace::simplify`) on
/// `triangles` as they are (any index type), on the workspace of the smallest link type that
/// fits: the host's pipeline run, shared by [`simplify_pipeline`] and the golden reference of
/// a fast or lean case (`host-sim demo`, `qemu`).
pub fn pipeline_run<I: tinydecimate::Index>(
    mode: Pipeline,
    positions: &[[f32; 3]],
    triangles: &mut [[I; 3]],
    config: &Config,
) -> Result<Report, tinydecimate::Error> {
    run_on(mode, positions, triangles, None, config)
}

/// [`pipeline_run`] on a welded mesh with its wedges (`simplify_with_wedges`): the golden
/// reference of a wedge case.
pub fn pipeline_run_wedges<I: tinydecimate::Index>(
    mode: Pipeline,
    positions: &[[f32; 3]],
    (triangles, wedges): (&mut [[I; 3]], &mut [[I; 3]]),
    config: &Config,
) -> Result<Report, tinydecimate::Error> {
    run_on(mode, positions, triangles, Some(wedges), config)
}

/// [`pipeline_run`] with `wedges` (`simplify_with_wedges`) when given.
fn run_on<I: tinydecimate::Index>(
    mode: Pipeline,
    positions: &[[f32; 3]],
    triangles: &mut [[I; 3]],
    wedges: Option<&mut [[I; 3]]>,
    config: &Config,
) -> Result<Report, tinydecimate::Error> {
    let small = positions.len() < 65_535 && triangles.len() < 65_535;
    match (mode, small) {
        (Pipeline::Fast, true) => on(&FAST_SMALL, positions, triangles, wedges, config),
        (Pipeline::Fast, false) => on(&FAST_LARGE, positions, triangles, wedges, config),
        (Pipeline::Lean, true) => on(&LEAN_SMALL, positions, triangles, wedges, config),
        (Pipeline::Lean, false) => on(&LEAN_LARGE, positions, triangles, wedges, config),
    }
}

/// [`run_on`] in integers (`pipeline::Integer`) on grid positions.
fn run_on_grid<I: tinydecimate::Index>(
    mode: Pipeline,
    positions: &[[u16; 3]],
    triangles: &mut [[I; 3]],
    wedges: Option<&mut [[I; 3]]>,
    config: &Config,
) -> Result<Report, tinydecimate::Error> {
    let small = positions.len() < 65_535 && triangles.len() < 65_535;
    match (mode, small) {
        (Pipeline::Fast, true) => on(&INT_FAST_SMALL, positions, triangles, wedges, config),
        (Pipeline::Fast, false) => on(&INT_FAST_LARGE, positions, triangles, wedges, config),
        (Pipeline::Lean, true) => on(&INT_LEAN_SMALL, positions, triangles, wedges, config),
        (Pipeline::Lean, false) => on(&INT_LEAN_LARGE, positions, triangles, wedges, config),
    }
}

/// One library call on a locked workspace.
fn on<W: PipelineWorkspace, I: tinydecimate::Index>(
    ws: &Mutex<W>,
    positions: &[W::Position],
    triangles: &mut [[I; 3]],
    wedges: Option<&mut [[I; 3]]>,
    config: &Config,
) -> Result<Report, tinydecimate::Error> {
    ws.lock()
        .unwrap_or_else(|e| e.into_inner())
        .run(positions, triangles, wedges, config)
}

/// [`pipeline_run`] in integers: `positions` put on the 15-bit grid (`pipeline::quantise`)
/// and the run on it (`FastWorkspace<_, _, _, Integer>`), the error limit and the reported
/// error converted to and from grid cells. Returns the report and the positions the run saw
/// (the grid's, as `f32`): the output is valid with them; with the input's own positions a
/// fold that the grid's rounding hid could show.
pub fn pipeline_run_integer<I: tinydecimate::Index>(
    mode: Pipeline,
    positions: &[[f32; 3]],
    triangles: &mut [[I; 3]],
    wedges: Option<&mut [[I; 3]]>,
    config: &Config,
) -> Result<(Report, Vec<[f32; 3]>), tinydecimate::Error> {
    let mut grid = vec![[0u16; 3]; positions.len()];
    let frame = tinydecimate::pipeline::quantise(positions, &mut grid)?;
    let config = config.with_error_limit(config.error_limit() / frame.step);
    let mut report = run_on_grid(mode, &grid, triangles, wedges, &config)?;
    report.collapse_error *= frame.step;
    Ok((report, grid.iter().map(|&q| frame.position(q)).collect()))
}

/// The library call of `mode` in integers on positions already on the grid (the error limit,
/// if any, in grid cells): the host's run of an integer golden case, whose case file carries
/// the grid positions the firmware runs on.
pub fn pipeline_run_grid<I: tinydecimate::Index>(
    mode: Pipeline,
    positions: &[[u16; 3]],
    triangles: &mut [[I; 3]],
    config: &Config,
) -> Result<Report, tinydecimate::Error> {
    run_on_grid(mode, positions, triangles, None, config)
}

/// Runs the pipeline in `mode` on `mesh` whose vertices carry attributes: seams welded by
/// position and the wedges kept (`simplify_with_wedges`), so the output names the input's
/// vertices and a seam moves as one. The wall time is that of the weld and the library call.
pub fn simplify_pipeline_wedges(
    mesh: &MeshData,
    config: &Config,
    mode: Pipeline,
    integer: bool,
) -> Result<(MeshData, Report, Duration)> {
    pipeline_welded(mesh, config, (mode, integer), true, true)
}

/// The pipeline in `mode` on `mesh`, welded by position first when `weld` and the mesh has
/// seams, with the wedges kept (the output in the input's numbering) when `keep_wedges`, else
/// in the welded numbering.
fn pipeline_welded(
    mesh: &MeshData,
    config: &Config,
    (mode, integer): (Pipeline, bool),
    weld: bool,
    keep_wedges: bool,
) -> Result<(MeshData, Report, Duration)> {
    let mut tris = mesh.triangles.clone();
    let mut order = vec![0u32; if weld { mesh.positions.len() } else { 0 }];
    let mut wedges = vec![[0u32; 3]; if weld { tris.len() } else { 0 }];
    let start = Instant::now();
    let welded = weld && shares_positions(&mesh.positions);
    if welded {
        tinydecimate::seam::weld(&mesh.positions, &mut tris, &mut wedges, &mut order)
            .map_err(library_error)?;
    }
    let wedges = (welded && keep_wedges).then_some(wedges.as_mut_slice());
    let (report, positions) = if integer {
        let (report, grid) = pipeline_run_integer(mode, &mesh.positions, &mut tris, wedges, config)
            .map_err(library_error)?;
        (report, grid)
    } else {
        let report =
            run_on(mode, &mesh.positions, &mut tris, wedges, config).map_err(library_error)?;
        (report, mesh.positions.clone())
    };
    let elapsed = start.elapsed();
    tris.truncate(report.triangles_out);
    Ok((
        MeshData {
            positions,
            triangles: tris,
        },
        report,
        elapsed,
    ))
}

/// Bytes a fast-mode workspace sized exactly for `v` vertices and `t` triangles takes
/// (`FastWorkspace::BYTES`, per element from the library's own sizes), with `u16` links when
/// both are below 65 535.
pub fn fast_bytes(v: usize, t: usize) -> usize {
    pipeline_bytes(Pipeline::Fast, v, t)
}

/// Bytes a lean-mode workspace sized exactly for `v` vertices and `t` triangles takes
/// (`LeanWorkspace::BYTES`), as [`fast_bytes`].
pub fn lean_bytes(v: usize, t: usize) -> usize {
    pipeline_bytes(Pipeline::Lean, v, t)
}

/// Bytes the workspace of `mode` sized exactly for `v` vertices and `t` triangles takes (its
/// `BYTES`, per element from the library's own sizes), with `u16` links when both are below
/// 65 535.
pub fn pipeline_bytes(mode: Pipeline, v: usize, t: usize) -> usize {
    const P: usize = 1024;
    macro_rules! per {
        ($w:ident, $l:ty) => {{
            let pv = ($w::<$l, { 2 * P }, 0>::BYTES - $w::<$l, P, 0>::BYTES) / P;
            let pt = ($w::<$l, 0, { 2 * P }>::BYTES - $w::<$l, 0, P>::BYTES) / P;
            $w::<$l, 0, 0>::BYTES + v * pv + t * pt
        }};
    }
    let small = v < 65_535 && t < 65_535;
    match (mode, small) {
        (Pipeline::Fast, true) => per!(FastWorkspace, u16),
        (Pipeline::Fast, false) => per!(FastWorkspace, u32),
        (Pipeline::Lean, true) => per!(LeanWorkspace, u16),
        (Pipeline::Lean, false) => per!(LeanWorkspace, u32),
    }
}

/// The report, every field, one per line.
pub fn format_report(r: &Report) -> String {
    format_report_for(r, None)
}

/// [`format_report`] with `target` in the target line instead of the triangle count (a run
/// to an error bound alone, whose count of 0 is no target).
pub fn format_report_for(r: &Report, target: Option<&str>) -> String {
    let j = &r.rejected;
    let passes: Vec<String> = r.pass_triangles.iter().map(|t| t.to_string()).collect();
    format!(
        "  triangles in           {}\n\
         \x20 degenerate dropped     {}\n\
         \x20 duplicates dropped     {}\n\
         \x20 double-sided twins     {}\n\
         \x20 triangles out          {} ({:.2} % of the input)\n\
         \x20 target                 {}\n\
         \x20 stop                   {:?}\n\
         \x20 collapses              {}\n\
         \x20 vertices removed       {}\n\
         \x20 parts removed          {}\n\
         \x20 locked vertices        {}\n\
         \x20 feature vertices       {}\n\
         \x20 passes                 {}\n\
         \x20 triangles after pass   [{}]\n\
         \x20 rejected (total {}): {}{}{}",
        r.triangles_in,
        r.degenerate_dropped,
        r.duplicates_dropped,
        r.twins,
        r.triangles_out,
        100.0 * r.triangles_out as f64 / r.triangles_in.max(1) as f64,
        match target {
            Some(t) => t.to_string(),
            None => format!(
                "{} (reached: {})",
                r.target_triangles,
                if r.target_reached { "yes" } else { "no" }
            ),
        },
        r.stop,
        r.collapses,
        r.vertices_removed,
        r.parts_removed,
        r.locked_vertices,
        r.feature_vertices,
        r.passes,
        passes.join(", "),
        j.total(),
        j,
        if r.over_limit > 0 || r.collapse_error > 0.0 {
            format!(
                "\n  error limit            {} candidates over it; largest collapse error made {:.6e}",
                r.over_limit, r.collapse_error
            )
        } else {
            String::new()
        },
        match (r.max_error, r.mean_error) {
            (Some(a), Some(b)) => format!("\n  E_max, E_mean          {a:.6e}, {b:.6e}"),
            _ => String::new(),
        },
    )
}

/// [`simplify`] driven step by step, with a progress bar on stderr when it is a terminal and
/// the run takes over a second. Same result as [`simplify`] (steps of any size give the result
/// of `Storage::simplify`).
pub fn simplify_with_progress(
    mesh: &MeshData,
    config: &Config,
) -> Result<(MeshData, Report, Duration)> {
    simplify_with(
        mesh,
        config,
        &Run {
            progress: true,
            ..Run::default()
        },
    )
}

/// The report as JSON: every field of `Report`.
pub fn report_json(r: &Report) -> serde_json::Value {
    let j = &r.rejected;
    let mut rejected = serde_json::Map::new();
    rejected.insert("total".into(), j.total().into());
    for (rule, n) in j.iter() {
        rejected.insert(rule.name.into(), n.into());
    }
    serde_json::json!({
        "triangles_in": r.triangles_in,
        "degenerate_dropped": r.degenerate_dropped,
        "duplicates_dropped": r.duplicates_dropped,
        "twins": r.twins,
        "triangles_out": r.triangles_out,
        "target_triangles": r.target_triangles,
        "target_reached": r.target_reached,
        "stop": format!("{:?}", r.stop),
        "collapses": r.collapses,
        "vertices_removed": r.vertices_removed,
        "parts_removed": r.parts_removed,
        "locked_vertices": r.locked_vertices,
        "feature_vertices": r.feature_vertices,
        "passes": r.passes,
        "pass_triangles": r.pass_triangles.iter().collect::<Vec<_>>(),
        "rejected": rejected,
        "max_error": r.max_error,
        "mean_error": r.mean_error,
        "over_limit": r.over_limit,
        "collapse_error": r.collapse_error,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A `n` x `n` quad grid on a gentle wave (two triangles per quad), built in memory.
    fn wave_grid(n: usize) -> MeshData {
        let w = n + 1;
        let positions = (0..w * w)
            .map(|i| {
                let (x, y) = ((i % w) as f32, (i / w) as f32);
                [x, y, (x * 0.05).sin() * (y * 0.03).cos() * 4.0]
            })
            .collect();
        let mut triangles = Vec::with_capacity(2 * n * n);
        for y in 0..n {
            for x in 0..n {
                let a = (y * w + x) as u32;
                let (b, c, d) = (a + 1, a + w as u32, a + w as u32 + 1);
                triangles.push([a, b, d]);
                triangles.push([a, d, c]);
            }
        }
        MeshData {
            positions,
            triangles,
        }
    }

    /// Storage sized to the mesh: a 2 M-triangle grid (far beyond u16 links and the former
    /// fixed 262 144-vertex workspace) simplifies through the harness's path.
    #[test]
    fn two_million_triangles_simplify() {
        let mesh = wave_grid(1000);
        assert_eq!(mesh.triangles.len(), 2_000_000);
        let config = Config::new().with_ratio(0.9);
        let (out, report, _) = simplify(&mesh, &config).expect("simplify");
        assert!(report.target_reached, "{report:?}");
        assert!(report.triangles_out <= 1_800_000 && report.triangles_out > 1_700_000);
        assert_eq!(out.triangles.len(), report.triangles_out);
        assert!(out
            .triangles
            .iter()
            .all(|t| t.iter().all(|&i| (i as usize) < mesh.positions.len())));
    }

    /// A mesh too big for a storage says so in words, and names the way out for u16 links.
    #[test]
    fn capacity_errors_read_well() {
        let mesh = wave_grid(8);
        let mut tris = mesh.triangles.clone();
        let mut ws = tinydecimate::Workspace::<u16, 16, 512>::new();
        let e = ws
            .simplify(&mesh.positions, &mut tris, &Config::new())
            .unwrap_err();
        assert_eq!(
            e.to_string(),
            "mesh needs 81 vertices but the workspace holds 16"
        );
        let e = tinydecimate::Error::Capacity {
            what: tinydecimate::Capacity::Vertices,
            needed: 313_600,
            available: 65_535,
        };
        assert_eq!(
            e.to_string(),
            "mesh needs 313600 vertices but the workspace holds 65535 (u16 links number at \
             most 65535: use u32 links)"
        );
    }

    #[test]
    fn simplifies_a_grid_validly() {
        let n = 12u32;
        let mut m = MeshData::default();
        for y in 0..=n {
            for x in 0..=n {
                let (fx, fy) = (x as f32 / n as f32, y as f32 / n as f32);
                m.positions
                    .push([fx, fy, 0.1 * (fx * 3.0).sin() * (fy * 2.0).cos()]);
            }
        }
        for y in 0..n {
            for x in 0..n {
                let v = y * (n + 1) + x;
                m.triangles.push([v, v + 1, v + n + 2]);
                m.triangles.push([v, v + n + 2, v + n + 1]);
            }
        }
        let cfg = Config::new().with_ratio(0.3);
        let (out, report, _) = simplify(&m, &cfg).unwrap();
        assert_eq!(out.triangles.len(), report.triangles_out);
        assert!(report.triangles_out < m.triangles.len());
        assert_eq!(out.positions, m.positions);
        let v = crate::check::compare(&m, &out);
        assert!(v.is_valid(), "{v}");
        assert!(format_report(&report).contains("triangles out"));
    }
}
