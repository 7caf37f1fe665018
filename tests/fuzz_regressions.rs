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
/// Suggested fix (src/mesh.rs, `Mesh::build` step 3): unlink a duplicate from its three lists
/// while it is intact (`self.unlink(x, t)` for each vertex, as `collapse` does), then `kill`
/// it, so that walks never meet a dead triangle.
#[test]
fn duplicate_after_a_killed_duplicate_is_dropped() {
    let positions = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [2.0, 1.0, 0.0],
        [2.0, -1.0, 0.0],
    ];
    let mut tris: [[u32; 3]; 4] = [[0, 1, 2], [0, 1, 2], [1, 3, 4], [1, 4, 3]];
    let mut ws = Workspace::<u16, 64, 64>::new();
    let config = Config::new().with_ratio(1.0);
    let r = ws.simplify(&positions, &mut tris, &config).unwrap();
    assert_eq!(r.duplicates_dropped, 2, "{r:?}");
    assert_eq!(&tris[..r.triangles_out], &[[0, 1, 2], [1, 3, 4]]);
}
