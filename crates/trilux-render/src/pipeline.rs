//! Solve and render in one call, in the scene's own mode: 3 bands for RGB
//! scenes, 10 spectral bands for spectral ones (design.md §2).

use std::time::Instant;

use crate::driver::{RenderSettings, RenderStats, render};
use crate::error::RenderError;
use crate::image::Image;
use crate::solved::solve_scene;
use crate::view::ViewOverrides;

/// What [`solve_and_render`] did.
#[derive(Clone, Debug)]
pub struct PipelineStats {
    /// The solve's statistics.
    pub solve: trilux_solver::SolveStats,
    /// The render's statistics.
    pub render: RenderStats,
    /// Wall-clock seconds of the solve.
    pub solve_seconds: f64,
}

/// Solves `scene` with `solver` settings and renders it from its camera,
/// in the scene's own colour mode (`Scene::mode`).
pub fn solve_and_render(
    scene: &trilux_scene::Scene,
    solver: trilux_solver::SolverSettings,
    view: &ViewOverrides,
    settings: &RenderSettings,
) -> Result<(Image, PipelineStats), RenderError> {
    if scene.mode() == trilux_color::Mode::Spectral {
        solve_and_render_bands::<{ trilux_color::SPECTRAL_BANDS }>(scene, solver, view, settings)
    } else {
        solve_and_render_bands::<3>(scene, solver, view, settings)
    }
}

/// [`solve_and_render`] with `N` bands.
fn solve_and_render_bands<const N: usize>(
    scene: &trilux_scene::Scene,
    solver: trilux_solver::SolverSettings,
    view: &ViewOverrides,
    settings: &RenderSettings,
) -> Result<(Image, PipelineStats), RenderError> {
    let start = Instant::now();
    let sol = solve_scene::<N>(scene, solver)?;
    let solve_seconds = start.elapsed().as_secs_f64();
    let (image, render) = render(scene, &sol, view, settings, |_, _| {})?;
    Ok((
        image,
        PipelineStats {
            solve: sol.stats().clone(),
            render,
            solve_seconds,
        },
    ))
}
