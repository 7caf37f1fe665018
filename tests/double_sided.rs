//! Double-sided surfaces: a triangle and its twin (the same vertices turned over) are the two
//! sides of one leaf, card or pane. Both sides come out, the count asked for is the whole
//! output's, and the shared checker checks the fronts with the backs counted.

mod common;
use std::collections::HashSet;

use common::*;
use tinydecimate::{Config, Target};

/// `m` with every triangle followed by its twin.
fn double(m: &MeshData) -> MeshData {
    let mut triangles = Vec::new();
    for &[a, b, c] in &m.triangles {
        triangles.push([a, b, c]);
        triangles.push([a, c, b]);
    }
    MeshData {
        positions: m.positions.clone(),
        triangles,
    }
}

/// The output's triangles as front, back pairs: every triangle's twin is in the output.
fn assert_both_sides(name: &str, out: &MeshData) {
    let set: HashSet<[u32; 3]> = out.triangles.iter().copied().collect();
    for &[a, b, c] in &out.triangles {
        let back = [a, c, b];
        assert!(
            set.contains(&back) || set.contains(&[c, b, a]) || set.contains(&[b, a, c]),
            "{name}: {:?} lost its other side",
            [a, b, c]
        );
    }
}

#[test]
fn both_sides_come_out_at_the_count_asked_for() {
    let one = grid(20, 20, 0.1);
    let two = double(&one);
    let (out, r) = simplify(&two, &Config::new().with_ratio(0.1));
    assert_eq!(r.twins, one.triangles.len());
    assert_eq!(r.duplicates_dropped, 0);
    assert_eq!(r.target_triangles, two.triangles.len() / 10);
    assert!(r.target_reached, "{r:?}");
    assert!(out.triangles.len() + 4 > r.target_triangles, "{r:?}");
    assert_both_sides("grid", &out);
    assert_valid("grid", &two, &out, &r);
    // The fronts are exactly the one-sided surface simplified to half the count.
    let (front, _) = simplify(
        &one,
        &Config::new().with_target(Target::Triangles(r.target_triangles / 2)),
    );
    let fronts: Vec<[u32; 3]> = out.triangles.iter().step_by(2).copied().collect();
    assert_eq!(fronts, front.triangles);
}

#[test]
fn a_repeated_back_is_a_duplicate() {
    // Front, back, and the back again: the third is dropped, the output has no duplicate.
    let one = grid(8, 8, 0.0);
    let mut m = double(&one);
    let [a, b, c] = one.triangles[5];
    m.triangles.push([a, c, b]);
    let (out, r) = simplify(&m, &Config::new().with_ratio(0.25));
    assert_eq!(r.duplicates_dropped, 1);
    assert_eq!(r.twins, one.triangles.len());
    assert_both_sides("grid", &out);
    assert_valid("grid with a repeated back", &m, &out, &r);
}

#[test]
fn the_checker_counts_twins_and_refuses_new_ones() {
    let one = grid(6, 6, 0.1);
    let two = double(&one);
    // The one-sided surface against its double: valid, twins 72 -> 0.
    let v = verdict(&two, &one);
    assert!(v.is_valid(), "{v}");
    assert_eq!(v.twins, (one.triangles.len(), 0));
    // A back the input did not have is a defect.
    let v = verdict(&one, &double(&one));
    assert!(!v.is_valid());
}

#[cfg(feature = "seams")]
#[test]
fn welded_backs_keep_their_own_vertices() {
    use tinydecimate::{seam, Builtin, EdgeCollapse, NoBound, Positions};
    // The back as its own vertices (its normals point the other way), at the same positions.
    let one = grid(12, 12, 0.1);
    let nv = one.positions.len() as u32;
    let mut m = MeshData {
        positions: [one.positions.clone(), one.positions.clone()].concat(),
        triangles: Vec::new(),
    };
    for &[a, b, c] in &one.triangles {
        m.triangles.push([a, b, c]);
        m.triangles.push([a + nv, c + nv, b + nv]);
    }
    let mut tris = m.triangles.clone();
    let mut wedges = vec![[0u32; 3]; tris.len()];
    let mut order = vec![0u32; m.positions.len()];
    seam::weld(&m.positions, &mut tris, &mut wedges, &mut order).expect("weld");
    let mut ws = BIG.lock().unwrap_or_else(|e| e.into_inner());
    let config = Config::new().with_ratio(0.1);
    let r = ws
        .start(
            Positions::Read(&m.positions),
            &mut tris,
            &config,
            Builtin::new(),
            NoBound,
            EdgeCollapse,
        )
        .expect("start")
        .with_wedges(&mut wedges, tinydecimate::seam::SeamCorners::Lock)
        .expect("wedges")
        .run();
    assert_eq!(r.twins, one.triangles.len());
    assert!(r.target_reached, "{r:?}");
    tris.truncate(r.triangles_out);
    // Fronts and backs alternate; each back is its front turned over, at the same positions,
    // with back vertices only (the backs' normals), never the front's.
    for pair in tris.chunks(2) {
        let [f, b] = [pair[0], pair[1]];
        assert!(f.iter().all(|&x| x < nv), "front {f:?}");
        assert!(b.iter().all(|&x| x >= nv), "back {b:?} of {f:?}");
        assert_eq!([f[0], f[2], f[1]], b.map(|x| x - nv), "back {b:?} of {f:?}");
    }
}
