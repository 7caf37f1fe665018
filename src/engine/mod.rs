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
//! Batched: Mean ─> Price ─> Batch: pop in price order, skip stale, collapse ─> next pass
//!                    ^                  (Mean again first when the mesh has halved)
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
use crate::math::V3;
use crate::mesh::{flag, Mesh, NIL};
use crate::operator::{EdgeCollapse, Operator};
use crate::policy::bound::{Bound, NoBound};
use crate::policy::cost::Cost;
use crate::policy::feature::Mean;
use crate::policy::legality::Rules;
use crate::report::{Rejections, Report, Stop};
use crate::{Config, Schedule};
use heap::Heap;

mod batched;
mod greedy;
pub(crate) mod heap;
mod log;
mod parts;
mod passes;
mod price;
mod remove;
mod report;
mod triangle;
mod walk;

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
    /// Batched: pricing every vertex's cheapest candidate into the pass's order.
    Price,
    /// Batched: collapsing in the pass's order.
    #[cfg_attr(not(feature = "batched"), allow(dead_code))]
    Batch,
    /// Finished.
    Done(Stop),
}

/// A simplification in progress; see [`Storage::start`](crate::Storage::start).
///
/// Between steps the mesh is always valid: [`Simplifier::triangles`] yields its live
/// triangles. The caller's buffer itself holds removed triangles as `[i, i, i]` (and the backs
/// of double-sided triangles as `[i, i, j]`: degenerate, so a renderer draws nothing for them)
/// until [`Simplifier::finish`] compacts it.
///
/// `B` is the error bound: [`NoBound`] (none, the default) or
/// [`Controls`](crate::bound::Controls). `O` is the operator: [`EdgeCollapse`] (the default),
/// [`TriangleCollapse`](crate::TriangleCollapse) or
/// [`VertexDecimation`](crate::VertexDecimation).
pub struct Simplifier<
    'a,
    L: Index,
    I: Index,
    C: Cost,
    B: Bound<'a, I> = NoBound,
    O: Operator = EdgeCollapse,
> {
    mesh: Mesh<'a, L, I>,
    heap: Heap<'a, L>,
    config: Config,
    rules: Rules,
    cost: C,
    target: usize,
    /// The target of the whole output, twins included (`target` without twins).
    target_out: usize,
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
    /// `Config::error_limit` squared, in normalised units (infinite: no limit).
    limit2: f32,
    /// Candidates refused by the error limit, in all and in this round.
    over_limit: u32,
    round_over_limit: bool,
    /// The largest squared error of a collapse made (tracked with a finite limit only).
    reached2: f32,
    /// Greedy: refresh the feature threshold when the mesh is down to this many triangles.
    refresh_at: usize,
    /// Greedy: the Mean sweep under way only refreshes the threshold (no new round).
    refresh_only: bool,
    /// Batched: the pass under way (nothing without the `batched` feature).
    #[cfg_attr(not(feature = "batched"), allow(dead_code))]
    batch: batched::Pass,
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
    /// The operator (no state for the collapses; a removal operator's parameters).
    operator: O,
    /// Parts that may vanish whole (`with_parts`).
    #[cfg(feature = "parts")]
    parts: parts::Parts<'a, L>,
}

/// `n / d` (`d > 0`) by binary long division. The run's one integer division (the fronts'
/// share of the target): a Cortex-M0 has no divider, and the compiler's division routine
/// costs more flash than this loop.
fn div_floor(n: usize, d: usize) -> usize {
    let (mut q, mut r) = (0usize, 0usize);
    for i in (0..usize::BITS).rev() {
        // `r < d` before the shift, so `2r + bit < 2d`: one subtraction, with the bit shifted
        // out of `r` standing for the `2^BITS` it lost.
        let carry = r >> (usize::BITS - 1);
        r = r << 1 | (n >> i & 1);
        if carry != 0 || r >= d {
            r = r.wrapping_sub(d);
            q |= 1 << i;
        }
    }
    q
}

impl<'a, L: Index, I: Index, C: Cost, B: Bound<'a, I>, O: Operator> Simplifier<'a, L, I, C, B, O> {
    #[inline(always)]
    pub(crate) fn new(
        mesh: Mesh<'a, L, I>,
        heap: Heap<'a, L>,
        config: Config,
        cost: C,
        bound: B,
        operator: O,
    ) -> Self {
        // Twins (double-sided triangles' backs) come back at the end, so the fronts aim for
        // their share of the target.
        let all = mesh.valid_in + mesh.twins;
        let target_out = config.target.triangles(all);
        let target = if mesh.twins == 0 {
            target_out
        } else {
            // Rounded down: a wholly double-sided surface never ends above the target. In
            // `usize` (no 64-bit division in the image); past its range, in `f32`.
            match target_out.checked_mul(mesh.valid_in) {
                Some(p) => div_floor(p, all.max(1)),
                None => (target_out as f32 * (mesh.valid_in as f32 / all as f32)) as usize,
            }
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
            target_out,
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
            limit2: f32::INFINITY,
            over_limit: 0,
            round_over_limit: false,
            reached2: 0.0,
            refresh_at: 0,
            refresh_only: false,
            batch: batched::Pass::new(),
            pass_triangles: heapless::Vec::new(),
            rejected: Rejections::default(),
            log: &mut [],
            logging: false,
            logged: 0,
            initialised: false,
            bound,
            operator,
            #[cfg(feature = "parts")]
            parts: parts::Parts::off(),
        };
        if s.config.error_limit.is_finite() {
            let l = s.mesh.normalised_length(s.config.error_limit);
            s.limit2 = l * l;
        }
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
        if let Some(e) = self.bound.envelope_mut() {
            e.enrol(&self.mesh, d);
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

    /// Runs to the end and [finishes](Simplifier::finish): the one-shot run.
    pub fn run(mut self) -> Report {
        while !self.step(u32::MAX) {}
        self.finish()
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
    /// with their first two indices equal: `[i, i, i]`, or `[i, i, j]` for the back of a
    /// double-sided triangle, which [`Simplifier::finish`] writes back if its front survived.
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
        self.mesh.input_position(v)
    }

    /// Whether vertex `v` currently has triangles.
    pub fn is_used(&self, v: usize) -> bool {
        self.mesh.first(v) != NIL
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
                        let mut w = self.unwalked();
                        let w = self.walk(self.v, &mut w);
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
                    if self.config.schedule == Schedule::Batched {
                        self.threshold_taken();
                    }
                    if self.refresh_only {
                        // Vertices meet the new threshold as they are re-keyed.
                        self.refresh_only = false;
                        self.refresh_at = self.mesh.live / 2;
                        if self.config.schedule == Schedule::Batched {
                            return self.start_pass();
                        }
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
                        && self.is_feature_now(self.walk(v, &mut self.unwalked()));
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
            Phase::Price => self.price_next(),
            Phase::Batch => self.batch(),
        }
    }

    /// The phase that starts a round's work.
    fn after_init(&self) -> Phase {
        match self.config.schedule {
            Schedule::Passes => Phase::Flags,
            Schedule::Greedy => Phase::Keys,
            Schedule::Batched => Phase::Price,
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
}

#[cfg(test)]
mod tests {
    use super::div_floor;

    /// The long division agrees with `/`, at the ends of the range too.
    #[test]
    fn div_floor_is_division() {
        let big = [
            usize::MAX,
            usize::MAX - 1,
            usize::MAX / 2,
            usize::MAX / 2 + 1,
        ];
        let mut x = 0x9e37_79b9_usize;
        for i in 0..20_000usize {
            // A fixed pseudo-random sequence (xorshift), and small values.
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            let n = [x, i, x >> (i % 31), big[i % 4]][i % 4];
            let d = [x.rotate_left(11) >> (i % 29), i % 7, big[(i / 4) % 4], n][i / 4 % 4].max(1);
            assert_eq!(div_floor(n, d), n / d, "{n} / {d}");
        }
    }
}
