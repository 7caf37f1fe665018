//! Changing the mesh: a half-edge collapse with its list splicing, and the final compaction.

use super::Mesh;
use crate::index::Index;
use crate::tri::{next3, NIL};

impl<'a, L: Index, I: Index> Mesh<'a, L, I> {
    /// Removes triangle `t` (still intact) from `v`'s list; a vertex left without triangles
    /// loses its flags.
    pub(super) fn unlink(&mut self, v: usize, t: usize) {
        let mut prev = NIL;
        let mut c = self.first(v);
        let mut guard = self.tris.len() + 1;
        while c != NIL && guard > 0 {
            guard -= 1;
            let n = self.after_in(c, v);
            if (c >> 2) == t {
                if prev == NIL {
                    self.set_first(v, n);
                } else {
                    self.set_after(prev, n);
                }
                break;
            }
            prev = c;
            c = n;
        }
        if self.first(v) == NIL {
            self.set_flags(v, 0);
        }
    }

    /// Moves `a` onto `b` (half-edge collapse with subset placement, Lin 2007 §2): the (one or
    /// two) triangles on edge `a-b` are removed, `a`'s other triangles now use `b`. The caller
    /// has checked legality. Returns the number of triangles removed.
    ///
    /// Fan order is kept: in `a`'s fan the survivors run from the triangle after `(a, b, o1)`
    /// to the one before `(a, o2, b)`; in `b`'s fan the removed `(b, o1, a)` and `(b, a, o2)`
    /// are adjacent, and the run takes their place. `o1` and `o2` just lose one triangle.
    pub(crate) fn collapse(&mut self, a: usize, b: usize) -> usize {
        // Rotate a's list to start right after (a, b, o1), so that the survivors come out in
        // fan order whether a's fan is a disc or a half-disc.
        let first = self.first(a);
        let (mut c1, mut last) = (NIL, NIL);
        let mut c = first;
        let mut guard = self.tris.len();
        while c != NIL && guard > 0 {
            guard -= 1;
            let tri = self.tri(c >> 2);
            if tri[next3(c & 3)] == b {
                c1 = c;
            }
            last = c;
            c = self.after_in(c, a);
        }
        let mut c = first;
        if c1 != NIL && c1 != last {
            self.set_after(last, first);
            c = self.after_in(c1, a);
            self.set_after(c1, NIL);
        }
        // Walk the rotated list: survivors are re-pointed at b and chained into the run;
        // removed triangles are noted (at most two in a regular fan).
        let (mut run_head, mut run_tail) = (NIL, NIL);
        let mut dead = [NIL; 2];
        let mut n_dead = 0;
        let mut guard = self.tris.len();
        while c != NIL && guard > 0 {
            guard -= 1;
            // Before `c`'s triangle is re-pointed at b.
            let n = self.after_in(c, a);
            let t = c >> 2;
            if self.tri(t).contains(&b) {
                if let Some(d) = dead.get_mut(n_dead) {
                    *d = t;
                    n_dead += 1;
                } else {
                    // Only with a switched-off rule: a third triangle on a-b.
                    self.remove_triangle(t, a);
                }
            } else {
                self.set_corner(c, b);
                self.set_after(c, NIL);
                if run_tail == NIL {
                    run_head = c;
                } else {
                    self.set_after(run_tail, c);
                }
                run_tail = c;
            }
            c = n;
        }
        let dead = dead.get(..n_dead).unwrap_or(&[]);
        #[cfg(feature = "seams")]
        if !self.wedges.is_empty() {
            self.move_wedges(a, b, dead, run_head);
        }
        self.splice(b, dead, run_head, run_tail);
        self.set_first(a, NIL);
        self.set_flags(a, 0);
        for &t in dead {
            self.remove_triangle(t, b);
        }
        dead.len()
    }

    /// Welded seams: the corners of `a`'s survivors (the run from `head`, in fan order from the
    /// side of `(a, b, o1)`, already re-pointed at `b`) take wedges of `b`
    /// ([`crate::seam::moved_wedge`]). Never inlined: only welded runs call it.
    #[cfg(feature = "seams")]
    #[inline(never)]
    fn move_wedges(&mut self, a: usize, b: usize, dead: &[usize], head: usize) {
        // Each removed triangle's (a wedge, b wedge); the one whose a-corner is followed by b
        // (`(a, b, o1)`) first: the survivors' walk starts next to it.
        let mut sides = [(NIL, NIL); 2];
        for &t in dead {
            let (tri, w) = (self.tri(t), self.wedges.get(t).copied());
            let (Some(ka), Some(kb), Some(w)) = (
                tri.iter().position(|&x| x == a),
                tri.iter().position(|&x| x == b),
                w,
            ) else {
                continue;
            };
            let side = (w[ka].to_usize(), w[kb].to_usize());
            if tri[next3(ka)] == b {
                sides[0] = side;
            } else {
                sides[1] = side;
            }
        }
        // One removed triangle (a boundary edge): both sides are it.
        if sides[0].0 == NIL {
            sides[0] = sides[1];
        } else if sides[1].0 == NIL {
            sides[1] = sides[0];
        }
        let mut n = 0;
        let mut c = head;
        let mut guard = self.tris.len();
        while c != NIL && guard > 0 {
            guard -= 1;
            n += 1;
            c = self.after(c);
        }
        let (mut i, mut c) = (0, head);
        let mut guard = self.tris.len();
        while c != NIL && guard > 0 {
            guard -= 1;
            if let Some(x) = self.wedges.get_mut(c >> 2).and_then(|w| w.get_mut(c & 3)) {
                let w = crate::seam::moved_wedge(x.to_usize(), sides, 2 * i < n);
                if w != NIL {
                    *x = I::narrow(w);
                }
            }
            i += 1;
            c = self.after(c);
        }
    }

    /// Welded seams: live triangle `t` (positions `tri`) as the caller's wedges; a placing
    /// cost moved only the position's first vertex, so each wedge takes its position.
    #[cfg(feature = "seams")]
    fn wedge_out(&mut self, t: usize, tri: [I; 3]) -> [I; 3] {
        let Some(w) = self.wedges.get(t).copied() else {
            return tri;
        };
        if self.movable() {
            for (c, x) in tri.iter().zip(w) {
                if let Some(q) = self.input_position(c.to_usize()) {
                    self.place(x.to_usize(), q);
                }
            }
        }
        w
    }

    /// Replaces the (adjacent) corners of `b` in the `dead` triangles with the run
    /// `head..tail`. Non-adjacent windows arise when `b` is locked (its list has no order) or
    /// from a switched-off rule: then the dead corners are unlinked and the run goes in front.
    pub(super) fn splice(&mut self, b: usize, dead: &[usize], head: usize, tail: usize) {
        let (mut w_first, mut w_pred, mut w_last, mut w_last_pred, mut w_succ) =
            (NIL, NIL, NIL, NIL, NIL);
        let mut adjacent = true;
        let (mut prev, mut c) = (NIL, self.first(b));
        let mut guard = self.tris.len();
        while c != NIL && guard > 0 {
            guard -= 1;
            let n = self.after_in(c, b);
            if dead.contains(&(c >> 2)) {
                if w_first == NIL {
                    w_first = c;
                    w_pred = prev;
                } else if prev != w_last {
                    adjacent = false;
                }
                w_last = c;
                w_last_pred = prev;
                w_succ = n;
            }
            prev = c;
            c = n;
        }
        let list_last = prev;
        // What comes after the run, and where the run hangs.
        if w_first != NIL && adjacent {
            // ... pred, [dead], succ ...  ->  ... pred, run, succ ...
            self.link_run(b, w_pred, head, tail, w_succ);
        } else if dead.len() == 2 && w_first == self.first(b) && w_last == list_last {
            // The window wraps around the end of a disc's list: [d2, x.., y, d1]
            // -> [x.., y, run].
            let x = self.after(w_first);
            if w_last_pred == w_first {
                self.set_first(b, NIL);
                self.link_run(b, NIL, head, tail, NIL);
            } else {
                self.set_first(b, x);
                self.link_run(b, w_last_pred, head, tail, NIL);
            }
        } else {
            for &t in dead {
                self.unlink(b, t);
            }
            let h = self.first(b);
            self.link_run(b, NIL, head, tail, h);
        }
    }

    /// Links `pred -> head..tail -> succ` in `b`'s list (`pred` NIL: the run becomes the head;
    /// an empty run links `pred -> succ`).
    pub(super) fn link_run(
        &mut self,
        b: usize,
        pred: usize,
        head: usize,
        tail: usize,
        succ: usize,
    ) {
        let (h, t) = if head == NIL {
            (succ, NIL)
        } else {
            (head, tail)
        };
        if pred == NIL {
            self.set_first(b, h);
        } else {
            self.set_after(pred, h);
        }
        if t != NIL {
            self.set_after(t, succ);
        }
    }

    /// Takes triangle `t` (still intact) out of the lists of its vertices other than `skip`
    /// and writes it as removed.
    pub(super) fn remove_triangle(&mut self, t: usize, skip: usize) {
        for x in self.tri(t) {
            if x != skip {
                self.unlink(x, t);
            }
        }
        self.kill(t);
        self.live = self.live.saturating_sub(1);
    }

    /// Removes every triangle around `v` (pruning a whole part); returns how many. `v` and
    /// the vertices it shared them with lose their flags once they have none left.
    #[cfg(feature = "parts")]
    pub(crate) fn drop_fan(&mut self, v: usize) -> usize {
        let (mut n, mut guard) = (0, self.tris.len());
        while guard > 0 {
            guard -= 1;
            let c = self.first(v);
            if c == NIL {
                break;
            }
            self.remove_triangle(c >> 2, NIL);
            n += 1;
        }
        n
    }

    /// Twins ([`Mesh::kill_twin`]) whose front is alive: the backs [`Mesh::compact`] will write.
    pub(crate) fn live_twins(&self) -> usize {
        let mut n = 0;
        for (t, (x, l)) in self.tris.iter().zip(self.next.iter()).enumerate() {
            let front = l[0].to_usize();
            if x[0] == x[1] && x[1] != x[2] && front < t && !super::is_dead(self.tri(front)) {
                n += 1;
            }
        }
        n
    }

    /// Writes every twin ([`Mesh::kill_twin`]) whose front survived as its front turned over.
    /// With welded seams each corner takes a back's own wedge at its position: the twin's own
    /// if its input triangle had that position, else one that another back had there (kept in
    /// `spare`, one link per vertex), else the front's.
    fn revive_twins(&mut self, #[cfg(feature = "seams")] spare: &mut [L]) {
        #[cfg(feature = "seams")]
        let welded = !self.wedges.is_empty();
        #[cfg(feature = "seams")]
        if welded {
            for s in spare.iter_mut() {
                *s = L::NIL;
            }
            for t in 0..self.tris.len() {
                if let (Some(&x), Some(n), Some(w)) =
                    (self.tris.get(t), self.next.get(t), self.wedges.get(t))
                {
                    if x[0] == x[1] && x[1] != x[2] {
                        for (p, &w) in [x[0].to_usize(), x[2].to_usize(), n[1].to_usize()]
                            .iter()
                            .zip(w)
                        {
                            if let Some(s) = spare.get_mut(*p) {
                                *s = L::narrow(w.to_usize());
                            }
                        }
                    }
                }
            }
        }
        for t in 0..self.tris.len() {
            let (Some(&x), Some(n)) = (self.tris.get(t), self.next.get(t)) else {
                break;
            };
            if !(x[0] == x[1] && x[1] != x[2]) {
                continue;
            }
            let front = n[0].to_usize();
            let f = self.tri(front);
            if front >= t || super::is_dead(f) {
                self.kill(t);
                continue;
            }
            let back = [f[0], f[2], f[1]];
            #[cfg(feature = "seams")]
            if welded {
                let own = [x[0].to_usize(), x[2].to_usize(), n[1].to_usize()];
                if let (Some(&ow), Some(&fw)) = (self.wedges.get(t), self.wedges.get(front)) {
                    let mut w = [fw[0], fw[2], fw[1]];
                    for (w, &v) in w.iter_mut().zip(&back) {
                        if let Some(k) = own.iter().position(|&o| o == v) {
                            *w = ow.get(k).copied().unwrap_or(*w);
                        } else if let Some(&s) = spare.get(v) {
                            if s != L::NIL {
                                *w = I::narrow(s.to_usize());
                            }
                        }
                    }
                    if let Some(slot) = self.wedges.get_mut(t) {
                        *slot = w;
                    }
                }
            }
            if let Some(slot) = self.tris.get_mut(t) {
                *slot = [I::narrow(back[0]), I::narrow(back[1]), I::narrow(back[2])];
            }
        }
    }

    /// Moves the live triangles to the front of the buffer, in their original order, and
    /// returns how many there are. The workspace's lists are stale afterwards.
    pub(crate) fn compact(&mut self, #[cfg(feature = "seams")] spare: &mut [L]) -> usize {
        if self.twins > 0 {
            self.revive_twins(
                #[cfg(feature = "seams")]
                spare,
            );
        }
        let mut n = 0;
        for t in 0..self.tris.len() {
            let Some(&tri) = self.tris.get(t) else { break };
            if tri[0] != tri[1] {
                // Welded seams: the wedges (the caller's vertices) go out, not the positions.
                #[cfg(feature = "seams")]
                let tri = self.wedge_out(t, tri);
                if let Some(slot) = self.tris.get_mut(n) {
                    *slot = tri;
                }
                n += 1;
            }
        }
        n
    }
}
