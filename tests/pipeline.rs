//! The pipeline's two modes (crate feature `fast`), the fast one (`pipeline::FastWorkspace`)
//! and the lean one (`pipeline::LeanWorkspace`): every shared mesh at 50 %, 25 % and 10 %
//! gives a valid output (the shared checker, topology included); bad input is a typed error
//! with the buffer untouched; two runs give the same bytes.
#![cfg(feature = "fast")]

mod common;
use common::*;
use std::sync::Mutex;
use tinydecimate::pipeline::{FastWorkspace, LeanWorkspace};
use tinydecimate::{Capacity, Config, Error, Report, Stop};

static BIG_FAST: Mutex<FastWorkspace<u32, 65_536, 131_072>> = Mutex::new(FastWorkspace::new());
static BIG_LEAN: Mutex<LeanWorkspace<u32, 65_536, 131_072>> = Mutex::new(LeanWorkspace::new());

use common::{modes, Mode};

fn fixtures() -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(shared_meshes())
        .unwrap()
        .filter_map(|e| {
            let n = e.unwrap().file_name().into_string().unwrap();
            n.ends_with(".obj").then_some(n)
        })
        .collect();
    names.sort();
    names
}

fn run(mode: Mode, m: &MeshData, ratio: f32) -> (MeshData, Report) {
    run_with(mode, m, &Config::new().with_ratio(ratio))
}

fn run_with(mode: Mode, m: &MeshData, config: &Config) -> (MeshData, Report) {
    let mut tris = m.triangles.clone();
    let r = match mode {
        Mode::Fast => BIG_FAST.lock().unwrap_or_else(|e| e.into_inner()).simplify(
            &m.positions,
            &mut tris,
            config,
        ),
        Mode::Lean => BIG_LEAN.lock().unwrap_or_else(|e| e.into_inner()).simplify(
            &m.positions,
            &mut tris,
            config,
        ),
    }
    .expect("simplify");
    output(&m.positions, tris, r)
}

#[test]
fn every_fixture_at_50_25_10_percent_is_valid() {
    let mut failures = Vec::new();
    for name in fixtures() {
        let input = load_obj(&name);
        for (mode, ratio) in modes()
            .into_iter()
            .flat_map(|m| [(m, 0.5f32), (m, 0.25), (m, 0.1)])
        {
            let t0 = std::time::Instant::now();
            let (out, r) = run(mode, &input, ratio);
            let dt = t0.elapsed();
            let v = verdict(&input, &out);
            eprintln!(
                "{mode:?} {name} {ratio}: {} -> {} (target {}, {:?}, {} passes, {} collapses, locked {}) in {dt:.2?} {} rejected [{}]",
                r.triangles_in,
                r.triangles_out,
                r.target_triangles,
                r.stop,
                r.passes,
                r.collapses,
                r.locked_vertices,
                if v.is_valid() { "VALID" } else { "INVALID" },
                r.rejected,
            );
            if !v.is_valid() {
                failures.push(format!("{mode:?} {name} {ratio}:\n{}", v.describe(5)));
            }
            assert_eq!(r.triangles_out, out.triangles.len());
            if r.stop == Stop::Target {
                assert!(r.target_reached, "{name} {ratio}");
            } else {
                assert!(!r.target_reached, "{name} {ratio}");
            }
            // On clean meshes the topology was compared (Euler characteristic, loops).
            if v.topology_compared {
                assert!(
                    v.euler_unchanged() && v.boundary_loops_unchanged(),
                    "{name}"
                );
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn the_target_is_reached_on_clean_closed_meshes() {
    for name in ["cow.obj", "spot.obj", "stanford_bunny.obj", "armadillo.obj"] {
        let input = load_obj(name);
        for (mode, ratio) in modes()
            .into_iter()
            .flat_map(|m| [(m, 0.5f32), (m, 0.25), (m, 0.1)])
        {
            let (_, r) = run(mode, &input, ratio);
            assert_eq!(r.stop, Stop::Target, "{mode:?} {name} {ratio}: {r:?}");
        }
    }
}

#[test]
fn generated_meshes_are_valid() {
    for (what, m) in [
        ("icosphere", icosphere(4)),
        ("grid", grid(30, 20, 0.2)),
        ("cube", cube(8)),
        ("fin_and_pinch", fin_and_pinch(12)),
    ] {
        for mode in modes() {
            for ratio in [0.5f32, 0.25, 0.1, 0.0] {
                let (out, r) = run(mode, &m, ratio);
                let v = verdict(&m, &out);
                assert!(
                    v.is_valid(),
                    "{mode:?} {what} {ratio}: {r:?}\n{}",
                    v.describe(10)
                );
            }
        }
    }
}

#[test]
fn two_runs_give_the_same_bytes() {
    let m = load_obj("cow.obj");
    for mode in modes() {
        let (a, ra) = run(mode, &m, 0.1);
        let (b, rb) = run(mode, &m, 0.1);
        assert_eq!(a.triangles, b.triangles, "{mode:?}");
        assert_eq!(ra, rb, "{mode:?}");
        // A fresh workspace too (nothing read before it is written).
        let mut tris = m.triangles.clone();
        let config = Config::new().with_ratio(0.1);
        let r = match mode {
            Mode::Fast => Box::new(FastWorkspace::<u16, 4096, 8192>::new())
                .as_mut()
                .simplify(&m.positions, &mut tris, &config),
            Mode::Lean => Box::new(LeanWorkspace::<u16, 4096, 8192>::new())
                .as_mut()
                .simplify(&m.positions, &mut tris, &config),
        }
        .unwrap();
        tris.truncate(r.triangles_out);
        assert_eq!(
            tris, a.triangles,
            "{mode:?}: u16 links, another workspace: same bytes"
        );
    }
}

/// Bad input to `$ws::simplify`: a typed error, the buffer untouched.
macro_rules! bad_input {
    ($ws:ident) => {{
        let m = icosphere(2);
        let config = Config::new();
        let mut ws: Box<$ws<u16, 200, 400>> = Box::new($ws::new());

        // NaN position.
        let mut p = m.positions.clone();
        p[7][1] = f32::NAN;
        let mut tris = m.triangles.clone();
        assert_eq!(
            ws.simplify(&p, &mut tris, &config),
            Err(Error::NonFinitePosition { vertex: 7 })
        );
        assert_eq!(tris, m.triangles);
        p[7][1] = f32::INFINITY;
        assert_eq!(
            ws.simplify(&p, &mut tris, &config),
            Err(Error::NonFinitePosition { vertex: 7 })
        );
        assert_eq!(tris, m.triangles);

        // Out-of-range index.
        let mut bad = m.triangles.clone();
        bad[100][2] = 5000;
        let before = bad.clone();
        assert_eq!(
            ws.simplify(&m.positions, &mut bad, &config),
            Err(Error::IndexOutOfRange {
                triangle: 100,
                index: 5000
            })
        );
        assert_eq!(bad, before);

        // Over capacity: vertices, then triangles.
        let mut small: Box<$ws<u16, 100, 400>> = Box::new($ws::new());
        let mut tris = m.triangles.clone();
        assert_eq!(
            small.simplify(&m.positions, &mut tris, &config),
            Err(Error::Capacity {
                what: Capacity::Vertices,
                needed: 162,
                available: 100
            })
        );
        let mut small: Box<$ws<u16, 200, 300>> = Box::new($ws::new());
        assert_eq!(
            small.simplify(&m.positions, &mut tris, &config),
            Err(Error::Capacity {
                what: Capacity::Triangles,
                needed: 320,
                available: 300
            })
        );
        assert_eq!(tris, m.triangles);

        // A configuration out of range.
        assert!(matches!(
            ws.simplify(&m.positions, &mut tris, &Config::new().with_ratio(1.5)),
            Err(Error::InvalidConfig { .. })
        ));
        assert_eq!(tris, m.triangles);
    }};
}

#[test]
fn bad_input_is_a_typed_error_and_the_buffer_is_untouched() {
    bad_input!(FastWorkspace);
    bad_input!(LeanWorkspace);
}

#[test]
fn bytes_per_triangle_with_u16_links() {
    // The cow: 2 903 vertices, 5 804 triangles.
    type Cow = FastWorkspace<u16, 2903, 5804>;
    let per = Cow::BYTES as f64 / 5804.0;
    eprintln!(
        "FastWorkspace<u16, 2903, 5804>::BYTES = {} ({per:.2} B per triangle)",
        Cow::BYTES
    );
    assert!(per <= 25.0, "{per}");
    // Without the fixed histogram, V = T/2: 24.5 B (a 24-byte quadric, four links, a cost and
    // a flag byte per vertex; three fan list entries per triangle).
    type Half = FastWorkspace<u16, 32_000, 64_000>;
    let per = Half::BYTES as f64 / 64_000.0;
    eprintln!(
        "FastWorkspace<u16, 32000, 64000>::BYTES = {} ({per:.2} B per triangle)",
        Half::BYTES
    );
    assert!(per <= 24.6, "{per}");
    // The lean mode: the same without the quadric and the border successor, 11.5 B.
    type Lean = LeanWorkspace<u16, 32_000, 64_000>;
    let per = Lean::BYTES as f64 / 64_000.0;
    eprintln!(
        "LeanWorkspace<u16, 32000, 64000>::BYTES = {} ({per:.2} B per triangle)",
        Lean::BYTES
    );
    assert!(per <= 11.6, "{per}");
}

#[test]
fn small_closed_meshes_keep_their_topology() {
    // A tetrahedron: every collapse would turn a's last triangle into a copy of one of b's,
    // turned over (the link condition passes: the common neighbours are the two opposite
    // vertices); the duplicate rule refuses it, and so does the fold rule (a copy turned over
    // faces the other way). An octahedron and an icosahedron towards nothing.
    let tetra = tetrahedron();
    let mut octa = MeshData {
        positions: Vec::new(),
        triangles: Vec::new(),
    };
    octahedron(&mut octa, [0.0; 3], 1.0);
    for (what, m) in [
        ("tetrahedron", tetra),
        ("octahedron", octa),
        ("icosahedron", icosphere(0)),
    ] {
        for mode in modes() {
            let (out, r) = run(mode, &m, 0.0);
            let v = verdict(&m, &out);
            eprintln!(
                "{mode:?} {what}: {} -> {} {:?}",
                r.triangles_in, r.triangles_out, r.stop
            );
            assert!(v.is_valid(), "{mode:?} {what}: {r:?}\n{}", v.describe(10));
            assert_eq!(r.stop, Stop::NoLegalCollapse, "{mode:?} {what}");
        }
    }
}

/// The rules that no validity check can see fire where they are meant to: the flip test
/// (`normal_turn`) and the zero-area test (`sliver`) on real meshes, the duplicate rule on the
/// tetrahedron (checked before the fold rule, which would refuse the same collapse). With any
/// of them switched off (`PIPELINE_RULE_OFF=flip|area|duplicate`) its count is zero and this
/// fails, as the validity tests fail for the others.
#[test]
fn each_rule_fires_where_it_should() {
    let count = |r: &Report, name: &str| {
        r.rejected
            .iter()
            .find(|(rule, _)| rule.name == name)
            .map_or(0, |(_, n)| n)
    };
    for mode in modes() {
        let (mut turn, mut sliver) = (0, 0);
        for name in [
            "cow.obj",
            "fandisk.obj",
            "tray_bottom.obj",
            "pr2_sensor_mount.obj",
        ] {
            let (_, r) = run(mode, &load_obj(name), 0.1);
            turn += count(&r, "normal_turn");
            sliver += count(&r, "sliver");
        }
        assert!(turn > 0, "{mode:?}: the flip test never refused");
        assert!(sliver > 0, "{mode:?}: the zero-area test never refused");
        let tetra = tetrahedron();
        let (_, r) = run(mode, &tetra, 0.0);
        assert!(count(&r, "duplicate") > 0, "{mode:?}: {r:?}");
    }
}

/// Pruning (`Config::prune_parts`): the sheet with ten small octahedra beside it reaches a
/// target its parts would keep it from; each part is all there or all gone, the smallest go
/// first, the report counts them and the output is valid with parts gone whole.
#[test]
fn small_parts_vanish_whole_when_pruning() {
    let (m, parts) = sheet_and_bolts();
    for mode in modes() {
        let keep = Config::new().with_ratio(0.02);
        let (out, report) = run_with(mode, &m, &keep);
        assert_eq!(report.parts_removed, 0, "{mode:?}");
        // Ten closed parts of at least four triangles each: 24 triangles are out of reach.
        assert!(!report.target_reached, "{mode:?}: {report:?}");
        for p in &parts {
            assert!(kept_of(&m, &out, p).0 > 0, "{mode:?}: part {p:?} lost");
        }
        assert_valid("sheet and bolts, kept", &m, &out, &report);

        let (out, report) = run_with(mode, &m, &keep.with_prune_parts(true));
        assert!(report.target_reached, "{mode:?}: {report:?}");
        let mut gone = 0;
        for p in &parts {
            let (kept, total) = kept_of(&m, &out, p);
            assert!(
                kept == 0 || kept == total,
                "{mode:?}: part {p:?}: {kept} of {total}"
            );
            gone += usize::from(kept == 0);
        }
        assert!(gone > 0);
        assert_eq!(gone, report.parts_removed, "{mode:?}: {report:?}");
        // A collapse removes a vertex, a part all it has left.
        let used = |t: &[[u32; 3]]| {
            t.iter()
                .flatten()
                .collect::<std::collections::BTreeSet<_>>()
                .len()
        };
        assert_eq!(
            report.vertices_removed,
            used(&m.triangles) - used(&out.triangles),
            "{mode:?}: {report:?}"
        );
        assert!(report.vertices_removed > report.collapses);
        let left: Vec<usize> = (0..parts.len())
            .filter(|&i| kept_of(&m, &out, &parts[i]).0 > 0)
            .collect();
        assert!(
            left.iter().all(|&i| i >= parts.len() - left.len()),
            "{mode:?}: {left:?}"
        );
        assert!(
            kept_of(&m, &out, &(0..25 * 25)).0 > 0,
            "{mode:?}: the sheet went"
        );
        let v = parts_verdict(&m, &out);
        v.assert_valid("sheet and bolts, pruned");
        assert_eq!(v.parts_removed, report.parts_removed);
    }
}

/// Pruning never empties a mesh: of five octahedra towards no triangle the largest stays;
/// and an error limit below every part's size removes none.
#[test]
fn the_largest_part_stays_and_the_error_limit_holds() {
    let mut m = MeshData::default();
    for i in 0..5 {
        octahedron(&mut m, [i as f32, 0.0, 0.0], 0.1 + 0.05 * i as f32);
    }
    for mode in modes() {
        let config = Config::new().with_ratio(0.0).with_prune_parts(true);
        let (out, report) = run_with(mode, &m, &config);
        assert_eq!(report.parts_removed, 4, "{mode:?}: {report:?}");
        let left: std::collections::BTreeSet<u32> =
            out.triangles.iter().flatten().copied().collect();
        assert!(
            !left.is_empty() && left.iter().all(|&v| v >= 24),
            "{mode:?}: {left:?}"
        );
        parts_verdict(&m, &out).assert_valid("octahedra");

        let (out, report) = run_with(mode, &m, &config.with_error_limit(0.05));
        assert_eq!(report.parts_removed, 0, "{mode:?}: {report:?}");
        assert_valid("octahedra, limited", &m, &out, &report);
    }
}

/// One part is the largest part and never goes: the cow prunes to the same bytes.
#[test]
fn one_part_prunes_to_the_same_bytes() {
    let m = load_obj("cow.obj");
    for mode in modes() {
        let config = Config::new().with_ratio(0.1);
        let (with, r_with) = run_with(mode, &m, &config.with_prune_parts(true));
        let (without, _) = run_with(mode, &m, &config);
        assert_eq!(r_with.parts_removed, 0, "{mode:?}");
        assert_eq!(with.triangles, without.triangles, "{mode:?}");
    }
}
