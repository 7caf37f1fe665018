//! The progressive mesh's adjacency: per vertex, a singly linked list of its triangles sorted
//! by slot, largest first (see the module comment of [`crate::progressive`]).

use crate::index::Index;
use crate::tri::NIL;

/// Triangle lists per vertex, sorted by slot, largest first (see the module comment).
pub(crate) struct Lists<'a, I: Index> {
    pub(crate) tris: &'a mut [[I; 3]],
    pub(crate) next: &'a mut [[I; 3]],
    pub(crate) head: &'a mut [I],
}

impl<'a, I: Index> Lists<'a, I> {
    pub(crate) fn new(tris: &'a mut [[I; 3]], next: &'a mut [[I; 3]], head: &'a mut [I]) -> Self {
        Lists { tris, next, head }
    }

    pub(crate) fn tri(&self, t: usize) -> [usize; 3] {
        match self.tris.get(t) {
            Some(&[a, b, c]) => [a.to_usize(), b.to_usize(), c.to_usize()],
            None => [NIL; 3],
        }
    }

    /// The slot of `v` in triangle `t`.
    pub(crate) fn slot(&self, t: usize, v: usize) -> Option<usize> {
        self.tri(t).iter().position(|&x| x == v)
    }

    pub(crate) fn first(&self, v: usize) -> usize {
        match self.head.get(v) {
            Some(&h) if h != I::NIL => h.to_usize(),
            _ => NIL,
        }
    }

    pub(crate) fn set_first(&mut self, v: usize, t: usize) {
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

    pub(crate) fn set_after(&mut self, t: usize, v: usize, n: usize) {
        if let Some(k) = self.slot(t, v) {
            if let Some(l) = self.next.get_mut(t).and_then(|l| l.get_mut(k)) {
                *l = if n == NIL { I::NIL } else { I::narrow(n) };
            }
        }
    }

    pub(crate) fn rename(&mut self, t: usize, from: usize, to: usize) {
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
    pub(crate) fn insert(&mut self, v: usize, t: usize) {
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
    pub(crate) fn unlink(&mut self, v: usize, t: usize) {
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
    pub(crate) fn unlink_triangle(&mut self, t: usize) {
        for v in self.tri(t) {
            self.unlink(v, t);
        }
    }

    /// Moves every triangle of `t` to `s` (renaming the corner), merging the two sorted lists.
    /// Returns the mask of the moved triangles' positions in the merged list, or `None` if a
    /// moved one lands past position 63.
    pub(crate) fn merge(&mut self, t: usize, s: usize) -> Option<u64> {
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
    pub(crate) fn part(&mut self, s: usize, t: usize, moved: u64) {
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
