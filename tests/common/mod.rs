//! Test support: an OBJ reader for the shared meshes, mesh generators, and an invariant checker
//! written independently of the library (plain std collections, f64 math).
#![allow(dead_code)]

use std::collections::HashMap;
use std::path::PathBuf;
use std::sync::Mutex;

use tinydecimate::{Config, Report, Workspace};

pub type Tri = [u32; 3];

#[derive(Clone, Debug, Default)]
pub struct MeshData {
    pub positions: Vec<[f32; 3]>,
    pub triangles: Vec<Tri>,
}

/// The repository's public test meshes (`tests/fixtures`, sources and licences in its
/// SOURCES.md).
pub fn shared_meshes() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests")
        .join("fixtures")
}

/// Minimal reader for the shared meshes (only `v x y z` and `f a b c`, 1-based).
pub fn load_obj(name: &str) -> MeshData {
    let path = shared_meshes().join(name);
    let text = std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
    parse_obj(&text)
}

pub fn parse_obj(text: &str) -> MeshData {
    let mut m = MeshData::default();
    for line in text.lines() {
        let mut it = line.split_whitespace();
        match it.next() {
            Some("v") => {
                let p: Vec<f32> = it.take(3).map(|x| x.parse().unwrap()).collect();
                m.positions.push([p[0], p[1], p[2]]);
            }
            Some("f") => {
                let f: Vec<u32> = it
                    .map(|x| x.split('/').next().unwrap().parse::<u32>().unwrap() - 1)
                    .collect();
                assert_eq!(f.len(), 3, "triangles only");
                m.triangles.push([f[0], f[1], f[2]]);
            }
            _ => {}
        }
    }
    m
}

/// Workspace big enough for every shared mesh, as a static (it is several megabytes).
pub static BIG: Mutex<Workspace<u32, 65_536, 131_072>> = Mutex::new(Workspace::new());

/// Runs the library on a copy of the mesh with the big workspace.
pub fn simplify(m: &MeshData, config: &Config) -> (MeshData, Report) {
    let mut tris = m.triangles.clone();
    let mut ws = BIG.lock().unwrap_or_else(|e| e.into_inner());
    let report = ws
        .simplify(&m.positions, &mut tris, config)
        .expect("simplify");
    tris.truncate(report.triangles_out);
    (
        MeshData {
            positions: m.positions.clone(),
            triangles: tris,
        },
        report,
    )
}

/// Simplifies `m` by edge collapse with the built-in cost and a collapse log: the log, the
/// output triangles and the report.
pub fn simplify_logged(m: &MeshData, config: &Config) -> (Vec<[u32; 2]>, Vec<Tri>, Report) {
    let mut tris = m.triangles.clone();
    let mut log = vec![[0u32; 2]; m.positions.len()];
    let mut ws = BIG.lock().unwrap_or_else(|e| e.into_inner());
    let mut s = ws
        .start(
            tinydecimate::Positions::Read(&m.positions),
            &mut tris,
            config,
            tinydecimate::Builtin::new(),
            tinydecimate::NoBound,
            tinydecimate::EdgeCollapse,
        )
        .expect("start")
        .record_into(&mut log);
    while !s.step(u32::MAX) {}
    let n = s.records().len();
    let r = s.finish();
    assert_eq!(n, r.collapses);
    log.truncate(n);
    tris.truncate(r.triangles_out);
    (log, tris, r)
}

/// FNV-1a over the triangles' little-endian bytes: a short fingerprint of an output.
pub fn digest(tris: &[Tri]) -> u64 {
    let mut h = 0xcbf2_9ce4_8422_2325u64;
    for b in tris.iter().flatten().flat_map(|i| i.to_le_bytes()) {
        h ^= b as u64;
        h = h.wrapping_mul(0x100_0000_01b3);
    }
    h
}

// ---- generators ------------------------------------------------------------------------

/// Icosahedron subdivided `n` times, projected to the unit sphere.
pub fn icosphere(n: u32) -> MeshData {
    let t = (1.0 + 5f64.sqrt()) / 2.0;
    let mut p: Vec<[f64; 3]> = vec![
        [-1.0, t, 0.0],
        [1.0, t, 0.0],
        [-1.0, -t, 0.0],
        [1.0, -t, 0.0],
        [0.0, -1.0, t],
        [0.0, 1.0, t],
        [0.0, -1.0, -t],
        [0.0, 1.0, -t],
        [t, 0.0, -1.0],
        [t, 0.0, 1.0],
        [-t, 0.0, -1.0],
        [-t, 0.0, 1.0],
    ];
    let mut f: Vec<Tri> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..n {
        let mut mid: HashMap<(u32, u32), u32> = HashMap::new();
        let mut nf = Vec::new();
        for tri in &f {
            let mut m = [0u32; 3];
            for k in 0..3 {
                let (a, b) = (tri[k], tri[(k + 1) % 3]);
                let key = (a.min(b), a.max(b));
                m[k] = *mid.entry(key).or_insert_with(|| {
                    let (pa, pb) = (p[a as usize], p[b as usize]);
                    p.push([
                        (pa[0] + pb[0]) / 2.0,
                        (pa[1] + pb[1]) / 2.0,
                        (pa[2] + pb[2]) / 2.0,
                    ]);
                    (p.len() - 1) as u32
                });
            }
            nf.push([tri[0], m[0], m[2]]);
            nf.push([tri[1], m[1], m[0]]);
            nf.push([tri[2], m[2], m[1]]);
            nf.push([m[0], m[1], m[2]]);
        }
        f = nf;
    }
    let positions = p
        .iter()
        .map(|q| {
            let l = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2]).sqrt();
            [(q[0] / l) as f32, (q[1] / l) as f32, (q[2] / l) as f32]
        })
        .collect();
    MeshData {
        positions,
        triangles: f,
    }
}

/// An open `n` x `m` grid of quads on a wavy height field (boundary: one loop).
pub fn grid(n: u32, m: u32, wave: f32) -> MeshData {
    let mut positions = Vec::new();
    for j in 0..=m {
        for i in 0..=n {
            let (x, y) = (i as f32 / n as f32, j as f32 / m as f32);
            let z = wave * ((x * 6.0).sin() * (y * 4.0).cos());
            positions.push([x, y, z]);
        }
    }
    let mut triangles = Vec::new();
    let w = n + 1;
    for j in 0..m {
        for i in 0..n {
            let v = j * w + i;
            if (i + j) % 2 == 0 {
                triangles.push([v, v + 1, v + w + 1]);
                triangles.push([v, v + w + 1, v + w]);
            } else {
                triangles.push([v, v + 1, v + w]);
                triangles.push([v + 1, v + w + 1, v + w]);
            }
        }
    }
    MeshData {
        positions,
        triangles,
    }
}

/// A cube with `n` x `n` quads per face, welded, sharp creases at the edges.
pub fn cube(n: u32) -> MeshData {
    let mut positions: Vec<[f32; 3]> = Vec::new();
    let mut index: HashMap<[i64; 3], u32> = HashMap::new();
    let mut triangles = Vec::new();
    let mut vid = |p: [f32; 3], positions: &mut Vec<[f32; 3]>| -> u32 {
        let key = p.map(|x| (x as f64 * 1e6).round() as i64);
        *index.entry(key).or_insert_with(|| {
            positions.push(p);
            (positions.len() - 1) as u32
        })
    };
    // Each face: origin, u axis, v axis (u x v points outwards).
    let faces: [([f32; 3], [f32; 3], [f32; 3]); 6] = [
        ([0.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]), // z = 0, normal -z
        ([0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]), // z = 1, +z
        ([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]), // y = 0, -y
        ([0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]), // y = 1, +y
        ([0.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 1.0, 0.0]), // x = 0, -x
        ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]), // x = 1, +x
    ];
    for (o, u, v) in faces {
        let at = |i: u32, j: u32| {
            let (s, t) = (i as f32 / n as f32, j as f32 / n as f32);
            [
                o[0] + u[0] * s + v[0] * t,
                o[1] + u[1] * s + v[1] * t,
                o[2] + u[2] * s + v[2] * t,
            ]
        };
        for j in 0..n {
            for i in 0..n {
                let a = vid(at(i, j), &mut positions);
                let b = vid(at(i + 1, j), &mut positions);
                let c = vid(at(i + 1, j + 1), &mut positions);
                let d = vid(at(i, j + 1), &mut positions);
                triangles.push([a, b, c]);
                triangles.push([a, c, d]);
            }
        }
    }
    MeshData {
        positions,
        triangles,
    }
}

// ---- invariants ------------------------------------------------------------------------
// The checker is the `meshcheck` crate (meshcheck/), shared with the fuzz targets and
// host-sim: written independently of the library, f64 geometry.

#[allow(unused_imports)]
pub use meshcheck::{Defect, Topology, Verdict, FOLD_DOT};

/// Topology and defect counts of one mesh.
pub fn analyse(m: &MeshData) -> Topology {
    meshcheck::analyse(&m.positions, &m.triangles).topology
}

/// [`analyse`] with the sets behind the counts (pinched vertices, boundary vertices, ...).
pub fn analysis(m: &MeshData) -> meshcheck::Analysis {
    meshcheck::analyse(&m.positions, &m.triangles)
}

/// The shared checker's verdict on `output` as a simplification of `input` (same positions).
pub fn verdict(input: &MeshData, output: &MeshData) -> Verdict {
    verdict_with(input, output, false)
}

/// [`verdict`]; with `allow_moved`, kept vertices may have moved (optimal placement).
pub fn verdict_with(input: &MeshData, output: &MeshData, allow_moved: bool) -> Verdict {
    verdict_opts(
        input,
        output,
        &meshcheck::Options {
            allow_moved,
            ..Default::default()
        },
    )
}

/// The shared checker's verdict with any of its options (welded seams, parts removed whole).
pub fn verdict_opts(input: &MeshData, output: &MeshData, opts: &meshcheck::Options) -> Verdict {
    meshcheck::check_with(
        meshcheck::MeshRef {
            positions: &input.positions,
            triangles: &input.triangles,
        },
        meshcheck::MeshRef {
            positions: &output.positions,
            triangles: &output.triangles,
        },
        opts,
    )
}

/// A run's output: the first `report.triangles_out` of `tris`, on `positions`.
pub fn output(positions: &[[f32; 3]], mut tris: Vec<Tri>, report: Report) -> (MeshData, Report) {
    tris.truncate(report.triangles_out);
    (
        MeshData {
            positions: positions.to_vec(),
            triangles: tris,
        },
        report,
    )
}

/// Asserts that `output` is a valid simplification of `input` (the shared checker), and that
/// the library's report agrees with the output.
pub fn assert_valid(name: &str, input: &MeshData, output: &MeshData, report: &Report) {
    assert_eq!(
        report.triangles_out,
        output.triangles.len(),
        "{name}: count"
    );
    verdict(input, output).assert_valid(name);
}

/// A grid with a fin (a third triangle on an interior edge) and a small cone pinched onto
/// corner vertex 0: a non-manifold edge and a pinched vertex.
pub fn fin_and_pinch(n: u32) -> MeshData {
    let mut m = grid(n, n, 0.1);
    // Fin on the edge of the middle triangle.
    let [a, b, _] = m.triangles[m.triangles.len() / 2];
    m.positions.push([0.5, 0.5, 1.0]);
    let top = (m.positions.len() - 1) as u32;
    m.triangles.push([a, b, top]);
    // A small cone pinched onto grid corner vertex 0.
    let base = m.positions.len() as u32;
    for i in 0..5 {
        let t = i as f32 / 5.0 * std::f32::consts::TAU;
        m.positions
            .push([-0.2 + 0.1 * t.cos(), -0.2 + 0.1 * t.sin(), -0.3]);
    }
    for i in 0..5 {
        m.triangles.push([0, base + (i + 1) % 5, base + i]);
    }
    m
}

/// Deterministic xorshift jitter of every coordinate, in `±amount / 2`.
pub fn jitter(mut m: MeshData, seed: u64, amount: f32) -> MeshData {
    let mut s = seed | 1;
    for p in &mut m.positions {
        for x in p.iter_mut() {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            *x += ((s % 1000) as f32 / 1000.0 - 0.5) * amount;
        }
    }
    m
}

/// A closed octahedron of radius `r` about `c`, appended to `m`.
pub fn octahedron(m: &mut MeshData, c: [f32; 3], r: f32) {
    let b = m.positions.len() as u32;
    for d in [
        [r, 0.0, 0.0],
        [-r, 0.0, 0.0],
        [0.0, r, 0.0],
        [0.0, -r, 0.0],
        [0.0, 0.0, r],
        [0.0, 0.0, -r],
    ] {
        m.positions.push([c[0] + d[0], c[1] + d[1], c[2] + d[2]]);
    }
    for [x, y, z] in [
        [0, 2, 4],
        [2, 1, 4],
        [1, 3, 4],
        [3, 0, 4],
        [2, 0, 5],
        [1, 2, 5],
        [3, 1, 5],
        [0, 3, 5],
    ] {
        m.triangles.push([b + x, b + y, b + z]);
    }
}

/// The tetrahedron (0,0,0), (1,0,0), (0,1,0), (0,0,1), outward.
pub fn tetrahedron() -> MeshData {
    MeshData {
        positions: vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
        ],
        triangles: vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]],
    }
}

/// A wavy 24 x 24 sheet and, beside it, ten small octahedra (8 triangles each, radius 0.01 to
/// 0.028 of the sheet's unit width). Returns the mesh and each small part's vertex range.
pub fn sheet_and_bolts() -> (MeshData, Vec<std::ops::Range<u32>>) {
    let mut m = grid(24, 24, 0.15);
    let mut parts = Vec::new();
    for i in 0..10 {
        let start = m.positions.len() as u32;
        let r = 0.01 + 0.002 * i as f32;
        octahedron(&mut m, [0.1 * i as f32, 1.2, 0.05], r);
        parts.push(start..m.positions.len() as u32);
    }
    (m, parts)
}

/// The shared checker with parts allowed to vanish whole.
pub fn parts_verdict(input: &MeshData, output: &MeshData) -> meshcheck::Verdict {
    verdict_opts(
        input,
        output,
        &meshcheck::Options {
            parts: true,
            ..Default::default()
        },
    )
}

/// How many of `part`'s input triangles the output still has.
pub fn kept_of(input: &MeshData, output: &MeshData, part: &std::ops::Range<u32>) -> (usize, usize) {
    let inside = |t: &[u32; 3]| t.iter().all(|v| part.contains(v));
    let total = input.triangles.iter().filter(|t| inside(t)).count();
    let kept = output.triangles.iter().filter(|t| inside(t)).count();
    (kept, total)
}

/// The pipeline's modes (tests/pipeline.rs, tests/integer.rs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Mode {
    Fast,
    Lean,
}

/// Both pipeline modes, or the one `PIPELINE_MODE` (`fast` or `lean`) names: with a rule
/// switched off (`PIPELINE_RULE_OFF`), each mode alone must fail.
pub fn modes() -> Vec<Mode> {
    match std::env::var("PIPELINE_MODE").as_deref() {
        Ok("fast") => vec![Mode::Fast],
        Ok("lean") => vec![Mode::Lean],
        _ => vec![Mode::Fast, Mode::Lean],
    }
}
