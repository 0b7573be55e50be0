//! The progress of `solve`, `render` and `bake`: a bar on a terminal;
//! elsewhere (a CI log, a scheduler's log file) a plain line now and then
//! (`Plain`), so that a long run shows it is alive and how far it got, and
//! a short one stays quiet.

use std::io::IsTerminal;
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

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
    /// The plain lines when stderr is not a terminal.
    plain: Option<Plain>,
    /// Set by the first tile: the bar then shows the render.
    rendering: AtomicBool,
}

impl Bars {
    /// The bar of a command (on a terminal).
    pub fn new() -> Self {
        let bar = bar();
        let plain = bar.is_none().then(Plain::new);
        Bars {
            bar,
            plain,
            rendering: AtomicBool::new(false),
        }
    }

    /// Shows the solve's progress after a shot: how far the unshot
    /// remainder 1 − CR has fallen towards its target on a log scale (it
    /// falls about geometrically with the shots, so this moves about evenly
    /// in time), with the time left that its rate so far predicts.
    pub fn solve(&self, p: &Progress) {
        if let Some(plain) = &self.plain {
            plain.report(solve_line(p));
        }
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
        let first = !self.rendering.swap(true, Ordering::AcqRel);
        if let Some(plain) = &self.plain {
            if first {
                plain.end_phase();
            }
            let seconds = plain.phase_seconds();
            plain.report(format!("render: {done}/{total} tiles after {seconds:.1} s"));
        }
        let Some(bar) = &self.bar else { return };
        if first {
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
        if let Some(plain) = &self.plain {
            plain.end_phase();
        }
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

/// The plain line of the solve's progress.
fn solve_line(p: &Progress) -> String {
    format!(
        "solve: CR {:.4} (target {}) after {:.1} s, {} shots",
        p.convergence_ratio, p.target, p.elapsed_seconds, p.shots
    )
}

/// The default seconds between two plain progress lines.
const PLAIN_SECONDS: f64 = 10.0;

/// Progress as plain lines on a stderr that is not a terminal: one line
/// every `TRILUX_PROGRESS_SECONDS` (default 10 s), no carriage return,
/// and the phase's last state when a phase (solve, render) that printed a
/// line ends. A run shorter than the interval prints nothing.
struct Plain {
    every: Duration,
    state: Mutex<PlainState>,
}

struct PlainState {
    /// When the last line was printed (or the phase began).
    last: Instant,
    /// When the current phase began.
    phase_start: Instant,
    /// The current phase's latest line, if not printed yet.
    pending: Option<String>,
    /// Whether the current phase printed a line.
    printed: bool,
}

impl Plain {
    fn new() -> Self {
        let every = std::env::var("TRILUX_PROGRESS_SECONDS")
            .ok()
            .map(|v| match v.trim().parse::<f64>() {
                Ok(s) if s.is_finite() && s > 0.0 && s < 1e9 => s,
                _ => {
                    crate::streams::eprint_line(&format!(
                        "warning: TRILUX_PROGRESS_SECONDS={v:?} is not a number of seconds above 0: a progress line every {PLAIN_SECONDS} s"
                    ));
                    PLAIN_SECONDS
                }
            })
            .unwrap_or(PLAIN_SECONDS);
        let now = Instant::now();
        Plain {
            every: Duration::from_secs_f64(every),
            state: Mutex::new(PlainState {
                last: now,
                phase_start: now,
                pending: None,
                printed: false,
            }),
        }
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, PlainState> {
        self.state.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Seconds since the current phase began.
    fn phase_seconds(&self) -> f64 {
        self.lock().phase_start.elapsed().as_secs_f64()
    }

    /// Prints `line` if the interval has passed since the last one, else
    /// keeps it for the end of the phase.
    fn report(&self, line: String) {
        let mut st = self.lock();
        if st.last.elapsed() >= self.every {
            crate::streams::eprint_line(&line);
            st.last = Instant::now();
            st.printed = true;
            st.pending = None;
        } else {
            st.pending = Some(line);
        }
    }

    /// Ends a phase: its last state, if it printed a line and has a newer
    /// one; the next phase starts its clock.
    fn end_phase(&self) {
        let mut st = self.lock();
        if let Some(line) = st.pending.take()
            && st.printed
        {
            crate::streams::eprint_line(&line);
        }
        let now = Instant::now();
        (st.last, st.phase_start, st.printed) = (now, now, false);
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
