//! The batched schedule (meshoptimizer's `simplifier.cpp` pass structure): each pass prices
//! every vertex's cheapest candidate once, orders the vertices by that price and collapses in
//! that order, skipping any vertex whose price an earlier collapse of the pass made stale.
//!
//! Memory: no per-vertex memory of its own. The pass's order is a binary heap in the queue's
//! arrays (one vertex slot and one key per vertex, the greedy queue's `heap` and `key`; the
//! per-vertex slot array stays unused), the per-pass lock is the `DONE` flag bit (which only
//! the passes schedule uses otherwise) and a key raised at its pop is marked with the greedy
//! queue's `RAISED` bit. The simplifier carries five more words of state (pass goal, pass
//! limit, count, the triangle count of the last feature threshold, a flag).
//!
//! Staleness: the price of `x -> y` reads `x`'s fan (memoryless costs, the feature rule) or
//! only the two vertices' states and positions (stored costs without the feature rule,
//! [`Simplifier::keys_only_fall`]). A collapse `a -> b` changes the fans of `b` and of `a`'s
//! other neighbours, and moves `b` if the cost places it, which changes the fans of `b`'s
//! neighbours too; those vertices are locked for the rest of the pass. A popped vertex is
//! walked and priced again, so a price that rose (a stored cost whose `y` grew, a refused
//! cheapest candidate) sends it back into the order at its new price, as the greedy queue
//! does; the legality rules run at commit, on the mesh as it is then.
//!
//! A pass ends when the order is empty, when the price popped is above the pass's limit
//! (the price of the vertex at the position in the order that would reach the pass's goal if
//! every collapse before it were made: meshoptimizer's error goal, see [`PASS_LIMIT`]; the goal
//! is the target, or half the live triangles if that is nearer, see [`PASS_SHARE`]) once the
//! pass has made a collapse, or when a price is above [`Config::max_cost`](crate::Config::max_cost).
//! A pass without a collapse ends the run (after pruning parts, if any may go): the next pass
//! would price the same mesh the same way, unless the feature threshold was older than the
//! mesh: then one more pass follows a fresh threshold (the greedy schedule's new round).
//!
//! Work: each pass walks a live vertex at most once to price it and once per pop; a vertex no
//! collapse touched since its last pricing keeps its key without a walk (memoryless costs:
//! the same fan gives the same price), so after the first pass pricing walks roughly the
//! vertices the last pass locked. The feature threshold is taken afresh (a full sweep, then
//! a full pricing) when the mesh has halved.

use super::Simplifier;
use crate::index::Index;
use crate::operator::Operator;
use crate::policy::bound::Bound;
use crate::policy::cost::Cost;
#[cfg(feature = "batched")]
use {
    super::price::take_cheapest_of, super::walk::MAX_CANDIDATES, super::Phase, crate::math::V3,
    crate::mesh::flag, crate::policy::legality::on, crate::report::Stop,
};

/// The state of the pass under way.
#[cfg(feature = "batched")]
pub(super) struct Pass {
    /// Vertices of this pass's order collapsed or skipped as stale so far.
    pops: usize,
    /// Collapses this pass needs to reach the target (each removes two triangles).
    goal: usize,
    /// The pass's own price limit, once the order has reached `goal`.
    limit: f32,
    /// Live triangles when the feature threshold was last taken.
    mean_live: usize,
    /// The pricing under way prices every vertex (the first after a new threshold).
    price_all: bool,
}

#[cfg(feature = "batched")]
impl Pass {
    pub(super) const fn new() -> Self {
        Pass {
            pops: 0,
            goal: 0,
            limit: f32::INFINITY,
            mean_live: 0,
            price_all: true,
        }
    }
}

/// Without the `batched` feature: nothing (`Storage::start` refuses the schedule).
#[cfg(not(feature = "batched"))]
pub(super) struct Pass;

#[cfg(not(feature = "batched"))]
impl Pass {
    pub(super) const fn new() -> Self {
        Pass
    }
}

/// A pass aims at no more than `live / PASS_SHARE` collapses (about half the live triangles
/// for 4), however far the target is: meshoptimizer aims each pass at the target, but with the
/// memoryless cost a pass that aims far ends up collapsing past prices that its locked vertices
/// would have undercut (decision record: docs/speed.md, batched schedule).
#[cfg(feature = "batched")]
const PASS_SHARE: usize = 4;

#[cfg(feature = "batched")]
/// The pass's limit over the price of the candidate that would reach the pass's goal.
/// meshoptimizer takes 1.5 (`1.5f * edge_collapses[collapse_order[edge_collapse_goal]].error`);
/// with the memoryless cost 1.0 gives a lower mean error for the same instructions
/// (decision record: docs/speed.md, batched schedule).
const PASS_LIMIT: f32 = 1.0;

#[cfg(feature = "batched")]
impl<'a, L: Index, I: Index, C: Cost, B: Bound<'a, I>, O: Operator> Simplifier<'a, L, I, C, B, O> {
    /// Batched: the feature threshold was just taken: the next pricing is a full one.
    pub(super) fn threshold_taken(&mut self) {
        self.refresh_at = self.mesh.live / 2;
        self.batch.mean_live = self.mesh.live;
        self.batch.price_all = true;
    }

    /// Batched: prices the vertex under the cursor into the pass's order (its feature flag is
    /// set against the threshold on the way), or ends the sweep.
    pub(super) fn price_next(&mut self) {
        if self.v == 0 {
            self.heap.batch_clear();
            self.batch.pops = 0;
            self.batch.limit = f32::INFINITY;
            self.batch.goal =
                (self.mesh.live.saturating_sub(self.target) / 2).min(self.mesh.live / PASS_SHARE);
        }
        let nv = self.mesh.vertex_count();
        if self.v >= nv {
            self.v = 0;
            self.batch.price_all = false;
            self.phase = Phase::Batch;
            return;
        }
        let v = self.v;
        self.v += 1;
        let f = self.mesh.flags(v);
        self.mesh.set_flag(v, flag::DONE | flag::RAISED, false);
        if f & flag::USED == 0 || (on!(Locked) && f & flag::LOCKED != 0) {
            return;
        }
        if f & (flag::DONE | flag::RAISED) == 0 && self.reuses_keys() {
            // Untouched since its last pricing: the same fan, flags and neighbours' positions
            // give the same price (and the same feature flag under the same threshold).
            self.features += (f & flag::FEATURE != 0) as usize;
            let key = self.heap.batch_key(v);
            if key.is_finite() {
                self.heap.batch_push(v, key);
            }
            return;
        }
        let mut w = self.unwalked();
        let w = self.walk(v, &mut w);
        let is = self.config.features && self.is_feature_now(w);
        self.mesh.set_flag(v, flag::FEATURE, is);
        self.features += is as usize;
        if is && on!(Feature) {
            return self.heap.batch_set_key(v, f32::INFINITY);
        }
        let key = self.least(v, w);
        if key.is_finite() {
            self.heap.batch_push(v, key);
        } else {
            self.heap.batch_set_key(v, f32::INFINITY);
        }
    }

    /// Batched: whether a vertex that no collapse touched since its last pricing keeps its
    /// key: not in the first pass after a new feature threshold (whose pricing is a full one),
    /// not for a cost whose price onto a vertex changes when that vertex grows (stored
    /// quadrics: only the kept vertex is locked), and not when a candidate's price depends on
    /// whether its kept vertex is a feature (the paper's rule), which can change with that
    /// vertex's own fan.
    fn reuses_keys(&self) -> bool {
        !self.batch.price_all
            && !self.cost.stores()
            && (!self.config.features || self.rules.feature_targets)
    }

    /// Batched: one vertex from the pass's order, collapsed at its cheapest legal candidate
    /// if its price is still that of the pass's pricing.
    pub(super) fn batch(&mut self) {
        if self.mesh.live <= self.target {
            if self.twins_over() {
                return;
            }
            return self.done(Stop::Target);
        }
        let Some((v, key)) = self.heap.batch_pop() else {
            return self.end_pass();
        };
        if key > self.batch.limit && self.pass_collapses > 0 {
            return self.end_pass();
        }
        if self.mesh.has(v, flag::DONE) || !self.mesh.has(v, flag::USED) {
            // Its fan changed in this pass: priced afresh in the next.
            self.count_pop(key);
            return;
        }
        if self.prune_below(key) {
            // A part cheaper than this collapse went first (`with_parts`); `v` goes back.
            self.heap.batch_push(v, key);
            return;
        }
        if key > self.config.max_cost {
            self.over_cost = true;
            return self.end_pass();
        }
        if let Some((to, at)) = self.choose_batched(v, key) {
            self.count_pop(key);
            self.collapse_batched(v, to, at);
        }
    }

    /// Batched: the cheapest legal candidate of `v` (keyed `key`) if its price is still
    /// `key`; else `v` goes back into the order at its new price, or is dropped.
    #[allow(clippy::type_complexity)]
    #[inline(always)]
    fn choose_batched(&mut self, v: usize, key: f32) -> Option<(usize, Option<([f32; 3], V3)>)> {
        let mut w = self.unwalked();
        let w = self.walk(v, &mut w);
        let mut prices = [f32::INFINITY; MAX_CANDIDATES];
        self.prices(v, w, &mut prices);
        while let Some((c, to)) = take_cheapest_of(&mut prices, &w.nb, w.n) {
            if c > key {
                // Its cheapest candidate was refused, or its price rose (a stored cost's
                // kept vertex grew): back into the order at this price, and priced in full
                // in the next pass (the key is no longer its cheapest price).
                self.heap.batch_push(v, c);
                self.mesh.set_flag(v, flag::RAISED, true);
                return None;
            }
            match self.legal(v, w, to, c) {
                Ok((c, at)) => {
                    if c > key {
                        // Placement refused: at the kept vertex's own, higher price.
                        self.heap.batch_push(v, c);
                        self.mesh.set_flag(v, flag::RAISED, true);
                        return None;
                    }
                    if !self.over_error_limit(v, w, to, c) {
                        return Some((to, at));
                    }
                    // Not cut to reach a count: the next candidate, if any.
                }
                Err(r) => self.rejected.count(r),
            }
        }
        None
    }

    /// Batched: counts a vertex of the order that was collapsed or skipped as stale; the one
    /// that would reach the target if every one before it collapsed sets the pass's limit.
    /// Vertices whose every candidate the rules refused do not count (unlike meshoptimizer's
    /// count over its sorted edges): where the cheapest candidates are illegal, as on a messy
    /// mesh near its target, they would set the limit so low that each pass made one collapse.
    fn count_pop(&mut self, key: f32) {
        self.batch.pops += 1;
        if self.batch.pops == self.batch.goal + 1 {
            self.batch.limit = PASS_LIMIT * key;
        }
    }

    /// Batched: collapses `a -> b` and locks the vertices whose prices it made stale for
    /// the rest of the pass.
    fn collapse_batched(&mut self, a: usize, b: usize, at: Option<([f32; 3], V3)>) {
        if !self.log_collapse(a, b) {
            return;
        }
        // Fans that change: `b`'s and those of `a`'s neighbours; a price that reads only the
        // two vertices' states changes only onto `b` (see `keys_only_fall`), which is checked
        // at the pop.
        let fans = !self.keys_only_fall();
        let mesh = &self.mesh;
        if fans {
            mesh.for_each_neighbour(a, |x| mesh.set_flag(x, flag::DONE, true));
        }
        mesh.set_flag(a, flag::DONE, true);
        mesh.set_flag(b, flag::DONE, true);
        self.apply(a, b, at);
        if fans && at.is_some() {
            // `b` moved: its neighbours' fans changed too.
            let mesh = &self.mesh;
            mesh.for_each_neighbour(b, |x| mesh.set_flag(x, flag::DONE, true));
        }
        self.collapses += 1;
        self.pass_collapses += 1;
    }

    /// Batched: the end of a pass; the next one, or the end of the run.
    fn end_pass(&mut self) {
        self.heap.batch_clear();
        if self.pass_collapses == 0 {
            // Short of the target: the smallest parts may still go (`with_parts`).
            if self.prune_below(f32::INFINITY) {
                return self.start_pass();
            }
            if self.mesh.live != self.batch.mean_live && self.passes < self.config.max_passes {
                // The feature threshold is older than the mesh: one more pass with it taken
                // afresh (the greedy schedule's new round).
                self.refresh_at = self.mesh.live;
                return self.start_pass();
            }
            let stop = if self.over_cost {
                Stop::MaxCost
            } else if self.round_over_limit {
                Stop::ErrorLimit
            } else {
                Stop::NoLegalCollapse
            };
            return self.done(stop);
        }
        self.log_pass();
        if self.passes >= self.config.max_passes {
            self.phase = Phase::Done(Stop::MaxPasses);
            return;
        }
        self.start_pass();
    }

    /// Batched: starts a pass, after a fresh feature threshold if the mesh has halved since
    /// the last.
    pub(super) fn start_pass(&mut self) {
        self.v = 0;
        self.over_cost = false;
        self.round_over_limit = false;
        if self.mesh.live <= self.refresh_at {
            self.refresh_only = true;
            self.phase = Phase::Mean;
            return;
        }
        self.features = 0;
        self.passes += 1;
        self.pass_collapses = 0;
        self.phase = Phase::Price;
    }
}

#[cfg(not(feature = "batched"))]
impl<'a, L: Index, I: Index, C: Cost, B: Bound<'a, I>, O: Operator> Simplifier<'a, L, I, C, B, O> {
    /// Without the feature no run reaches a batched phase.
    #[inline(always)]
    pub(super) fn threshold_taken(&mut self) {}

    /// Without the feature no run reaches a batched phase.
    #[inline(always)]
    pub(super) fn price_next(&mut self) {}

    /// Without the feature no run reaches a batched phase.
    #[inline(always)]
    pub(super) fn batch(&mut self) {}

    /// Without the feature no run reaches a batched phase.
    #[inline(always)]
    pub(super) fn start_pass(&mut self) {}
}
