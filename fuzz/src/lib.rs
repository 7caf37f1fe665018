//! Shared code of the fuzz targets: the `simplify` case generator and its run, checked after
//! every run with the shared validity checker (`meshcheck`, meshcheck/: written
//! independently of the library, std collections and f64 geometry).

use std::collections::HashMap;

use arbitrary::{Result, Unstructured};
use tinydecimate::cost::{NormalVariation, Quadric};
use tinydecimate::pipeline::{quantise, Arithmetic, FastWorkspace, Float, Integer, LeanWorkspace};
use tinydecimate::{
    Config, EdgeCollapse, Error, FeatureMode, Index, Report, Schedule, Stop, Target, Workspace,
};
use tinydecimate::{NoBound, Positions};

/// The caller's index type: `u16` or `u32`, converted from the generator's `u32` by truncation
/// (so out-of-range and NIL-valued indices reach the library as they are).
pub trait Idx: Index {
    fn from_u32(v: u32) -> Self;
    fn to_u32(self) -> u32;
}

impl Idx for u16 {
    fn from_u32(v: u32) -> Self {
        v as u16
    }
    fn to_u32(self) -> u32 {
        u32::from(self)
    }
}

impl Idx for u32 {
    fn from_u32(v: u32) -> Self {
        v
    }
    fn to_u32(self) -> u32 {
        self
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum CostKind {
    /// `simplify` / `start` with `Builtin`: the cost `config.cost` names.
    Default,
    /// `start` with `Quadric` (`config.cost` set to match).
    Plane,
    /// `start` with `NormalVariation` (`config.cost` set to match).
    Normal,
}

/// One generated run.
#[derive(Clone, Debug)]
pub struct Case {
    /// 0: `<u16, 64, 64>`, 1: `<u16, 512, 512>`, 2: `<u32, 512, 1024>`.
    pub workspace: u8,
    /// Caller's triangles as `u32` (else `u16`).
    pub wide: bool,
    pub positions: Vec<[f32; 3]>,
    pub triangles: Vec<[u32; 3]>,
    pub config: Config,
    pub cost: CostKind,
    /// Step budgets, used in turn.
    pub budgets: Vec<u32>,
    /// Also finish a third run early, after this many `step` calls.
    pub early: Option<u16>,
}

const SPECIAL: [f32; 16] = [
    f32::NAN,
    f32::INFINITY,
    f32::NEG_INFINITY,
    f32::MAX,
    f32::MIN,
    f32::MIN_POSITIVE,
    1e-45, // smallest subnormal
    -1e-45,
    1e-40, // subnormal
    0.0,
    -0.0,
    1e30,
    -1e30,
    1e-30,
    1.0,
    -1.0,
];

/// A float in `[lo, hi]` most of the time, else a special value or raw bits.
fn float(u: &mut Unstructured, lo: f32, hi: f32) -> Result<f32> {
    let tag: u8 = u.arbitrary()?;
    Ok(match tag {
        0..=199 => {
            let x: u16 = u.arbitrary()?;
            lo + (hi - lo) * (x as f32 / 65535.0)
        }
        200..=239 => SPECIAL[u.choose_index(SPECIAL.len())?],
        _ => f32::from_bits(u.arbitrary()?),
    })
}

/// A coordinate: small grid values mostly (so that meshes are meaningful), else anything.
fn coord(u: &mut Unstructured) -> Result<f32> {
    let tag: u8 = u.arbitrary()?;
    Ok(match tag {
        0..=191 => (u.arbitrary::<i8>()? as f32) / 16.0,
        192..=231 => SPECIAL[u.choose_index(SPECIAL.len())?],
        _ => f32::from_bits(u.arbitrary()?),
    })
}

/// A vertex index below `n` mostly, else anything.
fn index(u: &mut Unstructured, n: usize) -> Result<u32> {
    let tag: u8 = u.arbitrary()?;
    Ok(if tag < 240 && n > 0 {
        u.int_in_range(0..=(n - 1) as u32)?
    } else {
        match tag % 4 {
            0 => n as u32,
            1 => u16::MAX as u32,
            2 => u32::MAX,
            _ => u.arbitrary()?,
        }
    })
}

fn config(u: &mut Unstructured) -> Result<Config> {
    let mut c = Config::new();
    c = c.with_schedule(if u.arbitrary()? {
        Schedule::Passes
    } else {
        Schedule::Greedy
    });
    c = c.with_target(match u.int_in_range(0..=3u8)? {
        0 => Target::Ratio(float(u, 0.0, 1.0)?),
        1 | 2 => Target::Triangles(u.int_in_range(0..=1200)?),
        _ => Target::Triangles(u.arbitrary::<u64>()? as usize),
    });
    c = c.with_max_cost(match u.int_in_range(0..=3u8)? {
        0 | 1 => f32::INFINITY,
        2 => float(u, 0.0, 0.05)?,
        _ => float(u, 0.0, 10.0)?,
    });
    c = c.with_max_passes(match u.int_in_range(0..=7u8)? {
        0 => u.arbitrary()?,
        _ => u.int_in_range(1..=40)?,
    });
    c = c.with_lambda(float(u, 0.0, 4.0)?);
    c = c.with_features(u.arbitrary()?);
    c = c.with_feature_mode(if u.arbitrary()? {
        FeatureMode::ValenceNormalized
    } else {
        FeatureMode::Paper
    });
    c = c.with_feature_targets(u.arbitrary()?);
    c = c.with_max_normal_turn(float(u, 0.0, 180.0)?);
    c = c.with_min_quality(float(u, 0.0, 1.0)?);
    c = c.with_boundary_weight(float(u, 0.0, 10.0)?);
    // Read by the pipeline only; the exact engine prunes when given part links.
    c = c.with_prune_parts(u.arbitrary()?);
    Ok(c)
}

/// Height/displacement in a sane range, from one byte.
fn bump(u: &mut Unstructured, amp: f32) -> Result<f32> {
    Ok((u.arbitrary::<i8>()? as f32) / 128.0 * amp)
}

fn quad(tris: &mut Vec<[u32; 3]>, a: u32, b: u32, c: u32, d: u32, diag: bool) {
    if diag {
        tris.push([a, b, c]);
        tris.push([a, c, d]);
    } else {
        tris.push([a, b, d]);
        tris.push([b, c, d]);
    }
}

/// Positions and triangles: raw, or a generated shape with fuzzed geometry and edits.
/// Positions and triangles.
type MeshParts = (Vec<[f32; 3]>, Vec<[u32; 3]>);

fn mesh(u: &mut Unstructured) -> Result<MeshParts> {
    let mut p: Vec<[f32; 3]> = Vec::new();
    let mut t: Vec<[u32; 3]> = Vec::new();
    let amp = match u.int_in_range(0..=3u8)? {
        0 => 0.0,
        1 => 0.05,
        2 => 0.3,
        _ => 2.0,
    };
    match u.int_in_range(0..=5u8)? {
        0 => {
            // Raw.
            let n = u.int_in_range(0..=600usize)?;
            for _ in 0..n {
                p.push([coord(u)?, coord(u)?, coord(u)?]);
            }
            let m = u.int_in_range(0..=1100usize)?;
            for _ in 0..m {
                if u.is_empty() {
                    break;
                }
                t.push([index(u, n)?, index(u, n)?, index(u, n)?]);
            }
        }
        1 => {
            // Open grid on a height field.
            let nx = u.int_in_range(1..=20u32)?;
            let ny = u.int_in_range(1..=20u32)?;
            let diag_mode = u.int_in_range(0..=2u8)?;
            for j in 0..=ny {
                for i in 0..=nx {
                    p.push([i as f32, j as f32, bump(u, amp * 4.0)?]);
                }
            }
            let w = nx + 1;
            for j in 0..ny {
                for i in 0..nx {
                    let v = j * w + i;
                    let diag = match diag_mode {
                        0 => true,
                        1 => (i + j) % 2 == 0,
                        _ => u.arbitrary()?,
                    };
                    quad(&mut t, v, v + 1, v + w + 1, v + w, diag);
                }
            }
        }
        2 => {
            // Torus: closed, genus 1.
            let nx = u.int_in_range(3..=20u32)?;
            let ny = u.int_in_range(3..=20u32)?;
            let (r0, r1) = (3.0f32, 1.0f32);
            for j in 0..ny {
                for i in 0..nx {
                    let a = i as f32 / nx as f32 * std::f32::consts::TAU;
                    let b = j as f32 / ny as f32 * std::f32::consts::TAU;
                    let r = r1 + bump(u, amp)?;
                    p.push([
                        (r0 + r * b.cos()) * a.cos(),
                        (r0 + r * b.cos()) * a.sin(),
                        r * b.sin(),
                    ]);
                }
            }
            let diag_random: bool = u.arbitrary()?;
            for j in 0..ny {
                for i in 0..nx {
                    let at = |i: u32, j: u32| (j % ny) * nx + (i % nx);
                    let diag = if diag_random { u.arbitrary()? } else { true };
                    quad(
                        &mut t,
                        at(i, j),
                        at(i + 1, j),
                        at(i + 1, j + 1),
                        at(i, j + 1),
                        diag,
                    );
                }
            }
        }
        3 => {
            // UV sphere with poles: closed, genus 0, high-valence poles.
            let rings = u.int_in_range(1..=14u32)?;
            let segs = u.int_in_range(3..=24u32)?;
            p.push([0.0, 0.0, 1.0]);
            for j in 1..=rings {
                let th = j as f32 / (rings + 1) as f32 * std::f32::consts::PI;
                for i in 0..segs {
                    let ph = i as f32 / segs as f32 * std::f32::consts::TAU;
                    let r = 1.0 + bump(u, amp)?;
                    p.push([
                        r * th.sin() * ph.cos(),
                        r * th.sin() * ph.sin(),
                        r * th.cos(),
                    ]);
                }
            }
            p.push([0.0, 0.0, -1.0]);
            let south = (p.len() - 1) as u32;
            let ring = |j: u32, i: u32| 1 + (j - 1) * segs + (i % segs);
            for i in 0..segs {
                t.push([0, ring(1, i), ring(1, i + 1)]);
                t.push([south, ring(rings, i + 1), ring(rings, i)]);
            }
            for j in 1..rings {
                for i in 0..segs {
                    quad(
                        &mut t,
                        ring(j, i),
                        ring(j + 1, i),
                        ring(j + 1, i + 1),
                        ring(j, i + 1),
                        u.arbitrary()?,
                    );
                }
            }
        }
        4 => {
            // Welded cube with n x n quads per face: sharp creases.
            let n = u.int_in_range(1..=6u32)?;
            let mut ids: HashMap<[i32; 3], u32> = HashMap::new();
            let faces: [([i32; 3], [i32; 3], [i32; 3]); 6] = [
                ([0, 0, 0], [0, 1, 0], [1, 0, 0]),
                ([0, 0, 1], [1, 0, 0], [0, 1, 0]),
                ([0, 0, 0], [1, 0, 0], [0, 0, 1]),
                ([0, 1, 0], [0, 0, 1], [1, 0, 0]),
                ([0, 0, 0], [0, 0, 1], [0, 1, 0]),
                ([1, 0, 0], [0, 1, 0], [0, 0, 1]),
            ];
            let ni = n as i32;
            for (o, a, b) in faces {
                let mut vid = |i: i32, j: i32, p: &mut Vec<[f32; 3]>| -> u32 {
                    let k = [0, 1, 2].map(|c| o[c] * ni + a[c] * i + b[c] * j);
                    *ids.entry(k).or_insert_with(|| {
                        p.push(k.map(|x| x as f32 / ni as f32));
                        (p.len() - 1) as u32
                    })
                };
                for j in 0..ni {
                    for i in 0..ni {
                        let q = [
                            vid(i, j, &mut p),
                            vid(i + 1, j, &mut p),
                            vid(i + 1, j + 1, &mut p),
                            vid(i, j + 1, &mut p),
                        ];
                        quad(&mut t, q[0], q[1], q[2], q[3], u.arbitrary()?);
                    }
                }
            }
            for q in p.iter_mut() {
                for c in q.iter_mut() {
                    *c += bump(u, amp * 0.1)?;
                }
            }
        }
        _ => {
            // A fan around one vertex (open disc) of high valence, or a closed double cone.
            let k = u.int_in_range(3..=80u32)?;
            let closed: bool = u.arbitrary()?;
            p.push([0.0, 0.0, bump(u, amp)?]);
            for i in 0..k {
                let a = i as f32 / k as f32 * std::f32::consts::TAU;
                p.push([a.cos(), a.sin(), bump(u, amp)?]);
            }
            for i in 0..k {
                t.push([0, 1 + i, 1 + (i + 1) % k]);
            }
            if closed {
                p.push([0.0, 0.0, -1.0 + bump(u, amp)?]);
                let s = k + 1;
                for i in 0..k {
                    t.push([s, 1 + (i + 1) % k, 1 + i]);
                }
            }
        }
    }
    // Scale and offset (normalisation must make the result scale-free).
    if u.int_in_range(0..=3u8)? == 0 {
        let s = match u.int_in_range(0..=4u8)? {
            0 => 1e-38,
            1 => 1e30,
            2 => 1e-20,
            3 => 1e6,
            _ => float(u, -1e3, 1e3)?,
        };
        let off = float(u, -1e6, 1e6)?;
        for q in p.iter_mut() {
            for c in q.iter_mut() {
                *c = *c * s + off;
            }
        }
    }
    // Edits.
    let edits = u.int_in_range(0..=8u8)?;
    for _ in 0..edits {
        let n = p.len();
        match u.int_in_range(0..=7u8)? {
            0 if n > 0 => {
                let v = u.choose_index(n)?;
                let c = u.choose_index(3)?;
                p[v][c] = coord(u)?;
            }
            1 if !t.is_empty() => {
                let i = u.choose_index(t.len())?;
                let c = u.choose_index(3)?;
                t[i][c] = index(u, n)?;
            }
            2 if !t.is_empty() => {
                let i = u.choose_index(t.len())?;
                t[i].swap(0, 1);
            }
            3 if !t.is_empty() => {
                let i = u.choose_index(t.len())?;
                t.swap_remove(i);
            }
            4 if !t.is_empty() => {
                let i = u.choose_index(t.len())?;
                let mut x = t[i];
                x.rotate_left(u.choose_index(3)?);
                let at = u.choose_index(t.len() + 1)?;
                t.insert(at, x);
            }
            5 => t.push([index(u, n)?, index(u, n)?, index(u, n)?]),
            6 => p.push([coord(u)?, coord(u)?, coord(u)?]),
            _ => {
                if !t.is_empty() {
                    let i = u.choose_index(t.len())?;
                    let j = u.choose_index(t.len())?;
                    t.swap(i, j);
                }
            }
        }
    }
    Ok((p, t))
}

impl Case {
    pub fn generate(u: &mut Unstructured) -> Result<Case> {
        let workspace = u.int_in_range(0..=2u8)?;
        let wide = u.arbitrary()?;
        let mut config = config(u)?;
        // The same bytes as before the costs took their settings from the configuration
        // (the corpus stays meaningful); the explicit costs' settings go into it.
        let cost = match u.int_in_range(0..=5u8)? {
            0..=3 => CostKind::Default,
            4 => {
                config = config.with_cost(tinydecimate::CostKind::Quadric);
                config = config.with_boundary_weight(float(u, 0.0, 10.0)?);
                CostKind::Plane
            }
            _ => {
                let _length_weighted: bool = u.arbitrary()?;
                config = config.with_cost(tinydecimate::CostKind::NormalVariation);
                config = config.with_boundary_weight(float(u, 0.0, 10.0)?);
                CostKind::Normal
            }
        };
        let nb = u.int_in_range(1..=8usize)?;
        let mut budgets = Vec::with_capacity(nb);
        for _ in 0..nb {
            budgets.push(match u.int_in_range(0..=9u8)? {
                0 => 0,
                1..=3 => 1,
                4..=8 => u.int_in_range(2..=300)?,
                _ => u.arbitrary()?,
            });
        }
        let early = if u.int_in_range(0..=3u8)? == 0 {
            Some(u.arbitrary()?)
        } else {
            None
        };
        let (positions, triangles) = mesh(u)?;
        Ok(Case {
            workspace,
            wide,
            positions,
            triangles,
            config,
            cost,
            budgets,
            early,
        })
    }

    /// Runs every check; panics with a description on a violation.
    pub fn check(&self) {
        match (self.workspace, self.wide) {
            (0, false) => run::<u16, u16, 64, 64>(self),
            (0, true) => run::<u16, u32, 64, 64>(self),
            (1, false) => run::<u16, u16, 512, 512>(self),
            (1, true) => run::<u16, u32, 512, 512>(self),
            (_, false) => run::<u32, u16, 512, 1024>(self),
            (_, true) => run::<u32, u32, 512, 1024>(self),
        }
    }
}

impl Case {
    /// The pipeline's two modes on the case (its configuration: target, passes, error limit),
    /// each on a fresh workspace and again on the same one, in both arithmetics (the integer
    /// one on the positions `quantise` puts on its grid); panics with a description on a
    /// violation.
    pub fn check_pipeline(&self) {
        match (self.workspace, self.wide) {
            (0, false) => pipeline::<u16, u16, 64, 64>(self),
            (0, true) => pipeline::<u16, u32, 64, 64>(self),
            (1, false) => pipeline::<u16, u16, 512, 512>(self),
            (1, true) => pipeline::<u16, u32, 512, 512>(self),
            (_, false) => pipeline::<u32, u16, 512, 1024>(self),
            (_, true) => pipeline::<u32, u32, 512, 1024>(self),
        }
    }
}

fn pipeline<L: Index + 'static, I: Idx, const V: usize, const T: usize>(case: &Case) {
    let input: Vec<[I; 3]> = case.triangles.iter().map(|t| t.map(I::from_u32)).collect();
    let expected = pipeline_error::<L, I, V, T>(&case.positions, &input, &case.config);
    modes::<L, I, V, T, Float>(case, &case.positions, &input, expected, "");
    pipeline_integer::<L, I, V, T>(case, &input);
}

/// The error of a pipeline run on `positions`, by the documented order of checks.
fn pipeline_error<L: Index, I: Idx, const V: usize, const T: usize>(
    positions: &[[f32; 3]],
    input: &[[I; 3]],
    config: &Config,
) -> Option<Error> {
    // The pipeline's triangle capacity is `T` links, not a third of them.
    checked_error(positions, input, config, (V.min(L::COUNT), T.min(L::COUNT)))
}

/// The integer arithmetic on the case: its positions put on the grid by `quantise` (the
/// documented error for a non-finite one), both modes checked there as the float ones are (the
/// grid positions, exact in `f32`, are the checker's), and a coordinate moved off the grid
/// refused as documented.
fn pipeline_integer<L: Index + 'static, I: Idx, const V: usize, const T: usize>(
    case: &Case,
    input: &[[I; 3]],
) {
    let mut grid = vec![[0u16; 3]; case.positions.len()];
    if let Err(e) = quantise(&case.positions, &mut grid) {
        // Every position is checked, used or not.
        let vertex = case
            .positions
            .iter()
            .position(|p| !p.iter().all(|c| c.is_finite()));
        assert_eq!(
            Some(e),
            vertex.map(|vertex| Error::NonFinitePosition { vertex }),
            "quantise: unexpected error"
        );
        return;
    }
    assert!(
        grid.iter()
            .flatten()
            .all(|&c| c < tinydecimate::pipeline::GRID),
        "quantise: a coordinate off the grid"
    );
    let on_grid = Case {
        positions: grid.iter().map(|q| q.map(f32::from)).collect(),
        ..case.clone()
    };
    let expected = pipeline_error::<L, I, V, T>(&on_grid.positions, input, &case.config);
    let runs = modes::<L, I, V, T, Integer>(&on_grid, &grid, input, expected, ", integer");

    // One vertex off the grid: refused where the run checks its first corner, as a non-finite
    // position is in the float arithmetic; unused, it changes nothing.
    let Some(&budget) = case.budgets.first() else {
        return;
    };
    if grid.is_empty() {
        return;
    }
    let v = budget as usize % grid.len();
    grid[v][budget as usize % 3] |= tinydecimate::pipeline::GRID;
    let mut marked = on_grid.positions.clone();
    marked[v] = [f32::NAN; 3];
    let expected = pipeline_error::<L, I, V, T>(&marked, input, &case.config).map(|e| match e {
        Error::NonFinitePosition { vertex } => Error::OffGrid { vertex },
        e => e,
    });
    let mut fast = Box::new(FastWorkspace::<L, V, T, Integer>::new());
    let mut lean = Box::new(LeanWorkspace::<L, V, T, Integer>::new());
    for (mode, on) in ["fast, integer", "lean, integer"].into_iter().zip(runs) {
        let mut buf = input.to_vec();
        let r = if mode.starts_with("fast") {
            fast.simplify(&grid, &mut buf, &case.config)
        } else {
            lean.simplify(&grid, &mut buf, &case.config)
        };
        match expected {
            Some(e) => {
                assert_eq!(r, Err(e), "{mode}: vertex {v} off the grid");
                assert!(buf == input, "{mode}: buffer modified on error {e:?}");
            }
            None => assert!(
                (r, buf) == on,
                "{mode}: unused vertex {v} off the grid changed the result"
            ),
        }
    }
}

/// A pipeline run: its result and the triangle buffer after it.
type Run<I> = (std::result::Result<Report, Error>, Vec<[I; 3]>);

/// Both modes in arithmetic `N` on `positions` (`case.positions` the same as `f32`, for the
/// checker): `expected`, or a valid output, the same again on the same workspace; then with
/// wedges. Returns each mode's first run. `arithmetic` is appended to the modes' names.
fn modes<L: Index + 'static, I: Idx, const V: usize, const T: usize, N: Arithmetic>(
    case: &Case,
    positions: &[N::Position],
    input: &[[I; 3]],
    expected: Option<Error>,
    arithmetic: &str,
) -> Vec<Run<I>> {
    let inp: Vec<[u32; 3]> = input.iter().map(|t| t.map(I::to_u32)).collect();
    let view = pipeline_view(&case.positions, &inp);
    let mut fast = Box::new(FastWorkspace::<L, V, T, N>::new());
    let mut lean = Box::new(LeanWorkspace::<L, V, T, N>::new());
    let mut first = Vec::new();
    for name in ["fast", "lean"] {
        let mode = format!("{name}{arithmetic}");
        let mut runs = Vec::new();
        for _ in 0..2 {
            let mut buf = input.to_vec();
            let r = if name == "fast" {
                fast.simplify(positions, &mut buf, &case.config)
            } else {
                lean.simplify(positions, &mut buf, &case.config)
            };
            match &r {
                Err(e) => {
                    assert_eq!(Some(*e), expected, "{mode}: unexpected error");
                    assert!(buf == input, "{mode}: buffer modified on error {e:?}");
                }
                Ok(report) => {
                    assert_eq!(expected, None, "{mode}: expected an error");
                    assert_ne!(report.stop, Stop::Running);
                    check_output(case, input, &buf, report, &view, &mode);
                }
            }
            runs.push((r, buf));
        }
        assert!(
            runs[0] == runs[1],
            "{mode}: a reused workspace gave another result"
        );
        first.push(runs.swap_remove(0));
    }
    if expected.is_none() {
        pipeline_wedges::<L, I, V, T, N>(
            case,
            positions,
            input,
            (&mut fast, &mut lean),
            &view,
            arithmetic,
        );
    }
    first
}

/// The pipeline with wedges (`simplify_with_wedges`) on the case split into two charts: each
/// vertex copied, the triangles of one chart (a hash of the triangle's number) on the copies,
/// then welded. Each output must keep every triangle within one chart, and, each wedge read
/// as its position's first vertex, be a valid simplification of the input welded likewise.
fn pipeline_wedges<L: Index + 'static, I: Idx, const V: usize, const T: usize, N: Arithmetic>(
    case: &Case,
    positions: &[N::Position],
    input: &[[I; 3]],
    (fast, lean): (
        &mut FastWorkspace<L, V, T, N>,
        &mut LeanWorkspace<L, V, T, N>,
    ),
    view: &[[f32; 3]],
    arithmetic: &str,
) {
    let nv = case.positions.len();
    if nv == 0 || 2 * nv > V.min(L::COUNT) || 2 * nv > I::COUNT {
        return;
    }
    // Welded by the checker's positions (the same as `positions`, as `f32`).
    let mut welding = case.positions.clone();
    welding.extend_from_within(..);
    let mut positions = positions.to_vec();
    positions.extend_from_within(..);
    let chart = |t: usize| (t as u32).wrapping_mul(0x9E37_79B9) >> 31 == 1;
    let split: Vec<[I; 3]> = input
        .iter()
        .enumerate()
        .map(|(t, tr)| {
            if chart(t) {
                tr.map(|v| I::from_u32(v.to_u32() + nv as u32))
            } else {
                *tr
            }
        })
        .collect();
    let mut welded = split.clone();
    let mut wedges = vec![[I::ZERO; 3]; split.len()];
    let mut order = vec![0u32; positions.len()];
    tinydecimate::seam::weld(&welding, &mut welded, &mut wedges, &mut order)
        .expect("weld: indices checked");
    // The first vertex at a position is an original (the copies come after them all).
    let firsts = welded_firsts(&case.positions);
    let first = |v: u32| firsts[(v % nv as u32) as usize];
    let input_welded: Vec<[I; 3]> = input
        .iter()
        .map(|t| t.map(|v| I::from_u32(first(v.to_u32()))))
        .collect();
    for mode in ["fast", "lean"] {
        let (mut buf, mut w) = (welded.clone(), wedges.clone());
        let r = if mode == "fast" {
            fast.simplify_with_wedges(&positions, &mut buf, &mut w, &case.config)
        } else {
            lean.simplify_with_wedges(&positions, &mut buf, &mut w, &case.config)
        };
        let what = format!("{mode}{arithmetic} with wedges");
        let report = r.unwrap_or_else(|e| panic!("{what}: {e:?} on input the plain run took"));
        let out = &buf[..report.triangles_out];
        for t in out {
            let sides = t.map(|v| v.to_u32() >= nv as u32);
            assert!(
                sides[0] == sides[1] && sides[1] == sides[2],
                "{what}: triangle {t:?} takes two charts"
            );
        }
        let out_welded: Vec<[I; 3]> = out
            .iter()
            .map(|t| t.map(|v| I::from_u32(first(v.to_u32()))))
            .collect();
        check_output(case, &input_welded, &out_welded, &report, view, &what);
    }
}

/// Each vertex's first vertex of `positions` at its position (positions compared by bits,
/// `-0.0` as `0.0`, as `seam::weld` compares them).
fn welded_firsts(positions: &[[f32; 3]]) -> Vec<u32> {
    let key = |p: &[f32; 3]| p.map(|x| if x == 0.0 { 0 } else { x.to_bits() });
    let mut seen = HashMap::new();
    (0..positions.len() as u32)
        .map(|v| *seen.entry(key(&positions[v as usize])).or_insert(v))
        .collect()
}

/// The bounding box (low and high corners) of the vertices the triangles use; infinite
/// corners without any.
fn used_bounds(pos: &[[f32; 3]], tris: &[[u32; 3]]) -> ([f32; 3], [f32; 3]) {
    let mut lo = [f32::INFINITY; 3];
    let mut hi = [f32::NEG_INFINITY; 3];
    for t in tris {
        for &i in t {
            if let Some(p) = pos.get(i as usize) {
                for a in 0..3 {
                    lo[a] = lo[a].min(p[a]);
                    hi[a] = hi[a].max(p[a]);
                }
            }
        }
    }
    (lo, hi)
}

/// The positions as the pipeline sees them: translated by the bounding box's corner (over the
/// vertices the triangles use) and scaled by a power of two (exact) to an extent near one.
pub fn pipeline_view(pos: &[[f32; 3]], tris: &[[u32; 3]]) -> Vec<[f32; 3]> {
    let (lo, hi) = used_bounds(pos, tris);
    let extent = (0..3).map(|a| hi[a] - lo[a]).fold(0.0f32, f32::max);
    let scale = if extent.is_finite() && extent >= f32::MIN_POSITIVE {
        let e = (extent.to_bits() >> 23) as i32 - 127;
        2.0f32.powi(-e)
    } else {
        0.0
    };
    let lo = if lo[0].is_finite() { lo } else { [0.0; 3] };
    pos.iter()
        .map(|q| [0, 1, 2].map(|a| (q[a] - lo[a]) * scale))
        .collect()
}

/// The error `start` must return, by the documented order of checks.
fn expected_error<L: Index, I: Idx, const V: usize, const T: usize>(
    positions: &[[f32; 3]],
    tris: &[[I; 3]],
    config: &Config,
) -> Option<Error> {
    checked_error(
        positions,
        tris,
        config,
        (V.min(L::COUNT), T.min(L::COUNT / 3)),
    )
}

/// The error of a run that checks, in order, the configuration, the vertex and the triangle
/// capacity, then each corner's index and position.
fn checked_error<I: Idx>(
    positions: &[[f32; 3]],
    tris: &[[I; 3]],
    config: &Config,
    (cap_v, cap_t): (usize, usize),
) -> Option<Error> {
    if let Err(e) = config.validate() {
        return Some(e);
    }
    if positions.len() > cap_v {
        return Some(Error::Capacity {
            what: tinydecimate::Capacity::Vertices,
            needed: positions.len(),
            available: cap_v,
        });
    }
    if tris.len() > cap_t {
        return Some(Error::Capacity {
            what: tinydecimate::Capacity::Triangles,
            needed: tris.len(),
            available: cap_t,
        });
    }
    for (t, tri) in tris.iter().enumerate() {
        for &i in tri {
            let index = i.to_u32() as usize;
            match positions.get(index) {
                None => return Some(Error::IndexOutOfRange { triangle: t, index }),
                Some(p) if !p.iter().all(|c| c.is_finite()) => {
                    return Some(Error::NonFinitePosition { vertex: index })
                }
                _ => {}
            }
        }
    }
    None
}

struct Dirty<L: Index, const V: usize, const T: usize>(Box<Workspace<L, V, T>>);

thread_local! {
    static WS0: std::cell::RefCell<Dirty<u16, 64, 64>> = std::cell::RefCell::new(Dirty(Box::new(Workspace::new())));
    static WS1: std::cell::RefCell<Dirty<u16, 512, 512>> = std::cell::RefCell::new(Dirty(Box::new(Workspace::new())));
    static WS2: std::cell::RefCell<Dirty<u32, 512, 1024>> = std::cell::RefCell::new(Dirty(Box::new(Workspace::new())));
}

/// Runs `f` on a long-lived workspace of the type (reused across runs, so stale state from
/// earlier inputs is there to leak if it could).
fn with_dirty<L: Index + 'static, const V: usize, const T: usize, R>(
    f: impl FnOnce(&mut Workspace<L, V, T>) -> R,
) -> R {
    use std::any::Any;
    let mut f = Some(f);
    let mut out = None;
    macro_rules! try_ws {
        ($ws:ident) => {
            if out.is_none() {
                $ws.with(|w| {
                    let mut w = w.borrow_mut();
                    if let Some(ws) =
                        (&mut *w.0 as &mut dyn Any).downcast_mut::<Workspace<L, V, T>>()
                    {
                        out = Some((f.take().unwrap())(ws));
                    }
                });
            }
        };
    }
    try_ws!(WS0);
    try_ws!(WS1);
    try_ws!(WS2);
    out.unwrap_or_else(|| (f.take().unwrap())(&mut Workspace::new()))
}

/// Drives `start` (with the case's cost) to the end with the given budgets, checking the state
/// between steps; `stop_after`: finish early after that many `step` calls.
fn stepped<L: Index, I: Idx, const V: usize, const T: usize>(
    ws: &mut Workspace<L, V, T>,
    case: &Case,
    tris: &mut [[I; 3]],
    stop_after: Option<usize>,
) -> std::result::Result<Report, Error> {
    macro_rules! drive {
        ($s:expr) => {{
            let mut s = $s?;
            let nv = case.positions.len();
            let mut calls = 0usize;
            let mut zero_run = 0usize;
            loop {
                if stop_after.is_some_and(|k| calls >= k) {
                    break;
                }
                let mut b = case.budgets[calls % case.budgets.len()];
                if b == 0 {
                    zero_run += 1;
                    if zero_run > case.budgets.len() {
                        b = 1; // every budget is 0: make progress anyway
                    }
                } else {
                    zero_run = 0;
                }
                let live_before = s.live_triangles();
                let done = s.step(b);
                calls += 1;
                if b == 0 {
                    assert_eq!(s.live_triangles(), live_before, "step(0) changed the mesh");
                }
                // Between steps: the view, the buffer and the report agree.
                if calls % 16 == 1 || done || nv <= 64 {
                    let live: Vec<[I; 3]> = s.triangles().collect();
                    assert_eq!(
                        live.len(),
                        s.live_triangles(),
                        "triangles() vs live_triangles()"
                    );
                    let buf_live: Vec<[I; 3]> = s
                        .buffer()
                        .iter()
                        .copied()
                        .filter(|t| t[0] != t[1])
                        .collect();
                    assert_eq!(buf_live, live, "buffer's live triangles vs triangles()");
                    let r = s.report();
                    assert_eq!(r.triangles_out, s.live_triangles());
                    assert_eq!(r.stop == Stop::Running, !done, "report().stop vs step()");
                    let mut used = vec![false; nv];
                    for t in &live {
                        for &i in t {
                            used[i.to_u32() as usize] = true;
                        }
                    }
                    for (v, &u) in used.iter().enumerate() {
                        assert_eq!(s.is_used(v), u, "is_used({v})");
                        if !u {
                            let _ = s.is_feature(v);
                        }
                    }
                    assert!(!s.is_used(nv) && !s.is_used(usize::MAX));
                    let _ = s.is_feature(nv);
                }
                if done {
                    // Finished stays finished.
                    assert!(s.step(1) && s.step(0) && s.step(u32::MAX));
                    break;
                }
                assert!(calls < 50_000_000, "no end in sight");
            }
            Ok(s.finish())
        }};
    }
    match case.cost {
        CostKind::Default => drive!(ws.start(
            Positions::Read(&case.positions),
            tris,
            &case.config,
            tinydecimate::Builtin::new(),
            NoBound,
            EdgeCollapse,
        )),
        CostKind::Plane => drive!(ws.start(
            Positions::Read(&case.positions),
            tris,
            &case.config,
            Quadric::new(),
            NoBound,
            EdgeCollapse,
        )),
        CostKind::Normal => drive!(ws.start(
            Positions::Read(&case.positions),
            tris,
            &case.config,
            NormalVariation::new(),
            NoBound,
            EdgeCollapse,
        )),
    }
}

fn run<L: Index + 'static, I: Idx, const V: usize, const T: usize>(case: &Case) {
    let input: Vec<[I; 3]> = case.triangles.iter().map(|t| t.map(I::from_u32)).collect();
    let expected = expected_error::<L, I, V, T>(&case.positions, &input, &case.config);

    // 1. One shot, on a reused workspace.
    let mut one = input.clone();
    let r1 = with_dirty::<L, V, T, _>(|ws| match case.cost {
        CostKind::Default => ws.simplify(&case.positions, &mut one, &case.config),
        _ => stepped(
            ws,
            &Case {
                budgets: vec![u32::MAX],
                ..case.clone()
            },
            &mut one,
            None,
        ),
    });
    // 2. Stepped with the fuzzed budgets, on a fresh workspace.
    let mut two = input.clone();
    let mut ws = Box::new(Workspace::<L, V, T>::new());
    let r2 = stepped(&mut ws, case, &mut two, None);

    match (&r1, &r2) {
        (Err(e1), Err(e2)) => {
            assert_eq!(e1, e2, "one-shot and stepped errors differ");
            assert_eq!(Some(*e1), expected, "unexpected error");
            assert!(
                one == input && two == input,
                "buffer modified on error {e1:?}"
            );
            let mut s = String::new();
            std::fmt::Write::write_fmt(&mut s, format_args!("{e1}")).unwrap();
            assert!(!s.is_empty());
            return;
        }
        (Ok(a), Ok(b)) => {
            assert_eq!(expected, None, "expected an error");
            assert_eq!(a, b, "stepped report differs from one-shot");
            assert!(one == two, "stepped buffer differs from one-shot");
        }
        _ => panic!("one-shot {r1:?} vs stepped {r2:?}"),
    }
    let report = r1.unwrap();
    assert_ne!(report.stop, Stop::Running);
    let inp: Vec<[u32; 3]> = input.iter().map(|t| t.map(I::to_u32)).collect();
    let view = engine_view(&case.positions, &inp);
    check_output(case, &input, &one, &report, &view, "complete");

    // 3. Finished early: still a valid mesh.
    if let Some(k) = case.early {
        let mut three = input.clone();
        let r3 = stepped(&mut ws, case, &mut three, Some(k as usize)).expect("early run");
        check_output(case, &input, &three, &r3, &view, "early");
    }
}

fn check_output<I: Idx>(
    case: &Case,
    input: &[[I; 3]],
    buf: &[[I; 3]],
    report: &Report,
    view: &[[f32; 3]],
    what: &str,
) {
    let pos = &case.positions;
    let inp: Vec<[u32; 3]> = input.iter().map(|t| t.map(I::to_u32)).collect();
    assert_eq!(report.triangles_in, inp.len());
    assert!(
        report.triangles_out <= inp.len(),
        "{what}: more triangles out than in"
    );
    let out: Vec<[u32; 3]> = buf[..report.triangles_out]
        .iter()
        .map(|t| t.map(I::to_u32))
        .collect();
    assert_eq!(
        report.target_reached,
        report.triangles_out <= report.target_triangles
    );
    if report.stop == Stop::Target {
        assert!(
            report.target_reached,
            "{what}: stop Target but target not reached"
        );
    }
    let a = meshcheck::analyse(pos, &inp).topology;
    assert_eq!(
        report.degenerate_dropped, a.degenerate_triangles,
        "{what}: degenerate_dropped"
    );
    // The checker counts every later copy; the library keeps the first turned over as a twin.
    assert_eq!(
        report.duplicates_dropped + report.twins,
        a.duplicate_triangles,
        "{what}: duplicates_dropped + twins"
    );
    // The shared checker. Folds and new zero-area triangles count only if the true geometry
    // (f64) and the engine's own f32 view of it agree: where they disagree, the input has
    // detail below f32 resolution at its scale.
    let opts = meshcheck::Options {
        view: Some(meshcheck::View {
            positions: view,
            margin: FOLD_MARGIN,
            min_quality: MIN_Q,
        }),
        allow_moved: false,
        welded: false,
        // The pipeline's runs (`what` names its mode) may remove parts whole.
        parts: case.config.prune_parts() && (what.starts_with("fast") || what.starts_with("lean")),
    };
    let mesh = |triangles| meshcheck::MeshRef {
        positions: pos,
        triangles,
    };
    meshcheck::check_with(mesh(&inp), mesh(&out), &opts).assert_valid(what);
}

/// The engines refuse `dot < -0.89` in f32, inside the checker's -0.9; pairs within this of
/// the checker's limit count as either.
pub const FOLD_MARGIN: f64 = 1e-4;

/// Below this quality (`4√3·area / Σ edge²`, f64) a triangle's f32 normal may point anywhere.
pub const MIN_Q: f64 = 1e-3;

/// The positions as the exact engine sees them: its affine map of the input's bounding box (over
/// the vertices the triangles use) into about `[-1, 1]³`, in f32 (src/mesh.rs, `Mesh::build`).
/// Fold checks use these, so that geometry finer than f32 resolves at the mesh's scale (say a
/// 1e-20 detail beside a 1e-11 extent) does not count as a fold the engine failed to see.
pub fn engine_view(pos: &[[f32; 3]], tris: &[[u32; 3]]) -> Vec<[f32; 3]> {
    let (lo, hi) = used_bounds(pos, tris);
    let mut centre = [0.0f32; 3];
    let mut half = 0.0f32;
    if !tris.is_empty() {
        for a in 0..3 {
            centre[a] = lo[a] * 0.5 + hi[a] * 0.5;
            half = half.max(hi[a] * 0.5 - lo[a] * 0.5);
        }
    }
    let inv = 1.0 / half;
    let inv = if inv.is_finite() { inv } else { 1.0 };
    pos.iter()
        .map(|q| [0, 1, 2].map(|a| (q[a] * 0.5 - centre[a] * 0.5) * inv))
        .collect()
}

/// What `tinydecimate_cli::io` promises of a loaded mesh: triangles, indices in range, and finite
/// coordinates in every vertex a triangle uses (an unused vertex may hold anything, as the
/// library ignores it).
pub fn check_mesh_data(m: &tinydecimate_cli::io::MeshData) {
    assert!(!m.triangles.is_empty(), "loaded a mesh without triangles");
    for t in &m.triangles {
        for &i in t {
            let p = m.positions.get(i as usize);
            assert!(p.is_some(), "index {i} out of range");
            let p = p.into_iter().flatten();
            assert!(
                p.clone().all(|c| c.is_finite()),
                "non-finite position of used vertex {i}: {:?}",
                p.collect::<Vec<_>>()
            );
        }
    }
    let _ = m.bbox_diagonal();
}

impl Case {
    /// The envelope bound (`bound::Envelope`) on the case's mesh, with the edge collapse and
    /// with vertex decimation: a documented error, or a valid output whose sampled distance to
    /// the input, both ways, is within the bound.
    pub fn check_envelope(&self) {
        match (self.workspace, self.wide) {
            (0, false) => envelope::<u16, u16, 64, 64>(self),
            (0, true) => envelope::<u16, u32, 64, 64>(self),
            (1, false) => envelope::<u16, u16, 512, 512>(self),
            (1, true) => envelope::<u16, u32, 512, 512>(self),
            (_, false) => envelope::<u32, u16, 512, 1024>(self),
            (_, true) => envelope::<u32, u32, 512, 1024>(self),
        }
    }
}

fn envelope<L: Index + 'static, I: Idx, const V: usize, const T: usize>(case: &Case) {
    use tinydecimate::bound::{bounding_diagonal, index_len, Envelope};
    use tinydecimate::{Builtin, VertexDecimation};
    let input: Vec<[I; 3]> = case.triangles.iter().map(|t| t.map(I::from_u32)).collect();
    if expected_error::<L, I, V, T>(&case.positions, &input, &case.config).is_some() {
        // The errors before a bound's are the `simplify` target's.
        return;
    }
    let step = case.budgets.first().copied().unwrap_or(0) % 16;
    let eps = bounding_diagonal(&case.positions) * (0.005 + 0.004 * step as f32);
    let config = Config::new().with_ratio(0.0).with_max_error(eps);
    let inp: Vec<[u32; 3]> = input.iter().map(|t| t.map(I::to_u32)).collect();
    let view = engine_view(&case.positions, &inp);
    for removal in [false, true] {
        let mut buf = input.clone();
        let mut shell = vec![[[0.0f32; 3]; 2]; case.positions.len()];
        let mut index = vec![0u32; index_len(input.len())];
        let bound = Envelope::new(&input, &mut shell, &mut index);
        let mut ws = Box::new(Workspace::<L, V, T>::new());
        let p = Positions::Read(&case.positions);
        let r = if removal {
            ws.as_storage()
                .start(p, &mut buf, &config, Builtin::new(), bound, VertexDecimation::new())
                .map(|s| s.run())
        } else {
            ws.as_storage()
                .start(p, &mut buf, &config, Builtin::new(), bound, EdgeCollapse)
                .map(|s| s.run())
        };
        let report = match r {
            Err(e) => {
                assert!(
                    matches!(e, Error::InvalidConfig { .. }),
                    "envelope: unexpected error {e:?}"
                );
                assert!(buf == input, "envelope: buffer modified on error {e:?}");
                continue;
            }
            Ok(r) => r,
        };
        check_output(case, &input, &buf, &report, &view, "envelope");
        let out: Vec<[u32; 3]> = buf[..report.triangles_out]
            .iter()
            .map(|t| t.map(I::to_u32))
            .collect();
        let bound = f64::from(eps) * 1.0001;
        let d = sampled_distance(&case.positions, &out, &inp)
            .max(sampled_distance(&case.positions, &inp, &out));
        assert!(
            d <= bound,
            "envelope ({}): sampled distance {d:e} above the bound {bound:e}: {} of {} triangles \
             out {:?}",
            if removal { "vertex decimation" } else { "edge collapse" },
            out.len(),
            inp.len(),
            out
        );
    }
}

/// The largest distance from points sampled on `from` (corners, edge midpoints, centroids and
/// the points halfway from each corner to the centroid) to the triangles of `to`, in f64. A
/// triangle of `from` that `to` has too is at distance 0 and not sampled: f64 cannot find a
/// point on a sliver 10¹⁶ long, which it would then count as far from itself.
fn sampled_distance(pos: &[[f32; 3]], from: &[[u32; 3]], to: &[[u32; 3]]) -> f64 {
    let p = |v: u32| pos[v as usize].map(f64::from);
    let kept: std::collections::HashSet<[u32; 3]> = to.iter().map(|&t| sorted(t)).collect();
    let to: Vec<[[f64; 3]; 3]> = to.iter().map(|t| t.map(p)).collect();
    let mut worst = 0.0f64;
    for t in from {
        let [a, b, c] = t.map(p);
        if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] || kept.contains(&sorted(*t)) {
            continue;
        }
        let g = [0, 1, 2].map(|k| (a[k] + b[k] + c[k]) / 3.0);
        let mid = |x: [f64; 3], y: [f64; 3]| [0, 1, 2].map(|k| (x[k] + y[k]) / 2.0);
        for q in [a, b, c, mid(a, b), mid(b, c), mid(c, a), g, mid(a, g), mid(b, g), mid(c, g)] {
            let d = to
                .iter()
                .map(|&s| point_triangle(q, s))
                .fold(f64::INFINITY, f64::min);
            worst = worst.max(d);
        }
    }
    worst
}

fn sorted(mut t: [u32; 3]) -> [u32; 3] {
    t.sort_unstable();
    t
}

/// Distance from `p` to the triangle `t` (Ericson, "Real-Time Collision Detection" §5.1.5).
fn point_triangle(p: [f64; 3], t: [[f64; 3]; 3]) -> f64 {
    let sub = |x: [f64; 3], y: [f64; 3]| [x[0] - y[0], x[1] - y[1], x[2] - y[2]];
    let dot = |x: [f64; 3], y: [f64; 3]| x[0] * y[0] + x[1] * y[1] + x[2] * y[2];
    let at = |o: [f64; 3], u: [f64; 3], s: f64| [o[0] + u[0] * s, o[1] + u[1] * s, o[2] + u[2] * s];
    let [a, b, c] = t;
    let (ab, ac, ap) = (sub(b, a), sub(c, a), sub(p, a));
    let (d1, d2) = (dot(ab, ap), dot(ac, ap));
    let q = if d1 <= 0.0 && d2 <= 0.0 {
        a
    } else {
        let bp = sub(p, b);
        let (d3, d4) = (dot(ab, bp), dot(ac, bp));
        let cp = sub(p, c);
        let (d5, d6) = (dot(ab, cp), dot(ac, cp));
        let vc = d1 * d4 - d3 * d2;
        let vb = d5 * d2 - d1 * d6;
        let va = d3 * d6 - d5 * d4;
        if d3 >= 0.0 && d4 <= d3 {
            b
        } else if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
            at(a, ab, d1 / (d1 - d3))
        } else if d6 >= 0.0 && d5 <= d6 {
            c
        } else if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
            at(a, ac, d2 / (d2 - d6))
        } else if va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0 {
            at(b, sub(c, b), (d4 - d3) / ((d4 - d3) + (d5 - d6)))
        } else {
            let s = va + vb + vc;
            if s > 0.0 {
                at(at(a, ab, vb / s), ac, vc / s)
            } else {
                // Degenerate: its corners.
                let e = [a, b, c].map(|x| dot(sub(p, x), sub(p, x)));
                return e[0].min(e[1]).min(e[2]).sqrt();
            }
        }
    };
    let d = sub(p, q);
    dot(d, d).sqrt()
}
