//! Errors of the solver layer.

use thiserror::Error;

use crate::prepared::PrepareError;

/// The message of [`SolverError::NoFiniteSolution`], without the shape.
pub fn no_finite_solution(band: usize, bands: usize) -> String {
    let band = if bands == 3 {
        format!("in the {} band", ["red", "green", "blue"][band.min(2)])
    } else {
        format!("in band {} of {bands}", band + 1)
    };
    format!(
        "the scene has no finite solution: every surface this light reaches reflects all of it {band} and no probe ray leaves the scene, so it would grow without bound (lower a reflectance below 1 or open the scene)"
    )
}

/// What can go wrong when preparing, running, saving or loading a solve.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum SolverError {
    /// The scene description could not be prepared.
    #[error(transparent)]
    Prepare(#[from] PrepareError),
    /// The scene's light is never absorbed and never escapes
    /// (`divergence`): it would grow without bound.
    #[error("shape {shape}: {}", no_finite_solution(*band, *bands))]
    NoFiniteSolution {
        /// Index of an emitting shape whose light is trapped.
        shape: usize,
        /// The band in which nothing is absorbed (0-based).
        band: usize,
        /// The number of bands.
        bands: usize,
    },
    /// Invalid solver settings.
    #[error("invalid solver settings: {0}")]
    Settings(String),
    /// Statistics or settings could not be serialised (for a solution file
    /// or its hash).
    #[error("cannot serialise {what}: {source}")]
    Serialise {
        /// What was being serialised.
        what: &'static str,
        /// The cause.
        #[source]
        source: serde_json::Error,
    },
    /// A solution file could not be read.
    #[error("{path}: cannot read the solution file: {source}")]
    Read {
        /// The file.
        path: String,
        /// The cause.
        #[source]
        source: trilux_files::ReadError,
    },
    /// A solution file could not be written; the file is as it was.
    #[error(transparent)]
    Write(#[from] trilux_files::WriteError),
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
