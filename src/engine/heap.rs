//! Indexed binary min-heap of vertices keyed by the cost of their cheapest collapse.
//!
//! Three arrays in the workspace: the heap of vertex numbers, each vertex's slot in it, and
//! each vertex's key. Ties are broken on the vertex number, so the order is total and the same
//! on every machine.

use crate::index::Index;
use core::cmp::Ordering;

pub(crate) struct Heap<'a, L: Index> {
    heap: &'a mut [L],
    pos: &'a mut [L],
    key: &'a mut [f32],
    len: usize,
}

impl<'a, L: Index> Heap<'a, L> {
    /// One link per vertex to lend once the run is over (the queue's order).
    #[cfg(feature = "seams")]
    pub(crate) fn spent(&mut self) -> &mut [L] {
        self.heap
    }

    pub(crate) fn new(heap: &'a mut [L], pos: &'a mut [L], key: &'a mut [f32]) -> Self {
        for p in pos.iter_mut() {
            *p = L::NIL;
        }
        Heap {
            heap,
            pos,
            key,
            len: 0,
        }
    }

    fn at(&self, slot: usize) -> usize {
        self.heap.get(slot).map_or(usize::MAX, |v| v.to_usize())
    }

    fn key_of(&self, v: usize) -> f32 {
        self.key.get(v).copied().unwrap_or(f32::INFINITY)
    }

    fn slot_of(&self, v: usize) -> Option<usize> {
        match self.pos.get(v) {
            Some(&p) if p != L::NIL => Some(p.to_usize()),
            _ => None,
        }
    }

    /// `(key, vertex)` order; keys are never NaN (costs are sanitised by the engine) but
    /// `total_cmp` keeps the order total regardless.
    fn less(&self, u: usize, w: usize) -> bool {
        match self.key_of(u).total_cmp(&self.key_of(w)) {
            Ordering::Less => true,
            Ordering::Greater => false,
            Ordering::Equal => u < w,
        }
    }

    /// Writes `v` at `slot` of the order, and with `SLOTS` its slot (the batched order keeps
    /// none).
    fn place_with<const SLOTS: bool>(&mut self, slot: usize, v: usize) {
        if let Some(h) = self.heap.get_mut(slot) {
            *h = L::narrow(v);
        }
        if SLOTS {
            if let Some(p) = self.pos.get_mut(v) {
                *p = L::narrow(slot);
            }
        }
    }

    fn place(&mut self, slot: usize, v: usize) {
        self.place_with::<true>(slot, v);
    }

    /// Moves `v` up from `slot` to its place in the order.
    fn sift_up<const SLOTS: bool>(&mut self, mut slot: usize, v: usize) {
        while slot > 0 {
            let parent = (slot - 1) / 2;
            let u = self.at(parent);
            if !self.less(v, u) {
                break;
            }
            self.place_with::<SLOTS>(slot, u);
            slot = parent;
        }
        self.place_with::<SLOTS>(slot, v);
    }

    /// Moves `v` down from `slot` to its place in the order.
    fn sift_down<const SLOTS: bool>(&mut self, mut slot: usize, v: usize) {
        loop {
            let l = 2 * slot + 1;
            if l >= self.len {
                break;
            }
            let r = l + 1;
            let mut child = l;
            if r < self.len && self.less(self.at(r), self.at(l)) {
                child = r;
            }
            let u = self.at(child);
            if !self.less(u, v) {
                break;
            }
            self.place_with::<SLOTS>(slot, u);
            slot = child;
        }
        self.place_with::<SLOTS>(slot, v);
    }

    fn up(&mut self, slot: usize) {
        let v = self.at(slot);
        self.sift_up::<true>(slot, v);
    }

    fn down(&mut self, slot: usize) {
        let v = self.at(slot);
        self.sift_down::<true>(slot, v);
    }

    /// Inserts `v` with `key`, or moves it if already queued.
    pub(crate) fn set(&mut self, v: usize, key: f32) {
        let old = self.key_of(v);
        if let Some(k) = self.key.get_mut(v) {
            *k = key;
        } else {
            return;
        }
        match self.slot_of(v) {
            Some(slot) => {
                if key.total_cmp(&old) == Ordering::Less {
                    self.up(slot)
                } else {
                    self.down(slot)
                }
            }
            None => {
                if self.len >= self.heap.len() {
                    return;
                }
                self.len += 1;
                self.place(self.len - 1, v);
                self.up(self.len - 1);
            }
        }
    }

    /// Removes `v` if queued.
    pub(crate) fn remove(&mut self, v: usize) {
        let Some(slot) = self.slot_of(v) else { return };
        if let Some(p) = self.pos.get_mut(v) {
            *p = L::NIL;
        }
        self.len = self.len.saturating_sub(1);
        if slot == self.len {
            return;
        }
        let last = self.at(self.len);
        self.place(slot, last);
        self.down(slot);
        let moved = self.slot_of(last).unwrap_or(0);
        self.up(moved);
    }

    /// `v`'s key if it is queued.
    pub(crate) fn queued(&self, v: usize) -> Option<f32> {
        self.slot_of(v).map(|_| self.key_of(v))
    }

    /// The key array while nothing is queued (scratch before the first round: pruning sorts
    /// its parts' sizes there); `None` once a vertex is queued.
    #[cfg(feature = "parts")]
    pub(crate) fn idle_keys(&mut self) -> Option<&mut [f32]> {
        if self.len == 0 {
            Some(&mut *self.key)
        } else {
            None
        }
    }

    #[cfg(feature = "batched")]
    /// Batched: empties the queue for a pass's order. The batched schedule never uses the
    /// per-vertex slots (they stay unset), so [`Heap::remove`] and [`Heap::queued`] see no
    /// vertex queued.
    pub(crate) fn batch_clear(&mut self) {
        self.len = 0;
    }

    #[cfg(feature = "batched")]
    /// Batched: puts `v` in the pass's order with `key` (a binary heap on the same arrays,
    /// without the slots: `v` must not be in it already).
    pub(crate) fn batch_push(&mut self, v: usize, key: f32) {
        if self.len >= self.heap.len() {
            return;
        }
        if let Some(k) = self.key.get_mut(v) {
            *k = key;
        } else {
            return;
        }
        let slot = self.len;
        self.len += 1;
        self.sift_up::<false>(slot, v);
    }

    #[cfg(feature = "batched")]
    /// Batched: `v`'s key, whether or not it is in the order.
    pub(crate) fn batch_key(&self, v: usize) -> f32 {
        self.key_of(v)
    }

    #[cfg(feature = "batched")]
    /// Batched: sets `v`'s key without putting it in the order.
    pub(crate) fn batch_set_key(&mut self, v: usize, key: f32) {
        if let Some(k) = self.key.get_mut(v) {
            *k = key;
        }
    }

    #[cfg(feature = "batched")]
    /// Batched: takes the cheapest vertex of the pass's order and its key.
    pub(crate) fn batch_pop(&mut self) -> Option<(usize, f32)> {
        if self.len == 0 {
            return None;
        }
        let top = self.at(0);
        self.len -= 1;
        if self.len > 0 {
            let v = self.at(self.len);
            self.sift_down::<false>(0, v);
        }
        Some((top, self.key_of(top)))
    }

    /// The cheapest vertex and its key, without removing it.
    pub(crate) fn peek(&self) -> Option<(usize, f32)> {
        if self.len == 0 {
            None
        } else {
            let v = self.at(0);
            Some((v, self.key_of(v)))
        }
    }
}
