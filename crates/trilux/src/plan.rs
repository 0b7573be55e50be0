//! Carrying out a command's plan: what `solve`, `render` and `bake` share.

use std::sync::Arc;
use std::sync::atomic::AtomicBool;

use trilux_solver::Progress;

use crate::progress::Bars;
use crate::record::Record;

/// What a command's plan did, and its record.
pub struct Finished {
    /// The plan's products and statistics.
    pub outcome: trilux::Outcome,
    /// How the run went (`record`).
    pub record: Record,
}

/// Checks `plan` against the scene read so far, reads the rest of it
/// (meshes, textures) and carries the plan out, with a progress bar
/// (`pipeline::check`, then `pipeline::run`, then a warning for a scene
/// without an emitter: after the work, so that an error stays one line,
/// and a dark scene's solve has no light to shoot and ends at once).
/// `stop`, when given, stops the solve between shots
/// (`crate::interrupt`).
pub fn run_plan(
    pending: trilux_scene::Pending,
    plan: &trilux::Plan<'_>,
    stop: Option<Arc<AtomicBool>>,
) -> anyhow::Result<Finished> {
    trilux::pipeline::check(pending.scene(), plan)?;
    let scene = pending.finish()?;
    crate::warn_loading(&scene);
    let bars = Bars::new();
    let mut on_shot = |p: &Progress| bars.solve(p);
    let on_tile = |done: usize, total: usize| bars.render(done, total);
    let read_seconds = crate::record::elapsed();
    let outcome = trilux::pipeline::run(
        &scene,
        plan,
        trilux::Observer {
            solve: &mut on_shot,
            render: &on_tile,
            stop,
        },
    );
    bars.finish();
    let outcome = outcome?;
    let record = Record::new(&scene, plan, &outcome, read_seconds)?;
    crate::warn_if_dark(&scene);
    Ok(Finished { outcome, record })
}
