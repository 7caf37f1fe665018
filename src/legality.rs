//! Which collapses keep the mesh valid, and what they cost.
//!
//! A half-edge collapse `a -> b` (a moves onto b, b stays where it is) is refused when any rule
//! below fails. The rules, in the order they are checked (cheapest first):
//!
//! | rule       | refuses when                                                        | source |
//! |------------|---------------------------------------------------------------------|--------|
//! | `Locked`   | a or b is on a non-manifold edge, a pinched fan or an inconsistently wound edge | seed 001 §3 |
//! | `Feature`  | a is a feature vertex; or b is, unless feature targets are allowed  | seed 004 §3.3 |
//! | `Boundary` | a is on the boundary and a-b is not a boundary edge; or the boundary loop through a-b has only three edges | seed 000 §3.2 |
//! | `Link`     | a vertex adjacent to both a and b is not opposite a-b (the surface would pinch) | seed 000 §3.1 |
//! | `Duplicate`| a triangle of a would become a copy of one of b's                    | |
//! | `Sliver`   | a surviving triangle gets zero area, or a quality below the limit that is also worse than before | |
//! | `NormalTurn` | a surviving triangle's normal turns by more than the limit       | seed 000 §3.2 |
//! | `Fold`     | a surviving triangle and a neighbour across any of its edges end up with nearly opposite normals | |
//!
//! Interior vertices may move onto boundary vertices (the boundary does not change), never the
//! reverse. Together with the link condition this keeps a closed manifold closed, keeps the
//! Euler characteristic and the number of boundary loops, and never creates a non-manifold edge.

use crate::cost::{Cost, EdgeChange, TriangleChange};
use crate::index::Index;
use crate::math;
use crate::mesh::{flag, is_dead, Mesh, NIL};
use crate::report::Reject;
use crate::{Config, Schedule};

/// Which rules are on. All of them, in every normal build. Building with the environment
/// variable `TINYDECIMATE_RULE_OFF` set to one rule's name (`locked`, `feature`, `boundary`,
/// `link`, `duplicate`, `sliver`, `normal_turn`, `fold`) switches that rule off, so that
/// `scripts/rules-off.sh` can show that the test suite fails without each of them. Constants,
/// so a normal build carries no trace of the switch.
pub(crate) mod on {
    const OFF: &str = match option_env!("TINYDECIMATE_RULE_OFF") {
        Some(s) => s,
        None => "",
    };
    const fn off(name: &str) -> bool {
        let (a, b) = (OFF.as_bytes(), name.as_bytes());
        if a.len() != b.len() {
            return false;
        }
        let mut i = 0;
        while i < a.len() {
            if a[i] != b[i] {
                return false;
            }
            i += 1;
        }
        true
    }
    pub(crate) const LOCKED: bool = !off("locked");
    pub(crate) const FEATURE: bool = !off("feature");
    pub(crate) const BOUNDARY: bool = !off("boundary");
    pub(crate) const LINK: bool = !off("link");
    pub(crate) const DUPLICATE: bool = !off("duplicate");
    pub(crate) const SLIVER: bool = !off("sliver");
    pub(crate) const NORMAL_TURN: bool = !off("normal_turn");
    pub(crate) const FOLD: bool = !off("fold");
}

/// Two adjacent triangles whose unit normals have a dot product below this are folded onto
/// each other (more than about 154° apart).
pub(crate) const FOLD_DOT: f32 = -0.9;

/// The geometric limits of a [`Config`], precomputed.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Rules {
    cos_turn: f32,
    /// `min_quality² / 12`, compared with `|n|² / (Σ edge²)²`.
    min_ratio: f32,
    feature_targets: bool,
}

impl Rules {
    pub(crate) fn new(config: &Config) -> Self {
        let q = config.min_quality;
        Rules {
            cos_turn: math::cos(config.max_normal_turn_deg * (core::f32::consts::PI / 180.0)),
            min_ratio: q * q / 12.0,
            // The paper's schedule keeps the paper's rule.
            feature_targets: config.feature_targets && config.schedule == Schedule::Greedy,
        }
    }
}

/// `tri` after moving `a` onto `b`, or `None` if it contains both and vanishes.
#[inline]
fn moved(tri: [usize; 3], a: usize, b: usize) -> Option<[usize; 3]> {
    if tri.contains(&a) && tri.contains(&b) {
        return None;
    }
    Some(tri.map(|v| if v == a { b } else { v }))
}

/// What the rules need of one triangle.
struct Shape {
    /// Unit normal (zero if no area).
    normal: [f32; 3],
    /// Twice the area.
    area2: f32,
    /// quality² / 12 = |n|² / (Σ edge²)², scale-free; 1/12 for an equilateral triangle.
    quality: f32,
}

/// The triangle's shape, computed on its edges divided by their largest component, so that
/// neither squares nor products of tiny or huge edges leave f32's normal range.
#[inline]
fn shape(p: [[f32; 3]; 3]) -> Shape {
    let e = [
        math::sub(p[1], p[0]),
        math::sub(p[2], p[1]),
        math::sub(p[0], p[2]),
    ];
    let m = math::max_abs(e[0])
        .max(math::max_abs(e[1]))
        .max(math::max_abs(e[2]));
    if m.is_nan() || m <= 0.0 {
        return Shape {
            normal: [0.0; 3],
            area2: 0.0,
            quality: 0.0,
        };
    }
    let e = e.map(|v| math::div(v, m));
    // cross(p1 - p0, p2 - p0), with p2 - p0 = -e2.
    let n = math::cross(e[0], math::scale(e[2], -1.0));
    let l2 = math::dot(n, n);
    let s = math::dot(e[0], e[0]) + math::dot(e[1], e[1]) + math::dot(e[2], e[2]);
    let len = math::sqrt(l2);
    Shape {
        normal: if len > 0.0 {
            math::scale(n, 1.0 / len)
        } else {
            [0.0; 3]
        },
        area2: len * m * m,
        quality: if s > 0.0 { l2 / (s * s) } else { 0.0 },
    }
}

/// Checks every rule for `a -> b` and returns its cost.
pub(crate) fn evaluate<L: Index, I: Index, C: Cost>(
    mesh: &Mesh<'_, L, I>,
    rules: &Rules,
    cost: &C,
    a: usize,
    b: usize,
) -> Result<f32, Reject> {
    let c = price(mesh, rules, cost, a, b)?;
    connectivity(mesh, a, b)?;
    Ok(c)
}

/// The cheap rules (flags, boundary, each surviving triangle's own shape and turn) and the
/// cost. The schedules call this for every candidate and [`connectivity`] only for the
/// cheapest ones, in cost order, until one passes.
pub(crate) fn price<L: Index, I: Index, C: Cost>(
    mesh: &Mesh<'_, L, I>,
    rules: &Rules,
    cost: &C,
    a: usize,
    b: usize,
) -> Result<f32, Reject> {
    let (fa, fb) = (mesh.flags(a), mesh.flags(b));
    if fa & fb & flag::USED == 0 || (on::LOCKED && (fa | fb) & flag::LOCKED != 0) {
        return Err(Reject::Locked);
    }
    if on::FEATURE
        && (fa & flag::FEATURE != 0 || (fb & flag::FEATURE != 0 && !rules.feature_targets))
    {
        return Err(Reject::Feature);
    }

    // The number of triangles on edge a-b.
    let mut n_ab = 0;
    for (t, _) in mesh.corners(a) {
        if mesh.tri(t).contains(&b) {
            n_ab += 1;
        }
    }
    if n_ab == 0 {
        return Err(Reject::Link);
    }
    if on::LOCKED && n_ab > 2 {
        return Err(Reject::Locked);
    }

    // Boundary: a boundary vertex only slides along its own boundary edge.
    let mut retreat2 = 0.0;
    if fa & flag::BOUNDARY != 0 {
        if on::BOUNDARY && n_ab != 1 {
            return Err(Reject::Boundary);
        }
        let x = mesh.boundary_neighbour(a, b);
        let y = mesh.boundary_neighbour(b, a);
        if on::BOUNDARY && x == y {
            // A loop of three edges would close up (or a lone triangle vanish).
            return Err(Reject::Boundary);
        }
        if x != NIL {
            retreat2 = math::segment_distance2(mesh.p(a), mesh.p(x), mesh.p(b));
        }
    }

    // Each surviving triangle's shape and turn, and the cost. Positions are read once per
    // triangle; the moved one differs from the old one in a's corner only.
    let pa = mesh.p(a);
    let pb = mesh.p(b);
    let shift = math::sub(pb, pa);
    let mut sum = 0.0f32;
    for (t, k) in mesh.corners(a) {
        let old = mesh.tri(t);
        if old.contains(&b) {
            continue;
        }
        let q = old.map(|v| mesh.p(v));
        let mut r = q;
        if let Some(x) = r.get_mut(k) {
            *x = pb;
        }
        let old_shape = shape(q);
        let new_shape = shape(r);
        // No area left (or none representable).
        if on::SLIVER && new_shape.quality <= 0.0 {
            return Err(Reject::Sliver);
        }
        if on::SLIVER
            && new_shape.quality < rules.min_ratio
            && new_shape.quality < old_shape.quality
        {
            return Err(Reject::Sliver);
        }
        // A zero-area triangle has no direction to turn from.
        let (u0, u1) = (old_shape.normal, new_shape.normal);
        if on::NORMAL_TURN && old_shape.quality > 0.0 && math::dot(u0, u1) < rules.cos_turn {
            return Err(Reject::NormalTurn);
        }
        sum += cost.triangle(&TriangleChange {
            old_normal: u0,
            new_normal: u1,
            old_area2: old_shape.area2,
            moved: shift,
        });
    }
    let total = cost.total(
        sum,
        &EdgeChange {
            length2: math::dot(shift, shift),
            boundary_retreat2: retreat2,
        },
    );
    if total.is_nan() || total == f32::INFINITY {
        return Err(Reject::Sliver);
    }
    Ok(if total > 0.0 { total } else { 0.0 })
}

/// The rules that look past `a`'s own triangles: link condition, duplicates, folds.
pub(crate) fn connectivity<L: Index, I: Index>(
    mesh: &Mesh<'_, L, I>,
    a: usize,
    b: usize,
) -> Result<(), Reject> {
    // The vertices opposite edge a-b (at most two: `price` refused more).
    let mut opp = [NIL; 2];
    let mut n_ab = 0;
    for (t, _) in mesh.corners(a) {
        let tri = mesh.tri(t);
        if tri.contains(&b) {
            if let Some(slot) = opp.get_mut(n_ab) {
                *slot = tri
                    .iter()
                    .copied()
                    .find(|&x| x != a && x != b)
                    .unwrap_or(NIL);
            }
            n_ab += 1;
        }
    }
    let opp = &opp[..n_ab.min(2)];

    // Link condition: a neighbour x of a that is not opposite a-b must not be a neighbour of
    // b too. b's neighbours are marked first, so the check is O(valence), not O(valence²).
    mesh.mark_fan(b, true);
    let link = link_and_duplicates(mesh, a, b, opp);
    mesh.mark_fan(b, false);
    link?;

    for (t, _) in mesh.corners(a) {
        let Some(new) = moved(mesh.tri(t), a, b) else {
            continue;
        };
        let u1 = mesh.unit_normal(new);
        if on::FOLD && folds(mesh, t, new, u1, a, b) {
            return Err(Reject::Fold);
        }
    }
    Ok(())
}

fn link_and_duplicates<L: Index, I: Index>(
    mesh: &Mesh<'_, L, I>,
    a: usize,
    b: usize,
    opp: &[usize],
) -> Result<(), Reject> {
    for (t, _) in mesh.corners(a) {
        let tri = mesh.tri(t);
        if tri.contains(&b) {
            continue;
        }
        let mut both_opposite = true;
        for &x in &tri {
            if x == a || opp.contains(&x) {
                continue;
            }
            both_opposite = false;
            if on::LINK && mesh.has(x, flag::MARK) {
                return Err(Reject::Link);
            }
        }
        if on::DUPLICATE && both_opposite {
            // a's triangle (a, c, d) with c and d both opposite a-b becomes (b, c, d): refuse if
            // b already has it.
            let others = tri.map(|v| if v == a { b } else { v });
            if mesh
                .corners(b)
                .any(|(u, _)| others.iter().all(|v| mesh.tri(u).contains(v)))
            {
                return Err(Reject::Duplicate);
            }
        }
    }
    Ok(())
}

/// Whether the moved triangle `t` (now `new`, unit normal `u1`) would be folded onto any of its
/// neighbours after the collapse `a -> b`.
fn folds<L: Index, I: Index>(
    mesh: &Mesh<'_, L, I>,
    t: usize,
    new: [usize; 3],
    u1: [f32; 3],
    a: usize,
    b: usize,
) -> bool {
    for k in 0..3 {
        let (p, q) = (new[k], new[(k + 1) % 3]);
        // After the collapse, b's triangles are a's and b's together.
        let lists = if p == b || q == b { [a, b] } else { [p, NIL] };
        for owner in lists {
            if owner == NIL {
                continue;
            }
            for (s, _) in mesh.corners(owner) {
                if s == t {
                    continue;
                }
                let tri = mesh.tri(s);
                if is_dead(tri) {
                    continue;
                }
                let Some(post) = moved(tri, a, b) else {
                    continue;
                };
                if post.contains(&p) && post.contains(&q) {
                    let us = mesh.unit_normal(post);
                    if math::dot(u1, us) < FOLD_DOT {
                        return true;
                    }
                }
            }
        }
    }
    false
}
