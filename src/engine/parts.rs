//! Pruning parts: a connected component that costs less to remove than the collapse the queue
//! is about to make vanishes whole (crate feature `parts`).
//!
//! A collapse never changes topology, so on an assembly of many parts every small part keeps
//! its last few triangles however far the rest goes: a screw's four faces cost as much of the
//! triangle budget as four faces of the body. This is meshoptimizer's `meshopt_SimplifyPrune`
//! (`simplifier.cpp`: `buildComponents`, `measureComponents`, `pruneComponents`): components
//! by union-find over the triangles, each sized once by its squared radius about its
//! centroid, and removed in order of size while they are below the current error; then, short
//! of the target with no collapse left, the smallest ones up to the error limit
//! ([`Config::max_cost`](crate::Config::max_cost) here). Two differences: a part's size is in
//! the cost's units ([`Cost::part`]: the squared radius times twice the area for the quadric
//! costs, as the keys are an area times a squared distance) and is compared with every key
//! the queue pops instead of once per pass; and the last part is never removed, so the result
//! is never empty.
//!
//! Memory: two links per vertex in the caller's slice (4 B with `u16` links): a ring through
//! the vertices of each part, and the parts' order (part `i`'s smallest vertex in slot `i`).
//! The sizes are sorted in the workspace's key array before the queue first uses it; when a
//! part's turn comes its size is measured again, with its area as it is then. Time: O(T log V)
//! to label (union-find, path halving, the smaller vertex as root: deterministic), O(V log V)
//! for the sort (heapsort, ties on the vertex), O(part) to measure or remove a part.

#[cfg(feature = "parts")]
use super::Phase;
use super::Simplifier;
use crate::index::Index;
use crate::operator::Operator;
use crate::policy::bound::Bound;
use crate::policy::cost::Cost;
#[cfg(feature = "parts")]
use {
    crate::math,
    crate::mesh::{flag, is_dead, Mesh},
    crate::{ConfigField, Error},
};

/// The parts of a pruning run.
#[cfg(feature = "parts")]
pub(crate) struct Parts<'a, L: Index> {
    /// Per vertex: `[next vertex of its part (a ring), slot of the parts' order]`.
    links: &'a mut [[L; 2]],
    /// Parts with triangles at the start (the length of the order).
    count: usize,
    /// Parts removed so far: the order's first `cursor` entries.
    cursor: usize,
    /// The size of the part at the cursor, and its squared radius (normalised units).
    next: f32,
    next_r2: f32,
    /// Removed parts that still had triangles.
    removed: usize,
}

#[cfg(feature = "parts")]
impl<L: Index> Parts<'_, L> {
    /// No pruning.
    pub(crate) fn off() -> Self {
        Parts {
            links: &mut [],
            count: 0,
            cursor: 0,
            next: f32::INFINITY,
            next_r2: f32::INFINITY,
            removed: 0,
        }
    }

    fn ring(&self, v: usize) -> usize {
        self.links.get(v).map_or(v, |l| l[0].to_usize())
    }

    fn order(&self, i: usize) -> usize {
        self.links.get(i).map_or(0, |l| l[1].to_usize())
    }
}

#[cfg(feature = "parts")]
impl<'a, L: Index, I: Index, C: Cost, B: Bound<'a, I>, O: Operator> Simplifier<'a, L, I, C, B, O> {
    /// Lets whole parts vanish: a connected component of the mesh (with welded seams
    /// ([`seam`](crate::seam)), of positions, so a part split on a seam is one part) whose
    /// size ([`Cost::part`]: for the quadric costs its squared radius about the centroid
    /// times twice its area, in the units of the queue's keys) is below the key of the
    /// collapse the queue is about to make is removed whole, all its triangles at once, before
    /// that collapse. Short of the target with no legal collapse left, parts go smallest first
    /// while their size is at most [`Config::max_cost`](crate::Config::max_cost). The largest
    /// part (the last in size order) always stays. [`Report::parts_removed`](crate::Report)
    /// counts them; a removed part's vertices count as removed.
    ///
    /// `links`: one pair of links per position (4 B with `u16` links, 8 B with `u32`), at
    /// least as many pairs as positions; their contents on entry do not matter. The parts are
    /// labelled and sorted here, in O(T log V).
    ///
    /// Errors: [`Error::Capacity`] (vertices) if `links` is short;
    /// [`Error::InvalidConfig`] for [`ConfigField::Parts`] with the passes schedule, an error
    /// bound ([`Controls`](crate::Controls): its control points live on the triangles), a
    /// collapse log ([`Simplifier::record_into`]: the log holds collapses only; one given after
    /// this call keeps every part), or after the first step.
    pub fn with_parts(mut self, links: &'a mut [[L; 2]]) -> Result<Self, Error> {
        let nv = self.mesh.vertex_count();
        if B::ON
            || self.logging
            || !self.config.schedule.is_ordered()
            || self.phase != Phase::Mean
            || self.v != 0
            || self.passes != 0
        {
            return Err(Error::InvalidConfig {
                field: ConfigField::Parts,
            });
        }
        let available = links.len();
        let (Some(links), Some(keys)) = (links.get_mut(..nv), self.heap.idle_keys()) else {
            return Err(Error::Capacity {
                what: crate::Capacity::Vertices,
                needed: nv,
                available,
            });
        };
        let count = label(&self.mesh, links, keys, &self.cost);
        let mut parts = Parts {
            links,
            count,
            cursor: 0,
            next: f32::INFINITY,
            next_r2: f32::INFINITY,
            removed: 0,
        };
        if count > 1 {
            (parts.next, parts.next_r2) = measure(&self.mesh, &parts, &self.cost, parts.order(0));
        }
        self.parts = parts;
        Ok(self)
    }

    /// Removes the smallest part left if it is below `limit` (the key about to be collapsed;
    /// infinite when no collapse is left) and at most `max_cost`, the mesh is above its target
    /// and another part remains. One operation; `true` if it removed one.
    pub(super) fn prune_below(&mut self, limit: f32) -> bool {
        let p = &self.parts;
        if p.cursor + 1 >= p.count || self.logging || self.mesh.live <= self.target {
            return false;
        }
        // A part wider than the error limit stays: removing it is an error of its radius.
        if !(p.next < limit && p.next <= self.config.max_cost && p.next_r2 <= self.limit2) {
            return false;
        }
        let root = p.order(p.cursor);
        let (mut v, mut dropped, mut guard) = (root, 0, self.mesh.vertex_count());
        while guard > 0 {
            guard -= 1;
            dropped += self.mesh.drop_fan(v);
            self.heap.remove(v);
            v = self.parts.ring(v);
            if v == root {
                break;
            }
        }
        let p = &mut self.parts;
        p.cursor += 1;
        p.removed += usize::from(dropped > 0);
        let next = measure(&self.mesh, p, &self.cost, p.order(p.cursor));
        (self.parts.next, self.parts.next_r2) = next;
        true
    }

    /// Parts removed so far.
    pub(super) fn parts_removed(&self) -> usize {
        self.parts.removed
    }
}

#[cfg(not(feature = "parts"))]
impl<'a, L: Index, I: Index, C: Cost, B: Bound<'a, I>, O: Operator> Simplifier<'a, L, I, C, B, O> {
    /// Without the feature no part is removed.
    #[inline(always)]
    pub(super) fn prune_below(&mut self, _limit: f32) -> bool {
        false
    }

    /// Without the feature no part is removed.
    #[inline(always)]
    pub(super) fn parts_removed(&self) -> usize {
        0
    }
}

/// Labels the parts of `mesh` in `links` and sorts them by size (sizes in `keys`, one per
/// part's smallest vertex); returns how many have triangles.
#[cfg(feature = "parts")]
fn label<L: Index, I: Index, C: Cost>(
    mesh: &Mesh<'_, L, I>,
    links: &mut [[L; 2]],
    keys: &mut [f32],
    cost: &C,
) -> usize {
    let nv = links.len();
    // Union-find in slot 0: each vertex's parent, a part's smallest vertex its root.
    for (v, l) in links.iter_mut().enumerate() {
        l[0] = L::narrow(v);
    }
    // Two unions per live triangle join its three vertices; the roots do not depend on the
    // order of the unions.
    for t in 0..mesh.triangle_count() {
        let tri = mesh.tri(t);
        if is_dead(tri) {
            continue;
        }
        for w in [tri[1], tri[2]] {
            let (a, b) = (find(links, tri[0]), find(links, w));
            if let Some(l) = links.get_mut(a.max(b)) {
                l[0] = L::narrow(a.min(b));
            }
        }
    }
    // Each vertex's root in slot 1, then slot 0 becomes a ring through each part: a root is
    // below its other vertices, so its ring exists before they join it.
    for v in 0..nv {
        let r = find(links, v);
        if let Some(l) = links.get_mut(v) {
            l[1] = L::narrow(r);
        }
    }
    for v in 0..nv {
        let r = links.get(v).map_or(v, |l| l[1].to_usize());
        if r == v {
            if let Some(l) = links.get_mut(v) {
                l[0] = L::narrow(v);
            }
        } else {
            let after = links.get(r).map_or(L::narrow(v), |l| l[0]);
            if let Some(l) = links.get_mut(v) {
                l[0] = after;
            }
            if let Some(l) = links.get_mut(r) {
                l[0] = L::narrow(v);
            }
        }
    }
    // The parts with triangles, by their roots, into the order (slot 1; entry `k` is written
    // only once vertex `k` has been read), each root's size in `keys`.
    let mut count = 0;
    for v in 0..nv {
        let root = links.get(v).is_some_and(|l| l[1].to_usize() == v);
        if root && mesh.has(v, flag::USED) {
            if let Some(l) = links.get_mut(count) {
                l[1] = L::narrow(v);
            }
            count += 1;
        }
    }
    if count < 2 {
        // One part never goes (the last part stays): no sizes to take.
        return count;
    }
    for i in 0..count {
        let r = links.get(i).map_or(0, |l| l[1].to_usize());
        let size = measure_ring(mesh, links, cost, r).0;
        if let Some(k) = keys.get_mut(r) {
            *k = size;
        }
    }
    sort(links.get_mut(..count).unwrap_or(&mut []), keys);
    count
}

/// The root of `v`'s set, halving the path on the way.
#[cfg(feature = "parts")]
fn find<L: Index>(links: &mut [[L; 2]], mut v: usize) -> usize {
    let mut guard = links.len();
    while guard > 0 {
        guard -= 1;
        let p = links.get(v).map_or(v, |l| l[0].to_usize());
        if p == v {
            break;
        }
        let g = links.get(p).map_or(p, |l| l[0].to_usize());
        if let Some(l) = links.get_mut(v) {
            l[0] = L::narrow(g);
        }
        v = g;
    }
    v
}

/// Heapsorts the order (slot 1 of `order`) by `(size, root)`, in place, without recursion.
#[cfg(feature = "parts")]
fn sort<L: Index>(order: &mut [[L; 2]], keys: &[f32]) {
    let k = |order: &[[L; 2]], i: usize| {
        let r = order.get(i).map_or(0, |l| l[1].to_usize());
        (keys.get(r).copied().unwrap_or(f32::INFINITY), r)
    };
    let less = |a: (f32, usize), b: (f32, usize)| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)).is_lt();
    let swap = |order: &mut [[L; 2]], i: usize, j: usize| {
        let (a, b) = (order.get(i).map(|l| l[1]), order.get(j).map(|l| l[1]));
        if let (Some(a), Some(b)) = (a, b) {
            if let Some(l) = order.get_mut(i) {
                l[1] = b;
            }
            if let Some(l) = order.get_mut(j) {
                l[1] = a;
            }
        }
    };
    let sift = |order: &mut [[L; 2]], mut root: usize, end: usize| loop {
        let mut child = 2 * root + 1;
        if child >= end {
            break;
        }
        if child + 1 < end && less(k(order, child), k(order, child + 1)) {
            child += 1;
        }
        if !less(k(order, root), k(order, child)) {
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

/// The size of the part through `root` ([`Cost::part`]), from `parts`' ring.
#[cfg(feature = "parts")]
fn measure<L: Index, I: Index, C: Cost>(
    mesh: &Mesh<'_, L, I>,
    parts: &Parts<'_, L>,
    cost: &C,
    root: usize,
) -> (f32, f32) {
    if parts.cursor >= parts.count {
        return (f32::INFINITY, f32::INFINITY);
    }
    measure_ring(mesh, parts.links, cost, root)
}

/// The size of the part whose ring (slot 0 of `links`) goes through `root`, and its squared
/// radius. The size: its squared
/// radius about the mean of its vertices (all the part's vertices, removed ones too: with
/// read-only positions the radius is the input's throughout) and twice the area of its live
/// triangles, each counted at its smallest vertex.
#[cfg(feature = "parts")]
fn measure_ring<L: Index, I: Index, C: Cost>(
    mesh: &Mesh<'_, L, I>,
    links: &[[L; 2]],
    cost: &C,
    root: usize,
) -> (f32, f32) {
    let ring = |v: usize| links.get(v).map_or(root, |l| l[0].to_usize());
    let (mut sum, mut n) = ([0.0f32; 3], 0u32);
    let (mut v, mut guard) = (root, links.len());
    while guard > 0 {
        guard -= 1;
        sum = math::add(sum, mesh.p(v));
        n += 1;
        v = ring(v);
        if v == root {
            break;
        }
    }
    let centre = math::scale(sum, 1.0 / n.max(1) as f32);
    let (mut r2, mut area2) = (0.0f32, 0.0f32);
    let (mut v, mut guard) = (root, links.len());
    while guard > 0 {
        guard -= 1;
        let d = math::sub(mesh.p(v), centre);
        r2 = r2.max(math::dot(d, d));
        for (t, _) in mesh.corners(v) {
            let tri = mesh.tri(t);
            if tri.iter().all(|&x| x >= v) {
                let (p, q, s) = (mesh.p(tri[0]), mesh.p(tri[1]), mesh.p(tri[2]));
                let c = math::cross(math::sub(q, p), math::sub(s, p));
                let l2 = math::dot(c, c);
                if l2 > math::TINY2 && l2.is_finite() {
                    area2 += l2 * math::rsqrt(l2);
                }
            }
        }
        v = ring(v);
        if v == root {
            break;
        }
    }
    (cost.part(r2, area2), r2)
}
