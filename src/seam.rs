//! Seams: vertices at identical positions are one surface vertex with several *wedges*.
//!
//! A renderer's index buffer splits a vertex wherever an attribute jumps (a UV seam, a hard
//! normal, a material border): two or more vertices share one position, and to the collapse
//! engine each split is an open boundary, which it may only shrink along itself. A textured
//! model then keeps most of its triangles, and one simplified piece by piece cracks open.
//!
//! [`weld`] makes the surface whole before a run: every corner is renumbered to its
//! position's first vertex (the *representative*), and the caller's wedge buffer keeps a copy
//! of the triangles as given. The engine then collapses positions, so a seam keeps its shape
//! and moves as one; [`Simplifier::with_wedges`](crate::Simplifier::with_wedges) hands it the
//! copy, which it keeps up to date: a corner whose vertex stays keeps its own wedge (with
//! subset placement its UVs, normals and colours are exactly the input's), and a corner of a
//! removed vertex `a` moved onto `b` takes the wedge of `b` from the removed triangle on its
//! side of `a`'s fan (the wedge that the removed triangle's `a` shared an attribute region
//! with, where there is one). When the run finishes, the output triangles name wedges again.
//!
//! This is meshoptimizer's `remap`/`wedge` idea (`simplifier.cpp`). Where more than two
//! wedges meet (a corner where seams meet, or a vertex shaded flat, one wedge per face) no
//! single wedge of the kept vertex belongs to every region, so a corner of a third region would
//! take a wedge from another texture chart: [`SeamCorners::Lock`] keeps such a vertex where it
//! is (it still accepts collapses onto it), as meshoptimizer locks its complex vertices;
//! [`SeamCorners::Move`] moves all its wedges with the removed triangles' neighbours, for
//! wedges that carry nothing a seam corner could tear (positions only).
//!
//! Memory: the wedge buffer holds one triangle per triangle (`3·size_of::<I>()` bytes per
//! triangle: 6 B with `u16` indices), and [`weld`] sorts in one caller slice of one index per
//! vertex (`size_of::<L>()`, 2 B with `u16`), free again once it returns. Time: O(V log V) for
//! the sort (a heapsort, in place) and O(T log V) to renumber the corners (a binary search
//! each). Nothing here runs unless the caller asks: [`Storage::simplify`](crate::Storage::simplify)
//! carries none of it.

use crate::index::Index;
use crate::Error;

/// What a welded vertex where more than two wedges meet may do
/// ([`Simplifier::with_wedges`](crate::Simplifier::with_wedges)).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum SeamCorners {
    /// It never moves (other vertices may still collapse onto it): each region around it keeps
    /// its own wedge, so no triangle takes corners from two texture charts. meshoptimizer's
    /// rule for its complex vertices, and the one for real attributes.
    Lock,
    /// It moves like any other vertex, each corner taking a wedge of the kept vertex from the
    /// removed triangle on its side: for wedges that carry nothing to tear (a split index
    /// buffer whose attributes are not kept), where locking would freeze a mesh shaded flat.
    Move,
}

/// The bits a position is compared by: `-0.0` is `0.0` (equal positions are one position).
#[inline]
fn key(p: &[f32; 3]) -> [u32; 3] {
    p.map(|x| if x == 0.0 { 0 } else { x.to_bits() })
}

/// The position key of vertex `v`, then `v` (a total order: ties on the vertex number).
#[inline]
fn order_key(positions: &[[f32; 3]], v: usize) -> ([u32; 3], usize) {
    match positions.get(v) {
        Some(p) => (key(p), v),
        None => ([u32::MAX; 3], v),
    }
}

/// Sorts `order` (vertex numbers) by position, then vertex number: a heapsort, in place,
/// O(n log n), no recursion.
fn sort<L: Index>(positions: &[[f32; 3]], order: &mut [L]) {
    let k = |order: &[L], i: usize| order_key(positions, order.get(i).map_or(0, |v| v.to_usize()));
    let sift = |order: &mut [L], mut root: usize, end: usize| loop {
        let mut child = 2 * root + 1;
        if child >= end {
            break;
        }
        if child + 1 < end && k(order, child) < k(order, child + 1) {
            child += 1;
        }
        if k(order, root) >= k(order, child) {
            break;
        }
        swap(order, root, child);
        root = child;
    };
    let n = order.len();
    for root in (0..n / 2).rev() {
        sift(order, root, n);
    }
    for end in (1..n).rev() {
        swap(order, 0, end);
        sift(order, 0, end);
    }
}

/// `order.swap(i, j)` where both are in range; the check keeps the heapsort panic-free where
/// the optimiser cannot see the bounds through the sift's closure.
#[inline]
fn swap<L: Index>(order: &mut [L], i: usize, j: usize) {
    if i < order.len() && j < order.len() {
        order.swap(i, j);
    }
}

/// The representative of vertex `v` (the first vertex at its position), found by binary
/// search in `order` (sorted by [`sort`]): the group of `v`'s position starts with it.
fn representative<L: Index>(positions: &[[f32; 3]], order: &[L], v: usize) -> usize {
    let Some(p) = positions.get(v) else {
        return v;
    };
    let target = (key(p), 0usize);
    // The first entry not below (position, 0).
    let (mut lo, mut hi) = (0, order.len());
    while lo < hi {
        let mid = lo + (hi - lo) / 2;
        let m = order.get(mid).map_or(0, |x| x.to_usize());
        if order_key(positions, m) < target {
            lo = mid + 1;
        } else {
            hi = mid;
        }
    }
    match order.get(lo) {
        Some(x) if positions.get(x.to_usize()).map(key) == Some(key(p)) => x.to_usize(),
        _ => v,
    }
}

/// Welds `triangles` by position, in place: `wedges` receives a copy of them as given, and
/// every corner of `triangles` is renumbered to the first vertex at its position. `order` is
/// scratch of one index per position (`positions.len()` entries; its contents on return mean
/// nothing). Returns how many corners were renumbered (0: no seams).
///
/// Errors, before anything is written: [`Error::IndexOutOfRange`] for a corner past
/// `positions`; [`Error::Capacity`] if `wedges` is shorter than `triangles` or `order` than
/// `positions` (or `L` cannot number them).
pub fn weld<I: Index, L: Index>(
    positions: &[[f32; 3]],
    triangles: &mut [[I; 3]],
    wedges: &mut [[I; 3]],
    order: &mut [L],
) -> Result<usize, Error> {
    let nv = positions.len();
    if order.len() < nv || nv > L::COUNT {
        return Err(Error::Capacity {
            what: crate::Capacity::Vertices,
            needed: nv,
            available: order.len().min(L::COUNT),
        });
    }
    if wedges.len() < triangles.len() {
        return Err(Error::Capacity {
            what: crate::Capacity::Triangles,
            needed: triangles.len(),
            available: wedges.len(),
        });
    }
    for (t, tri) in triangles.iter().enumerate() {
        for &i in tri {
            if i.to_usize() >= nv {
                return Err(Error::IndexOutOfRange {
                    triangle: t,
                    index: i.to_usize(),
                });
            }
        }
    }
    let order = order.get_mut(..nv).unwrap_or(&mut []);
    for (i, o) in order.iter_mut().enumerate() {
        *o = L::narrow(i);
    }
    sort(positions, order);
    let mut moved = 0;
    for (tri, w) in triangles.iter_mut().zip(wedges.iter_mut()) {
        *w = *tri;
        for c in tri.iter_mut() {
            let r = representative(positions, order, c.to_usize());
            if r != c.to_usize() {
                *c = I::narrow(r);
                moved += 1;
            }
        }
    }
    Ok(moved)
}

/// The wedge of `b` that a corner of the removed vertex `a` takes when `a` moves onto `b`:
/// `x` is the corner's own wedge of `a`; `sides` the removed triangles' `(a wedge, b wedge)`,
/// the first on the side where the walk of `a`'s survivors starts; `first_half` whether the
/// corner is in the first half of that walk. A wedge of `a` that only one removed triangle
/// holds goes to that triangle's wedge of `b` (the two shared an attribute region); any other
/// goes to the nearer removed triangle's.
#[inline]
pub(crate) fn moved_wedge(x: usize, sides: [(usize, usize); 2], first_half: bool) -> usize {
    let [(a1, b1), (a2, b2)] = sides;
    if x == a1 && x != a2 {
        b1
    } else if x == a2 && x != a1 {
        b2
    } else if first_half {
        b1
    } else {
        b2
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn weld_renumbers_to_the_first_vertex_at_each_position() {
        // Two triangles of a quad, split along the diagonal (vertices 3 and 4 repeat 0 and 2),
        // and a negative zero.
        let p = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [-0.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
        ];
        let mut t = [[0u16, 1, 2], [3, 4, 5]];
        let mut w = [[0u16; 3]; 2];
        let mut order = [0u16; 6];
        assert_eq!(weld(&p, &mut t, &mut w, &mut order), Ok(2));
        assert_eq!(t, [[0, 1, 2], [0, 2, 5]]);
        assert_eq!(w, [[0, 1, 2], [3, 4, 5]]);
    }

    #[test]
    fn weld_refuses_short_storage_and_bad_indices_untouched() {
        let p = [[0.0f32; 3]; 3];
        let mut t = [[0u16, 1, 2]];
        let mut w = [[0u16; 3]; 1];
        assert!(weld(&p, &mut t, &mut w, &mut [0u16; 2]).is_err());
        assert!(weld(&p, &mut t, &mut [], &mut [0u16; 3]).is_err());
        let mut bad = [[0u16, 1, 7]];
        assert_eq!(
            weld(&p, &mut bad, &mut w, &mut [0u16; 3]),
            Err(Error::IndexOutOfRange {
                triangle: 0,
                index: 7
            })
        );
        assert_eq!(bad, [[0, 1, 7]]);
    }

    #[test]
    fn sort_orders_many_positions() {
        let mut p = [[0.0f32; 3]; 97];
        for (i, q) in p.iter_mut().enumerate() {
            *q = [((i * 37) % 11) as f32, ((i * 13) % 5) as f32, 0.0];
        }
        let mut order: [u32; 97] = core::array::from_fn(|i| i as u32);
        sort(&p, &mut order);
        for w in order.windows(2) {
            assert!(order_key(&p, w[0] as usize) < order_key(&p, w[1] as usize));
        }
        for v in 0..97 {
            let r = representative(&p, &order, v);
            assert!(r <= v && key(&p[r]) == key(&p[v]));
            assert!((0..r).all(|u| key(&p[u]) != key(&p[v])));
        }
    }
}
