//! The seam rule (welded seams, feature `seams`): a vertex on a seam moves only along it, and
//! no collapse removes a chart's last triangle.

use crate::index::Index;
use crate::mesh::{flag, next3, prev3, Mesh};

/// Welded seams: whether `a` may move onto `b` as far as its wedges go. Around `a`'s fan (in
/// fan order, a disc's last triangle next to its first) the wedge of `a` changes across some
/// spokes. One wedge: `a` is inside one attribute region, anything goes. Two (a seam through
/// `a`, or one that ends on `a`'s boundary): only along the seam, onto the vertex of a spoke
/// where the wedge changes (at a boundary that is never, since the boundary rule allows only
/// boundary edges: meshoptimizer locks a seam's end too). More (a corner where seams meet, or
/// a flat-shaded vertex, whose every face has its own wedge): never with
/// [`SeamCorners::Lock`](crate::seam::SeamCorners::Lock) (meshoptimizer's complex vertices);
/// with `Move` the wedges go with the removed triangles' neighbours (`Mesh::move_wedges`).
#[cfg(feature = "seams")]
#[inline(never)]
pub(super) fn along_seam<L: Index, I: Index>(mesh: &Mesh<'_, L, I>, a: usize, b: usize) -> bool {
    let wedge = |t: usize, k: usize| {
        mesh.wedges
            .get(t)
            .and_then(|w| w.get(k))
            .map(|x| x.to_usize())
    };
    let (mut changes, mut onto_b) = (0, false);
    let mut first: Option<Option<usize>> = None;
    let mut prev: Option<(Option<usize>, usize)> = None;
    for (t, k) in mesh.corners(a) {
        let tri = mesh.tri(t);
        let w = wedge(t, k);
        // The spoke shared with the previous triangle is this one's `x` (its next vertex).
        if let Some((pw, _)) = prev {
            if pw != w {
                changes += 1;
                onto_b |= tri[next3(k)] == b;
            }
        }
        if first.is_none() {
            first = Some(w);
        }
        prev = Some((w, tri[prev3(k)]));
    }
    // A disc closes: its last triangle's `y` spoke is its first triangle's `x`.
    if let (false, Some(f), Some((lw, ly))) = (mesh.has(a, flag::BOUNDARY), first, prev) {
        if f != lw {
            changes += 1;
            onto_b |= ly == b;
        }
    }
    // A boundary fan's wedges are one more than its changes, a disc's as many.
    let wedges = changes + usize::from(mesh.has(a, flag::BOUNDARY));
    if wedges > 2 {
        return !mesh.lock_corners;
    }
    // Charts are kept only where the wedges carry attributes (`Lock`): with `Move` a split
    // index buffer's wedges carry nothing, and a mesh shaded flat (every face its own chart)
    // would not simplify at all.
    (wedges != 2 || onto_b) && (wedges < 2 || !mesh.lock_corners || !removes_a_chart(mesh, a, b))
}

/// Welded seams: whether a triangle the collapse `a -> b` removes is the last of its chart
/// (the triangles joined to it across edges where both ends keep their wedges): no
/// surviving triangle across any of its edges shares both wedges of that edge. Such a
/// triangle is the last piece of a texture chart or of a material (a material boundary is a
/// seam, `tinydecimate simplify` joins a mesh's primitives), and a collapse along a seam would
/// take it whole. Only a vertex with two or more wedges can remove one: inside a chart the
/// removed triangles have chart neighbours in `a`'s fan. Asked only with
/// [`SeamCorners::Lock`](crate::seam::SeamCorners::Lock), the wedges of real attributes.
#[cfg(feature = "seams")]
pub(super) fn removes_a_chart<L: Index, I: Index>(
    mesh: &Mesh<'_, L, I>,
    a: usize,
    b: usize,
) -> bool {
    let wedge = |t: usize, v: usize| {
        let k = mesh.tri(t).iter().position(|&x| x == v)?;
        mesh.wedges.get(t)?.get(k).map(|x| x.to_usize())
    };
    mesh.corners(a).any(|(t, k)| {
        let tri = mesh.tri(t);
        let (x, y) = crate::tri::others(tri, k);
        let o = if x == b {
            y
        } else if y == b {
            x
        } else {
            return false;
        };
        // Edge a-b joins only the other removed triangle, which goes too.
        let joined = [(b, o), (a, o)].into_iter().any(|(u, v)| {
            mesh.corners(u).any(|(s, _)| {
                s != t
                    && mesh.tri(s).contains(&v)
                    && !mesh.tri(s).contains(&if u == a { b } else { a })
                    && wedge(s, u) == wedge(t, u)
                    && wedge(s, v) == wedge(t, v)
            })
        });
        !joined
    })
}
