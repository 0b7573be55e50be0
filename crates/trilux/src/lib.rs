//! # trilux — the orchestration and the `trilux` command
//!
//! Layer: the top. The library is the one orchestration from a loaded scene
//! to a solution, an image and a bake, shared by the command (`main.rs`
//! and its subcommand modules), the examples and the xtask tools; it is
//! kept apart from the final gather (`trilux-render`) as pbrt-v4 keeps
//! `RenderCPU` apart from its integrators, so that the renderer depends on
//! colour, geometry, BRDFs and the solver only.
//!
//! Contents, in the order a plan runs:
//! - [`view`]: the scene's sensor as a `trilux_render::Camera`, with the
//!   command line's overrides (`--lookat`, `--fov`, film size), and the
//!   scene's own render settings.
//! - [`pipeline`]: prepare a loaded scene in its mode, solve it or load a
//!   saved solution, save it, bake it, render a view.
//! - [`oneshot`]: the one-call API on top of the pipeline, from a scene
//!   file to an image ([`render_file`]), a solution or a bake, with the
//!   command's defaults (the examples and the Python module use it).
//! - [`error`]: the error type, [`PipelineError`], wrapping each layer's.
#![forbid(unsafe_code)]

pub mod error;
mod glossy_light;
pub mod oneshot;
pub mod pipeline;
pub mod view;

pub use error::PipelineError;
pub use oneshot::{
    SavedSolution, SolveOptions, ViewOptions, bake_scene, check_solution, load_file, render_file,
    render_scene, solve_scene,
};
pub use pipeline::{
    Observer, Outcome, Plan, RenderPlan, SolutionSource, check, prepare, run, scene_camera,
};
pub use view::{ViewOverrides, apply_integrator, camera_of, filter_of, render_settings};
