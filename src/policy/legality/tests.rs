//! The rules on small meshes built in code.

use super::collapse::*;
use super::shape::*;
use super::*;
use crate::math::V3;
use crate::mesh::{is_dead, Positions};
use crate::mesh::{next3, Mesh};

/// A pair whose normals meet at the checker's limit (dot −0.9 in `f64`) or a little inside
/// it is folded here: the margin that covers `f32` rounding.
#[test]
fn a_pair_at_the_checkers_fold_limit_is_folded() {
    let shape = |n: V3| Shape {
        n,
        n2: math::dot(n, n),
        quality: 0.05,
    };
    let up = shape([0.0, 0.0, 1.0]);
    let at = |d: f32| shape([math::sqrt(1.0 - d * d), 0.0, d]);
    assert!(folded(&up, &at(-0.9)));
    assert!(folded(&up, &at(-0.895)));
    assert!(!folded(&up, &at(-0.88)));
}

const N: usize = 7;
const NV: usize = (N + 1) * (N + 1);
const NT: usize = 2 * N * N;

/// An accordion-folded open grid, `N` x `N` quads: interior vertices of valence 6 whose
/// corner lists start at their lowest-numbered triangle, so that most of `b`'s lists start
/// inside the fan (a first and a last survivor that share a spoke).
fn grid() -> ([[f32; 3]; NV], [[u16; 3]; NT]) {
    let mut p = [[0.0f32; 3]; NV];
    for (i, q) in p.iter_mut().enumerate() {
        let (x, y) = ((i % (N + 1)) as f32, (i / (N + 1)) as f32);
        let h = (i as u32).wrapping_mul(2_654_435_761) >> 16;
        *q = [
            x,
            y,
            // Ridges along y (an accordion: steep dihedrals, so that a moved triangle can
            // fold against one neighbour and not the others) and a bump per vertex.
            if i % 2 == 0 { 0.9 } else { -0.9 } + 0.35 * (h as f32 / 65_536.0 - 0.5),
        ];
    }
    let mut t = [[0u16; 3]; NT];
    for y in 0..N {
        for x in 0..N {
            let a = (y * (N + 1) + x) as u16;
            let (b, c, d) = (a + 1, a + N as u16 + 1, a + N as u16 + 2);
            t[2 * (y * N + x)] = [a, b, d];
            t[2 * (y * N + x) + 1] = [a, d, c];
        }
    }
    (p, t)
}

/// A vertex removal whose diagonal is already an edge is refused by the link rule: a
/// pentagon fan around vertex 0 (ring 1..=5) with a vertex 6 below ring vertices 1, 2 and
/// 3, whose triangle (1, 3, 6) holds edge 1-3. Triangulating the hole with the diagonal
/// 1-3 would put a third triangle on it; the diagonals 1-4 and 4-2 put none. Fails if the
/// diagonal-exists check is switched off (`TINYDECIMATE_RULE_OFF=link`).
#[test]
fn removal_refuses_a_diagonal_that_is_an_edge() -> Result<(), crate::Error> {
    let mut p = [[0.0f32; 3]; 7];
    p[0] = [0.0, 0.0, 0.2];
    for i in 0..5 {
        let a = i as f32 * core::f32::consts::TAU / 5.0;
        p[i + 1] = [
            math::cos_deg(a.to_degrees()),
            math::cos_deg(90.0 - a.to_degrees()),
            0.0,
        ];
    }
    p[6] = [
        (p[1][0] + p[2][0] + p[3][0]) / 3.0,
        (p[1][1] + p[2][1] + p[3][1]) / 3.0,
        -0.8,
    ];
    let mut t: [[u16; 3]; 8] = [
        [0, 1, 2],
        [0, 2, 3],
        [0, 3, 4],
        [0, 4, 5],
        [0, 5, 1],
        [2, 1, 6],
        [3, 2, 6],
        [1, 3, 6],
    ];
    let (mut head, mut next, mut flags) = ([0u16; 7], [[0u16; 3]; 8], [0u8; 7]);
    let (mut s0, mut s1) = ([0u16; 7], [0u16; 7]);
    let mesh = Mesh::build(
        Positions::Read(&p),
        &mut t,
        &mut head,
        &mut next,
        &mut flags,
        (&mut s0, &mut s1),
    )?;
    let rules = Rules::new(&Config::new());
    let ring = [1, 2, 3, 4, 5];
    let up = [[0.0, 0.0, 1.0]; 3];
    assert!((1..6).all(|v| !mesh.has(v, flag::LOCKED)));
    // Ring positions: the diagonal 0-2 is vertices 1-3.
    let through_edge = [[0u8, 1, 2], [0, 2, 3], [0, 3, 4]];
    assert_eq!(
        check_fan(&mesh, &rules, 0, (&ring, false), &through_edge, &up),
        Err(Reject::Link)
    );
    let around_it = [[0u8, 1, 3], [1, 2, 3], [0, 3, 4]];
    assert_eq!(
        check_fan(&mesh, &rules, 0, (&ring, false), &around_it, &up),
        Ok(())
    );
    Ok(())
}

/// Whether one of `b`'s survivors of `a -> b` with `b` at `p` folds against any other
/// triangle that shares an edge with it after the collapse: a search of every triangle,
/// what [`check_moved_b`]'s fan-order lookups (and [`check`]'s across `b-o1`, `b-o2`)
/// stand for.
fn folds_by_search(mesh: &Mesh<'_, u16, u16>, a: usize, b: usize, p: V3) -> bool {
    let merged = |v: usize| if v == a { b } else { v };
    let survives = |t: usize| {
        let s = mesh.tri(t);
        let removed = s.contains(&a) && s.contains(&b);
        !is_dead(s) && !removed
    };
    for t in 0..mesh.triangle_count() {
        let old = mesh.tri(t);
        if !survives(t) || !old.contains(&b) || old.contains(&a) {
            continue;
        }
        let now = shape_moved(mesh, t, a, b, p);
        for (u, w) in [(old[0], old[1]), (old[1], old[2]), (old[2], old[0])] {
            for s in 0..mesh.triangle_count() {
                let m = mesh.tri(s).map(merged);
                if s != t
                    && survives(s)
                    && m.contains(&u)
                    && m.contains(&w)
                    && folded(&now, &shape_moved(mesh, s, a, b, p))
                {
                    return true;
                }
            }
        }
    }
    false
}

/// The shape and turn rules alone on `b`'s survivors.
fn shapes_allow(mesh: &Mesh<'_, u16, u16>, rules: &Rules, a: usize, b: usize, p: V3) -> bool {
    mesh.corners(b).all(|(t, _)| {
        let old = mesh.tri(t);
        old.contains(&a)
            || shape_rules(
                rules,
                &Shape::of(old.map(|v| mesh.p(v))),
                &shape_moved(mesh, t, a, b, p),
            )
            .is_ok()
    })
}

/// Optimal placement: on every edge of the grid, in both directions, with the kept vertex
/// moved to 52 positions around it (26 directions, two distances), under the shipped limits and under limits loose enough
/// for many folds, [`check_placed`] says yes exactly when [`check`] does and `b`'s moved
/// triangles keep their shapes and fold against no neighbour found by a search of every
/// triangle. Fails when any of `check_moved_b`'s three fold lookups (spoke, outer edge,
/// first and last survivor) is left out.
#[test]
fn moved_b_rules_agree_with_a_search() -> Result<(), crate::Error> {
    let (p, mut t) = grid();
    let (mut head, mut next, mut flags) = ([0u16; NV], [[0u16; 3]; NT], [0u8; NV]);
    let (mut s0, mut s1) = ([0u16; NV], [0u16; NV]);
    let mesh = Mesh::build(
        Positions::Read(&p),
        &mut t,
        &mut head,
        &mut next,
        &mut flags,
        (&mut s0, &mut s1),
    )?;
    // The shipped limits, and limits so loose that the fold rule has the last word.
    let mut loose = Config::stored();
    loose.max_normal_turn_deg = 179.0;
    loose.min_quality = 0.0;
    let (mut cases, mut folds) = (0, 0);
    for rules in [Rules::new(&Config::stored()), Rules::new(&loose)] {
        for a in 0..NV {
            for (t0, k) in mesh.corners(a) {
                let b = mesh.tri(t0)[next3(k)];
                let (pb, l) = (mesh.p(b), math::sub(mesh.p(a), mesh.p(b)));
                let l2 = math::dot(l, l);
                let l = l2 * math::rsqrt(l2);
                for i in 0..54 {
                    if i % 27 == 13 {
                        continue;
                    }
                    let d = [
                        (i % 3) as f32 - 1.0,
                        ((i / 3) % 3) as f32 - 1.0,
                        ((i / 9) % 3) as f32 - 1.0,
                    ];
                    let r = if i < 27 { 0.6 } else { 1.5 };
                    let at = math::add(pb, math::scale(d, r * l));
                    if check(&mesh, &rules, a, b, Some(at)).is_err() {
                        continue;
                    }
                    cases += 1;
                    let fold = folds_by_search(&mesh, a, b, at);
                    folds += usize::from(fold);
                    let expected = shapes_allow(&mesh, &rules, a, b, at) && !fold;
                    assert_eq!(
                        check_placed(&mesh, &rules, a, b, at).is_ok(),
                        expected,
                        "{a} -> {b} at {at:?}"
                    );
                }
            }
        }
    }
    assert!(
        cases > 1000 && folds > 100,
        "{cases} cases, {folds} with a fold"
    );
    Ok(())
}
