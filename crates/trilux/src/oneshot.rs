//! The one-call API: from a scene file to an image ([`render_file`]), a
//! solution file's bytes ([`solve_scene`]) or a bake ([`bake_scene`]),
//! with the `trilux` command's defaults, so that a program (the examples,
//! the Python module `trilux-py`) gets the command's image for the same
//! settings without assembling a [`Plan`].
//!
//! Each call is one [`Plan`] carried out by [`crate::pipeline::run`], the
//! command's own orchestration: the scene's camera and film, its sample
//! count unless `spp` is given, the path gather with the extra bounce
//! everywhere, the quality preset's solver settings. A renderer seeded the
//! same gives the same image as `trilux render` with the same flags.

use std::path::Path;

use trilux_color::Mode;
use trilux_render::{ExtraBounce, Image};
use trilux_scene::Scene;
use trilux_solver::{Quality, SolverSettings};

use crate::error::PipelineError;
use crate::pipeline::{Observer, Outcome, Plan, RenderPlan, SolutionSource, run};
use crate::view::{ViewOverrides, apply_integrator, render_settings};

/// How the light is solved: the command's `--quality`, `--convergence`
/// and `--mode`. A saved solution must have been made with the same.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub struct SolveOptions {
    /// The preset: error bounds, depth limit, default convergence.
    pub quality: Quality,
    /// The target convergence ratio, in [0, 1] (default: the preset's).
    pub convergence: Option<f64>,
    /// RGB or spectral (default: the scene's own).
    pub mode: Option<Mode>,
}

impl Default for SolveOptions {
    fn default() -> Self {
        SolveOptions {
            quality: Quality::Default,
            convergence: None,
            mode: None,
        }
    }
}

impl SolveOptions {
    /// The solver settings these options ask for.
    pub fn settings(&self) -> SolverSettings {
        let mut settings = SolverSettings::preset(self.quality);
        if let Some(cr) = self.convergence {
            settings.convergence = cr;
        }
        settings
    }

    /// The colour mode: the one asked for, else the scene's.
    pub fn mode(&self, scene: &Scene) -> Mode {
        self.mode.unwrap_or_else(|| scene.mode())
    }
}

/// A view to render: the command's `--spp`, `--width`, `--height` and
/// `--seed` (the scene's own values where `None`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[non_exhaustive]
pub struct ViewOptions {
    /// Camera samples per pixel.
    pub spp: Option<u32>,
    /// Film width in pixels.
    pub width: Option<u32>,
    /// Film height in pixels.
    pub height: Option<u32>,
    /// Seed of the sample sequences.
    pub seed: u32,
}

/// A saved solution to use instead of a solve: its file's bytes, and the
/// name errors give it.
#[derive(Clone, Copy, Debug)]
pub struct SavedSolution<'a> {
    /// The solution file's bytes (`trilux solve`, [`solve_scene`]).
    pub bytes: &'a [u8],
    /// The file they came from, for error messages.
    pub name: &'a Path,
}

/// Loads a scene file (Mitsuba 3 XML subset, or glTF 2.0) with values for
/// its `$name` parameters, as `trilux -D NAME=VALUE`; a value the scene
/// does not use is an error, as in Mitsuba 3.
pub fn load_file(
    path: impl AsRef<Path>,
    defines: &[(String, String)],
) -> Result<Scene, PipelineError> {
    Ok(trilux_scene::load_with_params(path, defines)?)
}

/// The plan of a one-call: `solve`'s source (a solve, or the saved one).
fn plan<'p>(scene: &Scene, solve: &SolveOptions, saved: Option<SavedSolution<'p>>) -> Plan<'p> {
    Plan {
        mode: solve.mode(scene),
        solver: solve.settings(),
        source: saved.map_or(SolutionSource::Solve, |s| SolutionSource::Bytes {
            bytes: s.bytes,
            name: s.name,
        }),
        save: None,
        solution_file: false,
        render: None,
        bake: None,
    }
}

/// Carries out a plan without progress reports.
fn quiet(scene: &Scene, plan: &Plan<'_>) -> Result<Outcome, PipelineError> {
    Observer::quiet(|o| run(scene, plan, o))
}

/// Solves `scene` and returns the solution file's bytes (what `trilux
/// solve` writes) and the solve's statistics.
pub fn solve_scene(
    scene: &Scene,
    solve: &SolveOptions,
) -> Result<(Vec<u8>, trilux_solver::SolveStats), PipelineError> {
    let mut plan = plan(scene, solve, None);
    plan.solution_file = true;
    let outcome = quiet(scene, &plan)?;
    let bytes = outcome
        .solution_file
        .ok_or_else(|| PipelineError::NotMade {
            path: scene.path.clone(),
            what: "solution file",
        })?;
    Ok((bytes, outcome.solve))
}

/// Checks that `saved` is a solution of `scene` with `solve`'s settings
/// (the scene is prepared and the file read, as a render from it would)
/// and returns the statistics it records.
pub fn check_solution(
    scene: &Scene,
    solve: &SolveOptions,
    saved: SavedSolution<'_>,
) -> Result<trilux_solver::SolveStats, PipelineError> {
    quiet(scene, &plan(scene, solve, Some(saved))).map(|o| o.solve)
}

/// Renders `scene` as `trilux render` does with the same flags: solving
/// first, or from `saved`.
pub fn render_scene(
    scene: &Scene,
    solve: &SolveOptions,
    saved: Option<SavedSolution<'_>>,
    view: &ViewOptions,
) -> Result<Image, PipelineError> {
    let camera = scene
        .camera
        .as_ref()
        .ok_or_else(|| PipelineError::NoCamera {
            path: scene.path.clone(),
        })?;
    let mut settings = render_settings(camera);
    settings.spp = view.spp.unwrap_or(settings.spp);
    settings.seed = view.seed;
    // The path gather, or the control variate where the file limits path
    // length (no estimator is chosen here, so nothing to warn about).
    let _ = apply_integrator(&mut settings, scene, None);
    settings.extra_bounce = ExtraBounce::Always;
    let mut plan = plan(scene, solve, saved);
    plan.render = Some(RenderPlan {
        view: ViewOverrides {
            width: view.width,
            height: view.height,
            ..ViewOverrides::default()
        },
        settings,
    });
    quiet(scene, &plan)?
        .image
        .ok_or_else(|| PipelineError::NotMade {
            path: scene.path.clone(),
            what: "image",
        })
}

/// Loads, solves and renders a scene file in one call: `trilux render
/// FILE -D ... --spp ... --seed ...` without the files.
///
/// ```no_run
/// let mut view = trilux::ViewOptions::default();
/// view.spp = Some(16);
/// let image = trilux::render_file(
///     "scenes/cornell-box.xml",
///     &[],
///     &trilux::SolveOptions::default(),
///     &view,
/// )?;
/// println!("{} × {}, mean {:?}", image.width(), image.height(), image.mean());
/// # Ok::<(), trilux::PipelineError>(())
/// ```
pub fn render_file(
    path: impl AsRef<Path>,
    defines: &[(String, String)],
    solve: &SolveOptions,
    view: &ViewOptions,
) -> Result<Image, PipelineError> {
    let scene = load_file(path, defines)?;
    render_scene(&scene, solve, None, view)
}

/// Bakes `scene`'s light into a glTF binary as `trilux bake` does:
/// solving first, or from `saved`.
pub fn bake_scene(
    scene: &Scene,
    solve: &SolveOptions,
    saved: Option<SavedSolution<'_>>,
    options: &trilux_bake::BakeOptions,
) -> Result<trilux_bake::Baked, PipelineError> {
    let mut plan = plan(scene, solve, saved);
    plan.bake = Some(*options);
    quiet(scene, &plan)?
        .baked
        .ok_or_else(|| PipelineError::NotMade {
            path: scene.path.clone(),
            what: "bake",
        })
}
