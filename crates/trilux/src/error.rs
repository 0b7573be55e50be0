//! Errors of the pipeline: each layer's own error, kept whole, and the one
//! the pipeline itself finds (a scene without a camera).

use std::path::PathBuf;

/// What can go wrong while carrying out a plan.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum PipelineError {
    /// The scene cannot be prepared as written (a material or emitter that
    /// does not convert, a shape the geometry refuses, a camera it does not
    /// allow), at its place in the file.
    #[error(transparent)]
    Scene(#[from] trilux_scene::SceneError),
    /// The scene has no camera to render from.
    #[error("{}: the scene has no <sensor> to render from", path.display())]
    NoCamera {
        /// The scene file.
        path: PathBuf,
    },
    /// Solving, or saving or loading a solution, failed.
    #[error(transparent)]
    Solver(#[from] trilux_solver::SolverError),
    /// The render's settings, camera or image failed.
    #[error(transparent)]
    Render(#[from] trilux_render::RenderError),
    /// A plan did not make what it was asked for (a render without an
    /// image): a defect of the pipeline, reported rather than panicking.
    #[error("{}: the {what} was not made", path.display())]
    NotMade {
        /// The scene file.
        path: PathBuf,
        /// What is missing.
        what: &'static str,
    },
    /// The solution could not be baked.
    #[error(transparent)]
    Bake(#[from] trilux_bake::BakeError),
}
