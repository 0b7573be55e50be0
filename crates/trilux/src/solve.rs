//! `trilux solve SCENE [-o FILE]`: solve the light once and save it, so
//! that any number of views can be rendered from it.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use crate::options::{Product, SolveOptions, parse_threads};
use crate::output::{DEFAULT_FOLDER, Kind, Outputs, default_output, named, stats_json};
use anyhow::{Context, Result};
use clap::Args;

/// Arguments of `trilux solve`.
#[derive(Debug, Args)]
pub struct SolveArgs {
    /// The scene file (Mitsuba 3 XML subset, or glTF 2.0: .gltf, .glb).
    pub scene: PathBuf,
    #[command(flatten)]
    pub params: crate::options::SceneParams,
    /// Where to write the solution (any name but an image's, a glTF
    /// file's or a JSON file's). Default: out/<scene name>.sol (the folder is made when
    /// missing).
    #[arg(short = 'o', long = "output")]
    pub output: Option<PathBuf>,
    /// Write solve statistics as JSON.
    #[arg(long)]
    pub stats: Option<PathBuf>,
    /// Worker threads (default: all cores).
    #[arg(long, value_parser = parse_threads)]
    pub threads: Option<u32>,
    #[command(flatten)]
    pub options: SolveOptions,
}

/// Runs `trilux solve`: status 0, or 128 + the signal's number when
/// SIGINT or SIGTERM stopped it (`crate::interrupt`).
pub fn run(args: &SolveArgs) -> Result<ExitCode> {
    let output = match &args.output {
        Some(path) => {
            named(path, "-o", Kind::Solution)?;
            path.clone()
        }
        None => default_output(&args.scene, "sol"),
    };
    crate::set_threads(args.threads);
    let mut outputs = vec![(output.as_path(), "solution")];
    outputs.extend(args.stats.as_deref().map(|p| (p, "statistics")));
    let folder = args.output.is_none().then(|| Path::new(DEFAULT_FOLDER));
    let outputs = Outputs::plan(&outputs, &[args.scene.as_path()], folder)?;
    let pending = trilux_scene::open_with_params(&args.scene, &args.params.define)?;
    outputs.check_inputs(&pending.input_files())?;
    let interrupt = crate::interrupt::Interrupt::catch()?;
    let plan = args
        .options
        .plan(pending.scene(), None, Product::SolutionFile);
    let crate::plan::Finished {
        mut outcome,
        record,
    } = crate::plan::run_plan(pending, &plan, Some(interrupt.flag()))?;
    let solution = outcome
        .solution_file
        .take()
        .context("the solve produced no solution file")?;
    let mut files = vec![solution];
    if args.stats.is_some() {
        files.push(stats_json(&outcome.solve, None, 0.0, &record)?);
    }
    outputs.write(&files)?;
    crate::warn(&outcome);
    outputs.report(None)?;
    Ok(interrupt.status().map_or(ExitCode::SUCCESS, ExitCode::from))
}
