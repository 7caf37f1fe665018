//! Progressive meshes: the collapses of a simplification turned into vertex splits, and a
//! level-of-detail slider that moves between levels in place.
//!
//! Cheng, Pan and Shi 1998 ("A fast algorithm for generating progressive meshes") §2.1-2.2:
//! the input `M = Mⁿ` is simplified by edge collapses to a base mesh `M⁰`, and each collapse
//! is undone by a vertex split, so `M⁰ → M¹ → … → Mⁿ` recovers the input exactly. Here a
//! collapse keeps one endpoint (subset placement, Lin 2007 §2), so a split needs no new
//! position on the device.
//!
//! # Layout
//! [`Progressive::from_log`] rearranges the input once:
//! - **Vertices** are renumbered: the base mesh's vertices first (in input order), then the
//!   removed vertices in reverse collapse order (Cheng, Pan and Shi 1998 name them `m₀+i+1`),
//!   so split `j` always creates vertex `m₀ + j` and a record need not name it. `order[new] =
//!   input index` finds the positions, which stay where they are (they may be in flash).
//! - **Triangles**: the base mesh first (in input order), then the triangles each split
//!   restores, in split order. Every level is a prefix of the buffer, so a split or a collapse
//!   only moves the end of the prefix and rewrites the corners that change vertex.
//!
//! # Adjacency
//! Each vertex keeps a singly linked list of its triangles *sorted by slot, largest first*.
//! The order is a function of the current triangles alone (not of the history), which is what
//! lets a split name the corners that move by their positions in the kept vertex's list:
//! [`Split::moved`] is a bit mask over that list. A split takes the masked corners out of
//! `s`'s list (they stay sorted) and puts the restored triangles, whose slots are the largest,
//! at the heads of their corners' lists: O(1) each, where an ascending order would walk every
//! list to its end. A collapse unlinks those same triangles from the heads, and merges two
//! sorted lists. Both are O(valence) (the ascending order's cost is in docs/progressive.md).
//!
//! Memory: the triangle buffer, one link per corner and one list head per vertex (for `u16`:
//! 12 bytes per input triangle and 2 per vertex), plus 16 bytes per [`Split`].

use crate::index::Index;

pub mod stream;

/// Marks the end of a list.
const NIL: usize = usize::MAX;

/// One vertex split (the inverse of one logged collapse). Split `j` creates vertex `m₀ + j`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Split<I> {
    /// The vertex that stays (`s` of Cheng, Pan and Shi's `vsplit(s, l, r)`), in the new numbering.
    pub kept: I,
    /// Triangles the split restores: 2 for an interior edge, 1 for a boundary edge. They sit
    /// in the buffer right after the level's prefix.
    pub restored: u8,
    /// Which of `kept`'s triangles, counted in its list (by slot, largest first), go to the
    /// new vertex: bit `p` for the `p`-th.
    pub moved: u64,
}

impl<I: Index> Split<I> {
    /// A placeholder to fill a buffer with.
    pub const EMPTY: Self = Split {
        kept: I::ZERO,
        restored: 0,
        moved: 0,
    };
}

/// Why a collapse log could not be turned into vertex splits, or a progressive mesh not built.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ProgressiveError {
    /// A buffer of the storage is too small.
    Capacity {
        /// Which buffer (`"triangles"`, `"links"`, `"heads"`, `"order"`, `"scratch"`,
        /// `"splits"`).
        what: &'static str,
        /// Entries needed.
        needed: usize,
        /// Entries given.
        available: usize,
    },
    /// A triangle refers to a vertex at or past `vertex_count`.
    IndexOutOfRange {
        /// The triangle.
        triangle: usize,
    },
    /// Log entry `entry` is not a collapse of the mesh at that point (a vertex out of range
    /// or already removed, not an edge, more than two triangles on the edge, or a vertex left
    /// without triangles).
    BadLog {
        /// The entry.
        entry: usize,
    },
    /// The kept vertex of log entry `entry` has more than 64 triangles after the collapse and
    /// one that the split moves lies past the 64th of its list, which [`Split::moved`] cannot
    /// name. (A kept vertex of any valence is fine while the moved triangles are among its
    /// first 64.)
    ValenceTooHigh {
        /// The entry.
        entry: usize,
    },
}

impl core::fmt::Display for ProgressiveError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            ProgressiveError::Capacity {
                what,
                needed,
                available,
            } => write!(f, "{what}: {needed} needed, {available} given"),
            ProgressiveError::IndexOutOfRange { triangle } => {
                write!(f, "triangle {triangle} refers to a missing vertex")
            }
            ProgressiveError::BadLog { entry } => {
                write!(f, "log entry {entry} is not a collapse of the mesh")
            }
            ProgressiveError::ValenceTooHigh { entry } => {
                write!(
                    f,
                    "log entry {entry}: a triangle the split moves lies past the 64th of the kept vertex's"
                )
            }
        }
    }
}

/// Caller-provided memory of a [`Progressive`].
pub struct Storage<'a, I: Index> {
    /// Triangles: at least the input's count.
    pub triangles: &'a mut [[I; 3]],
    /// One link per corner: as many entries as `triangles`.
    pub links: &'a mut [[I; 3]],
    /// One list head per vertex: at least the vertex count.
    pub heads: &'a mut [I],
    /// One record per vertex split: at least the number of collapses.
    pub splits: &'a mut [Split<I>],
}

/// Triangle lists per vertex, sorted by slot, largest first (see the module comment).
pub(crate) struct Lists<'a, I: Index> {
    pub(crate) tris: &'a mut [[I; 3]],
    next: &'a mut [[I; 3]],
    head: &'a mut [I],
}

impl<'a, I: Index> Lists<'a, I> {
    pub(crate) fn new(tris: &'a mut [[I; 3]], next: &'a mut [[I; 3]], head: &'a mut [I]) -> Self {
        Lists { tris, next, head }
    }

    fn tri(&self, t: usize) -> [usize; 3] {
        match self.tris.get(t) {
            Some(&[a, b, c]) => [a.to_usize(), b.to_usize(), c.to_usize()],
            None => [NIL; 3],
        }
    }

    /// The slot of `v` in triangle `t`.
    fn slot(&self, t: usize, v: usize) -> Option<usize> {
        self.tri(t).iter().position(|&x| x == v)
    }

    pub(crate) fn first(&self, v: usize) -> usize {
        match self.head.get(v) {
            Some(&h) if h != I::NIL => h.to_usize(),
            _ => NIL,
        }
    }

    fn set_first(&mut self, v: usize, t: usize) {
        if let Some(h) = self.head.get_mut(v) {
            *h = if t == NIL { I::NIL } else { I::narrow(t) };
        }
    }

    /// The triangle after `t` in `v`'s list.
    pub(crate) fn after(&self, t: usize, v: usize) -> usize {
        let Some(k) = self.slot(t, v) else {
            return NIL;
        };
        match self.next.get(t).and_then(|n| n.get(k)) {
            Some(&n) if n != I::NIL => n.to_usize(),
            _ => NIL,
        }
    }

    fn set_after(&mut self, t: usize, v: usize, n: usize) {
        if let Some(k) = self.slot(t, v) {
            if let Some(l) = self.next.get_mut(t).and_then(|l| l.get_mut(k)) {
                *l = if n == NIL { I::NIL } else { I::narrow(n) };
            }
        }
    }

    fn rename(&mut self, t: usize, from: usize, to: usize) {
        if let Some(k) = self.slot(t, from) {
            if let Some(x) = self.tris.get_mut(t).and_then(|x| x.get_mut(k)) {
                *x = I::narrow(to);
            }
        }
    }

    /// Number of triangles in `v`'s list (bounded by the buffer, so a broken list ends).
    pub(crate) fn len(&self, v: usize) -> usize {
        let mut n = 0;
        let mut t = self.first(v);
        while t != NIL && n <= self.tris.len() {
            n += 1;
            t = self.after(t, v);
        }
        n
    }

    /// Inserts `t` (which holds `v`) into `v`'s list at its sorted place.
    fn insert(&mut self, v: usize, t: usize) {
        let mut prev = NIL;
        let mut c = self.first(v);
        let mut guard = 0;
        while c != NIL && c > t && guard <= self.tris.len() {
            prev = c;
            c = self.after(c, v);
            guard += 1;
        }
        self.set_after(t, v, c);
        if prev == NIL {
            self.set_first(v, t);
        } else {
            self.set_after(prev, v, t);
        }
    }

    /// Takes `t` out of `v`'s list.
    fn unlink(&mut self, v: usize, t: usize) {
        let mut prev = NIL;
        let mut c = self.first(v);
        let mut guard = 0;
        while c != NIL && c != t && guard <= self.tris.len() {
            prev = c;
            c = self.after(c, v);
            guard += 1;
        }
        if c != t {
            return;
        }
        let n = self.after(t, v);
        if prev == NIL {
            self.set_first(v, n);
        } else {
            self.set_after(prev, v, n);
        }
    }

    /// Links triangle `t`'s three corners.
    pub(crate) fn link(&mut self, t: usize) {
        for v in self.tri(t) {
            self.insert(v, t);
        }
    }

    /// Unlinks triangle `t`'s three corners.
    fn unlink_triangle(&mut self, t: usize) {
        for v in self.tri(t) {
            self.unlink(v, t);
        }
    }

    /// Moves every triangle of `t` to `s` (renaming the corner), merging the two sorted lists.
    /// Returns the mask of the moved triangles' positions in the merged list, or `None` if a
    /// moved one lands past position 63.
    fn merge(&mut self, t: usize, s: usize) -> Option<u64> {
        let mut a = self.first(s);
        let mut b = self.first(t);
        let mut prev = NIL;
        let mut mask = 0u64;
        let mut fits = true;
        let mut pos = 0usize;
        while (a != NIL || b != NIL) && pos <= self.tris.len() {
            let node = if b != NIL && (a == NIL || b > a) {
                let node = b;
                b = self.after(b, t);
                self.rename(node, t, s);
                match 1u64.checked_shl(pos as u32) {
                    Some(bit) if pos < 64 => mask |= bit,
                    _ => fits = false,
                }
                node
            } else {
                let node = a;
                a = self.after(a, s);
                node
            };
            if prev == NIL {
                self.set_first(s, node);
            } else {
                self.set_after(prev, s, node);
            }
            prev = node;
            pos += 1;
        }
        if prev != NIL {
            self.set_after(prev, s, NIL);
        }
        self.set_first(t, NIL);
        fits.then_some(mask)
    }

    /// The inverse of [`Lists::merge`]: the triangles at the `moved` positions of `s`'s list
    /// go to `t` (whose list must be empty), keeping both lists sorted.
    fn part(&mut self, s: usize, t: usize, moved: u64) {
        let mut prev_s = NIL;
        let mut tail_t = NIL;
        let mut c = self.first(s);
        let mut pos = 0u32;
        while c != NIL && (pos as usize) <= self.tris.len() {
            let n = self.after(c, s);
            let goes = pos < 64 && moved & (1u64 << (pos & 63)) != 0;
            if goes {
                // Out of s's list ...
                if prev_s == NIL {
                    self.set_first(s, n);
                } else {
                    self.set_after(prev_s, s, n);
                }
                // ... onto the end of t's.
                self.rename(c, s, t);
                self.set_after(c, t, NIL);
                if tail_t == NIL {
                    self.set_first(t, c);
                } else {
                    self.set_after(tail_t, t, c);
                }
                tail_t = c;
            } else {
                prev_s = c;
            }
            c = n;
            pos += 1;
        }
    }
}

/// A progressive mesh over caller-provided storage: the slider between its base mesh and the
/// full mesh. Every level is a prefix of [`Progressive::triangles`].
pub struct Progressive<'a, I: Index> {
    pub(crate) lists: Lists<'a, I>,
    pub(crate) splits: &'a mut [Split<I>],
    /// Vertices and triangles of the base mesh.
    pub(crate) base_vertices: usize,
    pub(crate) base_triangles: usize,
    /// Splits known (all of them after `from_log`; so far received when decoding).
    pub(crate) known: usize,
    /// Triangles of the finest known level.
    pub(crate) top_triangles: usize,
    /// Splits applied now.
    pub(crate) level: usize,
    /// Live triangles now.
    pub(crate) live: usize,
}

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
        cap("order", nv, order.len())?;
        cap("scratch", nt, scratch.len())?;
        cap("splits", log.len(), storage.splits.len().min(I::COUNT - 2))?;
        for (t, tri) in input.iter().enumerate() {
            if tri.iter().any(|i| i.to_usize() >= nv) {
                return Err(ProgressiveError::IndexOutOfRange { triangle: t });
            }
        }
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
        for u in 0..nt {
            let [a, b, c] = lists.tri(u);
            let mut drop = a == b || b == c || a == c;
            if !drop {
                let mut w = lists.first(a);
                while w != NIL && w < u {
                    if same_set(lists.tri(w), [a, b, c]) {
                        drop = true;
                        break;
                    }
                    w = lists.after(w, a);
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

        // 2. Replay the log: each collapse removes the triangles on its edge and renames the
        // removed vertex's other corners.
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

        // 3. Where each triangle goes: base (in input order), then removed ones in reverse
        // collapse order (ties: the input order within a collapse), then dropped ones.
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
        for sp in splits.iter_mut().take(log.len()) {
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
        for e in (0..log.len()).rev() {
            if let Some(sp) = splits.get_mut(e) {
                sp.moved = at as u64;
                at += sp.restored as usize;
            }
        }
        // `scratch` holds each slot's destination from here on.
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
        // The full mesh is the input itself (the replay left each removed triangle as it was
        // when removed): permute the input in place along the cycles of `dest`.
        let Lists { tris, next, head } = lists;
        for (d, &x) in tris.iter_mut().zip(input) {
            *d = x;
        }
        for i in 0..nt {
            let mut guard = 0;
            while let Some(&j) = rank.get(i) {
                let j = j.to_usize();
                if j == i || j >= nt || guard > nt {
                    break;
                }
                if i < tris.len() && j < tris.len() && i < rank.len() && j < rank.len() {
                    tris.swap(i, j);
                    rank.swap(i, j);
                }
                guard += 1;
            }
        }

        // 4. Renumber: base vertices in input order, then removed ones in reverse collapse
        // order. `head` is the old -> new map meanwhile.
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
        for v in 0..nv {
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
        for e in 0..k {
            let t = pm.base_vertices + pm.level - 1;
            let s = pm
                .splits
                .get(pm.level - 1)
                .map_or(NIL, |sp| sp.kept.to_usize());
            match pm.collapse_last(t, s) {
                Some(split) => {
                    if let Some(sp) = pm.splits.get_mut(pm.level) {
                        *sp = split;
                    }
                }
                None => {
                    return Err(if pm.lists.len(s) + pm.lists.len(t) > 64 {
                        ProgressiveError::ValenceTooHigh { entry: e }
                    } else {
                        ProgressiveError::BadLog { entry: e }
                    })
                }
            }
        }
        // Back up to full resolution.
        pm.refine(usize::MAX);
        Ok(pm)
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

    /// An empty progressive mesh (for the stream decoder to fill).
    pub(crate) fn empty(storage: Storage<'a, I>) -> Self {
        let Storage {
            triangles,
            links,
            heads,
            splits,
        } = storage;
        heads.fill(I::NIL);
        let n = triangles.len().min(links.len()).min(I::COUNT);
        let tris = triangles.get_mut(..n).unwrap_or_default();
        let next = links.get_mut(..n).unwrap_or_default();
        Progressive {
            lists: Lists::new(tris, next, heads),
            splits,
            base_vertices: 0,
            base_triangles: 0,
            known: 0,
            top_triangles: 0,
            level: 0,
            live: 0,
        }
    }

    /// Vertices the storage can number.
    pub(crate) fn vertex_capacity(&self) -> usize {
        self.lists.head.len().min(I::COUNT)
    }

    /// Triangles the storage holds.
    pub(crate) fn triangle_capacity(&self) -> usize {
        self.lists.tris.len()
    }

    /// Vertex splits the storage holds.
    pub(crate) fn split_capacity(&self) -> usize {
        self.splits.len()
    }

    /// Starts an empty base mesh over `base_vertices` vertices.
    pub(crate) fn start(&mut self, base_vertices: usize) {
        self.base_vertices = base_vertices;
    }

    /// Appends a base triangle; `false` if it does not fit or is not a triangle of the base
    /// vertices.
    pub(crate) fn push_base(&mut self, tri: [I; 3]) -> bool {
        let [a, b, c] = tri.map(|i| i.to_usize());
        if self.known > 0
            || a == b
            || b == c
            || a == c
            || a.max(b).max(c) >= self.base_vertices
            || self.live >= self.lists.tris.len()
        {
            return false;
        }
        if let Some(slot) = self.lists.tris.get_mut(self.live) {
            *slot = tri;
        }
        self.lists.link(self.live);
        self.live += 1;
        self.base_triangles += 1;
        self.top_triangles += 1;
        true
    }

    /// Appends a vertex split (creating vertex `base + levels`) with the triangles it
    /// restores, and applies it; `false` if it does not fit the storage.
    pub(crate) fn push_split(&mut self, split: Split<I>, restored: &[[I; 3]]) -> bool {
        self.refine(usize::MAX);
        let t = self.base_vertices + self.known;
        let top = self.top_triangles;
        if t >= self.vertex_capacity()
            || self.known >= self.splits.len()
            || top + restored.len() > self.lists.tris.len()
            || restored.len() != split.restored as usize
            || split.kept.to_usize() >= t
        {
            return false;
        }
        for (u, tri) in restored.iter().enumerate() {
            if let Some(slot) = self.lists.tris.get_mut(top + u) {
                *slot = *tri;
            }
        }
        if let Some(slot) = self.splits.get_mut(self.known) {
            *slot = split;
        }
        self.known += 1;
        self.top_triangles += restored.len();
        self.refine(1) == 1
    }

    /// Applies up to `n` vertex splits (finer); returns how many it applied.
    pub fn refine(&mut self, n: usize) -> usize {
        let mut done = 0;
        while done < n && self.level < self.known {
            let Some(&sp) = self.splits.get(self.level) else {
                break;
            };
            let t = self.base_vertices + self.level;
            self.lists.part(sp.kept.to_usize(), t, sp.moved);
            for u in self.live..self.live + sp.restored as usize {
                self.lists.link(u);
            }
            self.live += sp.restored as usize;
            self.level += 1;
            done += 1;
        }
        done
    }

    /// Applies up to `n` edge collapses (coarser); returns how many it applied.
    pub fn coarsen(&mut self, n: usize) -> usize {
        let mut done = 0;
        while done < n && self.level > 0 {
            let Some(&sp) = self.splits.get(self.level - 1) else {
                break;
            };
            let t = self.base_vertices + self.level - 1;
            let r = sp.restored as usize;
            if r > self.live {
                break;
            }
            for u in self.live - r..self.live {
                self.lists.unlink_triangle(u);
            }
            self.lists.merge(t, sp.kept.to_usize());
            self.live -= r;
            self.level -= 1;
            done += 1;
        }
        done
    }

    /// Goes to the finest level with at most `triangles` triangles (the base mesh if it has
    /// more): the mesh the simplifier had when it first reached that count.
    pub fn set_level(&mut self, triangles: usize) {
        while self.live > triangles && self.coarsen(1) == 1 {}
        while self.level < self.known {
            let r = self
                .splits
                .get(self.level)
                .map_or(usize::MAX, |s| s.restored as usize);
            if self.live + r > triangles || self.refine(1) == 0 {
                break;
            }
        }
    }

    /// The current level's triangles (new vertex numbers).
    pub fn triangles(&self) -> &[[I; 3]] {
        self.lists.tris.get(..self.live).unwrap_or(&[])
    }

    /// Vertices of the current level: numbers `0..vertices()` are in use.
    pub fn vertices(&self) -> usize {
        self.base_vertices + self.level
    }

    /// Vertex splits applied now (0: the base mesh).
    pub fn level(&self) -> usize {
        self.level
    }

    /// Vertex splits known: the finest level.
    pub fn levels(&self) -> usize {
        self.known
    }

    /// Triangles of the base mesh.
    pub fn base_triangles(&self) -> usize {
        self.base_triangles
    }

    /// Vertices of the base mesh.
    pub fn base_vertices(&self) -> usize {
        self.base_vertices
    }

    /// Triangles of the finest known level.
    pub fn full_triangles(&self) -> usize {
        self.top_triangles
    }

    /// The vertex splits (the first [`Progressive::levels`] are meaningful).
    pub fn splits(&self) -> &[Split<I>] {
        self.splits.get(..self.known).unwrap_or(&[])
    }
}

/// Same three vertices.
fn same_set(a: [usize; 3], b: [usize; 3]) -> bool {
    a.iter().all(|x| b.contains(x)) && b.iter().all(|x| a.contains(x))
}
