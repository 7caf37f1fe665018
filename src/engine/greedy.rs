//! The greedy schedule: a queue keyed by each vertex's cheapest candidate, popped in cost
//! order, re-keying the vertices whose fans a collapse changed.

use super::price::take_cheapest_of;
use super::walk::{FanSummary, MAX_CANDIDATES};
use super::{Phase, Simplifier};
use crate::index::Index;
use crate::math::V3;
use crate::mesh::{flag, NIL};
use crate::operator::{Kind, Operator};
use crate::policy::bound::Bound;
use crate::policy::cost::Cost;
use crate::policy::feature::Variation;
use crate::policy::legality::on;
use crate::report::Stop;

impl<'a, L: Index, I: Index, C: Cost, B: Bound<'a, I>, O: Operator> Simplifier<'a, L, I, C, B, O> {
    /// Greedy: re-classify `v` against the round's threshold and re-key it: the cheapest
    /// price among its candidates (a lower bound of its cheapest legal collapse).
    pub(super) fn rekey(&mut self, v: usize) {
        match O::KIND {
            Kind::Triangle => return self.rekey_triangles(v),
            Kind::Removal => return self.rekey_removal(v),
            Kind::Edge => {}
        }
        let f = self.mesh.flags(v);
        if self.keys_only_fall() {
            // Priced in full below: the key is a lower bound again.
            self.mesh.set_flag(v, flag::RAISED, false);
        }
        if f & flag::USED == 0 || (on!(Locked) && f & flag::LOCKED != 0) {
            return self.heap.remove(v);
        }
        let mut w = self.unwalked();
        let w = self.walk(v, &mut w);
        let is = self.config.features && self.is_feature_now(w);
        self.mesh.set_flag(v, flag::FEATURE, is);
        if is && on!(Feature) {
            return self.heap.remove(v);
        }
        let key = self.least(v, w);
        if key.is_finite() {
            self.heap.set(v, key)
        } else {
            self.heap.remove(v)
        }
    }

    /// Greedy, both operators: the vertex on top of the queue and its key; `None` when this
    /// pop instead ended the run, started a new round or a refresh of the feature threshold.
    pub(super) fn top(&mut self) -> Option<(usize, f32)> {
        if self.mesh.live <= self.target {
            if self.twins_over() {
                return None;
            }
            self.done(Stop::Target);
            return None;
        }
        let Some((v, key)) = self.heap.peek() else {
            // Rules that look past a vertex's own fan may have changed far from recent
            // collapses: a new round re-keys everything, and only a round without a collapse
            // ends the run.
            let over = self.passes >= self.config.max_passes;
            if self.pass_collapses == 0 && !over && self.operator.relax() {
                // A removal operator with a looser criterion gets another round.
                self.new_round();
            } else if self.pass_collapses == 0 || over {
                // Short of the target: the smallest parts may still go (`with_parts`).
                if !self.prune_below(f32::INFINITY) {
                    self.done(if self.round_over_limit {
                        Stop::ErrorLimit
                    } else {
                        Stop::NoLegalCollapse
                    });
                }
            } else {
                self.new_round();
            }
            return None;
        };
        if self.mesh.live <= self.refresh_at {
            // The mesh has halved since the threshold was taken: take it afresh (one sweep;
            // the keys stand, and vertices meet the new threshold as they are re-keyed).
            self.refresh_only = true;
            self.phase = Phase::Mean;
            self.v = 0;
            return None;
        }
        if self.prune_below(key) {
            // A part cheaper than this collapse went first (`with_parts`).
            return None;
        }
        if key > self.config.max_cost {
            self.done(Stop::MaxCost);
            return None;
        }
        Some((v, key))
    }

    /// Greedy: one pop of the queue.
    pub(super) fn pop(&mut self) {
        match O::KIND {
            Kind::Triangle => return self.pop_triangles(),
            Kind::Removal => return self.pop_removal(),
            Kind::Edge => {}
        }
        if let Some((v, to, at)) = self.choose() {
            self.collapse_greedy(v, to, at);
        }
    }

    /// Greedy: the collapse the top of the queue makes, if any (a vertex whose cheapest
    /// candidate is refused or dearer than its key goes back in at its true price, or out).
    #[allow(clippy::type_complexity)]
    #[inline(always)]
    fn choose(&mut self) -> Option<(usize, usize, Option<([f32; 3], V3)>)> {
        let (v, key) = self.top()?;
        let mut w = self.unwalked();
        let w = self.walk(v, &mut w);
        let mut prices = [f32::INFINITY; MAX_CANDIDATES];
        self.prices(v, w, &mut prices);
        let mut refused = false;
        while let Some((c, to)) = take_cheapest_of(&mut prices, &w.nb, w.n) {
            if c > key && self.keys_only_fall() {
                // A stale key (see `keys_only_fall`): back in at this price before the rules
                // are spent on it; above a refused candidate, no longer a lower bound.
                self.heap.set(v, c);
                self.mesh.set_flag(v, flag::RAISED, refused);
                return None;
            }
            refused = true;
            match self.legal(v, w, to, c) {
                Ok((c, at)) => {
                    if c > key {
                        // Its cheapest candidate was illegal: back in at its true price.
                        self.heap.set(v, c);
                        if self.keys_only_fall() {
                            // Past a refused candidate or placement.
                            self.mesh.set_flag(v, flag::RAISED, true);
                        }
                        return None;
                    }
                    if self.over_error_limit(v, w, to, c) {
                        // Not cut to reach a count: the next candidate, if any.
                        continue;
                    }
                    self.heap.remove(v);
                    return Some((v, to, at));
                }
                Err(r) => self.rejected.count(r),
            }
        }
        self.heap.remove(v);
        None
    }

    /// Whether `from -> to`, priced `c`, is over [`Config::error_limit`](crate::Config::error_limit)
    /// (then counted); else its error is taken into the largest made. Nothing without a limit.
    pub(super) fn over_error_limit(
        &mut self,
        from: usize,
        w: &FanSummary<C::Fan>,
        to: usize,
        c: f32,
    ) -> bool {
        if !self.limit2.is_finite() {
            return false;
        }
        let e2 = match self.make_move(from, w, to, true) {
            Some(m) => self.cost.error2(&w.fan, &m, c),
            None => 0.0,
        };
        if e2 > self.limit2 {
            self.over_limit = self.over_limit.saturating_add(1);
            self.round_over_limit = true;
            return true;
        }
        if e2 > self.reached2 {
            self.reached2 = e2;
        }
        false
    }

    /// With twins: whether the fronts' share of the target left the whole output (fronts and
    /// the backs whose fronts live) above it; then the share drops by the excess and the run
    /// goes on. One sweep of the buffer, only when the share is met.
    pub(super) fn twins_over(&mut self) -> bool {
        if self.mesh.twins == 0 {
            return false;
        }
        let out = self.mesh.live + self.mesh.live_twins();
        if out <= self.target_out {
            return false;
        }
        self.target = self.mesh.live.saturating_sub(out - self.target_out);
        true
    }

    pub(super) fn new_round(&mut self) {
        self.round_over_limit = false;
        self.log_pass();
        self.phase = Phase::Mean;
        self.v = 0;
    }

    /// Greedy: collapse `a -> b`, then re-key the vertices whose fan changed: `b` and `a`'s
    /// other neighbours (marked before the collapse). Nothing else changes: the other
    /// neighbours of `b` keep their fans, so their prices stand.
    ///
    /// A placing cost may have moved `b` and changes how its neighbours price onto it, so
    /// then all of `b`'s neighbours are re-keyed (see below why stored quadrics with `b` in
    /// place need not).
    pub(super) fn collapse_greedy(&mut self, a: usize, b: usize, at: Option<([f32; 3], V3)>) {
        if !self.log_collapse(a, b) {
            return;
        }
        let mesh = &self.mesh;
        mesh.for_each_neighbour(a, |x| mesh.mark(x, true));
        // A stored cost's quadric at `b` grew by `a`'s (positive semi-definite), so with `b`
        // where it was, every other neighbour's price onto `b` (`Q_x(p_b) + Q_b(p_b)`) only
        // rose: their keys stay lower bounds, checked exactly when they reach the top, and
        // re-keying them now is wasted (docs/speed.md). A placing cost
        // (optimal placement) prices onto `b` through a minimiser that a larger `Q_b` can
        // move inside the edge's reach, so there every neighbour is re-keyed (with
        // `keys_only_fall`, by its one price onto `b`).
        if self.movable() {
            mesh.for_each_neighbour(b, |x| mesh.mark(x, true));
        }
        self.apply(a, b, at);
        self.collapses += 1;
        self.pass_collapses += 1;
        self.mesh.mark(b, false);
        self.rekey(b);
        // Both neighbours of every corner: a locked b's list has no order.
        let mut c = self.mesh.first(b);
        while c != NIL {
            let (x, y) = crate::tri::others(self.mesh.tri(c >> 2), c & 3);
            self.refresh(x, b);
            self.refresh(y, b);
            c = self.mesh.after_in(c, b);
        }
    }

    /// Re-keys `x` (a former neighbour of the removed vertex, now one of `b`'s) if it is
    /// marked, and clears the mark.
    pub(super) fn refresh(&mut self, x: usize, b: usize) {
        if self.mesh.has(x, flag::MARK) {
            self.mesh.mark(x, false);
            if self.keys_only_fall() {
                self.rekey_onto(x, b);
            } else {
                self.rekey(x);
            }
        }
    }

    /// Whether a collapse `a -> b` changes a neighbour `x`'s prices only in `x -> b`: a
    /// stored cost and no feature rule. Then the price of `x -> y` for `y ≠ b` depends on
    /// `Q_x`, `Q_y`, `p_x` and `p_y` alone, none of which changed, and `x`'s flags and
    /// boundary ends stay (the boundary is kept), so the least of the old key and the new
    /// price onto `b` is a lower bound of `x`'s cheapest collapse, found exactly when it
    /// reaches the top (the old key may have been the price onto `a`, now gone, or onto `b`
    /// before it grew: too low is allowed, too high is not). Not for a cost whose price reads
    /// the fan ([`Cost::needs_fan`]): `x`'s fan changed.
    pub(super) fn keys_only_fall(&self) -> bool {
        self.cost.stores() && !self.cost.needs_fan() && !self.config.features
    }

    /// [`Self::rekey`] for [`Self::keys_only_fall`]: one price instead of `x`'s whole fan. A
    /// vertex out of the queue (every candidate refused when it last reached the top) is
    /// re-keyed in full: its fan changed, so a refused candidate may be allowed now; so is
    /// one whose key was raised past a refused candidate ([`flag::RAISED`]). Never
    /// inlined: its frame stays out of the collapse path's (the micro:bit's stack).
    #[inline(never)]
    pub(super) fn rekey_onto(&mut self, x: usize, b: usize) {
        let Some(key) = self.heap.queued(x) else {
            return self.rekey(x);
        };
        if self.mesh.has(x, flag::RAISED) {
            // A refused cheaper candidate may be allowed in the changed fan: price them all.
            return self.rekey(x);
        }
        // What a price reads of the fan: the position and, on the boundary, the ends.
        let w = FanSummary {
            fan: self.cost.empty(),
            variation: Variation::default(),
            ends: if self.mesh.has(x, flag::BOUNDARY) {
                self.mesh.boundary_ends(x)
            } else {
                (NIL, NIL)
            },
            p: self.mesh.p(x),
            area2: 0.0,
            nb: [0; MAX_CANDIDATES],
            n: 0,
        };
        if let Some(p) = self.price(x, &w, b) {
            if p < key {
                self.heap.set(x, p);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::policy::cost::{Placement, StoredQuadric, VertexQuadric};
    use crate::{Config, EdgeCollapse, NoBound, Positions, Workspace};

    impl<'a, L: Index, I: Index, C: Cost, B: Bound<'a, I>, O: Operator> Simplifier<'a, L, I, C, B, O> {
        /// The queue's promise: every queued key is at most its vertex's cheapest price now,
        /// or for a vertex raised past a refused candidate ([`flag::RAISED`]) at most its
        /// cheapest price the rules allow now. The first vertex that breaks it, with its key
        /// and that price.
        fn key_above_price(&self) -> Option<(usize, f32, f32)> {
            for v in 0..self.mesh.vertex_count() {
                let Some(key) = self.heap.queued(v) else {
                    continue;
                };
                let mut w = self.unwalked();
                let w = self.walk(v, &mut w);
                let mut prices = [f32::INFINITY; MAX_CANDIDATES];
                self.prices(v, w, &mut prices);
                let least = prices
                    .iter()
                    .fold(f32::INFINITY, |m, &c| if c < m { c } else { m });
                if key > least && !self.mesh.has(v, flag::RAISED) {
                    return Some((v, key, least));
                }
                // Raised: at most its cheapest candidate the rules allow now.
                let legal = prices
                    .iter()
                    .zip(w.neighbours())
                    .filter(|c| c.0.is_finite())
                    .filter_map(|c| self.legal(v, w, c.1, *c.0).ok())
                    .fold(f32::INFINITY, |m, c| if c.0 < m { c.0 } else { m });
                if key > legal {
                    return Some((v, key, legal));
                }
            }
            None
        }
    }

    /// A wavy open grid, `n` x `n` quads, every second row shifted: boundary, curvature and
    /// no two equal prices by symmetry.
    fn wavy(n: usize, noise: f32) -> ([[f32; 3]; 121], [[u16; 3]; 200]) {
        let mut p = [[0.0f32; 3]; 121];
        let mut t = [[0u16; 3]; 200];
        for (i, q) in p.iter_mut().enumerate() {
            let (x, y) = ((i % (n + 1)) as f32, (i / (n + 1)) as f32);
            let s = (x * 0.7 + y * 0.3) * 0.9;
            q[0] = x + 0.13 * (y * 1.7).sin();
            q[1] = y;
            // A fixed pseudo-random bump per vertex (Knuth's multiplicative hash).
            let h = (i as u32).wrapping_mul(2_654_435_761) >> 16;
            q[2] = 0.6 * s.sin() + 0.05 * x * y / n as f32 + noise * (h as f32 / 65_536.0 - 0.5);
        }
        let mut k = 0;
        for y in 0..n {
            for x in 0..n {
                let a = (y * (n + 1) + x) as u16;
                let (b, c, d) = (a + 1, a + n as u16 + 1, a + n as u16 + 2);
                t[k] = [a, b, d];
                t[k + 1] = [a, d, c];
                k += 2;
            }
        }
        (p, t)
    }

    /// Stored quadrics, subset placement, no feature rule: after every operation of the run,
    /// each queued key is still a lower bound (the one-price re-key of a collapse's
    /// neighbours and the unchecked re-insert of a stale key rely on it). Fails without the
    /// one price, without `RAISED` set or without `RAISED` honoured.
    #[test]
    fn stored_subset_keys_stay_lower_bounds() -> Result<(), crate::Error> {
        let (p, mut t) = wavy(10, 0.0);
        let mut q = [[0.0f32; 10]; 121] as [VertexQuadric; 121];
        let mut ws = Workspace::<u16, 121, 200>::new();
        let config = Config::stored().with_ratio(0.1);
        let cost = StoredQuadric::new(&mut q, Placement::Subset);
        audit(ws.start(
            Positions::Read(&p),
            &mut t,
            &config,
            cost,
            NoBound,
            EdgeCollapse,
        )?);
        Ok(())
    }

    const NOISE: f32 = 0.4;

    /// The same with optimal placement: the kept vertex moves, so every neighbour's price
    /// onto it may fall as well as rise.
    #[test]
    fn stored_optimal_keys_stay_lower_bounds() -> Result<(), crate::Error> {
        let (mut p, mut t) = wavy(10, NOISE);
        let mut q = [[0.0f32; 10]; 121] as [VertexQuadric; 121];
        let mut ws = Workspace::<u16, 121, 200>::new();
        let config = Config::stored().with_ratio(0.1);
        let cost = StoredQuadric::new(&mut q, Placement::Optimal);
        audit(ws.start(
            Positions::Write(&mut p),
            &mut t,
            &config,
            cost,
            NoBound,
            EdgeCollapse,
        )?);
        Ok(())
    }

    /// Runs `s` one operation at a time, checking the queue after each.
    fn audit<C: Cost>(mut s: Simplifier<'_, u16, u16, C>) {
        assert!(s.keys_only_fall());
        let mut ops = 0;
        while !s.step(1) {
            ops += 1;
            if s.phase == Phase::Queue {
                assert_eq!(s.key_above_price(), None, "after {ops} operations");
            }
        }
        let r = s.finish();
        assert!(r.collapses > 60, "{r:?}");
    }
}
