//! Progress bars on a terminal, nothing otherwise (CI stays quiet).

use std::io::IsTerminal;

use indicatif::{ProgressBar, ProgressStyle};
use trilux_solver::Progress;

/// A progress bar labelled `what` on a terminal, `None` otherwise.
fn bar(len: u64, what: &str) -> Option<ProgressBar> {
    if !std::io::stderr().is_terminal() {
        return None;
    }
    let bar = ProgressBar::new(len);
    if let Ok(style) = ProgressStyle::with_template("{prefix} [{bar:40}] {msg} ({elapsed})") {
        bar.set_style(style.progress_chars("=> "));
    }
    bar.set_prefix(what.to_string());
    Some(bar)
}

/// The bars of one command: the solve's convergence and the render's tiles.
pub struct Bars {
    solve: Option<ProgressBar>,
    render: Option<ProgressBar>,
}

impl Bars {
    /// Bars for a solve and, with `render`, a render.
    pub fn new(render: bool) -> Self {
        Bars {
            solve: bar(1000, "solve"),
            render: if render { bar(1, "render") } else { None },
        }
    }

    /// Shows the solve's progress after a shot: how far the unshot
    /// remainder 1 − CR has fallen towards its target on a log scale (it
    /// falls about geometrically with the shots, so this moves about evenly
    /// in time), with the time left that its rate so far predicts.
    pub fn solve(&self, p: &Progress) {
        let Some(bar) = &self.solve else { return };
        let frac = convergence_fraction(p.convergence_ratio, p.target);
        bar.set_position((frac * 1000.0) as u64);
        let left = match time_left(frac, p.elapsed_seconds) {
            Some(s) => format!(", about {s:.0} s left"),
            None => String::new(),
        };
        let budget = match p.time_budget_seconds {
            Some(b) => format!(" (budget {b} s)"),
            None => String::new(),
        };
        bar.set_message(format!(
            "CR {:.4}/{:.4}{left}{budget}, shot {}, {} interactions, {} links",
            p.convergence_ratio, p.target, p.shots, p.interactions, p.live_links
        ));
    }

    /// Shows the render's progress after a tile.
    pub fn render(&self, done: usize, total: usize) {
        if let Some(s) = &self.solve {
            s.finish_and_clear();
        }
        let Some(bar) = &self.render else { return };
        bar.set_length(total as u64);
        bar.set_position(done as u64);
        bar.set_message(format!("{done}/{total} tiles"));
    }

    /// Clears every bar.
    pub fn finish(&self) {
        for b in [&self.solve, &self.render].into_iter().flatten() {
            b.finish_and_clear();
        }
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

/// Checks `plan` against the scene read so far, reads the rest of it
/// (meshes, textures) and carries the plan out, with bars for its solve
/// and, when it renders, its render (`pipeline::check`, then
/// `pipeline::run`, then a warning for a scene without an emitter: after
/// the work, so that an error stays one line, and a dark scene's solve
/// has no light to shoot and ends at once): what `solve`,
/// `render` and `bake` share.
pub fn run_plan(
    pending: trilux_scene::Pending,
    plan: &trilux::Plan<'_>,
) -> anyhow::Result<trilux::Outcome> {
    trilux::pipeline::check(pending.scene(), plan)?;
    let scene = pending.finish()?;
    crate::warn_loading(&scene);
    let bars = Bars::new(plan.render.is_some());
    let mut on_shot = |p: &Progress| bars.solve(p);
    let on_tile = |done: usize, total: usize| bars.render(done, total);
    let outcome = trilux::pipeline::run(
        &scene,
        plan,
        trilux::Observer {
            solve: &mut on_shot,
            render: &on_tile,
        },
    );
    bars.finish();
    let outcome = outcome?;
    crate::warn_if_dark(&scene);
    Ok(outcome)
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
