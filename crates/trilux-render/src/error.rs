//! Errors of the renderer.

use std::path::PathBuf;

/// What can go wrong while setting up a render or writing an image.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum RenderError {
    /// A camera parameter is out of range (fov, film size, transform).
    #[error("invalid camera: {0}")]
    Camera(String),
    /// A render setting is out of range (samples per pixel, tile size).
    #[error("invalid render setting: {0}")]
    Settings(String),
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
