//! Errors of the renderer.

use std::path::PathBuf;

/// What can go wrong while setting up a render or writing an image.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    /// A camera parameter is out of range (fov, film size, transform).
    #[error("invalid camera: {0}")]
    Camera(String),
    /// A render setting is out of range (samples per pixel, tile size).
    #[error("invalid render setting: {0}")]
    Settings(String),
    /// The scene cannot be prepared as written (a material or emitter that
    /// does not convert, a shape the geometry refuses), at its place in the
    /// file.
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
    /// The solution could not be baked.
    #[error(transparent)]
    Bake(#[from] trilux_bake::BakeError),
    /// An output could not be written; the file is as it was.
    #[error(transparent)]
    Output(#[from] trilux_files::WriteError),
    /// An image could not be encoded.
    #[error("cannot encode the {format} image: {reason}")]
    Encode {
        /// "EXR" or "PNG".
        format: &'static str,
        /// The encoder's reason.
        reason: String,
    },
    /// A pixel is not finite: such an image is never written.
    #[error("pixel ({x}, {y}) is not finite ({value:?}): the image is not written")]
    NonFinitePixel {
        /// Column.
        x: u32,
        /// Row.
        y: u32,
        /// Its value.
        value: [f32; 3],
    },
    /// An image could not be read.
    #[error("cannot read {path}: {reason}")]
    Read {
        /// The path read.
        path: PathBuf,
        /// What failed.
        reason: String,
    },
}
