//! Deterministic termination, measured: the number of operations `step` performs is bounded by
//! the mesh size.
//!
//! Proof sketch (also in `src/engine/mod.rs`). Every collapse removes a vertex, so there are at
//! most V collapses. Sweeps (feature mean, flags, keys, pairing) visit each vertex once per
//! pass or round, and a pass or round without a collapse ends the run, so there are at most
//! min(max_passes, collapses + 1) of them; greedy also refreshes its feature threshold with one
//! sweep each time the mesh halves, at most log2(T) + 1 times. A queue pop either collapses, drops the vertex, or
//! re-queues it at its exact current cost, which the next pop of that vertex accepts unless a
//! collapse intervened; so between two collapses each queued vertex is popped at most twice.

mod common;
use common::*;
use tinydecimate::EdgeCollapse;
use tinydecimate::{Config, Schedule, Workspace};

fn operations(m: &MeshData, config: &Config) -> (u64, usize, u32) {
    let mut tris = m.triangles.clone();
    let mut ws = BIG.lock().unwrap_or_else(|e| e.into_inner());
    let mut s = ws
        .start(
            tinydecimate::Positions::Read(&m.positions),
            &mut tris,
            config,
            tinydecimate::Builtin::new(),
            tinydecimate::NoBound,
            EdgeCollapse,
        )
        .unwrap();
    let mut ops = 0u64;
    while !s.step(1) {
        ops += 1;
    }
    let r = s.finish();
    (ops, r.collapses, r.passes)
}

#[test]
fn operations_are_bounded_by_the_mesh_size() {
    for (name, m) in [
        ("cow", load_obj("cow.obj")),
        ("camelhead", load_obj("camelhead.obj")),
        ("sphere", icosphere(4)),
        ("grid", grid(40, 30, 0.2)),
    ] {
        let (v, t) = (m.positions.len() as u64, m.triangles.len() as u64);
        let mut configs = vec![
            Config::new().with_ratio(0.0),
            Config::paper().with_ratio(0.0),
        ];
        if cfg!(feature = "batched") {
            configs.push(
                Config::new()
                    .with_ratio(0.0)
                    .with_schedule(Schedule::Batched),
            );
        }
        for config in configs {
            let (ops, collapses, passes) = operations(&m, &config);
            // Sweeps: 3 per pass/round over V vertices, and one per halving of the mesh
            // (greedy's threshold refresh); queue: pops per collapse.
            let halvings = 64 - t.leading_zeros() as u64;
            let sweeps = 3 * v * passes as u64 + v * halvings;
            let per_collapse = (ops - sweeps.min(ops)) as f64 / collapses.max(1) as f64;
            eprintln!(
                "{name} {:?}: V {v} T {t}: {ops} operations, {collapses} collapses, {passes} passes; {per_collapse:.2} non-sweep operations per collapse",
                config.schedule()
            );
            assert!(
                (collapses as u64) < v,
                "{name}: a collapse removes a vertex"
            );
            assert!(passes <= config.max_passes());
            // The proof's bound is far looser (O(V) pops between collapses); in practice the
            // queue needs about one pop per collapse (on these four meshes every run stays
            // within the sweep allowance alone). 2 per collapse is what this claims, and fails a
            // regression that loses track of its keys.
            match config.schedule() {
                Schedule::Greedy => assert!(
                    ops <= sweeps + 2 * (collapses as u64 + 1) + v,
                    "{name}: {ops} operations"
                ),
                Schedule::Passes => assert!(ops <= (v + 1) * 3 * passes as u64 + 1),
                // Per pass: one pricing sweep, and a pop per priced vertex or re-queued one.
                Schedule::Batched => assert!(
                    ops <= 2 * (v + 1) * passes as u64 + v * halvings + 2 * collapses as u64,
                    "{name}: {ops} operations"
                ),
            }
            assert!(ops <= 3 * v * config.max_passes() as u64 + v * halvings + 2 * t);
        }
    }
}

#[test]
fn a_workspace_is_reusable_and_runs_are_repeatable() {
    let m = load_obj("cow.obj");
    let mut ws = Workspace::<u16, 4096, 8192>::new();
    let mut first = m.triangles.clone();
    let r1 = ws
        .simplify(&m.positions, &mut first, &Config::new())
        .unwrap();
    // Something else in between, with other sizes.
    let s = icosphere(2);
    let mut other = s.triangles.clone();
    ws.simplify(&s.positions, &mut other, &Config::paper().with_ratio(0.3))
        .unwrap();
    let mut second = m.triangles.clone();
    let r2 = ws
        .simplify(&m.positions, &mut second, &Config::new())
        .unwrap();
    assert_eq!(r1, r2);
    assert_eq!(first[..r1.triangles_out], second[..r2.triangles_out]);
}

/// Stored quadrics without the feature rule (`Config::stored()`): a stale key goes back in at
/// the vertex's cheapest price before any rule runs, so a pop may re-queue a vertex at a
/// refused candidate's price first; still strictly higher each time, so the proof's bound
/// holds, and in practice the queue stays near one pop per collapse.
#[test]
fn stored_operations_are_bounded_by_the_mesh_size() {
    use tinydecimate::cost::{Placement, StoredQuadric, VertexQuadric};
    for (name, m) in [("cow", load_obj("cow.obj")), ("grid", grid(40, 30, 0.2))] {
        let (v, t) = (m.positions.len() as u64, m.triangles.len() as u64);
        for placement in [Placement::Subset, Placement::Optimal] {
            let config = Config::stored().with_ratio(0.0);
            let mut tris = m.triangles.clone();
            let mut pos = m.positions.clone();
            let mut q: Vec<VertexQuadric> = vec![[0.0; 10]; pos.len()];
            let cost = StoredQuadric::new(&mut q, placement);
            let mut ws = BIG.lock().unwrap_or_else(|e| e.into_inner());
            let mut s = match placement {
                Placement::Subset => ws.start(
                    tinydecimate::Positions::Read(&m.positions),
                    &mut tris,
                    &config,
                    cost,
                    tinydecimate::NoBound,
                    EdgeCollapse,
                ),
                Placement::Optimal => ws.start(
                    tinydecimate::Positions::Write(&mut pos),
                    &mut tris,
                    &config,
                    cost,
                    tinydecimate::NoBound,
                    EdgeCollapse,
                ),
            }
            .unwrap();
            let mut ops = 0u64;
            while !s.step(1) {
                ops += 1;
            }
            let r = s.finish();
            let halvings = 64 - t.leading_zeros() as u64;
            // Sweeps: the quadrics' init once and the keys per round, V + 1 operations each;
            // the feature sweeps (each round's and each halving's) take 2 operations, as
            // nothing reads them.
            let passes = r.passes as u64;
            let sweeps = (v + 1) * (1 + passes) + 2 * (passes + halvings);
            let pops = ops.saturating_sub(sweeps);
            eprintln!(
                "{name} {placement:?}: V {v}: {ops} operations, {} collapses, {} passes, {:.2} pops per collapse",
                r.collapses,
                r.passes,
                pops as f64 / r.collapses.max(1) as f64
            );
            assert!((r.collapses as u64) < v);
            // Measured 1.8-3.0 pops per collapse (the collapse's own and the stale keys'
            // re-queues); 4 is the claim, and fails a queue that loses track of its keys.
            assert!(
                ops <= sweeps + 4 * (r.collapses as u64 + 1),
                "{name} {placement:?}: {ops} operations"
            );
        }
    }
}
