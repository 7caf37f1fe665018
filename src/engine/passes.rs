//! The passes schedule (Lin 2007 Algorithms 3-4): sweep the vertices in index order, pair each
//! with its cheapest legal unpaired neighbour, and repeat until a pass makes no collapse.

use super::walk::MAX_CANDIDATES;
use super::{Phase, Simplifier};
use crate::index::Index;
use crate::mesh::{flag, NIL};
use crate::operator::Operator;
use crate::policy::bound::Bound;
use crate::policy::cost::Cost;
use crate::policy::legality::on;
use crate::report::Stop;

impl<'a, L: Index, I: Index, C: Cost, B: Bound<'a, I>, O: Operator> Simplifier<'a, L, I, C, B, O> {
    /// Passes: try to pair the vertex under the cursor (Lin 2007 Algorithm 3), or end the pass.
    pub(super) fn pair(&mut self) {
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
        if !self.mesh.has(v, flag::USED) || self.mesh.has(v, flag::DONE | unmovable()) {
            return;
        }
        // Every collapse between v and an unpaired neighbour, in either direction (Algorithm 1
        // moves the endpoint whose W is smaller), priced; the rules then run in price order.
        let mut cand = [(f32::INFINITY, NIL, NIL); 2 * MAX_CANDIDATES];
        let mut n = 0;
        let mut wv = self.unwalked();
        let wv = self.walk(v, &mut wv);
        let movable = self.movable();
        for y in wv.neighbours() {
            if self.mesh.has(y, flag::DONE) {
                continue;
            }
            let mut wy = self.unwalked();
            let wy = self.walk(y, &mut wy);
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
                let mut w = self.unwalked();
                let w = self.walk(from, &mut w);
                self.legal(from, w, to, c)
            } else {
                self.check(from, to, None).map(|()| (c, None))
            };
            match checked {
                Ok((c, at)) => {
                    if c > self.config.max_cost {
                        self.over_cost = true;
                        return;
                    }
                    if !self.log_collapse(from, to) {
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

/// `(price, from, to)` order: cheaper first, then the lower `(from, to)`.
#[inline]
fn cand_less(a: (f32, usize, usize), b: (f32, usize, usize)) -> bool {
    a.0 < b.0 || (a.0 == b.0 && (a.1, a.2) < (b.1, b.2))
}

/// Flags that keep a vertex from moving (with the legality switches, `legality::on!`).
const fn unmovable() -> u8 {
    (if on!(Locked) { flag::LOCKED } else { 0 }) | (if on!(Feature) { flag::FEATURE } else { 0 })
}
