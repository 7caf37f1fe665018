//! The rules on a vertex removal (vertex decimation): the new triangles over the hole's ring,
//! which have no "before", against the hard rules of a collapse.

use crate::index::Index;
use crate::math::{self, V3};
use crate::mesh::{flag, Mesh, NIL};

use super::collapse::other_with;
use super::shape::*;
use super::{on, Reject, Rules};

/// The rules on a vertex removal: `v`'s fan replaced by `new`, triangles over its `ring`
/// (ring positions, each wound in ring order; a `boundary` ring's closing edge, last to first,
/// becomes a boundary edge), each checked against its plane's unit normal in `planes` (the
/// average plane, or its side's of a feature line). The hard rules of a collapse, for
/// triangles that have no "before":
///
/// * `locked`: a ring vertex is locked (its list has no fan order to splice into);
/// * `link`: a diagonal, or a boundary ring's closing edge, is already an edge (a
///   non-manifold edge, or a boundary loop closed);
/// * `duplicate`: a new triangle already exists;
/// * `sliver`: a new triangle has no area, or one so thin that rounding decides its normal;
/// * `fold`: a new triangle faces away from the average plane, or folds against the triangle
///   across its loop edge or another new one across a diagonal;
/// * `normal_turn`: a new triangle's normal is farther from the average plane's than
///   [`Config::max_normal_turn_deg`].
pub(crate) fn check_fan<L: Index, I: Index>(
    mesh: &Mesh<'_, L, I>,
    rules: &Rules,
    v: usize,
    (ring, boundary): (&[usize], bool),
    new: &[[u8; 3]],
    planes: &[V3],
) -> Result<(), Reject> {
    let n = ring.len();
    let at = |k: u8| ring.get(k as usize).copied().unwrap_or(NIL);
    if on!(Locked) && ring.iter().any(|&x| mesh.has(x, flag::LOCKED)) {
        return Err(Reject::Locked);
    }
    for (i, (&t, &normal)) in new.iter().zip(planes).enumerate() {
        let tri = t.map(at);
        let now = Shape::of(tri.map(|x| mesh.p(x)));
        if on!(Sliver) && now.quality < FLAT {
            return Err(Reject::Sliver);
        }
        let d = math::dot(now.n, normal);
        if on!(Fold) && d <= 0.0 {
            return Err(Reject::Fold);
        }
        // Farther from the plane's normal than the turn limit (as `shape_rules` compares).
        let turned = if rules.cos_turn >= 0.0 {
            d < 0.0 || d * d < rules.cos_turn2 * now.n2
        } else {
            d < 0.0 && d * d > rules.cos_turn2 * now.n2
        };
        if on!(NormalTurn) && turned {
            return Err(Reject::NormalTurn);
        }
        if on!(Duplicate) {
            let [x, y, z] = tri;
            if mesh
                .corners(x)
                .any(|(u, _)| mesh.tri(u).contains(&y) && mesh.tri(u).contains(&z))
            {
                return Err(Reject::Duplicate);
            }
        }
        for (p, q) in [(t[0], t[1]), (t[1], t[2]), (t[0], t[2])] {
            let (x, y) = (at(p), at(q));
            // Loop edges (ring neighbours; around an interior vertex also last-first) stay.
            let loop_edge = q == p + 1 || (!boundary && p == 0 && q as usize + 1 == n);
            if loop_edge {
                if on!(Fold) {
                    if let Some(u) = other_with(mesh, x, y, v) {
                        if folded(&now, &shape_of(mesh, u)) {
                            return Err(Reject::Fold);
                        }
                    }
                }
            } else {
                if on!(Link) && other_with(mesh, x, y, v).is_some() {
                    return Err(Reject::Link);
                }
                // The other new triangle on this diagonal (none on a boundary's closing edge).
                if on!(Fold) {
                    for &o in new.iter().skip(i + 1) {
                        if o.contains(&p) && o.contains(&q) {
                            let other = Shape::of(o.map(|k| mesh.p(at(k))));
                            if folded(&now, &other) {
                                return Err(Reject::Fold);
                            }
                        }
                    }
                }
            }
        }
    }
    Ok(())
}
