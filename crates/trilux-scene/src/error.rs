//! Errors of scene loading, each carrying the place in the file that caused it.
//!
//! Every error displays as `FILE:LINE:COL: what is wrong` (README, "Scene format"), like a
//! compiler's, so that the command line can print it on one line. Lines and
//! columns count from 1 and point at the element or attribute value at fault.
//!
//! Errors in independent objects of one file (different top-level
//! elements, glTF materials or nodes) are collected (`Errors`) and
//! returned together as [`SceneError::Several`], as a compiler reports
//! every error of a file in one run; one error alone is returned as itself.

use std::collections::HashSet;
use std::fmt;
use std::hash::{DefaultHasher, Hash, Hasher};
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
    /// Several independent errors of one file, each an `At` or a `Read`
    /// (never nested), in the order found: the first
    /// [`MAX_REPORTED_ERRORS`](crate::limits::MAX_REPORTED_ERRORS), and how
    /// many more there were. Displays one error a line.
    #[error("{}", self.lines().join("\n"))]
    Several {
        /// The errors reported, at least two.
        errors: Vec<SceneError>,
        /// How many more errors were found and left out.
        more: usize,
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

    /// Where the error is, when it is at a place in the file (the first
    /// one's, for [`SceneError::Several`]).
    pub fn location(&self) -> Option<&SourceLocation> {
        match self {
            SceneError::At { location, .. } => Some(location),
            SceneError::Read { .. } => None,
            SceneError::Several { errors, .. } => errors.first().and_then(SceneError::location),
        }
    }

    /// The errors this one holds: itself, or each of [`SceneError::Several`].
    pub fn errors(&self) -> &[SceneError] {
        match self {
            SceneError::Several { errors, .. } => errors,
            single => std::slice::from_ref(single),
        }
    }

    /// The error as lines to print: one a located error, and for
    /// [`SceneError::Several`] with errors left out, a last line counting
    /// them.
    pub fn lines(&self) -> Vec<String> {
        let mut lines: Vec<String> = self.errors().iter().map(ToString::to_string).collect();
        if let SceneError::Several { errors, more, .. } = self
            && *more > 0
        {
            let file = match errors.first() {
                Some(SceneError::Read { path, .. }) => path.display().to_string(),
                Some(e) => e
                    .location()
                    .map_or_else(String::new, |l| l.file.display().to_string()),
                None => String::new(),
            };
            lines.push(format!(
                "{file}: and {more} more errors (only the first {} are reported)",
                errors.len()
            ));
        }
        lines
    }
}

/// The errors of independent objects, collected while loading goes on:
/// at most [`MAX_REPORTED_ERRORS`](crate::limits::MAX_REPORTED_ERRORS)
/// kept, the rest counted; an error found twice (a definition's, met
/// again through each object that references it) counts once. Each error
/// has a place in the file's order (its top-level element's index), so
/// that those reported are the file's first, in its order, whatever stage
/// found them.
#[derive(Debug, Default)]
pub(crate) struct Errors {
    /// (place, error), at most the limit.
    kept: Vec<(usize, SceneError)>,
    more: usize,
    /// Hashes of the messages seen: a hostile file's million errors cost
    /// 8 bytes each, not their text.
    seen: HashSet<u64>,
}

impl Errors {
    /// Adds `e` (each of its errors, if it holds several) after those of
    /// every place.
    pub fn push(&mut self, e: SceneError) {
        self.push_at(usize::MAX, e);
    }

    /// Adds `e` (each of its errors, if it holds several) at `place`.
    pub fn push_at(&mut self, place: usize, e: SceneError) {
        if let SceneError::Several { errors, more } = e {
            errors.into_iter().for_each(|e| self.push_at(place, e));
            self.more += more;
            return;
        }
        let mut hasher = DefaultHasher::new();
        e.to_string().hash(&mut hasher);
        if !self.seen.insert(hasher.finish()) {
            return;
        }
        if self.kept.len() < crate::limits::MAX_REPORTED_ERRORS {
            self.kept.push((place, e));
            return;
        }
        self.more += 1;
        // Full: `e` replaces the kept error latest in the file, if it is
        // earlier.
        if let Some(last) = self.latest()
            && self.kept[last].0 > place
        {
            self.kept[last] = (place, e);
        }
    }

    /// The index of the kept error latest in the file (the last found
    /// among equals).
    fn latest(&self) -> Option<usize> {
        (0..self.kept.len()).max_by_key(|&k| self.kept[k].0)
    }

    /// The value of `r`, or `None` with its error kept (after every
    /// place).
    pub fn keep<T>(&mut self, r: Result<T>) -> Option<T> {
        self.keep_at(usize::MAX, r)
    }

    /// The value of `r`, or `None` with its error kept at `place`.
    pub fn keep_at<T>(&mut self, place: usize, r: Result<T>) -> Option<T> {
        r.map_err(|e| self.push_at(place, e)).ok()
    }

    /// True when no error was found.
    pub fn is_empty(&self) -> bool {
        self.kept.is_empty()
    }

    /// `value` when no error was found, else the errors.
    pub fn or<T>(self, value: T) -> Result<T> {
        if self.is_empty() {
            Ok(value)
        } else {
            Err(self.into_error())
        }
    }

    /// The errors found and then `last`, one that stops loading at once (a
    /// limit passed): reported last, whatever else is left out.
    pub fn stop(mut self, last: SceneError) -> SceneError {
        if self.is_empty() {
            return last;
        }
        if self.kept.len() == crate::limits::MAX_REPORTED_ERRORS
            && let Some(k) = self.latest()
        {
            self.kept.remove(k);
            self.more += 1;
        }
        self.kept.push((usize::MAX, last));
        self.into_error()
    }

    /// One error as itself, several as [`SceneError::Several`] in the
    /// file's order; only when some error was found.
    fn into_error(mut self) -> SceneError {
        if self.kept.len() == 1 && self.more == 0 {
            return self.kept.remove(0).1;
        }
        self.kept.sort_by_key(|(place, _)| *place);
        SceneError::Several {
            errors: self.kept.into_iter().map(|(_, e)| e).collect(),
            more: self.more,
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
