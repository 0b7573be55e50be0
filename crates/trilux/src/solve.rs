//! `trilux solve SCENE -o FILE`: solve the light once and save it, so that
//! any number of views can be rendered from it (design.md §3).

use std::io::IsTerminal;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use trilux_color::Mode;
use trilux_solver::{Quality, SceneInput, Solution, Solver, SolverSettings, solve_hash};

use crate::ModeArg;

/// Solver options shared by `solve` and `render`.
#[derive(Debug, Args, Clone)]
pub struct SolveOptions {
    /// Quality preset: error bounds, depth limit and default convergence.
    #[arg(long, value_parser = ["draft", "default", "high"], default_value = "default")]
    pub quality: String,
    /// Target convergence ratio CR = (IF − RF)/IF in [0, 1] (default from
    /// --quality: 0.95, 0.999, 0.9999).
    #[arg(long)]
    pub convergence: Option<f64>,
    /// Override the scene's colour mode.
    #[arg(long, value_enum)]
    pub mode: Option<ModeArg>,
}

impl SolveOptions {
    /// The solver settings these options ask for.
    pub fn settings(&self) -> Result<SolverSettings> {
        let quality: Quality = self.quality.parse().map_err(anyhow::Error::msg)?;
        let mut settings = SolverSettings::preset(quality);
        if let Some(cr) = self.convergence {
            anyhow::ensure!(
                cr.is_finite() && (0.0..=1.0).contains(&cr),
                "--convergence must be in [0, 1], got {cr}"
            );
            settings.convergence = cr;
        }
        Ok(settings)
    }

    /// The colour mode: the override, else the scene's own.
    pub fn mode(&self, scene: &trilux_scene::Scene) -> Mode {
        match self.mode {
            Some(ModeArg::Rgb) => Mode::Rgb,
            Some(ModeArg::Spectral) => Mode::Spectral,
            None => scene.mode(),
        }
    }
}

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
    #[command(flatten)]
    pub options: SolveOptions,
}

/// A progress bar on a terminal, nothing otherwise (CI stays quiet).
pub fn progress_bar(len: u64, what: &str) -> Option<ProgressBar> {
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

/// Solves `input` with `N` bands, reporting convergence on a progress bar.
pub fn solve_with_progress<const N: usize>(
    input: &SceneInput,
    settings: SolverSettings,
) -> Result<Solution<N>> {
    let solver = Solver::<N>::new(&input.as_input(), settings)?;
    let bar = progress_bar(1000, "solve");
    let solution = solver.solve(|p| {
        if let Some(bar) = &bar {
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
    });
    if let Some(bar) = bar {
        bar.finish_and_clear();
    }
    Ok(solution)
}

/// Writes JSON atomically (temporary file, then rename).
pub fn write_json(path: &Path, value: &impl serde::Serialize) -> Result<()> {
    let text = serde_json::to_string_pretty(value)?;
    let tmp = path.with_extension("tmp-trilux");
    std::fs::write(&tmp, text).with_context(|| format!("{}: cannot write", path.display()))?;
    std::fs::rename(&tmp, path).map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        anyhow::anyhow!("{}: cannot write: {e}", path.display())
    })
}

fn solve_and_save<const N: usize>(
    args: &SolveArgs,
    input: &SceneInput,
    settings: SolverSettings,
) -> Result<()> {
    let hash = solve_hash(&input.as_input(), &settings, N);
    let solution = solve_with_progress::<N>(input, settings)?;
    solution.save(&args.output, hash)?;
    if let Some(path) = &args.stats {
        let mut stats = solution.stats().clone();
        stats.warnings.clear();
        write_json(path, &crate::stats_json(solution.stats(), 0.0))?;
    }
    for w in &solution.stats().warnings {
        eprintln!("warning: {w}");
    }
    Ok(())
}

/// Runs `trilux solve`.
pub fn run(args: &SolveArgs) -> Result<()> {
    let scene = trilux_scene::load(&args.scene)?;
    let settings = args.options.settings()?;
    let input = SceneInput::from_scene(&scene);
    match args.options.mode(&scene) {
        Mode::Rgb => solve_and_save::<3>(args, &input, settings),
        Mode::Spectral => {
            solve_and_save::<{ trilux_color::SPECTRAL_BANDS }>(args, &input, settings)
        }
    }
}
