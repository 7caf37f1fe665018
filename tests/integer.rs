//! The pipeline in integers (`pipeline::Integer`, crate feature `fast`): both modes
//! (`FastWorkspace` and `LeanWorkspace` with `Integer`) on meshes put on the 15-bit grid by
//! `pipeline::quantise`, or written on it directly. Every decision is made on the grid, so
//! each output is checked by the shared checker on the grid's own positions
//! (`GridFrame::position`), and by the zero-area floor of the integer rule itself:
//!
//! * validity with the topology kept on fixtures and generated meshes at 50 %, 25 % and 10 %,
//!   on meshes spanning the whole grid, and on welded seams with wedges;
//! * the rules no checker sees, one collapse at a time: no surviving triangle turned by 75.5°
//!   or more (the flip test), no copy of a turned-over face (the duplicate rule);
//! * the target reached on clean closed meshes; the same bytes run to run, for either link
//!   width and index type, and in either mode;
//! * typed errors (`Error::OffGrid` naming the first used vertex off the grid in corner order,
//!   capacity, indices, wedges) with the buffers untouched;
//! * the error limit in grid cells, and `Report::collapse_error` under it;
//! * on smooth meshes, an error close to the float pipeline's on the same grid mesh.
//!
//! `PIPELINE_RULE_OFF=<rule>` (a rule of `src/pipeline/perform.rs` switched off at build time)
//! makes at least one of these fail for each rule.
#![cfg(feature = "fast")]

mod common;
use common::*;
use std::collections::{BTreeSet, HashMap};
use std::sync::Mutex;
use tinydecimate::pipeline::{quantise, FastWorkspace, GridFrame, Integer, LeanWorkspace, GRID};
use tinydecimate::{Capacity, Config, Error, Reject, Report, Stop, Target};

static FAST: Mutex<FastWorkspace<u32, 65_536, 131_072, Integer>> = Mutex::new(FastWorkspace::new());
static LEAN: Mutex<LeanWorkspace<u32, 65_536, 131_072, Integer>> = Mutex::new(LeanWorkspace::new());
/// The float pipeline, for the quality comparison.
static FLOAT_FAST: Mutex<FastWorkspace<u32, 65_536, 131_072>> = Mutex::new(FastWorkspace::new());
static FLOAT_LEAN: Mutex<LeanWorkspace<u32, 65_536, 131_072>> = Mutex::new(LeanWorkspace::new());

use common::{modes, Mode};

/// A mesh on the grid: the grid positions the run reads, and the same mesh on their float
/// positions (`GridFrame::position`), which the checker reads.
struct OnGrid {
    grid: Vec<[u16; 3]>,
    mesh: MeshData,
}

/// `m` put on the grid by `quantise`.
fn quantised(m: &MeshData) -> OnGrid {
    let mut grid = vec![[0u16; 3]; m.positions.len()];
    let frame = quantise(&m.positions, &mut grid).expect("quantise");
    on_frame(grid, m.triangles.clone(), frame)
}

/// Grid positions and triangles, with the float positions of `frame`.
fn on_frame(grid: Vec<[u16; 3]>, triangles: Vec<Tri>, frame: GridFrame) -> OnGrid {
    let positions = grid.iter().map(|&q| frame.position(q)).collect();
    OnGrid {
        grid,
        mesh: MeshData {
            positions,
            triangles,
        },
    }
}

/// Grid positions taken as they are (one cell a unit, the origin at zero).
fn raw_grid(grid: Vec<[u16; 3]>, triangles: Vec<Tri>) -> OnGrid {
    let frame = GridFrame {
        origin: [0.0; 3],
        step: 1.0,
    };
    on_frame(grid, triangles, frame)
}

fn run(mode: Mode, g: &OnGrid, ratio: f32) -> (MeshData, Report) {
    run_with(mode, g, &Config::new().with_ratio(ratio))
}

fn run_with(mode: Mode, g: &OnGrid, config: &Config) -> (MeshData, Report) {
    let mut tris = g.mesh.triangles.clone();
    let r = simplify_on(mode, &g.grid, &mut tris, config);
    output(&g.mesh.positions, tris, r)
}

/// One run on the shared workspace of `mode`: `tris` simplified in place.
fn simplify_on(mode: Mode, grid: &[[u16; 3]], tris: &mut [Tri], config: &Config) -> Report {
    match mode {
        Mode::Fast => FAST
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .simplify(grid, tris, config),
        Mode::Lean => LEAN
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .simplify(grid, tris, config),
    }
    .expect("simplify")
}

/// The float pipeline on the grid mesh's float positions.
fn run_float(mode: Mode, g: &OnGrid, ratio: f32) -> (MeshData, Report) {
    let config = Config::new().with_ratio(ratio);
    let mut tris = g.mesh.triangles.clone();
    let r = match mode {
        Mode::Fast => FLOAT_FAST
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .simplify(&g.mesh.positions, &mut tris, &config),
        Mode::Lean => FLOAT_LEAN
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .simplify(&g.mesh.positions, &mut tris, &config),
    }
    .expect("simplify");
    output(&g.mesh.positions, tris, r)
}

/// The checks every run must pass: the checker's verdict (topology included on a clean
/// input), no new sliver, and a report that agrees with the output.
fn assert_run_valid(what: &str, g: &OnGrid, out: &MeshData, r: &Report) {
    assert_eq!(r.triangles_out, out.triangles.len(), "{what}: count");
    assert_eq!(r.target_reached, r.stop == Stop::Target, "{what}: {r:?}");
    let v = verdict(&g.mesh, out);
    assert!(v.is_valid(), "{what}: {r:?}\n{}", v.describe(10));
    assert!(
        v.euler_unchanged() && v.boundary_loops_unchanged(),
        "{what}"
    );
    assert_eq!(v.components.0, v.components.1, "{what}: components");
    let slivers = new_slivers(g, out);
    assert!(
        slivers.is_empty(),
        "{what}: {} new triangles at or under the zero-area floor, first {:?}",
        slivers.len(),
        &slivers[..slivers.len().min(5)]
    );
}

/// Grid triangle `t`'s `|n|²` (`n` the cross product of two edges) and the sum of its
/// squared edges, exact.
fn grid_shape(grid: &[[u16; 3]], t: Tri) -> (i128, i128) {
    let p = t.map(|v| grid[v as usize].map(i128::from));
    let e = |i: usize, j: usize| [0, 1, 2].map(|k| p[j][k] - p[i][k]);
    let (u, w, z) = (e(0, 1), e(0, 2), e(1, 2));
    let n = [
        u[1] * w[2] - u[2] * w[1],
        u[2] * w[0] - u[0] * w[2],
        u[0] * w[1] - u[1] * w[0],
    ];
    let l2 = |x: [i128; 3]| x.iter().map(|c| c * c).sum::<i128>();
    (l2(n), l2(u) + l2(w) + l2(z))
}

/// Output triangles (by vertex set not an input triangle, so made by a collapse) that the
/// zero-area rule would refuse: the integer pipeline's floor is `|n|² > ⌊s / 2¹³⌋²` (`s` the
/// sum of squared edges), the float rule's `|n|² > 10⁻⁸ s²` with `2⁻²⁶` for `10⁻⁸`. The
/// checker counts only exact zeros; this sees the near-degenerate ones the rule keeps out.
fn new_slivers(g: &OnGrid, out: &MeshData) -> Vec<Tri> {
    let input: BTreeSet<Tri> = g.mesh.triangles.iter().map(|&t| sorted(t)).collect();
    out.triangles
        .iter()
        .copied()
        .filter(|&t| !input.contains(&sorted(t)))
        .filter(|&t| {
            let (n2, s) = grid_shape(&g.grid, t);
            n2 <= (s >> 13) * (s >> 13)
        })
        .collect()
}

fn sorted(mut t: Tri) -> Tri {
    t.sort_unstable();
    t
}

/// Real meshes: closed organic with a pinched vertex (cow), CAD with sharp edges and long
/// thin triangles (fandisk, plate_holes, tray_bottom), CAD in several closed parts (pins), and
/// an open one with non-manifold edges and many parts (pr2_sensor_mount).
const FIXTURES: [&str; 6] = [
    "cow.obj",
    "fandisk.obj",
    "plate_holes.obj",
    "pins.obj",
    "tray_bottom.obj",
    "pr2_sensor_mount.obj",
];

#[test]
fn quantised_fixtures_at_50_25_10_percent_are_valid() {
    for name in FIXTURES {
        let g = quantised(&load_obj(name));
        for mode in modes() {
            for ratio in [0.5f32, 0.25, 0.1] {
                let (out, r) = run(mode, &g, ratio);
                let what = format!("{mode:?} {name} {ratio}");
                assert_run_valid(&what, &g, &out, &r);
                // Something was simplified: the run is not valid by doing nothing.
                assert!(r.collapses > 0, "{what}: {r:?}");
            }
        }
    }
}

#[test]
fn quantised_generated_meshes_are_valid_down_to_nothing() {
    for (what, m) in [
        ("icosphere", icosphere(4)),
        ("grid", grid(30, 20, 0.2)),
        ("cube", cube(8)),
        ("fin_and_pinch", fin_and_pinch(12)),
        ("jittered grid", jitter(grid(24, 24, 0.1), 7, 0.02)),
    ] {
        let g = quantised(&m);
        for mode in modes() {
            for ratio in [0.5f32, 0.25, 0.1, 0.0] {
                let (out, r) = run(mode, &g, ratio);
                assert_run_valid(&format!("{mode:?} {what} {ratio}"), &g, &out, &r);
            }
        }
    }
}

#[test]
fn the_target_is_reached_on_clean_closed_meshes() {
    for (name, m) in [
        ("cow", load_obj("cow.obj")),
        ("spot", load_obj("spot.obj")),
        ("icosphere", icosphere(4)),
    ] {
        let g = quantised(&m);
        for mode in modes() {
            for ratio in [0.5f32, 0.25, 0.1] {
                let (_, r) = run(mode, &g, ratio);
                assert_eq!(r.stop, Stop::Target, "{mode:?} {name} {ratio}: {r:?}");
                assert!(r.target_reached, "{mode:?} {name} {ratio}");
                assert!(r.triangles_out <= r.target_triangles, "{mode:?} {name}");
            }
        }
    }
}

/// The run on a fresh workspace of its own, `u16` links, with triangle indices of type `I`.
fn run_fresh<I: tinydecimate::Index + Copy>(
    mode: Mode,
    g: &OnGrid,
    tris: &[[I; 3]],
    config: &Config,
) -> (Vec<[I; 3]>, Report) {
    let mut tris = tris.to_vec();
    let r = match mode {
        Mode::Fast => Box::new(FastWorkspace::<u16, 4096, 8192, Integer>::new())
            .as_mut()
            .simplify(&g.grid, &mut tris, config),
        Mode::Lean => Box::new(LeanWorkspace::<u16, 4096, 8192, Integer>::new())
            .as_mut()
            .simplify(&g.grid, &mut tris, config),
    }
    .expect("simplify");
    tris.truncate(r.triangles_out);
    (tris, r)
}

#[test]
fn two_runs_and_both_link_widths_give_the_same_bytes() {
    let g = quantised(&load_obj("cow.obj"));
    let config = Config::new().with_ratio(0.1);
    for mode in modes() {
        let (a, ra) = run(mode, &g, 0.1);
        let (b, rb) = run(mode, &g, 0.1);
        assert_same(&a.triangles, &b.triangles, &format!("{mode:?}: two runs"));
        assert_eq!(ra, rb, "{mode:?}");
        // u16 links in a fresh workspace (nothing read before it is written).
        let (t, r) = run_fresh(mode, &g, &g.mesh.triangles, &config);
        assert_same(
            &t,
            &a.triangles,
            &format!("{mode:?}: u16 links, u32 indices"),
        );
        assert_eq!(r, ra, "{mode:?}");
        // u16 triangle indices too.
        let small: Vec<[u16; 3]> = g
            .mesh
            .triangles
            .iter()
            .map(|t| t.map(|v| v as u16))
            .collect();
        let (t, _) = run_fresh(mode, &g, &small, &config);
        let t: Vec<Tri> = t.iter().map(|t| t.map(u32::from)).collect();
        assert_same(
            &t,
            &a.triangles,
            &format!("{mode:?}: u16 links, u16 indices"),
        );
    }
}

/// Panics unless `a` and `b` are the same triangles in the same order, naming the first
/// difference (not printing whole meshes).
#[track_caller]
fn assert_same(a: &[Tri], b: &[Tri], what: &str) {
    if a != b {
        let i = a.iter().zip(b).take_while(|(x, y)| x == y).count();
        panic!(
            "{what}: {} and {} triangles, first difference at {i}: {:?} / {:?}",
            a.len(),
            b.len(),
            a.get(i),
            b.get(i)
        );
    }
}

/// In integers a quadric's sum is exact in any order, so the lean mode's quadrics built from
/// the fans are the fast mode's stored ones bit for bit, and the two modes make the same
/// decisions: the same triangles (in floats the order of the sums may change a price's last
/// bits, and the outputs with it).
#[test]
fn the_fast_and_lean_modes_give_the_same_triangles() {
    for name in ["cow.obj", "fandisk.obj", "pins.obj", "pr2_sensor_mount.obj"] {
        let g = quantised(&load_obj(name));
        for ratio in [0.5f32, 0.1, 0.02] {
            let (fast, rf) = run(Mode::Fast, &g, ratio);
            let (lean, rl) = run(Mode::Lean, &g, ratio);
            assert_same(&fast.triangles, &lean.triangles, &format!("{name} {ratio}"));
            assert_eq!(rf, rl, "{name} {ratio}");
        }
    }
}

// ---- welded seams ------------------------------------------------------------------------

/// `m` on the grid welded by grid position (each index the first vertex at its grid
/// position), with the caller's triangles as the wedges: what `simplify_with_wedges` takes.
fn welded(g: &OnGrid) -> (Vec<Tri>, Vec<Tri>) {
    let mut first = HashMap::new();
    for (v, &q) in g.grid.iter().enumerate() {
        first.entry(q).or_insert(v as u32);
    }
    let tris = g
        .mesh
        .triangles
        .iter()
        .map(|t| t.map(|v| first[&g.grid[v as usize]]))
        .collect();
    (tris, g.mesh.triangles.clone())
}

/// `simplify_with_wedges` on `g` welded: the output as wedges (the caller's vertices).
fn run_wedges(mode: Mode, g: &OnGrid, config: &Config) -> (MeshData, Report) {
    let (mut tris, mut wedges) = welded(g);
    assert!(
        tris != wedges,
        "the mesh has seams: welding changed no triangle"
    );
    let r = match mode {
        Mode::Fast => FAST
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .simplify_with_wedges(&g.grid, &mut tris, &mut wedges, config),
        Mode::Lean => LEAN
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .simplify_with_wedges(&g.grid, &mut tris, &mut wedges, config),
    }
    .expect("simplify_with_wedges");
    output(&g.mesh.positions, tris, r)
}

fn welded_verdict(input: &MeshData, output: &MeshData) -> meshcheck::Verdict {
    verdict_opts(
        input,
        output,
        &meshcheck::Options {
            welded: true,
            ..Default::default()
        },
    )
}

/// A wavy `n` x `n` grid cut along its vertices where `seam(column, row)`: each triangle on a
/// cut vertex takes the copy of that vertex for its side, `side(x)` of its centroid's column
/// `x` (in columns).
fn split_grid(n: u32, seam: impl Fn(u32, u32) -> bool, side: impl Fn(f32) -> u8) -> MeshData {
    let g = grid(n, n, 0.25);
    let mut m = MeshData {
        positions: g.positions.clone(),
        triangles: Vec::new(),
    };
    let mut copy = HashMap::new();
    for t in &g.triangles {
        let x = t.iter().map(|&v| (v % (n + 1)) as f32).sum::<f32>() / 3.0;
        let s = side(x);
        m.triangles.push(t.map(|v| {
            if !seam(v % (n + 1), v / (n + 1)) || s == 0 {
                return v;
            }
            *copy.entry((s, v)).or_insert_with(|| {
                m.positions.push(g.positions[v as usize]);
                m.positions.len() as u32 - 1
            })
        }));
    }
    m
}

/// Each vertex's chart: the vertices connected through the triangles (wedges are split on
/// every seam, so a chart is a connected piece of the split mesh).
fn charts(m: &MeshData) -> Vec<u32> {
    let mut parent: Vec<u32> = (0..m.positions.len() as u32).collect();
    fn root(p: &mut [u32], mut x: u32) -> u32 {
        while p[x as usize] != x {
            p[x as usize] = p[p[x as usize] as usize];
            x = p[x as usize];
        }
        x
    }
    for t in &m.triangles {
        for k in 1..3 {
            let (a, b) = (root(&mut parent, t[0]), root(&mut parent, t[k]));
            parent[a.max(b) as usize] = a.min(b);
        }
    }
    (0..m.positions.len() as u32)
        .map(|v| root(&mut parent, v))
        .collect()
}

/// A wavy `n` x `n` grid in four charts, its quarters, with the middle position in all four.
fn four_charts(n: u32) -> MeshData {
    let g = grid(n, n, 0.25);
    let mut m = MeshData::default();
    let mut copy = HashMap::new();
    for t in &g.triangles {
        let (i, j) = (
            t.iter().map(|&v| (v % (n + 1)) as f32).sum::<f32>() / 3.0,
            t.iter().map(|&v| (v / (n + 1)) as f32).sum::<f32>() / 3.0,
        );
        let half = n as f32 / 2.0;
        let ch = u8::from(i >= half) + 2 * u8::from(j >= half);
        m.triangles.push(t.map(|v| {
            *copy.entry((ch, v)).or_insert_with(|| {
                m.positions.push(g.positions[v as usize]);
                m.positions.len() as u32 - 1
            })
        }));
    }
    m
}

#[test]
fn welded_seams_stay_closed_and_charts_whole() {
    let n = 24;
    let half = n as f32 / 2.0;
    // Two charts along column n/2; four charts meeting in the middle; a chart one column wide
    // between two, moved to a tenth of a column (seam vertices of both seams are then
    // neighbours across short spokes where no wedge changes); a seam from the border to the
    // middle (one chart, cut).
    let mut strip = split_grid(
        n,
        |i, _| i == n / 2 || i == n / 2 + 1,
        |x| u8::from(x > half) + u8::from(x > half + 1.0),
    );
    let (from, to) = ((n / 2 + 1) as f32 / n as f32, (half + 0.1) / n as f32);
    for p in &mut strip.positions {
        if p[0] == from {
            p[0] = to;
        }
    }
    let meshes = [
        (
            "two charts",
            split_grid(n, |i, _| i == n / 2, |x| u8::from(x > half)),
        ),
        ("four charts", four_charts(16)),
        ("a strip", strip),
        (
            "a slit",
            split_grid(n, |i, j| i == n / 2 && j < n / 2, |x| u8::from(x > half)),
        ),
    ];
    let mut seam_refusals = 0;
    for (name, m) in &meshes {
        let g = quantised(m);
        let chart = charts(m);
        for mode in modes() {
            for ratio in [0.5, 0.25, 0.1] {
                let what = format!("{mode:?} {name} {ratio}");
                let (out, r) = run_wedges(mode, &g, &Config::new().with_ratio(ratio));
                assert_eq!(r.stop, Stop::Target, "{what}: {r:?}");
                seam_refusals += r.rejected.get(Reject::Seam);
                let v = welded_verdict(&g.mesh, &out);
                v.assert_valid(&what);
                assert_eq!(v.lost_wedges, 0, "{what}: wedges of kept positions lost");
                for t in &out.triangles {
                    let sides: BTreeSet<u32> = t.iter().map(|&x| chart[x as usize]).collect();
                    assert_eq!(sides.len(), 1, "{what}: triangle {t:?} takes two charts");
                }
            }
        }
    }
    assert!(seam_refusals > 0, "the seam rule never refused");
}

// ---- errors ------------------------------------------------------------------------------

/// The first vertex of `tris` in corner order that `off` holds.
fn first_in_corner_order(tris: &[Tri], off: &[u32]) -> usize {
    tris.iter()
        .flatten()
        .find(|v| off.contains(v))
        .map(|&v| v as usize)
        .expect("a used vertex")
}

/// Runs `mode` on a fresh small workspace (`u16` links; 200 vertices, 400 triangles).
fn run_small(
    mode: Mode,
    grid: &[[u16; 3]],
    tris: &mut [Tri],
    config: &Config,
) -> Result<Report, Error> {
    match mode {
        Mode::Fast => Box::new(FastWorkspace::<u16, 200, 400, Integer>::new())
            .as_mut()
            .simplify(grid, tris, config),
        Mode::Lean => Box::new(LeanWorkspace::<u16, 200, 400, Integer>::new())
            .as_mut()
            .simplify(grid, tris, config),
    }
}

#[test]
fn a_used_vertex_off_the_grid_is_a_typed_error_naming_the_first_in_corner_order() {
    let g = quantised(&icosphere(2));
    let tris = &g.mesh.triangles;
    let config = Config::new().with_ratio(0.25);
    for mode in modes() {
        // One vertex, each axis, at the grid's bound and above.
        for (v, k, x) in [(7u32, 0usize, GRID), (100, 1, GRID + 1), (161, 2, u16::MAX)] {
            let mut grid = g.grid.clone();
            grid[v as usize][k] = x;
            let mut t = tris.clone();
            assert_eq!(
                run_small(mode, &grid, &mut t, &config),
                Err(Error::OffGrid { vertex: v as usize }),
                "{mode:?} vertex {v} axis {k} at {x}"
            );
            assert_eq!(&t, tris, "{mode:?}: triangles touched");
        }
        // Several: the first in corner order, whatever their numbers.
        let off = [150u32, 3, 90];
        let mut grid = g.grid.clone();
        for &v in &off {
            grid[v as usize][1] = GRID;
        }
        let first = first_in_corner_order(tris, &off);
        assert_ne!(first, 3, "the lowest number is not the first corner");
        let mut t = tris.clone();
        assert_eq!(
            run_small(mode, &grid, &mut t, &config),
            Err(Error::OffGrid { vertex: first }),
            "{mode:?}"
        );
        assert_eq!(&t, tris, "{mode:?}: triangles touched");
        // Reordered triangles name another vertex.
        let mut reordered = tris.clone();
        reordered.reverse();
        let first = first_in_corner_order(&reordered, &off);
        let mut t = reordered.clone();
        assert_eq!(
            run_small(mode, &grid, &mut t, &config),
            Err(Error::OffGrid { vertex: first }),
            "{mode:?} reversed"
        );
        assert_eq!(t, reordered, "{mode:?}: triangles touched");
    }
}

#[test]
fn an_unused_vertex_off_the_grid_is_accepted() {
    let mut g = quantised(&icosphere(2));
    // Two vertices no triangle uses, every coordinate off the grid.
    for x in [GRID, u16::MAX] {
        g.grid.push([x; 3]);
        g.mesh.positions.push([f32::from(x); 3]);
    }
    for mode in modes() {
        let mut t = g.mesh.triangles.clone();
        let r = run_small(mode, &g.grid, &mut t, &Config::new().with_ratio(0.25))
            .unwrap_or_else(|e| panic!("{mode:?}: {e:?}"));
        let (out, r) = output(&g.mesh.positions, t, r);
        assert_eq!(r.stop, Stop::Target, "{mode:?}");
        assert_run_valid(&format!("{mode:?}"), &g, &out, &r);
    }
}

#[test]
fn bad_input_is_a_typed_error_and_the_buffer_is_untouched() {
    let g = quantised(&icosphere(2));
    let tris = &g.mesh.triangles;
    let config = Config::new();
    for mode in modes() {
        // Out-of-range index.
        let mut bad = tris.clone();
        bad[100][2] = 5000;
        let before = bad.clone();
        assert_eq!(
            run_small(mode, &g.grid, &mut bad, &config),
            Err(Error::IndexOutOfRange {
                triangle: 100,
                index: 5000
            }),
            "{mode:?}"
        );
        assert_eq!(bad, before, "{mode:?}");
        // An index out of range before a vertex off the grid in corner order, and after it.
        let mut grid = g.grid.clone();
        let v = tris[50][0];
        grid[v as usize][0] = GRID;
        let mut t = tris.clone();
        t[10][1] = 5000;
        assert_eq!(
            run_small(mode, &grid, &mut t, &config),
            Err(Error::IndexOutOfRange {
                triangle: 10,
                index: 5000
            }),
            "{mode:?}"
        );
        let mut t = tris.clone();
        t[300][1] = 5000;
        let first = first_in_corner_order(tris, &[v]);
        assert_eq!(
            run_small(mode, &grid, &mut t, &config),
            Err(Error::OffGrid { vertex: first }),
            "{mode:?}"
        );

        // Over capacity: vertices (162 > 100), then triangles (320 > 300).
        let mut t = tris.clone();
        let r = match mode {
            Mode::Fast => Box::new(FastWorkspace::<u16, 100, 400, Integer>::new())
                .as_mut()
                .simplify(&g.grid, &mut t, &config),
            Mode::Lean => Box::new(LeanWorkspace::<u16, 100, 400, Integer>::new())
                .as_mut()
                .simplify(&g.grid, &mut t, &config),
        };
        assert_eq!(
            r,
            Err(Error::Capacity {
                what: Capacity::Vertices,
                needed: 162,
                available: 100
            }),
            "{mode:?}"
        );
        let r = match mode {
            Mode::Fast => Box::new(FastWorkspace::<u16, 200, 300, Integer>::new())
                .as_mut()
                .simplify(&g.grid, &mut t, &config),
            Mode::Lean => Box::new(LeanWorkspace::<u16, 200, 300, Integer>::new())
                .as_mut()
                .simplify(&g.grid, &mut t, &config),
        };
        assert_eq!(
            r,
            Err(Error::Capacity {
                what: Capacity::Triangles,
                needed: 320,
                available: 300
            }),
            "{mode:?}"
        );
        assert_eq!(&t, tris, "{mode:?}");

        // A configuration out of range.
        assert!(
            matches!(
                run_small(mode, &g.grid, &mut t, &Config::new().with_ratio(1.5)),
                Err(Error::InvalidConfig { .. })
            ),
            "{mode:?}"
        );
        assert_eq!(&t, tris, "{mode:?}");
    }
}

#[test]
fn bad_input_with_wedges_is_a_typed_error_and_both_buffers_are_untouched() {
    let m = split_grid(4, |i, _| i == 2, |x| u8::from(x > 2.0));
    let g = quantised(&m);
    let (tris, wedges) = welded(&g);
    let config = Config::new().with_ratio(0.5);
    let nv = g.grid.len() as u32;
    let mut far = wedges.clone();
    far[3][1] = nv;
    // A used vertex off the grid, refused as without wedges.
    let mut off = g.grid.clone();
    let used = tris[0][0];
    off[used as usize][2] = GRID;
    type Case<'a> = (&'a [[u16; 3]], Vec<Tri>, Error);
    let cases: [Case; 3] = [
        (
            &g.grid,
            wedges[..wedges.len() - 1].to_vec(),
            Error::Capacity {
                what: Capacity::Triangles,
                needed: tris.len(),
                available: tris.len() - 1,
            },
        ),
        (
            &g.grid,
            far,
            Error::IndexOutOfRange {
                triangle: 3,
                index: nv as usize,
            },
        ),
        (
            &off,
            wedges.clone(),
            Error::OffGrid {
                vertex: used as usize,
            },
        ),
    ];
    for (grid, w, expected) in cases {
        for mode in modes() {
            let (mut t, mut w) = (tris.clone(), w.clone());
            let before = w.clone();
            let r = match mode {
                Mode::Fast => Box::new(FastWorkspace::<u16, 200, 400, Integer>::new())
                    .as_mut()
                    .simplify_with_wedges(grid, &mut t, &mut w, &config),
                Mode::Lean => Box::new(LeanWorkspace::<u16, 200, 400, Integer>::new())
                    .as_mut()
                    .simplify_with_wedges(grid, &mut t, &mut w, &config),
            };
            assert_eq!(r, Err(expected), "{mode:?}");
            assert_eq!(t, tris, "{mode:?}: triangles touched");
            assert_eq!(w, before, "{mode:?}: wedges touched");
        }
    }
}

// ---- each collapse --------------------------------------------------------------------

/// What one collapse did, from the triangles before and after it: the vertex that went, the
/// vertex it moved onto, and its surviving triangles before and after.
struct Collapse {
    a: u32,
    b: u32,
    survivors: Vec<(Tri, Tri)>,
}

/// The collapse that turned `before` into `after` (one vertex gone, its triangles not on the
/// collapsed edge rewritten to the vertex it moved onto).
fn the_collapse(before: &[Tri], after: &[Tri]) -> Collapse {
    let used = |t: &[Tri]| t.iter().flatten().copied().collect::<BTreeSet<u32>>();
    let gone: Vec<u32> = used(before).difference(&used(after)).copied().collect();
    assert_eq!(gone.len(), 1, "one collapse, one vertex gone: {gone:?}");
    let a = gone[0];
    let fan: Vec<Tri> = before.iter().copied().filter(|t| t.contains(&a)).collect();
    let after: BTreeSet<Tri> = after.iter().copied().collect();
    let moved = |t: Tri, b: u32| t.map(|v| if v == a { b } else { v });
    let b = fan
        .iter()
        .flatten()
        .copied()
        .filter(|&b| b != a)
        .find(|&b| {
            fan.iter()
                .filter(|t| !t.contains(&b))
                .all(|&t| after.contains(&moved(t, b)))
        })
        .expect("a's triangles rewritten to one neighbour");
    let survivors = fan
        .iter()
        .filter(|t| !t.contains(&b))
        .map(|&t| (t, moved(t, b)))
        .collect();
    Collapse { a, b, survivors }
}

/// The cosine of the angle between two grid triangles' normals.
fn turn(grid: &[[u16; 3]], t: Tri, u: Tri) -> f64 {
    let n = |t: Tri| {
        let p = t.map(|v| grid[v as usize].map(f64::from));
        let (e, f) = (
            [0, 1, 2].map(|k| p[1][k] - p[0][k]),
            [0, 1, 2].map(|k| p[2][k] - p[0][k]),
        );
        [
            e[1] * f[2] - e[2] * f[1],
            e[2] * f[0] - e[0] * f[2],
            e[0] * f[1] - e[1] * f[0],
        ]
    };
    let (a, b) = (n(t), n(u));
    dot(a, b) / (dot(a, a) * dot(b, b)).sqrt()
}

/// The flip test refuses a collapse that turns a surviving triangle's normal by 75.5° or more
/// (cosine at most 1/4; the integer test compares shifted normals, so a hair of margin).
const FLIP_COS: f64 = 0.24;

/// `g` simplified one collapse a run (each run's target one triangle under its input) until
/// no collapse is left, `mode` on the shared workspace: each collapse seen on its own. Small
/// closed meshes, simplified to the end, where the cheapest collapses left are the ones that
/// turn triangles the most: no collapse turns a surviving triangle by 75.5° or more (the
/// flip test), makes a sliver (the zero-area test), or leaves an invalid mesh.
#[test]
fn no_collapse_turns_a_triangle_by_75_degrees_or_more() {
    let mut octa = MeshData::default();
    octahedron(&mut octa, [0.0; 3], 1.0);
    let meshes = [
        ("octahedron", quantised(&octa)),
        ("icosahedron", quantised(&icosphere(0))),
        ("sphere", quantised(&jitter(icosphere(2), 3, 0.05))),
        ("box", quantised(&cube(3))),
        ("plank", cuboid([GRID - 1, 8000, 300], [6, 3, 1])),
    ];
    for (name, g) in &meshes {
        for mode in modes() {
            let mut tris = g.mesh.triangles.clone();
            let mut steps = 0;
            loop {
                let config = Config::new().with_target(Target::Triangles(tris.len() - 1));
                let mut after = tris.clone();
                let r = simplify_on(mode, &g.grid, &mut after, &config);
                after.truncate(r.triangles_out);
                let what = format!("{mode:?} {name}, collapse {steps}");
                if r.collapses == 0 {
                    assert_eq!(r.stop, Stop::NoLegalCollapse, "{what}: {r:?}");
                    break;
                }
                assert_eq!(r.collapses, 1, "{what}: {r:?}");
                let c = the_collapse(&tris, &after);
                for &(t, u) in &c.survivors {
                    let cos = turn(&g.grid, t, u);
                    assert!(
                        cos > FLIP_COS,
                        "{what}: {} onto {} turns {t:?} to {u:?} by {:.1}°",
                        c.a,
                        c.b,
                        cos.clamp(-1.0, 1.0).acos().to_degrees()
                    );
                }
                let before = OnGrid {
                    grid: g.grid.clone(),
                    mesh: MeshData {
                        positions: g.mesh.positions.clone(),
                        triangles: tris,
                    },
                };
                let (out, r) = output(&g.mesh.positions, after.clone(), r);
                assert_run_valid(&what, &before, &out, &r);
                tris = after;
                steps += 1;
            }
            assert!(steps > 0, "{mode:?} {name}: nothing collapsed");
        }
    }
}

/// A tetrahedron with one face turned over: that face's three vertices are inconsistently
/// wound (locked) and the fourth, a low apex over the turned face, may move; each of its
/// collapses would copy the turned face with its own winding, a duplicate that the fold rule
/// cannot see (the two copies face the same way) and the flip test lets through (a small
/// turn). The duplicate rule keeps the mesh as it is.
#[test]
fn a_turned_face_is_never_copied() {
    let (o1, o2, b, a) = (0u32, 1, 2, 3);
    let g = raw_grid(
        vec![
            [1000, 1000, 1000],
            [21_000, 1000, 1000],
            [11_000, 21_000, 1000],
            [11_000, 11_000, 3000],
        ],
        // The consistent tetrahedron's fourth face is (b, o2, o1).
        vec![[a, o1, o2], [a, o2, b], [a, b, o1], [b, o1, o2]],
    );
    for mode in modes() {
        for ratio in [0.5f32, 0.0] {
            let (out, r) = run(mode, &g, ratio);
            let what = format!("{mode:?} {ratio}");
            assert_run_valid(&what, &g, &out, &r);
            assert_eq!(out.triangles, g.mesh.triangles, "{what}: {r:?}");
            assert!(r.rejected.get(Reject::Duplicate) > 0, "{what}: {r:?}");
        }
    }
}

// ---- the grid's extremes -----------------------------------------------------------------

/// `m`'s positions scaled to fill the grid on every axis: each coordinate's range mapped onto
/// 0 ..= 32767 (a flat axis stays at 0).
fn stretched(m: &MeshData) -> OnGrid {
    let top = f64::from(GRID - 1);
    let (mut lo, mut hi) = ([f64::MAX; 3], [f64::MIN; 3]);
    for p in &m.positions {
        for k in 0..3 {
            lo[k] = lo[k].min(f64::from(p[k]));
            hi[k] = hi[k].max(f64::from(p[k]));
        }
    }
    let grid = m
        .positions
        .iter()
        .map(|p| {
            [0, 1, 2].map(|k| {
                let span = hi[k] - lo[k];
                if span > 0.0 {
                    ((f64::from(p[k]) - lo[k]) / span * top).round() as u16
                } else {
                    0
                }
            })
        })
        .collect();
    raw_grid(grid, m.triangles.clone())
}

/// A closed box from the origin to `size` (grid cells), `n[k]` segments along axis `k`, each
/// face a grid of quads: a beam when two sizes are small, a plank when one is.
fn cuboid(size: [u16; 3], n: [u32; 3]) -> OnGrid {
    let mut grid = Vec::new();
    let mut index = HashMap::new();
    let mut triangles = Vec::new();
    let at =
        |k: usize, i: u32| (f64::from(size[k]) * f64::from(i) / f64::from(n[k])).round() as u16;
    // Each face: its fixed axis and side, and its two axes in the order that winds it outwards.
    for (fixed, side) in [(0usize, 0u32), (0, 1), (1, 0), (1, 1), (2, 0), (2, 1)] {
        let (u, v) = match (fixed, side) {
            (0, 0) => (2, 1),
            (0, _) => (1, 2),
            (1, 0) => (0, 2),
            (1, _) => (2, 0),
            (_, 0) => (1, 0),
            _ => (0, 1),
        };
        let mut vertex = |i: u32, j: u32| {
            let mut q = [0u16; 3];
            q[fixed] = if side == 0 { 0 } else { size[fixed] };
            q[u] = at(u, i);
            q[v] = at(v, j);
            *index.entry(q).or_insert_with(|| {
                grid.push(q);
                grid.len() as u32 - 1
            })
        };
        for j in 0..n[v] {
            for i in 0..n[u] {
                let (a, b, c, d) = (
                    vertex(i, j),
                    vertex(i + 1, j),
                    vertex(i + 1, j + 1),
                    vertex(i, j + 1),
                );
                triangles.push([a, b, c]);
                triangles.push([a, c, d]);
            }
        }
    }
    raw_grid(grid, triangles)
}

#[test]
fn meshes_spanning_the_whole_grid_simplify_validly() {
    let top = GRID - 1;
    let meshes = [
        // The largest box: every face as large as the grid.
        ("the grid's box", cuboid([top; 3], [8; 3])),
        // Slivers: a beam the grid long and two cells across, and one a cell across.
        ("a long beam", cuboid([top, 2, 2], [16, 1, 1])),
        ("a thin beam", cuboid([top, 1, 1], [16, 1, 1])),
        // A plank: the grid long and wide, one cell thick.
        ("a plank", cuboid([top, top, 1], [8, 8, 1])),
        // Curved surfaces filling the grid: the largest cross products and areas.
        ("a sphere", stretched(&icosphere(3))),
        ("a wavy sheet", stretched(&grid(20, 20, 0.3))),
        ("fin and pinch", stretched(&fin_and_pinch(10))),
    ];
    for (what, g) in &meshes {
        let used: BTreeSet<u32> = g.mesh.triangles.iter().flatten().copied().collect();
        for k in 0..3 {
            let xs: BTreeSet<u16> = used.iter().map(|&v| g.grid[v as usize][k]).collect();
            assert!(xs.contains(&0), "{what}: axis {k} does not reach 0");
        }
        assert!(
            used.iter()
                .any(|&v| g.grid[v as usize].contains(&(GRID - 1))),
            "{what}: no coordinate at the grid's top"
        );
        for mode in modes() {
            for ratio in [0.5f32, 0.1, 0.0] {
                let (out, r) = run(mode, g, ratio);
                assert_run_valid(&format!("{mode:?} {what} {ratio}"), g, &out, &r);
                assert!(r.collapses > 0, "{mode:?} {what} {ratio}: {r:?}");
            }
        }
    }
}

// ---- the error limit ---------------------------------------------------------------------

/// A flat 16 x 16 grid with its middle vertex raised by `height` grid cells, on the grid
/// (512 cells a column); the apex's index.
fn spike(height: u16) -> (OnGrid, u32) {
    let mut grid = Vec::new();
    for j in 0..=16u16 {
        for i in 0..=16u16 {
            grid.push([i * 512, j * 512, 0]);
        }
    }
    let apex = 8 * 17 + 8;
    grid[apex][2] = height;
    (
        raw_grid(grid, common::grid(16, 16, 0.0).triangles),
        apex as u32,
    )
}

#[test]
fn the_error_limit_in_grid_cells_holds_and_keeps_the_spike() {
    let (g, apex) = spike(2000);
    let config = Config::new().with_target(Target::Triangles(8));
    let uses = |m: &MeshData| m.triangles.iter().any(|t| t.contains(&apex));
    for mode in modes() {
        // Without a limit the target is reached, with collapses far over the limit below (a
        // limit too high to refuse anything tracks the largest).
        let (_, r) = run_with(mode, &g, &config);
        assert_eq!(r.stop, Stop::Target, "{mode:?}: {r:?}");
        assert_eq!(r.collapse_error, 0.0, "{mode:?}: tracked only with a limit");
        let (_, r) = run_with(mode, &g, &config.with_error_limit(1e6));
        assert_eq!(r.over_limit, 0, "{mode:?}");
        let limit = 40.0;
        assert!(r.collapse_error > 2.0 * limit, "{mode:?}: {r:?}");

        let (out, r) = run_with(mode, &g, &config.with_error_limit(limit));
        assert_eq!(r.stop, Stop::ErrorLimit, "{mode:?}: {r:?}");
        assert!(!r.target_reached, "{mode:?}");
        assert!(r.over_limit > 0, "{mode:?}");
        assert!(
            r.collapse_error <= limit,
            "{mode:?}: largest collapse error {} over the limit {limit}",
            r.collapse_error
        );
        assert!(uses(&out), "{mode:?}: the spike was cut");
        // The flat part costs nothing and was not held back.
        assert!(
            out.triangles.len() * 4 < g.mesh.triangles.len(),
            "{mode:?}: {} of {} triangles left",
            out.triangles.len(),
            g.mesh.triangles.len()
        );
        assert_run_valid(&format!("{mode:?} spike"), &g, &out, &r);
    }
}

/// `Report::collapse_error` is, with any finite limit, the largest error of a collapse made:
/// a limit above every distance on the grid (whose diagonal is under 56 756 cells) refuses
/// nothing, gives the same triangles and reports the same largest error, however high it is.
#[test]
fn a_limit_above_every_grid_distance_still_reports_the_largest_error() {
    let (g, _) = spike(2000);
    let config = Config::new().with_target(Target::Triangles(8));
    for mode in modes() {
        let (_, unlimited) = run_with(mode, &g, &config);
        let (out, tracked) = run_with(mode, &g, &config.with_error_limit(1e5));
        assert!(tracked.collapse_error > 0.0, "{mode:?}: {tracked:?}");
        assert_eq!(out.triangles.len(), unlimited.triangles_out, "{mode:?}");
        for limit in [1e6f32, 1e9, f32::MAX] {
            let (o, r) = run_with(mode, &g, &config.with_error_limit(limit));
            assert_eq!(r.over_limit, 0, "{mode:?} {limit:e}");
            assert_same(&o.triangles, &out.triangles, &format!("{mode:?} {limit:e}"));
            assert_eq!(
                r.collapse_error, tracked.collapse_error,
                "{mode:?}: limit {limit:e}: {r:?}"
            );
        }
    }
}

#[test]
fn a_tiny_error_limit_stops_the_run() {
    let g = quantised(&icosphere(4));
    for mode in modes() {
        for limit in [0.25f32, 2.0] {
            let config = Config::new().with_ratio(0.1).with_error_limit(limit);
            let (out, r) = run_with(mode, &g, &config);
            let what = format!("{mode:?} limit {limit}");
            assert_eq!(r.stop, Stop::ErrorLimit, "{what}: {r:?}");
            assert!(!r.target_reached && r.over_limit > 0, "{what}: {r:?}");
            assert!(r.collapse_error <= limit, "{what}: {r:?}");
            assert_run_valid(&what, &g, &out, &r);
        }
    }
}

// ---- quality -----------------------------------------------------------------------------

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// The squared distance from `p` to triangle `abc` (Ericson, Real-Time Collision Detection
/// §5.1.5: the closest point by Voronoi region).
fn point_triangle2(p: [f64; 3], [a, b, c]: [[f64; 3]; 3]) -> f64 {
    let (ab, ac, ap) = (sub(b, a), sub(c, a), sub(p, a));
    let at = |s: f64, t: f64| {
        let q = [0, 1, 2].map(|k| a[k] + s * ab[k] + t * ac[k]);
        dot(sub(p, q), sub(p, q))
    };
    let (d1, d2) = (dot(ab, ap), dot(ac, ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return dot(ap, ap);
    }
    let bp = sub(p, b);
    let (d3, d4) = (dot(ab, bp), dot(ac, bp));
    if d3 >= 0.0 && d4 <= d3 {
        return dot(bp, bp);
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return at(d1 / (d1 - d3), 0.0);
    }
    let cp = sub(p, c);
    let (d5, d6) = (dot(ab, cp), dot(ac, cp));
    if d6 >= 0.0 && d5 <= d6 {
        return dot(cp, cp);
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return at(0.0, d2 / (d2 - d6));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return at(1.0 - w, w);
    }
    let denom = 1.0 / (va + vb + vc);
    at(vb * denom, vc * denom)
}

/// The mean squared distance from the input's vertices to the output's surface.
fn mean_squared_distance(input: &MeshData, output: &MeshData) -> f64 {
    let p = |v: u32| input.positions[v as usize].map(f64::from);
    let tris: Vec<[[f64; 3]; 3]> = output.triangles.iter().map(|t| t.map(p)).collect();
    let used: BTreeSet<u32> = input.triangles.iter().flatten().copied().collect();
    let total: f64 = used
        .iter()
        .map(|&v| {
            tris.iter()
                .map(|&t| point_triangle2(p(v), t))
                .fold(f64::INFINITY, f64::min)
        })
        .sum();
    total / used.len() as f64
}

#[test]
fn on_smooth_meshes_the_error_is_close_to_the_float_pipelines() {
    for (name, m) in [("icosphere", icosphere(4)), ("spot", load_obj("spot.obj"))] {
        let g = quantised(&m);
        for mode in modes() {
            let mut float_errors = Vec::new();
            for ratio in [0.5f32, 0.25, 0.1] {
                let (int, ri) = run(mode, &g, ratio);
                let (float, rf) = run_float(mode, &g, ratio);
                let (ei, ef) = (
                    mean_squared_distance(&g.mesh, &int),
                    mean_squared_distance(&g.mesh, &float),
                );
                eprintln!("{mode:?} {name} {ratio}: integer {ei:.3e}, float {ef:.3e}");
                assert!(ri.target_reached && rf.target_reached, "{mode:?} {name}");
                assert!(ef > 0.0, "{mode:?} {name} {ratio}: no error to compare");
                assert!(
                    ei <= 1.5 * ef,
                    "{mode:?} {name} {ratio}: integer {ei:e} over 1.5 x float {ef:e}"
                );
                float_errors.push(ef);
            }
            // The bound tells levels apart: each level's float error is more than 1.5 times
            // the one before, so a result a level worse would fail it.
            for w in float_errors.windows(2) {
                assert!(w[1] > 1.5 * w[0], "{mode:?} {name}: {float_errors:?}");
            }
        }
    }
}
