//! The classification, the loop splitting and the fill plan on rings built in code.

use super::triangulate::*;
use super::*;
use crate::mesh::NIL;

fn fan_of(p: &[V3]) -> (Fan, [V3; MAX_RING]) {
    let mut pos = [[0.0; 3]; MAX_RING];
    let mut ring = [NIL; MAX_RING];
    for (i, q) in p.iter().enumerate() {
        pos[i] = *q;
        ring[i] = i;
    }
    (
        Fan {
            ring,
            n: p.len(),
            boundary: false,
            normal: [0.0, 0.0, 1.0],
            key: 0.0,
            line: None,
            ends: 0,
        },
        pos,
    )
}

/// Signed doubled area of a triangle of ring positions, seen from +z.
fn area_z(pos: &[V3; MAX_RING], t: [u8; 3]) -> f32 {
    let [a, b, c] = t.map(|k| pos[k as usize]);
    (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
}

/// Concave loops (an L, a star, counter-clockwise): every triangle the splitting makes
/// faces +z and they tile the loop. Fails if the side test of the split plane is dropped
/// (a star's triangle then faces −z) or if the aspect ratio stops choosing (a hexagon's
/// triangles are then not the widest splits').
#[test]
fn concave_loops_split_inside() {
    let p = [
        [0.0, 0.0, 0.0],
        [4.0, 0.0, 0.0],
        [4.0, 1.0, 0.0],
        [1.0, 1.0, 0.0],
        [1.0, 4.0, 0.0],
        [0.0, 4.0, 0.0],
    ];
    let (fan, pos) = fan_of(&p);
    let mut out = [[0u8; 3]; MAX_RING];
    let mut planes = [[0.0f32; 3]; MAX_RING];
    let n = triangulate(&fan, &pos, 0.1, &mut out, &mut planes).expect("a split");
    assert_eq!(n, 4);
    let total: f32 = out[..n].iter().map(|&t| area_z(&pos, t)).sum();
    for &t in &out[..n] {
        assert!(area_z(&pos, t) > 0.0, "{t:?} faces away");
    }
    // The pieces tile the loop exactly (no overlap, nothing outside).
    let mut shoelace = 0.0;
    for i in 0..p.len() {
        let (a, b) = (p[i], p[(i + 1) % p.len()]);
        shoelace += a[0] * b[1] - a[1] * b[0];
    }
    assert!((total - shoelace).abs() < 1e-4, "{total} vs {shoelace}");
    // The widest split first: in this hexagon 2-5 (aspect 0.45, then 1-4 at 0.42), then
    // 1-5 and 2-4 in the halves; taking the first valid split instead gives a fan from 0.
    let hex = [
        [2.0, 0.0, 0.0],
        [1.2, 1.5, 0.0],
        [-0.8, 1.6, 0.0],
        [-2.0, 0.2, 0.0],
        [-1.0, -1.4, 0.0],
        [1.0, -1.3, 0.0],
    ];
    let (fan, pos) = fan_of(&hex);
    let n = triangulate(&fan, &pos, 0.1, &mut out, &mut planes).expect("a split");
    let mut got = out[..n].to_vec();
    got.sort();
    assert_eq!(got, [[0, 1, 5], [1, 2, 5], [2, 3, 4], [2, 4, 5]]);
    // A star whose widest chord (1-3, around the notch at 2) leaves the loop: without
    // the side test it is taken and a triangle faces −z.
    let star = [
        [-0.4, 1.8, 0.0],
        [-0.3, 0.0, 0.0],
        [-0.8, -0.2, 0.0],
        [-0.2, -1.5, 0.0],
        [0.2, -0.7, 0.0],
        [1.0, -1.3, 0.0],
        [0.5, 0.0, 0.0],
    ];
    let (fan, pos) = fan_of(&star);
    let n = triangulate(&fan, &pos, 0.1, &mut out, &mut planes).expect("a split");
    assert_eq!(n, 5);
    for &t in &out[..n] {
        assert!(area_z(&pos, t) > 0.0, "{t:?} faces away");
    }
    // Below the aspect limit: refused.
    let thin = [
        [0.0, 0.0, 0.0],
        [10.0, 0.0, 0.0],
        [10.0, 0.2, 0.0],
        [0.0, 0.2, 0.0],
    ];
    let (fan, pos) = fan_of(&thin);
    assert_eq!(
        triangulate(&fan, &pos, 0.1, &mut out, &mut planes),
        Err(NoSplit::Aspect)
    );
    assert!(triangulate(&fan, &pos, 0.0, &mut out, &mut planes).is_ok());
}

/// A vertex on a fold (two planes meeting along the line through ring positions 0 and 3):
/// the fan from 0 keeps both planes exactly, so the fitted fill takes it at no cost, while
/// the loop splitting, chosen for shape, crosses the fold. Fails if the ring's fans are
/// not candidates or the fill is not chosen by fit.
#[test]
fn the_fitted_fill_keeps_a_fold() {
    let p = [
        [2.0, 0.0, 0.0],
        [1.0, 1.5, 1.5],
        [-1.0, 1.5, 1.5],
        [-2.0, 0.0, 0.0],
        [-1.0, -1.5, 0.0],
        [1.0, -1.5, 0.0],
    ];
    let (mut fan, pos) = fan_of(&p);
    fan.normal = math::scale([0.0, -1.0, 1.0 + 2.0f32.sqrt()], 1.0 / 2.613_126);
    let pv = [0.0, 0.0, 0.0];
    let mut out = [[0u8; 3]; MAX_RING];
    let mut planes = [[0.0f32; 3]; MAX_RING];
    let op = VertexDecimation::new();
    let (n, key, _) = plan(&fan, pv, &pos, &op, 0.0, &mut out, &mut planes).expect("a fill");
    assert_eq!(n, 4);
    assert!(key.abs() < 1e-6, "{key}");
    for t in &out[..n] {
        assert!(t.contains(&0), "{t:?} is not the fan from 0");
    }
    let shape = op.with_fill(Fill::Shape);
    let (n, _, _) = plan(&fan, pv, &pos, &shape, 0.0, &mut out, &mut planes).expect("a split");
    let (e, _, _) = fit2(pv, &pos, &out[..n]);
    assert!(e > 1e-3, "the loop splitting fits too: {e}");
}
