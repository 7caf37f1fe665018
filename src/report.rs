//! What a run did: counts, rejections by rule, why it stopped.

use crate::legality::{Reject, Rule, RULES};

/// Maximum number of passes whose triangle counts a [`Report`] keeps.
pub const PASS_LOG: usize = 32;

/// Collapses refused, by rule: one count per row of [`RULES`]. A candidate is counted once
/// per evaluation, under the first rule that refuses it, so the figures say which rule binds
/// most, not how many distinct edges were refused.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Rejections {
    counts: [u32; Reject::COUNT],
}

impl Rejections {
    pub(crate) fn count(&mut self, r: Reject) {
        if let Some(c) = self.counts.get_mut(r as usize) {
            *c = c.saturating_add(1);
        }
    }

    /// The refusals counted under `r`.
    pub fn get(&self, r: Reject) -> u32 {
        self.counts.get(r as usize).copied().unwrap_or(0)
    }

    /// Each rule of [`RULES`] with its count, in the table's order.
    pub fn iter(&self) -> impl Iterator<Item = (&'static Rule, u32)> + '_ {
        RULES.iter().zip(self.counts.iter().copied())
    }

    /// All rejections together.
    pub fn total(&self) -> u32 {
        self.counts.iter().fold(0u32, |a, b| a.saturating_add(*b))
    }
}

/// `locked 0, feature 3, ..`: every rule's name and count, in the order of [`RULES`].
impl core::fmt::Display for Rejections {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        for (i, (rule, n)) in self.iter().enumerate() {
            let sep = if i == 0 { "" } else { ", " };
            write!(f, "{sep}{} {n}", rule.name)?;
        }
        Ok(())
    }
}

/// As [`Display`](core::fmt::Display): each rule's name with its count, so a device's log
/// says which rule refused what without the table at hand.
#[cfg(feature = "defmt")]
impl defmt::Format for Rejections {
    fn format(&self, f: defmt::Formatter<'_>) {
        for (i, (rule, n)) in self.iter().enumerate() {
            let sep = if i == 0 { "" } else { ", " };
            defmt::write!(f, "{=str:a}{=str:a} {=u32}", sep, rule.name, n);
        }
    }
}

/// Why the engine stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Stop {
    /// Still running (only seen in a report taken between steps).
    Running,
    /// The target triangle count was reached.
    Target,
    /// No legal collapse is left: every remaining one is locked, feature-protected or illegal.
    NoLegalCollapse,
    /// Every remaining legal collapse costs more than `max_cost`.
    MaxCost,
    /// The collapses left that the rules allow are over
    /// [`Config::error_limit`](crate::Config::error_limit): the target was not reached
    /// because reaching it would cut corners. Raise the limit to go further.
    ErrorLimit,
    /// `max_passes` passes were run ([`Schedule::Passes`](crate::Schedule::Passes)).
    MaxPasses,
    /// The collapse log given to [`Simplifier::record_into`](crate::Simplifier::record_into)
    /// is full: the mesh is valid and every collapse made is in the log.
    LogFull,
}

/// The outcome of a simplification.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Report {
    /// Triangles handed in.
    pub triangles_in: usize,
    /// Input triangles dropped because two of their indices were equal.
    pub degenerate_dropped: usize,
    /// Input triangles dropped because an earlier triangle had the same three vertices in the
    /// same winding.
    pub duplicates_dropped: usize,
    /// Input triangles that are an earlier triangle turned over (the back of a double-sided
    /// surface). They take no part in the run: each is written back after the output's other
    /// triangles, turned over from its front, if the front survived (and counted in
    /// `triangles_out`). The fronts aim for their share of the target; when they meet it the
    /// backs still to come are counted, and the share drops until the whole output is within
    /// the target.
    pub twins: usize,
    /// Triangles in the output (the prefix of the caller's buffer that holds the result).
    pub triangles_out: usize,
    /// The triangle count the engine aimed for.
    pub target_triangles: usize,
    /// Whether `triangles_out <= target_triangles`.
    pub target_reached: bool,
    /// Why it stopped.
    pub stop: Stop,
    /// Edge collapses performed (each removes one vertex).
    pub collapses: usize,
    /// Vertices that lost all their triangles.
    pub vertices_removed: usize,
    /// Parts (connected components) removed whole because they cost less than the collapses
    /// left (`Simplifier::with_parts`, crate feature `parts`); 0 otherwise.
    pub parts_removed: usize,
    /// Vertices locked because the mesh is not a manifold around them.
    pub locked_vertices: usize,
    /// Feature vertices found by the last global classification (the start of the last pass
    /// or round).
    pub feature_vertices: usize,
    /// Passes run. For `Greedy`, rounds: the queue is refilled with fresh feature flags each
    /// time it runs empty, until a round collapses nothing.
    pub passes: u32,
    /// Triangles after each pass (the first [`PASS_LOG`] passes).
    pub pass_triangles: heapless::Vec<u32, PASS_LOG>,
    /// Refused candidate collapses by reason.
    pub rejected: Rejections,
    /// Candidate collapses refused because their error was over
    /// [`Config::error_limit`](crate::Config::error_limit).
    pub over_limit: u32,
    /// With a finite [`Config::error_limit`](crate::Config::error_limit): the largest error
    /// of a collapse made, in the input's units (what the limit compares). Zero without one.
    pub collapse_error: f32,
    /// With an error bound ([`Controls`](crate::bound::Controls)):
    /// E_max of Zhu, Wang and Meng 2007 eq. 4, the largest distance of a control point (original
    /// centroid or feature-edge vertex) to its controlled triangle, in the input's units. Never
    /// more than [`Config::max_error`](crate::Config::max_error). `None` without a bound.
    pub max_error: Option<f32>,
    /// With an error bound: E_mean of Zhu, Wang and Meng 2007 eq. 5, `Σ dc_i·A_i / Σ A_i` over the
    /// original triangles' centroids (`A_i`: the original triangle's area), in the input's units.
    pub mean_error: Option<f32>,
}
