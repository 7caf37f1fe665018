//! Pruning parts (`Simplifier::with_parts`, crate feature `parts`): what it promises on real
//! output, through the shared checker.
//!
//! * `small_parts_vanish_whole`: a wavy sheet with small closed parts beside it reaches its
//!   target; each small part is either all there or all gone, the gone ones are what the
//!   report counts, and the sheet is a valid simplification (meshcheck with `parts`).
//! * `keeping_parts_loses_none`: the same mesh without `with_parts` keeps every part, leaves
//!   the sheet fewer triangles, and stops short of a target that pruning reaches.
//! * `the_last_part_stays`: small parts only and a target of one triangle: never empty.
//! * `one_part_runs_as_without_parts`: the cow (one part) gives the same triangles with and
//!   without `with_parts`.
//! * `stepping_prunes_as_one_run`: a run in steps of one operation gives the same bytes.
//! * `refusals`: passes schedule, an error bound, short links, after the first step.
//! * `shared_meshes_reach_their_target`: pr2_sensor_mount and pins at 10 %.
#![cfg(feature = "parts")]

mod common;
use std::collections::BTreeSet;

use common::*;
use tinydecimate::{
    bound, Builtin, Capacity, Config, ConfigField, Controls, EdgeCollapse, Error, NoBound,
    Positions, Report, Schedule, Stop, Workspace,
};

/// Runs the default configuration at `ratio` on `m` (u32 links), pruning with `prune`; the
/// output in the input's numbering.
fn run(m: &MeshData, ratio: f32, prune: bool) -> (MeshData, Report) {
    let mut tris = m.triangles.clone();
    let mut links = vec![[0u32; 2]; m.positions.len()];
    let mut ws = BIG.lock().unwrap_or_else(|e| e.into_inner());
    let config = Config::new().with_ratio(ratio);
    let s = ws
        .start(
            Positions::Read(&m.positions),
            &mut tris,
            &config,
            Builtin::new(),
            NoBound,
            EdgeCollapse,
        )
        .expect("start");
    let s = if prune {
        s.with_parts(&mut links).expect("parts")
    } else {
        s
    };
    let report = s.run();
    output(&m.positions, tris, report)
}

#[test]
fn small_parts_vanish_whole() {
    let (m, parts) = sheet_and_bolts();
    let (out, report) = run(&m, 0.05, true);
    assert!(report.target_reached, "{report:?}");
    assert!(report.parts_removed > 0, "{report:?}");
    let mut gone = 0;
    for p in &parts {
        let (kept, total) = kept_of(&m, &out, p);
        // Whole or nothing: an octahedron never collapses below itself with the link rule,
        // and pruning takes every triangle of a part at once.
        assert!(kept == 0 || kept == total, "part {p:?}: {kept} of {total}");
        gone += usize::from(kept == 0);
    }
    assert_eq!(gone, report.parts_removed, "{report:?}");
    // The smallest go first: the parts left are the largest ones.
    let left: Vec<usize> = (0..parts.len())
        .filter(|&i| kept_of(&m, &out, &parts[i]).0 > 0)
        .collect();
    assert!(
        left.iter().all(|&i| i >= parts.len() - left.len()),
        "{left:?}"
    );
    // The sheet is still there and the whole output valid, its parts gone whole.
    let sheet = 0..25 * 25;
    assert!(kept_of(&m, &out, &sheet).0 > 0);
    let v = parts_verdict(&m, &out);
    v.assert_valid("sheet and bolts, pruned");
    assert_eq!(v.parts_removed, report.parts_removed);
    // The plain checker calls the same output a lost component.
    assert!(!verdict(&m, &out).is_valid());
}

#[test]
fn keeping_parts_loses_none() {
    let (m, parts) = sheet_and_bolts();
    let (out, report) = run(&m, 0.05, false);
    assert_eq!(report.parts_removed, 0);
    for p in &parts {
        let (kept, total) = kept_of(&m, &out, p);
        assert!(kept > 0 && kept <= total, "part {p:?}");
    }
    assert_valid("sheet and bolts, kept", &m, &out, &report);
    // The parts hold on to the budget: pruning leaves the sheet more of it.
    let sheet = 0..25 * 25;
    let (pruned, _) = run(&m, 0.05, true);
    assert!(
        kept_of(&m, &pruned, &sheet).0 > kept_of(&m, &out, &sheet).0,
        "sheet: {} pruned, {} kept",
        kept_of(&m, &pruned, &sheet).0,
        kept_of(&m, &out, &sheet).0
    );
    // Ten closed parts of at least four triangles each: 24 triangles are out of reach.
    let (_, report) = run(&m, 0.02, false);
    assert!(!report.target_reached, "{report:?}");
    let (out, report) = run(&m, 0.02, true);
    assert!(report.target_reached, "{report:?}");
    parts_verdict(&m, &out).assert_valid("sheet and bolts at 2 %");
}

#[test]
fn the_last_part_stays() {
    let mut m = MeshData::default();
    for i in 0..5 {
        octahedron(&mut m, [i as f32, 0.0, 0.0], 0.1 + 0.05 * i as f32);
    }
    let (out, report) = run(&m, 0.0, true);
    assert_eq!(report.parts_removed, 4, "{report:?}");
    assert_eq!(report.stop, Stop::NoLegalCollapse);
    assert!(!out.triangles.is_empty());
    // The one left is the largest.
    let left: BTreeSet<u32> = out.triangles.iter().flatten().copied().collect();
    assert!(left.iter().all(|&v| v >= 24), "{left:?}");
    parts_verdict(&m, &out).assert_valid("octahedra");
}

/// One part is the last part and never goes: the cow runs as without `with_parts`.
#[test]
fn one_part_runs_as_without_parts() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/cow.obj");
    let m = parse_obj(&std::fs::read_to_string(path).expect("cow"));
    let (with, r_with) = run(&m, 0.1, true);
    let (without, r_without) = run(&m, 0.1, false);
    assert_eq!(r_with.parts_removed, 0, "{r_with:?}");
    assert_eq!(r_with.collapses, r_without.collapses);
    assert_eq!(with.triangles, without.triangles);
    parts_verdict(&m, &with).assert_valid("cow");
}

#[test]
fn stepping_prunes_as_one_run() {
    let (m, _) = sheet_and_bolts();
    let (one, report) = run(&m, 0.05, true);
    let mut tris = m.triangles.clone();
    let mut links = vec![[0u16; 2]; m.positions.len()];
    let mut ws = Workspace::<u16, 1024, 2048>::new();
    let config = Config::new().with_ratio(0.05);
    let mut s = ws
        .start(
            Positions::Read(&m.positions),
            &mut tris,
            &config,
            Builtin::new(),
            NoBound,
            EdgeCollapse,
        )
        .expect("start")
        .with_parts(&mut links)
        .expect("parts");
    while !s.step(1) {}
    let stepped = s.finish();
    assert_eq!(stepped, report);
    let stepped: Vec<[u32; 3]> = tris[..stepped.triangles_out]
        .iter()
        .map(|t| t.map(u32::from))
        .collect();
    assert_eq!(stepped, one.triangles);
}

#[test]
fn refusals() {
    let (m, _) = sheet_and_bolts();
    let mut tris = m.triangles.clone();
    let mut ws = BIG.lock().unwrap_or_else(|e| e.into_inner());
    let parts_field = Err(Error::InvalidConfig {
        field: ConfigField::Parts,
    });
    let nv = m.positions.len();
    let mut links = vec![[0u32; 2]; nv];
    macro_rules! start {
        ($config:expr) => {
            ws.start(
                Positions::Read(&m.positions),
                &mut tris,
                &$config,
                Builtin::new(),
                NoBound,
                EdgeCollapse,
            )
            .expect("start")
        };
    }
    let passes = Config::paper().with_schedule(Schedule::Passes);
    assert_eq!(
        start!(passes).with_parts(&mut links).map(|_| ()),
        parts_field
    );
    assert_eq!(
        start!(Config::new())
            .with_parts(&mut links[..nv - 1])
            .map(|_| ()),
        Err(Error::Capacity {
            what: Capacity::Vertices,
            needed: nv,
            available: nv - 1
        })
    );
    let mut s = start!(Config::new());
    s.step(1);
    assert_eq!(s.with_parts(&mut links).map(|_| ()), parts_field);
    let mut log = vec![[0u32; 2]; nv];
    assert_eq!(
        start!(Config::new())
            .record_into(&mut log)
            .with_parts(&mut links)
            .map(|_| ()),
        parts_field
    );
    // An error bound: its control points live on the triangles.
    let original = m.triangles.clone();
    let mut control = vec![0u32; bound::control_len(original.len(), nv)];
    let bounded = ws
        .start(
            Positions::Read(&m.positions),
            &mut tris,
            &Config::new().with_ratio(0.1).with_max_error(0.05),
            Builtin::new(),
            Controls::new(&original, &mut control),
            EdgeCollapse,
        )
        .expect("start");
    assert_eq!(bounded.with_parts(&mut links).map(|_| ()), parts_field);
}

#[test]
fn shared_meshes_reach_their_target() {
    for name in ["pr2_sensor_mount.obj", "pins.obj"] {
        let m = load_obj(name);
        let (out, report) = run(&m, 0.1, true);
        assert!(report.target_reached, "{name}: {report:?}");
        parts_verdict(&m, &out).assert_valid(name);
    }
}
