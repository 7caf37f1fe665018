//! Deterministic mesh generators for the golden cases (`tests/golden/cases.toml`) and for the
//! capacity search of `host-sim qemu --measure`.
//!
//! Every coordinate is computed in a way that gives the same `f32` bits on every host: small
//! multiples of powers of two, or (icosphere) `f64` arithmetic with correctly rounded `sqrt`
//! narrowed once. A case names a generator by a short spec such as `"grid 12"`
//! ([`generate`]); the meshes are never stored, only regenerated.

use std::collections::HashMap;
use std::string::String;
use std::vec;
use std::vec::Vec;

/// A generated triangle mesh.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mesh {
    /// Vertex positions.
    pub positions: Vec<[f32; 3]>,
    /// Triangles, counter-clockwise seen from outside.
    pub triangles: Vec<[u32; 3]>,
}

/// The generators [`generate`] knows, with their parameter: `(name, description)`.
pub const GENERATORS: &[(&str, &str)] = &[
    (
        "grid",
        "grid N: bumpy N x N quad grid with a step, open (boundary), (N+1)^2 vertices, 2N^2 triangles",
    ),
    (
        "icosphere",
        "icosphere N: closed unit sphere, 12 vertices / 20 triangles subdivided N times (x4 each)",
    ),
    (
        "box",
        "box N: closed box 1 x 0.75 x 0.5 with sharp 90-degree creases, N x N quads per face, 6N^2+2 vertices, 12N^2 triangles",
    ),
    (
        "fin",
        "fin N: grid N plus a fin standing on the middle row (edges with 3 triangles) and a closed tetrahedron touching the grid at one vertex (pinched vertex)",
    ),
    (
        "strip",
        "strip T: the first T triangles of a bumpy grid about twice as wide as tall, unused vertices dropped (capacity search)",
    ),
    (
        "charts",
        "charts N: grid N cut into two texture charts (or materials) along its middle column: that column's N+1 vertices doubled, the right half's triangles on the copies; the wedge cases weld it back",
    ),
];

/// Why [`generate`] refused a spec.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum SpecError {
    /// Not `<generator> <count>`.
    Syntax(String),
    /// The parameter is out of range.
    Range(String),
}

/// Builds the mesh a spec names: `grid N`, `icosphere N`, `box N`, `fin N` or `strip T`.
/// `None`: the spec names no generator (it may be a file).
pub fn generate(spec: &str) -> Option<Result<Mesh, SpecError>> {
    let mut words = spec.split_whitespace();
    let name = words.next()?;
    if !GENERATORS.iter().any(|(g, _)| *g == name) {
        return None;
    }
    let n = match (words.next().map(str::parse::<u32>), words.next()) {
        (Some(Ok(n)), None) => n,
        _ => {
            return Some(Err(SpecError::Syntax(std::format!(
                "{spec:?}: expected `{name} <count>`"
            ))))
        }
    };
    let limit = match name {
        "icosphere" => 5,
        "strip" => 4_000_000,
        _ => 1000,
    };
    let min = if name == "fin" { 4 } else { 1 };
    if n < min || n > limit {
        return Some(Err(SpecError::Range(std::format!(
            "{spec:?}: {name} takes {min}..={limit}"
        ))));
    }
    Some(Ok(match name {
        "grid" => bumpy_grid(n),
        "icosphere" => icosphere(n),
        "box" => creased_box(n),
        "fin" => fin(n),
        "charts" => charts(n),
        _ => strip(n as usize),
    }))
}

/// A bumpy `w × h` grid of quads on z = height(x, y) with a step of 1 across the middle
/// column: `(w+1)(h+1)` vertices, `2wh` triangles, open. Coordinates are small multiples of
/// 1/8, exact in `f32`.
pub fn bumpy_rect(w: u32, h: u32) -> Mesh {
    let stride = w + 1;
    let mut positions = Vec::with_capacity(((w + 1) * (h + 1)) as usize);
    for y in 0..=h {
        for x in 0..=w {
            let z = ((x * 7 + y * 3) % 5) as f32 * 0.125 + if x > w / 2 { 1.0 } else { 0.0 };
            positions.push([x as f32, y as f32, z]);
        }
    }
    let mut triangles = Vec::with_capacity((2 * w * h) as usize);
    for y in 0..h {
        for x in 0..w {
            let v = y * stride + x;
            triangles.push([v, v + 1, v + stride + 1]);
            triangles.push([v, v + stride + 1, v + stride]);
        }
    }
    Mesh {
        positions,
        triangles,
    }
}

/// [`bumpy_grid`] cut along its middle column `n / 2` into two charts, as an exporter splits a
/// texture seam or a material border: each vertex of that column gets a copy at the same
/// position (appended, bottom to top), and the triangles right of the column use the copies.
/// `(n+1)^2 + n+1` vertices, `2n^2` triangles.
pub fn charts(n: u32) -> Mesh {
    let mut m = bumpy_grid(n);
    let (stride, mid) = (n + 1, n / 2);
    let first = m.positions.len() as u32;
    for y in 0..=n {
        m.positions.push(m.positions[(y * stride + mid) as usize]);
    }
    for (t, tri) in m.triangles.iter_mut().enumerate() {
        // Two triangles per quad, quads row by row: the quad's column.
        let x = (t as u32 / 2) % n;
        if x >= mid {
            for v in tri.iter_mut() {
                if *v % stride == mid {
                    *v = first + *v / stride;
                }
            }
        }
    }
    m
}

/// [`bumpy_rect`] with `w = h = n`.
pub fn bumpy_grid(n: u32) -> Mesh {
    bumpy_rect(n, n)
}

/// The first `t` triangles of a bumpy grid about twice as wide as tall, with the vertices no
/// kept triangle uses dropped: a mesh of exactly `t` triangles and about `t / 2` vertices.
pub fn strip(t: usize) -> Mesh {
    // w quads per row, 2w triangles per row; w ≈ 2h gives 4h² ≈ t.
    let mut w = 1usize;
    while w * w < t {
        w += 1;
    }
    let rows = t.div_ceil(2 * w).max(1);
    let mut m = bumpy_rect(w as u32, rows as u32);
    m.triangles.truncate(t);
    compact(&mut m);
    m
}

/// Drops the vertices no triangle uses, keeping the order of the others.
pub fn compact(m: &mut Mesh) {
    let mut used = vec![false; m.positions.len()];
    for t in &m.triangles {
        for &i in t {
            if let Some(u) = used.get_mut(i as usize) {
                *u = true;
            }
        }
    }
    let mut remap = vec![u32::MAX; m.positions.len()];
    let mut kept = Vec::new();
    for (i, p) in m.positions.iter().enumerate() {
        if used[i] {
            remap[i] = kept.len() as u32;
            kept.push(*p);
        }
    }
    for t in &mut m.triangles {
        for i in t.iter_mut() {
            if let Some(&r) = remap.get(*i as usize) {
                *i = r;
            }
        }
    }
    m.positions = kept;
}

/// An icosphere (closed, no boundary): 12 vertices / 20 triangles, each subdivision ×4.
pub fn icosphere(subdivisions: u32) -> Mesh {
    let g = (1.0 + 5f64.sqrt()) / 2.0;
    let mut p: Vec<[f64; 3]> = vec![
        [-1.0, g, 0.0],
        [1.0, g, 0.0],
        [-1.0, -g, 0.0],
        [1.0, -g, 0.0],
        [0.0, -1.0, g],
        [0.0, 1.0, g],
        [0.0, -1.0, -g],
        [0.0, 1.0, -g],
        [g, 0.0, -1.0],
        [g, 0.0, 1.0],
        [-g, 0.0, -1.0],
        [-g, 0.0, 1.0],
    ];
    let mut t: Vec<[u32; 3]> = vec![
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
    for _ in 0..subdivisions {
        let mut mid = HashMap::new();
        let mut next = Vec::new();
        let mut midpoint = |a: u32, b: u32, p: &mut Vec<[f64; 3]>| -> u32 {
            *mid.entry((a.min(b), a.max(b))).or_insert_with(|| {
                let (pa, pb) = (p[a as usize], p[b as usize]);
                p.push([
                    (pa[0] + pb[0]) / 2.0,
                    (pa[1] + pb[1]) / 2.0,
                    (pa[2] + pb[2]) / 2.0,
                ]);
                (p.len() - 1) as u32
            })
        };
        for [a, b, c] in t {
            let ab = midpoint(a, b, &mut p);
            let bc = midpoint(b, c, &mut p);
            let ca = midpoint(c, a, &mut p);
            next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        t = next;
    }
    let positions = p
        .into_iter()
        .map(|v| {
            let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            [(v[0] / l) as f32, (v[1] / l) as f32, (v[2] / l) as f32]
        })
        .collect();
    Mesh {
        positions,
        triangles: t,
    }
}

/// A closed box of 1 × 0.75 × 0.5 (a machined block: six flat faces meeting at 90° creases),
/// each face an `n × n` grid of quads, welded along the edges: `6n² + 2` vertices, `12n²`
/// triangles, wound outwards.
pub fn creased_box(n: u32) -> Mesh {
    let scale = [1.0f32, 0.75, 0.5];
    let mut index: HashMap<[u32; 3], u32> = HashMap::new();
    let mut positions = Vec::new();
    let mut vertex = |c: [u32; 3], positions: &mut Vec<[f32; 3]>| -> u32 {
        *index.entry(c).or_insert_with(|| {
            positions.push([
                c[0] as f32 / n as f32 * scale[0],
                c[1] as f32 / n as f32 * scale[1],
                c[2] as f32 / n as f32 * scale[2],
            ]);
            (positions.len() - 1) as u32
        })
    };
    let mut triangles = Vec::new();
    for axis in 0..3 {
        for side in [0, n] {
            // (u, v) with u × v = +axis; swapped on the low side so the face points outwards.
            let (mut u, mut v) = ((axis + 1) % 3, (axis + 2) % 3);
            if side == 0 {
                core::mem::swap(&mut u, &mut v);
            }
            let at = |i: u32, j: u32| {
                let mut c = [0u32; 3];
                c[axis] = side;
                c[u] = i;
                c[v] = j;
                c
            };
            for j in 0..n {
                for i in 0..n {
                    let a = vertex(at(i, j), &mut positions);
                    let b = vertex(at(i + 1, j), &mut positions);
                    let c = vertex(at(i + 1, j + 1), &mut positions);
                    let d = vertex(at(i, j + 1), &mut positions);
                    triangles.push([a, b, c]);
                    triangles.push([a, c, d]);
                }
            }
        }
    }
    Mesh {
        positions,
        triangles,
    }
}

/// Non-manifold input: the bumpy `n × n` grid, plus
/// * a fin: a strip of `n / 2` quads standing on the grid line `y = n / 2`, so each of those
///   grid edges has three triangles;
/// * a closed tetrahedron below the grid whose apex is grid vertex `(1, 1)`: that vertex has
///   two separate triangle fans (pinched).
pub fn fin(n: u32) -> Mesh {
    let mut m = bumpy_grid(n);
    let stride = n + 1;
    let row = n / 2;
    let (x0, x1) = (n / 4, n / 4 + n / 2);
    let first_top = m.positions.len() as u32;
    for x in x0..=x1 {
        let p = m.positions[(row * stride + x) as usize];
        m.positions.push([p[0], p[1], p[2] + 1.5]);
    }
    for x in x0..x1 {
        let (a, b) = (row * stride + x, row * stride + x + 1);
        let (c, d) = (first_top + (x + 1 - x0), first_top + (x - x0));
        m.triangles.push([a, b, c]);
        m.triangles.push([a, c, d]);
    }
    let apex = stride + 1;
    let p = m.positions[apex as usize];
    let base = m.positions.len() as u32;
    m.positions.push([p[0] - 0.5, p[1] - 0.5, p[2] - 1.0]);
    m.positions.push([p[0] + 0.5, p[1] - 0.5, p[2] - 1.0]);
    m.positions.push([p[0], p[1] + 0.5, p[2] - 1.0]);
    let (a, b, c) = (base, base + 1, base + 2);
    m.triangles
        .extend([[apex, b, a], [apex, c, b], [apex, a, c], [a, b, c]]);
    m
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Triangles per undirected edge.
    fn edge_uses(m: &Mesh) -> HashMap<(u32, u32), usize> {
        let mut e = HashMap::new();
        for t in &m.triangles {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                *e.entry((a.min(b), a.max(b))).or_insert(0) += 1;
            }
        }
        e
    }

    #[test]
    fn counts() {
        let g = bumpy_grid(12);
        assert_eq!((g.positions.len(), g.triangles.len()), (169, 288));
        let s = icosphere(2);
        assert_eq!((s.positions.len(), s.triangles.len()), (162, 320));
        let b = creased_box(6);
        assert_eq!((b.positions.len(), b.triangles.len()), (218, 432));
        for t in [1, 2, 3, 7, 100, 441, 1000, 12345] {
            let m = strip(t);
            assert_eq!(m.triangles.len(), t);
            let max = m.triangles.iter().flatten().copied().max().unwrap();
            assert_eq!(max as usize + 1, m.positions.len(), "t = {t}: compact");
        }
    }

    #[test]
    fn box_is_closed_and_consistently_wound() {
        let b = creased_box(3);
        assert!(edge_uses(&b).values().all(|&n| n == 2));
        let mut directed = std::collections::HashSet::new();
        for t in &b.triangles {
            for k in 0..3 {
                assert!(
                    directed.insert((t[k], t[(k + 1) % 3])),
                    "edge used twice the same way"
                );
            }
        }
        // Outwards: the signed volume is positive (1 × 0.75 × 0.5).
        let vol: f64 = b
            .triangles
            .iter()
            .map(|t| {
                let [a, b2, c] = t.map(|i| b.positions[i as usize].map(f64::from));
                (a[0] * (b2[1] * c[2] - b2[2] * c[1]) - a[1] * (b2[0] * c[2] - b2[2] * c[0])
                    + a[2] * (b2[0] * c[1] - b2[1] * c[0]))
                    / 6.0
            })
            .sum();
        assert!((vol - 0.375).abs() < 1e-6, "{vol}");
    }

    #[test]
    fn fin_is_non_manifold() {
        let m = fin(10);
        assert!(edge_uses(&m).values().any(|&n| n == 3));
        // The apex is used by grid triangles and by the tetrahedron.
        let apex = 12;
        let uses = m.triangles.iter().filter(|t| t.contains(&apex)).count();
        assert_eq!(uses, 6 + 3);
    }

    #[test]
    fn specs() {
        assert_eq!(generate("grid 3").unwrap().unwrap(), bumpy_grid(3));
        assert!(generate("tests/fixtures/cow.obj").is_none());
        assert!(matches!(generate("grid"), Some(Err(SpecError::Syntax(_)))));
        assert!(matches!(
            generate("grid 3 4"),
            Some(Err(SpecError::Syntax(_)))
        ));
        assert!(matches!(
            generate("icosphere 9"),
            Some(Err(SpecError::Range(_)))
        ));
    }
}
