//! Errors of the solver layer.

use thiserror::Error;

/// What can go wrong when preparing, running, saving or loading a solve.
#[derive(Debug, Error)]
pub enum SolverError {
    /// The scene's geometry could not be built.
    #[error(transparent)]
    Geometry(#[from] trilux_geometry::GeometryError),
    /// A material could not be built for this spectral mode.
    #[error("shape {shape}: {message}")]
    Material {
        /// Index of the shape.
        shape: usize,
        /// What is wrong.
        message: String,
    },
    /// Invalid solver settings.
    #[error("invalid solver settings: {0}")]
    Settings(String),
    /// Reading or writing a solution file failed.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: String,
        /// The cause.
        source: std::io::Error,
    },
    /// A solution file is not one trilux can read, or belongs to another
    /// scene or mode.
    #[error("{path}: {message}")]
    SolutionFile {
        /// The file.
        path: String,
        /// What is wrong.
        message: String,
    },
}
