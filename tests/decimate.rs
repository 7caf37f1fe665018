//! Vertex decimation (`VertexDecimation`, Schroeder, Zarge and Lorensen 1992): valid output by
//! the shared checker on generated meshes and a real fixture at 50, 25 and 10 %, the same
//! result whatever the step size, the combinations the operator refuses, and no panic on bad
//! input. The triangulation's own criterion (split plane and aspect ratio) is tested in
//! `src/operator/decimate/`, the diagonal rule (`link`) in `src/policy/legality/fan.rs`.

mod common;
use common::*;
use tinydecimate::{
    Builtin, Config, ConfigField, Controls, Error, NoBound, Positions, Report, Schedule, Stop,
    VertexDecimation,
};

/// Runs vertex decimation on a copy of `m` (steps of `budget` operations).
fn decimate_with(
    m: &MeshData,
    config: &Config,
    op: VertexDecimation,
    budget: u32,
) -> (MeshData, Report) {
    let mut tris = m.triangles.clone();
    let mut ws = BIG.lock().unwrap_or_else(|e| e.into_inner());
    let mut s = ws
        .start(
            Positions::Read(&m.positions),
            &mut tris,
            config,
            Builtin::new(),
            NoBound,
            op,
        )
        .expect("start");
    while !s.step(budget) {}
    let r = s.finish();
    output(&m.positions, tris, r)
}

fn decimate(m: &MeshData, config: &Config) -> (MeshData, Report) {
    decimate_with(m, config, VertexDecimation::new(), u32::MAX)
}

/// A mesh of `tests/fixtures`.
fn fixture(name: &str) -> MeshData {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures")
        .join(name);
    parse_obj(&std::fs::read_to_string(&path).unwrap())
}

/// The generated meshes and the cow: closed and open, smooth, bumpy and with sharp edges.
fn meshes() -> Vec<(&'static str, MeshData)> {
    vec![
        ("icosphere", icosphere(3)),
        ("bumpy icosphere", jitter(icosphere(3), 7, 0.02)),
        ("wavy grid", grid(24, 16, 0.3)),
        ("cube", cube(6)),
        ("fin and pinch", fin_and_pinch(10)),
        ("cow", fixture("cow.obj")),
    ]
}

#[test]
fn output_is_valid_at_50_25_and_10_percent() {
    for (name, m) in meshes() {
        for ratio in [0.5f32, 0.25, 0.1] {
            let config = Config::new().with_ratio(ratio);
            let (out, r) = decimate(&m, &config);
            let label = format!("{name} at {ratio}");
            assert_valid(&label, &m, &out, &r);
            assert!(r.collapses > 0, "{label}: nothing removed: {r:?}");
            // Every removal takes one or two triangles.
            let removed =
                r.triangles_in - r.degenerate_dropped - r.duplicates_dropped - r.triangles_out;
            assert!(
                removed >= r.collapses && removed <= 2 * r.collapses,
                "{label}: {removed} triangles for {} removals",
                r.collapses
            );
        }
    }
}

/// The smooth meshes reach every target (the feature angle grows when a round stalls).
#[test]
fn smooth_meshes_reach_their_targets() {
    for (name, m) in [
        ("icosphere", icosphere(3)),
        ("wavy grid", grid(24, 16, 0.3)),
        ("cow", fixture("cow.obj")),
    ] {
        for ratio in [0.5f32, 0.25, 0.1] {
            let (_, r) = decimate(&m, &Config::new().with_ratio(ratio));
            assert!(r.target_reached, "{name} at {ratio}: {r:?}");
        }
    }
}

/// Stepping one operation at a time gives exactly the one-shot run's bytes.
#[test]
fn steps_of_any_size_give_the_same_bytes() {
    let m = fixture("cow.obj");
    let config = Config::new().with_ratio(0.2);
    let (a, _) = decimate_with(&m, &config, VertexDecimation::new(), u32::MAX);
    for budget in [1, 7, 1000] {
        let (b, _) = decimate_with(&m, &config, VertexDecimation::new(), budget);
        assert_eq!(
            digest(&a.triangles),
            digest(&b.triangles),
            "budget {budget}"
        );
    }
}

/// Without growth a corner (one or three feature edges) never goes: a cube's corners stay.
#[test]
fn corners_stay_at_a_fixed_feature_angle() {
    let m = cube(4);
    let op = VertexDecimation::new().with_feature_growth(0.0, 0.0);
    let (out, r) = decimate_with(&m, &Config::new().with_ratio(0.0), op, u32::MAX);
    assert_valid("cube", &m, &out, &r);
    let used: std::collections::BTreeSet<u32> = out.triangles.iter().flatten().copied().collect();
    let mut corners = 0;
    for (v, p) in m.positions.iter().enumerate() {
        if p.iter().all(|&x| x == 0.0 || x == 1.0) {
            corners += 1;
            assert!(used.contains(&(v as u32)), "corner {v} at {p:?} removed");
        }
    }
    assert_eq!(corners, 8);
    assert!(r.collapses > 0);
}

#[test]
fn refused_combinations() {
    let m = icosphere(2);
    let start = |config: &Config| {
        let mut tris = m.triangles.clone();
        let mut ws = BIG.lock().unwrap_or_else(|e| e.into_inner());
        ws.start(
            Positions::Read(&m.positions),
            &mut tris,
            config,
            Builtin::new(),
            NoBound,
            VertexDecimation::new(),
        )
        .map(|_| ())
    };
    assert_eq!(
        start(&Config::paper()),
        Err(Error::InvalidConfig {
            field: ConfigField::Operator
        })
    );
    assert_eq!(
        start(&Config::new().with_schedule(Schedule::Passes)),
        Err(Error::InvalidConfig {
            field: ConfigField::Operator
        })
    );
    // An error bound.
    let original = m.triangles.clone();
    let mut links = vec![0u32; tinydecimate::bound::control_len(original.len(), m.positions.len())];
    let mut tris = m.triangles.clone();
    let mut ws = BIG.lock().unwrap_or_else(|e| e.into_inner());
    let e = ws
        .start(
            Positions::Read(&m.positions),
            &mut tris,
            &Config::new().with_max_error(0.1),
            Builtin::new(),
            Controls::new(&original, &mut links),
            VertexDecimation::new(),
        )
        .map(|_| ());
    assert_eq!(
        e,
        Err(Error::InvalidConfig {
            field: ConfigField::Operator
        })
    );
    // A collapse log cannot hold a removal: the run stops at once, the mesh untouched.
    let mut tris = m.triangles.clone();
    let mut log = vec![[0u32; 2]; m.positions.len()];
    let s = ws
        .start(
            Positions::Read(&m.positions),
            &mut tris,
            &Config::new(),
            Builtin::new(),
            NoBound,
            VertexDecimation::new(),
        )
        .expect("start")
        .record_into(&mut log);
    let r = s.run();
    assert_eq!(r.stop, Stop::LogFull);
    assert_eq!(r.triangles_out, m.triangles.len());
}

/// `Config::max_cost` is Schroeder's threshold: no removal farther from its plane or line.
#[test]
fn max_cost_is_the_distance_threshold() {
    let m = jitter(grid(20, 20, 0.0), 3, 0.01);
    let (out, r) = decimate(&m, &Config::new().with_ratio(0.0).with_max_cost(0.0));
    assert_eq!(r.stop, Stop::MaxCost);
    assert_eq!(out.triangles.len(), m.triangles.len());
    // A flat grid: every interior vertex is at distance 0 from its plane.
    let flat = grid(20, 20, 0.0);
    let (out, r) = decimate(&flat, &Config::new().with_ratio(0.0).with_max_cost(1e-6));
    assert_valid("flat grid", &flat, &out, &r);
    assert!(out.triangles.len() < flat.triangles.len() / 4, "{r:?}");
}

/// Garbage in (random indices: degenerate, duplicate, non-manifold and inconsistently wound
/// triangles; huge and tiny coordinates): an error or a valid output, never a panic.
#[test]
fn bad_input_never_panics() {
    let mut s = 0x2545_f491_4f6c_dd1du64;
    let mut next = move || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        s
    };
    for round in 0..60 {
        let nv = 4 + (next() % 40) as usize;
        let nt = 1 + (next() % 120) as usize;
        let scale = [1.0f32, 1e-30, 1e30, 3.0e38][round % 4];
        let positions: Vec<[f32; 3]> = (0..nv)
            .map(|_| [0, 1, 2].map(|_| ((next() % 2001) as f32 / 1000.0 - 1.0) * scale))
            .collect();
        let mut triangles: Vec<[u32; 3]> = (0..nt)
            .map(|_| [0, 1, 2].map(|_| (next() % nv as u64) as u32))
            .collect();
        if round % 10 == 9 {
            // One index out of range.
            triangles[0][1] = nv as u32 + 3;
        }
        let m = MeshData {
            positions,
            triangles,
        };
        let mut tris = m.triangles.clone();
        let mut ws = BIG.lock().unwrap_or_else(|e| e.into_inner());
        let started = ws.start(
            Positions::Read(&m.positions),
            &mut tris,
            &Config::new().with_ratio(0.1),
            Builtin::new(),
            NoBound,
            VertexDecimation::new(),
        );
        match started {
            Err(e) => assert!(round % 10 == 9, "round {round}: {e}"),
            Ok(s) => {
                let r = s.run();
                drop(ws);
                let (out, r) = output(&m.positions, tris, r);
                assert_valid(&format!("round {round}"), &m, &out, &r);
            }
        }
    }
}
