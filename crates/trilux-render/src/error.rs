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
    /// The scene cannot be rendered as given (a material or emitter that
    /// does not convert, a shape the geometry does not know).
    #[error("{0}")]
    Scene(String),
    /// An image could not be written; nothing is left at `path`.
    #[error("cannot write {path}: {reason}")]
    Write {
        /// The output path asked for.
        path: PathBuf,
        /// What failed.
        reason: String,
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
