//! The progress bar of `solve`, `render` and `bake` on a terminal, nothing
//! otherwise (CI stays quiet).

use std::io::IsTerminal;
use std::sync::atomic::{AtomicBool, Ordering};

use indicatif::{ProgressBar, ProgressStyle};
use trilux_solver::Progress;

/// The one bar of a command, `None` when stderr is not a terminal. The
/// message is `{wide_msg}`: cut to the terminal's width, so that the bar
/// stays one line and clearing it leaves nothing behind.
fn bar() -> Option<ProgressBar> {
    if !std::io::stderr().is_terminal() {
        return None;
    }
    let bar = ProgressBar::new(1000);
    if let Ok(style) = ProgressStyle::with_template("{prefix} [{bar:30}] {elapsed} {wide_msg}") {
        bar.set_style(style.progress_chars("=> "));
    }
    bar.set_prefix("solve");
    Some(bar)
}

/// The progress of one command (`solve`, `render`, `bake`): one bar,
/// the solve's convergence and then the render's tiles, each with the time
/// left that its rate so far predicts ([`time_left`]).
pub struct Bars {
    bar: Option<ProgressBar>,
    /// Set by the first tile: the bar then shows the render.
    rendering: AtomicBool,
}

impl Bars {
    /// The bar of a command (on a terminal).
    pub fn new() -> Self {
        Bars {
            bar: bar(),
            rendering: AtomicBool::new(false),
        }
    }

    /// Shows the solve's progress after a shot: how far the unshot
    /// remainder 1 − CR has fallen towards its target on a log scale (it
    /// falls about geometrically with the shots, so this moves about evenly
    /// in time), with the time left that its rate so far predicts.
    pub fn solve(&self, p: &Progress) {
        let Some(bar) = &self.bar else { return };
        let frac = convergence_fraction(p.convergence_ratio, p.target);
        bar.set_position((frac * 1000.0) as u64);
        let budget = match p.time_budget_seconds {
            Some(b) => format!(" (budget {b} s)"),
            None => String::new(),
        };
        bar.set_message(format!(
            "{}CR {:.4}/{:.4}{budget}, shot {}, {} interactions, {} links",
            left(time_left(frac, p.elapsed_seconds)),
            p.convergence_ratio,
            p.target,
            p.shots,
            p.interactions,
            p.live_links
        ));
    }

    /// Shows the render's progress after a tile (from worker threads); the
    /// first tile turns the bar into the render's, its clock restarted.
    pub fn render(&self, done: usize, total: usize) {
        let Some(bar) = &self.bar else { return };
        if !self.rendering.swap(true, Ordering::AcqRel) {
            bar.set_prefix("render");
            bar.set_message("");
            bar.reset();
        }
        bar.set_length(total.max(1) as u64);
        bar.set_position(done as u64);
        let frac = done as f64 / total.max(1) as f64;
        let seconds = bar.elapsed().as_secs_f64();
        bar.set_message(format!(
            "{}{done}/{total} tiles",
            left(time_left(frac, seconds))
        ));
    }

    /// Clears the bar: the terminal is left as it was before.
    pub fn finish(&self) {
        if let Some(bar) = &self.bar {
            bar.finish_and_clear();
        }
    }
}

impl Default for Bars {
    fn default() -> Self {
        Self::new()
    }
}

/// "about N s left, " when there is an estimate, else nothing.
fn left(seconds: Option<f64>) -> String {
    match seconds {
        Some(s) if s < 10.0 => format!("about {s:.1} s left, "),
        Some(s) => format!("about {s:.0} s left, "),
        None => String::new(),
    }
}

/// How far the unshot remainder 1 − CR has come from 1 towards 1 − target,
/// on a log scale, in [0, 1].
fn convergence_fraction(cr: f64, target: f64) -> f64 {
    let (gap, goal) = (1.0 - cr, 1.0 - target);
    let frac = if !gap.is_finite() {
        0.0
    } else if goal <= 0.0 || goal >= 1.0 {
        cr
    } else if gap <= goal {
        1.0
    } else {
        gap.max(f64::MIN_POSITIVE).ln() / goal.ln()
    };
    if frac.is_finite() {
        frac.clamp(0.0, 1.0)
    } else {
        0.0
    }
}

/// The seconds left if the fraction keeps growing at its rate so far
/// (`None` before there is a rate to go by).
fn time_left(frac: f64, elapsed: f64) -> Option<f64> {
    (frac > 0.01 && frac < 1.0 && elapsed > 0.0).then(|| elapsed * (1.0 - frac) / frac)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_fraction_is_the_log_of_the_remainder_over_the_log_of_its_target() {
        // 1 − CR from 1 to 0.001: 0.1 is a third of the way (log scale).
        assert!((convergence_fraction(0.9, 0.999) - 1.0 / 3.0).abs() < 1e-12);
        assert_eq!(convergence_fraction(0.0, 0.999), 0.0);
        assert_eq!(convergence_fraction(0.9995, 0.999), 1.0);
        assert_eq!(convergence_fraction(1.0, 0.999), 1.0);
        // A target of 1 (or 0) has no log scale: CR itself.
        assert_eq!(convergence_fraction(0.5, 1.0), 0.5);
        assert_eq!(convergence_fraction(f64::NAN, 0.999), 0.0);
    }

    #[test]
    fn the_time_left_extrapolates_the_rate_so_far() {
        // A quarter of the way in 10 s: 30 s to go at that rate.
        assert_eq!(time_left(0.25, 10.0), Some(30.0));
        assert_eq!(time_left(0.0, 10.0), None);
        assert_eq!(time_left(1.0, 10.0), None);
    }
}
