//! Hoppe's energy as a cost (`tinydecimate::cost::Energy`).
//!
//! Properties: valid output (the shared checker) on generated meshes and the cow at 50, 25
//! and 10 %; each term does work: the spring keeps a flat grid's triangles better shaped than
//! the distance alone (on a plane every sample lies in every new plane, so distance alone
//! prices every interior move at zero), and the distance keeps a wavy grid closer to its
//! original vertices than the spring alone; the storage is checked before anything runs.

mod common;

use common::{cube, grid, icosphere, jitter, MeshData};
use std::sync::Mutex;
use tinydecimate::cost::{Energy, Samples};
use tinydecimate::{Capacity, Config, EdgeCollapse, Error, NoBound, Report, Target, Workspace};

type Ws = Workspace<u32, 8_192, 16_384>;
static WS: Mutex<Ws> = Mutex::new(Workspace::new());

fn fixture(name: &str) -> MeshData {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests")
        .join("fixtures")
        .join(name);
    common::parse_obj(&std::fs::read_to_string(path).expect("fixture"))
}

/// Runs the energy with weights `dist` and κ `spring` to `ratio` of the triangles.
fn energy(m: &MeshData, ratio: f32, dist: f32, spring: f32) -> (MeshData, Report) {
    let mut ws = WS.lock().unwrap_or_else(|e| e.into_inner());
    let mut tris = m.triangles.clone();
    let mut s: Vec<Samples> = vec![[0.0; 10]; m.positions.len()];
    let config = Config::new().with_target(Target::Ratio(ratio));
    let r = ws
        .start(
            tinydecimate::Positions::Read(&m.positions),
            &mut tris,
            &config,
            Energy::new(&mut s).with_weights(dist, spring),
            NoBound,
            EdgeCollapse,
        )
        .map(|s| s.run())
        .expect("simplify");
    common::output(&m.positions, tris, r)
}

/// `4√3 A / Σℓ²` per triangle (1 for equilateral, 0 for degenerate): their mean.
fn mean_quality(m: &MeshData) -> f64 {
    let p = |i: u32| m.positions[i as usize].map(f64::from);
    let sub = |a: [f64; 3], b: [f64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let mut sum = 0.0;
    for t in &m.triangles {
        let (a, b, c) = (p(t[0]), p(t[1]), p(t[2]));
        let (u, v, w) = (sub(b, a), sub(c, a), sub(c, b));
        let n = [
            u[1] * v[2] - u[2] * v[1],
            u[2] * v[0] - u[0] * v[2],
            u[0] * v[1] - u[1] * v[0],
        ];
        let area = 0.5 * dot(n, n).sqrt();
        let l2 = dot(u, u) + dot(v, v) + dot(w, w);
        sum += if l2 > 0.0 {
            4.0 * 3f64.sqrt() * area / l2
        } else {
            0.0
        };
    }
    sum / m.triangles.len().max(1) as f64
}

/// Mean over `input`'s vertices of the squared distance to `output`'s surface.
fn mean_distance2(input: &MeshData, output: &MeshData) -> f64 {
    let p = |i: u32| output.positions[i as usize].map(f64::from);
    let sub = |a: [f64; 3], b: [f64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    // Squared distance to a triangle: inside its prism the plane, else the nearest edge.
    let seg = |x: [f64; 3], a: [f64; 3], b: [f64; 3]| {
        let (ab, ax) = (sub(b, a), sub(x, a));
        let l = dot(ab, ab);
        let t = if l > 0.0 {
            (dot(ax, ab) / l).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let d = sub(ax, [ab[0] * t, ab[1] * t, ab[2] * t]);
        dot(d, d)
    };
    let mut sum = 0.0;
    for x in &input.positions {
        let x = x.map(f64::from);
        let mut best = f64::INFINITY;
        for t in &output.triangles {
            let (a, b, c) = (p(t[0]), p(t[1]), p(t[2]));
            let (u, v) = (sub(b, a), sub(c, a));
            let n = [
                u[1] * v[2] - u[2] * v[1],
                u[2] * v[0] - u[0] * v[2],
                u[0] * v[1] - u[1] * v[0],
            ];
            let nn = dot(n, n);
            let ax = sub(x, a);
            let inside = nn > 0.0 && {
                let side = |e: [f64; 3], q: [f64; 3]| {
                    let c = [
                        e[1] * q[2] - e[2] * q[1],
                        e[2] * q[0] - e[0] * q[2],
                        e[0] * q[1] - e[1] * q[0],
                    ];
                    dot(c, n) >= 0.0
                };
                side(sub(b, a), sub(x, a))
                    && side(sub(c, b), sub(x, b))
                    && side(sub(a, c), sub(x, c))
            };
            let d = if inside {
                let h = dot(ax, n);
                h * h / nn
            } else {
                seg(x, a, b).min(seg(x, b, c)).min(seg(x, c, a))
            };
            best = best.min(d);
        }
        sum += best;
    }
    sum / input.positions.len().max(1) as f64
}

#[test]
fn valid_on_generated_meshes_and_the_cow() {
    let meshes = [
        ("icosphere", icosphere(3)),
        ("grid", grid(20, 16, 0.15)),
        ("cube", cube(6)),
        ("jittered sphere", jitter(icosphere(3), 7, 0.01)),
        ("cow", fixture("cow.obj")),
    ];
    for (name, m) in &meshes {
        for ratio in [0.5, 0.25, 0.1] {
            let (out, r) = energy(m, ratio, 1.0, Energy::KAPPA);
            common::assert_valid(&format!("{name} at {ratio}"), m, &out, &r);
            assert!(
                out.triangles.len() as f32 <= (m.triangles.len() as f32 * ratio).ceil() + 2.0
                    || r.stop != tinydecimate::Stop::Target,
                "{name} at {ratio}: {} triangles",
                out.triangles.len()
            );
        }
    }
}

#[test]
fn the_spring_shapes_triangles_on_a_plane() {
    let flat = grid(24, 24, 0.0);
    let (alone, _) = energy(&flat, 0.2, 1.0, 0.0);
    let (sprung, r) = energy(&flat, 0.2, 1.0, Energy::KAPPA);
    common::assert_valid("flat grid", &flat, &sprung, &r);
    let (q0, q1) = (mean_quality(&alone), mean_quality(&sprung));
    eprintln!("flat grid mean quality: distance alone {q0:.3}, with the spring {q1:.3}");
    assert!(q1 > q0 + 0.05, "distance alone {q0}, with the spring {q1}");
}

#[test]
fn the_distance_keeps_the_surface() {
    let wavy = grid(24, 24, 0.2);
    let (springs, _) = energy(&wavy, 0.15, 0.0, 1.0);
    let (both, r) = energy(&wavy, 0.15, 1.0, Energy::KAPPA);
    common::assert_valid("wavy grid", &wavy, &both, &r);
    let (e0, e1) = (
        mean_distance2(&wavy, &springs),
        mean_distance2(&wavy, &both),
    );
    eprintln!("wavy grid mean squared distance: spring alone {e0:.3e}, with distance {e1:.3e}");
    assert!(e1 < 0.5 * e0, "spring alone {e0}, with distance {e1}");
}

#[test]
fn short_storage_is_refused() {
    let m = icosphere(2);
    let mut ws = WS.lock().unwrap_or_else(|e| e.into_inner());
    let mut tris = m.triangles.clone();
    let mut s: Vec<Samples> = vec![[0.0; 10]; m.positions.len() - 1];
    let config = Config::new().with_target(Target::Ratio(0.5));
    let e = ws
        .start(
            tinydecimate::Positions::Read(&m.positions),
            &mut tris,
            &config,
            Energy::new(&mut s),
            NoBound,
            EdgeCollapse,
        )
        .err();
    assert!(
        matches!(
            e,
            Some(Error::Capacity {
                what: Capacity::Quadrics,
                ..
            })
        ),
        "{e:?}"
    );
    assert_eq!(tris, m.triangles, "nothing written");
}
