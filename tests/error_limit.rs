//! `Config::error_limit`: a run stops short of its target (`Stop::ErrorLimit`) rather than make
//! a collapse whose own error is over the limit, and every collapse it does make is under it.
//!
//! The mesh is a flat square grid with one tall spike: the flat part costs nothing to
//! simplify, the spike cannot be collapsed without an error of about its height.

mod common;
use common::*;
use tinydecimate::cost::VertexQuadric;
use tinydecimate::{
    Builtin, Config, EdgeCollapse, NoBound, Placement, Positions, Report, Stop, StoredQuadric,
    Target, VertexDecimation,
};

const HEIGHT: f32 = 0.3;

/// A flat 16 x 16 grid on the unit square with its middle vertex raised by [`HEIGHT`]; the
/// apex's index.
fn spike() -> (MeshData, u32) {
    let mut m = grid(16, 16, 0.0);
    let apex = 8 * 17 + 8;
    m.positions[apex][2] = HEIGHT;
    (m, apex as u32)
}

/// Whether an output triangle still uses `v`.
fn uses(m: &MeshData, v: u32) -> bool {
    m.triangles.iter().any(|t| t.contains(&v))
}

fn stored(m: &MeshData, config: &Config) -> (MeshData, Report) {
    let mut ws = BIG.lock().unwrap_or_else(|e| e.into_inner());
    let mut tris = m.triangles.clone();
    let mut q: Vec<VertexQuadric> = vec![[0.0; 10]; m.positions.len()];
    let r = ws
        .start(
            Positions::Read(&m.positions),
            &mut tris,
            config,
            StoredQuadric::new(&mut q, Placement::Subset),
            NoBound,
            EdgeCollapse,
        )
        .expect("start")
        .run();
    output(&m.positions, tris, r)
}

fn decimate(m: &MeshData, config: &Config) -> (MeshData, Report) {
    let mut ws = BIG.lock().unwrap_or_else(|e| e.into_inner());
    let mut tris = m.triangles.clone();
    let r = ws
        .start(
            Positions::Read(&m.positions),
            &mut tris,
            config,
            Builtin::new(),
            NoBound,
            VertexDecimation::new(),
        )
        .expect("start")
        .run();
    output(&m.positions, tris, r)
}

/// The limit's promises on one run: it stopped on the limit short of the target, refused
/// something, made every collapse under the limit, kept the spike and stayed valid; and the
/// flat part was not held back (far fewer triangles than the input).
fn assert_limited(name: &str, m: &MeshData, apex: u32, out: &MeshData, r: &Report, limit: f32) {
    assert_eq!(r.stop, Stop::ErrorLimit, "{name}: {r:?}");
    assert!(!r.target_reached, "{name}");
    assert!(r.over_limit > 0, "{name}");
    assert!(
        r.collapse_error <= limit,
        "{name}: largest collapse error {} over the limit {limit}",
        r.collapse_error
    );
    assert!(uses(out, apex), "{name}: the spike was cut");
    assert!(
        out.triangles.len() * 4 < m.triangles.len(),
        "{name}: {} of {} triangles left: the flat part was held back",
        out.triangles.len(),
        m.triangles.len()
    );
    assert_valid(name, m, out, r);
}

#[test]
fn the_limit_stops_before_the_spike_is_cut() {
    let (m, apex) = spike();
    let config = Config::new().with_target(Target::Triangles(8));
    let limit = 0.05;
    // Without a limit the count is reached, with collapses far over the limit (a limit too
    // high to refuse anything tracks the largest).
    let (_, r) = simplify(&m, &config);
    assert_eq!(r.stop, Stop::Target);
    assert_eq!(r.over_limit, 0);
    assert_eq!(r.collapse_error, 0.0, "tracked only with a limit");
    let (_, r) = simplify(&m, &config.with_error_limit(1e6));
    assert_eq!(r.stop, Stop::Target);
    assert!(r.collapse_error > 2.0 * limit, "{}", r.collapse_error);
    // With one, the run stops at the spike.
    let (out, r) = simplify(&m, &config.with_error_limit(limit));
    assert_limited("memoryless", &m, apex, &out, &r, limit);
}

#[test]
fn the_limit_holds_with_stored_quadrics() {
    let (m, apex) = spike();
    let config = Config::stored().with_target(Target::Triangles(8));
    let limit = 0.05;
    let (_, r) = stored(&m, &config.with_error_limit(1e6));
    assert_eq!(r.stop, Stop::Target);
    assert!(r.collapse_error > 2.0 * limit, "{}", r.collapse_error);
    let (out, r) = stored(&m, &config.with_error_limit(limit));
    assert_limited("stored", &m, apex, &out, &r, limit);
}

#[test]
fn a_limit_nothing_reaches_changes_nothing() {
    // On a gentle wave no collapse down to 10 % comes near the limit: the output is the
    // unlimited one, byte for byte.
    let m = grid(24, 24, 0.05);
    let config = Config::new().with_ratio(0.1);
    let (a, ra) = simplify(&m, &config);
    let (b, rb) = simplify(&m, &config.with_relative_error_limit(0.5, &m.positions));
    assert_eq!(a.triangles, b.triangles);
    assert_eq!(ra.stop, Stop::Target);
    assert_eq!(rb.stop, Stop::Target);
    assert_eq!(rb.over_limit, 0);
    assert!(rb.collapse_error > 0.0);
}

/// Vertex decimation measures each removal's own error too: the removed vertex's distance to
/// the farthest plane of its new triangles (or the boundary's retreat). On the cow down to
/// 2 %: without a limit some removal is over 1 % of the diagonal; with that limit the run
/// stops on it, every removal under it, and the output valid.
#[test]
fn the_limit_holds_with_vertex_decimation() {
    let m = load_obj("cow.obj");
    let config = Config::new().with_ratio(0.02);
    let limit = 0.01 * diagonal(&m);
    let (_, r) = decimate(&m, &config.with_error_limit(1e6));
    assert!(r.collapse_error > limit, "{r:?}");
    let (out, r) = decimate(&m, &config.with_error_limit(limit));
    assert_eq!(r.stop, Stop::ErrorLimit, "{r:?}");
    assert!(r.over_limit > 0);
    assert!(r.collapse_error <= limit, "{} > {limit}", r.collapse_error);
    assert!(out.triangles.len() < m.triangles.len() / 4, "{r:?}");
    assert_valid("cow", &m, &out, &r);
}

/// The bounding box's diagonal.
fn diagonal(m: &MeshData) -> f32 {
    let (mut lo, mut hi) = ([f32::MAX; 3], [f32::MIN; 3]);
    for p in &m.positions {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f32>().sqrt()
}

/// The pipeline's modes (`pipeline::FastWorkspace`, `pipeline::LeanWorkspace`) price from
/// their quadrics over their weights, the same mean squared distance as the stored quadric:
/// the same promises on the spike.
#[cfg(feature = "fast")]
#[test]
fn the_limit_holds_in_the_fast_and_lean_modes() {
    use tinydecimate::pipeline::{FastWorkspace, LeanWorkspace};
    let (m, apex) = spike();
    for lean in [false, true] {
        let what = if lean { "lean" } else { "fast" };
        let run = |config: &Config| {
            let mut tris = m.triangles.clone();
            let r = if lean {
                Box::new(LeanWorkspace::<u16, 400, 600>::new())
                    .as_mut()
                    .simplify(&m.positions, &mut tris, config)
            } else {
                Box::new(FastWorkspace::<u16, 400, 600>::new())
                    .as_mut()
                    .simplify(&m.positions, &mut tris, config)
            }
            .expect(what);
            output(&m.positions, tris, r)
        };
        let config = Config::new().with_target(Target::Triangles(8));
        // The pipeline refuses more of the spike than the greedy engines: its largest collapse
        // without a limit is under 0.05, so the limit here is lower.
        let limit = 0.02;
        let (_, r) = run(&config);
        assert_eq!(r.collapse_error, 0.0, "{what}: tracked only with a limit");
        let (_, r) = run(&config.with_error_limit(1e6));
        assert_eq!(r.over_limit, 0, "{what}");
        assert!(r.collapse_error > 2.0 * limit, "{what}: {r:?}");
        let (out, r) = run(&config.with_error_limit(limit));
        assert_limited(what, &m, apex, &out, &r, limit);
    }
}
