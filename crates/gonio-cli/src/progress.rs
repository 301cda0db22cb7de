//! The progress bar on standard error: shown only when stderr is a terminal, `--quiet` was not
//! given, and the work has been running for more than [`DELAY`] (short runs stay silent).

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// How long work runs before its bar appears.
pub const DELAY: Duration = Duration::from_secs(1);

/// A progress bar that stays hidden for its first [`DELAY`], and for good when stderr is not a
/// terminal or `--quiet` is set.
pub struct Progress {
    bar: ProgressBar,
    start: Instant,
    enabled: bool,
    shown: AtomicBool,
}

impl Progress {
    /// A bar over `total` units (e.g. samples), labelled `label`; never shown when `quiet`
    /// (`--quiet`).
    pub fn new(total: u64, label: &str, quiet: bool) -> Self {
        let enabled = !quiet && std::io::stderr().is_terminal();
        let bar = ProgressBar::with_draw_target(Some(total), ProgressDrawTarget::hidden());
        bar.set_style(
            ProgressStyle::with_template(
                "{prefix} [{elapsed_precise}] {wide_bar} {pos}/{len} ({eta}) {msg}",
            )
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
        );
        bar.set_prefix(label.to_string());
        Progress {
            bar,
            start: Instant::now(),
            enabled,
            shown: AtomicBool::new(false),
        }
    }

    /// A bar over a fraction in [0, 1] (shown in per mille).
    pub fn fraction(label: &str, quiet: bool) -> Self {
        let p = Self::new(1000, label, quiet);
        p.bar.set_style(
            ProgressStyle::with_template(
                "{prefix} [{elapsed_precise}] {wide_bar} {percent}% {msg}",
            )
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
        );
        p
    }

    fn reveal(&self) {
        if self.enabled
            && !self.shown.load(Ordering::Relaxed)
            && self.start.elapsed() >= DELAY
            && !self.shown.swap(true, Ordering::Relaxed)
        {
            self.bar.set_draw_target(ProgressDrawTarget::stderr());
        }
    }

    /// Sets the position.
    pub fn set(&self, pos: u64) {
        self.bar.set_position(pos);
        self.reveal();
    }

    /// Sets the fraction done (for bars made by [`Progress::fraction`]) and the message.
    pub fn set_fraction(&self, fraction: f64, msg: &str) {
        self.bar
            .set_position((fraction.clamp(0.0, 1.0) * 1000.0).round() as u64);
        self.bar.set_message(msg.to_string());
        self.reveal();
    }
}

impl Drop for Progress {
    fn drop(&mut self) {
        self.bar.finish_and_clear();
    }
}
