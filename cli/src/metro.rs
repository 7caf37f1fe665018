//! Metro-style surface distance between two meshes (Cignoni, Rocchini, Scopigno, "Metro:
//! measuring error on simplified surfaces", 1998; the error definitions are quoted in
//! §4 of Zhu, Wang and Meng, mesh simplification with control-point error control, 2007:
//! `E_max = max q(v, S2)` and `E_mean = ∫ q(v, S2) ds / |S1|`).
//!
//! For each direction (a→b, then b→a) the source mesh is sampled and each sample's exact
//! distance to the other mesh's surface is computed (closest point on a triangle, f64, found
//! with a bounding-volume hierarchy over the triangles):
//!
//! * **vertex samples**: every referenced vertex;
//! * **edge samples**: `N/4` points on the distinct edges, spread by edge length (stratified,
//!   jittered);
//! * **face samples**: `N` points spread by triangle area (each triangle gets `⌊n⌋` or `⌈n⌉` of
//!   its expected `n`, uniform inside it),
//!
//! with `N = samples_per_triangle × max(triangles of a, triangles of b)` (10 by default). The
//! random numbers come from a PCG seeded with a fixed seed, so results are reproducible.
//!
//! * **max** is over all samples (vertices and edges catch the extremes that random face
//!   samples miss);
//! * **mean** and **RMS** are over the face samples only: they estimate `∫ d ds / |S|` and
//!   `sqrt(∫ d² ds / |S|)`, Metro's area-weighted definitions, which vertex and edge samples
//!   would bias.
//!
//! The report gives both directions, absolute and in percent of the bounding-box diagonal of
//! the FIRST (original) mesh over its referenced vertices; the symmetric **Hausdorff** distance
//! is the larger of the two maxima, and the **symmetric mean** is the average of the two
//! directions' means, `(mean(a→b) + mean(b→a)) / 2` (the figure compared with meshoptimizer's
//! published error numbers).

use std::io::IsTerminal;

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use rand::{RngExt, SeedableRng};
use rayon::prelude::*;
use serde::Serialize;

use crate::io::MeshData;

use crate::vec3::{cross, dot, norm2, sub, V3};

/// Sampling settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MetroOptions {
    /// Face samples per triangle of the larger mesh (edge samples are a quarter of that).
    pub samples_per_triangle: f64,
    /// Seed of the sampling RNG.
    pub seed: u64,
    /// Show a progress bar on stderr (only if stderr is a terminal).
    pub progress: bool,
}

impl Default for MetroOptions {
    fn default() -> Self {
        MetroOptions {
            samples_per_triangle: 10.0,
            seed: 0x6d65_7472_6f00_0001,
            progress: false,
        }
    }
}

/// Distances from the samples of one mesh to the surface of the other.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct DirectionStats {
    /// All samples (vertex + edge + face).
    pub samples: usize,
    /// Face samples (those behind mean and RMS).
    pub face_samples: usize,
    /// Largest distance over all samples.
    pub max: f64,
    /// Area-weighted mean distance (face samples).
    pub mean: f64,
    /// Area-weighted root mean square distance (face samples).
    pub rms: f64,
    /// `max` in % of the original mesh's bbox diagonal.
    pub max_pct: f64,
    /// `mean` in % of the original mesh's bbox diagonal.
    pub mean_pct: f64,
    /// `rms` in % of the original mesh's bbox diagonal.
    pub rms_pct: f64,
}

/// Result of [`metro`].
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct MetroReport {
    /// Bounding-box diagonal of the first mesh (referenced vertices), the unit of the `_pct`
    /// fields.
    pub diagonal: f64,
    /// Samples on the first mesh, distances to the second.
    pub a_to_b: DirectionStats,
    /// Samples on the second mesh, distances to the first.
    pub b_to_a: DirectionStats,
    /// Symmetric Hausdorff distance: the larger of the two maxima.
    pub hausdorff: f64,
    /// `hausdorff` in % of the diagonal.
    pub hausdorff_pct: f64,
    /// Mean of the two directions' means.
    pub symmetric_mean: f64,
    /// `symmetric_mean` in % of the diagonal.
    pub symmetric_mean_pct: f64,
}

impl std::fmt::Display for MetroReport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        writeln!(f, "  bbox diagonal (original) {:.6}", self.diagonal)?;
        writeln!(
            f,
            "  {:<16} {:>9} {:>13} {:>9} {:>13} {:>9} {:>13} {:>9}",
            "direction", "samples", "max", "max %", "mean", "mean %", "rms", "rms %"
        )?;
        for (name, d) in [
            ("orig -> simpl", &self.a_to_b),
            ("simpl -> orig", &self.b_to_a),
        ] {
            writeln!(
                f,
                "  {:<16} {:>9} {:>13.6e} {:>9.5} {:>13.6e} {:>9.5} {:>13.6e} {:>9.5}",
                name, d.samples, d.max, d.max_pct, d.mean, d.mean_pct, d.rms, d.rms_pct
            )?;
        }
        writeln!(
            f,
            "  Hausdorff (symmetric)    {:.6e} = {:.5} %",
            self.hausdorff, self.hausdorff_pct
        )?;
        write!(
            f,
            "  symmetric mean           {:.6e} = {:.5} %  ((mean a->b + mean b->a) / 2)",
            self.symmetric_mean, self.symmetric_mean_pct
        )
    }
}

// ---------------------------------------------------------------------------------------------
// Geometry

fn lerp(a: V3, b: V3, t: f64) -> V3 {
    [
        a[0] + (b[0] - a[0]) * t,
        a[1] + (b[1] - a[1]) * t,
        a[2] + (b[2] - a[2]) * t,
    ]
}

/// Squared distance from `p` to segment `ab`.
fn point_segment_dist2(p: V3, a: V3, b: V3) -> f64 {
    let ab = sub(b, a);
    let l2 = norm2(ab);
    let t = if l2 > 0.0 {
        (dot(sub(p, a), ab) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    norm2(sub(p, lerp(a, b, t)))
}

/// Squared distance from `p` to triangle `abc` (Ericson, Real-Time Collision Detection §5.1.5,
/// with a segment fallback for zero-area triangles).
pub fn point_triangle_dist2(p: V3, a: V3, b: V3, c: V3) -> f64 {
    let ab = sub(b, a);
    let ac = sub(c, a);
    let ap = sub(p, a);
    let d1 = dot(ab, ap);
    let d2 = dot(ac, ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return norm2(ap);
    }
    let bp = sub(p, b);
    let d3 = dot(ab, bp);
    let d4 = dot(ac, bp);
    if d3 >= 0.0 && d4 <= d3 {
        return norm2(bp);
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 && d1 - d3 > 0.0 {
        let v = d1 / (d1 - d3);
        return norm2(sub(p, lerp(a, b, v)));
    }
    let cp = sub(p, c);
    let d5 = dot(ab, cp);
    let d6 = dot(ac, cp);
    if d6 >= 0.0 && d5 <= d6 {
        return norm2(cp);
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 && d2 - d6 > 0.0 {
        let w = d2 / (d2 - d6);
        return norm2(sub(p, lerp(a, c, w)));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0 && (d4 - d3) + (d5 - d6) > 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return norm2(sub(p, lerp(b, c, w)));
    }
    let denom = va + vb + vc;
    let n = cross(ab, ac);
    if denom > 0.0 && norm2(n) > 0.0 {
        // Inside the face: distance to the plane.
        let d = dot(ap, n);
        return d * d / norm2(n);
    }
    // Zero-area (or numerically flat) triangle: the nearest of its three edges.
    point_segment_dist2(p, a, b)
        .min(point_segment_dist2(p, b, c))
        .min(point_segment_dist2(p, a, c))
}

// ---------------------------------------------------------------------------------------------
// Bounding-volume hierarchy

#[derive(Clone, Copy)]
struct Node {
    lo: V3,
    hi: V3,
    /// Leaf: first triangle; inner: index of the left child (the right one is `left + 1`).
    start: u32,
    /// Leaf: triangle count (> 0); inner: 0.
    count: u32,
}

/// A BVH over triangles for closest-point queries.
pub struct Bvh {
    nodes: Vec<Node>,
    tris: Vec<[V3; 3]>,
}

const LEAF: usize = 4;

fn box_dist2(p: V3, lo: V3, hi: V3) -> f64 {
    let mut d = 0.0;
    for k in 0..3 {
        let e = (lo[k] - p[k]).max(p[k] - hi[k]).max(0.0);
        d += e * e;
    }
    d
}

impl Bvh {
    /// Builds the hierarchy over the in-range triangles of `mesh`.
    pub fn new(mesh: &MeshData) -> Self {
        let n = mesh.positions.len();
        let mut tris: Vec<[V3; 3]> = mesh
            .triangles
            .iter()
            .filter(|t| t.iter().all(|&i| (i as usize) < n))
            .map(|t| t.map(|i| mesh.positions[i as usize].map(f64::from)))
            .collect();
        let mut bvh = Bvh {
            nodes: Vec::with_capacity(2 * tris.len() / LEAF + 1),
            tris: Vec::new(),
        };
        if !tris.is_empty() {
            bvh.nodes.push(Node {
                lo: [0.0; 3],
                hi: [0.0; 3],
                start: 0,
                count: 0,
            });
            let len = tris.len();
            bvh.build(0, &mut tris, 0, len);
        }
        bvh.tris = tris;
        bvh
    }

    fn build(&mut self, node: usize, tris: &mut [[V3; 3]], start: usize, end: usize) {
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        let mut clo = [f64::INFINITY; 3];
        let mut chi = [f64::NEG_INFINITY; 3];
        for t in &tris[start..end] {
            for k in 0..3 {
                for v in t {
                    lo[k] = lo[k].min(v[k]);
                    hi[k] = hi[k].max(v[k]);
                }
                let c = t[0][k] + t[1][k] + t[2][k];
                clo[k] = clo[k].min(c);
                chi[k] = chi[k].max(c);
            }
        }
        self.nodes[node].lo = lo;
        self.nodes[node].hi = hi;
        if end - start <= LEAF {
            self.nodes[node].start = start as u32;
            self.nodes[node].count = (end - start) as u32;
            return;
        }
        let axis = (0..3)
            .max_by(|&a, &b| (chi[a] - clo[a]).total_cmp(&(chi[b] - clo[b])))
            .unwrap_or(0);
        let mid = (start + end) / 2;
        let key = |t: &[V3; 3]| t[0][axis] + t[1][axis] + t[2][axis];
        tris[start..end].select_nth_unstable_by(mid - start, |x, y| key(x).total_cmp(&key(y)));
        let left = self.nodes.len();
        let blank = self.nodes[node];
        self.nodes.push(blank);
        self.nodes.push(blank);
        self.nodes[node].start = left as u32;
        self.nodes[node].count = 0;
        self.build(left, tris, start, mid);
        self.build(left + 1, tris, mid, end);
    }

    /// Squared distance from `p` to the nearest triangle and that triangle's index, starting
    /// from the bound given by triangle `hint` (any index; out of range means none).
    pub fn closest(&self, p: V3, hint: usize) -> (f64, usize) {
        let mut best = f64::INFINITY;
        let mut best_i = usize::MAX;
        if let Some(t) = self.tris.get(hint) {
            best = point_triangle_dist2(p, t[0], t[1], t[2]);
            best_i = hint;
        }
        if self.nodes.is_empty() {
            return (best, best_i);
        }
        let mut stack: [(u32, f64); 64] = [(0, 0.0); 64];
        let mut sp = 1;
        stack[0] = (0, box_dist2(p, self.nodes[0].lo, self.nodes[0].hi));
        while sp > 0 {
            sp -= 1;
            let (ni, d) = stack[sp];
            if d >= best {
                continue;
            }
            let node = self.nodes[ni as usize];
            if node.count > 0 {
                let s = node.start as usize;
                for (i, t) in self.tris[s..s + node.count as usize].iter().enumerate() {
                    let dt = point_triangle_dist2(p, t[0], t[1], t[2]);
                    if dt < best {
                        best = dt;
                        best_i = s + i;
                    }
                }
                continue;
            }
            let l = node.start as usize;
            let dl = box_dist2(p, self.nodes[l].lo, self.nodes[l].hi);
            let dr = box_dist2(p, self.nodes[l + 1].lo, self.nodes[l + 1].hi);
            // Push the farther child first so the nearer one is visited first. The tree is
            // balanced (median splits), so its depth stays far below the stack size.
            let (near, far) = if dl <= dr {
                ((l, dl), (l + 1, dr))
            } else {
                ((l + 1, dr), (l, dl))
            };
            if far.1 < best && sp < stack.len() {
                stack[sp] = (far.0 as u32, far.1);
                sp += 1;
            }
            if near.1 < best && sp < stack.len() {
                stack[sp] = (near.0 as u32, near.1);
                sp += 1;
            }
        }
        (best, best_i)
    }
}

// ---------------------------------------------------------------------------------------------
// Sampling

/// Sample points of a mesh: vertex and edge samples first, then `face` face samples.
struct Samples {
    points: Vec<V3>,
    /// Index of the first face sample in `points`.
    first_face: usize,
}

fn sample_mesh(mesh: &MeshData, n_face: usize, seed: u64) -> Samples {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
    let nv = mesh.positions.len();
    let pos = |i: u32| mesh.positions[i as usize].map(f64::from);
    let tris: Vec<[u32; 3]> = mesh
        .triangles
        .iter()
        .copied()
        .filter(|t| t.iter().all(|&i| (i as usize) < nv))
        .collect();
    let mut points = Vec::new();

    // Vertices.
    let mut used = vec![false; nv];
    for t in &tris {
        for &i in t {
            used[i as usize] = true;
        }
    }
    for (i, _) in used.iter().enumerate().filter(|(_, &u)| u) {
        points.push(pos(i as u32));
    }

    // Edges, by length.
    let mut edges: Vec<(u32, u32)> = tris
        .iter()
        .flat_map(|t| [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])])
        .filter(|(a, b)| a != b)
        .map(|(a, b)| (a.min(b), a.max(b)))
        .collect();
    edges.sort_unstable();
    edges.dedup();
    let lengths: Vec<f64> = edges
        .iter()
        .map(|&(a, b)| norm2(sub(pos(a), pos(b))).sqrt())
        .collect();
    let total_len: f64 = lengths.iter().sum();
    let n_edge = n_face / 4;
    if total_len > 0.0 {
        for (&(a, b), &len) in edges.iter().zip(&lengths) {
            let expect = len / total_len * n_edge as f64;
            let k = expect.floor() as usize + usize::from(rng.random::<f64>() < expect.fract());
            for j in 0..k {
                let t = (j as f64 + rng.random::<f64>()) / k as f64;
                points.push(lerp(pos(a), pos(b), t));
            }
        }
    }

    // Faces, by area.
    let first_face = points.len();
    let areas: Vec<f64> = tris
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(pos);
            norm2(cross(sub(b, a), sub(c, a))).sqrt() / 2.0
        })
        .collect();
    let total_area: f64 = areas.iter().sum();
    if total_area > 0.0 {
        points.reserve(n_face + tris.len());
        for (t, &area) in tris.iter().zip(&areas) {
            let expect = area / total_area * n_face as f64;
            let k = expect.floor() as usize + usize::from(rng.random::<f64>() < expect.fract());
            let [a, b, c] = t.map(pos);
            for _ in 0..k {
                let s = rng.random::<f64>().sqrt();
                let r = rng.random::<f64>();
                let (wa, wb, wc) = (1.0 - s, s * (1.0 - r), s * r);
                points.push([
                    wa * a[0] + wb * b[0] + wc * c[0],
                    wa * a[1] + wb * b[1] + wc * c[1],
                    wa * a[2] + wb * b[2] + wc * c[2],
                ]);
            }
        }
    }
    Samples { points, first_face }
}

const CHUNK: usize = 2048;

/// Distances (not squared) from every point to the BVH's surface, in order, in parallel.
fn distances(points: &[V3], bvh: &Bvh, bar: &ProgressBar) -> Vec<f64> {
    points
        .par_chunks(CHUNK)
        .flat_map_iter(|chunk| {
            let mut hint = usize::MAX;
            let out: Vec<f64> = chunk
                .iter()
                .map(|&p| {
                    let (d2, i) = bvh.closest(p, hint);
                    hint = i;
                    d2.sqrt()
                })
                .collect();
            let n = chunk.len() as u64;
            bar.inc(n);
            out
        })
        .collect()
}

fn direction(
    from: &MeshData,
    to: &Bvh,
    n_face: usize,
    seed: u64,
    bar: &ProgressBar,
) -> DirectionStats {
    let s = sample_mesh(from, n_face, seed);
    let d = distances(&s.points, to, bar);
    let max = d.iter().copied().fold(0.0, f64::max);
    let faces = &d[s.first_face..];
    let (mean, rms) = if faces.is_empty() {
        (0.0, 0.0)
    } else {
        let n = faces.len() as f64;
        // Fixed chunking: the sums do not depend on the thread count.
        let sum: f64 = faces.chunks(CHUNK).map(|c| c.iter().sum::<f64>()).sum();
        let sum2: f64 = faces
            .chunks(CHUNK)
            .map(|c| c.iter().map(|x| x * x).sum::<f64>())
            .sum();
        (sum / n, (sum2 / n).sqrt())
    };
    DirectionStats {
        samples: d.len(),
        face_samples: faces.len(),
        max,
        mean,
        rms,
        ..Default::default()
    }
}

fn progress_bar(enabled: bool, total: u64) -> ProgressBar {
    if enabled && std::io::stderr().is_terminal() {
        let bar = ProgressBar::with_draw_target(Some(total), ProgressDrawTarget::stderr());
        if let Ok(style) =
            ProgressStyle::with_template("metro {bar:40} {pos}/{len} samples ({eta} left)")
        {
            bar.set_style(style);
        }
        bar
    } else {
        ProgressBar::hidden()
    }
}

/// Metro distance between `a` (the original) and `b` (the simplification). See the module
/// documentation for the sampling and the definitions.
pub fn metro(a: &MeshData, b: &MeshData, opts: &MetroOptions) -> MetroReport {
    let tmax = a.triangles.len().max(b.triangles.len());
    let n_face = (opts.samples_per_triangle.max(0.0) * tmax as f64).ceil() as usize;
    // Vertices + edges + faces, roughly, for the bar.
    let estimate = |m: &MeshData| (m.positions.len() + n_face + n_face / 4) as u64;
    let bar = progress_bar(opts.progress, estimate(a) + estimate(b));
    let bvh_a = Bvh::new(a);
    let bvh_b = Bvh::new(b);
    let mut ab = direction(a, &bvh_b, n_face, opts.seed, &bar);
    let mut ba = direction(b, &bvh_a, n_face, opts.seed ^ 0x9e37_79b9_7f4a_7c15, &bar);
    bar.finish_and_clear();

    let diagonal = a.bbox_diagonal();
    let pct = |x: f64| {
        if diagonal > 0.0 {
            100.0 * x / diagonal
        } else {
            0.0
        }
    };
    for d in [&mut ab, &mut ba] {
        d.max_pct = pct(d.max);
        d.mean_pct = pct(d.mean);
        d.rms_pct = pct(d.rms);
    }
    let hausdorff = ab.max.max(ba.max);
    let symmetric_mean = (ab.mean + ba.mean) / 2.0;
    MetroReport {
        diagonal,
        hausdorff,
        hausdorff_pct: pct(hausdorff),
        symmetric_mean,
        symmetric_mean_pct: pct(symmetric_mean),
        a_to_b: ab,
        b_to_a: ba,
    }
}

/// Distance of every vertex of `a` (unreferenced ones included) to the surface of `b`.
pub fn per_vertex_error(a: &MeshData, b: &MeshData) -> Vec<f32> {
    let bvh = Bvh::new(b);
    let points: Vec<V3> = a.positions.iter().map(|p| p.map(f64::from)).collect();
    distances(&points, &bvh, &ProgressBar::hidden())
        .into_iter()
        .map(|d| d as f32)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An n x n grid on the unit square at height z.
    fn plane(n: u32, z: f32) -> MeshData {
        let mut m = MeshData::default();
        for y in 0..=n {
            for x in 0..=n {
                m.positions
                    .push([x as f32 / n as f32, y as f32 / n as f32, z]);
            }
        }
        for y in 0..n {
            for x in 0..n {
                let v = y * (n + 1) + x;
                m.triangles.push([v, v + 1, v + n + 2]);
                m.triangles.push([v, v + n + 2, v + n + 1]);
            }
        }
        m
    }

    /// Icosphere on the unit sphere: `levels` subdivisions of the icosahedron (the golden
    /// cases' generator).
    fn sphere(levels: u32) -> MeshData {
        let m = meshfmt::golden::icosphere(levels);
        MeshData {
            positions: m.positions,
            triangles: m.triangles,
        }
    }

    fn icosahedron() -> MeshData {
        sphere(0)
    }

    #[test]
    fn point_triangle_regions() {
        let (a, b, c) = ([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
        let d = |p| point_triangle_dist2(p, a, b, c);
        assert_eq!(d([0.2, 0.2, 3.0]), 9.0); // face
        assert_eq!(d([-1.0, -1.0, 0.0]), 2.0); // vertex a
        assert_eq!(d([2.0, 0.0, 0.0]), 1.0); // vertex b
        assert_eq!(d([0.0, 3.0, 0.0]), 4.0); // vertex c
        assert_eq!(d([0.5, -2.0, 0.0]), 4.0); // edge ab
        assert!((d([1.0, 1.0, 0.0]) - 0.5).abs() < 1e-15); // edge bc
        assert_eq!(d([-0.5, 0.5, 1.0]), 1.25); // edge ca
                                               // Degenerate: all on a line, and all one point.
        let e = point_triangle_dist2([0.5, 1.0, 0.0], a, b, [2.0, 0.0, 0.0]);
        assert!((e - 1.0).abs() < 1e-15);
        assert_eq!(point_triangle_dist2([0.0, 0.0, 2.0], a, a, a), 4.0);
    }

    #[test]
    fn bvh_matches_brute_force() {
        let m = sphere(2);
        let bvh = Bvh::new(&m);
        let mut rng = rand_pcg::Pcg64::seed_from_u64(7);
        for _ in 0..500 {
            let p: V3 = [0, 1, 2].map(|_| rng.random::<f64>() * 3.0 - 1.5);
            let brute = m
                .triangles
                .iter()
                .map(|t| {
                    let [a, b, c] = t.map(|i| m.positions[i as usize].map(f64::from));
                    point_triangle_dist2(p, a, b, c)
                })
                .fold(f64::INFINITY, f64::min);
            let (d, _) = bvh.closest(p, usize::MAX);
            assert_eq!(d, brute);
            let (d2, _) = bvh.closest(p, 17);
            assert_eq!(d2, brute);
        }
    }

    #[test]
    fn shifted_plane_is_d_everywhere() {
        let d = 0.01f32;
        let a = plane(8, 0.0);
        let b = plane(8, d);
        let r = metro(&a, &b, &MetroOptions::default());
        let d = f64::from(d);
        for s in [&r.a_to_b, &r.b_to_a] {
            assert!(s.face_samples >= 1280 && s.samples > s.face_samples);
            for x in [s.max, s.mean, s.rms] {
                assert!((x - d).abs() < 1e-9, "{r:?}");
            }
        }
        assert!((r.hausdorff - d).abs() < 1e-9);
        assert!((r.symmetric_mean - d).abs() < 1e-9);
        assert!((r.diagonal - 2f64.sqrt()).abs() < 1e-12);
        assert!((r.hausdorff_pct - 100.0 * d / 2f64.sqrt()).abs() < 1e-6);
        let e = per_vertex_error(&a, &b);
        assert_eq!(e.len(), 81);
        assert!(e.iter().all(|&x| (f64::from(x) - d).abs() < 1e-9));
    }

    #[test]
    fn sphere_against_inscribed_icosahedron() {
        let inradius = 0.794_654_472_291_766_1;
        let s = sphere(5); // 20480 triangles; its chords sag by at most ~2e-4
        let ico = icosahedron();
        let r = metro(&s, &ico, &MetroOptions::default());
        let want = 1.0 - inradius;
        assert!((r.a_to_b.max - want).abs() < 2e-3, "{r:?}");
        assert!((r.b_to_a.max - want).abs() < 2e-3, "{r:?}");
        assert!((r.hausdorff - want).abs() < 2e-3);
        for d in [&r.a_to_b, &r.b_to_a] {
            assert!(d.mean > 0.05 && d.mean < d.rms && d.rms < d.max, "{r:?}");
        }
        // The icosahedron's vertices lie on the icosphere.
        let e = per_vertex_error(&ico, &s);
        assert!(e.iter().all(|&x| x < 1e-6), "{e:?}");
    }

    #[test]
    fn mesh_against_itself_is_zero_and_deterministic() {
        let s = sphere(3);
        let r = metro(&s, &s, &MetroOptions::default());
        assert!(r.hausdorff < 1e-12 && r.symmetric_mean < 1e-12, "{r:?}");
        let a = plane(5, 0.0);
        let mut b = plane(5, 0.0);
        b.positions[8][2] = 0.3; // a bump
        let opts = MetroOptions {
            samples_per_triangle: 3.0,
            ..Default::default()
        };
        assert_eq!(metro(&a, &b, &opts), metro(&a, &b, &opts));
        let r = metro(&a, &b, &opts);
        assert!((r.b_to_a.max - 0.3).abs() < 1e-6, "{r:?}");
    }
}
