//! Errors of the solver layer.

use thiserror::Error;

use crate::prepared::PrepareError;

/// What can go wrong when preparing, running, saving or loading a solve.
#[derive(Debug, Error)]
pub enum SolverError {
    /// The scene description could not be prepared.
    #[error(transparent)]
    Prepare(#[from] PrepareError),
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
