//! Building a progressive mesh from a simplification's collapse log.

use super::{Lists, Progressive, ProgressiveError, Split, Storage};
use crate::index::Index;
use crate::tri::{self, NIL};

impl<'a, I: Index> Progressive<'a, I> {
    /// Builds the progressive mesh of a simplification from the input triangles (as they were
    /// before simplifying) and the simplifier's collapse log
    /// ([`Simplifier::record_into`](crate::Simplifier::record_into)), and leaves it at full
    /// resolution.
    ///
    /// `order` receives, for each new vertex number, the input's vertex (at least
    /// `vertex_count` entries); `scratch` needs one entry per input triangle. Input triangles
    /// with a repeated index, and later copies of a triangle (same vertices), are dropped as
    /// the simplifier drops them; they end up past [`Progressive::full_triangles`].
    ///
    /// O(triangles + collapses × valence). Errors leave the storage's contents unspecified.
    pub fn from_log(
        input: &[[I; 3]],
        vertex_count: usize,
        log: &[[I; 2]],
        storage: Storage<'a, I>,
        order: &mut [I],
        scratch: &mut [I],
    ) -> Result<Self, ProgressiveError> {
        let nt = input.len();
        let nv = vertex_count;
        check_capacity(input, nv, log.len(), &storage, order.len(), scratch.len())?;
        let Storage {
            triangles,
            links,
            heads,
            splits,
        } = storage;
        let (Some(tris), Some(next), Some(head), Some(order), Some(rank)) = (
            triangles.get_mut(..nt),
            links.get_mut(..nt),
            heads.get_mut(..nv),
            order.get_mut(..nv),
            scratch.get_mut(..nt),
        ) else {
            return Err(ProgressiveError::BadLog { entry: 0 });
        };
        for (d, &x) in tris.iter_mut().zip(input) {
            *d = x;
        }
        head.fill(I::NIL);
        // rank[u]: NIL while live, the collapse that removed it, or DROPPED.
        let dropped = I::narrow(I::COUNT - 1);
        rank.fill(I::NIL);
        let mut lists = Lists::new(tris, next, head);

        // 1. Link the input in slot order (appends), dropping what the simplifier drops.
        link_input(&mut lists, rank, dropped);
        // 2. Replay the log.
        replay(&mut lists, log, rank, nv)?;
        // 3. Where each triangle goes; the full mesh in that order.
        let (base_triangles, full_triangles) = destinations(rank, splits, log.len(), dropped);
        let Lists { tris, next, head } = lists;
        permute(tris, input, rank);
        // 4. Renumber the vertices.
        let base_vertices = renumber(tris, head, order, splits, log, full_triangles)?;

        // 5. Links for the full mesh, then collapse it down to the base mesh: each collapse
        // removes the last triangles of the prefix and yields the split that undoes it.
        head.fill(I::NIL);
        let mut lists = Lists::new(tris, next, head);
        for u in 0..full_triangles {
            for v in lists.tri(u) {
                // Pushing in front, slots ascending: largest first.
                let first = lists.first(v);
                lists.set_after(u, v, first);
                lists.set_first(v, u);
            }
        }
        let mut pm = Progressive {
            lists,
            splits,
            base_vertices,
            base_triangles,
            known: log.len(),
            top_triangles: full_triangles,
            level: log.len(),
            live: full_triangles,
        };
        pm.collapse_to_base(log.len())?;
        // Back up to full resolution.
        pm.refine(usize::MAX);
        Ok(pm)
    }

    /// Collapses the full mesh down to the base mesh, `k` collapses, writing each split that
    /// undoes one.
    fn collapse_to_base(&mut self, k: usize) -> Result<(), ProgressiveError> {
        for e in 0..k {
            let t = self.base_vertices + self.level - 1;
            let s = self
                .splits
                .get(self.level - 1)
                .map_or(NIL, |sp| sp.kept.to_usize());
            match self.collapse_last(t, s) {
                Some(split) => {
                    if let Some(sp) = self.splits.get_mut(self.level) {
                        *sp = split;
                    }
                }
                None => {
                    return Err(if self.lists.len(s) + self.lists.len(t) > 64 {
                        ProgressiveError::ValenceTooHigh { entry: e }
                    } else {
                        ProgressiveError::BadLog { entry: e }
                    })
                }
            }
        }
        Ok(())
    }

    /// Undoes split `level - 1`: vertex `t` (the last one) goes back onto `s`, and the last
    /// triangles of the prefix (those on edge `s-t`) leave it. Returns the split that redoes
    /// it, `None` if the prefix does not end with `s-t` triangles.
    fn collapse_last(&mut self, t: usize, s: usize) -> Option<Split<I>> {
        if self.level == 0 || s >= t {
            return None;
        }
        // Triangles on the edge: the ones of t's list that hold s.
        let mut on_edge = 0;
        let mut u = self.lists.first(t);
        while u != NIL && on_edge <= 2 {
            if self.lists.slot(u, s).is_some() {
                on_edge += 1;
            }
            u = self.lists.after(u, t);
        }
        if !(1..=2).contains(&on_edge) || on_edge > self.live {
            return None;
        }
        for u in self.live - on_edge..self.live {
            let tri = self.lists.tri(u);
            if !tri.contains(&s) || !tri.contains(&t) {
                return None;
            }
        }
        for u in self.live - on_edge..self.live {
            self.lists.unlink_triangle(u);
        }
        let moved = self.lists.merge(t, s)?;
        self.live -= on_edge;
        self.level -= 1;
        Some(Split {
            kept: I::narrow(s),
            restored: on_edge as u8,
            moved,
        })
    }
}

/// Checks every buffer's size and the input's indices before anything is written.
fn check_capacity<I: Index>(
    input: &[[I; 3]],
    nv: usize,
    collapses: usize,
    storage: &Storage<'_, I>,
    order: usize,
    scratch: usize,
) -> Result<(), ProgressiveError> {
    let nt = input.len();
    let cap = |what, needed: usize, available: usize| {
        if needed > available {
            Err(ProgressiveError::Capacity {
                what,
                needed,
                available,
            })
        } else {
            Ok(())
        }
    };
    // Slots and vertex numbers must stay below the index type's NIL.
    cap("triangles", nt, storage.triangles.len().min(I::COUNT))?;
    cap("links", nt, storage.links.len())?;
    cap("heads", nv, storage.heads.len().min(I::COUNT))?;
    cap("order", nv, order)?;
    cap("scratch", nt, scratch)?;
    cap("splits", collapses, storage.splits.len().min(I::COUNT - 2))?;
    for (t, tri) in input.iter().enumerate() {
        if tri.iter().any(|i| i.to_usize() >= nv) {
            return Err(ProgressiveError::IndexOutOfRange { triangle: t });
        }
    }
    Ok(())
}

/// Links the input in slot order (appends), marking what the simplifier drops (a repeated
/// index, a later copy of a triangle) as `dropped` in `rank`.
fn link_input<I: Index>(lists: &mut Lists<'_, I>, rank: &mut [I], dropped: I) {
    for u in 0..lists.tris.len() {
        let tri = lists.tri(u);
        let mut drop = tri::is_degenerate(tri);
        if !drop {
            // A later copy: the same vertices as a kept triangle before it in the list of
            // its first vertex.
            let mut w = lists.first(tri[0]);
            while w != NIL && w < u {
                if tri::same_set(lists.tri(w), tri) {
                    drop = true;
                    break;
                }
                w = lists.after(w, tri[0]);
            }
        }
        if drop {
            if let Some(r) = rank.get_mut(u) {
                *r = dropped;
            }
        } else {
            lists.link(u);
        }
    }
}

/// Replays the log: each collapse removes the triangles on its edge (ranked by the collapse)
/// and renames the removed vertex's other corners.
fn replay<I: Index>(
    lists: &mut Lists<'_, I>,
    log: &[[I; 2]],
    rank: &mut [I],
    nv: usize,
) -> Result<(), ProgressiveError> {
    for (e, &[t, s]) in log.iter().enumerate() {
        let bad = ProgressiveError::BadLog { entry: e };
        let (t, s) = (t.to_usize(), s.to_usize());
        if t >= nv || s >= nv || t == s || lists.first(t) == NIL || lists.first(s) == NIL {
            return Err(bad);
        }
        let mut gone = 0;
        let mut u = lists.first(t);
        while u != NIL {
            let n = lists.after(u, t);
            if lists.slot(u, s).is_some() {
                lists.unlink_triangle(u);
                if let Some(r) = rank.get_mut(u) {
                    *r = I::narrow(e);
                }
                gone += 1;
            }
            u = n;
        }
        if !(1..=2).contains(&gone) {
            return Err(bad);
        }
        lists.merge(t, s);
    }
    Ok(())
}

/// Where each triangle goes: base (in input order), then removed ones in reverse collapse
/// order (ties: the input order within a collapse), then dropped ones. Rewrites `rank` as each
/// slot's destination and the first `collapses` splits' `restored`; returns the base and full
/// triangle counts.
fn destinations<I: Index>(
    rank: &mut [I],
    splits: &mut [Split<I>],
    collapses: usize,
    dropped: I,
) -> (usize, usize) {
    let mut base_triangles = 0;
    let mut removed = 0;
    for &r in rank.iter() {
        if r == I::NIL {
            base_triangles += 1;
        } else if r != dropped {
            removed += 1;
        }
    }
    let full_triangles = base_triangles + removed;
    // Per collapse, its triangle count (in `restored`), then its first destination (in
    // `moved`): the later a collapse, the earlier its triangles.
    for sp in splits.iter_mut().take(collapses) {
        *sp = Split::EMPTY;
    }
    for &r in rank.iter() {
        if r != I::NIL && r != dropped {
            if let Some(sp) = splits.get_mut(r.to_usize()) {
                sp.restored += 1;
            }
        }
    }
    let mut at = base_triangles;
    for e in (0..collapses).rev() {
        if let Some(sp) = splits.get_mut(e) {
            sp.moved = at as u64;
            at += sp.restored as usize;
        }
    }
    let (mut b, mut d) = (0, full_triangles);
    for r in rank.iter_mut() {
        let dest = if *r == I::NIL {
            b += 1;
            b - 1
        } else if *r == dropped {
            d += 1;
            d - 1
        } else {
            match splits.get_mut(r.to_usize()) {
                Some(sp) => {
                    sp.moved += 1;
                    sp.moved as usize - 1
                }
                None => 0,
            }
        };
        *r = I::narrow(dest);
    }
    (base_triangles, full_triangles)
}

/// The full mesh is the input itself (the replay left each removed triangle as it was when
/// removed): copies the input and permutes it in place along the cycles of `dest`.
fn permute<I: Index>(tris: &mut [[I; 3]], input: &[[I; 3]], dest: &mut [I]) {
    let nt = input.len();
    for (d, &x) in tris.iter_mut().zip(input) {
        *d = x;
    }
    for i in 0..nt {
        let mut guard = 0;
        while let Some(&j) = dest.get(i) {
            let j = j.to_usize();
            if j == i || j >= nt || guard > nt {
                break;
            }
            if i < tris.len() && j < tris.len() && i < dest.len() && j < dest.len() {
                tris.swap(i, j);
                dest.swap(i, j);
            }
            guard += 1;
        }
    }
}

/// Renumbers the vertices: base vertices in input order, then removed ones in reverse collapse
/// order, in the full mesh's triangles and in `order` (new -> input); parks the renumbered kept
/// vertex of collapse `e` where split `K-1-e` will go. `head` is the old -> new map meanwhile.
/// Returns the number of base vertices.
fn renumber<I: Index>(
    tris: &mut [[I; 3]],
    head: &mut [I],
    order: &mut [I],
    splits: &mut [Split<I>],
    log: &[[I; 2]],
    full_triangles: usize,
) -> Result<usize, ProgressiveError> {
    head.fill(I::NIL);
    let mark = I::ZERO;
    // Base vertices: used by the full mesh and never removed.
    for tri in tris.iter().take(full_triangles) {
        for &v in tri {
            if let Some(m) = head.get_mut(v.to_usize()) {
                *m = mark;
            }
        }
    }
    for &[t, _] in log {
        if let Some(m) = head.get_mut(t.to_usize()) {
            *m = I::NIL;
        }
    }
    let mut n = 0;
    for v in 0..head.len() {
        if head.get(v) == Some(&mark) {
            if let (Some(m), Some(o)) = (head.get_mut(v), order.get_mut(n)) {
                *m = I::narrow(n);
                *o = I::narrow(v);
            }
            n += 1;
        }
    }
    let base_vertices = n;
    for (e, &[t, _]) in log.iter().enumerate().rev() {
        match head.get_mut(t.to_usize()) {
            Some(m) if *m == I::NIL => *m = I::narrow(n),
            _ => return Err(ProgressiveError::BadLog { entry: e }),
        }
        if let Some(o) = order.get_mut(n) {
            *o = t;
        }
        n += 1;
    }
    for tri in tris.iter_mut().take(full_triangles) {
        for x in tri.iter_mut() {
            match head.get(x.to_usize()) {
                Some(&m) if m != I::NIL => *x = m,
                // A vertex left without triangles by the log (never removed, not in the base).
                _ => return Err(ProgressiveError::BadLog { entry: log.len() }),
            }
        }
    }
    // The kept vertex of collapse `e`, renumbered, parked where split `K-1-e` will go.
    let k = log.len();
    for (e, &[_, sv]) in log.iter().enumerate() {
        let m = head.get(sv.to_usize()).copied().unwrap_or(I::NIL);
        match splits.get_mut(k - 1 - e) {
            Some(sp) if m != I::NIL => sp.kept = m,
            _ => return Err(ProgressiveError::BadLog { entry: e }),
        }
    }
    Ok(base_vertices)
}
