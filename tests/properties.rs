//! Property tests on generated meshes: after every run (and, where it matters, after every
//! single operation) the mesh is valid, closed stays closed, topology is kept, features stay.

mod common;
use common::*;
use proptest::prelude::*;
use tinydecimate::EdgeCollapse;
use tinydecimate::{Config, FeatureMode, Schedule, Target, Workspace};

#[derive(Clone, Debug)]
enum Kind {
    Sphere(u32),
    Grid(u32, u32),
    Cube(u32),
    /// A grid with a fin: a third triangle on one interior edge (non-manifold edge), and a cone
    /// touching it at one vertex (pinched vertex).
    NonManifold(u32),
}

fn build(kind: &Kind, jitter: u64) -> MeshData {
    let m = match *kind {
        Kind::Sphere(n) => icosphere(n),
        Kind::Grid(n, k) => grid(n, k, 0.15),
        Kind::Cube(n) => cube(n),
        Kind::NonManifold(n) => fin_and_pinch(n),
    };
    // Deterministic jitter so that ties and symmetric cases vary.
    common::jitter(m, jitter, 1e-3)
}

fn kind() -> impl Strategy<Value = Kind> {
    prop_oneof![
        (1u32..4).prop_map(Kind::Sphere),
        (2u32..14, 2u32..14).prop_map(|(a, b)| Kind::Grid(a, b)),
        (1u32..7).prop_map(Kind::Cube),
        (3u32..9).prop_map(Kind::NonManifold),
    ]
}

fn config() -> impl Strategy<Value = Config> {
    (
        prop_oneof![Just(Schedule::Greedy), Just(Schedule::Passes)],
        0.0f32..0.9,
        prop_oneof![Just(0.0f32), Just(0.5), Just(1.0), Just(2.0)],
        any::<bool>(),
        any::<bool>(),
        any::<bool>(),
    )
        .prop_map(|(schedule, ratio, lambda, valence, targets, loose)| {
            let mut c = Config::new()
                .with_schedule(schedule)
                .with_ratio(ratio)
                .with_lambda(lambda)
                .with_feature_mode(if valence {
                    FeatureMode::ValenceNormalized
                } else {
                    FeatureMode::Paper
                });
            c = c.with_feature_targets(targets);
            if loose {
                // Geometry barely constrains: the topological rules must hold on their own.
                c = c.with_max_normal_turn(179.0);
                c = c.with_min_quality(0.0);
            }
            c
        })
}

fn angle_deg(m: &MeshData, a: [u32; 3], b: [u32; 3]) -> f64 {
    let n = |t: [u32; 3]| {
        let p = |i: u32| m.positions[i as usize].map(|x| x as f64);
        let (x, y, z) = (p(t[0]), p(t[1]), p(t[2]));
        let u = [y[0] - x[0], y[1] - x[1], y[2] - x[2]];
        let v = [z[0] - x[0], z[1] - x[1], z[2] - x[2]];
        [
            u[1] * v[2] - u[2] * v[1],
            u[2] * v[0] - u[0] * v[2],
            u[0] * v[1] - u[1] * v[0],
        ]
    };
    let (p, q) = (n(a), n(b));
    let d = p[0] * q[0] + p[1] * q[1] + p[2] * q[2];
    let l = ((p[0] * p[0] + p[1] * p[1] + p[2] * p[2]) * (q[0] * q[0] + q[1] * q[1] + q[2] * q[2]))
        .sqrt();
    if l == 0.0 {
        return 0.0;
    }
    (d / l).clamp(-1.0, 1.0).acos().to_degrees()
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 96, ..ProptestConfig::default() })]

    /// One-shot runs: the output is a valid simplification of the input.
    #[test]
    fn output_is_valid(kind in kind(), jitter in any::<u64>(), config in config()) {
        let input = build(&kind, jitter);
        let (output, report) = simplify(&input, &config);
        assert_valid(&format!("{kind:?}"), &input, &output, &report);
        prop_assert!(report.triangles_out <= input.triangles.len());
        // The target, computed here from the configuration and the valid input (floored
        // ratio, or the triangle count if higher), and whether the triangles actually handed
        // back reach it: neither is read off the report it is checked against.
        let valid_in = report.triangles_in - report.degenerate_dropped - report.duplicates_dropped;
        let target = match config.target() {
            Target::Ratio(r) => (r * valid_in as f32) as usize,
            Target::Triangles(n) => n,
        };
        prop_assert_eq!(report.target_triangles, target);
        prop_assert_eq!(report.target_reached, output.triangles.len() <= target);
    }

    /// Operation by operation: no triangle turns beyond the limit in one collapse, and a vertex
    /// that is a feature before an operation survives it.
    #[test]
    fn every_operation_respects_limits(kind in kind(), jitter in any::<u64>(), config in config()) {
        let input = build(&kind, jitter);
        let mut tris = input.triangles.clone();
        let mut ws = Workspace::<u16, 2048, 2048>::new();
        let mut s = ws.start(tinydecimate::Positions::Read(&input.positions), &mut tris, &config, tinydecimate::Builtin::new(), tinydecimate::NoBound, EdgeCollapse).unwrap();
        let mut guard = 0;
        loop {
            let before: Vec<[u32; 3]> = s.buffer().to_vec();
            let features: Vec<usize> = (0..input.positions.len())
                .filter(|&v| s.is_feature(v) && s.is_used(v))
                .collect();
            let finished = s.step(1);
            for &v in &features {
                prop_assert!(s.is_used(v), "feature vertex {} removed", v);
            }
            for (t, (old, new)) in before.iter().zip(s.buffer()).enumerate() {
                if new[0] != new[1] && old != new {
                    let a = angle_deg(&input, *old, *new);
                    prop_assert!(a <= config.max_normal_turn_deg() as f64 + 0.5,
                        "triangle {} turned {:.1} degrees", t, a);
                }
            }
            guard += 1;
            prop_assert!(guard < 100_000, "no termination");
            if finished { break; }
        }
        let report = s.finish();
        tris.truncate(report.triangles_out);
        let output = MeshData { positions: input.positions.clone(), triangles: tris };
        assert_valid(&format!("{kind:?}"), &input, &output, &report);
    }

    /// Stepping with any budgets gives exactly the one-shot bytes and report.
    #[test]
    fn stepping_equals_one_shot(kind in kind(), jitter in any::<u64>(), config in config(),
                                budgets in proptest::collection::vec(1u32..50, 1..8)) {
        let input = build(&kind, jitter);
        let mut one = input.triangles.clone();
        let mut ws = Workspace::<u32, 2048, 2048>::new();
        let r1 = ws.simplify(&input.positions, &mut one, &config).unwrap();
        let mut stepped = input.triangles.clone();
        let mut s = ws.start(tinydecimate::Positions::Read(&input.positions), &mut stepped, &config, tinydecimate::Builtin::new(), tinydecimate::NoBound, EdgeCollapse).unwrap();
        let mut i = 0;
        while !s.step(budgets[i % budgets.len()]) {
            i += 1;
        }
        let r2 = s.finish();
        prop_assert_eq!(&r1, &r2);
        prop_assert_eq!(&one[..r1.triangles_out], &stepped[..r2.triangles_out]);
    }
}
