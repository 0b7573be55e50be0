//! `trilux solve SCENE -o FILE`: solve the light once and save it, so that
//! any number of views can be rendered from it.

use std::path::PathBuf;

use anyhow::Result;
use clap::Args;
use trilux_render::{Observer, Plan, SolutionSource};

use crate::options::{SolveOptions, check_distinct, check_output, parse_positive};
use crate::output::{stats_json, write_json};
use crate::progress::Bars;

/// Arguments of `trilux solve`.
#[derive(Debug, Args)]
pub struct SolveArgs {
    /// The scene file (Mitsuba 3 XML subset).
    pub scene: PathBuf,
    /// Where to write the solution.
    #[arg(short = 'o', long = "output")]
    pub output: PathBuf,
    /// Write solve statistics as JSON.
    #[arg(long)]
    pub stats: Option<PathBuf>,
    /// Worker threads (default: all cores).
    #[arg(long, value_parser = parse_positive)]
    pub threads: Option<u32>,
    #[command(flatten)]
    pub options: SolveOptions,
}

/// Runs `trilux solve`.
pub fn run(args: &SolveArgs) -> Result<()> {
    crate::set_threads(args.threads);
    check_output(&args.output, "solution")?;
    let mut outputs = vec![(args.output.as_path(), "solution")];
    if let Some(stats) = &args.stats {
        check_output(stats, "statistics")?;
        outputs.push((stats.as_path(), "statistics"));
    }
    check_distinct(&[args.scene.as_path()], &outputs)?;
    let scene = trilux_scene::load(&args.scene)?;
    let plan = Plan {
        mode: args.options.mode(&scene),
        solver: args.options.settings(),
        source: SolutionSource::Solve,
        save: Some(&args.output),
        render: None,
    };
    let bars = Bars::new(false);
    let mut on_shot = |p: &trilux_solver::Progress| bars.solve(p);
    let outcome = trilux_render::pipeline::run(
        &scene,
        &plan,
        Observer {
            solve: &mut on_shot,
            render: &|_, _| {},
        },
    );
    bars.finish();
    let outcome = outcome?;
    if let Some(path) = &args.stats {
        write_json(path, &stats_json(&outcome.solve, 0.0))?;
    }
    for w in &outcome.solve.warnings {
        eprintln!("warning: {w}");
    }
    Ok(())
}
