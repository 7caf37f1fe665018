//! Welded seams (`tinydecimate::seam`, crate feature `seams`): what welding promises on real
//! output, through the shared checker.
//!
//! * `seams_keep_their_shape_and_sides`: a wavy grid split into two texture charts along a
//!   seam reaches its target without a crack (the output welded by position is a valid
//!   simplification of the input welded), every wedge of a kept seam position survives, the
//!   seam's positions stay on the seam, and no output triangle takes corners from both charts
//!   (the `seam` rule of `legality::RULES`).
//! * `flat_shaded_faces_simplify_whole`: a box whose every face has its own vertices (a
//!   flat-shaded export) reaches its target as one closed surface when its seam corners move.
//! * `locked_seam_corners_keep_every_chart_whole`: a grid in four charts meeting at one
//!   position: with the corners locked no output triangle takes corners from two charts, and
//!   with them moving some do (so the lock is what keeps them).
//! * `the_pipeline_keeps_seams_closed_and_charts_whole` (crate feature `fast` too): the
//!   pipeline's `simplify_with_wedges`, both modes, on the grids above, on a chart one column
//!   wide between two and on a seam that ends inside: the target reached with no crack, no
//!   wedge of a kept position lost, no triangle across two charts.
//! * `no_chart_loses_its_last_triangle`: islands of one, two and eight triangles of their own
//!   chart inside a grid all survive, in both engines.
#![cfg(feature = "seams")]

mod common;
use std::collections::BTreeSet;

use common::*;
use tinydecimate::seam::SeamCorners;
use tinydecimate::{seam, Builtin, Config, EdgeCollapse, NoBound, Positions, Report, Stop};

/// Welds, simplifies (default configuration at `ratio`, seam corners as `corners` say) and
/// returns the output in the input's numbering.
fn simplify_welded(m: &MeshData, ratio: f32, corners: SeamCorners) -> (MeshData, Report) {
    let mut tris = m.triangles.clone();
    let mut wedges = vec![[0u32; 3]; tris.len()];
    let mut order = vec![0u32; m.positions.len()];
    let moved = seam::weld(&m.positions, &mut tris, &mut wedges, &mut order).expect("weld");
    assert!(moved > 0, "the mesh has seams");
    let mut ws = BIG.lock().unwrap_or_else(|e| e.into_inner());
    let config = Config::new().with_ratio(ratio);
    let report = ws
        .start(
            Positions::Read(&m.positions),
            &mut tris,
            &config,
            Builtin::new(),
            NoBound,
            EdgeCollapse,
        )
        .expect("start")
        .with_wedges(&mut wedges, corners)
        .expect("wedges")
        .run();
    output(&m.positions, tris, report)
}

/// [`simplify_welded`] with seam corners locked, checked: the target reached, the output a
/// valid simplification with no crack, and every wedge of a kept seam position still used.
fn simplify_locked(m: &MeshData, ratio: f32, what: &str) -> MeshData {
    let (out, report) = simplify_welded(m, ratio, SeamCorners::Lock);
    assert_eq!(report.stop, Stop::Target, "{what}: {report:?}");
    let v = welded_verdict(m, &out);
    v.assert_valid(what);
    assert_eq!(
        v.lost_wedges, 0,
        "{what}: wedges of kept seam positions lost"
    );
    out
}

fn welded_verdict(input: &MeshData, output: &MeshData) -> meshcheck::Verdict {
    verdict_opts(
        input,
        output,
        &meshcheck::Options {
            welded: true,
            ..Default::default()
        },
    )
}

/// A wavy `n` x `n` grid whose vertices on a seam (column `n/2`) are duplicated: the left
/// chart uses the originals, the right chart the copies along the seam. Returns the mesh and
/// each vertex's chart (0 left, 1 right; a seam position has one vertex in each).
fn two_charts(n: u32) -> (MeshData, Vec<u8>) {
    let mut m = grid(n, n, 0.25);
    let w = n + 1;
    // The seam: column n/2.
    let seam_col = |_: u32| n / 2;
    let mut chart = vec![0u8; m.positions.len()];
    let mut copy = std::collections::HashMap::new();
    for j in 0..=n {
        let v = j * w + seam_col(j);
        copy.insert(v, m.positions.len() as u32);
        m.positions.push(m.positions[v as usize]);
        chart.push(1);
    }
    for (i, c) in chart.iter_mut().enumerate().take((w * w) as usize) {
        let (x, j) = (i as u32 % w, i as u32 / w);
        if x > seam_col(j) {
            *c = 1;
        }
    }
    for t in &mut m.triangles {
        // A triangle is right of the seam when a vertex is.
        let right = t.iter().any(|&v| chart[v as usize] == 1);
        if right {
            for v in t.iter_mut() {
                if let Some(&c) = copy.get(v) {
                    *v = c;
                }
            }
        }
    }
    (m, chart)
}

#[test]
fn seams_keep_their_shape_and_sides() {
    let (m, chart) = two_charts(24);
    let seam: BTreeSet<[u32; 3]> = m
        .positions
        .iter()
        .enumerate()
        .filter(|&(v, _)| v >= 25 * 25)
        .map(|(_, p)| p.map(f32::to_bits))
        .collect();
    for t in &m.triangles {
        let sides: BTreeSet<u8> = t.iter().map(|&x| chart[x as usize]).collect();
        assert_eq!(sides.len(), 1, "input triangle {t:?} takes both charts");
    }
    for ratio in [0.5, 0.25, 0.1] {
        let what = format!("two charts at {ratio}");
        let out = simplify_locked(&m, ratio, &what);
        for t in &out.triangles {
            let sides: BTreeSet<u8> = t.iter().map(|&x| chart[x as usize]).collect();
            assert_eq!(sides.len(), 1, "{what}: triangle {t:?} takes both charts");
        }
        // The seam stays a seam: both charts still meet, each side on seam positions only.
        let used: BTreeSet<u32> = out.triangles.iter().flatten().copied().collect();
        for &x in &used {
            let on_seam = seam.contains(&m.positions[x as usize].map(f32::to_bits));
            if x as usize >= 25 * 25 {
                assert!(on_seam, "{what}: a seam copy off the seam");
            }
        }
        assert!(used.iter().any(|&x| x as usize >= 25 * 25), "{what}");
    }
}

/// A box of `n` x `n` quads per face, every face with its own vertices (flat-shaded).
fn flat_box(n: u32) -> MeshData {
    let welded = cube(n);
    let mut m = MeshData::default();
    // Faces of the cube: triangles in groups by their normal's axis and sign.
    let mut face_of = std::collections::BTreeMap::new();
    for t in &welded.triangles {
        let p = t.map(|v| welded.positions[v as usize]);
        let e1 = [p[1][0] - p[0][0], p[1][1] - p[0][1], p[1][2] - p[0][2]];
        let e2 = [p[2][0] - p[0][0], p[2][1] - p[0][1], p[2][2] - p[0][2]];
        let c = [
            e1[1] * e2[2] - e1[2] * e2[1],
            e1[2] * e2[0] - e1[0] * e2[2],
            e1[0] * e2[1] - e1[1] * e2[0],
        ];
        let axis = (0..3)
            .max_by(|&a, &b| c[a].abs().total_cmp(&c[b].abs()))
            .unwrap();
        let key = (axis, c[axis] > 0.0);
        let map: &mut std::collections::HashMap<u32, u32> = face_of.entry(key).or_default();
        let tri = t.map(|v| {
            *map.entry(v).or_insert_with(|| {
                m.positions.push(welded.positions[v as usize]);
                m.positions.len() as u32 - 1
            })
        });
        m.triangles.push(tri);
    }
    m
}

#[test]
fn flat_shaded_faces_simplify_whole() {
    // Every triangle of a sphere its own three vertices, as a flat-shaded export splits them:
    // each triangle is its own chart, and with `Move` no chart is kept.
    let sphere = icosphere(2);
    let mut split = MeshData::default();
    for t in &sphere.triangles {
        let base = split.positions.len() as u32;
        split
            .positions
            .extend(t.iter().map(|&v| sphere.positions[v as usize]));
        split.triangles.push([base, base + 1, base + 2]);
    }
    let (_, report) = simplify_welded(&split, 0.25, SeamCorners::Move);
    assert_eq!(report.stop, Stop::Target, "flat-shaded sphere: {report:?}");
    let m = flat_box(6);
    for ratio in [0.5, 0.1] {
        let what = format!("flat-shaded box at {ratio}");
        let (out, report) = simplify_welded(&m, ratio, SeamCorners::Move);
        assert_eq!(report.stop, Stop::Target, "{what}: {report:?}");
        let v = welded_verdict(&m, &out);
        v.assert_valid(&what);
        assert_eq!(v.components, (1, 1), "{what}");
        assert_eq!(v.boundary_loops, (0, 0), "{what}: a crack");
    }
}

/// A wavy `n` x `n` grid (`n` even) in four texture charts, its quarters: every position on a
/// chart border has one vertex per chart around it, and the middle of the grid has four.
/// Returns the mesh and each vertex's chart.
fn four_charts(n: u32) -> (MeshData, Vec<u8>) {
    let g = grid(n, n, 0.25);
    let mut m = MeshData::default();
    let mut chart = Vec::new();
    let mut copy = std::collections::HashMap::new();
    for t in &g.triangles {
        let c = t.map(|v| g.positions[v as usize]);
        let (x, y) = (
            (c[0][0] + c[1][0] + c[2][0]) / 3.0,
            (c[0][1] + c[1][1] + c[2][1]) / 3.0,
        );
        let mid = |k: usize| {
            let (lo, hi) = g
                .positions
                .iter()
                .fold((f32::MAX, f32::MIN), |(lo, hi), p| {
                    (lo.min(p[k]), hi.max(p[k]))
                });
            (lo + hi) / 2.0
        };
        let ch = u8::from(x >= mid(0)) + 2 * u8::from(y >= mid(1));
        m.triangles.push(t.map(|v| {
            *copy.entry((ch, v)).or_insert_with(|| {
                m.positions.push(g.positions[v as usize]);
                chart.push(ch);
                m.positions.len() as u32 - 1
            })
        }));
    }
    (m, chart)
}

#[test]
fn locked_seam_corners_keep_every_chart_whole() {
    let (m, chart) = four_charts(16);
    let torn = |out: &MeshData| {
        out.triangles
            .iter()
            .filter(|t| {
                t.iter()
                    .map(|&x| chart[x as usize])
                    .collect::<BTreeSet<u8>>()
                    .len()
                    > 1
            })
            .count()
    };
    for ratio in [0.25, 0.1, 0.05] {
        let what = format!("four charts at {ratio}");
        let out = simplify_locked(&m, ratio, &what);
        assert_eq!(
            torn(&out),
            0,
            "{what}: triangles take corners from two charts"
        );
    }
    let mut torn_moving = Vec::new();
    for ratio in [0.25, 0.1, 0.05] {
        let (out, _) = simplify_welded(&m, ratio, SeamCorners::Move);
        welded_verdict(&m, &out).assert_valid("four charts, corners moving");
        torn_moving.push(torn(&out));
    }
    assert!(
        torn_moving.iter().any(|&n| n > 0),
        "moving seam corners tore no chart: the test cannot fail"
    );
}

/// A wavy `n` x `n` grid cut along its vertices where `seam(column, row)`: each triangle on a
/// cut vertex takes the copy of that vertex for its side, `side(x)` of its centroid's column
/// `x` (in columns).
#[cfg(feature = "fast")]
fn split_grid(n: u32, seam: impl Fn(u32, u32) -> bool, side: impl Fn(f32) -> u8) -> MeshData {
    let g = grid(n, n, 0.25);
    let mut m = MeshData {
        positions: g.positions.clone(),
        triangles: Vec::new(),
    };
    let mut copy = std::collections::HashMap::new();
    for t in &g.triangles {
        let x = t.iter().map(|&v| (v % (n + 1)) as f32).sum::<f32>() / 3.0;
        let s = side(x);
        m.triangles.push(t.map(|v| {
            if !seam(v % (n + 1), v / (n + 1)) || s == 0 {
                return v;
            }
            *copy.entry((s, v)).or_insert_with(|| {
                m.positions.push(g.positions[v as usize]);
                m.positions.len() as u32 - 1
            })
        }));
    }
    m
}

/// The grid of [`split_grid`] with its column `n/2 + 1` moved to a tenth of a column from
/// column `n/2` (every copy with it).
#[cfg(feature = "fast")]
fn narrow(mut m: MeshData, n: u32) -> MeshData {
    let (from, to) = (
        (n / 2 + 1) as f32 / n as f32,
        (n as f32 / 2.0 + 0.1) / n as f32,
    );
    for p in &mut m.positions {
        if p[0] == from {
            p[0] = to;
        }
    }
    m
}

/// Each vertex's chart: the vertices connected through the triangles (wedges are split on
/// every seam, so a chart is a connected piece of the split mesh).
#[cfg(feature = "fast")]
fn charts(m: &MeshData) -> Vec<u32> {
    let mut parent: Vec<u32> = (0..m.positions.len() as u32).collect();
    fn root(p: &mut [u32], mut x: u32) -> u32 {
        while p[x as usize] != x {
            p[x as usize] = p[p[x as usize] as usize];
            x = p[x as usize];
        }
        x
    }
    for t in &m.triangles {
        for k in 1..3 {
            let (a, b) = (root(&mut parent, t[0]), root(&mut parent, t[k]));
            parent[a.max(b) as usize] = a.min(b);
        }
    }
    (0..m.positions.len() as u32)
        .map(|v| root(&mut parent, v))
        .collect()
}

#[cfg(feature = "fast")]
#[test]
fn the_pipeline_keeps_seams_closed_and_charts_whole() {
    let run = pipeline_welded;
    let n = 24;
    let meshes = [
        ("two charts", two_charts(n).0),
        ("four charts", four_charts(16).0),
        // A narrow chart between two: seam vertices of both seams are neighbours across short
        // spokes where no wedge changes, the cheapest collapses of the strip's vertices.
        (
            "a strip",
            narrow(
                split_grid(
                    n,
                    |i, _| i == n / 2 || i == n / 2 + 1,
                    |x| u8::from(x > n as f32 / 2.0) + u8::from(x > n as f32 / 2.0 + 1.0),
                ),
                n,
            ),
        ),
        // A seam from the border to the middle (one chart, cut): it ends at a vertex with one
        // wedge whose neighbour down the seam has two.
        (
            "a slit",
            split_grid(
                n,
                |i, j| i == n / 2 && j < n / 2,
                |x| u8::from(x > n as f32 / 2.0),
            ),
        ),
    ];
    let mut seam_refusals = 0;
    for (name, m) in &meshes {
        let chart = charts(m);
        for lean in [false, true] {
            for ratio in [0.5, 0.25, 0.1] {
                let what = format!("{name}, lean {lean}, {ratio}");
                let (out, report) = run(m, ratio, lean);
                assert_eq!(report.stop, Stop::Target, "{what}: {report:?}");
                seam_refusals += report.rejected.get(tinydecimate::Reject::Seam);
                let v = welded_verdict(m, &out);
                v.assert_valid(&what);
                assert_eq!(v.lost_wedges, 0, "{what}: wedges of kept positions lost");
                for t in &out.triangles {
                    let sides: BTreeSet<u32> = t.iter().map(|&x| chart[x as usize]).collect();
                    assert_eq!(sides.len(), 1, "{what}: triangle {t:?} takes two charts");
                }
            }
        }
    }
    // The strip's seam vertices are offered each other across the strip: the seam rule
    // refuses (switched off, `PIPELINE_RULE_OFF=seam`, the strip's output is invalid).
    assert!(seam_refusals > 0, "the seam rule never refused");
}

/// The pipeline's wedge buffer, refused before either buffer is touched: shorter than the
/// triangles, or naming a vertex past the positions.
/// The pipeline (the lean mode with `lean`) on `m` welded by position with its wedges, at
/// `ratio`: the output in `m`'s numbering.
#[cfg(feature = "fast")]
fn pipeline_welded(m: &MeshData, ratio: f32, lean: bool) -> (MeshData, Report) {
    use std::sync::Mutex;
    use tinydecimate::pipeline::{FastWorkspace, LeanWorkspace};
    static FAST: Mutex<FastWorkspace<u32, 65_536, 131_072>> = Mutex::new(FastWorkspace::new());
    static LEAN: Mutex<LeanWorkspace<u32, 65_536, 131_072>> = Mutex::new(LeanWorkspace::new());
    let mut tris = m.triangles.clone();
    let mut wedges = vec![[0u32; 3]; tris.len()];
    let mut order = vec![0u32; m.positions.len()];
    let moved = seam::weld(&m.positions, &mut tris, &mut wedges, &mut order).expect("weld");
    assert!(moved > 0, "the mesh has seams");
    let config = Config::new().with_ratio(ratio);
    let report = if lean {
        LEAN.lock()
            .unwrap_or_else(|e| e.into_inner())
            .simplify_with_wedges(&m.positions, &mut tris, &mut wedges, &config)
    } else {
        FAST.lock()
            .unwrap_or_else(|e| e.into_inner())
            .simplify_with_wedges(&m.positions, &mut tris, &mut wedges, &config)
    }
    .expect("simplify");
    output(&m.positions, tris, report)
}

/// A wavy `n` x `n` grid with islands of their own chart (a material's region, or a texture
/// chart, inside another): one triangle, one quad (two triangles) and a 2 x 2 block of quads,
/// each island's triangles on their own copies of its vertices. Returns the mesh and each
/// triangle's chart (0 the grid, 1 to 3 the islands).
fn islands(n: u32) -> (MeshData, Vec<u8>) {
    let g = grid(n, n, 0.25);
    let cell = |i: u32, j: u32| 2 * (j * n + i) as usize;
    let mut island = vec![0u8; g.triangles.len()];
    island[cell(n / 4, n / 4)] = 1;
    island[cell(3 * n / 4, n / 4)] = 2;
    island[cell(3 * n / 4, n / 4) + 1] = 2;
    for (i, j) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
        island[cell(n / 2 + i, 3 * n / 4 + j)] = 3;
        island[cell(n / 2 + i, 3 * n / 4 + j) + 1] = 3;
    }
    let mut m = MeshData {
        positions: g.positions.clone(),
        triangles: Vec::new(),
    };
    let mut copy = std::collections::HashMap::new();
    for (t, &c) in g.triangles.iter().zip(&island) {
        m.triangles.push(t.map(|v| {
            if c == 0 {
                return v;
            }
            *copy.entry((c, v)).or_insert_with(|| {
                m.positions.push(g.positions[v as usize]);
                m.positions.len() as u32 - 1
            })
        }));
    }
    (m, island)
}

/// A chart's last triangle is never collapsed away (the `seam` rule, both engines): islands of
/// one, two and eight triangles inside a grid all keep a triangle at 25 % and 5 %, each
/// output triangle on one chart, the output valid welded with no wedge of a kept position
/// lost. This is what keeps every material when `tinydecimate simplify` joins a glTF mesh's
/// primitives. (With the chart clause of either engine's seam rule removed, the one-triangle
/// island goes.)
#[test]
fn no_chart_loses_its_last_triangle() {
    let (m, island) = islands(24);
    let chart_of_vertex = {
        let mut c = vec![0u8; m.positions.len()];
        for (t, &i) in m.triangles.iter().zip(&island) {
            for &v in t {
                c[v as usize] = c[v as usize].max(i);
            }
        }
        c
    };
    let judge = |out: &MeshData, what: &str| {
        let v = welded_verdict(&m, out);
        v.assert_valid(what);
        assert_eq!(v.lost_wedges, 0, "{what}: wedges of kept positions lost");
        let mut kept = BTreeSet::new();
        for t in &out.triangles {
            let c: BTreeSet<u8> = t.iter().map(|&x| chart_of_vertex[x as usize]).collect();
            // An island triangle has every corner on the island's copies.
            let c = if c.len() == 1 { *c.first().unwrap() } else { 0 };
            kept.insert(c);
        }
        for i in 1..=3 {
            assert!(kept.contains(&i), "{what}: island {i} is gone");
        }
    };
    for ratio in [0.25, 0.05] {
        let (out, report) = simplify_welded(&m, ratio, SeamCorners::Lock);
        judge(&out, &format!("exact engine at {ratio}: {report:?}"));
    }
    #[cfg(feature = "fast")]
    for lean in [false, true] {
        for ratio in [0.25, 0.05] {
            let (out, report) = pipeline_welded(&m, ratio, lean);
            judge(
                &out,
                &format!("pipeline, lean {lean}, at {ratio}: {report:?}"),
            );
        }
    }
}

#[cfg(feature = "fast")]
#[test]
fn the_pipeline_refuses_bad_wedges_untouched() {
    use tinydecimate::pipeline::{FastWorkspace, LeanWorkspace};
    use tinydecimate::{Capacity, Error};
    let (m, _) = two_charts(4);
    let mut tris = m.triangles.clone();
    let mut wedges = vec![[0u32; 3]; tris.len()];
    let mut order = vec![0u32; m.positions.len()];
    seam::weld(&m.positions, &mut tris, &mut wedges, &mut order).expect("weld");
    let config = Config::new().with_ratio(0.5);
    let nv = m.positions.len() as u32;
    let mut bad = wedges.clone();
    bad[3][1] = nv;
    let cases: [(Vec<[u32; 3]>, Error); 2] = [
        (
            wedges[..wedges.len() - 1].to_vec(),
            Error::Capacity {
                what: Capacity::Triangles,
                needed: tris.len(),
                available: tris.len() - 1,
            },
        ),
        (
            bad,
            Error::IndexOutOfRange {
                triangle: 3,
                index: nv as usize,
            },
        ),
    ];
    for (w, expected) in cases {
        for lean in [false, true] {
            let (mut t, mut w) = (tris.clone(), w.clone());
            let r = if lean {
                Box::new(LeanWorkspace::<u16, 1024, 2048>::new())
                    .as_mut()
                    .simplify_with_wedges(&m.positions, &mut t, &mut w, &config)
            } else {
                Box::new(FastWorkspace::<u16, 1024, 2048>::new())
                    .as_mut()
                    .simplify_with_wedges(&m.positions, &mut t, &mut w, &config)
            };
            assert_eq!(r, Err(expected), "lean {lean}");
            assert_eq!(t, tris, "lean {lean}: triangles touched");
        }
    }
}
