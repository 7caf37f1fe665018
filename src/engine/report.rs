//! The run's report, and finishing a run.

use super::{Phase, Simplifier};
use crate::index::Index;
use crate::mesh::NIL;
use crate::operator::Operator;
use crate::policy::bound::Bound;
use crate::policy::cost::Cost;
use crate::report::{Report, Stop};

impl<'a, L: Index, I: Index, C: Cost, B: Bound<'a, I>, O: Operator> Simplifier<'a, L, I, C, B, O> {
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
            target_triangles: self.target_out,
            target_reached: self.mesh.live <= self.target,
            twins: self.mesh.twins,
            stop,
            collapses: self.collapses,
            vertices_removed: self.used_in.saturating_sub(used),
            parts_removed: self.parts_removed(),
            locked_vertices: self.locked,
            feature_vertices: self.features,
            passes: self.passes,
            pass_triangles: self.pass_triangles.clone(),
            rejected: self.rejected,
            over_limit: self.over_limit,
            collapse_error: self
                .mesh
                .input_length(if self.reached2 >= f32::MIN_POSITIVE {
                    self.reached2 * crate::math::rsqrt(self.reached2)
                } else {
                    0.0
                }),
            max_error: errors.map(|e| e.0),
            mean_error: errors.map(|e| e.1),
        }
    }

    /// Compacts the result into the front of the caller's buffer and returns the report.
    /// Finishing early (before `step` returned `true`) keeps the valid mesh reached so far.
    pub fn finish(mut self) -> Report {
        let report = self.report();
        #[cfg(feature = "seams")]
        let n = self.mesh.compact(self.heap.spent());
        #[cfg(not(feature = "seams"))]
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
            // With twins the fronts met their share; the whole output is what counts.
            target_reached: if self.mesh.twins == 0 {
                report.target_reached
            } else {
                n <= self.target_out
            },
            ..report
        }
    }

    pub(super) fn done(&mut self, stop: Stop) {
        if self.pass_collapses > 0 || self.pass_triangles.is_empty() {
            self.log_pass();
        }
        self.phase = Phase::Done(stop);
    }

    pub(super) fn log_pass(&mut self) {
        // Full log: later passes are still counted in `passes`.
        let _ = self.pass_triangles.push(self.mesh.live as u32);
    }
}
