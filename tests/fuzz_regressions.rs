//! Inputs found by the fuzz targets (`fuzz/`), each with the reproducer it came from in
//! `fuzz/regressions/`. Replay a reproducer with
//! `cd fuzz && cargo +nightly fuzz run -O -a -s none simplify regressions/<file>`, or decode it
//! with `cargo run --example show -- regressions/<file>`.

use tinydecimate::{Config, Schedule, Workspace};

/// `fuzz/regressions/simplify-dead-duplicate-matches-later-triangle`.
///
/// Step 3 of `Mesh::build` (src/mesh.rs) kills a duplicate as `[x, x, x]` but leaves its
/// corners linked until the re-link after the loop. `same_set(tri(u), tri)` only asks whether
/// every index of the *earlier* triangle occurs in the later one, so the dead `[0, 0, 0]`
/// "matches" every later triangle containing vertex 0 whose first vertex's list still holds a
/// dead corner: here `[0, 2, 3]` and `[0, 3, 1]` are dropped as duplicates too.
#[test]
fn dead_duplicate_does_not_swallow_later_triangles() {
    let positions = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [-0.5, 0.866, 0.0],
        [-0.5, -0.866, 0.0],
    ];
    let mut tris: [[u16; 3]; 4] = [[0, 1, 2], [0, 1, 2], [0, 2, 3], [0, 3, 1]];
    let mut ws = Workspace::<u32, 512, 1024>::new();
    // Ratio 1: nothing to collapse, the output is the cleaned input.
    let config = Config::new()
        .with_ratio(1.0)
        .with_schedule(Schedule::Passes);
    let r = ws.simplify(&positions, &mut tris, &config).unwrap();
    assert_eq!(r.duplicates_dropped, 1, "{r:?}");
    assert_eq!(r.triangles_out, 3);
    assert_eq!(&tris[..3], &[[0, 1, 2], [0, 2, 3], [0, 3, 1]]);
}

/// `fuzz/regressions/simplify-duplicate-survives-build` (same root cause as above).
///
/// The killed `[0, 0, 0]` stays linked, and since links name triangles and `first`/`after`
/// find the slot again by looking for the list's vertex, a walk of vertex 1's list stops at
/// the dead triangle (`corner_of` finds no 1 in `[0, 0, 0]`): the copy `[1, 4, 3]` never meets
/// `[1, 3, 4]` and both stay, so the output holds a duplicate triangle.
///
/// Fixed in c26274b (src/mesh.rs, `Mesh::build` step 3): a duplicate leaves its three lists
/// while it is intact, then is killed, so that walks never meet a dead triangle.
#[test]
fn duplicate_after_a_killed_duplicate_is_dropped() {
    let positions = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [2.0, 1.0, 0.0],
        [2.0, -1.0, 0.0],
    ];
    // The copy in the same winding (rotated) is a duplicate.
    let mut tris: [[u32; 3]; 4] = [[0, 1, 2], [0, 1, 2], [1, 3, 4], [3, 4, 1]];
    let mut ws = Workspace::<u16, 64, 64>::new();
    let config = Config::new().with_ratio(1.0);
    let r = ws.simplify(&positions, &mut tris, &config).unwrap();
    assert_eq!(r.duplicates_dropped, 2, "{r:?}");
    assert_eq!(&tris[..r.triangles_out], &[[0, 1, 2], [1, 3, 4]]);
    // Turned over, it is found the same way, and kept as the back of a double-sided triangle.
    let mut tris: [[u32; 3]; 4] = [[0, 1, 2], [0, 1, 2], [1, 3, 4], [1, 4, 3]];
    let r = ws.simplify(&positions, &mut tris, &config).unwrap();
    assert_eq!((r.duplicates_dropped, r.twins), (1, 1), "{r:?}");
    assert_eq!(&tris[..r.triangles_out], &[[0, 1, 2], [1, 3, 4], [1, 4, 3]]);
}

/// Unit normal (f64) of a triangle, zero if it has no area.
fn normal64(p: &[[f32; 3]], t: [u32; 3]) -> [f64; 3] {
    let q = |i: u32| p[i as usize].map(f64::from);
    let (a, b, c) = (q(t[0]), q(t[1]), q(t[2]));
    let (u, v) = (
        [b[0] - a[0], b[1] - a[1], b[2] - a[2]],
        [c[0] - a[0], c[1] - a[1], c[2] - a[2]],
    );
    let n = [
        u[1] * v[2] - u[2] * v[1],
        u[2] * v[0] - u[0] * v[2],
        u[0] * v[1] - u[1] * v[0],
    ];
    let l = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    if l > 0.0 {
        n.map(|x| x / l)
    } else {
        [0.0; 3]
    }
}

/// Pairs of triangles on a common edge whose unit normals have a dot product below -0.9.
fn folded(p: &[[f32; 3]], tris: &[[u32; 3]]) -> Vec<([u32; 3], [u32; 3])> {
    let mut out = Vec::new();
    for (i, &t) in tris.iter().enumerate() {
        for &u in &tris[i + 1..] {
            if t.iter().filter(|v| u.contains(v)).count() == 2 {
                let (a, b) = (normal64(p, t), normal64(p, u));
                if a[0] * b[0] + a[1] * b[1] + a[2] * b[2] < -0.9 {
                    out.push((t, u));
                }
            }
        }
    }
    out
}

/// `fuzz/regressions/simplify-fold-missed-normal-underflow`.
///
/// One stray vertex (y = -3.2e10) sets the bounding box, so in the engine's normalised units
/// (src/mesh.rs `Mesh::p`) the rest of the mesh is ~1e-11 across: cross products are ~1e-22
/// and their squares ~1e-44, below f32's normal range. `math::unit` (src/math.rs) then returns
/// the zero vector (`l2 > 0.0` fails, or a subnormal `l2` loses all precision), so
/// `legality::folds` (dot of zero vectors is 0, never < -0.9) and the `NormalTurn` test in
/// `legality::price` (`len0 * len1` underflows) pass vacuously and the collapse 7 -> 8 folds
/// triangle (0, 4, 8) onto (4, 5, 8) (normals 180° apart, f64 on the true positions).
///
/// Fixed in f055ab3 (scale-safe unit normals and triangle shape).
#[test]
fn no_fold_when_a_stray_vertex_dwarfs_the_mesh() {
    let positions: [[f32; 3]; 9] = [
        [0.0, 0.0, 0.0],
        [2.375, -32065930000.0, 0.0],
        [2.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [1.0, -5.0625, 0.0171875],
        [0.0, 1.0, 0.0],
        [0.0, 2.0, 0.075],
        [1.0, 2.0, 0.0015625],
        [2.0, 2.0, 0.06875],
    ];
    let input: [[u32; 3]; 9] = [
        [0, 1, 4],
        [0, 4, 3],
        [1, 2, 5],
        [1, 5, 4],
        [3, 4, 7],
        [3, 7, 6],
        [4, 5, 8],
        [4, 8, 7],
        [0, 4, 5],
    ];
    let before = folded(&positions, &input);
    let mut tris = input;
    let mut ws = Workspace::<u16, 64, 64>::new();
    let r = ws
        .simplify(&positions, &mut tris, &Config::new().with_ratio(0.0))
        .unwrap();
    let out = &tris[..r.triangles_out];
    let new: Vec<_> = folded(&positions, out)
        .into_iter()
        .filter(|f| !before.contains(f))
        .collect();
    assert!(new.is_empty(), "new folded pairs {new:?} in {out:?}");
}

/// `fuzz/regressions/simplify-fold-missed-cross-product-underflow`: the same stray-vertex
/// failure one step further (after f055ab3).
///
/// With the stray vertex at x = 1e30 the rest of the mesh is ~1e-30 across in normalised
/// units, so a cross product of the raw edge vectors underflows to zero. When this input was
/// found, the legality rules took the direction of exactly such a cross product, got zero
/// vectors and never saw a fold: collapses folded (0, 2, 6) onto (0, 2, 5) and (2, 6, 7) onto
/// (2, 5, 7). Fixed since: the rules take every normal from `legality::Shape::of`
/// (src/policy/legality/shape.rs), which scales the edges by a power of two before the cross product.
#[test]
fn no_fold_when_a_stray_vertex_is_1e30_away() {
    let positions: [[f32; 3]; 8] = [
        [0.0, 0.0, 1.0],
        [1e30, 0.0, -4.28918e-8],
        [-3.4375, 0.9005312, -4.5453017e-8],
        [-0.51210946, 0.8869995, -4.4770026e-8],
        [-0.9785156, -8.5544556e-8, -4.2772278e-8],
        [-0.50722647, -0.87854224, -4.4343157e-8],
        [0.49374992, -0.8552001, -4.3164995e-8],
        [0.0, 0.0, -1.0],
    ];
    let input: [[u32; 3]; 12] = [
        [0, 1, 2],
        [7, 2, 1],
        [0, 2, 3],
        [7, 3, 2],
        [0, 3, 4],
        [7, 4, 3],
        [0, 4, 5],
        [7, 5, 4],
        [0, 5, 6],
        [7, 0, 5],
        [0, 6, 1],
        [7, 1, 6],
    ];
    let before = folded(&positions, &input);
    let mut tris = input;
    let mut ws = Workspace::<u32, 512, 1024>::new();
    let mut config = Config::new().with_ratio(0.0);
    config = config.with_features(false);
    let r = ws.simplify(&positions, &mut tris, &config).unwrap();
    let out = &tris[..r.triangles_out];
    let new: Vec<_> = folded(&positions, out)
        .into_iter()
        .filter(|f| !before.contains(f))
        .collect();
    assert!(new.is_empty(), "new folded pairs {new:?} in {out:?}");
}
