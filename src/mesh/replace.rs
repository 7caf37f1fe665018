//! Replacing a vertex's fan by triangles over its ring (vertex removal), in the fan's own
//! slots, keeping every list in fan order.

use super::{corner, Mesh};
use crate::index::Index;
use crate::tri::{next3, prev3, NIL};

/// The most triangles a replaced fan may have: the removal operators size their ring buffers
/// by it (`operator::MAX_RING`).
pub(crate) const MAX_FAN: usize = 32;

impl<L: Index, I: Index> Mesh<'_, L, I> {
    /// Removes `v` and its `k` triangles and writes `new` (triangles over `v`'s neighbours,
    /// `new.len() ≤ k`, wound as the fan was) into the first `new.len()` of their slots; the
    /// rest are removed. Returns how many triangles were removed (`k − new.len()`), 0 if
    /// nothing was done (a fan of more than `MAX_FAN` triangles, or `new` longer than
    /// the fan). The caller has checked the new fan (`legality::check_fan`); `v` and its
    /// neighbours are not locked, so their lists are in fan order.
    ///
    /// Each neighbour `x` had a window of one or two consecutive corners (cyclically, in a
    /// disc) in its list, in `v`'s triangles; its new triangles form one run from the
    /// neighbour after it in the loop to the one before, and the run takes the window's place:
    /// first every window is unlinked, remembering its neighbours in the list (corners of
    /// triangles that do not change), then the slots are rewritten and the runs linked in.
    pub(crate) fn replace_fan(&mut self, v: usize, new: &[[usize; 3]]) -> usize {
        let mut slots = [NIL; MAX_FAN];
        let mut k = 0;
        for (t, _) in self.corners(v) {
            match slots.get_mut(k) {
                Some(s) => *s = t,
                None => return 0,
            }
            k += 1;
        }
        if new.len() > k {
            return 0;
        }
        let slots = slots.get(..k).unwrap_or(&[]);
        // The ring: every other vertex of the fan, once.
        let mut ring = [NIL; MAX_FAN + 1];
        let mut n = 0;
        for &t in slots {
            for x in self.tri(t) {
                if x != v && !ring.iter().take(n).any(|&r| r == x) {
                    if let Some(r) = ring.get_mut(n) {
                        *r = x;
                        n += 1;
                    }
                }
            }
        }
        let ring = ring.get(..n).unwrap_or(&[]);
        // 1. Each neighbour's window out of its list: (flags, corner before, corner after).
        let mut at = [(0u8, NIL, NIL); MAX_FAN + 1];
        for (&x, place) in ring.iter().zip(at.iter_mut()) {
            *place = (self.flags(x), NIL, NIL);
            let (mut i, mut first_dead, mut last_dead, mut dead) = (0, NIL, NIL, 0);
            let (mut before, mut after_last, mut last_live) = (NIL, NIL, NIL);
            let mut prev = NIL;
            let mut c = self.first(x);
            let mut guard = self.tris.len();
            while c != NIL && guard > 0 {
                guard -= 1;
                if slots.contains(&(c >> 2)) {
                    if first_dead == NIL {
                        first_dead = i;
                        before = prev;
                    }
                    last_dead = i;
                    dead += 1;
                } else {
                    if last_dead != NIL && last_dead + 1 == i && after_last == NIL {
                        after_last = c;
                    }
                    last_live = c;
                }
                prev = c;
                c = self.after(c);
                i += 1;
            }
            if first_dead == NIL {
                continue;
            }
            *place = if last_dead + 1 - first_dead == dead {
                // One window: the run goes between its neighbours.
                (place.0, before, after_last)
            } else {
                // A disc's window across the list's end: the run goes last.
                (place.0, last_live, NIL)
            };
            for &t in slots {
                if self.tri(t).contains(&x) {
                    self.unlink(x, t);
                }
            }
        }
        // 2. The slots rewritten, the spare ones removed, v gone.
        self.set_first(v, NIL);
        self.set_flags(v, 0);
        for (i, &t) in slots.iter().enumerate() {
            match new.get(i) {
                Some(tri) => {
                    if let (Some(s), Some(l)) = (self.tris.get_mut(t), self.next.get_mut(t)) {
                        *s = tri.map(I::narrow);
                        *l = [L::NIL; 3];
                    }
                }
                None => {
                    self.kill(t);
                    self.live = self.live.saturating_sub(1);
                }
            }
        }
        // 3. Each neighbour's run, in its fan order: from the triangle whose edge to the next
        // neighbour no other new triangle shares, each next one across the last one's far edge.
        for (&x, &(flags, before, after)) in ring.iter().zip(at.iter()) {
            let mut mine = [(NIL, NIL, NIL); MAX_FAN];
            let mut m = 0;
            for (&t, tri) in slots.iter().zip(new) {
                if let Some(kx) = tri.iter().position(|&y| y == x) {
                    if let Some(s) = mine.get_mut(m) {
                        *s = (corner(t, kx), tri[next3(kx)], tri[prev3(kx)]);
                        m += 1;
                    }
                }
            }
            let mine = mine.get(..m).unwrap_or(&[]);
            let start = mine
                .iter()
                .position(|&(_, a, _)| !mine.iter().any(|&(_, _, b)| b == a))
                .unwrap_or(0);
            let (mut head, mut tail) = (NIL, NIL);
            let mut cur = mine.get(start).copied();
            let mut left = m;
            while let (Some((c, _, b)), true) = (cur, left > 0) {
                left -= 1;
                if tail == NIL {
                    head = c;
                } else {
                    self.set_after(tail, c);
                }
                tail = c;
                cur = mine.iter().copied().find(|&(_, a, _)| a == b);
            }
            if tail != NIL {
                self.set_after(tail, NIL);
            }
            self.link_run(x, before, head, tail, after);
            self.set_flags(x, flags);
        }
        k - new.len()
    }
}
