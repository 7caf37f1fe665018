//! The collapse log: `[removed, kept]` per collapse, for progressive meshes.

use super::Simplifier;
use crate::index::Index;
use crate::operator::Operator;
use crate::policy::bound::Bound;
use crate::policy::cost::Cost;
use crate::report::Stop;

impl<'a, L: Index, I: Index, C: Cost, B: Bound<'a, I>, O: Operator> Simplifier<'a, L, I, C, B, O> {
    /// Welded seams ([`crate::seam`]): `wedges` holds each triangle's corners as the caller's
    /// vertices (filled by [`seam::weld`](crate::seam::weld), which also renumbered the
    /// triangles given to the run to one vertex per position). Call it before the first step.
    /// Collapses keep it up to date, and [`Simplifier::finish`] writes the result's triangles
    /// as wedges; until then [`Simplifier::triangles`] and [`Simplifier::buffer`] show the
    /// welded numbering. `corners` says what a vertex where more than two wedges meet may do.
    /// [`Error::Capacity`](crate::Error::Capacity) (triangles) if `wedges` is shorter than the
    /// triangle buffer.
    #[cfg(feature = "seams")]
    pub fn with_wedges(
        mut self,
        wedges: &'a mut [[I; 3]],
        corners: crate::seam::SeamCorners,
    ) -> Result<Self, crate::Error> {
        let n = self.mesh.triangle_count();
        let available = wedges.len();
        match wedges.get_mut(..n) {
            Some(w) => {
                self.mesh.wedges = w;
                self.mesh.lock_corners = corners == crate::seam::SeamCorners::Lock;
                Ok(self)
            }
            None => Err(crate::Error::Capacity {
                what: crate::Capacity::Triangles,
                needed: n,
                available,
            }),
        }
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
    pub(super) fn log_collapse(&mut self, a: usize, b: usize) -> bool {
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
}
