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

    /// Shows the solve's progress after a shot.
    pub fn solve(&self, p: &Progress) {
        let Some(bar) = &self.solve else { return };
        let frac = if p.target > 0.0 {
            p.convergence_ratio / p.target
        } else {
            1.0
        };
        bar.set_position((frac.clamp(0.0, 1.0) * 1000.0) as u64);
        bar.set_message(format!(
            "CR {:.4}/{:.4}, shot {}, {} interactions, {} links",
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
