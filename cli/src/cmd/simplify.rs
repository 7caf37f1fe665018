//! `tinydecimate simplify`: runs the library on a mesh file, prints its report, memory figures, the
//! validity check of the file written (`crate::check::verdict`, as `tinydecimate check`) and, with
//! `--measure`, the Metro error of the result, as text or (`--json`) as one JSON object.
//!
//! The output path and format are checked before anything else; the input may be standard
//! input and the output standard output (`-`). Output files keep only the vertices the result
//! uses unless `--keep-numbering` (or optimal placement, whose moved vertices only their
//! numbering ties to the input's).

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Duration;

use anyhow::{anyhow, bail, Result};
use tinydecimate::cost::Placement;
use tinydecimate::{Config, CostKind, FeatureMode, Report, Schedule, Storage, Target};

use crate::io::{Format, MeshData};
use crate::simplify::{report_json, simplify_with};
use crate::workspace::{control_bytes, element_bytes, workspace_bytes, QUADRIC_BYTES};

pub mod advice;
mod attributes;
mod shading;
mod textured;

/// Which schedule, on the command line.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum ScheduleArg {
    /// The default and the one to use: the cheapest legal collapse of the whole mesh first,
    /// so the error grows as slowly as it can.
    Greedy,
    /// Lin 2007's passes as the paper writes them (Algorithms 3-4; λ = 1, normal-variation cost):
    /// collapses in sweeps over the mesh, each vertex at most once per pass. For comparison
    /// with the paper; its error is higher than greedy's at the same triangle count.
    Passes,
    /// Greedy in batches (meshoptimizer's passes): every vertex priced once per pass, the
    /// pass collapsed in price order, skipping vertices an earlier collapse of the pass
    /// touched; `Config::new()` otherwise.
    Batched,
}

/// Which engine, on the command line.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum EngineArg {
    /// The fast mode, unless an option only the exact engine takes is given (--schedule,
    /// --cost, --quadric, --placement, --operator, --max-error, the feature
    /// and legality options) or the mesh is double-sided somewhere (the fast mode keeps one
    /// side): then the exact engine.
    #[default]
    Auto,
    /// The engine every other option configures: exact greedy order (or the passes of
    /// --schedule), every cost, operator, bound, seam and part policy.
    Exact,
    /// The fast mode (`tinydecimate::pipeline::FastWorkspace`, meshoptimizer's pipeline in
    /// fixed memory): stored quadrics priced once per pass, collapses in sorted order, every
    /// output valid. Without attributes seams are welded by position (the output keeps the
    /// welded numbering); with them (glTF, OBJ with vt/vn) the wedges are kept, a seam
    /// sliding along itself. Of the options it takes the target, --error-limit, --parts
    /// and --seams.
    Fast,
    /// The lean mode (`tinydecimate::pipeline::LeanWorkspace`): the fast mode's pipeline
    /// without stored quadrics (each built from its vertex's fan whenever a pass reads it),
    /// for about half the RAM; the same options as `fast`.
    Lean,
}

impl EngineArg {
    /// The library's pipeline mode of `fast` and `lean`; `None` for the exact engine and
    /// `auto` (resolved by [`Args::pipeline`]).
    pub fn pipeline(self) -> Option<crate::simplify::Pipeline> {
        match self {
            EngineArg::Auto | EngineArg::Exact => None,
            EngineArg::Fast => Some(crate::simplify::Pipeline::Fast),
            EngineArg::Lean => Some(crate::simplify::Pipeline::Lean),
        }
    }
}

/// Which cost, on the command line (`Config::with_cost`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum CostArg {
    /// The default and the one to use for the lowest geometric error: memoryless quadric,
    /// the squared distance to the removed vertex's current planes plus a boundary term
    /// (`Config::new()`). Nothing stored per vertex.
    Quadric,
    /// The paper's normal variation W (Lin 2007 eq. 1-2), scaled by ℓ² for the greedy
    /// schedule (`Config::paper()`): keeps flat regions flat rather than minimising distance;
    /// for comparison with the paper, higher Metro error than `quadric`.
    Normal,
    /// Hoppe's energy, E_dist + E_spring (`tinydecimate::cost::Energy`): per vertex the
    /// moments of the original surface's samples merged into it (40 bytes), subset placement,
    /// greedy only.
    Energy,
}

impl From<CostArg> for CostKind {
    fn from(c: CostArg) -> CostKind {
        match c {
            // The energy is its own cost, not a built-in one: the configuration's is unused.
            CostArg::Quadric | CostArg::Energy => CostKind::Quadric,
            CostArg::Normal => CostKind::NormalVariation,
        }
    }
}

pub use crate::simplify::OperatorArg;

/// Which quadric, on the command line.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum QuadricArg {
    /// The cost of `--cost` (memoryless quadric by default): nothing stored per vertex, the
    /// choice when RAM is tight.
    #[default]
    Memoryless,
    /// `tinydecimate::cost::StoredQuadric`: a 4x4 quadric per vertex
    /// (40 B), summed on collapse, boundary planes weighted by --boundary-weight (greedy
    /// schedule only). Lower error than memoryless when 40 B per vertex can be spared.
    Stored,
}

/// Where stored quadrics leave the kept vertex, on the command line.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum PlacementArg {
    /// At an endpoint: positions are only read, the output's vertices are input vertices.
    #[default]
    Subset,
    /// At the minimiser of the summed quadric (or the best of the endpoints and the
    /// midpoint): lower error, but vertices move, so the output file carries the moved
    /// positions (and the input's numbering: check it with `check --placement optimal`).
    Optimal,
}

impl From<PlacementArg> for Placement {
    fn from(p: PlacementArg) -> Placement {
        match p {
            PlacementArg::Subset => Placement::Subset,
            PlacementArg::Optimal => Placement::Optimal,
        }
    }
}

/// A number in a range, for clap: the error names the range and what the value means.
fn ranged(
    v: &str,
    ok: impl Fn(f32) -> bool,
    range: &str,
    meaning: &str,
) -> std::result::Result<f32, String> {
    let x: f32 = v
        .trim()
        .parse()
        .map_err(|_| format!("{v:?} is not a number; accepted: {range} ({meaning})"))?;
    if x.is_finite() && ok(x) {
        Ok(x)
    } else {
        Err(format!(
            "{v} is out of range; accepted: {range} ({meaning})"
        ))
    }
}

/// A ratio of 0 asks for the empty mesh, which no simplification makes: refused.
fn parse_ratio(v: &str) -> std::result::Result<f32, String> {
    ranged(
        v,
        |x| x > 0.0 && x <= 1.0,
        "above 0, at most 1",
        "the fraction of the input triangles to keep, 0.25 keeps a quarter",
    )
}

/// A count of 0 asks for the empty mesh: refused, as `--ratio 0` is.
fn parse_triangles(v: &str) -> std::result::Result<usize, String> {
    match v.trim().parse::<usize>() {
        Ok(n) if n > 0 => Ok(n),
        _ => Err(format!(
            "{v:?}: accepted: a whole number of triangles, 1 or more"
        )),
    }
}

/// The error bound at control points on the command line: a percentage of the bounding-box diagonal
/// (`0.5%`) or an absolute distance in the input's units (`0.02`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum MaxError {
    /// This fraction of the diagonal (`0.5%` is 0.005).
    Fraction(f32),
    /// This distance.
    Absolute(f32),
}

impl MaxError {
    /// The distance on `mesh`.
    pub fn distance(self, positions: &[[f32; 3]]) -> f32 {
        match self {
            MaxError::Fraction(f) => f * tinydecimate::bound::bounding_diagonal(positions),
            MaxError::Absolute(d) => d,
        }
    }
}

impl std::fmt::Display for MaxError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            MaxError::Fraction(x) => write!(f, "{}%", 100.0 * x),
            MaxError::Absolute(d) => write!(f, "{d}"),
        }
    }
}

/// What `--max-error` bounds.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum BoundArg {
    /// Control points (Zhu, Wang and Meng 2007): original centroids and feature vertices.
    #[default]
    Controls,
    /// Simplification envelopes (Cohen et al.): every point, both ways.
    Envelope,
}

/// `P%` or a distance.
pub fn parse_max_error(v: &str) -> std::result::Result<MaxError, String> {
    let v = v.trim();
    if let Some(p) = v.strip_suffix('%') {
        ranged(
            p,
            |x| x > 0.0 && x <= 100.0,
            "above 0 %, at most 100 %",
            "a percentage of the bounding-box diagonal, 0.5% is half a percent",
        )
        .map(|x| MaxError::Fraction(x / 100.0))
    } else {
        ranged(
            v,
            |x| x >= 0.0,
            "0 or more, or a percentage such as 0.5%",
            "a distance in the input's units",
        )
        .map(MaxError::Absolute)
    }
}

fn parse_lambda(v: &str) -> std::result::Result<f32, String> {
    ranged(v, |x| x >= 0.0, "0 or more", "the feature factor λ")
}

fn parse_turn(v: &str) -> std::result::Result<f32, String> {
    ranged(v, |x| x > 0.0 && x < 180.0, "above 0, below 180", "degrees")
}

fn parse_quality(v: &str) -> std::result::Result<f32, String> {
    ranged(
        v,
        |x| (0.0..1.0).contains(&x),
        "0 or more, below 1",
        "1 is an equilateral triangle",
    )
}

fn parse_weight(v: &str) -> std::result::Result<f32, String> {
    ranged(v, |x| x >= 0.0, "0 or more", "a weight")
}

/// `--attribute-weights`: a weight for texture coordinates and one for normals.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct AttributeWeights {
    /// Both texture coordinates' weight.
    pub uv: f32,
    /// The normal's three components' weight.
    pub normal: f32,
}

fn parse_attribute_weights(v: &str) -> std::result::Result<AttributeWeights, String> {
    let mut w = AttributeWeights::default();
    for item in v.split(',') {
        let (name, value) = item
            .split_once('=')
            .ok_or_else(|| format!("`{item}`: give name=weight (uv=W,normal=W)"))?;
        let x = parse_weight(value.trim())?;
        match name.trim() {
            "uv" => w.uv = x,
            "normal" => w.normal = x,
            n => return Err(format!("`{n}`: the attributes are uv and normal")),
        }
    }
    Ok(w)
}

fn parse_samples(v: &str) -> std::result::Result<f64, String> {
    ranged(v, |x| x > 0.0, "above 0", "samples per triangle").map(f64::from)
}

/// The default `--error-limit` as a fraction of the bounding-box diagonal (the bench uses it
/// too): on the shared clean meshes no collapse down to 10 % is over it; on the real-world ones
/// it refuses the few collapses that cut a part or a corner (docs/realworld.md).
pub const DEFAULT_ERROR_LIMIT: f32 = tinydecimate::Config::MODEL_ERROR_LIMIT;

/// `--error-limit`: a distance, a percentage of the diagonal, or none.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ErrorLimit {
    /// No limit.
    None,
    /// This distance, or fraction of the diagonal.
    At(MaxError),
}

impl ErrorLimit {
    /// The distance on a mesh with these positions (infinite: none).
    pub fn distance(self, positions: &[[f32; 3]]) -> f32 {
        match self {
            ErrorLimit::None => f32::INFINITY,
            ErrorLimit::At(e) => e.distance(positions),
        }
    }
}

impl std::fmt::Display for ErrorLimit {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ErrorLimit::None => f.write_str("none"),
            ErrorLimit::At(e) => write!(f, "{e}"),
        }
    }
}

fn parse_error_limit(v: &str) -> std::result::Result<ErrorLimit, String> {
    if v.trim() == "none" {
        return Ok(ErrorLimit::None);
    }
    parse_max_error(v).map(ErrorLimit::At)
}

/// `--format`: the output's format, instead of its extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum OutputFormat {
    /// Wavefront OBJ (text).
    Obj,
    /// PLY (binary little endian).
    Ply,
    /// STL (binary).
    Stl,
    /// Binary glTF (GLB), from a glTF input only: every attribute kept (`io::gltf::write`).
    Glb,
}

impl OutputFormat {
    /// The mesh-file format, `None` for GLB (written by the glTF path, `textured.rs`).
    pub fn mesh(self) -> Option<Format> {
        match self {
            OutputFormat::Obj => Some(Format::Obj),
            OutputFormat::Ply => Some(Format::Ply),
            OutputFormat::Stl => Some(Format::Stl),
            OutputFormat::Glb => None,
        }
    }
}

/// How vertices at identical positions are treated (`--seams`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum, serde::Serialize)]
pub enum SeamsArg {
    /// One vertex with several wedges, collapsed together.
    Weld,
    /// Separate vertices (each seam an open boundary).
    Split,
}

/// How vertices split only by their normal or tangent are treated (`--hard-edges`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum, serde::Serialize)]
pub enum HardEdgesArg {
    /// One vertex per position and texture coordinates (and other non-shading attributes).
    Weld,
    /// Each vertex as the file has it (a hard edge is a seam).
    Keep,
}

/// Whether small parts may vanish (`--parts`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum, serde::Serialize)]
pub enum PartsArg {
    /// Every part stays: a collapse never changes topology.
    Keep,
    /// A part cheaper than the next collapse vanishes whole (greedy runs without a bound).
    Prune,
}

/// `tinydecimate simplify IN OUT ...`
#[derive(Clone, Debug, clap::Args)]
#[command(group = clap::ArgGroup::new("target").required(true).multiple(true))]
pub struct Args {
    /// Input mesh (.obj, .ply, .stl, .gltf, .glb; `-` reads standard input, the format found
    /// from the bytes). Quads and n-gons are split into triangles (ear clipping). glTF keeps
    /// every vertex attribute and is written as glTF; an OBJ with texture coordinates or
    /// normals written to OBJ keeps them and its materials, a PLY written to PLY its vertex
    /// properties. Otherwise only positions and faces are read: attributes are not carried,
    /// and a warning says which were dropped.
    pub input: PathBuf,
    /// Output mesh (.obj, .ply, .stl; .gltf or .glb from a glTF input; `-` writes standard
    /// output, OBJ unless --format says otherwise, and the report then goes to stderr).
    /// Checked before simplifying. Vertices no output triangle uses are dropped (see
    /// --keep-numbering; kept with `--placement optimal`).
    pub output: PathBuf,
    /// Output format, instead of the output's extension (`glb`: from a glTF input, to a file).
    #[arg(long, value_enum)]
    pub format: Option<OutputFormat>,
    /// Keep every input vertex in the output file, so that its indices are the input's (what
    /// a firmware's index buffer into the same positions needs). STL has no numbering.
    #[arg(long)]
    pub keep_numbering: bool,
    /// Vertices at identical positions (a renderer's split on UV seams, hard normals,
    /// materials): `weld` collapses them together as one vertex with several wedges, each
    /// triangle keeping its own wedge (the default); `split` treats each as its own vertex, so
    /// every seam is an open boundary that only shrinks along itself.
    #[arg(long, value_enum, default_value_t = SeamsArg::Weld)]
    pub seams: SeamsArg,
    /// On inputs whose attributes are carried (glTF, OBJ with `vt`/`vn`): vertices that
    /// differ only in their normal or tangent (hard edges, flat shading). `weld` (the default)
    /// gives the simplifier one vertex per position and texture coordinates (and colours,
    /// joints, weights), so the seams it keeps are the texture's; each output corner then
    /// takes, among the input vertices of its position and texture coordinates, its own if the
    /// triangle is unchanged, else the one whose normal is closest to its triangle's. `keep`
    /// gives it the vertices as the file has them. Only with `--seams weld`: with `split`
    /// every split vertex is its own, hard edges too.
    #[arg(long, value_enum, default_value_t = HardEdgesArg::Weld)]
    pub hard_edges: HardEdgesArg,
    /// Simplify each glTF primitive (each OBJ material group) on its own, the target shared in
    /// proportion to their triangles. Without it the primitives of one glTF mesh (the groups
    /// of one OBJ) are simplified together in one run: with `--seams weld` a boundary between
    /// two materials is a seam, both sides move together along it and each triangle keeps its
    /// material, so no gap opens between them; the target applies to the mesh as a whole.
    #[arg(long)]
    pub per_primitive: bool,
    /// Parts (connected components): `prune` (the default) removes a part whole once it is
    /// within the error made (the fast and lean modes: its size within the largest collapse
    /// error so far) or costs less than the collapse about to be made (the exact engine),
    /// and short of the target with no collapse left the smallest parts, never the largest
    /// (the exact engine: greedy or batched schedule without --max-error only, else every
    /// part stays); `keep` keeps every part, as a collapse never changes topology.
    #[arg(long, value_enum)]
    pub parts: Option<PartsArg>,
    /// Target fraction of the input triangles, above 0, at most 1. Not with
    /// --target-triangles.
    #[arg(long, group = "target", allow_negative_numbers = true, value_parser = parse_ratio)]
    pub ratio: Option<f32>,
    /// Target triangle count, 1 or more. Not with --ratio (one target count: give one of
    /// them).
    #[arg(long, group = "target", conflicts_with = "ratio", value_parser = parse_triangles)]
    pub target_triangles: Option<usize>,
    /// Error bound at control points (Zhu, Wang and Meng 2007): what is guaranteed is that
    /// no control point, i.e. no original triangle's centroid and no vertex of an original
    /// feature edge, ends farther than this from the result. Points of the original surface
    /// between control points are not bounded: the Metro one-sided and Hausdorff distances
    /// can exceed it (the run prints them next to it). `P%` of the bounding-box diagonal (`0.5%`) or an absolute distance in the
    /// input's units. Alone, simplifies as far as the bound allows; with --ratio or
    /// --target-triangles, whichever stops first. Any schedule and cost; `--quadric stored`
    /// with subset placement only. Prints E_max and E_mean (eq. 4-5) next to the Metro
    /// one-sided maximum from the input to the result.
    #[arg(long, group = "target", allow_negative_numbers = true, value_parser = parse_max_error)]
    pub max_error: Option<MaxError>,
    /// What --max-error bounds: `controls` (the default), the control points above; or
    /// `envelope`, simplification envelopes (Cohen et al. 1996): every point of
    /// the result within the bound of the original and every original point within it of
    /// the result, for a closed manifold input (docs/envelope.md: borders are kept, and
    /// vertices where the envelope cannot be built stay). With --operator edge (subset
    /// placement) or vertex-decimation.
    #[arg(long, value_enum, default_value_t = BoundArg::Controls, requires = "max_error")]
    pub bound: BoundArg,
    /// Error limit (`Config::error_limit`): a collapse whose own error (the RMS distance from
    /// the kept vertex to the planes it replaces, plus any boundary retreat) is above it is not
    /// made, so the run stops short of the target (`stop: ErrorLimit`) rather than cut a corner
    /// to reach a count. `P%` of the bounding-box diagonal or a distance in the input's units;
    /// `none` for no limit. Default: 2% with the greedy or batched schedule, except with the
    /// triangle collapse (the runs that measure it), none otherwise. Not a guarantee (see
    /// --max-error for one).
    #[arg(long, value_parser = parse_error_limit)]
    pub error_limit: Option<ErrorLimit>,
    /// Engine: `fast` is meshoptimizer's pipeline (the target, --error-limit and --seams),
    /// `lean` the same without stored quadrics, `exact` the engine every other option
    /// configures; `auto` (the default) is `fast` unless such an option is given.
    #[arg(long, value_enum, default_value_t = EngineArg::Auto)]
    pub engine: EngineArg,
    /// The fast or lean engine in integers (`pipeline::Integer`, for cores without an FPU):
    /// the positions put on a 15-bit grid over the bounding box (`pipeline::quantise`: a cell
    /// is the power of two at or above the largest extent / 32 766, and a position moves by at
    /// most half a cell's diagonal, 0.87 cell; the run's summary prints both), every decision
    /// in fixed point on the grid; the output's vertices are the grid's positions.
    #[arg(long)]
    pub integer: bool,
    /// Collapse schedule.
    #[arg(long, value_enum, default_value_t = ScheduleArg::Greedy)]
    pub schedule: ScheduleArg,
    /// Feature factor λ: a vertex is a feature iff D > λ·mean(D) (default 2; 1 with passes).
    #[arg(long, allow_negative_numbers = true, value_parser = parse_lambda)]
    pub lambda: Option<f32>,
    /// Normalise the feature measure D by valence² (FeatureMode::ValenceNormalized).
    #[arg(long)]
    pub valence_normalized: bool,
    /// Turn feature detection off (every vertex may be collapsed). The default with
    /// `--quadric stored` (`Config::stored()`).
    #[arg(long, conflicts_with = "features")]
    pub no_features: bool,
    /// Turn feature detection on with `--quadric stored` (Lin Mouguang 2007's rule on top of the
    /// quadrics; on by default in every other mode).
    #[arg(long)]
    pub features: bool,
    /// Greedy: feature vertices may not even be the kept end of a collapse (the paper's rule).
    #[arg(long)]
    pub no_feature_targets: bool,
    /// Largest normal turn of a triangle in one collapse, degrees.
    #[arg(long, allow_negative_numbers = true, value_parser = parse_turn)]
    pub max_turn: Option<f32>,
    /// Smallest triangle quality a collapse may create (unless already worse).
    #[arg(long, allow_negative_numbers = true, value_parser = parse_quality)]
    pub min_quality: Option<f32>,
    /// Weight of the boundary retreat in the cost.
    #[arg(long, allow_negative_numbers = true, value_parser = parse_weight)]
    pub boundary_weight: Option<f32>,
    /// Collapse cost (default: the schedule's own, quadric for greedy as in `Config::new()`,
    /// normal for passes as in `Config::paper()`).
    #[arg(long, value_enum)]
    pub cost: Option<CostArg>,
    /// Simplification operator: half-edge collapse, or the triangle collapse of
    /// Zhu, Wang and Meng 2007 (greedy schedule only).
    #[arg(long, value_enum, default_value_t = OperatorArg::Edge)]
    pub operator: OperatorArg,
    /// κ, the spring constant of `--cost energy` (0: distance alone).
    #[arg(long, default_value_t = tinydecimate::cost::Energy::KAPPA)]
    pub spring: f32,
    /// Quadric: `stored` keeps a quadric per vertex, replacing --cost.
    #[arg(long, value_enum, default_value_t = QuadricArg::Memoryless)]
    pub quadric: QuadricArg,
    /// Placement of the kept vertex with `--quadric stored`.
    #[arg(long, value_enum, default_value_t = PlacementArg::Subset)]
    pub placement: PlacementArg,
    /// Attribute weights for the stored quadric (`tinydecimate::cost::AttributeQuadric`,
    /// meshoptimizer's `simplifyWithAttributes` term): `uv=W,normal=W` (either or both). A
    /// weighted attribute change of 1 across a triangle of size d is priced like moving it by
    /// d. Needs `--quadric stored` with `--placement subset` and a mesh with attributes (glTF,
    /// OBJ with vt/vn); with welded seams each position's first vertex's attributes are used.
    #[arg(long, value_parser = parse_attribute_weights)]
    pub attribute_weights: Option<AttributeWeights>,
    /// Measure the Metro error of the result (input vs output, both directions) and, on
    /// textured parts, the UV stretch and texture deviation beside meshoptimizer's. Off by
    /// default: it takes several times the simplification. The validity check always runs.
    #[arg(long)]
    pub measure: bool,
    /// Accepted for old scripts: the Metro error is off unless --measure.
    #[arg(long, hide = true)]
    pub no_measure: bool,
    /// Metro face samples per triangle of the larger mesh.
    #[arg(long, default_value_t = 10.0, allow_negative_numbers = true, value_parser = parse_samples)]
    pub samples_per_triangle: f64,
    /// Print the report, the check and the Metro error as one JSON object on stdout.
    #[arg(long)]
    pub json: bool,
    /// Also write meshoptimizer's `meshopt_simplify` result at the triangle count this run
    /// reached (OBJ, PLY or STL by extension), to compare the two (`render --compare`).
    /// Meshes without vertex attributes only.
    #[arg(long, value_name = "FILE")]
    pub meshopt_out: Option<PathBuf>,
    /// Allow the output to be the input file (it is overwritten).
    #[arg(long)]
    pub force: bool,
}

impl Args {
    /// These arguments with `--engine auto` resolved for `mesh`: `fast`, unless an option
    /// only the exact engine takes is given ([`exact_only`](Self::exact_only)) or the mesh is
    /// double-sided somewhere (the exact engine keeps both sides, the pipeline one): `exact`.
    pub fn resolve(&self, mesh: &MeshData) -> Args {
        let mut args = self.clone();
        if args.engine == EngineArg::Auto {
            args.engine = if args.exact_only().is_none()
                && !crate::simplify::double_sided(&mesh.positions, &mesh.triangles)
            {
                EngineArg::Fast
            } else {
                EngineArg::Exact
            };
        }
        args
    }

    /// The pipeline mode this run uses (`None`: the exact engine): `--engine`, with `auto`
    /// resolved to the fast mode unless [`exact_only`](Self::exact_only) names an option
    /// (runs resolve `auto` for their mesh first, [`resolve`](Self::resolve)).
    pub fn pipeline(&self) -> Option<crate::simplify::Pipeline> {
        match self.engine {
            EngineArg::Auto if self.exact_only().is_none() => Some(crate::simplify::Pipeline::Fast),
            e => e.pipeline(),
        }
    }

    /// The first option given that only the exact engine takes (`None`: the pipeline takes
    /// them all).
    pub fn exact_only(&self) -> Option<&'static str> {
        let given = [
            (self.schedule != ScheduleArg::Greedy, "--schedule"),
            (self.cost.is_some(), "--cost"),
            (self.quadric != QuadricArg::Memoryless, "--quadric"),
            (self.placement != PlacementArg::Subset, "--placement"),
            (self.operator != OperatorArg::Edge, "--operator"),
            (self.max_error.is_some(), "--max-error"),
            (self.lambda.is_some(), "--lambda"),
            (self.valence_normalized, "--valence-normalized"),
            (self.no_features, "--no-features"),
            (self.features, "--features"),
            (self.no_feature_targets, "--no-feature-targets"),
            (self.max_turn.is_some(), "--max-turn"),
            (self.min_quality.is_some(), "--min-quality"),
            (self.boundary_weight.is_some(), "--boundary-weight"),
            (self.attribute_weights.is_some(), "--attribute-weights"),
            (self.spring != tinydecimate::cost::Energy::KAPPA, "--spring"),
        ];
        given.iter().find(|(on, _)| *on).map(|&(_, name)| name)
    }

    /// Whether parts may vanish: `--parts`, pruning unless `keep`.
    pub fn prunes(&self) -> bool {
        self.parts != Some(PartsArg::Keep)
    }

    /// `--parts` as this run takes it.
    pub fn parts(&self) -> PartsArg {
        if self.prunes() {
            PartsArg::Prune
        } else {
            PartsArg::Keep
        }
    }

    /// `--format` as a mesh-file format (`None`: not given, or GLB).
    pub fn mesh_format(&self) -> Option<Format> {
        self.format.and_then(OutputFormat::mesh)
    }

    /// The error limit asked for, or the default where the run measures one.
    pub fn error_limit(&self) -> ErrorLimit {
        match self.error_limit {
            Some(e) => e,
            None if self.schedule != ScheduleArg::Passes
                && self.operator != OperatorArg::Triangle =>
            {
                ErrorLimit::At(MaxError::Fraction(DEFAULT_ERROR_LIMIT))
            }
            None => ErrorLimit::None,
        }
    }

    /// `config` with the distances these arguments give relative to the mesh (the error bound
    /// and the error limit, as a fraction of `positions`' diagonal or in its units), validated.
    pub fn with_distances(&self, config: Config, positions: &[[f32; 3]]) -> Result<Config> {
        let mut config = config;
        if let Some(e) = self.max_error {
            config = config.with_max_error(e.distance(positions));
        }
        config = config.with_error_limit(self.error_limit().distance(positions));
        config
            .validate()
            .map_err(|e| anyhow!("configuration: {e}"))?;
        Ok(config)
    }

    /// The library configuration these arguments ask for.
    pub fn config(&self) -> Config {
        // `passes` means the paper as written (λ = 1, features take no part in any collapse).
        let base = match self.schedule {
            ScheduleArg::Greedy => Config::new().with_schedule(Schedule::Greedy),
            ScheduleArg::Passes => Config::paper(),
            ScheduleArg::Batched => Config::new().with_schedule(Schedule::Batched),
        };
        let base = match self.cost {
            Some(cost) => base.with_cost(cost.into()),
            None => base,
        };
        let mut c = base.with_feature_mode(if self.valence_normalized {
            FeatureMode::ValenceNormalized
        } else {
            FeatureMode::Paper
        });
        // A triangle count, else the ratio.
        c = c.with_target(match self.target_triangles {
            Some(t) => Target::Triangles(t),
            None => Target::Ratio(self.ratio.unwrap_or(0.0)),
        });
        if let Some(l) = self.lambda {
            c = c.with_lambda(l);
        }
        // Stored quadrics default to `Config::stored()`: no feature rule.
        c = c.with_features(if self.quadric == QuadricArg::Stored {
            self.features
        } else {
            !self.no_features
        });
        if self.no_feature_targets {
            c = c.with_feature_targets(false);
        }
        if let Some(x) = self.max_turn {
            c = c.with_max_normal_turn(x);
        }
        if let Some(x) = self.min_quality {
            c = c.with_min_quality(x);
        }
        if let Some(x) = self.boundary_weight {
            c = c.with_boundary_weight(x);
        }
        c
    }
}

/// `tinydecimate simplify`. Exit code 1 if the measured result is not a valid simplification.
pub fn run(args: &Args) -> Result<ExitCode> {
    // 1. Everything that can be refused is refused before the long work.
    let to_stdout = crate::io::is_std(&args.output);
    if to_stdout && args.json {
        bail!("--json and an output of `-` would both write standard output: give an output file");
    }
    refuse_exact_only(args)?;
    // glTF, and OBJ with texture coordinates or normals: attributes carried (textured.rs).
    if let Some(code) = textured::run_if_attributes(args)? {
        return Ok(code);
    }
    let out_format = crate::io::check_writable(&args.output, args.mesh_format())?;
    if !args.force && crate::io::same_file(&args.input, &args.output) {
        bail!(
            "{}: the output is the input file and would overwrite it: give another output, or \
             --force",
            args.output.display()
        );
    }
    #[cfg(not(feature = "meshopt"))]
    if args.meshopt_out.is_some() {
        bail!(
            "--meshopt-out needs meshoptimizer, which this build leaves out: install with \
             `cargo install --path cli --features meshopt`"
        );
    }
    #[cfg(feature = "meshopt")]
    let meshopt_format = match &args.meshopt_out {
        Some(path) => Some(crate::io::check_writable(path, None)?),
        None => None,
    };
    // 2. The run, and the file it writes (with `--engine auto` resolved for the mesh).
    let run = simplify_file(args, out_format)?;
    let args = &run.args;
    #[cfg(feature = "meshopt")]
    if let (Some(path), Some(format)) = (&args.meshopt_out, meshopt_format) {
        let (theirs, _, _) = crate::meshopt::meshopt_simplify(&run.mesh, run.report.triangles_out);
        let theirs = crate::io::compact(&theirs).0;
        crate::io::save_as(path, format, &theirs)?;
        eprintln!(
            "meshoptimizer at {} triangles: {} triangles written to {}",
            run.report.triangles_out,
            theirs.triangles.len(),
            path.display()
        );
    }
    // 3. What was done and the memory it takes, then the check and the error.
    let say = |text: &str| {
        if to_stdout {
            eprint!("{text}");
        } else if !args.json {
            crate::out!("{text}");
        }
    };
    say(&run_text(args, &run));
    let mut json = run_json(args, &run);
    let valid = measure(args, &run, &say, &mut json)?;
    json["valid"] = serde_json::Value::Bool(valid);
    if args.json {
        crate::outln!("{}", serde_json::to_string_pretty(&json)?);
    }
    Ok(if valid {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}

/// One `simplify` run: the input, the result, what was written and how.
struct Run {
    /// The arguments, `--engine auto` resolved for the mesh.
    args: Args,
    mesh: MeshData,
    config: Config,
    out: MeshData,
    written: MeshData,
    out_format: Format,
    report: Report,
    elapsed: Duration,
    stored: bool,
    moved: bool,
    keep_numbering: bool,
}

/// Loads the input, runs the library as `args` ask and writes the output file.
fn simplify_file(args: &Args, out_format: Format) -> Result<Run> {
    let mut mesh = crate::io::load_noting(&args.input)?;
    if args.integer {
        // The run's input is the mesh on the grid: the check and the error compare with it,
        // and the output's vertices are grid positions.
        let mut grid = vec![[0u16; 3]; mesh.positions.len()];
        let frame = tinydecimate::pipeline::quantise(&mesh.positions, &mut grid)
            .map_err(|e| anyhow!("{}: {e}", args.input.display()))?;
        mesh.positions = grid.iter().map(|&q| frame.position(q)).collect();
    }
    let args = &args.resolve(&mesh);
    let config = args.with_distances(args.config(), &mesh.positions)?;
    if args.attribute_weights.is_some() {
        bail!(
            "{}: --attribute-weights needs vertex attributes: a glTF, or an OBJ with vt or vn \
             written to OBJ",
            args.input.display()
        );
    }
    let pipeline = args.pipeline();
    let stored = args.quadric == QuadricArg::Stored;
    // Optimal placement moves vertices: only their numbering says which input vertex each
    // one was (`check --placement optimal` matches by index), so it is kept, and STL has none.
    let moved = stored && args.placement == PlacementArg::Optimal;
    if moved && out_format == Format::Stl {
        bail!(
            "--placement optimal moves vertices, and STL has no vertex numbering to tell which \
             input vertex each one was: write OBJ or PLY"
        );
    }
    let keep_numbering = args.keep_numbering || moved;
    let bounded = args.max_error.is_some();
    // The library refuses what it cannot run (stored quadrics with the passes schedule,
    // optimal placement with a bound) before any work, naming the option.
    let placement = stored.then(|| args.placement.into());
    let run = crate::simplify::Run {
        operator: args.operator,
        placement,
        bounded,
        envelope: args.bound == BoundArg::Envelope,
        progress: true,
        weld: args.seams == SeamsArg::Weld,
        // No attribute is carried here, so a seam corner has nothing to tear.
        lock_seam_corners: false,
        prune: args.prunes(),
        energy: (args.cost == Some(CostArg::Energy)).then_some(args.spring),
        pipeline,
        integer: args.integer,
    };
    let (out, report, elapsed) = simplify_with(&mesh, &config, &run)?;
    let written = if keep_numbering {
        out.clone()
    } else {
        crate::io::compact(&out).0
    };
    crate::io::save_as(&args.output, out_format, &written)?;
    Ok(Run {
        args: args.clone(),
        mesh,
        config,
        out,
        written,
        out_format,
        report,
        elapsed,
        stored,
        moved,
        keep_numbering,
    })
}

/// `--engine fast` or `lean` with an option only the exact engine takes: refused, naming it.
pub(crate) fn refuse_exact_only(args: &Args) -> Result<()> {
    if let (Some(mode), Some(option)) = (args.engine.pipeline(), args.exact_only()) {
        bail!(
            "--engine {} does not take {option} (the exact engine's): drop it, or give \
             --engine exact",
            mode.name()
        );
    }
    if args.integer && args.engine == EngineArg::Exact {
        bail!("--integer runs the fast or the lean engine: drop --engine exact");
    }
    if let (true, Some(option)) = (args.integer, args.exact_only()) {
        bail!("--integer runs the fast or the lean engine, which do not take {option}");
    }
    Ok(())
}

/// ", in integers" and the grid the input was put on (its cell and the most a position
/// moved), with `--integer`.
fn integer_words(args: &Args, positions: &[[f32; 3]]) -> String {
    if !args.integer {
        return String::new();
    }
    let mut grid = vec![[0u16; 3]; positions.len()];
    match tinydecimate::pipeline::quantise(positions, &mut grid) {
        Ok(frame) => format!(
            ", in integers on a 15-bit grid (cell {:e}; a position moved by at most {:e})",
            frame.step,
            frame.error()
        ),
        Err(_) => ", in integers on a 15-bit grid".to_string(),
    }
}

/// The run in words: files, modes, the library's report and the memory figures.
fn run_text(args: &Args, run: &Run) -> String {
    use std::fmt::Write as _;
    let Run {
        mesh,
        config,
        written,
        out_format,
        report,
        elapsed,
        stored,
        moved,
        ..
    } = run;
    let mut text = String::new();
    let _ = writeln!(
        text,
        "simplify {} -> {} ({:?}, {} vertices{})",
        args.input.display(),
        args.output.display(),
        out_format,
        written.positions.len(),
        if args.keep_numbering {
            ", input numbering kept"
        } else if *moved {
            ", input numbering kept: vertices moved"
        } else {
            ", unreferenced dropped"
        }
    );
    let pipeline = args.pipeline();
    if pipeline == Some(crate::simplify::Pipeline::Fast) {
        let _ = writeln!(
            text,
            "  engine                 fast (meshoptimizer's pipeline: stored quadrics, sorted \
             passes, subset placement){}",
            integer_words(args, &mesh.positions)
        );
    } else if pipeline == Some(crate::simplify::Pipeline::Lean) {
        let _ = writeln!(
            text,
            "  engine                 lean (meshoptimizer's pipeline: quadrics from each \
             vertex's fan, sorted passes, subset placement){}",
            integer_words(args, &mesh.positions)
        );
    } else if *stored {
        let _ =
            writeln!(
            text,
            "  schedule, cost         {:?}, stored quadric ({:?} placement, boundary weight {})",
            config.schedule(), args.placement, config.boundary_weight()
        );
    } else if args.cost == Some(CostArg::Energy) {
        let _ = writeln!(
            text,
            "  schedule, cost, op     {:?}, Hoppe's energy (κ {}), {:?} collapse",
            config.schedule(),
            args.spring,
            args.operator
        );
    } else {
        let _ = writeln!(
            text,
            "  schedule, cost, op     {:?}, {:?}, {:?} collapse",
            config.schedule(),
            config.cost(),
            args.operator
        );
    }
    if let Some(e) = args.max_error {
        let _ = writeln!(
            text,
            "  error bound            d_hold {e} = {:.6e} (guaranteed at the control points; \
             feature edges past {}°)",
            config.max_error(),
            config.control_angle_deg()
        );
    }
    // An error bound alone: the report's target is the bound, not a count of 0.
    let bound_alone = args.ratio.is_none() && args.target_triangles.is_none();
    let target = args
        .max_error
        .filter(|_| bound_alone)
        .map(|e| advice::bound_target(&e.to_string(), config.max_error(), report));
    let _ = writeln!(
        text,
        "{}",
        crate::simplify::format_report_for(report, target.as_deref())
    );
    if let Some((outcome, advice)) = advice_for(args, report) {
        text += &advice.text(&outcome, "  ");
    }
    let _ = writeln!(
        text,
        "  library call           {:.3} ms",
        elapsed.as_secs_f64() * 1e3
    );
    let (v, t) = (mesh.positions.len(), mesh.triangles.len());
    let per_tri = |b: usize| b as f64 / t.max(1) as f64;
    if let Some(mode) = pipeline {
        let need = crate::simplify::pipeline_bytes(mode, v, t);
        let _ = writeln!(
            text,
            "  workspace (right-size) {need} bytes: {} for V = {v}, T = {t} with {} links \
             ({:.2} bytes per input triangle)",
            mode.workspace(),
            if v < 65_535 && t < 65_535 {
                "u16"
            } else {
                "u32"
            },
            per_tri(need)
        );
        return text;
    }
    let host = Storage::<u32>::bytes(v, t);
    let _ = writeln!(
        text,
        "  workspace (this run)   {host} bytes: Storage<u32> sized to the mesh ({:.1} bytes per \
         input triangle)",
        per_tri(host)
    );
    let (need, link) = workspace_bytes(v, t);
    let _ = writeln!(
        text,
        "  workspace (right-size) {need} bytes for V = {v}, T = {t} with {link}-byte links \
         ({} bytes per vertex, {} per triangle; {:.2} bytes per input triangle)",
        if link == 2 {
            element_bytes::<u16>().0
        } else {
            element_bytes::<u32>().0
        },
        if link == 2 {
            element_bytes::<u16>().1
        } else {
            element_bytes::<u32>().1
        },
        per_tri(need)
    );
    if args.max_error.is_some() {
        let (b16, b32) = control_bytes(v, t);
        let _ = writeln!(
            text,
            "  control links          2T + V = {} links: {b16} bytes with u16 links ({:.2} per \
             input triangle), {b32} with u32 ({:.2})",
            tinydecimate::bound::control_len(t, v),
            per_tri(b16),
            per_tri(b32)
        );
    }
    if *stored {
        let _ = writeln!(
            text,
            "  stored quadrics        {} bytes ({QUADRIC_BYTES} per vertex); with the workspace \
             {:.2} bytes per input triangle",
            v * QUADRIC_BYTES,
            per_tri(need + v * QUADRIC_BYTES)
        );
    }
    text
}

/// What to do when the run stopped short of the triangle count it was asked for (with
/// `--max-error` alone the bound is the goal, and stopping there is no shortfall).
fn advice_for(args: &Args, report: &Report) -> Option<(advice::Outcome, advice::Advice)> {
    if args.ratio.is_none() && args.target_triangles.is_none() {
        return None;
    }
    let outcome = advice::Outcome::from(report).in_use(&args.config());
    let input = args.input.display().to_string();
    let output = args.output.display().to_string();
    advice::advise(&outcome, &input, &output).map(|a| (outcome, a))
}

/// The JSON object of `--json`, before the check and the error are added.
fn run_json(args: &Args, run: &Run) -> serde_json::Value {
    let (v, t) = (run.mesh.positions.len(), run.mesh.triangles.len());
    let config = &run.config;
    serde_json::json!({
        "input": args.input.display().to_string(),
        "output": args.output.display().to_string(),
        "output_format": format!("{:?}", run.out_format),
        "output_vertices": run.written.positions.len(),
        "keep_numbering": run.keep_numbering,
        "engine": match args.pipeline() {
            Some(crate::simplify::Pipeline::Fast) => "Fast",
            Some(crate::simplify::Pipeline::Lean) => "Lean",
            None => "Exact",
        },
        "schedule": format!("{:?}", config.schedule()),
        "cost": format!("{:?}", config.cost()),
        "operator": format!("{:?}", args.operator),
        "quadric": format!("{:?}", args.quadric),
        "placement": format!("{:?}", args.placement),
        "max_error": args.max_error.map(|e| e.to_string()),
        "d_hold": if config.max_error().is_finite() { Some(config.max_error()) } else { None },
        "report": report_json(&run.report),
        "advice": advice_for(args, &run.report).map(|(_, a)| a),
        "library_ms": run.elapsed.as_secs_f64() * 1e3,
        "workspace_bytes": match args.pipeline() {
            Some(mode) => crate::simplify::pipeline_bytes(mode, v, t),
            None => workspace_bytes(v, t).0,
        },
    })
}

/// The check of the file as written and read back and, with `--measure`, the Metro error
/// (and the bound's figures): said with `say`, added to `json`. Whether the result is valid.
fn measure(
    args: &Args,
    run: &Run,
    say: &dyn Fn(&str),
    json: &mut serde_json::Value,
) -> Result<bool> {
    use std::fmt::Write as _;
    let Run {
        mesh,
        config,
        out,
        written,
        out_format,
        report,
        moved,
        ..
    } = run;
    let out_format = *out_format;
    let mut text = String::new();
    // The library drops degenerate and duplicate triangles before it starts; the check
    // compares the output with the input as the library saw it (`meshcheck::clean`).
    // One checker, one verdict: what `tinydecimate check` says of the file with the same
    // --seams and --parts, as written and read back (an STL welded by position, a compact
    // file matched back by position).
    let ext = format!("{out_format:?}");
    let as_read = crate::io::encode(out_format, written)
        .map_err(|e| anyhow!("{e}"))
        .and_then(|b| crate::io::parse_bytes(&b, &ext))
        .map_err(|e| anyhow!("reading back what was written: {e:#}"))?;
    let promise = crate::check::Promise {
        moved: *moved,
        welded: args.seams == SeamsArg::Weld,
        parts: args.prunes(),
    };
    let (_, note, validity) = crate::check::verdict(mesh, &as_read, promise)?;
    let valid = validity.is_valid();
    let _ = writeln!(
        text,
        "check (output vs the cleaned input: the input less its {} degenerate and {} \
         duplicate triangles, as the library dropped them; {}):",
        report.degenerate_dropped,
        report.duplicates_dropped,
        promise_words(promise)
    );
    if let Some(n) = &note {
        let _ = writeln!(text, "note: {n}");
    }
    let _ = writeln!(text, "{validity}");
    let m = args.measure.then(|| {
        let opts = crate::metro::MetroOptions {
            samples_per_triangle: args.samples_per_triangle,
            progress: true,
            ..Default::default()
        };
        crate::metro::metro(mesh, out, &opts)
    });
    match &m {
        Some(m) => {
            let _ = writeln!(text, "metro (input vs output):");
            let _ = writeln!(text, "{m}");
        }
        None => {
            let _ = writeln!(text, "{NOT_MEASURED}");
        }
    }
    if let (Some(emax), Some(emean)) = (report.max_error, report.mean_error) {
        // Metro's unit too (`MetroReport::diagonal`).
        let pct = |x: f64| 100.0 * x / mesh.bbox_diagonal().max(f64::MIN_POSITIVE);
        let _ = writeln!(
            text,
            "error bound (input units; % of the diagonal):\n\
             \x20 d_hold                   {:.6e} = {:.5} %\n\
             \x20 E_max  (eq. 4)           {:.6e} = {:.5} %\n\
             \x20 E_mean (eq. 5)           {:.6e} = {:.5} %",
            config.max_error(),
            pct(f64::from(config.max_error())),
            emax,
            pct(f64::from(emax)),
            emean,
            pct(f64::from(emean)),
        );
        if let Some(m) = &m {
            let _ = writeln!(
                text,
                "  Metro max orig -> simpl  {:.6e} = {:.5} %  (sampled, not bounded)",
                m.a_to_b.max, m.a_to_b.max_pct,
            );
        }
    }
    say(&text);
    json["check"] = serde_json::json!({
        "against": "cleaned input",
        "seams": args.seams,
        "parts": args.parts(),
        "validity": validity,
        "defects": validity.defects.iter().map(|d| d.to_string()).collect::<Vec<_>>(),
        "valid": valid,
    });
    json["metro"] = match &m {
        Some(m) => serde_json::to_value(m)?,
        None => serde_json::Value::Null,
    };
    Ok(valid)
}

/// The report's line when the Metro error was not measured.
pub(crate) const NOT_MEASURED: &str =
    "error: not measured (--measure adds the Metro error, input vs output)";

/// The check's promises in words (as `check` says them, `crate::cmd::check::against`).
fn promise_words(p: crate::check::Promise) -> String {
    let mut s = String::from(if p.welded {
        "seams welded by position"
    } else {
        "seams split"
    });
    s += if p.parts {
        ", parts gone whole allowed"
    } else {
        ", every part kept"
    };
    if p.moved {
        s += ", kept vertices may have moved";
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[derive(Parser)]
    struct Cli {
        #[command(flatten)]
        args: Args,
    }

    #[test]
    fn the_error_limit_defaults_to_its_constant() {
        let c = Cli::try_parse_from(["x", "a.obj", "b.obj", "--ratio", "0.25"]).unwrap();
        assert_eq!(
            c.args.error_limit(),
            ErrorLimit::At(MaxError::Fraction(DEFAULT_ERROR_LIMIT))
        );
        let c =
            Cli::try_parse_from(["x", "a", "b", "--ratio", "0.1", "--schedule", "passes"]).unwrap();
        assert_eq!(c.args.error_limit(), ErrorLimit::None);
        let c = Cli::try_parse_from(["x", "a", "b", "--ratio", "0.1", "--error-limit", "none"])
            .unwrap();
        assert_eq!(c.args.error_limit(), ErrorLimit::None);
        assert_eq!(c.args.error_limit().distance(&[[0.0; 3]]), f32::INFINITY);
        let c =
            Cli::try_parse_from(["x", "a", "b", "--ratio", "0.1", "--error-limit", "0.5"]).unwrap();
        assert_eq!(
            c.args.error_limit(),
            ErrorLimit::At(MaxError::Absolute(0.5))
        );
        assert!(
            Cli::try_parse_from(["x", "a", "b", "--ratio", "0.1", "--error-limit", "-1"]).is_err()
        );
    }

    #[test]
    fn arguments_make_the_config() {
        let c = Cli::try_parse_from(["x", "a.obj", "b.obj", "--ratio", "0.25"]).unwrap();
        let cfg = c.args.config();
        assert_eq!(cfg.target(), Target::Ratio(0.25));
        assert_eq!(cfg.schedule(), Schedule::Greedy);
        assert_eq!(cfg.feature_mode(), FeatureMode::Paper);
        assert_eq!(cfg.cost(), CostKind::Quadric);
        assert_eq!(cfg, Config::new().with_ratio(0.25));
        let c = Cli::try_parse_from(["x", "a.obj", "b.obj", "--ratio", "0.1", "--cost", "normal"])
            .unwrap();
        assert_eq!(
            c.args.config(),
            Config::new().with_cost(CostKind::NormalVariation)
        );
        let c =
            Cli::try_parse_from(["x", "a", "b", "--ratio", "0.1", "--schedule", "passes"]).unwrap();
        assert_eq!(c.args.config(), Config::paper().with_ratio(0.1));
        let c = Cli::try_parse_from([
            "x",
            "a",
            "b",
            "--ratio",
            "0.1",
            "--schedule",
            "passes",
            "--cost",
            "quadric",
        ])
        .unwrap();
        assert_eq!(c.args.config().cost(), CostKind::Quadric);
        assert!(Cli::try_parse_from(["x", "a", "b", "--ratio", "0.1", "--cost", "plane"]).is_err());
        let c = Cli::try_parse_from([
            "x",
            "a.obj",
            "b.obj",
            "--target-triangles",
            "500",
            "--schedule",
            "passes",
            "--lambda",
            "1.5",
            "--valence-normalized",
        ])
        .unwrap();
        let cfg = c.args.config();
        assert_eq!(cfg.target(), Target::Triangles(500));
        assert_eq!(cfg.schedule(), Schedule::Passes);
        assert_eq!(cfg.lambda(), 1.5);
        assert_eq!(cfg.feature_mode(), FeatureMode::ValenceNormalized);
        assert!(Cli::try_parse_from(["x", "a.obj", "b.obj"]).is_err());
        // Stored quadrics: `Config::stored()` (no feature rule) unless --features.
        let stored = |extra: &[&str]| {
            let mut a = vec!["x", "a", "b", "--ratio", "0.1", "--quadric", "stored"];
            a.extend_from_slice(extra);
            Cli::try_parse_from(a).map(|c| c.args.config())
        };
        assert_eq!(stored(&[]).unwrap(), Config::stored().with_ratio(0.1));
        assert_eq!(
            stored(&["--features"]).unwrap(),
            Config::new().with_ratio(0.1)
        );
        assert!(stored(&["--features", "--no-features"]).is_err());
    }
}
