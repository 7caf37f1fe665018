//! The collapse engine: schedule, legality, apply.
//!
//! One [`Simplifier`] drives a mesh from start to finish as a small state machine, so that it
//! can stop after any number of operations and resume later (watchdogs, frame deadlines) and
//! still give exactly the bytes of a one-shot run: one-shot *is* stepping with an unlimited
//! budget.
//!
//! ```text
//! Greedy: Mean ─> Keys ─> Queue: pop the cheapest vertex, check the rules on its candidates
//!                   ^             in cost order, collapse, re-key the vertices whose fan changed
//!                   └── when the mesh has halved (fresh feature threshold) or the queue is empty
//! Passes: Mean ─> Flags ─> Pairs: sweep vertices in index order, pair, collapse ─> next pass
//! ```
//!
//! A vertex's key is a lower bound: the price of its cheapest candidate under the flag and
//! boundary rules only, from one walk around its fan. The connectivity and shape rules run when
//! it reaches the top; if its cheapest *legal* collapse costs more than the key it goes back in
//! at that price, so collapses still come out in exact cost order.
//!
//! Termination: every collapse removes a vertex, so there are fewer collapses than vertices.
//! Between two collapses the queue only re-keys a popped vertex to a strictly higher price of
//! one of its at most `MAX_CANDIDATES` candidates (its exact current cost, or for a stored
//! cost without the feature rule possibly a refused candidate's price first) or drops it, and
//! prices do not change without a collapse, so at most `(MAX_CANDIDATES + 1)·V` pops separate
//! two collapses; a
//! refresh comes at most once per halving of the mesh, and a round or pass without a collapse
//! ends the run. Every operation below is bounded by the valences involved.

use crate::index::Index;
use crate::policy::bound::{Bound, NoBound};
use crate::policy::cost::{Cost, Move};
use crate::policy::feature::{Mean, Variation};
use crate::policy::legality::{self, on, Rules, Shape};
use crate::math::{self, V3};
use crate::mesh::{flag, next3, prev3, Mesh, NIL};
use crate::report::{Rejections, Report, Stop};
use crate::{Config, Operator, Schedule};
use heap::Heap;

pub(crate) mod heap;
pub mod triangle;

/// Candidates priced per vertex: its first `MAX_CANDIDATES` neighbours in fan order (a vertex
/// of higher valence never moves onto the others).
const MAX_CANDIDATES: usize = 32;

/// One walk around a fan: the cost's summary, D, and the boundary ends.
struct Walk<F> {
    fan: F,
    variation: Variation,
    /// For a boundary vertex: the `a` of its first triangle and the `b` of its last.
    ends: (usize, usize),
    /// The walked vertex's position.
    p: V3,
    /// Twice the fan's area.
    area2: f32,
    /// Its neighbours in fan order.
    nb: [u32; MAX_CANDIDATES],
    n: usize,
}

impl<F> Walk<F> {
    fn push(&mut self, x: usize) {
        if let Some(slot) = self.nb.get_mut(self.n) {
            *slot = x as u32;
            self.n += 1;
        }
    }

    fn neighbours(&self) -> impl Iterator<Item = usize> + '_ {
        self.nb.iter().take(self.n).map(|&x| x as usize)
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Phase {
    /// Summing D for the feature threshold.
    Mean,
    /// Setting feature flags.
    Flags,
    /// Once, for a cost that stores per-vertex state: handing it every vertex's planes.
    Init,
    /// Greedy: classifying every vertex and computing its key.
    Keys,
    /// Greedy: collapsing from the queue.
    Queue,
    /// Passes: pairing vertices in index order.
    Pairs,
    /// Finished.
    Done(Stop),
}

/// A simplification in progress; see [`Storage::start`](crate::Storage::start).
///
/// Between steps the mesh is always valid: [`Simplifier::triangles`] yields its live
/// triangles. The caller's buffer itself holds removed triangles as `[i, i, i]` (degenerate,
/// so a renderer draws nothing for them) until [`Simplifier::finish`] compacts it.
///
/// `B` is the error bound: [`NoBound`] (none, the default) or
/// [`Controls`](crate::bound::Controls).
pub struct Simplifier<'a, L: Index, I: Index, C: Cost, B: Bound<'a, I> = NoBound> {
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
    /// Sum of twice the fan areas over a Mean sweep.
    area2: f32,
    features: usize,
    locked: usize,
    used_in: usize,
    collapses: usize,
    passes: u32,
    pass_collapses: usize,
    /// A legal collapse was skipped because it cost more than `max_cost`.
    over_cost: bool,
    /// Greedy: refresh the feature threshold when the mesh is down to this many triangles.
    refresh_at: usize,
    /// Greedy: the Mean sweep under way only refreshes the threshold (no new round).
    refresh_only: bool,
    pass_triangles: heapless::Vec<u32, { crate::PASS_LOG }>,
    rejected: Rejections,
    /// Collapse log (`[removed, kept]`), written only once `record_into` gave one.
    log: &'a mut [[I; 2]],
    logging: bool,
    logged: usize,
    /// The cost's per-vertex state has been filled (costs that store it only).
    initialised: bool,
    /// The error bound (control points), if any.
    bound: B,
}

impl<'a, L: Index, I: Index, C: Cost, B: Bound<'a, I>> Simplifier<'a, L, I, C, B> {
    #[inline(always)]
    pub(crate) fn new(
        mesh: Mesh<'a, L, I>,
        heap: Heap<'a, L>,
        config: Config,
        cost: C,
        bound: B,
    ) -> Self {
        // In f32, exact for counts below 2^24; the product is floored.
        let by_ratio = (config.target_ratio * mesh.valid_in as f32) as usize;
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
        let mut s = Simplifier {
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
            area2: 0.0,
            features: 0,
            locked,
            used_in,
            collapses: 0,
            passes: 0,
            pass_collapses: 0,
            over_cost: false,
            refresh_at: 0,
            refresh_only: false,
            pass_triangles: heapless::Vec::new(),
            rejected: Rejections::default(),
            log: &mut [],
            logging: false,
            logged: 0,
            initialised: false,
            bound,
        };
        if B::ON {
            s.enrol();
        }
        s
    }

    /// Enrols the control points of a bounded run (nothing without a bound).
    fn enrol(&mut self) {
        let d = self.config.max_error;
        if let Some(c) = self.bound.controls_mut() {
            c.enrol(&self.mesh, d);
        }
    }

    /// The legality rules for `from -> to` (at `at` if the cost places the kept vertex), then
    /// the error bound's veto.
    #[inline(always)]
    fn check(&self, from: usize, to: usize, at: Option<V3>) -> Result<(), crate::Reject> {
        // Inlined, so that the read-only modes (always `None`) drop the moved-`b` rules.
        match at {
            Some(p) => legality::check_placed(&self.mesh, &self.rules, from, to, p)?,
            None => legality::check(&self.mesh, &self.rules, from, to, None)?,
        }
        if B::ON && on!(Bound) {
            if let Some(c) = self.bound.controls() {
                if !c.allows(&self.mesh, from, to) {
                    return Err(crate::Reject::Bound);
                }
            }
        }
        Ok(())
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

    /// Runs to the end and [finishes](Simplifier::finish): the one-shot run.
    pub fn run(mut self) -> Report {
        while !self.step(u32::MAX) {}
        self.finish()
    }

    /// Writes every collapse made from now on into `log`, as `[removed, kept]` in the input's
    /// vertex numbers: the history that [`Progressive::from_log`](crate::Progressive::from_log)
    /// turns into vertex splits (call it before the first step to have the whole history).
    /// When `log` is full the run stops with [`Stop::LogFull`] before the next collapse, so
    /// the log always holds every collapse made and the mesh stays valid.
    pub fn record_into(mut self, log: &'a mut [[I; 2]]) -> Self {
        self.log = log;
        self.logging = true;
        self.logged = 0;
        self
    }

    /// The collapses logged so far (see [`Simplifier::record_into`]).
    pub fn records(&self) -> &[[I; 2]] {
        self.log.get(..self.logged).unwrap_or(&[])
    }

    /// Appends `[a, b]` to the log; `false` (and the run stops) if the log is full.
    fn note(&mut self, a: usize, b: usize) -> bool {
        if !self.logging {
            return true;
        }
        match self.log.get_mut(self.logged) {
            Some(slot) => {
                *slot = [I::narrow(a), I::narrow(b)];
                self.logged += 1;
                true
            }
            None => {
                self.done(Stop::LogFull);
                false
            }
        }
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

    /// Vertex `v`'s current position in the input's units (moved by optimal placement);
    /// `None` past the end.
    pub fn position(&self, v: usize) -> Option<[f32; 3]> {
        self.mesh.raw(v)
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
        let errors = self.bound.controls().map(|c| c.errors(&self.mesh));
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
            max_error: errors.map(|e| e.0),
            mean_error: errors.map(|e| e.1),
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
                    self.area2 = 0.0;
                }
                if self.v < nv && !self.normals() {
                    // Nothing reads the sums: skip the sweep.
                    self.v = nv;
                } else if self.v < nv {
                    if self.mesh.has(self.v, flag::USED) {
                        let w = self.walk(self.v);
                        if self.config.features {
                            self.mean.add(w.variation.value(self.config.feature_mode));
                        }
                        self.area2 += w.area2;
                    }
                    self.v += 1;
                } else {
                    self.threshold = self.mean.threshold(self.config.lambda);
                    // Each triangle was seen from its three corners.
                    let live = self.mesh.live as f32;
                    self.cost.round(if live > 0.0 {
                        self.area2 / (3.0 * live)
                    } else {
                        0.0
                    });
                    self.v = 0;
                    if self.refresh_only {
                        // Vertices meet the new threshold as they are re-keyed.
                        self.refresh_only = false;
                        self.refresh_at = self.mesh.live / 2;
                        self.phase = Phase::Queue;
                        return;
                    }
                    self.features = 0;
                    self.passes += 1;
                    self.pass_collapses = 0;
                    self.phase = if self.cost.stores() && !self.initialised {
                        Phase::Init
                    } else {
                        self.after_init()
                    };
                }
            }
            Phase::Init => {
                if self.v < nv {
                    self.init_vertex(self.v);
                    self.v += 1;
                } else {
                    self.initialised = true;
                    self.v = 0;
                    self.phase = self.after_init();
                }
            }
            Phase::Flags => {
                if self.v < nv {
                    let v = self.v;
                    let is = self.config.features
                        && self.mesh.has(v, flag::USED)
                        && self.is_feature_now(&self.walk(v));
                    self.mesh.set_flag(v, flag::FEATURE, is);
                    self.mesh.set_flag(v, flag::DONE, false);
                    self.features += is as usize;
                    self.v += 1;
                } else {
                    self.v = 0;
                    self.phase = Phase::Pairs;
                }
            }
            Phase::Keys => {
                if self.v < nv {
                    self.rekey(self.v);
                    self.features += self.mesh.has(self.v, flag::FEATURE) as usize;
                    self.v += 1;
                } else {
                    self.refresh_at = self.mesh.live / 2;
                    self.phase = Phase::Queue;
                }
            }
            Phase::Queue => self.pop(),
            Phase::Pairs => self.pair(),
        }
    }

    /// The phase that starts a round's work.
    fn after_init(&self) -> Phase {
        if self.config.schedule == Schedule::Passes {
            Phase::Flags
        } else {
            Phase::Keys
        }
    }

    /// Hands the cost `v`'s planes (costs that store per-vertex state): each triangle's plane
    /// weighted by twice its area, and for a boundary vertex the plane through each of its two
    /// boundary edges perpendicular to the edge's triangle (Cheng, Pan and Shi 1998 §3.3).
    fn init_vertex(&mut self, v: usize) {
        let f = self.mesh.flags(v);
        if f & flag::USED == 0 {
            return;
        }
        let pv = self.mesh.p(v);
        let (first, last) = (self.mesh.first(v), self.mesh.last(v));
        let mut c = first;
        let mut guard = self.mesh.triangle_count();
        while c != NIL && guard > 0 {
            guard -= 1;
            let tri = self.mesh.tri(c >> 2);
            let (x, y) = (tri[next3(c & 3)], tri[prev3(c & 3)]);
            let (px, py) = (self.mesh.p(x), self.mesh.p(y));
            let n = math::cross(math::sub(px, pv), math::sub(py, pv));
            let l2 = math::dot(n, n);
            if l2 > math::TINY2 && l2.is_finite() {
                let r = math::rsqrt(l2);
                let unit = math::scale(n, r);
                // Planes through v, in v's own frame (d = 0).
                self.cost.plane(v, unit, 0.0, l2 * r);
                if f & flag::BOUNDARY != 0 {
                    // The first triangle's edge v-x and the last one's v-y have no twin.
                    for (is, e) in [
                        (c == first, math::sub(px, pv)),
                        (c == last, math::sub(py, pv)),
                    ] {
                        if !is {
                            continue;
                        }
                        let m = math::cross(e, unit);
                        let m2 = math::dot(m, m);
                        if m2 > math::TINY2 && m2.is_finite() {
                            let m = math::scale(m, math::rsqrt(m2));
                            self.cost.boundary_plane(v, m, 0.0, math::dot(e, e));
                        }
                    }
                }
            }
            c = self.mesh.after(c);
        }
    }

    /// Whether walks compute the fan's normals and areas: the cost or the feature rule reads
    /// them.
    fn normals(&self) -> bool {
        self.config.features || self.cost.needs_fan()
    }

    fn is_feature_now(&self, w: &Walk<C::Fan>) -> bool {
        w.variation
            .value(self.config.feature_mode)
            .is_some_and(|d| d > self.threshold)
    }

    /// One walk around `v`'s fan: the cost's summary of it, D, the boundary ends and the
    /// neighbours (each corner's `a`, and a boundary fan's last `b`).
    fn walk(&self, v: usize) -> Walk<C::Fan> {
        let mesh = &self.mesh;
        let pv = mesh.p(v);
        let mut w = Walk {
            fan: self.cost.empty(),
            variation: Variation::default(),
            ends: (NIL, NIL),
            p: pv,
            area2: 0.0,
            nb: [0; MAX_CANDIDATES],
            n: 0,
        };
        // Normals only when something reads them: the cost's fan summary or the feature rule.
        let normals = self.normals();
        let mut c = mesh.first(v);
        while c != NIL {
            let tri = mesh.tri(c >> 2);
            let (x, y) = (tri[next3(c & 3)], tri[prev3(c & 3)]);
            if w.n == 0 {
                w.ends.0 = x;
            }
            w.ends.1 = y;
            w.push(x);
            c = mesh.after(c);
            if !normals {
                continue;
            }
            let dx = math::sub(mesh.p(x), pv);
            let dy = math::sub(mesh.p(y), pv);
            // Twice the area and the unit normal from one cross product and one 1/√.
            let n = math::cross(dx, dy);
            let l2 = math::dot(n, n);
            let (unit, area2) = if l2 > math::TINY2 && l2.is_finite() {
                let r = math::rsqrt(l2);
                (math::scale(n, r), l2 * r)
            } else {
                ([0.0; 3], 0.0)
            };
            self.cost.add(&mut w.fan, unit, area2);
            w.variation.add(unit);
            w.area2 += area2;
        }
        if mesh.has(v, flag::BOUNDARY) && w.n > 0 {
            w.push(w.ends.1);
        }
        w
    }

    /// The price of moving `from` (walked as `w`) onto `to`, if the flag and boundary rules
    /// allow it: the cheap half of legality, enough for a lower bound.
    fn price(&self, from: usize, w: &Walk<C::Fan>, to: usize) -> Option<f32> {
        self.price_kept(from, w, to, false)
    }

    /// [`Self::price`]; with `keep`, at `to`'s own position even for a placing cost.
    fn price_kept(&self, from: usize, w: &Walk<C::Fan>, to: usize, keep: bool) -> Option<f32> {
        let m = self.make_move(from, w, to, keep)?;
        let c = self.cost.price(&w.fan, &m);
        if c.is_finite() {
            Some(if c > 0.0 { c } else { 0.0 })
        } else {
            None
        }
    }

    /// Whether collapses may move the kept vertex: a placing cost on mutable positions
    /// (compile-time `false` for every other cost).
    #[inline]
    fn movable(&self) -> bool {
        C::PLACES && self.mesh.movable()
    }

    /// The move `from -> to` as a cost sees it, if the flag and boundary rules allow it.
    fn make_move(&self, from: usize, w: &Walk<C::Fan>, to: usize, keep: bool) -> Option<Move> {
        let mesh = &self.mesh;
        let ff = mesh.flags(from);
        legality::flags_allow(&self.rules, ff, mesh.flags(to)).ok()?;
        let mut retreat2 = 0.0;
        if ff & flag::BOUNDARY != 0 && on!(Boundary) {
            // Only along its own boundary edges; the boundary retreats to the segment from
            // its other boundary neighbour to `to`.
            let (x1, x2) = w.ends;
            let other = if to == x1 {
                x2
            } else if to == x2 {
                x1
            } else {
                return None;
            };
            retreat2 = math::segment_distance2(w.p, mesh.p(other), mesh.p(to));
        }
        let turn = if self.cost.needs_turn() {
            self.turn(from, to)
        } else {
            0.0
        };
        let p_to = mesh.p(to);
        Some(Move {
            d: math::sub(p_to, w.p),
            retreat2,
            turn,
            from,
            to,
            p_from: w.p,
            p_to,
            keep: keep || !self.movable() || mesh.has(to, flag::FEATURE),
        })
    }

    /// Where the kept vertex of `from -> to` goes if the cost places it (optimal placement on
    /// mutable positions): its input-unit coordinates and the normalised position they read
    /// back as. `None`: it stays.
    fn placement(&self, from: usize, w: &Walk<C::Fan>, to: usize) -> Option<([f32; 3], V3)> {
        if !self.movable() {
            return None;
        }
        let m = self.make_move(from, w, to, false)?;
        if m.keep {
            return None;
        }
        let p = self.cost.place(&m)?;
        self.mesh.stored_form(p)
    }

    /// The legality rules for `from -> to` priced `c`, at the cost's placement if it places
    /// the kept vertex. If the rules refuse the placed position but allow the kept vertex to
    /// stay, the collapse goes ahead at `to`'s own position and price. Returns the price and
    /// the placement.
    #[allow(clippy::type_complexity)]
    fn legal(
        &self,
        from: usize,
        w: &Walk<C::Fan>,
        to: usize,
        c: f32,
    ) -> Result<(f32, Option<([f32; 3], V3)>), crate::Reject> {
        if !self.movable() {
            return self.check(from, to, None).map(|()| (c, None));
        }
        self.legal_placed(from, w, to, c)
    }

    /// [`Self::legal`] on mutable positions. Never inlined, so that the read-only modes (every
    /// device mode) do not carry its frame: the micro:bit has 4.5 KB of stack.
    #[allow(clippy::type_complexity)]
    #[inline(never)]
    fn legal_placed(
        &self,
        from: usize,
        w: &Walk<C::Fan>,
        to: usize,
        c: f32,
    ) -> Result<(f32, Option<([f32; 3], V3)>), crate::Reject> {
        let at = self.placement(from, w, to);
        match self.check(from, to, at.map(|x| x.1)) {
            Ok(()) => Ok((c, at)),
            Err(r) => {
                if at.is_some() && self.check(from, to, None).is_ok() {
                    if let Some(kept) = self.price_kept(from, w, to, true) {
                        return Ok((kept, None));
                    }
                }
                Err(r)
            }
        }
    }

    /// Σ ‖N_new − N_old‖² over `from`'s triangles that survive the move onto `to` (Lin 2007
    /// eq. 1-2), for costs that need it.
    fn turn(&self, from: usize, to: usize) -> f32 {
        let mesh = &self.mesh;
        let pt = mesh.p(to);
        let mut sum = 0.0;
        for (t, k) in mesh.corners(from) {
            let tri = mesh.tri(t);
            if tri.contains(&to) {
                continue;
            }
            let q = tri.map(|v| mesh.p(v));
            let mut r = q;
            if let Some(x) = r.get_mut(k) {
                *x = pt;
            }
            let d = math::sub(Shape::of(r).unit(), Shape::of(q).unit());
            sum += math::dot(d, d);
        }
        sum
    }

    /// `v`'s candidates with their prices, in fan order; returns how many.
    fn candidates(
        &self,
        v: usize,
        w: &Walk<C::Fan>,
        out: &mut [(f32, usize); MAX_CANDIDATES],
    ) -> usize {
        let mut n = 0;
        for x in w.neighbours() {
            if let Some(p) = self.price(v, w, x) {
                if let Some(slot) = out.get_mut(n) {
                    *slot = (p, x);
                    n += 1;
                }
            }
        }
        n
    }

    /// Greedy: re-classify `v` against the round's threshold and re-key it: the cheapest
    /// price among its candidates (a lower bound of its cheapest legal collapse).
    fn rekey(&mut self, v: usize) {
        if cfg!(feature = "triangle") && self.config.operator == Operator::Triangle {
            return self.rekey_triangles(v);
        }
        let f = self.mesh.flags(v);
        if self.keys_only_fall() {
            // Priced in full below: the key is a lower bound again.
            self.mesh.set_flag(v, flag::RAISED, false);
        }
        if f & flag::USED == 0 || (on!(Locked) && f & flag::LOCKED != 0) {
            return self.heap.remove(v);
        }
        let w = self.walk(v);
        let is = self.config.features && self.is_feature_now(&w);
        self.mesh.set_flag(v, flag::FEATURE, is);
        if is && on!(Feature) {
            return self.heap.remove(v);
        }
        let mut cand = [(f32::INFINITY, NIL); MAX_CANDIDATES];
        let n = self.candidates(v, &w, &mut cand);
        let mut key = f32::INFINITY;
        for &(c, _) in cand.iter().take(n) {
            if c < key {
                key = c;
            }
        }
        if n > 0 {
            self.heap.set(v, key)
        } else {
            self.heap.remove(v)
        }
    }

    /// Greedy, both operators: the vertex on top of the queue and its key; `None` when this
    /// pop instead ended the run, started a new round or a refresh of the feature threshold.
    fn top(&mut self) -> Option<(usize, f32)> {
        if self.mesh.live <= self.target {
            self.done(Stop::Target);
            return None;
        }
        let Some((v, key)) = self.heap.peek() else {
            // Rules that look past a vertex's own fan may have changed far from recent
            // collapses: a new round re-keys everything, and only a round without a collapse
            // ends the run.
            if self.pass_collapses == 0 || self.passes >= self.config.max_passes {
                self.done(Stop::NoLegalCollapse);
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
        if key > self.config.max_cost {
            self.done(Stop::MaxCost);
            return None;
        }
        Some((v, key))
    }

    /// Greedy: one pop of the queue.
    fn pop(&mut self) {
        if cfg!(feature = "triangle") && self.config.operator == Operator::Triangle {
            return self.pop_triangles();
        }
        let Some((v, key)) = self.top() else {
            return;
        };
        let w = self.walk(v);
        let mut cand = [(f32::INFINITY, NIL); MAX_CANDIDATES];
        let n = self.candidates(v, &w, &mut cand);
        let cand = cand.get_mut(..n).unwrap_or(&mut []);
        let mut refused = false;
        while let Some((c, to)) = take_cheapest(cand) {
            if c > key && self.keys_only_fall() {
                // A stale key (see `keys_only_fall`): back in at this price before the rules
                // are spent on it; above a refused candidate, no longer a lower bound.
                self.heap.set(v, c);
                self.mesh.set_flag(v, flag::RAISED, refused);
                return;
            }
            refused = true;
            match self.legal(v, &w, to, c) {
                Ok((c, at)) => {
                    if c > key {
                        // Its cheapest candidate was illegal: back in at its true price.
                        self.heap.set(v, c);
                        if self.keys_only_fall() {
                            // Past a refused candidate or placement.
                            self.mesh.set_flag(v, flag::RAISED, true);
                        }
                    } else {
                        self.heap.remove(v);
                        self.collapse_greedy(v, to, at);
                    }
                    return;
                }
                Err(r) => self.rejected.count(r),
            }
        }
        self.heap.remove(v);
    }

    /// Triangle collapse (Zhu, Wang and Meng 2007 eq. 3): the weight of live triangle `t`, `A (α +
    /// rc + d_max)`; `None` if not finite.
    fn triangle_weight(&self, t: usize) -> Option<f32> {
        let tri = self.mesh.tri(t);
        let (w, area) = triangle::weight(&self.mesh, tri)?;
        let d = match self.bound.controls() {
            Some(c) if B::ON => c.max_distance(&self.mesh, t),
            _ => 0.0,
        };
        let w = w + area * d;
        w.is_finite().then_some(w)
    }

    /// Triangle collapse: `v`'s key is the smallest weight of its triangles (feature and
    /// locked vertices are not queued: their triangles are reached from their other vertices).
    fn rekey_triangles(&mut self, v: usize) {
        let f = self.mesh.flags(v);
        if f & flag::USED == 0 || (on!(Locked) && f & flag::LOCKED != 0) {
            return self.heap.remove(v);
        }
        let w = self.walk(v);
        let is = self.config.features && self.is_feature_now(&w);
        self.mesh.set_flag(v, flag::FEATURE, is);
        if is && on!(Feature) {
            return self.heap.remove(v);
        }
        let mut key = f32::INFINITY;
        for (t, _) in self.mesh.corners(v) {
            if let Some(x) = self.triangle_weight(t) {
                if x < key {
                    key = x;
                }
            }
        }
        if key.is_finite() {
            self.heap.set(v, key)
        } else {
            self.heap.remove(v)
        }
    }

    /// Triangle collapse: one pop. `v`'s triangles in weight order; the first that collapses
    /// ends the pop. All refused: the key times the penalty `p` (Zhu, Wang and Meng 2007 §3), at
    /// most `MAX_PENALTIES` times in a row.
    fn pop_triangles(&mut self) {
        use triangle::{MAX_PENALTIES, PENALTY};
        let Some((v, key)) = self.top() else {
            return;
        };
        let mut cand = [(f32::INFINITY, NIL); MAX_CANDIDATES];
        let mut n = 0;
        for (t, _) in self.mesh.corners(v) {
            if let (Some(w), Some(slot)) = (self.triangle_weight(t), cand.get_mut(n)) {
                *slot = (w, t);
                n += 1;
            }
        }
        let cand = cand.get_mut(..n).unwrap_or(&mut []);
        let mut least = f32::INFINITY;
        for c in cand.iter() {
            if c.0 < least {
                least = c.0;
            }
        }
        while let Some((_, t)) = take_cheapest(cand) {
            if self.collapse_triangle(t) {
                return;
            }
        }
        // Every triangle refused: back in at p times the key, unless it was already
        // penalised MAX_PENALTIES times since its weights last changed.
        let mut cap = least;
        for _ in 0..MAX_PENALTIES {
            cap *= PENALTY;
        }
        let next = key * PENALTY;
        if least.is_finite() && next > key && key < cap && next.is_finite() {
            self.heap.set(v, next);
        } else {
            self.heap.remove(v);
        }
    }

    /// Collapses live triangle `t` into one of its vertices, as two half-edge moves `x -> k`,
    /// `y -> k` (see `crate::triangle`); `false` if the first move is refused for every `k`.
    fn collapse_triangle(&mut self, t: usize) -> bool {
        let tri = self.mesh.tri(t);
        if crate::mesh::is_dead(tri) {
            return false;
        }
        // The kept vertex: the one whose two moves the cost prices lowest (ties: lower slot).
        let mut order = [(f32::INFINITY, 0usize); 3];
        for (k, slot) in order.iter_mut().enumerate() {
            let mut sum = 0.0f32;
            // Indexed with next3/prev3 directly: provably below 3 (no bounds check).
            for x in [tri[next3(k)], tri[prev3(k)]] {
                let w = self.walk(x);
                sum += self
                    .price_kept(x, &w, tri[prev3(next3(k))], true)
                    .unwrap_or(f32::INFINITY);
            }
            *slot = (sum, k);
        }
        for _ in 0..3 {
            // The cheapest choice left (a selection, not a sort: no comparator to misuse).
            let mut best: Option<usize> = None;
            for (i, c) in order.iter().enumerate() {
                if c.0.is_finite() && best.is_none_or(|b| order.get(b).is_some_and(|o| c.0 < o.0)) {
                    best = Some(i);
                }
            }
            let Some((price, k)) = best.and_then(|b| order.get_mut(b)).map(|o| {
                let v = *o;
                o.0 = f32::INFINITY;
                v
            }) else {
                break;
            };
            if !price.is_finite() {
                continue;
            }
            let keep = tri[prev3(next3(k))];
            let (x, y) = (tri[next3(k)], tri[prev3(k)]);
            match self.check(x, keep, None) {
                Ok(()) => {
                    self.heap.remove(x);
                    self.collapse_greedy(x, keep, None);
                    if matches!(self.phase, Phase::Done(_)) {
                        return true;
                    }
                    // The second move, on the mesh after the first.
                    let w = self.walk(y);
                    if self.mesh.live > self.target && self.price_kept(y, &w, keep, true).is_some()
                    {
                        match self.check(y, keep, None) {
                            Ok(()) => {
                                self.heap.remove(y);
                                self.collapse_greedy(y, keep, None);
                            }
                            Err(r) => self.rejected.count(r),
                        }
                    }
                    return true;
                }
                Err(r) => self.rejected.count(r),
            }
        }
        false
    }

    fn new_round(&mut self) {
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
    fn collapse_greedy(&mut self, a: usize, b: usize, at: Option<([f32; 3], V3)>) {
        if !self.note(a, b) {
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
        let mut c = self.mesh.first(b);
        let mut last = NIL;
        while c != NIL {
            let x = self.mesh.tri(c >> 2)[next3(c & 3)];
            self.refresh(x, b);
            last = c;
            c = self.mesh.after(c);
        }
        if last != NIL {
            let y = self.mesh.tri(last >> 2)[prev3(last & 3)];
            self.refresh(y, b);
        }
    }

    /// Collapses `a -> b` in the mesh, moves `b` to its placement and merges the cost's state.
    fn apply(&mut self, a: usize, b: usize, at: Option<([f32; 3], V3)>) {
        let (pa, pb) = (self.mesh.p(a), self.mesh.p(b));
        let chain = match self.bound.controls_mut() {
            Some(c) if B::ON => c.detach(&self.mesh, a),
            _ => NIL,
        };
        self.mesh.collapse(a, b);
        if B::ON {
            if let Some(c) = self.bound.controls_mut() {
                c.attach(&self.mesh, b, chain);
            }
        }
        let mut p_new = pb;
        if let Some((q, p)) = at {
            self.mesh.place(b, q);
            p_new = p;
        }
        if self.cost.stores() {
            self.cost.merge(a, b, pa, pb, p_new);
        }
    }

    /// Re-keys `x` (a former neighbour of the removed vertex, now one of `b`'s) if it is
    /// marked, and clears the mark.
    fn refresh(&mut self, x: usize, b: usize) {
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
    /// before it grew: too low is allowed, too high is not).
    fn keys_only_fall(&self) -> bool {
        self.cost.stores() && !self.config.features
    }

    /// [`Self::rekey`] for [`Self::keys_only_fall`]: one price instead of `x`'s whole fan. A
    /// vertex out of the queue (every candidate refused when it last reached the top) is
    /// re-keyed in full: its fan changed, so a refused candidate may be allowed now; so is
    /// one whose key was raised past a refused candidate ([`flag::RAISED`]). Never
    /// inlined: its frame stays out of the collapse path's (the micro:bit's stack).
    #[inline(never)]
    fn rekey_onto(&mut self, x: usize, b: usize) {
        let Some(key) = self.heap.queued(x) else {
            return self.rekey(x);
        };
        if self.mesh.has(x, flag::RAISED) {
            // A refused cheaper candidate may be allowed in the changed fan: price them all.
            return self.rekey(x);
        }
        // What a price reads of the fan: the position and, on the boundary, the ends.
        let w = Walk {
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

    /// Passes: try to pair the vertex under the cursor (Lin 2007 Algorithm 3), or end the pass.
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
        // Every collapse between v and an unpaired neighbour, in either direction (Algorithm 1
        // moves the endpoint whose W is smaller), priced; the rules then run in price order.
        let mut cand = [(f32::INFINITY, NIL, NIL); 2 * MAX_CANDIDATES];
        let mut n = 0;
        let wv = self.walk(v);
        let movable = self.movable();
        for y in wv.neighbours() {
            if self.mesh.has(y, flag::DONE) {
                continue;
            }
            let wy = self.walk(y);
            for (from, to, w) in [(v, y, &wv), (y, v, &wy)] {
                if let Some(p) = self.price(from, w, to) {
                    if let Some(slot) = cand.get_mut(n) {
                        *slot = (p, from, to);
                        n += 1;
                    }
                }
            }
        }
        let cand = cand.get_mut(..n).unwrap_or(&mut []);
        loop {
            let mut min: Option<(usize, (f32, usize, usize))> = None;
            for (i, &c) in cand.iter().enumerate() {
                if c.1 != NIL && min.is_none_or(|(_, m)| cand_less(c, m)) {
                    min = Some((i, c));
                }
            }
            let Some((i, (c, from, to))) = min else {
                return;
            };
            if let Some(slot) = cand.get_mut(i) {
                slot.1 = NIL;
            }
            let checked = if movable {
                // A placing cost: place with `from`'s own walk.
                let w = self.walk(from);
                self.legal(from, &w, to, c)
            } else {
                self.check(from, to, None).map(|()| (c, None))
            };
            match checked {
                Ok((c, at)) => {
                    if c > self.config.max_cost {
                        self.over_cost = true;
                        return;
                    }
                    if !self.note(from, to) {
                        return;
                    }
                    self.apply(from, to, at);
                    self.mesh.set_flag(to, flag::DONE, true);
                    self.collapses += 1;
                    self.pass_collapses += 1;
                    return;
                }
                Err(r) => self.rejected.count(r),
            }
        }
    }
}

/// Removes and returns the cheapest `(price, vertex)` (ties: lower vertex), if any is left.
fn take_cheapest(cand: &mut [(f32, usize)]) -> Option<(f32, usize)> {
    let mut min: Option<usize> = None;
    for (i, c) in cand.iter().enumerate() {
        if c.1 != NIL {
            if let Some(m) = min.and_then(|m| cand.get(m)) {
                if !less(*c, *m) {
                    continue;
                }
            }
            min = Some(i);
        }
    }
    let slot = cand.get_mut(min?)?;
    let c = *slot;
    slot.1 = NIL;
    Some(c)
}

/// `(price, from, to)` order: cheaper first, then the lower `(from, to)`.
#[inline]
fn cand_less(a: (f32, usize, usize), b: (f32, usize, usize)) -> bool {
    a.0 < b.0 || (a.0 == b.0 && (a.1, a.2) < (b.1, b.2))
}

/// Flags that keep a vertex from moving (with the legality switches, `legality::on!`).
const fn skip() -> u8 {
    (if on!(Locked) { flag::LOCKED } else { 0 }) | (if on!(Feature) { flag::FEATURE } else { 0 })
}

/// `(cost, vertex)` order: cheaper first, then the lower vertex number.
#[inline]
fn less(a: (f32, usize), b: (f32, usize)) -> bool {
    a.0 < b.0 || (a.0 == b.0 && a.1 < b.1)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::policy::cost::{Placement, StoredQuadric, VertexQuadric};
    use crate::{Positions, Workspace};

    impl<'a, L: Index, I: Index, C: Cost, B: Bound<'a, I>> Simplifier<'a, L, I, C, B> {
        /// The queue's promise: every queued key is at most its vertex's cheapest price now,
        /// or for a vertex raised past a refused candidate ([`flag::RAISED`]) at most its
        /// cheapest price the rules allow now. The first vertex that breaks it, with its key
        /// and that price.
        fn key_above_price(&self) -> Option<(usize, f32, f32)> {
            for v in 0..self.mesh.vertex_count() {
                let Some(key) = self.heap.queued(v) else {
                    continue;
                };
                let w = self.walk(v);
                let mut cand = [(f32::INFINITY, NIL); MAX_CANDIDATES];
                let n = self.candidates(v, &w, &mut cand);
                let least = cand
                    .iter()
                    .take(n)
                    .fold(f32::INFINITY, |m, c| if c.0 < m { c.0 } else { m });
                if key > least && !self.mesh.has(v, flag::RAISED) {
                    return Some((v, key, least));
                }
                // Raised: at most its cheapest candidate the rules allow now.
                let legal = cand
                    .iter()
                    .take(n)
                    .filter_map(|c| self.legal(v, &w, c.1, c.0).ok())
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
        audit(ws.start(Positions::Read(&p), &mut t, &config, cost, NoBound)?);
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
        audit(ws.start(Positions::Write(&mut p), &mut t, &config, cost, NoBound)?);
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
