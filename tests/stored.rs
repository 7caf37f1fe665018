//! Stored quadrics: `StoredQuadric` with `Placement::Subset` (subset placement) and
//! `StoredQuadric` with `Placement::Optimal` (optimal placement on mutable positions).
//!
//! Properties: valid output (the shared checker, moved positions allowed for optimal), optimal
//! placement lowers the error against the input below subset placement, exact determinism
//! (repeat runs and stepping give the same bytes and positions), bad input refused before
//! anything is written, and the stored error against the memoryless default where it holds.

mod common;

use common::{cube, fin_and_pinch, grid, icosphere, jitter, MeshData};
use std::sync::Mutex;
use tinydecimate::cost::{Placement, StoredQuadric, VertexQuadric};
use tinydecimate::EdgeCollapse;
use tinydecimate::{Capacity, Config, Error, Report, Workspace};

type Ws = Workspace<u32, 8_192, 16_384>;
static WS: Mutex<Ws> = Mutex::new(Workspace::new());

fn fixture(name: &str) -> MeshData {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests")
        .join("fixtures")
        .join(name);
    common::parse_obj(&std::fs::read_to_string(path).expect("fixture"))
}

/// Runs stored quadrics with `placement`; the result carries the positions the library left.
fn stored(m: &MeshData, config: &Config, placement: Placement) -> (MeshData, Report) {
    let mut ws = WS.lock().unwrap_or_else(|e| e.into_inner());
    let mut tris = m.triangles.clone();
    let mut pos = m.positions.clone();
    let mut q: Vec<VertexQuadric> = vec![[0.0; 10]; pos.len()];
    let r = match placement {
        Placement::Subset => ws
            .start(
                tinydecimate::Positions::Read(&pos),
                &mut tris,
                config,
                tinydecimate::StoredQuadric::new(&mut q, tinydecimate::Placement::Subset),
                tinydecimate::NoBound,
                EdgeCollapse,
            )
            .map(|s| s.run()),
        Placement::Optimal => ws
            .start(
                tinydecimate::Positions::Write(&mut pos),
                &mut tris,
                config,
                tinydecimate::StoredQuadric::new(&mut q, tinydecimate::Placement::Optimal),
                tinydecimate::NoBound,
                EdgeCollapse,
            )
            .map(|s| s.run()),
    }
    .expect("simplify");
    tris.truncate(r.triangles_out);
    (
        MeshData {
            positions: pos,
            triangles: tris,
        },
        r,
    )
}

fn assert_valid(name: &str, input: &MeshData, output: &MeshData, moved: bool) {
    common::verdict_with(input, output, moved).assert_valid(name);
}

/// Squared distance (f64) from `p` to triangle `a b c`.
fn point_triangle2(p: [f64; 3], a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> f64 {
    let sub = |x: [f64; 3], y: [f64; 3]| [x[0] - y[0], x[1] - y[1], x[2] - y[2]];
    let dot = |x: [f64; 3], y: [f64; 3]| x[0] * y[0] + x[1] * y[1] + x[2] * y[2];
    let seg = |p: [f64; 3], a: [f64; 3], b: [f64; 3]| {
        let (ab, ap) = (sub(b, a), sub(p, a));
        let l = dot(ab, ab);
        let t = if l > 0.0 {
            (dot(ap, ab) / l).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let d = [ap[0] - t * ab[0], ap[1] - t * ab[1], ap[2] - t * ab[2]];
        dot(d, d)
    };
    let (ab, ac, ap) = (sub(b, a), sub(c, a), sub(p, a));
    let n = [
        ab[1] * ac[2] - ab[2] * ac[1],
        ab[2] * ac[0] - ab[0] * ac[2],
        ab[0] * ac[1] - ab[1] * ac[0],
    ];
    let nn = dot(n, n);
    if nn > 0.0 {
        // Barycentric test of the projection.
        let d = dot(ap, n) / nn;
        let q = [p[0] - d * n[0], p[1] - d * n[1], p[2] - d * n[2]];
        let inside = |x: [f64; 3], y: [f64; 3]| {
            let (e, w) = (sub(y, x), sub(q, x));
            let c = [
                e[1] * w[2] - e[2] * w[1],
                e[2] * w[0] - e[0] * w[2],
                e[0] * w[1] - e[1] * w[0],
            ];
            dot(c, n) >= 0.0
        };
        if inside(a, b) && inside(b, c) && inside(c, a) {
            return d * d * nn;
        }
    }
    seg(p, a, b).min(seg(p, b, c)).min(seg(p, c, a))
}

/// Mean squared distance from the input's vertices to the output surface, over the squared
/// bounding-box diagonal: the error of the result against the input, independent of the
/// library's own cost (brute force, f64).
fn error(input: &MeshData, output: &MeshData) -> f64 {
    let f = |p: [f32; 3]| p.map(f64::from);
    let (mut lo, mut hi) = ([f64::MAX; 3], [f64::MIN; 3]);
    for p in &input.positions {
        for k in 0..3 {
            lo[k] = lo[k].min(f64::from(p[k]));
            hi[k] = hi[k].max(f64::from(p[k]));
        }
    }
    let diag2: f64 = (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum();
    let used: std::collections::BTreeSet<u32> = input.triangles.iter().flatten().copied().collect();
    let mut sum = 0.0;
    for &v in &used {
        let p = f(input.positions[v as usize]);
        let mut best = f64::MAX;
        for t in &output.triangles {
            let [a, b, c] = t.map(|i| f(output.positions[i as usize]));
            best = best.min(point_triangle2(p, a, b, c));
        }
        sum += best;
    }
    sum / used.len() as f64 / diag2
}

fn meshes() -> Vec<(&'static str, MeshData)> {
    vec![
        ("cow", fixture("cow.obj")),
        ("plate_holes", fixture("plate_holes.obj")),
        ("wavy grid (open)", grid(14, 10, 0.2)),
        ("jittered icosphere", jitter(icosphere(3), 7, 0.02)),
        ("cube (sharp edges)", cube(6)),
        ("fin and pinch (non-manifold)", fin_and_pinch(10)),
    ]
}

#[test]
fn both_placements_give_valid_simplifications() {
    for (name, m) in meshes() {
        // With the feature rule and without (`Config::stored()`, where subset placement
        // re-keys a collapse's neighbours with one price each).
        for (ratio, base) in [
            (0.5, Config::new()),
            (0.25, Config::new()),
            (0.05, Config::new()),
            (0.5, Config::stored()),
            (0.25, Config::stored()),
            (0.05, Config::stored()),
        ] {
            let config = base.with_ratio(ratio);
            for placement in [Placement::Subset, Placement::Optimal] {
                let (out, r) = stored(&m, &config, placement);
                let label = format!(
                    "{name} {ratio} {placement:?} features {}",
                    config.features()
                );
                assert_eq!(r.triangles_out, out.triangles.len(), "{label}");
                assert!(
                    r.triangles_out < m.triangles.len(),
                    "{label}: nothing removed"
                );
                assert_valid(&label, &m, &out, placement == Placement::Optimal);
                if placement == Placement::Subset {
                    assert_eq!(out.positions, m.positions, "{label}: subset moved a vertex");
                }
                // Every output position is finite.
                for t in &out.triangles {
                    for &i in t {
                        assert!(out.positions[i as usize].iter().all(|x| x.is_finite()));
                    }
                }
            }
        }
    }
}

#[test]
fn optimal_placement_lowers_the_error_against_subset() {
    for (name, m) in [
        ("cow", fixture("cow.obj")),
        ("plate_holes", fixture("plate_holes.obj")),
        ("jittered icosphere", jitter(icosphere(3), 7, 0.02)),
    ] {
        for ratio in [0.25, 0.1] {
            let config = Config::new().with_ratio(ratio);
            let (s, _) = stored(&m, &config, Placement::Subset);
            let (o, _) = stored(&m, &config, Placement::Optimal);
            let (es, eo) = (error(&m, &s), error(&m, &o));
            assert!(
                eo < es,
                "{name} {ratio}: optimal {eo:e} not below subset {es:e}"
            );
        }
    }
}

#[test]
fn optimal_placement_is_not_worse_than_the_memoryless_default() {
    // Measured: with subset placement the stored quadric is *not* below the memoryless
    // default on the cow (bench: mean 0.0182 % vs 0.0159 % at 50 %), so only optimal
    // placement is held to it.
    let m = fixture("cow.obj");
    for ratio in [0.5, 0.25, 0.1] {
        let config = Config::new().with_ratio(ratio);
        let (d, _) = common::simplify(&m, &config);
        let (o, _) = stored(&m, &config, Placement::Optimal);
        let (ed, eo) = (error(&m, &d), error(&m, &o));
        assert!(
            eo <= ed,
            "cow {ratio}: optimal {eo:e} above memoryless {ed:e}"
        );
    }
}

#[test]
fn runs_are_exactly_repeatable_and_stepping_gives_the_same_bytes() {
    let m = fixture("cow.obj");
    for (config, placement) in [
        (Config::new(), Placement::Subset),
        (Config::new(), Placement::Optimal),
        (Config::stored(), Placement::Subset),
        (Config::stored(), Placement::Optimal),
    ] {
        let config = config.with_ratio(0.1);
        let (a, ra) = stored(&m, &config, placement);
        let (b, rb) = stored(&m, &config, placement);
        assert_eq!(a.triangles, b.triangles, "{placement:?}");
        assert_eq!(ra, rb);
        let bits =
            |p: &[[f32; 3]]| -> Vec<u32> { p.iter().flatten().map(|x| x.to_bits()).collect() };
        assert_eq!(bits(&a.positions), bits(&b.positions), "{placement:?}");
        // Stepping with small budgets: the same bytes as one shot.
        let mut ws = WS.lock().unwrap_or_else(|e| e.into_inner());
        let mut tris = m.triangles.clone();
        let mut pos = m.positions.clone();
        let mut q: Vec<VertexQuadric> = vec![[0.0; 10]; pos.len()];
        let cost = StoredQuadric::new(&mut q, placement);
        let r = match placement {
            Placement::Subset => {
                let mut s = ws
                    .start(
                        tinydecimate::Positions::Read(&pos),
                        &mut tris,
                        &config,
                        cost,
                        tinydecimate::NoBound,
                        EdgeCollapse,
                    )
                    .unwrap();
                while !s.step(7) {}
                s.finish()
            }
            Placement::Optimal => {
                let mut s = ws
                    .start(
                        tinydecimate::Positions::Write(&mut pos),
                        &mut tris,
                        &config,
                        cost,
                        tinydecimate::NoBound,
                        EdgeCollapse,
                    )
                    .unwrap();
                while !s.step(7) {}
                s.finish()
            }
        };
        tris.truncate(r.triangles_out);
        assert_eq!(tris, a.triangles, "{placement:?} stepped");
        assert_eq!(bits(&pos), bits(&a.positions), "{placement:?} stepped");
    }
}

#[test]
fn bad_input_is_refused_before_anything_is_written() {
    let m = grid(6, 6, 0.1);
    let config = Config::new().with_ratio(0.2);
    let mut ws = WS.lock().unwrap_or_else(|e| e.into_inner());
    // Too few quadrics.
    let mut tris = m.triangles.clone();
    let mut pos = m.positions.clone();
    let mut q: Vec<VertexQuadric> = vec![[0.0; 10]; pos.len() - 1];
    for optimal in [false, true] {
        let r = if optimal {
            ws.start(
                tinydecimate::Positions::Write(&mut pos),
                &mut tris,
                &config,
                tinydecimate::StoredQuadric::new(&mut q, tinydecimate::Placement::Optimal),
                tinydecimate::NoBound,
                EdgeCollapse,
            )
            .map(|s| s.run())
        } else {
            ws.start(
                tinydecimate::Positions::Read(&pos),
                &mut tris,
                &config,
                tinydecimate::StoredQuadric::new(&mut q, tinydecimate::Placement::Subset),
                tinydecimate::NoBound,
                EdgeCollapse,
            )
            .map(|s| s.run())
        };
        assert_eq!(
            r,
            Err(Error::Capacity {
                what: Capacity::Quadrics,
                needed: m.positions.len(),
                available: m.positions.len() - 1,
            })
        );
        assert_eq!(tris, m.triangles);
        assert_eq!(pos, m.positions);
    }
    // A NaN position and an index out of range: typed errors, positions and triangles untouched.
    let mut q: Vec<VertexQuadric> = vec![[0.0; 10]; pos.len()];
    pos[3][1] = f32::NAN;
    let r = ws
        .start(
            tinydecimate::Positions::Write(&mut pos),
            &mut tris,
            &config,
            tinydecimate::StoredQuadric::new(&mut q, tinydecimate::Placement::Optimal),
            tinydecimate::NoBound,
            EdgeCollapse,
        )
        .map(|s| s.run());
    assert_eq!(r, Err(Error::NonFinitePosition { vertex: 3 }));
    assert!(pos[3][1].is_nan());
    pos[3][1] = m.positions[3][1];
    assert_eq!(tris, m.triangles);
    tris[5][2] = 10_000;
    let r = ws
        .start(
            tinydecimate::Positions::Write(&mut pos),
            &mut tris,
            &config,
            tinydecimate::StoredQuadric::new(&mut q, tinydecimate::Placement::Optimal),
            tinydecimate::NoBound,
            EdgeCollapse,
        )
        .map(|s| s.run());
    assert_eq!(
        r,
        Err(Error::IndexOutOfRange {
            triangle: 5,
            index: 10_000
        })
    );
    assert_eq!(pos, m.positions);
    // A bad configuration.
    tris[5] = m.triangles[5];
    let r = ws
        .start(
            tinydecimate::Positions::Write(&mut pos),
            &mut tris,
            &config.with_ratio(2.0),
            tinydecimate::StoredQuadric::new(&mut q, tinydecimate::Placement::Optimal),
            tinydecimate::NoBound,
            EdgeCollapse,
        )
        .map(|s| s.run());
    assert!(matches!(r, Err(Error::InvalidConfig { .. })));
    assert_eq!((tris, pos), (m.triangles.clone(), m.positions.clone()));
}

#[test]
fn feature_vertices_are_never_removed_nor_moved_while_they_are_features() {
    // Checked after every single operation: a vertex that was a feature before it is still
    // used and still where it was (as the kept end of a collapse it keeps its position).
    for (name, m) in [("cube", cube(6)), ("cow", fixture("cow.obj"))] {
        let config = Config::new().with_ratio(0.1);
        let mut ws = WS.lock().unwrap_or_else(|e| e.into_inner());
        let mut tris = m.triangles.clone();
        let mut pos = m.positions.clone();
        let mut q: Vec<VertexQuadric> = vec![[0.0; 10]; pos.len()];
        let cost = StoredQuadric::new(&mut q, Placement::Optimal);
        let mut s = ws
            .start(
                tinydecimate::Positions::Write(&mut pos),
                &mut tris,
                &config,
                cost,
                tinydecimate::NoBound,
                EdgeCollapse,
            )
            .unwrap();
        let (mut checked, mut moved) = (0usize, 0usize);
        loop {
            let before: Vec<(usize, [f32; 3])> = (0..m.positions.len())
                .filter(|&v| s.is_feature(v) && s.is_used(v))
                .filter_map(|v| s.position(v).map(|p| (v, p)))
                .collect();
            let all: Vec<Option<[f32; 3]>> =
                (0..m.positions.len()).map(|v| s.position(v)).collect();
            let done = s.step(1);
            for &(v, p) in &before {
                assert!(s.is_used(v), "{name}: feature {v} removed");
                assert_eq!(s.position(v), Some(p), "{name}: feature {v} moved");
                checked += 1;
            }
            moved += (0..m.positions.len())
                .filter(|&v| s.position(v) != all[v])
                .count();
            if done {
                break;
            }
        }
        let r = s.finish();
        assert!(checked > 0 && r.feature_vertices > 0, "{name}: no features");
        assert!(moved > 0, "{name}: optimal placement moved nothing");
    }
}
