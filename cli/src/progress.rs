//! Progress bars for long steps (indicatif), on stderr only, only when stderr is a terminal,
//! and only once a step has run for a second (`TINYDECIMATE_PROGRESS_AFTER_MS` sets another
//! delay, for tests): pipes, files and CI logs never see them.

use std::io::IsTerminal;
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

/// How long a step runs before its bar appears.
pub const AFTER: Duration = Duration::from_secs(1);

/// A bar that stays hidden for the first [`AFTER`] of a step, and for good when stderr is not
/// a terminal.
pub struct Progress {
    bar: ProgressBar,
    after: Duration,
    start: Instant,
    enabled: bool,
    shown: std::cell::Cell<bool>,
}

impl Progress {
    /// A bar over `total` units with an indicatif `template`.
    pub fn new(template: &str, total: u64) -> Progress {
        let bar = ProgressBar::with_draw_target(Some(total), ProgressDrawTarget::hidden());
        if let Ok(style) = ProgressStyle::with_template(template) {
            bar.set_style(style);
        }
        let after = std::env::var("TINYDECIMATE_PROGRESS_AFTER_MS")
            .ok()
            .and_then(|v| v.parse().ok())
            .map_or(AFTER, Duration::from_millis);
        Progress {
            bar,
            after,
            start: Instant::now(),
            enabled: std::io::stderr().is_terminal(),
            shown: std::cell::Cell::new(false),
        }
    }

    /// Whether the bar can ever be drawn (stderr is a terminal).
    pub fn enabled(&self) -> bool {
        self.enabled
    }

    /// Sets the position; draws from the first call after [`AFTER`] (or the delay the
    /// environment sets).
    pub fn set(&self, pos: u64) {
        if self.enabled && !self.shown.get() && self.start.elapsed() >= self.after {
            self.bar.set_draw_target(ProgressDrawTarget::stderr());
            self.shown.set(true);
        }
        self.bar.set_position(pos);
    }

    /// Changes the total.
    pub fn set_len(&self, total: u64) {
        self.bar.set_length(total);
    }

    /// The position last set.
    pub fn position(&self) -> u64 {
        self.bar.position()
    }

    /// Removes the bar.
    pub fn finish(&self) {
        self.bar.finish_and_clear();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Under `cargo test` stderr is captured or piped, never a terminal here in CI: the bar
    /// never draws.
    #[test]
    fn hidden_when_stderr_is_not_a_terminal() {
        let p = Progress::new("{bar} {pos}/{len}", 10);
        if !std::io::stderr().is_terminal() {
            assert!(!p.enabled());
            p.set(5);
            assert!(p.bar.is_hidden());
        }
        p.finish();
    }
}
