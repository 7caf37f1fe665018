//! One test per legality rule (`tinydecimate::RULES`, in `src/policy/legality/mod.rs`), each asserting a
//! property of real output that the rule exists to keep. `scripts/rules-off.sh` builds the
//! library with each rule switched off in turn (`TINYDECIMATE_RULE_OFF`) and checks that these
//! tests then fail. The table below has one row per rule of `RULES`, in its order, and
//! `every_rule_has_a_row_and_a_test` fails when a rule has no row or a row names no test.
//!
//! | rule          | property                                                                  | test |
//! |---------------|---------------------------------------------------------------------------|------|
//! | `locked`      | non-manifold, pinched and inconsistently wound parts stay as they were; an interior vertex may still move onto a locked one | `locked_parts_stay_untouched`, `interior_vertices_move_onto_locked_ones` |
//! | `feature`     | a vertex that is a feature before an operation is still used after it       | `features_survive_every_operation` |
//! | `boundary`    | boundaries only shrink along themselves: loops, vertices, no longer length  | `boundaries_keep_loops_vertices_and_length` |
//! | `link`        | no new pinched vertex or non-manifold edge (shared checker)                 | `no_new_pinch_or_non_manifold_edge` |
//! | `duplicate`   | no duplicate output triangle (shared checker); redundant with `fold` on output, so also: the tetrahedra's collapses are refused as duplicates (`Report::rejected`) | `no_duplicate_triangles_on_tetrahedral_parts`, `tetrahedra_are_kept_whole_by_the_duplicate_rule` |
//! | `normal_turn` | no live triangle slot turns by more than `max_normal_turn_deg` in one operation | `no_operation_turns_a_triangle_too_far` |
//! | `sliver`      | no operation leaves a zero-area triangle, or one below `min_quality` that got worse and left its plane | `no_operation_makes_a_sliver` |
//! | `fold`        | no new folded pair, even with the turn limit at 179° (shared checker)       | `no_new_folds_when_only_the_fold_rule_guards` |
//! | `bound`       | no control point ends farther than `max_error` from the output (an independent f64 measure, in `tests/bound.rs`) | `generated_meshes_stay_within_the_bound`, `fixtures_stay_within_the_bound` |
//! | `seam`        | with welded seams, no output triangle takes corners from both sides of a seam, and no crack (`tests/seams.rs`, crate feature `seams`) | `seams_keep_their_shape_and_sides` |

mod common;
use std::collections::BTreeSet;

use common::*;
use tinydecimate::EdgeCollapse;
use tinydecimate::{Config, Reject, Report, Schedule, RULES};

/// A mesh of `tests/fixtures`.
fn fixture(name: &str) -> MeshData {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures")
        .join(name);
    parse_obj(&std::fs::read_to_string(&path).unwrap())
}

/// A triangle that turns by less than this (degrees) stays in its plane (the library's limit is
/// about 1°; the margin is rounding).
const PLANAR_DEG: f64 = 1.1;

/// What happened between two operations.
#[derive(Default)]
struct Steps {
    /// (operation, vertex): a feature before the operation, unused after it.
    removed_features: Vec<(usize, usize)>,
    /// (operation, slot, degrees): a live slot whose normal turned beyond the limit.
    turned: Vec<(usize, usize, f64)>,
    /// (operation, slot, quality before, after): a live slot that became a sliver.
    slivers: Vec<(usize, usize, f64, f64)>,
    operations: usize,
}

/// Drives `Workspace::start` with `step(1)` to the end and records, for every operation, the
/// features it removed and the live triangle slots whose shape it spoiled.
fn step_by_step(m: &MeshData, config: &Config) -> (MeshData, Report, Steps) {
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
        .expect("start");
    let mut steps = Steps::default();
    let nv = m.positions.len();
    let limit = config.max_normal_turn_deg() as f64 + 0.5;
    let min_q = config.min_quality() as f64 * (1.0 - 1e-3);
    loop {
        let before: Vec<[u32; 3]> = s.buffer().to_vec();
        let features: Vec<usize> = (0..nv)
            .filter(|&v| s.is_feature(v) && s.is_used(v))
            .collect();
        let finished = s.step(1);
        let op = steps.operations;
        steps.operations += 1;
        for &v in &features {
            if !s.is_used(v) {
                steps.removed_features.push((op, v));
            }
        }
        for (slot, (old, new)) in before.iter().zip(s.buffer()).enumerate() {
            let live = |t: &[u32; 3]| t[0] != t[1];
            if old == new || !live(old) || !live(new) {
                continue;
            }
            let (q0, q1) = (
                meshcheck::quality(&m.positions, *old),
                meshcheck::quality(&m.positions, *new),
            );
            let angle = meshcheck::normal_angle_deg(&m.positions, *old, *new);
            // A sliver that stays in its triangle's plane costs no error and is allowed.
            let planar = angle.is_some_and(|a| a < PLANAR_DEG);
            if q1 <= 0.0 || (q1 < min_q && q1 < q0 * (1.0 - 1e-3) && !planar) {
                steps.slivers.push((op, slot, q0, q1));
            }
            if let Some(a) = angle {
                if a > limit {
                    steps.turned.push((op, slot, a));
                }
            }
        }
        assert!(steps.operations < 10_000_000, "no termination");
        if finished {
            break;
        }
    }
    let report = s.finish();
    tris.truncate(report.triangles_out);
    let out = MeshData {
        positions: m.positions.clone(),
        triangles: tris,
    };
    (out, report, steps)
}

/// `Config::new()` and `Config::paper()` at `ratio`.
fn both_configs(ratio: f32) -> [(&'static str, Config); 2] {
    [
        ("new", Config::new().with_ratio(ratio)),
        ("paper", Config::paper().with_ratio(ratio)),
    ]
}

/// A grid with a fin (a third triangle on an interior edge), a cone pinched onto a corner and
/// one triangle wound the other way.
fn messy_grid(n: u32, seed: u64) -> MeshData {
    let mut m = fin_and_pinch(n);
    let k = m.triangles.len() / 4;
    m.triangles[k].swap(0, 1);
    jitter(m, seed, 1e-3)
}

/// The meshes with locked parts of `locked_parts_stay_untouched`.
fn locked_cases() -> Vec<(String, MeshData)> {
    let mut cases = vec![
        ("messy grid 10".to_string(), messy_grid(10, 1)),
        ("messy grid 16".to_string(), messy_grid(16, 7)),
        // The cow has one pinched vertex.
        ("cow".to_string(), fixture("cow.obj")),
    ];
    // Two closed spheres sharing one vertex (a pinch on a closed surface).
    let mut two = icosphere(2);
    let b = icosphere(2);
    let off = two.positions.len() as u32;
    let apex = (0..b.positions.len())
        .max_by(|&i, &j| b.positions[i][0].total_cmp(&b.positions[j][0]))
        .unwrap() as u32;
    let far = (0..two.positions.len())
        .min_by(|&i, &j| two.positions[i][0].total_cmp(&two.positions[j][0]))
        .unwrap() as u32;
    let shift = two.positions[far as usize][0] - b.positions[apex as usize][0];
    two.positions
        .extend(b.positions.iter().map(|p| [p[0] + shift, p[1], p[2]]));
    two.triangles.extend(
        b.triangles
            .iter()
            .map(|t| t.map(|i| if i == apex { far } else { i + off })),
    );
    cases.push(("two pinched spheres".to_string(), two));
    cases
}

#[test]
fn locked_parts_stay_untouched() {
    let cases = locked_cases();
    for (name, m) in &cases {
        let before = analysis(m);
        let locked = before.locked_vertices();
        assert!(!locked.is_empty(), "{name}: the case has no locked part");
        for (cname, config) in both_configs(0.1) {
            let what = format!("{name} {cname}");
            let (out, report) = simplify(m, &config);
            assert_valid(&what, m, &out, &report);
            assert!(
                report.triangles_out < m.triangles.len() * 2 / 3,
                "{what}: the rest is simplified: {report:?}"
            );
            let after = analysis(&out);
            for &v in &locked {
                assert!(
                    after.vertices.contains(&v),
                    "{what}: locked vertex {v} removed"
                );
            }
            for e in &before.non_manifold_edges {
                assert!(
                    after.non_manifold_edges.contains(e),
                    "{what}: non-manifold edge {e:?} changed"
                );
            }
            for v in &before.pinched_vertices {
                assert!(
                    after.pinched_vertices.contains(v),
                    "{what}: pinched vertex {v} changed"
                );
            }
            for e in &before.inconsistent_edges {
                let has = |t: &[u32; 3]| t.contains(&e.0) && t.contains(&e.1);
                assert_eq!(
                    out.triangles.iter().filter(|t| has(t)).count(),
                    2,
                    "{what}: inconsistent edge {e:?} changed"
                );
            }
        }
    }
}

/// A locked vertex does not freeze its neighbourhood: interior vertices around it collapse onto
/// it (as meshoptimizer's manifold vertices collapse onto complex ones), and the result is
/// valid, with the locked parts as they were (`locked_parts_stay_untouched`).
#[test]
fn interior_vertices_move_onto_locked_ones() {
    for (name, m) in &locked_cases() {
        let locked: BTreeSet<u32> = analysis(m).locked_vertices().into_iter().collect();
        let (log, tris, report) = simplify_logged(m, &Config::new().with_ratio(0.1));
        let onto = log.iter().filter(|[_, b]| locked.contains(b)).count();
        // The cow's one pinched vertex sits where its neighbours have cheaper ways to go.
        assert!(
            onto > 0 || name == "cow",
            "{name}: no collapse onto a locked vertex"
        );
        assert!(
            log.iter().all(|[a, _]| !locked.contains(a)),
            "{name}: a locked vertex moved"
        );
        let out = MeshData {
            positions: m.positions.clone(),
            triangles: tris,
        };
        assert_valid(name, m, &out, &report);
    }
}

#[test]
fn features_survive_every_operation() {
    let meshes = [
        ("box", jitter(cube(6), 3, 1e-4)),
        ("fandisk", load_obj("fandisk.obj")),
    ];
    for (name, m) in &meshes {
        for (cname, config) in both_configs(0.1) {
            let what = format!("{name} {cname}");
            let (out, report, steps) = step_by_step(m, &config);
            assert!(report.feature_vertices > 0, "{what}: no features");
            assert!(
                steps.removed_features.is_empty(),
                "{what}: {} feature vertices removed, first (operation, vertex) {:?}",
                steps.removed_features.len(),
                &steps.removed_features[..steps.removed_features.len().min(5)]
            );
            assert_valid(&what, m, &out, &report);
        }
    }
}

/// Boundary vertices, number of loops and total length of the boundary edges.
fn boundary(m: &MeshData) -> (BTreeSet<u32>, usize, f64) {
    let a = analysis(m);
    let mut count = std::collections::HashMap::new();
    for t in &m.triangles {
        for k in 0..3 {
            let (x, y) = (t[k], t[(k + 1) % 3]);
            *count.entry((x.min(y), x.max(y))).or_insert(0) += 1;
        }
    }
    let length = count
        .iter()
        .filter(|(_, &c)| c == 1)
        .map(|(&(x, y), _)| {
            let (p, q) = (m.positions[x as usize], m.positions[y as usize]);
            (0..3)
                .map(|i| (p[i] as f64 - q[i] as f64).powi(2))
                .sum::<f64>()
                .sqrt()
        })
        .sum();
    (a.boundary_vertices, a.topology.boundary_loops, length)
}

#[test]
fn boundaries_keep_loops_vertices_and_length() {
    let mut holes = grid(24, 24, 0.2);
    // Two square holes.
    let w = 25;
    holes.triangles.retain(|t| {
        let inside = |v: u32, x0: u32, y0: u32| {
            let (x, y) = (v % w, v / w);
            (x0..x0 + 4).contains(&x) && (y0..y0 + 4).contains(&y)
        };
        !(t.iter().all(|&v| inside(v, 4, 4)) || t.iter().all(|&v| inside(v, 14, 12)))
    });
    let meshes = [
        ("grid", jitter(grid(20, 14, 0.15), 5, 1e-3)),
        ("grid with holes", holes),
        ("camelhead", load_obj("camelhead.obj")),
    ];
    for (name, m) in &meshes {
        let (bv, loops, len) = boundary(m);
        assert!(loops > 0, "{name}: not open");
        for (cname, config) in both_configs(0.1) {
            let what = format!("{name} {cname}");
            let (out, report) = simplify(m, &config);
            assert_valid(&what, m, &out, &report);
            let (bv2, loops2, len2) = boundary(&out);
            assert_eq!(loops2, loops, "{what}: boundary loops");
            let new: Vec<_> = bv2.difference(&bv).collect();
            assert!(new.is_empty(), "{what}: new boundary vertices {new:?}");
            assert!(
                len2 <= len * (1.0 + 1e-9),
                "{what}: boundary longer {len} -> {len2}"
            );
        }
    }
}

/// Geometry barely constrains: the topological rules must hold on their own.
fn loose(config: Config) -> Config {
    let mut c = config;
    c = c.with_max_normal_turn(179.0);
    c = c.with_min_quality(0.0);
    c
}

#[test]
fn no_new_pinch_or_non_manifold_edge() {
    let meshes = [
        ("icosphere", jitter(icosphere(3), 11, 1e-3)),
        ("grid", jitter(grid(16, 16, 0.15), 12, 1e-3)),
        ("box", jitter(cube(5), 13, 1e-3)),
        ("cow", fixture("cow.obj")),
    ];
    for (name, m) in &meshes {
        for (cname, config) in both_configs(0.05) {
            for (lname, config) in [("", config), (" loose", loose(config))] {
                let what = format!("{name} {cname}{lname}");
                let (out, report) = simplify(m, &config);
                assert_valid(&what, m, &out, &report);
                let v = verdict(m, &out);
                assert_eq!(v.new_pinched_vertices + v.new_non_manifold_edges, 0);
            }
        }
    }
}

/// Six separate closed tetrahedra: every vertex has valence 3, so collapsing any edge a-b
/// would turn a's third triangle into a copy of one of b's.
fn tetrahedra() -> MeshData {
    let mut m = MeshData::default();
    for i in 0..6u32 {
        let o = [i as f32 * 3.0, (i % 2) as f32, 0.0];
        let base = m.positions.len() as u32;
        for p in [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
        ] {
            m.positions.push([o[0] + p[0], o[1] + p[1], o[2] + p[2]]);
        }
        for t in [[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]] {
            m.triangles.push(t.map(|k: u32| base + k));
        }
    }
    m
}

#[test]
fn no_duplicate_triangles_on_tetrahedral_parts() {
    // Closed surfaces with valence-3 vertices, with loose geometry so that only the
    // connectivity rules decide.
    // An icosahedron with a low pyramid on every face: 20 valence-3 vertices.
    let mut bumpy = icosphere(0);
    let faces = bumpy.triangles.clone();
    bumpy.triangles.clear();
    for t in faces {
        let c = (0..3).fold([0.0f32; 3], |acc, k| {
            let p = bumpy.positions[t[k] as usize];
            [
                acc[0] + p[0] * 0.36,
                acc[1] + p[1] * 0.36,
                acc[2] + p[2] * 0.36,
            ]
        });
        let v = bumpy.positions.len() as u32;
        bumpy.positions.push(c);
        for k in 0..3 {
            bumpy.triangles.push([t[k], t[(k + 1) % 3], v]);
        }
    }
    for (name, m) in [("tetrahedra", tetrahedra()), ("bumpy icosahedron", bumpy)] {
        for (cname, config) in both_configs(0.0) {
            for (lname, config) in [("", config), (" loose", loose(config))] {
                let what = format!("{name} {cname}{lname}");
                let (out, report) = simplify(&m, &config);
                assert_valid(&what, &m, &out, &report);
                assert_eq!(verdict(&m, &out).duplicate_triangles, 0, "{what}");
            }
        }
    }
}

/// In a consistently wound manifold, the copy a collapse would make always has the opposite
/// winding of the triangle it copies, so the fold rule refuses it too, and an inconsistent
/// winding locks b. With every other rule on, the output is the same without the duplicate
/// rule; what shows the rule at work is the report's count of the collapses it refused
/// (`Report::rejected`, by the first rule that refuses, in the order of `src/policy/legality/mod.rs`).
#[test]
fn tetrahedra_are_kept_whole_by_the_duplicate_rule() {
    let m = tetrahedra();
    for schedule in [Schedule::Greedy, Schedule::Passes] {
        // Features off: on a regular shape they would refuse every collapse first.
        let mut config = loose(Config::new().with_schedule(schedule).with_ratio(0.0));
        config = config.with_features(false);
        let what = format!("tetrahedra {schedule:?} loose");
        let (out, report) = simplify(&m, &config);
        assert_valid(&what, &m, &out, &report);
        assert_eq!(
            out.triangles, m.triangles,
            "{what}: every tetrahedron stays"
        );
        assert!(
            report.rejected.get(Reject::Duplicate) > 0,
            "{what}: no collapse refused as a duplicate: {:?}",
            report.rejected
        );
    }
}

/// Meshes for the per-operation shape tests.
fn shape_meshes() -> Vec<(&'static str, MeshData)> {
    vec![
        ("wavy grid", jitter(grid(18, 18, 0.3), 21, 1e-3)),
        ("flat grid", grid(16, 12, 0.0)),
        ("icosphere", jitter(icosphere(3), 22, 1e-3)),
        ("box", jitter(cube(5), 23, 1e-4)),
        ("cow", fixture("cow.obj")),
    ]
}

#[test]
fn no_operation_makes_a_sliver() {
    for (name, m) in shape_meshes() {
        for (cname, config) in both_configs(0.05) {
            let what = format!("{name} {cname}");
            let (out, report, steps) = step_by_step(&m, &config);
            assert!(
                steps.slivers.is_empty(),
                "{what}: {} slivers made, first (operation, slot, quality before, after) {:?}",
                steps.slivers.len(),
                &steps.slivers[..steps.slivers.len().min(5)]
            );
            assert_valid(&what, &m, &out, &report);
            assert_eq!(verdict(&m, &out).new_zero_area_triangles, 0, "{what}");
        }
    }
}

#[test]
fn no_operation_turns_a_triangle_too_far() {
    for (name, m) in shape_meshes() {
        for (cname, config) in both_configs(0.05) {
            let what = format!("{name} {cname}");
            let (out, report, steps) = step_by_step(&m, &config);
            assert!(
                steps.turned.is_empty(),
                "{what}: {} triangles turned beyond {}°, first (operation, slot, degrees) {:?}",
                steps.turned.len(),
                config.max_normal_turn_deg(),
                &steps.turned[..steps.turned.len().min(5)]
            );
            assert_valid(&what, &m, &out, &report);
        }
    }
}

#[test]
fn no_new_folds_when_only_the_fold_rule_guards() {
    let meshes = [
        ("wavy grid", jitter(grid(18, 18, 0.3), 31, 1e-3)),
        ("icosphere", jitter(icosphere(3), 32, 1e-3)),
        ("box", jitter(cube(5), 33, 1e-3)),
        ("cow", fixture("cow.obj")),
    ];
    for (name, m) in &meshes {
        for (cname, config) in both_configs(0.02) {
            let what = format!("{name} {cname} loose");
            let (out, report) = simplify(m, &loose(config));
            assert_valid(&what, m, &out, &report);
            assert_eq!(verdict(m, &out).new_folded_pairs, 0, "{what}");
        }
    }
}

/// The table at the top of this file has one row per rule of `RULES`, in its order, and every
/// test a row names is a test of `tests/`: adding a rule to the library without its test here
/// fails.
#[test]
fn every_rule_has_a_row_and_a_test() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests");
    let mut sources = String::new();
    for e in std::fs::read_dir(&dir).unwrap() {
        let path = e.unwrap().path();
        if path.extension().is_some_and(|x| x == "rs") {
            sources += &std::fs::read_to_string(&path).unwrap();
        }
    }
    let ticked = |cell: &str| -> Vec<String> {
        cell.split('`')
            .skip(1)
            .step_by(2)
            .map(str::to_string)
            .collect()
    };
    let mut names = Vec::new();
    for line in include_str!("rules.rs").lines() {
        let Some(row) = line.strip_prefix("//! | `") else {
            continue;
        };
        let cells: Vec<&str> = row.split(" | ").collect();
        let name = cells[0].trim().trim_end_matches('`').to_string();
        let tests = ticked(cells.last().unwrap());
        assert!(!tests.is_empty(), "rule `{name}` names no test");
        for t in &tests {
            assert!(
                sources.contains(&format!("fn {t}(")),
                "rule `{name}`: no test `{t}` in tests/"
            );
        }
        names.push(name);
    }
    let rules: Vec<&str> = RULES.iter().map(|r| r.name).collect();
    assert_eq!(names, rules, "the table's rows and RULES");
    // scripts/rules-off.sh reads the names as the `name: "..."` lines of src/policy/legality/mod.rs.
    let script: Vec<&str> = include_str!("../src/policy/legality/mod.rs")
        .lines()
        .filter_map(|l| l.trim().strip_prefix("name: \"")?.strip_suffix("\","))
        .collect();
    assert_eq!(script, rules, "the names scripts/rules-off.sh reads");
    assert!(RULES
        .iter()
        .enumerate()
        .all(|(i, r)| r.reject as usize == i));
    assert_eq!(Reject::Bound.name(), "bound");
}
