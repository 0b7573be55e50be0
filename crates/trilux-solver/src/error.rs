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
    /// Reading or writing a solution file failed.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: String,
        /// The cause.
        #[source]
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
