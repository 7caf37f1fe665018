//! Streaming vertex clustering (`tinydecimate::cluster`) on the real meshes, checked by an
//! independent model: every output triangle is an input triangle whose three corners fell into
//! three distinct cells, each corner replaced by its cell's representative, winding kept; every
//! such input triangle is in the output (once, in some winding); no degenerate or duplicate
//! triangle; indices in range; the count at most the target. Plus bad input.

mod common;
use common::*;
use std::collections::{HashMap, HashSet};
use std::sync::Mutex;

use proptest::prelude::*;
use tinydecimate::cluster::{
    ClusterConfig, ClusterError, ClusterReport, Clusterer, Grid, GridChoice, PositionFn, Quadrics,
    Scratch, SliceSource, KEY_LANES,
};

const CELLS: usize = 65_535;
static TABLE: Mutex<Clusterer<CELLS>> = Mutex::new(Clusterer::new());
static QUADS: Mutex<Quadrics<CELLS>> = Mutex::new(Quadrics::new());

const MESHES: [&str; 10] = [
    "plate_holes.obj",
    "wuson.obj",
    "cow.obj",
    "spot.obj",
    "pr2_sensor_mount.obj",
    "fandisk.obj",
    "rocker_arm.obj",
    "camelhead.obj",
    "stanford_bunny.obj",
    "armadillo.obj",
];

fn cluster(m: &MeshData, config: &ClusterConfig, quadric: bool) -> (Vec<Tri>, ClusterReport) {
    let mut table = TABLE.lock().unwrap_or_else(|e| e.into_inner());
    let mut quads = QUADS.lock().unwrap_or_else(|e| e.into_inner());
    let mut out = vec![[0u32; 3]; m.triangles.len().max(1)];
    let mut src = SliceSource::new(&m.positions, &m.triangles);
    let q = if quadric { Some(&mut *quads) } else { None };
    let r = table
        .cluster(
            &mut src,
            config,
            &mut out,
            Scratch {
                quadrics: q,
                ..Scratch::new()
            },
        )
        .expect("cluster");
    out.truncate(r.triangles_out);
    (out, r)
}

/// The cell of a position (the library's own key function: the grid is the library's).
fn key(g: &Grid, p: [f32; 3]) -> u32 {
    g.key(p)
}

fn canonical(t: Tri) -> Tri {
    let r = (0..3).min_by_key(|&i| t[i]).unwrap();
    [t[r], t[(r + 1) % 3], t[(r + 2) % 3]]
}

/// The invariants, against the independent model.
fn check(name: &str, m: &MeshData, out: &[Tri], r: &ClusterReport) {
    let g = &r.grid;
    let mut seen = HashSet::new();
    let mut rep: HashMap<u32, u32> = HashMap::new();
    for t in out {
        for &v in t {
            assert!(
                (v as usize) < m.positions.len(),
                "{name}: index out of range"
            );
        }
        assert!(
            t[0] != t[1] && t[1] != t[2] && t[0] != t[2],
            "{name}: degenerate {t:?}"
        );
        assert!(
            seen.insert(meshcheck::sorted(*t)),
            "{name}: duplicate {t:?}"
        );
        for &v in t {
            let k = key(g, m.positions[v as usize]);
            let old = rep.insert(k, v);
            assert!(
                old.is_none() || old == Some(v),
                "{name}: two representatives of a cell"
            );
        }
    }
    // Expected: every input triangle with three distinct cells, mapped.
    let out_wound: HashSet<Tri> = out.iter().map(|&t| canonical(t)).collect();
    let mut expected = HashSet::new();
    let mut wound = HashSet::new();
    for t in &m.triangles {
        let k = t.map(|v| key(g, m.positions[v as usize]));
        if k[0] == k[1] || k[1] == k[2] || k[0] == k[2] {
            continue;
        }
        let mapped = k.map(|k| *rep.get(&k).expect("cell of an output triangle has a rep"));
        expected.insert(meshcheck::sorted(mapped));
        wound.insert(canonical(mapped));
    }
    assert_eq!(
        expected, seen,
        "{name}: output is not the set of surviving triangles"
    );
    for t in &out_wound {
        assert!(wound.contains(t), "{name}: {t:?} not an input winding");
    }
    assert!(r.triangles_out == out.len());
    if r.target_triangles > 0 {
        assert!(r.triangles_out <= r.target_triangles, "{name}: over target");
    }
    let v = meshcheck::analyse(&m.positions, out);
    assert_eq!(v.topology.duplicate_triangles, 0, "{name}");
}

#[test]
fn real_meshes_keep_every_invariant() {
    for name in MESHES {
        let m = load_obj(name);
        for quadric in [false, true] {
            for frac in [20usize, 5] {
                let target = m.triangles.len() * frac / 100;
                let t0 = std::time::Instant::now();
                let (out, r) = cluster(&m, &ClusterConfig::target(target), quadric);
                eprintln!(
                    "{name} quadric={quadric} {frac}%: {} -> {} (target {target}), grid {:?}, cells {}, dup {} ({} opposite), passes {}, {:.2?}",
                    r.triangles_in, r.triangles_out, r.grid.dims, r.cells, r.duplicates,
                    r.opposite_duplicates, r.passes, t0.elapsed()
                );
                check(name, &m, &out, &r);
                assert!(r.triangles_out > target / 3, "{name}: far below target");
            }
        }
    }
}

/// A bit per vertex (`Scratch::seen`) or an 8-byte cache per vertex (`Scratch::cache`)
/// gives the same output and report as none, also when too short (the vertices beyond take
/// the path without), with cleanup, with a given bounding box and with a cell size.
#[test]
fn vertex_memory_changes_nothing_but_time() {
    for name in ["cow.obj", "fandisk.obj", "stanford_bunny.obj"] {
        let m = load_obj(name);
        let words = m.positions.len() / 32 + 1;
        let nv = m.positions.len();
        let (lo, hi) = bounds(&m);
        let configs = [
            ClusterConfig::target(m.triangles.len() / 5),
            ClusterConfig::target(m.triangles.len() / 20),
            ClusterConfig::target(m.triangles.len() / 10).with_cleanup(),
            ClusterConfig::target(m.triangles.len() / 10).with_bbox(lo, hi),
            ClusterConfig::cell_size((hi[0] - lo[0]) / 17.0),
        ];
        for (frac, config) in configs.iter().enumerate() {
            let config = *config;
            let (want, wr) = cluster(&m, &config, true);
            for n in [nv, nv / 2, 1] {
                let mut table = TABLE.lock().unwrap_or_else(|e| e.into_inner());
                let mut quads = QUADS.lock().unwrap_or_else(|e| e.into_inner());
                let mut out = vec![[0u32; 3]; m.triangles.len()];
                let mut cache = vec![7u64; n];
                let mut src = SliceSource::new(&m.positions, &m.triangles);
                let r = table
                    .cluster(
                        &mut src,
                        &config,
                        &mut out,
                        Scratch {
                            quadrics: Some(&mut *quads),
                            cache: &mut cache,
                            ..Scratch::new()
                        },
                    )
                    .expect("cluster with a cache");
                out.truncate(r.triangles_out);
                assert_eq!(r, wr, "{name} config {frac}, cache {n}: report");
                assert_eq!(out, want, "{name} config {frac}, cache {n}: output");
            }
            for (n, nk) in [(nv, nv), (nv, nv / 2), (nv / 2, nv), (1, nv), (nv, 1)] {
                let mut table = TABLE.lock().unwrap_or_else(|e| e.into_inner());
                let mut quads = QUADS.lock().unwrap_or_else(|e| e.into_inner());
                let mut out = vec![[0u32; 3]; m.triangles.len()];
                let mut cache = vec![7u64; n];
                // Garbage on entry, including stamps that look current.
                let mut keys = vec![[u32::MAX; KEY_LANES]; nk];
                let mut src = SliceSource::new(&m.positions, &m.triangles);
                let r = table
                    .cluster(
                        &mut src,
                        &config,
                        &mut out,
                        Scratch {
                            quadrics: Some(&mut *quads),
                            cache: &mut cache,
                            keys: &mut keys,
                            ..Scratch::new()
                        },
                    )
                    .expect("cluster with cache and keys");
                out.truncate(r.triangles_out);
                assert_eq!(r, wr, "{name} config {frac}, cache {n}, keys {nk}: report");
                assert_eq!(
                    out, want,
                    "{name} config {frac}, cache {n}, keys {nk}: output"
                );
            }
            for n in [words, words / 2, 1] {
                let mut table = TABLE.lock().unwrap_or_else(|e| e.into_inner());
                let mut quads = QUADS.lock().unwrap_or_else(|e| e.into_inner());
                let mut out = vec![[0u32; 3]; m.triangles.len()];
                let mut bits = vec![u32::MAX; n];
                let mut src = SliceSource::new(&m.positions, &m.triangles);
                let r = table
                    .cluster(
                        &mut src,
                        &config,
                        &mut out,
                        Scratch {
                            quadrics: Some(&mut *quads),
                            seen: &mut bits,
                            ..Scratch::new()
                        },
                    )
                    .expect("cluster with seen bits");
                out.truncate(r.triangles_out);
                assert_eq!(r, wr, "{name} {frac}% {n} words: report");
                assert_eq!(out, want, "{name} {frac}% {n} words: output");
            }
        }
    }
}

#[test]
fn cell_size_grid_and_given_bbox() {
    let m = load_obj("cow.obj");
    let (a, ra) = cluster(&m, &ClusterConfig::cell_size(0.5), true);
    check("cow 0.5", &m, &a, &ra);
    assert_eq!(ra.passes, 3, "bbox, accumulate, choose");
    let (min, max) = (ra.grid.origin, [f32::MIN; 3]);
    let mut max = max;
    for p in &m.positions {
        for k in 0..3 {
            max[k] = max[k].max(p[k]);
        }
    }
    let (b, rb) = cluster(&m, &ClusterConfig::cell_size(0.5).with_bbox(min, max), true);
    assert_eq!(rb.passes, 2);
    assert_eq!(a, b);
}

/// One case's exact bytes (the same on the host and every Cortex-M core: integer hashing and
/// only `+ - * /` in f32).
#[test]
fn golden_bytes() {
    let m = load_obj("cow.obj");
    let (out, r) = cluster(&m, &ClusterConfig::target(600), true);
    let (out2, r2) = cluster(&m, &ClusterConfig::target(600), false);
    eprintln!(
        "quadric {} {:016x}, nearest {} {:016x}",
        r.triangles_out,
        digest(&out),
        r2.triangles_out,
        digest(&out2)
    );
    assert_eq!((r.triangles_out, digest(&out)), GOLDEN_QUADRIC);
    assert_eq!((r2.triangles_out, digest(&out2)), GOLDEN_NEAREST);
}
const GOLDEN_QUADRIC: (usize, u64) = (524, 0x4a3b_5adf_6844_d279);
const GOLDEN_NEAREST: (usize, u64) = (524, 0x8b4b_9885_249a_0f1f);

fn bounds(m: &MeshData) -> ([f32; 3], [f32; 3]) {
    let mut lo = [f32::INFINITY; 3];
    let mut hi = [f32::NEG_INFINITY; 3];
    for t in &m.triangles {
        for &v in t {
            for k in 0..3 {
                lo[k] = lo[k].min(m.positions[v as usize][k]);
                hi[k] = hi[k].max(m.positions[v as usize][k]);
            }
        }
    }
    (lo, hi)
}

#[test]
fn nan_position_is_a_typed_error() {
    let mut m = icosphere(2);
    m.positions[7][1] = f32::NAN;
    let mut table = Clusterer::<512>::new();
    let mut out = [[0u16; 3]; 400];
    let mut src = SliceSource::new(&m.positions, &m.triangles);
    let e = table.cluster(
        &mut src,
        &ClusterConfig::target(100),
        &mut out,
        Scratch::new(),
    );
    assert_eq!(e, Err(ClusterError::NonFinitePosition { vertex: 7 }));
    // The same first error with per-vertex memory, with and without a given box.
    let (lo, hi) = ([-2.0; 3], [2.0; 3]);
    for config in [
        ClusterConfig::target(100),
        ClusterConfig::target(100).with_bbox(lo, hi),
    ] {
        let mut cache = vec![0u64; m.positions.len()];
        let mut bits = vec![0u32; m.positions.len() / 32 + 1];
        let e = table.cluster(
            &mut src,
            &config,
            &mut out,
            Scratch {
                cache: &mut cache,
                ..Scratch::new()
            },
        );
        assert_eq!(e, Err(ClusterError::NonFinitePosition { vertex: 7 }));
        let mut quads = Quadrics::<512>::new();
        let e = table.cluster(
            &mut src,
            &config,
            &mut out,
            Scratch {
                quadrics: Some(&mut quads),
                cache: &mut cache,
                ..Scratch::new()
            },
        );
        assert_eq!(e, Err(ClusterError::NonFinitePosition { vertex: 7 }));
        let mut keys = vec![[0u32; KEY_LANES]; m.positions.len()];
        let e = table.cluster(
            &mut src,
            &config,
            &mut out,
            Scratch {
                quadrics: Some(&mut quads),
                cache: &mut cache,
                keys: &mut keys,
                ..Scratch::new()
            },
        );
        assert_eq!(e, Err(ClusterError::NonFinitePosition { vertex: 7 }));
        let e = table.cluster(
            &mut src,
            &config,
            &mut out,
            Scratch {
                quadrics: Some(&mut quads),
                seen: &mut bits,
                ..Scratch::new()
            },
        );
        assert_eq!(e, Err(ClusterError::NonFinitePosition { vertex: 7 }));
    }
}

#[test]
fn index_out_of_range_is_a_typed_error() {
    let mut m = icosphere(2);
    m.triangles[5][2] = 9999;
    let mut table = Clusterer::<512>::new();
    let mut out = [[0u16; 3]; 400];
    let mut src = SliceSource::new(&m.positions, &m.triangles);
    let e = table.cluster(
        &mut src,
        &ClusterConfig::cell_size(0.3),
        &mut out,
        Scratch::new(),
    );
    assert_eq!(
        e,
        Err(ClusterError::IndexOutOfRange {
            triangle: 5,
            index: 9999
        })
    );
    let mut cache = vec![0u64; m.positions.len()];
    let mut quads = Quadrics::<512>::new();
    for config in [ClusterConfig::cell_size(0.3), ClusterConfig::target(100)] {
        let e = table.cluster(
            &mut src,
            &config,
            &mut out,
            Scratch {
                quadrics: Some(&mut quads),
                cache: &mut cache,
                ..Scratch::new()
            },
        );
        assert_eq!(
            e,
            Err(ClusterError::IndexOutOfRange {
                triangle: 5,
                index: 9999
            })
        );
        let mut keys = vec![[0u32; KEY_LANES]; m.positions.len()];
        let e = table.cluster(
            &mut src,
            &config,
            &mut out,
            Scratch {
                quadrics: Some(&mut quads),
                cache: &mut cache,
                keys: &mut keys,
                ..Scratch::new()
            },
        );
        assert_eq!(
            e,
            Err(ClusterError::IndexOutOfRange {
                triangle: 5,
                index: 9999
            })
        );
    }
}

#[test]
fn full_table_says_how_big_it_must_be() {
    let m = load_obj("cow.obj");
    let (_, r) = cluster(&m, &ClusterConfig::cell_size(0.3), false);
    let needed = r.cells;
    let mut table = Clusterer::<256>::new();
    let mut out = vec![[0u32; 3]; m.triangles.len()];
    let mut src = SliceSource::new(&m.positions, &m.triangles);
    let e = table.cluster(
        &mut src,
        &ClusterConfig::cell_size(0.3),
        &mut out,
        Scratch::new(),
    );
    let Err(ClusterError::TableFull {
        capacity,
        needed_at_least,
        estimate,
    }) = e
    else {
        panic!("{e:?}");
    };
    eprintln!("needed {needed}: at least {needed_at_least}, estimate {estimate}");
    assert_eq!(capacity, 256);
    assert!(needed_at_least > 256 && needed_at_least <= needed);
    assert!(estimate >= needed_at_least);
    // A table of the estimate's size works.
    let mut big = Clusterer::<4096>::new();
    assert!(estimate <= 4096);
    let mut src = SliceSource::new(&m.positions, &m.triangles);
    let r2 = big
        .cluster(
            &mut src,
            &ClusterConfig::cell_size(0.3),
            &mut out,
            Scratch::new(),
        )
        .unwrap();
    assert_eq!(r2.cells, needed);
}

#[test]
fn full_output_says_how_big_it_must_be() {
    let m = icosphere(3);
    let mut table = Clusterer::<2048>::new();
    let mut out = [[0u16; 3]; 50];
    let mut src = SliceSource::new(&m.positions, &m.triangles);
    let e = table.cluster(
        &mut src,
        &ClusterConfig::cell_size(0.2),
        &mut out,
        Scratch::new(),
    );
    assert!(
        matches!(e, Err(ClusterError::OutputFull { capacity: 50, needed_at_least: 51, estimate }) if estimate > 51),
        "{e:?}"
    );
}

#[test]
fn a_table_too_wide_for_u16_is_refused() {
    let m = icosphere(1);
    let mut table = Clusterer::<70_000>::new();
    let mut out = [[0u16; 3]; 80];
    let mut src = SliceSource::new(&m.positions, &m.triangles);
    let e = table.cluster(
        &mut src,
        &ClusterConfig::cell_size(0.5),
        &mut out,
        Scratch::new(),
    );
    assert!(matches!(e, Err(ClusterError::TableTooWide { .. })), "{e:?}");
}

/// The single-pass stream API with an accessor closure gives the same output as `cluster`
/// with the nearest representative, for any chunking.
#[test]
fn stream_equals_cluster_for_any_chunking() {
    let m = load_obj("spot.obj");
    let (want, r) = cluster(&m, &ClusterConfig::target(800), false);
    for chunk in [1usize, 7, 64, 100_000] {
        let mut table = Clusterer::<4096>::new();
        let mut out = vec![[0u32; 3]; 2000];
        let mut s = table.stream(r.grid, &mut out).unwrap();
        let mut reads = 0usize;
        let mut acc = PositionFn(|v: usize| {
            reads += 1;
            m.positions.get(v).copied()
        });
        for c in m.triangles.chunks(chunk) {
            s.push(c, &mut acc).unwrap();
        }
        let r2 = s.finish().unwrap();
        out.truncate(r2.triangles_out);
        // The order follows the table's and buffer's sizes (hash slots); the set does not.
        let (mut a, mut b) = (out.clone(), want.clone());
        a.sort();
        b.sort();
        assert!(a == b, "chunk {chunk}: different output");
        assert_eq!(reads, 3 * m.triangles.len());
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]
    /// Random grids on a jittered sphere and a wavy grid with holes: invariants hold.
    #[test]
    fn random_grids_keep_every_invariant(
        res in 2u32..80,
        seed in 0u64..1000,
        quadric in any::<bool>(),
        which in 0u8..2,
    ) {
        let m = if which == 0 { jitter(icosphere(4), seed, 0.3) } else { jitter(grid(40, 30, 0.5), seed, 0.2) };
        let config = ClusterConfig { grid: GridChoice::Resolution(res), bbox: None, refine_passes: 0, table_cells: 0, cleanup: false };
        let (out, r) = cluster(&m, &config, quadric);
        check("prop", &m, &out, &r);
    }
}

/// Cluster, then collapse: the bunny (69 451 triangles) through a workspace of 4 096
/// triangles, to 600, in input vertex numbers, valid.
#[test]
fn cluster_then_collapse_fits_a_small_workspace() {
    use tinydecimate::cluster::cluster_then_collapse;
    use tinydecimate::{Config, Target, Workspace};
    let m = load_obj("stanford_bunny.obj");
    let mut table = Box::new(Clusterer::<4096>::new());
    let mut ws = Box::new(Workspace::<u16, 2048, 4096>::new());
    let mut out = vec![[0u16; 3]; 4096];
    let mut vertices = vec![0u32; 2048];
    let mut positions = vec![[0.0f32; 3]; 2048];
    let mut src = SliceSource::new(&m.positions, &m.triangles);
    let scratch = Scratch {
        vertices: &mut vertices,
        positions: &mut positions,
        ..Scratch::new()
    };
    let (cr, r) = cluster_then_collapse(
        &mut table,
        &mut src,
        &ClusterConfig::target(usize::MAX),
        &Config::new().with_target(Target::Triangles(600)),
        &mut out,
        ws.as_storage(),
        scratch,
    )
    .unwrap();
    eprintln!(
        "cluster {} -> {} (grid {:?}), collapse -> {}",
        cr.triangles_in, cr.triangles_out, cr.grid.dims, r.triangles_out
    );
    assert!(cr.triangles_out <= 4096 && cr.triangles_out > 2000);
    assert!(r.triangles_out <= 600 && r.triangles_out > 500);
    let tris: Vec<Tri> = out[..r.triangles_out]
        .iter()
        .map(|t| t.map(u32::from))
        .collect();
    let a = meshcheck::analyse(&m.positions, &tris);
    assert_eq!(a.topology.duplicate_triangles, 0);
    assert!(a.out_of_range.is_empty() && a.degenerate.is_empty());
}

/// `cleanup` removes exactly the zero-area triangles and, with quadrics, the triangles whose
/// normal opposes the summed area-weighted normals of the input triangles touching their three
/// cells (recomputed here independently, in f64); everything else is the output without it,
/// in the same order.
#[test]
fn cleanup_removes_exactly_zero_area_and_flipped_triangles() {
    let mut flipped_seen = 0;
    for name in [
        "wuson.obj",
        "cow.obj",
        "pr2_sensor_mount.obj",
        "stanford_bunny.obj",
    ] {
        let m = load_obj(name);
        for quadric in [false, true] {
            let target = m.triangles.len() / 20;
            let (plain, r0) = cluster(&m, &ClusterConfig::target(target), quadric);
            let (clean, r) = cluster(&m, &ClusterConfig::target(target).with_cleanup(), quadric);
            assert_eq!(r.grid, r0.grid, "{name}");
            assert_eq!(
                clean.len() + r.slivers_removed + r.flipped_removed,
                plain.len(),
                "{name}"
            );
            if !quadric {
                assert_eq!(r.flipped_removed, 0, "{name}");
            }
            flipped_seen += r.flipped_removed;
            // Cell normals, independently.
            let g = &r.grid;
            let p64 = |v: u32| m.positions[v as usize].map(f64::from);
            let mut normal: HashMap<u32, [f64; 3]> = HashMap::new();
            for t in &m.triangles {
                let [a, b, c] = [p64(t[0]), p64(t[1]), p64(t[2])];
                let n = cross64(sub64(b, a), sub64(c, a));
                let mut seen = Vec::new();
                for &v in t {
                    let k = key(g, m.positions[v as usize]);
                    if !seen.contains(&k) {
                        seen.push(k);
                        let e = normal.entry(k).or_insert([0.0; 3]);
                        for i in 0..3 {
                            e[i] += n[i];
                        }
                    }
                }
            }
            let mut kept = clean.iter().peekable();
            for t in &plain {
                let [a, b, c] = [p64(t[0]), p64(t[1]), p64(t[2])];
                let n = cross64(sub64(b, a), sub64(c, a));
                let emax = [sub64(b, a), sub64(c, a), sub64(c, b)]
                    .iter()
                    .map(|e| dot64(*e, *e))
                    .fold(0.0, f64::max);
                let mut sum = [0.0; 3];
                for &v in t {
                    let s = normal[&key(g, m.positions[v as usize])];
                    for i in 0..3 {
                        sum[i] += s[i];
                    }
                }
                let zero_area = dot64(n, n) <= 4e-12 * emax * emax * 1.01;
                let flipped = quadric && dot64(n, sum) < 0.0;
                if kept.peek() == Some(&t) {
                    kept.next();
                    assert!(
                        !flipped && dot64(n, n) > 4e-12 * emax * emax * 0.99,
                        "{name}: kept {t:?}"
                    );
                } else {
                    assert!(zero_area || flipped, "{name}: removed {t:?}");
                }
            }
            assert!(
                kept.next().is_none(),
                "{name}: the cleaned output is not a subsequence"
            );
            eprintln!(
                "{name} quadric={quadric}: {} -> {} (cleanup: {} zero-area, {} flipped)",
                plain.len(),
                clean.len(),
                r.slivers_removed,
                r.flipped_removed
            );
        }
    }
    assert!(
        flipped_seen > 0,
        "no flipped triangle on any mesh: the test tests nothing"
    );
}

fn sub64(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn dot64(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn cross64(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// A table too small for the grid fails the same way with key entries as without: a cell that
/// found no room stores no slot in its vertices' entries, so every later corner in it is
/// counted as missing again, and the error's figures are the same.
#[test]
fn a_full_table_fails_the_same_with_key_entries() {
    let m = load_obj("cow.obj");
    let (lo, hi) = bounds(&m);
    let cell = (hi[0] - lo[0]) / 25.0;
    for cells in [60usize, 300] {
        let config = ClusterConfig::cell_size(cell).with_table_cells(cells);
        let mut table = TABLE.lock().unwrap_or_else(|e| e.into_inner());
        let mut quads = QUADS.lock().unwrap_or_else(|e| e.into_inner());
        let mut out = vec![[0u32; 3]; m.triangles.len()];
        let mut src = SliceSource::new(&m.positions, &m.triangles);
        let want = table.cluster(
            &mut src,
            &config,
            &mut out,
            Scratch {
                quadrics: Some(&mut *quads),
                ..Scratch::new()
            },
        );
        assert!(
            matches!(want, Err(ClusterError::TableFull { capacity, .. }) if capacity == cells),
            "{cells} cells: {want:?}"
        );
        let mut cache = vec![0u64; m.positions.len()];
        let mut keys = vec![[0u32; KEY_LANES]; m.positions.len()];
        let mut src = SliceSource::new(&m.positions, &m.triangles);
        let got = table.cluster(
            &mut src,
            &config,
            &mut out,
            Scratch {
                quadrics: Some(&mut *quads),
                cache: &mut cache,
                keys: &mut keys,
                ..Scratch::new()
            },
        );
        assert_eq!(got, want, "{cells} cells");
    }
}
