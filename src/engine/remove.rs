//! The engine's path for vertex-removal operators ([`Kind::Removal`](crate::operator::Kind)):
//! the greedy queue keyed by the operator's criterion, a pop that asks it for the new fan,
//! checks that fan with the shared rules and writes it in place of the vertex's.

use super::Simplifier;
use crate::index::Index;
use crate::math::V3;
use crate::mesh::{flag, NIL};
use crate::operator::{classify, plan, Fill, Operator, MAX_RING};
use crate::policy::bound::Bound;
use crate::policy::cost::Cost;
use crate::policy::legality::{self, on};
use crate::report::Stop;

impl<'a, L: Index, I: Index, C: Cost, B: Bound<'a, I>, O: Operator> Simplifier<'a, L, I, C, B, O> {
    /// Removal: `v`'s key is its distance (`operator::classify`); out of the queue if it is
    /// never removed now (locked, a corner, a feature vertex of the round, ...).
    pub(super) fn rekey_removal(&mut self, v: usize) {
        let f = self.mesh.flags(v);
        if f & flag::USED == 0 || (on!(Locked) && f & flag::LOCKED != 0) {
            return self.heap.remove(v);
        }
        if self.config.features {
            let mut w = self.unwalked();
            let w = self.walk(v, &mut w);
            let is = self.is_feature_now(w);
            self.mesh.set_flag(v, flag::FEATURE, is);
            if is && on!(Feature) {
                return self.heap.remove(v);
            }
        }
        let Some(op) = self.operator.removal() else {
            return self.heap.remove(v);
        };
        let Some(fan) = classify(&self.mesh, v, &op) else {
            return self.heap.remove(v);
        };
        if op.fill == Fill::Shape {
            return self.heap.set(v, fan.key);
        }
        // The key is the fit of the fill the pop will make.
        match self.fill(
            v,
            &fan,
            &op,
            &mut [[0; 3]; MAX_RING],
            &mut [[0.0; 3]; MAX_RING],
        ) {
            Some((_, key, _)) => self.heap.set(v, key),
            None => self.heap.remove(v),
        }
    }

    /// Removal: one pop. The vertex on top leaves the queue; if its fan has a triangulation
    /// the rules allow, the fan is replaced and its neighbours (whose fans changed) are
    /// re-keyed; otherwise it waits until a neighbour's removal changes its fan.
    pub(super) fn pop_removal(&mut self) {
        let Some((v, _)) = self.top() else {
            return;
        };
        self.heap.remove(v);
        if self.logging {
            // A removal is no `[removed, kept]` pair.
            return self.done(Stop::LogFull);
        }
        #[cfg(feature = "seams")]
        if !self.mesh.wedges.is_empty() {
            // New triangles would need wedges: welded runs remove nothing.
            return self.rejected.count(legality::Reject::Seam);
        }
        let Some(op) = self.operator.removal() else {
            return;
        };
        let Some(fan) = classify(&self.mesh, v, &op) else {
            return;
        };
        let mut new = [[0u8; 3]; MAX_RING];
        let mut planes = [[0.0f32; 3]; MAX_RING];
        let Some((n, _, err2)) = self.fill(v, &fan, &op, &mut new, &mut planes) else {
            return;
        };
        if self.limit2.is_finite() {
            // Not cut to reach a count (`Config::error_limit`): the vertex waits until its
            // fan changes.
            if err2 > self.limit2 {
                self.over_limit = self.over_limit.saturating_add(1);
                self.round_over_limit = true;
                return;
            }
        }
        let new = new.get(..n).unwrap_or(&[]);
        if let Err(r) = legality::check_fan(
            &self.mesh,
            &self.rules,
            v,
            (fan.ring(), fan.boundary),
            new,
            &planes,
        ) {
            return self.rejected.count(r);
        }
        let mut tris = [[NIL; 3]; MAX_RING];
        for (t, s) in tris.iter_mut().zip(new) {
            *t = s.map(|k| fan.ring().get(k as usize).copied().unwrap_or(NIL));
        }
        if B::ON && on!(Bound) {
            if let Some(e) = self.bound.envelope() {
                if !e.allows_fill(&self.mesh, v, tris.get(..n).unwrap_or(&[])) {
                    return self.rejected.count(legality::Reject::Bound);
                }
            }
        }
        if self.mesh.replace_fan(v, tris.get(..n).unwrap_or(&[])) == 0 {
            // Nothing was replaced (cannot happen after `classify`): the vertex stays out.
            return;
        }
        if self.limit2.is_finite() && err2 > self.reached2 {
            self.reached2 = err2;
        }
        self.collapses += 1;
        self.pass_collapses += 1;
        for &x in fan.ring() {
            self.rekey(x);
        }
    }

    /// `v`'s new fan (`operator::plan`) and its key, if it has one.
    fn fill(
        &self,
        v: usize,
        fan: &crate::operator::RemovalFan,
        op: &crate::VertexDecimation,
        new: &mut [[u8; 3]; MAX_RING],
        planes: &mut [V3; MAX_RING],
    ) -> Option<(usize, f32, f32)> {
        let mut pos: [V3; MAX_RING] = [[0.0; 3]; MAX_RING];
        for (p, &x) in pos.iter_mut().zip(fan.ring()) {
            *p = self.mesh.p(x);
        }
        // Twice the mean triangle area of the last Mean sweep.
        let live = self.mesh.live as f32;
        let reference = if live > 0.0 {
            self.area2 / (3.0 * live)
        } else {
            0.0
        };
        plan(fan, self.mesh.p(v), &pos, op, reference, new, planes).ok()
    }
}
