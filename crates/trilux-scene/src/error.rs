//! Errors of scene loading, each carrying the place in the file that caused it.
//!
//! Every error displays as `FILE:LINE:COL: what is wrong` (README, "Scene format"), like a
//! compiler's, so that the command line can print it on one line. Lines and
//! columns count from 1 and point at the element or attribute value at fault.

use std::fmt;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// A place in a scene file: the file, and a 1-based line and column.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct SourceLocation {
    /// The scene file (as it was named when loading).
    pub file: Arc<Path>,
    /// Line, counting from 1.
    pub line: u32,
    /// Column in characters, counting from 1.
    pub col: u32,
    /// In a JSON file (glTF), the place as a JSON path instead of a line
    /// and column (`/materials/2/pbrMetallicRoughness`).
    pub pointer: Option<Arc<str>>,
}

impl SourceLocation {
    /// The place `pointer` (a JSON path) in `file`.
    pub fn json(file: &Arc<Path>, pointer: impl Into<String>) -> Self {
        SourceLocation {
            file: Arc::clone(file),
            line: 0,
            col: 0,
            pointer: Some(Arc::from(pointer.into())),
        }
    }
}

impl fmt::Display for SourceLocation {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.pointer {
            Some(p) => write!(f, "{}:{p}", self.file.display()),
            None => write!(f, "{}:{}:{}", self.file.display(), self.line, self.col),
        }
    }
}

/// Why a scene could not be loaded.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SceneError {
    /// Something is wrong at a known place of the scene file.
    #[error("{location}: {message}")]
    At {
        /// Where.
        location: SourceLocation,
        /// What is wrong (one line).
        message: String,
    },
    /// The scene file itself could not be read.
    #[error("{}: cannot read the scene file: {source}", path.display())]
    Read {
        /// The scene file.
        path: PathBuf,
        /// Why (the operating system's reason, not a regular file, too
        /// large).
        #[source]
        source: trilux_files::ReadError,
    },
}

impl SceneError {
    /// An error at `location`.
    pub fn at(location: &SourceLocation, message: impl Into<String>) -> Self {
        // One line, whatever the message (the command prints one line), and
        // a short one, whatever value it quotes.
        let message: String = message.into();
        SceneError::At {
            location: location.clone(),
            message: elide(&message.replace(['\n', '\r'], " "), MAX_MESSAGE_CHARS),
        }
    }

    /// Where the error is, when it is at a place in the file.
    pub fn location(&self) -> Option<&SourceLocation> {
        match self {
            SceneError::At { location, .. } => Some(location),
            SceneError::Read { .. } => None,
        }
    }
}

/// The longest message an error carries; longer ones (a quoted value of
/// megabytes) lose their middle.
pub(crate) const MAX_MESSAGE_CHARS: usize = 400;

/// `text` cut to at most `max` characters by replacing its middle with
/// "…(N characters)…", so that both its start and its end stay readable.
pub fn elide(text: &str, max: usize) -> String {
    let count = text.chars().count();
    if count <= max {
        return text.to_string();
    }
    let keep = max.saturating_sub(30) / 2;
    let head: String = text.chars().take(keep).collect();
    let tail: String = text.chars().skip(count - keep).collect();
    format!("{head}…({} characters)…{tail}", count - 2 * keep)
}

/// Shorthand for results of the loader.
pub type Result<T, E = SceneError> = std::result::Result<T, E>;
