//! The one orchestration from a loaded scene to a solution and an image,
//! shared by the `trilux` command, the examples and the xtask tools:
//! prepare the scene in its mode's band count ([`prepare`]), solve it or
//! load a saved solution, optionally save it, optionally render a view.
//!
//! Everything that can be checked before the long work is checked first:
//! the camera and its overrides and the render settings are validated
//! before the scene is prepared or solved.

use std::path::Path;
use std::sync::Arc;
use std::sync::atomic::AtomicBool;
use std::time::Instant;

use trilux_color::{ColorParam, Mode, WithBands};
use trilux_scene::{Scene, SceneError};
use trilux_solver::{
    PrepareError, PreparedScene, PreparedSky, Progress, SceneDescription, Solution, SolveStats,
    Solver, SolverError, SolverSettings,
};

use trilux_render::{
    Camera, Image, RenderError, RenderSettings, RenderStats, render, render_with_response,
};

use crate::error::PipelineError;
use crate::view::{ViewOverrides, camera_of};

/// Where the solution comes from.
#[derive(Clone, Copy, Debug)]
pub enum SolutionSource<'p> {
    /// Solve the scene.
    Solve,
    /// Load a solution saved for this scene, mode and settings.
    Load(&'p Path),
    /// Read one from its file's bytes, already in memory (`name` is the
    /// file they came from, for errors).
    Bytes {
        /// The solution file's bytes.
        bytes: &'p [u8],
        /// Where they came from.
        name: &'p Path,
    },
}

/// A view to render.
#[derive(Clone, Copy, Debug)]
pub struct RenderPlan {
    /// Changes to the scene's camera.
    pub view: ViewOverrides,
    /// Samples, seed, filter, extra-bounce rule.
    pub settings: RenderSettings,
}

/// What to do with a scene.
#[derive(Clone, Debug)]
pub struct Plan<'p> {
    /// RGB or spectral.
    pub mode: Mode,
    /// The solve's settings (also those a loaded solution must have).
    pub solver: SolverSettings,
    /// Solve, or load.
    pub source: SolutionSource<'p>,
    /// Save the solution there.
    pub save: Option<&'p Path>,
    /// Return the solution file's bytes in [`Outcome::solution_file`], for
    /// a caller that writes all its outputs at once (the `trilux` command).
    pub solution_file: bool,
    /// Render a view.
    pub render: Option<RenderPlan>,
    /// Bake the solution's light into a glTF binary (`trilux_bake`).
    pub bake: Option<trilux_bake::BakeOptions>,
}

/// What a plan did.
#[derive(Clone, Debug)]
pub struct Outcome {
    /// The rendered image, when the plan renders.
    pub image: Option<Image>,
    /// The solve's statistics (`solve_seconds` 0 for a loaded solution).
    pub solve: SolveStats,
    /// The solution file's bytes, when the plan asks for them.
    pub solution_file: Option<Vec<u8>>,
    /// The render's statistics, when the plan renders.
    pub render: Option<RenderStats>,
    /// The baked file, when the plan bakes.
    pub baked: Option<trilux_bake::Baked>,
    /// Wall-clock seconds spent preparing the scene (geometry, BVH,
    /// materials).
    pub prepare_seconds: f64,
    /// Wall-clock seconds of the solve (or of loading the solution).
    pub solve_seconds: f64,
    /// Wall-clock seconds of the render.
    pub render_seconds: f64,
}

/// Progress reports during a plan (the library never prints).
pub struct Observer<'o> {
    /// Called after every shot of a solve.
    pub solve: &'o mut dyn FnMut(&Progress),
    /// Called after every rendered tile, with (done, total), from worker
    /// threads.
    pub render: &'o (dyn Fn(usize, usize) + Sync),
    /// Once set, the solve stops between shots with the solution so far
    /// (`Solver::stop_when`; the command's SIGINT and SIGTERM).
    pub stop: Option<Arc<AtomicBool>>,
}

impl Observer<'_> {
    /// Runs `f` with an observer that ignores everything.
    pub fn quiet<T>(f: impl FnOnce(Observer<'_>) -> T) -> T {
        let mut solve = |_: &Progress| {};
        f(Observer {
            solve: &mut solve,
            render: &|_, _| {},
            stop: None,
        })
    }
}

/// The scene's camera with `view`'s overrides (an error when the scene has
/// no sensor or the view is invalid; at the `<sensor>` when the scene's own
/// values are at fault).
pub fn scene_camera(scene: &Scene, view: &ViewOverrides) -> Result<Camera, PipelineError> {
    let cam = scene
        .camera
        .as_ref()
        .ok_or_else(|| PipelineError::NoCamera {
            path: scene.path.clone(),
        })?;
    camera_of(cam, view).map_err(|e| match e {
        RenderError::Camera(m) if *view == ViewOverrides::default() => {
            SceneError::at(&cam.location, m).into()
        }
        e => e.into(),
    })
}

/// The scene prepared for `N` bands; errors point at the shape (or its
/// emitter) in the file.
pub fn prepare<const N: usize>(scene: &Scene) -> Result<Arc<PreparedScene<N>>, PipelineError> {
    let (shapes, bsdfs, emission) = (
        scene.geometry_shapes(),
        scene.bsdf_params(),
        scene.emitter_radiance(),
    );
    let desc = SceneDescription {
        shapes: &shapes,
        bsdfs: &bsdfs,
        emission: &emission,
    };
    let prepared = PreparedScene::new_textured(&desc, &scene.texture_slots())
        .map_err(|e| PipelineError::from(located(scene, &e)))?;
    prepared
        .with_enclosure(scene.enclosure())
        .with_transmission(&scene.transmission_params())
        .with_normal_maps(&scene.normal_maps())
        .with_sky(prepared_sky(scene)?)
        .with_lights(&scene.light_params())
        .map(Arc::new)
        .map_err(|e| {
            let at = scene
                .lights
                .get(e.index)
                .map_or_else(|| scene.shape_location(usize::MAX), |l| l.location.clone());
            SceneError::at(&at, e.problem).into()
        })
}

/// The scene's environment map in `N` bands, scaled (`None` without
/// one); errors at its `<emitter>`.
pub fn prepared_sky<const N: usize>(
    scene: &Scene,
) -> Result<Option<PreparedSky<N>>, PipelineError> {
    let (Some(env), Some(map)) = (&scene.environment, scene.sky_map()) else {
        return Ok(None);
    };
    let at = |m: String| PipelineError::from(SceneError::at(&env.location, m));
    let texels = map
        .texels
        .iter()
        .map(|t| ColorParam::Rgb(t.map(|c| f64::from(c) * map.scale)).emission::<N>())
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| at(e.to_string()))?;
    PreparedSky::new(map.width, map.height, texels, map.world_from_sky)
        .map(Some)
        .map_err(|e| at(e.to_string()))
}

/// A preparation error at its place in the scene file.
fn located(scene: &Scene, e: &PrepareError) -> SceneError {
    let location = match e.shape() {
        Some(i) if e.is_emitter() => scene.shapes[i]
            .emitter
            .as_ref()
            .map_or_else(|| scene.shape_location(i), |em| em.location.clone()),
        Some(i) => scene.shape_location(i),
        None => scene.shape_location(usize::MAX),
    };
    SceneError::at(&location, e.problem())
}

/// Everything [`run`] checks before the long work: the render settings,
/// the camera with its overrides, the solver settings. Only the scene's
/// camera is read, so a caller can check a scene whose meshes are not read
/// yet (`trilux_scene::Pending`).
pub fn check(
    scene: &Scene,
    plan: &Plan<'_>,
) -> Result<Option<(Camera, RenderSettings)>, PipelineError> {
    let view = match &plan.render {
        Some(r) => {
            r.settings.validate()?;
            Some((scene_camera(scene, &r.view)?, r.settings))
        }
        None => None,
    };
    plan.solver
        .validate()
        .map_err(trilux_solver::SolverError::Settings)?;
    Ok(view)
}

/// A solver error at its place in the scene file, when it names a shape.
fn located_solver(scene: &Scene, e: SolverError) -> PipelineError {
    match e {
        SolverError::NoFiniteSolution { shape, band, bands } => {
            let location = scene.shapes.get(shape).map_or_else(
                || scene.shape_location(shape),
                |s| {
                    s.emitter
                        .as_ref()
                        .map_or(s.location.clone(), |em| em.location.clone())
                },
            );
            SceneError::at(
                &location,
                trilux_solver::error::no_finite_solution(band, bands),
            )
            .into()
        }
        SolverError::Prepare(p) => located(scene, &p).into(),
        e => e.into(),
    }
}

/// Carries out `plan` on `scene` (module docs).
pub fn run(
    scene: &Scene,
    plan: &Plan<'_>,
    observer: Observer<'_>,
) -> Result<Outcome, PipelineError> {
    let view = check(scene, plan)?;
    plan.mode.with_bands(Run {
        scene,
        plan,
        view,
        observer,
    })
}

/// [`run`] once the band count is known.
struct Run<'a, 'o> {
    scene: &'a Scene,
    plan: &'a Plan<'a>,
    view: Option<(Camera, RenderSettings)>,
    observer: Observer<'o>,
}

impl WithBands for Run<'_, '_> {
    type Output = Result<Outcome, PipelineError>;

    fn run<const N: usize>(self) -> Self::Output {
        let start = Instant::now();
        let prepared = prepare::<N>(self.scene)?;
        if let Some((camera, _)) = &self.view {
            let located = |e| match (e, &self.scene.camera) {
                (RenderError::Camera(m), Some(c)) => SceneError::at(&c.location, m).into(),
                (e, _) => PipelineError::from(e),
            };
            camera
                .check_far_clip(&prepared.geometry().bounds())
                .map_err(located)?;
        }
        let prepare_seconds = start.elapsed().as_secs_f64();
        let start = Instant::now();
        let mut solution = match self.plan.source {
            SolutionSource::Solve => {
                let solver = Solver::new(prepared, self.plan.solver.clone())
                    .map_err(|e| located_solver(self.scene, e))?;
                match self.observer.stop {
                    Some(flag) => solver.stop_when(flag),
                    None => solver,
                }
                .solve(|p| (self.observer.solve)(p))
            }
            SolutionSource::Load(path) => {
                let mut s = Solution::load(path, prepared, &self.plan.solver)?;
                s.stats_mut().solve_seconds = 0.0;
                s
            }
            SolutionSource::Bytes { bytes, name } => {
                let mut s = Solution::from_bytes(bytes, prepared, &self.plan.solver).map_err(
                    |message| SolverError::SolutionFile {
                        path: name.display().to_string(),
                        message,
                    },
                )?;
                s.stats_mut().solve_seconds = 0.0;
                s
            }
        };
        let solve_seconds = start.elapsed().as_secs_f64();
        if let Some(path) = self.plan.save {
            solution.save(path)?;
        }
        let solution_file = match self.plan.solution_file {
            true => Some(solution.to_bytes()?),
            false => None,
        };
        let baked = match &self.plan.bake {
            Some(options) => Some(bake(self.scene, &solution, options)?),
            None => None,
        };
        let start = Instant::now();
        let rendered = match &self.view {
            Some((camera, settings)) => {
                let progress = self.observer.render;
                Some(match sensor_response::<N>(self.scene)? {
                    Some(r) => render_with_response(&solution, camera, settings, r, progress)?,
                    None => render(&solution, camera, settings, progress)?,
                })
            }
            None => None,
        };
        let render_seconds = start.elapsed().as_secs_f64();
        let (image, render) = rendered.map_or((None, None), |(i, s)| (Some(i), Some(s)));
        Ok(Outcome {
            image,
            solve: std::mem::take(solution.stats_mut()),
            solution_file,
            render,
            baked,
            prepare_seconds,
            solve_seconds,
            render_seconds,
        })
    }
}

/// The solution's light as a glTF binary, with the scene's materials,
/// shape names and camera (when it has one).
fn bake<const N: usize>(
    scene: &Scene,
    solution: &Solution<N>,
    options: &trilux_bake::BakeOptions,
) -> Result<trilux_bake::Baked, PipelineError> {
    let camera = scene_camera(scene, &ViewOverrides::default())
        .ok()
        .map(|c| trilux_bake::BakeCamera {
            world_from_camera: c.world_from_camera(),
            yfov: c.yfov(),
            aspect: c.film_aspect(),
        });
    let materials = scene.bsdf_params();
    let names: Vec<Option<String>> = scene.shapes.iter().map(|s| s.id.clone()).collect();
    let glossy = crate::glossy_light::RenderedGlossy::new(solution);
    let input = trilux_bake::BakeInput {
        solution,
        materials: &materials,
        names: &names,
        camera,
        glossy: (options.glossy && options.glossy_samples > 0)
            .then_some(&glossy as &dyn trilux_bake::GlossyLight),
        gathered: Some(&glossy as &dyn trilux_bake::GatheredLight),
    };
    Ok(trilux_bake::bake(&input, options)?)
}

/// The scene's sensor response (`srf`) in `N` bands, if it has one.
fn sensor_response<const N: usize>(
    scene: &Scene,
) -> Result<Option<trilux_color::Spectrum<N>>, PipelineError> {
    let Some(camera) = &scene.camera else {
        return Ok(None);
    };
    let Some(srf) = &camera.response else {
        return Ok(None);
    };
    let spectrum = srf
        .to_spectrum::<N>(trilux_color::Role::Unbounded)
        .map_err(|e| SceneError::at(&camera.location, format!("srf: {e}")))?;
    Ok(Some(spectrum))
}
