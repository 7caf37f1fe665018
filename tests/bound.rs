//! The guaranteed error bound (Zhu, Wang and Meng 2007, §2-§4), checked
//! from outside the library.
//!
//! For every mesh and bound: every original triangle's centroid (control points of the first
//! kind) and every vertex of an original feature edge (second kind) must lie within the bound
//! of the *output surface*. The distances are recomputed here in f64 with a point-triangle
//! distance of our own, against every output triangle whose bounding box (grown by the bound)
//! holds the point (a uniform grid: exact, no triangle that could be near is skipped).
//!
//! Tolerance: the library measures in f32 on positions mapped into `[-½, ½]³`, so its
//! distances carry a rounding error of a few f32 ulps of the bounding box; the check allows
//! `1e-5 ×` the bounding-box diagonal on top of the bound (0.2 % of the smallest bound
//! tested, 0.1 % of the diagonal).
//!
//! Feature edges are recomputed here too (boundary, non-manifold, or normals more than
//! `control_angle_deg` apart); edges within 0.5° of the threshold are left out, since f32 and
//! f64 may classify them differently.
//!
//! Building with `TINYDECIMATE_RULE_OFF=bound` switches the veto off: these tests then fail.

mod common;

use common::{cube, fin_and_pinch, grid, icosphere, jitter, MeshData, Tri};
use std::collections::HashMap;
use tinydecimate::bound::control_len;
use tinydecimate::operator::Operator;
use tinydecimate::{
    Builtin, Capacity, Config, ConfigField, Controls, Error, Placement, Positions, Reject, Report,
    StoredQuadric,
};
use tinydecimate::{EdgeCollapse, NoBound, TriangleCollapse};

type P = [f64; 3];

fn fixture(name: &str) -> MeshData {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests")
        .join("fixtures")
        .join(name);
    common::parse_obj(&std::fs::read_to_string(path).expect("fixture"))
}

/// Runs the library with control points (u32 links, the big shared workspace).
fn bounded(m: &MeshData, config: &Config) -> (MeshData, Report) {
    bounded_with(m, config, EdgeCollapse)
}

/// [`bounded`] with `operator`.
fn bounded_with<O: Operator>(m: &MeshData, config: &Config, operator: O) -> (MeshData, Report) {
    let mut tris = m.triangles.clone();
    let mut links = vec![0u32; control_len(tris.len(), m.positions.len())];
    let mut ws = common::BIG.lock().unwrap_or_else(|e| e.into_inner());
    let bound = Controls::new(&m.triangles, &mut links);
    let p = Positions::Read(&m.positions);
    let r = ws
        .start(p, &mut tris, config, Builtin::new(), bound, operator)
        .expect("start")
        .run();
    tris.truncate(r.triangles_out);
    (
        MeshData {
            positions: m.positions.clone(),
            triangles: tris,
        },
        r,
    )
}

fn p64(p: [f32; 3]) -> P {
    [p[0] as f64, p[1] as f64, p[2] as f64]
}
fn sub(a: P, b: P) -> P {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn dot(a: P, b: P) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn cross(a: P, b: P) -> P {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn segment_distance(p: P, a: P, b: P) -> f64 {
    let ab = sub(b, a);
    let l2 = dot(ab, ab);
    let t = if l2 > 0.0 {
        (dot(sub(p, a), ab) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let q = [a[0] + t * ab[0], a[1] + t * ab[1], a[2] + t * ab[2]];
    dot(sub(p, q), sub(p, q)).sqrt()
}

/// Distance from `p` to triangle `t`: the plane distance if the projection falls inside (by
/// the signs of the three edge cross products), else the nearest edge.
fn point_triangle(p: P, t: [P; 3]) -> f64 {
    let n = cross(sub(t[1], t[0]), sub(t[2], t[0]));
    let n2 = dot(n, n);
    if n2 > 0.0 {
        let inside = (0..3).all(|i| {
            let (a, b) = (t[i], t[(i + 1) % 3]);
            dot(cross(sub(b, a), sub(p, a)), n) >= 0.0
        });
        if inside {
            return dot(sub(p, t[0]), n).abs() / n2.sqrt();
        }
    }
    (0..3)
        .map(|i| segment_distance(p, t[i], t[(i + 1) % 3]))
        .fold(f64::INFINITY, f64::min)
}

fn diagonal(m: &MeshData) -> f64 {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for t in &m.triangles {
        for &v in t {
            let p = p64(m.positions[v as usize]);
            for a in 0..3 {
                lo[a] = lo[a].min(p[a]);
                hi[a] = hi[a].max(p[a]);
            }
        }
    }
    dot(sub(hi, lo), sub(hi, lo)).sqrt()
}

/// The control points, recomputed: each non-degenerate original triangle's centroid, and the
/// vertices of its feature edges.
fn control_points(m: &MeshData, angle_deg: f64) -> Vec<P> {
    let pos = |v: u32| p64(m.positions[v as usize]);
    let live: Vec<Tri> = m
        .triangles
        .iter()
        .copied()
        .filter(|t| t[0] != t[1] && t[1] != t[2] && t[0] != t[2])
        .collect();
    let mut out: Vec<P> = live
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(pos);
            [0, 1, 2].map(|i| (a[i] + b[i] + c[i]) / 3.0)
        })
        .collect();
    let mut edges: HashMap<(u32, u32), Vec<usize>> = HashMap::new();
    for (i, t) in live.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            edges.entry((a.min(b), a.max(b))).or_default().push(i);
        }
    }
    let normal = |t: &Tri| {
        let [a, b, c] = t.map(pos);
        cross(sub(b, a), sub(c, a))
    };
    let mut feature = vec![false; m.positions.len()];
    for (&(a, b), ts) in &edges {
        let sharp = if ts.len() != 2 {
            true
        } else {
            let (n1, n2) = (normal(&live[ts[0]]), normal(&live[ts[1]]));
            let l = (dot(n1, n1) * dot(n2, n2)).sqrt();
            if l > 0.0 {
                let angle = (dot(n1, n2) / l).clamp(-1.0, 1.0).acos().to_degrees();
                angle > angle_deg + 0.5
            } else {
                false
            }
        };
        if sharp {
            feature[a as usize] = true;
            feature[b as usize] = true;
        }
    }
    out.extend(
        feature
            .iter()
            .enumerate()
            .filter(|x| *x.1)
            .map(|(v, _)| pos(v as u32)),
    );
    out
}

/// The largest distance from a control point of `input` to the surface of `output`, found
/// with a uniform grid over the output triangles' boxes grown by `reach`; points farther than
/// `reach` from every triangle count as `f64::INFINITY`.
fn max_distance(input: &MeshData, output: &MeshData, angle_deg: f64, reach: f64) -> f64 {
    let tris: Vec<[P; 3]> = output
        .triangles
        .iter()
        .map(|t| t.map(|v| p64(output.positions[v as usize])))
        .collect();
    let diag = diagonal(input);
    let cell = (diag / 64.0).max(reach).max(1e-30);
    let key = |p: P| p.map(|x| (x / cell).floor() as i64);
    let mut grid: HashMap<[i64; 3], Vec<usize>> = HashMap::new();
    for (i, t) in tris.iter().enumerate() {
        let lo =
            key([0, 1, 2].map(|a| t.iter().map(|p| p[a]).fold(f64::INFINITY, f64::min) - reach));
        let hi = key(
            [0, 1, 2].map(|a| t.iter().map(|p| p[a]).fold(f64::NEG_INFINITY, f64::max) + reach)
        );
        for x in lo[0]..=hi[0] {
            for y in lo[1]..=hi[1] {
                for z in lo[2]..=hi[2] {
                    grid.entry([x, y, z]).or_default().push(i);
                }
            }
        }
    }
    let mut worst = 0.0f64;
    for p in control_points(input, angle_deg) {
        let d = grid
            .get(&key(p))
            .map(|ts| {
                ts.iter()
                    .map(|&i| point_triangle(p, tris[i]))
                    .fold(f64::INFINITY, f64::min)
            })
            .unwrap_or(f64::INFINITY);
        let d = if d <= reach { d } else { f64::INFINITY };
        worst = worst.max(d);
    }
    worst
}

/// Simplifies `m` as far as it goes under each bound (a fraction of the diagonal) and checks
/// every control point against the output; returns the triangle counts.
fn check(name: &str, m: &MeshData, fractions: &[f32], base: Config) -> Vec<usize> {
    check_with(name, m, fractions, base, EdgeCollapse)
}

/// [`check`] with `operator`.
fn check_with<O: Operator>(
    name: &str,
    m: &MeshData,
    fractions: &[f32],
    base: Config,
    operator: O,
) -> Vec<usize> {
    let diag = diagonal(m);
    let mut counts = Vec::new();
    for &f in fractions {
        let config = base.with_relative_max_error(f, &m.positions);
        let bound = config.max_error() as f64;
        assert!(
            (bound - f as f64 * diag).abs() <= 1e-5 * diag,
            "{name}: diagonal"
        );
        let (out, r) = bounded_with(m, &config, operator);
        common::assert_valid(name, m, &out, &r);
        let tol = 1e-5 * diag;
        let worst = max_distance(
            m,
            &out,
            config.control_angle_deg() as f64,
            bound + 2.0 * tol,
        );
        let (emax, emean) = (r.max_error.expect("E_max"), r.mean_error.expect("E_mean"));
        eprintln!(
            "{name}: bound {f} of the diagonal = {bound:.6}: {} -> {} triangles, \
             independent max {worst:.6}, E_max {emax:.6}, E_mean {emean:.6}, {} bound rejections",
            r.triangles_in,
            r.triangles_out,
            r.rejected.get(Reject::Bound)
        );
        assert!(
            worst <= bound + tol,
            "{name}: a control point is {worst} from the result, bound {bound}"
        );
        assert!(emax as f64 <= bound + tol, "{name}: E_max {emax} > {bound}");
        assert!(emean <= emax, "{name}: E_mean {emean} > E_max {emax}");
        // The library's controlled triangle is one triangle of the surface: never nearer.
        assert!(worst <= emax as f64 + tol, "{name}: {worst} > E_max {emax}");
        counts.push(r.triangles_out);
    }
    counts
}

/// As far as the bound allows: no triangle target.
fn unlimited() -> Config {
    Config::new().with_ratio(0.0)
}

#[test]
fn generated_meshes_stay_within_the_bound() {
    let fractions = [0.001, 0.005, 0.02];
    let meshes = [
        ("icosphere4", icosphere(4)),
        ("wavy grid", grid(40, 30, 0.3)),
        ("cube", cube(12)),
        ("fin and pinch", fin_and_pinch(16)),
        ("jittered icosphere", jitter(icosphere(3), 7, 0.01)),
    ];
    for (name, m) in &meshes {
        let counts = check(name, m, &fractions, unlimited());
        // A looser bound never keeps more triangles on these.
        assert!(
            counts.windows(2).all(|w| w[1] <= w[0]),
            "{name}: {counts:?}"
        );
        // And the bound does bind (the cube's faces are flat: any bound gives 12 triangles).
        if *name != "cube" {
            assert!(counts[0] > counts[2], "{name}: {counts:?}");
        } else {
            assert_eq!(counts, [12, 12, 12]);
        }
    }
}

#[test]
fn fixtures_stay_within_the_bound() {
    for name in ["cow.obj", "plate_holes.obj"] {
        let m = fixture(name);
        check(name, &m, &[0.002, 0.005, 0.02], unlimited());
    }
}

#[test]
fn every_schedule_and_cost_honours_the_bound() {
    let m = fixture("cow.obj");
    for (what, config) in [
        ("paper passes", Config::paper().with_ratio(0.0)),
        (
            "normal variation greedy",
            unlimited().with_cost(tinydecimate::CostKind::NormalVariation),
        ),
        ("target 10 %", Config::new()),
    ] {
        check(what, &m, &[0.005], config);
    }
}

#[test]
fn shared_meshes_stay_within_the_bound() {
    // The ones that run in a few seconds in release; `tinydecimate simplify --max-error` and the
    // figures of docs/error-bound.md cover the others.
    for name in [
        "wuson.obj",
        "spot.obj",
        "fandisk.obj",
        "pr2_sensor_mount.obj",
    ] {
        let m = common::load_obj(name);
        check(name, &m, &[0.005], unlimited());
    }
}

#[test]
fn stepping_gives_the_one_shot_bytes() {
    let m = fixture("cow.obj");
    let config = unlimited().with_relative_max_error(0.005, &m.positions);
    let (one, r1) = bounded(&m, &config);
    let mut tris = m.triangles.clone();
    let mut links = vec![0u16; control_len(tris.len(), m.positions.len())];
    let mut ws = common::BIG.lock().unwrap_or_else(|e| e.into_inner());
    let bound = Controls::new(&m.triangles, &mut links);
    let p = Positions::Read(&m.positions);
    let mut s = ws
        .start(p, &mut tris, &config, Builtin::new(), bound, EdgeCollapse)
        .expect("start");
    while !s.step(7) {}
    let r2 = s.finish();
    tris.truncate(r2.triangles_out);
    assert_eq!(r1, r2);
    assert_eq!(one.triangles, tris);
}

#[test]
fn no_bound_changes_nothing() {
    // An infinite bound: the plain engine's bytes, with E_max and E_mean reported.
    let m = fixture("cow.obj");
    let config = Config::new().with_ratio(0.2);
    let (plain, rp) = common::simplify(&m, &config);
    let (with, rb) = bounded(&m, &config);
    assert_eq!(plain.triangles, with.triangles);
    assert_eq!(rp.max_error, None);
    assert!(rb.max_error.expect("E_max") > 0.0);
    assert_eq!(rb.rejected.get(Reject::Bound), 0);
}

#[test]
fn bad_input_is_refused() {
    let m = icosphere(1);
    let mut ws = common::BIG.lock().unwrap_or_else(|e| e.into_inner());
    let need = control_len(m.triangles.len(), m.positions.len());
    assert_eq!(need, 2 * 80 + 42);
    let config = Config::new().with_max_error(0.1);
    // A bound without control points: a configuration error, not a capacity one.
    let mut tris = m.triangles.clone();
    assert_eq!(
        ws.simplify(&m.positions, &mut tris, &config),
        Err(Error::InvalidConfig {
            field: ConfigField::MaxError
        })
    );
    // A bound with optimal placement: refused (control points are read at the positions
    // placement would move).
    let mut q = vec![[0.0f32; 10]; m.positions.len()];
    let mut pos = m.positions.clone();
    let mut links = vec![0u32; need];
    let r = ws
        .start(
            Positions::Write(&mut pos),
            &mut tris,
            &Config::stored().with_max_error(0.1),
            StoredQuadric::new(&mut q, Placement::Optimal),
            Controls::new(&m.triangles, &mut links),
            EdgeCollapse,
        )
        .map(|s| s.run());
    assert_eq!(
        r,
        Err(Error::InvalidConfig {
            field: ConfigField::Placement
        })
    );
    assert_eq!(pos, m.positions);
    // Too few links.
    let mut links = vec![0u32; need - 1];
    assert_eq!(
        run_bounded(
            &mut ws,
            &m.positions,
            &m.triangles,
            &mut tris,
            &mut links,
            &config
        ),
        Err(Error::Capacity {
            what: Capacity::Controls,
            needed: need,
            available: need - 1
        })
    );
    let mut links = vec![0u32; need];
    // Originals that are not the triangles.
    let mut other = m.triangles.clone();
    other[5] = [0, 1, 2];
    assert_eq!(
        run_bounded(
            &mut ws,
            &m.positions,
            &other,
            &mut tris,
            &mut links,
            &config
        ),
        Err(Error::OriginalMismatch { triangle: 5 })
    );
    assert_eq!(
        run_bounded(
            &mut ws,
            &m.positions,
            &m.triangles[..70],
            &mut tris,
            &mut links,
            &config
        ),
        Err(Error::OriginalMismatch { triangle: 70 })
    );
    // Bad bounds.
    for d in [-1.0, f32::NAN] {
        assert_eq!(
            run_bounded(
                &mut ws,
                &m.positions,
                &m.triangles,
                &mut tris,
                &mut links,
                &config.with_max_error(d)
            ),
            Err(Error::InvalidConfig {
                field: ConfigField::MaxError
            })
        );
    }
    // Nothing was written.
    assert_eq!(tris, m.triangles);
    // A zero bound: only exactly coplanar collapses remain possible; still valid.
    let (out, r) = {
        drop(ws);
        bounded(&m, &Config::new().with_max_error(0.0).with_ratio(0.0))
    };
    common::assert_valid("zero bound", &m, &out, &r);
    assert_eq!(r.triangles_out, 80);
}

#[test]
fn triangle_collapse_honours_the_bound() {
    // Zhu, Wang and Meng's own operator (§3): eq. 3 order, penalty re-insertion, loop/flip/bound tests.
    let tri = unlimited();
    for (name, m) in [
        ("icosphere4", icosphere(4)),
        ("wavy grid", grid(40, 30, 0.3)),
        ("fin and pinch", fin_and_pinch(16)),
        ("cow", fixture("cow.obj")),
        ("plate_holes", fixture("plate_holes.obj")),
    ] {
        let counts = check_with(
            &format!("triangle {name}"),
            &m,
            &[0.002, 0.01],
            tri,
            TriangleCollapse,
        );
        assert!(counts[1] < counts[0], "{name}: {counts:?}");
        assert!(counts[0] < m.triangles.len(), "{name}: {counts:?}");
    }
    // Without a bound, to a triangle target.
    let m = fixture("cow.obj");
    let mut tris = m.triangles.clone();
    let mut ws = common::BIG.lock().unwrap_or_else(|e| e.into_inner());
    let p = Positions::Read(&m.positions);
    let r = ws
        .start(
            p,
            &mut tris,
            &Config::new(),
            Builtin::new(),
            NoBound,
            TriangleCollapse,
        )
        .expect("start")
        .run();
    tris.truncate(r.triangles_out);
    let out = MeshData {
        positions: m.positions.clone(),
        triangles: tris,
    };
    common::assert_valid("triangle cow 10 %", &m, &out, &r);
    assert!(r.target_reached, "{r:?}");
    // Passes and triangle collapse do not mix.
    let mut tris = m.triangles.clone();
    let p = Positions::Read(&m.positions);
    assert_eq!(
        ws.start(
            p,
            &mut tris,
            &Config::paper(),
            Builtin::new(),
            NoBound,
            TriangleCollapse
        )
        .err(),
        Some(Error::InvalidConfig {
            field: ConfigField::Operator
        })
    );
}

#[test]
#[ignore = "every shared mesh, both operators: about a minute in release"]
fn all_shared_meshes_stay_within_the_bound() {
    let mut names: Vec<String> = std::fs::read_dir(common::shared_meshes())
        .expect("shared meshes")
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".obj"))
        .collect();
    names.sort();
    for name in &names {
        let m = common::load_obj(name);
        check(name, &m, &[0.005], unlimited());
        check_with(
            &format!("triangle {name}"),
            &m,
            &[0.005],
            unlimited(),
            TriangleCollapse,
        );
    }
}

#[test]
fn operations_stay_bounded_with_the_bound_and_the_triangle_operator() {
    // The pops between two collapses: a refused edge candidate re-queues a vertex at its true
    // price or drops it; a triangle vertex whose triangles are all refused goes back at most
    // MAX_PENALTIES (3) times before it is dropped until its fan changes, and a collapse
    // re-keys the fans it touched (about 12 vertices). So pops ≤ 4·(V + 12·collapses) and
    // sweeps ≤ 3·V per round plus V per halving.
    let m = fixture("cow.obj");
    operations_stay_bounded(&m, EdgeCollapse);
    operations_stay_bounded(&m, TriangleCollapse);
}

fn operations_stay_bounded<O: Operator + std::fmt::Debug>(m: &MeshData, op: O) {
    let (v, t) = (m.positions.len() as u64, m.triangles.len() as u64);
    {
        let config = unlimited().with_relative_max_error(0.005, &m.positions);
        let mut tris = m.triangles.clone();
        let mut links = vec![0u32; control_len(tris.len(), m.positions.len())];
        let mut ws = common::BIG.lock().unwrap_or_else(|e| e.into_inner());
        let bound = Controls::new(&m.triangles, &mut links);
        let p = Positions::Read(&m.positions);
        let mut s = ws
            .start(p, &mut tris, &config, Builtin::new(), bound, op)
            .expect("start");
        let mut ops = 0u64;
        while !s.step(1) {
            ops += 1;
        }
        let r = s.finish();
        let halvings = 64 - t.leading_zeros() as u64;
        let sweeps = 3 * v * r.passes as u64 + v * halvings;
        let c = r.collapses as u64;
        eprintln!(
            "{op:?}: {ops} operations, {c} collapses, {} rounds, {:.2} non-sweep operations per collapse",
            r.passes,
            (ops - sweeps.min(ops)) as f64 / c.max(1) as f64
        );
        assert!(c < v);
        assert!(ops <= sweeps + 4 * (v + 12 * c), "{op:?}: {ops}");
    }
}

mod property {
    use super::*;
    use proptest::prelude::*;
    use tinydecimate::Schedule;

    fn mesh(kind: u8, n: u32, jitter_seed: u64) -> MeshData {
        let m = match kind % 4 {
            0 => icosphere(1 + n % 3),
            1 => grid(2 + n % 14, 2 + (n / 3) % 14, 0.3),
            2 => cube(1 + n % 6),
            _ => fin_and_pinch(3 + n % 6),
        };
        jitter(m, jitter_seed, 1e-2)
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

        /// Any generated mesh, bound, schedule, operator and target: valid output, every
        /// control point within the bound (checked outside the library).
        #[test]
        fn the_bound_holds(
            kind in any::<u8>(),
            n in any::<u32>(),
            seed in any::<u64>(),
            fraction in 0.0f32..0.05,
            ratio in prop_oneof![Just(0.0f32), 0.0f32..0.8],
            passes in any::<bool>(),
            triangle in any::<bool>(),
        ) {
            let m = mesh(kind, n, seed);
            let base = if passes && !triangle { Config::paper() } else { Config::new() };
            let base = base.with_ratio(ratio);
            prop_assume!(base.schedule() == Schedule::Greedy || !triangle);
            if triangle {
                check_with("property", &m, &[fraction], base, TriangleCollapse);
            } else {
                check("property", &m, &[fraction], base);
            }
        }
    }
}

/// One bounded run on `ws` with the built-in cost.
fn run_bounded(
    ws: &mut tinydecimate::Workspace<u32, 65_536, 131_072>,
    positions: &[[f32; 3]],
    original: &[[u32; 3]],
    triangles: &mut [[u32; 3]],
    links: &mut [u32],
    config: &Config,
) -> Result<Report, Error> {
    let bound = Controls::new(original, links);
    let p = Positions::Read(positions);
    Ok(ws
        .start(p, triangles, config, Builtin::new(), bound, EdgeCollapse)?
        .run())
}
