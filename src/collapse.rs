//! The collapse engine: schedule, legality, apply.
//!
//! One [`Simplifier`] drives a mesh from start to finish as a small state machine, so that it
//! can stop after any number of operations and resume later (watchdogs, frame deadlines) and
//! still give exactly the bytes of a one-shot run: one-shot *is* stepping with an unlimited
//! budget.
//!
//! ```text
//! Mean ─> Flags ─┬─ Greedy: Keys ─> Queue (pop cheapest, re-check, collapse, update around it)
//!                └─ Passes: Pairs (sweep vertices in index order, pair, collapse) ─> next pass: Mean
//! ```
//!
//! Termination: every collapse removes a vertex, so there are fewer collapses than vertices.
//! Between two collapses the queue only re-keys a popped vertex to its exact current cost (so
//! its next pop collapses it) or drops it, so at most `2·V` pops separate two collapses; each
//! pass of `Passes` visits each vertex once, and a pass without a collapse ends the run. Every
//! operation below is bounded by the valences involved.

use crate::cost::Cost;
use crate::feature::{self, Mean};
use crate::heap::Heap;
use crate::index::Index;
use crate::legality::{self, on, Rules};
use crate::mesh::{flag, Mesh, NIL};
use crate::report::{Rejections, Report, Stop};
use crate::{Config, Schedule};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Phase {
    /// Summing D for the feature threshold.
    Mean,
    /// Setting feature flags.
    Flags,
    /// Greedy: computing every vertex's cheapest collapse.
    Keys,
    /// Greedy: collapsing from the queue.
    Queue,
    /// Passes: pairing vertices in index order.
    Pairs,
    /// Finished.
    Done(Stop),
}

/// A simplification in progress; see [`Workspace::start`](crate::Workspace::start).
///
/// Between steps the mesh is always valid: [`Simplifier::triangles`] yields its live
/// triangles. The caller's buffer itself holds removed triangles as `[i, i, i]` (degenerate,
/// so a renderer draws nothing for them) until [`Simplifier::finish`] compacts it.
pub struct Simplifier<'a, L: Index, I: Index, C: Cost> {
    mesh: Mesh<'a, L, I>,
    heap: Heap<'a, L>,
    config: Config,
    rules: Rules,
    cost: C,
    target: usize,
    phase: Phase,
    /// Vertex cursor of the current sweep.
    v: usize,
    mean: Mean,
    threshold: f32,
    features: usize,
    locked: usize,
    used_in: usize,
    collapses: usize,
    passes: u32,
    pass_collapses: usize,
    /// A legal collapse was skipped because it cost more than `max_cost`.
    over_cost: bool,
    pass_triangles: heapless::Vec<u32, { crate::PASS_LOG }>,
    rejected: Rejections,
}

impl<'a, L: Index, I: Index, C: Cost> Simplifier<'a, L, I, C> {
    pub(crate) fn new(mesh: Mesh<'a, L, I>, heap: Heap<'a, L>, config: Config, cost: C) -> Self {
        let by_ratio = (config.target_ratio as f64 * mesh.valid_in as f64) as usize;
        let target = if config.target_triangles > by_ratio {
            config.target_triangles
        } else {
            by_ratio
        };
        let (mut locked, mut used_in) = (0, 0);
        for v in 0..mesh.vertex_count() {
            locked += mesh.has(v, flag::LOCKED) as usize;
            used_in += mesh.has(v, flag::USED) as usize;
        }
        Simplifier {
            mesh,
            heap,
            rules: Rules::new(&config),
            config,
            cost,
            target,
            phase: Phase::Mean,
            v: 0,
            mean: Mean::default(),
            threshold: f32::INFINITY,
            features: 0,
            locked,
            used_in,
            collapses: 0,
            passes: 0,
            pass_collapses: 0,
            over_cost: false,
            pass_triangles: heapless::Vec::new(),
            rejected: Rejections::default(),
        }
    }

    /// Runs at most `budget` operations and returns `true` once the run is finished.
    ///
    /// An operation is one vertex visited by a sweep, one queue pop, or one collapse with the
    /// updates around it; each is bounded by the valences involved. A budget of 0 does nothing.
    pub fn step(&mut self, budget: u32) -> bool {
        let mut ops = 0;
        while ops < budget {
            if let Phase::Done(_) = self.phase {
                return true;
            }
            self.operate();
            ops += 1;
        }
        matches!(self.phase, Phase::Done(_))
    }

    /// Live triangles now.
    pub fn live_triangles(&self) -> usize {
        self.mesh.live
    }

    /// The live triangles now, in buffer order (the order [`Simplifier::finish`] keeps).
    pub fn triangles(&self) -> impl Iterator<Item = [I; 3]> + '_ {
        self.mesh.tris.iter().copied().filter(|t| t[0] != t[1])
    }

    /// The caller's buffer as it is now: live triangles in their original slots, removed ones
    /// written as `[i, i, i]`.
    pub fn buffer(&self) -> &[[I; 3]] {
        self.mesh.tris
    }

    /// Whether vertex `v` is currently a feature vertex (never removed while it is one).
    pub fn is_feature(&self, v: usize) -> bool {
        self.mesh.has(v, flag::FEATURE)
    }

    /// Whether vertex `v` currently has triangles.
    pub fn is_used(&self, v: usize) -> bool {
        self.mesh.first(v) != NIL
    }

    /// The report so far (`stop` is [`Stop::Running`] until the run is finished).
    pub fn report(&self) -> Report {
        let stop = match self.phase {
            Phase::Done(s) => s,
            _ => Stop::Running,
        };
        let mut used = 0;
        for v in 0..self.mesh.vertex_count() {
            used += (self.mesh.first(v) != NIL) as usize;
        }
        Report {
            triangles_in: self.mesh.triangle_count(),
            degenerate_dropped: self.mesh.degenerate,
            duplicates_dropped: self.mesh.duplicates,
            triangles_out: self.mesh.live,
            target_triangles: self.target,
            target_reached: self.mesh.live <= self.target,
            stop,
            collapses: self.collapses,
            vertices_removed: self.used_in.saturating_sub(used),
            locked_vertices: self.locked,
            feature_vertices: self.features,
            passes: self.passes,
            pass_triangles: self.pass_triangles.clone(),
            rejected: self.rejected,
        }
    }

    /// Compacts the result into the front of the caller's buffer and returns the report.
    /// Finishing early (before `step` returned `true`) keeps the valid mesh reached so far.
    pub fn finish(mut self) -> Report {
        let report = self.report();
        let n = self.mesh.compact();
        #[cfg(feature = "defmt")]
        defmt::debug!(
            "tinydecimate: {} -> {} triangles, {} collapses",
            report.triangles_in,
            n,
            report.collapses
        );
        Report {
            triangles_out: n,
            ..report
        }
    }

    fn done(&mut self, stop: Stop) {
        if self.pass_collapses > 0 || self.pass_triangles.is_empty() {
            self.log_pass();
        }
        self.phase = Phase::Done(stop);
    }

    fn log_pass(&mut self) {
        // Full log: later passes are still counted in `passes`.
        let _ = self.pass_triangles.push(self.mesh.live as u32);
    }

    /// One operation of the state machine.
    fn operate(&mut self) {
        let nv = self.mesh.vertex_count();
        match self.phase {
            Phase::Done(_) => {}
            Phase::Mean => {
                if self.v == 0 {
                    if self.mesh.live <= self.target {
                        return self.done(Stop::Target);
                    }
                    self.mean = Mean::default();
                }
                if self.v < nv {
                    if self.config.features {
                        let d = feature::variation(&self.mesh, self.v, self.config.feature_mode);
                        self.mean.add(d);
                    }
                    self.v += 1;
                } else {
                    self.threshold = self.mean.threshold(self.config.lambda);
                    self.phase = Phase::Flags;
                    self.v = 0;
                    self.features = 0;
                }
            }
            Phase::Flags => {
                if self.v < nv {
                    let v = self.v;
                    let is = self.classify(v);
                    self.mesh.set_flag(v, flag::FEATURE, is);
                    self.mesh.set_flag(v, flag::DONE, false);
                    self.features += is as usize;
                    self.v += 1;
                } else {
                    self.v = 0;
                    self.passes += 1;
                    self.pass_collapses = 0;
                    self.phase = match self.config.schedule {
                        Schedule::Greedy => Phase::Keys,
                        Schedule::Passes => Phase::Pairs,
                    };
                }
            }
            Phase::Keys => {
                if self.v < nv {
                    self.rekey(self.v);
                    self.v += 1;
                } else {
                    self.phase = Phase::Queue;
                }
            }
            Phase::Queue => self.pop(),
            Phase::Pairs => self.pair(),
        }
    }

    fn classify(&self, v: usize) -> bool {
        self.config.features
            && feature::variation(&self.mesh, v, self.config.feature_mode)
                .is_some_and(|d| d > self.threshold)
    }

    /// The cheapest legal collapse of `from` onto one of its neighbours: `(cost, to)`.
    /// Ties go to the lower vertex number.
    ///
    /// Every neighbour is priced first (cheap rules and cost); the connectivity rules then run
    /// on the candidates in cost order only until one passes. Up to `CANDIDATES` candidates are
    /// kept on the stack; any beyond (valence > 32) are checked in full on the spot. Either way
    /// the answer is the minimum over the legal candidates.
    fn best(&mut self, from: usize) -> Option<(f32, usize)> {
        const CANDIDATES: usize = 32;
        let f = self.mesh.flags(from);
        if f & flag::USED == 0 || f & skip() != 0 {
            return None;
        }
        let mut cand = [(f32::INFINITY, NIL); CANDIDATES];
        let mut n = 0;
        let mut overflow: Option<(f32, usize)> = None;
        let (mesh, rules, cost, rejected) =
            (&self.mesh, &self.rules, &self.cost, &mut self.rejected);
        mesh.for_each_neighbour(from, |to| {
            match legality::price(mesh, rules, cost, from, to) {
                Ok(c) => {
                    if let Some(slot) = cand.get_mut(n) {
                        *slot = (c, to);
                        n += 1;
                    } else {
                        match legality::connectivity(mesh, from, to) {
                            Ok(()) => {
                                if overflow.is_none_or(|o| less((c, to), o)) {
                                    overflow = Some((c, to));
                                }
                            }
                            Err(r) => rejected.count(r),
                        }
                    }
                }
                Err(r) => rejected.count(r),
            }
        });
        let cand = cand.get_mut(..n).unwrap_or(&mut []);
        loop {
            let mut min: Option<(usize, (f32, usize))> = None;
            for (i, &c) in cand.iter().enumerate() {
                if c.1 != NIL && min.is_none_or(|(_, m)| less(c, m)) {
                    min = Some((i, c));
                }
            }
            let Some((i, c)) = min else {
                return overflow;
            };
            if overflow.is_some_and(|o| less(o, c)) {
                return overflow;
            }
            match legality::connectivity(mesh, from, c.1) {
                Ok(()) => return Some(c),
                Err(r) => {
                    rejected.count(r);
                    if let Some(slot) = cand.get_mut(i) {
                        slot.1 = NIL;
                    }
                }
            }
        }
    }

    /// Greedy: recompute `v`'s key, a lower bound of its cheapest legal collapse: the
    /// cheapest candidate that passes the cheap rules. The connectivity rules wait until the
    /// vertex reaches the top of the queue (`pop` re-checks everything and re-queues it at its
    /// true cost if the bound was not legal), so they run about once per collapse instead of
    /// once per re-keyed vertex. The order of collapses is the same: a popped vertex whose
    /// true cost equals its bound is cheaper than every other vertex's bound.
    fn rekey(&mut self, v: usize) {
        let f = self.mesh.flags(v);
        if f & flag::USED == 0 || f & skip() != 0 {
            return self.heap.remove(v);
        }
        let mut key: Option<f32> = None;
        let (mesh, rules, cost, rejected) =
            (&self.mesh, &self.rules, &self.cost, &mut self.rejected);
        mesh.for_each_neighbour(v, |to| match legality::price(mesh, rules, cost, v, to) {
            Ok(c) => {
                if key.is_none_or(|k| c < k) {
                    key = Some(c);
                }
            }
            Err(r) => rejected.count(r),
        });
        match key {
            Some(c) => self.heap.set(v, c),
            None => self.heap.remove(v),
        }
    }

    /// Greedy: one pop of the queue.
    fn pop(&mut self) {
        if self.mesh.live <= self.target {
            return self.done(Stop::Target);
        }
        let Some((v, key)) = self.heap.peek() else {
            // Flags far from recent collapses are stale: refresh everything once more (a new
            // round) and stop only when a round finds nothing to collapse.
            if self.pass_collapses == 0 || self.passes >= self.config.max_passes {
                return self.done(Stop::NoLegalCollapse);
            }
            self.log_pass();
            self.phase = Phase::Mean;
            self.v = 0;
            return;
        };
        if key > self.config.max_cost {
            return self.done(Stop::MaxCost);
        }
        match self.best(v) {
            None => self.heap.remove(v),
            // Its neighbourhood changed since it was keyed: queue it at its true cost.
            Some((c, _)) if c > key => self.heap.set(v, c),
            Some((_, to)) => {
                self.heap.remove(v);
                self.collapse_greedy(v, to);
                self.pass_collapses += 1;
            }
        }
    }

    /// Greedy: collapse `a -> b`, then refresh feature flags (seed 004 eq. 5 with a running
    /// mean) and queue keys where the surface changed.
    ///
    /// Only the fans of `a`'s neighbours change (`b` is one of them): they are marked before
    /// the collapse, their old D taken out of the mean and their new D put back, and they are
    /// re-keyed. All of `b`'s neighbours are re-classified against the new mean (it rises as
    /// the mesh coarsens, and stale flags would pin vertices that are no longer features);
    /// an unmarked one is re-keyed only if its flag changed.
    fn collapse_greedy(&mut self, a: usize, b: usize) {
        let mode = self.config.feature_mode;
        let features = self.config.features;
        self.mesh.mark_fan(a, true);
        if features {
            let mean = &mut self.mean;
            let mesh = &self.mesh;
            mean.sub(feature::variation(mesh, a, mode));
            mesh.for_each_neighbour(a, |x| mean.sub(feature::variation(mesh, x, mode)));
        }
        self.mesh.collapse(a, b);
        self.collapses += 1;
        if features {
            let mean = &mut self.mean;
            let mesh = &self.mesh;
            mean.add(feature::variation(mesh, b, mode));
            mesh.for_each_neighbour(b, |x| {
                if mesh.has(x, flag::MARK) {
                    mean.add(feature::variation(mesh, x, mode))
                }
            });
            self.threshold = self.mean.threshold(self.config.lambda);
        }
        // b and the marked neighbours: new flag, new key, mark cleared. (a lost its flags in
        // the collapse, and so did any vertex left without triangles.)
        self.refresh(b);
        self.for_neighbours(b, |s, x| s.refresh(x));
    }

    /// Greedy: re-classify `v`, and re-key it if its fan changed (marked) or its flag did;
    /// clear its mark.
    fn refresh(&mut self, v: usize) {
        let mut changed = self.mesh.has(v, flag::MARK);
        self.mesh.set_flag(v, flag::MARK, false);
        if self.config.features {
            let is = self.classify(v);
            changed |= is != self.mesh.has(v, flag::FEATURE);
            self.mesh.set_flag(v, flag::FEATURE, is);
        }
        if changed {
            self.rekey(v);
        }
    }

    /// Calls `f(self, x)` once for each neighbour `x` of `v`; `f` may change flags and keys,
    /// never adjacency, so the walk can hold a corner number across the call.
    fn for_neighbours(&mut self, v: usize, mut f: impl FnMut(&mut Self, usize)) {
        let mut c = self.mesh.first(v);
        while c != NIL {
            let tri = self.mesh.tri(c / 3);
            let k = c % 3;
            for x in [tri[(k + 1) % 3], tri[(k + 2) % 3]] {
                if !self.mesh.seen_before(v, c, x) {
                    f(self, x);
                }
            }
            c = self.mesh.after(c);
        }
    }

    /// Passes: try to pair the vertex under the cursor (seed 004 Algorithm 3), or end the pass.
    fn pair(&mut self) {
        if self.mesh.live <= self.target {
            return self.done(Stop::Target);
        }
        let nv = self.mesh.vertex_count();
        if self.v >= nv {
            // End of pass (Algorithm 4's outer loop).
            #[cfg(feature = "defmt")]
            defmt::debug!(
                "tinydecimate: pass {} -> {} triangles",
                self.passes,
                self.mesh.live
            );
            if self.pass_collapses == 0 {
                let stop = if self.over_cost {
                    Stop::MaxCost
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
            self.phase = Phase::Mean;
            self.v = 0;
            self.over_cost = false;
            return;
        }
        let v = self.v;
        self.v += 1;
        if !self.mesh.has(v, flag::USED) || self.mesh.has(v, flag::DONE | skip()) {
            return;
        }
        // Cheapest legal collapse between v and an unpaired neighbour, in either direction:
        // Algorithm 1 moves the endpoint whose W is smaller.
        let mut best: Option<(f32, usize, usize)> = None;
        let (mesh, rules, cost, rejected) =
            (&self.mesh, &self.rules, &self.cost, &mut self.rejected);
        mesh.for_each_neighbour(v, |y| {
            if mesh.has(y, flag::DONE) {
                return;
            }
            for (from, to) in [(v, y), (y, v)] {
                match legality::evaluate(mesh, rules, cost, from, to) {
                    Ok(c) => {
                        let better = best.is_none_or(|(bc, bf, bt)| {
                            c < bc || (c == bc && (from, to) < (bf, bt))
                        });
                        if better {
                            best = Some((c, from, to));
                        }
                    }
                    Err(r) => rejected.count(r),
                }
            }
        });
        if let Some((c, from, to)) = best {
            if c > self.config.max_cost {
                self.over_cost = true;
                return;
            }
            self.mesh.collapse(from, to);
            self.mesh.set_flag(to, flag::DONE, true);
            self.collapses += 1;
            self.pass_collapses += 1;
        }
    }
}

/// Flags that keep a vertex from moving (with the legality switches of `legality::on`).
const fn skip() -> u8 {
    (if on::LOCKED { flag::LOCKED } else { 0 }) | (if on::FEATURE { flag::FEATURE } else { 0 })
}

/// `(cost, vertex)` order: cheaper first, then the lower vertex number.
#[inline]
fn less(a: (f32, usize), b: (f32, usize)) -> bool {
    a.0 < b.0 || (a.0 == b.0 && a.1 < b.1)
}
