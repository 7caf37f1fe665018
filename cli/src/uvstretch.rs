//! How much a texture stretches on a mesh: the L2 stretch of Sander, Snyder, Gortler and Hoppe
//! ("Texture mapping progressive meshes", SIGGRAPH 2001, §3), area-weighted over the mesh and
//! normalised so that a map that is an isometry up to one global scale scores exactly 1.
//!
//! For a triangle with positions `q0, q1, q2` and texture coordinates `(s_i, t_i)`, the
//! map from texture to surface has the partial derivatives
//! `S_s = (q0 (t1 - t2) + q1 (t2 - t0) + q2 (t0 - t1)) / 2A` and
//! `S_t = (q0 (s2 - s1) + q1 (s0 - s2) + q2 (s1 - s0)) / 2A` (`A` the signed texture area);
//! its L2 stretch is `√((|S_s|² + |S_t|²) / 2)`. Over the mesh,
//! `L2 = √(Σ L2(T)² A'(T) / Σ A'(T))` with `A'` the texture area, and the figure reported is
//! `L2 · √(Σ A' / Σ A_3D)`: 1 for a conformal map of uniform scale, more as the texture is
//! stretched or sheared. Simplification changes it when a kept triangle spans texture that the
//! original surface laid out differently, which is what a textured model's user sees.
//! Triangles with zero texture area (degenerate charts) carry no weight.
//!
//! A second figure, [`texture_deviation`], says how far the texture slid on the surface: for
//! sample points of the original surface, the distance from each to the point of the result
//! that carries the same texture coordinates (the texture deviation of Cohen, Olano and
//! Manocha, "Appearance-preserving simplification", SIGGRAPH 1998, which the survey of
//! simplification methods cites). Stretch can fall when simplification removes small, badly
//! mapped triangles; deviation cannot hide a texture that moved.
//!
//! A third, [`torn_triangles`], counts the defect a user sees at once: result triangles whose
//! corners come from two texture charts, which show a piece of another chart's texture.

use crate::vec3::{cross, norm2, sub, V3};

fn area3(q: [V3; 3]) -> f64 {
    let (u, v) = (sub(q[1], q[0]), sub(q[2], q[0]));
    let c = cross(u, v);
    norm2(c).sqrt() / 2.0
}

/// The normalised L2 stretch of `triangles` over `positions` with one texture coordinate per
/// vertex (`uvs`, same indexing); `None` when no triangle has texture area or an index is out
/// of range.
pub fn l2_stretch(positions: &[[f32; 3]], uvs: &[[f32; 2]], triangles: &[[u32; 3]]) -> Option<f64> {
    let (mut sum, mut uv_area, mut area) = (0.0f64, 0.0f64, 0.0f64);
    for t in triangles {
        let q: Vec<V3> = t
            .iter()
            .map(|&i| positions.get(i as usize).map(|p| p.map(f64::from)))
            .collect::<Option<_>>()?;
        let st: Vec<[f64; 2]> = t
            .iter()
            .map(|&i| uvs.get(i as usize).map(|p| p.map(f64::from)))
            .collect::<Option<_>>()?;
        let q = [q[0], q[1], q[2]];
        let a2 = (st[1][0] - st[0][0]) * (st[2][1] - st[0][1])
            - (st[2][0] - st[0][0]) * (st[1][1] - st[0][1]);
        if a2 == 0.0 || !a2.is_finite() {
            continue;
        }
        let (s, tt) = (
            [st[0][0], st[1][0], st[2][0]],
            [st[0][1], st[1][1], st[2][1]],
        );
        let ss = [0, 1, 2].map(|k| {
            (q[0][k] * (tt[1] - tt[2]) + q[1][k] * (tt[2] - tt[0]) + q[2][k] * (tt[0] - tt[1])) / a2
        });
        let st_ = [0, 1, 2].map(|k| {
            (q[0][k] * (s[2] - s[1]) + q[1][k] * (s[0] - s[2]) + q[2][k] * (s[1] - s[0])) / a2
        });
        let l2sq = (norm2(ss) + norm2(st_)) / 2.0;
        let w = a2.abs() / 2.0;
        sum += l2sq * w;
        uv_area += w;
        area += area3(q);
    }
    (uv_area > 0.0 && area > 0.0).then(|| (sum / uv_area).sqrt() * (uv_area / area).sqrt())
}

/// How many of `result`'s triangles take corners from two or more texture charts of
/// `original`. A chart is a connected piece of the original surface with continuous texture
/// coordinates: its triangles joined across edges whose two ends have one position and one
/// texture coordinate on both sides (vertices split only by a normal do not separate charts).
/// Corners past `positions` or `uvs` are their own chart.
pub fn torn_triangles(
    positions: &[[f32; 3]],
    uvs: &[[f32; 2]],
    original: &[[u32; 3]],
    result: &[[u32; 3]],
) -> usize {
    let key = |v: u32| {
        let p = positions.get(v as usize).map(|p| p.map(f32::to_bits));
        let t = uvs.get(v as usize).map(|t| t.map(f32::to_bits));
        (p, t, if p.is_none() || t.is_none() { v } else { 0 })
    };
    // Union-find over (position, texture coordinate) keys, joined along triangle edges.
    let mut id = std::collections::HashMap::new();
    let mut parent: Vec<usize> = Vec::new();
    let mut node = |v: u32, parent: &mut Vec<usize>| {
        *id.entry(key(v)).or_insert_with(|| {
            parent.push(parent.len());
            parent.len() - 1
        })
    };
    fn root(parent: &mut [usize], mut x: usize) -> usize {
        while parent[x] != x {
            parent[x] = parent[parent[x]];
            x = parent[x];
        }
        x
    }
    for t in original {
        let n = t.map(|v| node(v, &mut parent));
        for k in 1..3 {
            let (a, b) = (root(&mut parent, n[0]), root(&mut parent, n[k]));
            parent[a] = b;
        }
    }
    result
        .iter()
        .filter(|t| {
            let c = t.map(|v| {
                let n = node(v, &mut parent);
                root(&mut parent, n)
            });
            c[0] != c[1] || c[1] != c[2]
        })
        .count()
}

/// Texture deviation of `result` against `original` (both over `positions` and `uvs`, one per
/// vertex): mean (area-weighted) and largest distance, over 4 samples per original triangle
/// (its centroid and the midpoints between the centroid and each corner), from the original
/// surface point to the nearest result point with the same texture coordinates. Samples whose
/// texture coordinates no result triangle covers are counted in the third value and left out
/// of the distances. `None` when an index is out of range.
pub fn texture_deviation(
    positions: &[[f32; 3]],
    uvs: &[[f32; 2]],
    original: &[[u32; 3]],
    result: &[[u32; 3]],
) -> Option<(f64, f64, usize)> {
    let get = |t: &[u32; 3]| -> Option<([V3; 3], [[f64; 2]; 3])> {
        let mut q = [[0.0; 3]; 3];
        let mut st = [[0.0; 2]; 3];
        for k in 0..3 {
            q[k] = positions.get(t[k] as usize)?.map(f64::from);
            st[k] = uvs.get(t[k] as usize)?.map(f64::from);
        }
        Some((q, st))
    };
    let out: Vec<([V3; 3], [[f64; 2]; 3])> = result.iter().map(get).collect::<Option<_>>()?;
    // A uniform grid over the result's texture box; each cell lists the triangles whose
    // texture box meets it.
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for (_, st) in &out {
        for c in st {
            for k in 0..2 {
                lo[k] = lo[k].min(c[k]);
                hi[k] = hi[k].max(c[k]);
            }
        }
    }
    let n = ((out.len() as f64).sqrt().ceil() as usize).clamp(1, 1024);
    let size = [0, 1].map(|k| ((hi[k] - lo[k]) / n as f64).max(f64::MIN_POSITIVE));
    let cell = |x: f64, k: usize| (((x - lo[k]) / size[k]).floor().max(0.0) as usize).min(n - 1);
    let mut grid: Vec<Vec<u32>> = vec![Vec::new(); n * n];
    for (i, (_, st)) in out.iter().enumerate() {
        let f = |k: usize, g: fn(f64, f64) -> f64, init: f64| st.iter().map(|c| c[k]).fold(init, g);
        let (x0, x1) = (
            cell(f(0, f64::min, f64::INFINITY), 0),
            cell(f(0, f64::max, f64::NEG_INFINITY), 0),
        );
        let (y0, y1) = (
            cell(f(1, f64::min, f64::INFINITY), 1),
            cell(f(1, f64::max, f64::NEG_INFINITY), 1),
        );
        for y in y0..=y1 {
            for x in x0..=x1 {
                grid[y * n + x].push(i as u32);
            }
        }
    }
    let (mut sum, mut weight, mut top, mut lost) = (0.0f64, 0.0f64, 0.0f64, 0usize);
    for t in original {
        let (q, st) = get(t)?;
        let area = area3(q);
        let centre = |v: &[V3; 3]| [0, 1, 2].map(|k| (v[0][k] + v[1][k] + v[2][k]) / 3.0);
        let cq = centre(&q);
        let cs = [0, 1].map(|k| (st[0][k] + st[1][k] + st[2][k]) / 3.0);
        let mut samples = vec![(cq, cs)];
        for c in 0..3 {
            samples.push((
                [0, 1, 2].map(|k| (cq[k] + q[c][k]) / 2.0),
                [0, 1].map(|k| (cs[k] + st[c][k]) / 2.0),
            ));
        }
        for (p, uv) in samples {
            if !(uv[0].is_finite() && uv[1].is_finite())
                || uv[0] < lo[0]
                || uv[0] > hi[0]
                || uv[1] < lo[1]
                || uv[1] > hi[1]
            {
                lost += 1;
                continue;
            }
            let mut best = f64::INFINITY;
            for &i in &grid[cell(uv[1], 1) * n + cell(uv[0], 0)] {
                let (oq, ost) = &out[i as usize];
                let d = (ost[1][0] - ost[0][0]) * (ost[2][1] - ost[0][1])
                    - (ost[2][0] - ost[0][0]) * (ost[1][1] - ost[0][1]);
                if d == 0.0 || !d.is_finite() {
                    continue;
                }
                let e = |a: [f64; 2], b: [f64; 2]| {
                    (b[0] - a[0]) * (uv[1] - a[1]) - (uv[0] - a[0]) * (b[1] - a[1])
                };
                let w = [e(ost[1], ost[2]) / d, e(ost[2], ost[0]) / d];
                let w = [w[0], w[1], 1.0 - w[0] - w[1]];
                // A little slack: a sample on a shared texture edge belongs to both sides.
                if w.iter().any(|&c| c < -1e-9) {
                    continue;
                }
                let at = [0, 1, 2].map(|k| w[0] * oq[0][k] + w[1] * oq[1][k] + w[2] * oq[2][k]);
                best = best.min(norm2(sub(at, p)));
            }
            if best.is_finite() {
                let d = best.sqrt();
                sum += d * area;
                weight += area;
                top = top.max(d);
            } else {
                lost += 1;
            }
        }
    }
    Some((if weight > 0.0 { sum / weight } else { 0.0 }, top, lost))
}

#[cfg(test)]
mod tests {
    use super::*;

    type Mesh = (Vec<[f32; 3]>, Vec<[f32; 2]>, Vec<[u32; 3]>);

    fn square(uv_scale: [f32; 2]) -> Mesh {
        let p = vec![
            [0.0, 0.0, 0.0],
            [2.0, 0.0, 0.0],
            [2.0, 2.0, 0.0],
            [0.0, 2.0, 0.0],
        ];
        let uv = p
            .iter()
            .map(|q| [q[0] * uv_scale[0], q[1] * uv_scale[1]])
            .collect();
        (p, uv, vec![[0, 1, 2], [0, 2, 3]])
    }

    #[test]
    fn isometry_up_to_scale_is_one_and_stretch_is_more() {
        let (p, uv, t) = square([0.3, 0.3]);
        let s = l2_stretch(&p, &uv, &t).unwrap();
        assert!((s - 1.0).abs() < 1e-12, "{s}");
        // Squashed 4:1 in the texture: √((4 + 1/4)/2)·... over the normalisation, > 1.
        let (p, uv, t) = square([0.4, 0.1]);
        let s = l2_stretch(&p, &uv, &t).unwrap();
        // S_s = 1/0.4, S_t = 1/0.1: L2 = √((6.25 + 100)/2); normalised by √(0.04).
        let want = ((6.25f64 + 100.0) / 2.0).sqrt() * 0.04f64.sqrt();
        assert!((s - want).abs() < 1e-6, "{s} {want}");
        assert!(s > 1.4);
    }

    #[test]
    fn a_folded_chart_and_bad_input() {
        // A kept triangle spanning texture laid out elsewhere: the bent square's second
        // triangle lifted out of the plane stretches the texture.
        let (mut p, uv, t) = square([0.5, 0.5]);
        p[3] = [0.0, 2.0, 3.0];
        assert!(l2_stretch(&p, &uv, &t).unwrap() > 1.01);
        assert_eq!(l2_stretch(&p, &uv, &[[0, 1, 9]]), None);
        assert_eq!(l2_stretch(&p, &[[0.0, 0.0]; 4], &t), None);
    }

    #[test]
    fn deviation_is_zero_for_the_same_mesh_and_sees_a_moved_texture() {
        // A 3x3-vertex grid, UV = xy / 2; the result drops the centre vertex.
        let mut p = Vec::new();
        let mut uv = Vec::new();
        for y in 0..3 {
            for x in 0..3 {
                p.push([x as f32, y as f32, 0.0]);
                uv.push([x as f32 / 2.0, y as f32 / 2.0]);
            }
        }
        p[4][2] = 0.5; // the centre is raised
        let id = |x: u32, y: u32| y * 3 + x;
        let mut full = Vec::new();
        for y in 0..2 {
            for x in 0..2 {
                full.push([id(x, y), id(x + 1, y), id(x + 1, y + 1)]);
                full.push([id(x, y), id(x + 1, y + 1), id(x, y + 1)]);
            }
        }
        let (mean, max, lost) = texture_deviation(&p, &uv, &full, &full).unwrap();
        assert!(
            mean < 1e-12 && max < 1e-12 && lost == 0,
            "{mean} {max} {lost}"
        );
        // Without the raised centre: every sample sits at most 0.5 above the flat result,
        // the centre's neighbourhood the most.
        let flat = vec![
            [id(0, 0), id(2, 0), id(2, 2)],
            [id(0, 0), id(2, 2), id(0, 2)],
        ];
        let (mean, max, lost) = texture_deviation(&p, &uv, &full, &flat).unwrap();
        assert_eq!(lost, 0);
        assert!(max > 0.2 && max <= 0.5 + 1e-9, "{max}");
        assert!(mean > 0.05 && mean < max, "{mean}");
        // A result missing half the texture loses the samples there.
        let half = vec![[id(0, 0), id(2, 0), id(2, 2)]];
        let (_, _, lost) = texture_deviation(&p, &uv, &full, &half).unwrap();
        assert!(lost > 4 && lost < 28, "{lost}");
        assert_eq!(texture_deviation(&p, &uv, &full, &[[0, 1, 99]]), None);
    }

    #[test]
    fn torn_triangles_count_corners_from_two_charts() {
        // A strip of two squares; the second square's texture is another chart (its left
        // edge's vertices 4, 5 repeat 1, 2 with other coordinates). Vertices 6, 7 repeat 4, 5
        // with another normal only: the same chart.
        let p = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [2.0, 0.0, 0.0],
            [2.0, 1.0, 0.0],
        ];
        let uv = vec![
            [0.0, 0.0],
            [0.5, 0.0],
            [0.5, 1.0],
            [0.0, 1.0],
            [0.6, 0.0],
            [0.6, 1.0],
            [0.6, 0.0],
            [0.6, 1.0],
            [1.0, 0.0],
            [1.0, 1.0],
        ];
        let original = [[0, 1, 2], [0, 2, 3], [4, 8, 9], [6, 9, 7]];
        assert_eq!(torn_triangles(&p, &uv, &original, &original), 0);
        // The first square's corner 0 with the second chart's 8, 9: torn; 4 with 6's chart-mate
        // 9 is not.
        let result = [[0, 8, 9], [4, 8, 9], [0, 2, 3], [6, 8, 5]];
        assert_eq!(torn_triangles(&p, &uv, &original, &result), 1);
    }
}
