//! Pricing a collapse and checking it: the cheap flag and boundary rules that make a key a lower
//! bound, the placement of the kept vertex, then the legality rules and the bound's veto.

use super::walk::{FanSummary, MAX_CANDIDATES};
use super::Simplifier;
use crate::index::Index;
use crate::math::{self, V3};
use crate::mesh::{flag, NIL};
use crate::operator::Operator;
use crate::policy::bound::Bound;
use crate::policy::cost::{Cost, Move};
use crate::policy::legality::{self, on};

impl<'a, L: Index, I: Index, C: Cost, B: Bound<'a, I>, O: Operator> Simplifier<'a, L, I, C, B, O> {
    /// The legality rules for `from -> to` (at `at` if the cost places the kept vertex), then
    /// the error bound's veto.
    #[inline(always)]
    pub(super) fn check(
        &self,
        from: usize,
        to: usize,
        at: Option<V3>,
    ) -> Result<(), crate::Reject> {
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
            if let Some(e) = self.bound.envelope() {
                if !e.allows(&self.mesh, from, to) {
                    return Err(crate::Reject::Bound);
                }
            }
        }
        Ok(())
    }

    /// The price of moving `from` (walked as `w`) onto `to`, if the flag and boundary rules
    /// allow it: the cheap half of legality, enough for a lower bound.
    pub(super) fn price(&self, from: usize, w: &FanSummary<C::Fan>, to: usize) -> Option<f32> {
        self.price_kept(from, w, to, false)
    }

    /// [`Self::price`]; with `keep`, at `to`'s own position even for a placing cost.
    pub(super) fn price_kept(
        &self,
        from: usize,
        w: &FanSummary<C::Fan>,
        to: usize,
        keep: bool,
    ) -> Option<f32> {
        self.price_with(from, self.mesh.flags(from), w, to, keep)
    }

    /// [`Self::price_kept`] with `from`'s flags `ff` already read: the move built in place,
    /// not returned through memory by a call (one copy, for flash).
    #[inline(never)]
    fn price_with(
        &self,
        from: usize,
        ff: u8,
        w: &FanSummary<C::Fan>,
        to: usize,
        keep: bool,
    ) -> Option<f32> {
        let m = self.move_of(from, ff, w, to, keep)?;
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
    pub(super) fn movable(&self) -> bool {
        C::PLACES && self.mesh.movable()
    }

    /// The move `from -> to` as a cost sees it, if the flag and boundary rules allow it.
    pub(super) fn make_move(
        &self,
        from: usize,
        w: &FanSummary<C::Fan>,
        to: usize,
        keep: bool,
    ) -> Option<Move> {
        self.move_of(from, self.mesh.flags(from), w, to, keep)
    }

    /// [`Self::make_move`] with `from`'s flags `ff` already read, inlined into its caller.
    #[inline(always)]
    fn move_of(
        &self,
        from: usize,
        ff: u8,
        w: &FanSummary<C::Fan>,
        to: usize,
        keep: bool,
    ) -> Option<Move> {
        let mesh = &self.mesh;
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
            // A feature or locked vertex stays where it is.
            keep: keep || !self.movable() || mesh.flags(to) & (flag::FEATURE | flag::LOCKED) != 0,
        })
    }

    /// Where the kept vertex of `from -> to` goes if the cost places it (optimal placement on
    /// mutable positions): its input-unit coordinates and the normalised position they read
    /// back as. `None`: it stays.
    pub(super) fn placement(
        &self,
        from: usize,
        w: &FanSummary<C::Fan>,
        to: usize,
    ) -> Option<([f32; 3], V3)> {
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
    pub(super) fn legal(
        &self,
        from: usize,
        w: &FanSummary<C::Fan>,
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
    pub(super) fn legal_placed(
        &self,
        from: usize,
        w: &FanSummary<C::Fan>,
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

    /// The prices of `v`'s candidates (`w`'s neighbours, in fan order) into `out`,
    /// `INFINITY` where the flag and boundary rules refuse one. One price per neighbour, no
    /// vertex numbers: those are `w.nb` (the micro:bit's stack).
    pub(super) fn prices(&self, v: usize, w: &FanSummary<C::Fan>, out: &mut [f32; MAX_CANDIDATES]) {
        let ff = self.movable_flags(v);
        for (x, slot) in w.neighbours().zip(out.iter_mut()) {
            *slot = ff
                .and_then(|ff| self.price_with(v, ff, w, x, false))
                .unwrap_or(f32::INFINITY);
        }
    }

    /// The least price among `v`'s candidates (`INFINITY`: none), without an array.
    pub(super) fn least(&self, v: usize, w: &FanSummary<C::Fan>) -> f32 {
        let mut key = f32::INFINITY;
        let Some(ff) = self.movable_flags(v) else {
            return key;
        };
        for x in w.neighbours() {
            if let Some(p) = self.price_with(v, ff, w, x, false) {
                if p < key {
                    key = p;
                }
            }
        }
        key
    }

    /// `v`'s flags, or `None` if the flag rules refuse every move of `v` whatever the kept
    /// vertex (unused, locked, a feature): then no candidate of its walk is priced.
    #[inline(always)]
    fn movable_flags(&self, v: usize) -> Option<u8> {
        let ff = self.mesh.flags(v);
        legality::flags_allow(&self.rules, ff, flag::USED).ok()?;
        Some(ff)
    }
}

/// Removes and returns the cheapest `(price, vertex)` among the first `n` of `prices` (finite
/// prices only; `nb` the vertices in the same order; ties: lower vertex), if any is left.
pub(super) fn take_cheapest_of(prices: &mut [f32], nb: &[u32], n: usize) -> Option<(f32, usize)> {
    let mut min: Option<(f32, u32, usize)> = None;
    for (i, (&c, &x)) in prices.iter().zip(nb).take(n).enumerate() {
        if c.is_finite() && min.is_none_or(|(m, y, _)| less((c, x as usize), (m, y as usize))) {
            min = Some((c, x, i));
        }
    }
    let (c, x, i) = min?;
    if let Some(slot) = prices.get_mut(i) {
        *slot = f32::INFINITY;
    }
    Some((c, x as usize))
}

/// Removes and returns the cheapest `(price, vertex)` (ties: lower vertex), if any is left.
pub(super) fn take_cheapest(cand: &mut [(f32, usize)]) -> Option<(f32, usize)> {
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

/// `(cost, vertex)` order: cheaper first, then the lower vertex number.
#[inline]
fn less(a: (f32, usize), b: (f32, usize)) -> bool {
    a.0 < b.0 || (a.0 == b.0 && a.1 < b.1)
}

#[cfg(test)]
mod tests {
    use super::take_cheapest_of;

    /// Cheapest first, ties on the lower vertex, refused (infinite) prices and the slots past
    /// the fan's own candidates never taken.
    #[test]
    fn cheapest_then_lower_vertex() {
        let inf = f32::INFINITY;
        let mut prices = [2.0, inf, 1.0, 1.0, 0.5, 0.0];
        let nb = [7, 3, 9, 4, 8, 1];
        let mut order = [(0.0, 0); 6];
        let mut n = 0;
        while let Some(c) = take_cheapest_of(&mut prices, &nb, 5) {
            order[n] = c;
            n += 1;
        }
        // Slot 5 (price 0, vertex 1) is past the fan's 5 candidates; slot 1 was refused.
        assert_eq!(n, 4);
        assert_eq!(order[..4], [(0.5, 8), (1.0, 4), (1.0, 9), (2.0, 7)]);
    }
}
