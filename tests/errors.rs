//! Bad input gets a typed error before the caller's buffer is touched, or a documented
//! behaviour (dropped and counted, or locked and simplified around).

mod common;
use common::*;
use tinydecimate::{Capacity, Config, ConfigField, Error, Schedule, Stop, Target, Workspace};

fn sphere() -> MeshData {
    icosphere(2) // 162 vertices, 320 triangles
}

#[test]
fn too_many_vertices_or_triangles_is_a_capacity_error() {
    let m = sphere();
    let mut tris = m.triangles.clone();
    let mut small = Workspace::<u32, 100, 400>::new();
    let e = small.simplify(&m.positions, &mut tris, &Config::new());
    assert_eq!(
        e,
        Err(Error::Capacity {
            what: Capacity::Vertices,
            needed: 162,
            available: 100
        })
    );
    let mut small = Workspace::<u32, 200, 300>::new();
    let e = small.simplify(&m.positions, &mut tris, &Config::new());
    assert!(matches!(
        e,
        Err(Error::Capacity {
            what: Capacity::Triangles,
            needed: 320,
            ..
        })
    ));
    assert_eq!(tris, m.triangles, "buffer untouched");
}

#[test]
fn u16_links_cap_the_triangle_count() {
    // u16 links number triangles below NIL (65 535): 65 536 triangles do not fit.
    let positions = vec![[0.0f32; 3]; 3];
    let mut tris = vec![[0u32, 1, 2]; 65_536];
    let mut ws = Box::new(Workspace::<u16, 4, 70_000>::new());
    let e = ws.simplify(&positions, &mut tris, &Config::new());
    assert_eq!(tris[0], [0, 1, 2]);
    assert_eq!(
        e,
        Err(Error::Capacity {
            what: Capacity::Triangles,
            needed: 65_536,
            available: 65_535
        })
    );
}

#[test]
fn index_out_of_range_names_the_triangle() {
    let m = sphere();
    let mut tris = m.triangles.clone();
    tris[17][2] = 162;
    let before = tris.clone();
    let mut ws = Workspace::<u32, 256, 512>::new();
    let e = ws.simplify(&m.positions, &mut tris, &Config::new());
    assert_eq!(
        e,
        Err(Error::IndexOutOfRange {
            triangle: 17,
            index: 162
        })
    );
    assert_eq!(tris, before);
}

#[test]
fn non_finite_positions_name_the_vertex() {
    for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
        let mut m = sphere();
        m.positions[40][1] = bad;
        let mut tris = m.triangles.clone();
        let mut ws = Workspace::<u32, 256, 512>::new();
        let e = ws.simplify(&m.positions, &mut tris, &Config::new());
        assert_eq!(e, Err(Error::NonFinitePosition { vertex: 40 }));
        assert_eq!(tris, m.triangles);
    }
    // An unused vertex may be anything.
    let mut m = sphere();
    m.positions.push([f32::NAN; 3]);
    let (out, report) = simplify(&m, &Config::new().with_ratio(0.5));
    assert_valid("unused NaN", &m, &out, &report);
}

#[test]
fn bad_configuration_is_refused() {
    let m = sphere();
    let mut ws = Workspace::<u32, 256, 512>::new();
    let cases: [(Config, ConfigField); 8] = [
        (Config::new().with_ratio(1.5), ConfigField::Target),
        (Config::new().with_ratio(f32::NAN), ConfigField::Target),
        (Config::new().with_lambda(-1.0), ConfigField::Lambda),
        (Config::new().with_max_passes(0), ConfigField::MaxPasses),
        (Config::new().with_max_cost(f32::NAN), ConfigField::MaxCost),
        (
            Config::new().with_error_limit(f32::NAN),
            ConfigField::ErrorLimit,
        ),
        (
            Config::new().with_error_limit(-1.0),
            ConfigField::ErrorLimit,
        ),
        (
            Config::new().with_max_normal_turn(0.0),
            ConfigField::MaxNormalTurn,
        ),
    ];
    for (config, field) in cases {
        let mut tris = m.triangles.clone();
        let e = ws.simplify(&m.positions, &mut tris, &config);
        assert_eq!(e, Err(Error::InvalidConfig { field }));
        assert_eq!(tris, m.triangles);
    }
}

#[test]
fn degenerate_and_duplicate_triangles_are_dropped_and_counted() {
    let mut m = sphere();
    m.triangles.push([3, 3, 4]); // repeated index
    m.triangles.push([5, 6, 5]);
    let t = m.triangles[10];
    m.triangles.push(t); // exact duplicate
    m.triangles.push([t[2], t[0], t[1]]); // the same, rotated
    m.triangles.push([t[1], t[0], t[2]]); // turned over: a twin, kept (double-sided)
    m.triangles.push([t[0], t[2], t[1]]); // turned over again: a duplicate of the twin
    let (out, report) = simplify(&m, &Config::new().with_ratio(1.0));
    assert_eq!(report.degenerate_dropped, 2);
    assert_eq!(report.duplicates_dropped, 3);
    assert_eq!(report.twins, 1);
    assert_eq!(report.triangles_out, 321, "ratio 1: only the bad ones go");
    let mut clean = sphere();
    clean.triangles.push([t[0], t[2], t[1]]);
    assert_eq!(
        out.triangles, clean.triangles,
        "the first copy is kept, in order, and the twin after as its front turned over"
    );
}

#[test]
fn empty_and_tiny_meshes() {
    let mut ws = Workspace::<u16, 8, 8>::new();
    let mut none: [[u16; 3]; 0] = [];
    let r = ws.simplify(&[], &mut none, &Config::new()).unwrap();
    assert_eq!((r.triangles_out, r.stop), (0, Stop::Target));

    let p = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    let mut one = [[0u16, 1, 2]];
    let r = ws
        .simplify(&p, &mut one, &Config::new().with_ratio(0.0))
        .unwrap();
    assert_eq!(
        r.triangles_out, 1,
        "a lone triangle cannot lose its boundary loop"
    );
    assert_eq!(r.stop, Stop::NoLegalCollapse);
    assert!(!r.target_reached);
    assert_eq!(one, [[0, 1, 2]]);

    // A tetrahedron is the smallest closed surface: nothing can go.
    let p = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
    ];
    let mut tet = [[0u16, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]];
    for schedule in [Schedule::Greedy, Schedule::Passes] {
        let c = Config::new().with_ratio(0.0).with_schedule(schedule);
        let r = ws.simplify(&p, &mut tet, &c).unwrap();
        assert_eq!(r.triangles_out, 4);
        assert_eq!(r.stop, Stop::NoLegalCollapse);
    }
}

#[test]
fn all_zero_area_triangles_only_lose_whole_triangles() {
    // Collinear points: every triangle has zero area. A collapse may still delete triangles
    // outright (the end of the strip), but never move a vertex of a surviving one, which would
    // need a new zero-area triangle.
    let m = MeshData {
        positions: (0..6).map(|i| [i as f32, 0.0, 0.0]).collect(),
        triangles: vec![[0, 1, 2], [1, 3, 2], [2, 3, 4], [3, 5, 4]],
    };
    let (out, r) = simplify(&m, &Config::new().with_ratio(0.0));
    assert_eq!(r.stop, Stop::NoLegalCollapse);
    assert!(r.triangles_out >= 1);
    assert!(
        out.triangles.iter().all(|t| m.triangles.contains(t)),
        "{out:?}"
    );
    assert_valid("collinear", &m, &out, &r);
}

#[test]
fn coordinates_near_f32_limits_simplify_like_small_ones() {
    let m = icosphere(3);
    let huge = MeshData {
        positions: m.positions.iter().map(|p| p.map(|x| x * 3.0e38)).collect(),
        triangles: m.triangles.clone(),
    };
    let tiny = MeshData {
        positions: m.positions.iter().map(|p| p.map(|x| x * 1.0e-36)).collect(),
        triangles: m.triangles.clone(),
    };
    let c = Config::new().with_ratio(0.2);
    let (a, ra) = simplify(&m, &c);
    let (b, rb) = simplify(&huge, &c);
    let (t, rt) = simplify(&tiny, &c);
    assert!(ra.target_reached && rb.target_reached && rt.target_reached);
    assert_valid("huge", &huge, &b, &rb);
    assert_valid("tiny", &tiny, &t, &rt);
    // Power-of-two-free scales round differently, so only sizes are compared.
    assert_eq!(a.triangles.len(), b.triangles.len());
}

/// Positions are read through a power-of-two-exact normalisation, so scaling the input by a
/// power of two (far from overflow and underflow) must give exactly the same triangles.
#[test]
fn power_of_two_scales_give_identical_bytes() {
    for (name, m) in [("sphere", icosphere(3)), ("cow", load_obj("cow.obj"))] {
        for c in [
            Config::new().with_ratio(0.2),
            Config::paper().with_ratio(0.2),
        ] {
            let (a, ra) = simplify(&m, &c);
            for k in [-60i32, -8, 1, 20, 100] {
                let f = 2f32.powi(k);
                let scaled = MeshData {
                    positions: m.positions.iter().map(|p| p.map(|x| x * f)).collect(),
                    triangles: m.triangles.clone(),
                };
                let (b, rb) = simplify(&scaled, &c);
                assert_eq!(a.triangles, b.triangles, "{name} at 2^{k}");
                assert_eq!(ra, rb, "{name} at 2^{k}");
            }
        }
    }
}

#[test]
fn non_manifold_input_is_simplified_around_locked_vertices() {
    let mut m = grid(8, 8, 0.1);
    let [a, b, _] = m.triangles[64];
    m.positions.push([0.5, 0.5, 1.0]);
    let top = (m.positions.len() - 1) as u32;
    m.triangles.push([a, b, top]); // third triangle on edge a-b
    let (out, report) = simplify(&m, &Config::new().with_ratio(0.2));
    assert!(report.locked_vertices >= 2, "{report:?}");
    assert!(report.triangles_out < m.triangles.len() / 2);
    assert_valid("fin", &m, &out, &report);
    let e = analyse(&out);
    assert_eq!(e.non_manifold_edges, 1, "the fin edge stays, untouched");
    assert!(out.triangles.contains(&[a, b, top]));
}

#[test]
fn inconsistent_winding_is_locked_not_rejected() {
    let mut m = grid(6, 6, 0.0);
    m.triangles[20].swap(0, 1);
    let (out, report) = simplify(&m, &Config::new().with_ratio(0.3));
    assert_valid("flipped", &m, &out, &report);
    assert!(report.locked_vertices >= 3);
    assert!(out.triangles.len() < m.triangles.len());
    let t = m.triangles[20];
    assert!(out.triangles.contains(&t), "the flipped triangle is kept");
}

#[test]
fn target_of_zero_or_above_input() {
    let m = sphere();
    let (out, r) = simplify(&m, &Config::new().with_ratio(1.0));
    assert_eq!(
        (r.triangles_out, r.collapses, r.stop),
        (320, 0, Stop::Target)
    );
    assert_eq!(out.triangles, m.triangles);
    let (_, r) = simplify(&m, &Config::new().with_target(Target::Triangles(10_000)));
    assert_eq!((r.triangles_out, r.stop), (320, Stop::Target));
    let (out, r) = simplify(&m, &Config::new().with_ratio(0.0));
    assert!(!r.target_reached);
    assert_ne!(r.stop, Stop::Target);
    assert_valid("zero", &m, &out, &r);
}

#[test]
fn max_cost_and_max_passes_stop_the_run() {
    let m = icosphere(3);
    let (_, r) = simplify(&m, &Config::new().with_ratio(0.0).with_max_cost(0.0));
    assert_eq!((r.stop, r.collapses), (Stop::MaxCost, 0));
    let c = Config::new()
        .with_ratio(0.0)
        .with_schedule(Schedule::Passes)
        .with_max_passes(2);
    let (_, r) = simplify(&m, &c);
    assert_eq!((r.stop, r.passes), (Stop::MaxPasses, 2));
    assert_eq!(r.pass_triangles.len(), 2);
    assert_eq!(r.pass_triangles[1] as usize, r.triangles_out);
}

#[test]
fn pinched_vertex_is_locked_and_kept() {
    // Two closed cones (tips up and down) sharing only their apex: two fans touch at one
    // vertex, like the cow's vertex 254.
    let mut m = MeshData::default();
    m.positions.push([0.0, 0.0, 0.0]); // shared apex
    for (z, flip) in [(1.0f32, false), (-1.0, true)] {
        let base = m.positions.len() as u32;
        for i in 0..12 {
            let t = i as f32 / 12.0 * std::f32::consts::TAU;
            m.positions.push([t.cos(), t.sin(), z]);
        }
        let centre = m.positions.len() as u32;
        m.positions.push([0.0, 0.0, z * 1.2]);
        for i in 0..12 {
            let (a, b) = (base + i, base + (i + 1) % 12);
            let (side, cap) = ([0, a, b], [centre, b, a]);
            let flipped = |t: [u32; 3]| if flip { [t[0], t[2], t[1]] } else { t };
            m.triangles.push(flipped(side));
            m.triangles.push(flipped(cap));
        }
    }
    let before = analyse(&m);
    assert_eq!(before.non_manifold_edges, 0);
    let (out, report) = simplify(&m, &Config::new().with_ratio(0.2));
    assert!(report.locked_vertices >= 1, "{report:?}");
    assert_valid("pinch", &m, &out, &report);
    assert!(
        out.triangles.iter().any(|t| t.contains(&0)),
        "the apex stays"
    );
    assert!(out.triangles.len() < m.triangles.len());
}
