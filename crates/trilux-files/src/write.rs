//! Outputs planned before the work and written all or none after it.
//!
//! - [`Output::plan`] resolves an output path before any work: symbolic
//!   links are followed to the file they name (the link itself is never
//!   replaced); the folder must exist and accept a new file (probed with a
//!   temporary file made and removed at once); a folder (or a path ending
//!   in `/`, which names one), a block device or a socket is refused; a FIFO or a character device (`/dev/null`,
//!   `/dev/stdout`) is written through, never replaced by a file.
//! - [`write_all`] stages every regular-file output in a temporary file of
//!   its own folder, created exclusively under a name no other file has
//!   (`.NAME.trilux-PID-K.tmp`, K counting up until the name is free), so
//!   no unrelated file is ever touched; then writes the write-through
//!   outputs; then renames each staged file over its target. A failure
//!   before the renames removes every temporary file and leaves every
//!   target as it was.

use std::fs::{File, OpenOptions};
use std::io::{self, Write};
use std::path::{Path, PathBuf};

use crate::identity::{FileIdentity, resolve};
use crate::read::kind_of;

/// Why an output could not be planned or written.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum WriteError {
    /// The output cannot be written as asked (missing folder, a folder in
    /// its place, a kind of file trilux does not write to).
    #[error("{}: cannot write the {what}: {reason}", path.display())]
    Refused {
        /// The output path as given.
        path: PathBuf,
        /// What the output is ("image", "solution", ...).
        what: String,
        /// Why.
        reason: String,
    },
    /// The operating system refused a step of the write.
    #[error("{}: cannot write the {what}: {source}", path.display())]
    Io {
        /// The output path as given.
        path: PathBuf,
        /// What the output is.
        what: String,
        /// The cause.
        #[source]
        source: io::Error,
    },
    /// A rename failed after other outputs were already in place.
    #[error("{}: cannot write the {what}: {source} (already written: {})", path.display(), list(written))]
    Partial {
        /// The output path as given.
        path: PathBuf,
        /// What the output is.
        what: String,
        /// The cause.
        #[source]
        source: io::Error,
        /// The outputs already renamed into place.
        written: Vec<PathBuf>,
    },
}

fn list(paths: &[PathBuf]) -> String {
    let names: Vec<String> = paths.iter().map(|p| p.display().to_string()).collect();
    names.join(", ")
}

/// One planned output (module docs).
#[derive(Clone, Debug)]
pub struct Output {
    /// The path as given.
    path: PathBuf,
    /// What it is, for messages ("image", "PNG", "statistics", ...).
    what: String,
    /// The file actually written: `path` with its symbolic links followed.
    target: PathBuf,
    /// Written through (FIFO, character device) rather than replaced.
    through: bool,
    identity: FileIdentity,
}

impl Output {
    /// Plans writing the `what` to `path` (module docs).
    pub fn plan(path: &Path, what: &str) -> Result<Output, WriteError> {
        let refused = |reason: String| WriteError::Refused {
            path: path.to_path_buf(),
            what: what.to_string(),
            reason,
        };
        let io_err = |source| WriteError::Io {
            path: path.to_path_buf(),
            what: what.to_string(),
            source,
        };
        // `out/` names a folder whether it exists or not: refused now,
        // not at the final rename after the work.
        if path.as_os_str().as_encoded_bytes().ends_with(b"/") {
            return Err(refused(
                "the path ends in '/', so it names a folder, not a file".into(),
            ));
        }
        let resolved = resolve(path).map_err(io_err)?;
        let through = match &resolved.meta {
            None => false,
            Some(m) if m.is_file() => false,
            Some(m) if m.is_dir() => return Err(refused("it is a folder".into())),
            Some(m) if writes_through(m) => true,
            Some(m) => {
                return Err(refused(format!(
                    "it is {}; trilux writes regular files, FIFOs and character devices",
                    kind_of(m)
                )));
            }
        };
        let target = resolved.path;
        if !through {
            let dir = folder_of(&target).ok_or_else(|| refused("the path names no file".into()))?;
            if !dir.is_dir() {
                return Err(refused(format!(
                    "the folder {} does not exist",
                    dir.display()
                )));
            }
            // The folder must take a new file: try, and remove it at once.
            drop(Staged::new(&target, &[], false).map_err(io_err)?);
        }
        let identity = FileIdentity::of(path).map_err(io_err)?;
        Ok(Output {
            path: path.to_path_buf(),
            what: what.to_string(),
            target,
            through,
            identity,
        })
    }

    /// The path as given.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// What the output is.
    pub fn what(&self) -> &str {
        &self.what
    }

    /// What file the output is (to compare with inputs and other outputs).
    pub fn identity(&self) -> &FileIdentity {
        &self.identity
    }

    /// True when the output is written through (a FIFO or a character
    /// device) instead of being replaced.
    pub fn is_write_through(&self) -> bool {
        self.through
    }
}

#[cfg(unix)]
fn writes_through(m: &std::fs::Metadata) -> bool {
    use std::os::unix::fs::FileTypeExt;
    m.file_type().is_fifo() || m.file_type().is_char_device()
}

#[cfg(not(unix))]
fn writes_through(_m: &std::fs::Metadata) -> bool {
    false
}

/// The folder a file is (to be) made in.
fn folder_of(path: &Path) -> Option<PathBuf> {
    path.file_name()?;
    Some(match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    })
}

/// A temporary file beside its target, removed when dropped unless
/// renamed into place.
struct Staged {
    tmp: PathBuf,
    target: PathBuf,
    committed: bool,
}

impl Staged {
    /// Creates the temporary file exclusively and writes `bytes` to it
    /// (synced, with the permissions of the file it will replace when
    /// `keep_mode`).
    fn new(target: &Path, bytes: &[u8], keep_mode: bool) -> io::Result<Staged> {
        let (tmp, file) = create_exclusive(target)?;
        let mut staged = Staged {
            tmp,
            target: target.to_path_buf(),
            committed: false,
        };
        staged.write(file, bytes, keep_mode)?;
        Ok(staged)
    }

    fn write(&mut self, mut file: File, bytes: &[u8], keep_mode: bool) -> io::Result<()> {
        file.write_all(bytes)?;
        file.sync_all()?;
        if keep_mode && let Ok(meta) = std::fs::metadata(&self.target) {
            file.set_permissions(meta.permissions())?;
        }
        Ok(())
    }

    fn commit(mut self) -> io::Result<()> {
        std::fs::rename(&self.tmp, &self.target)?;
        self.committed = true;
        Ok(())
    }
}

impl Drop for Staged {
    fn drop(&mut self) {
        if !self.committed {
            let _ = std::fs::remove_file(&self.tmp);
        }
    }
}

/// A new file beside `target` whose name no file had (module docs).
fn create_exclusive(target: &Path) -> io::Result<(PathBuf, File)> {
    let dir = folder_of(target)
        .ok_or_else(|| io::Error::new(io::ErrorKind::InvalidInput, "the path names no file"))?;
    let name = target
        .file_name()
        .map_or_else(String::new, |n| n.to_string_lossy().into_owned());
    let pid = std::process::id();
    for k in 0..10_000u32 {
        let tmp = dir.join(format!(".{name}.trilux-{pid}-{k}.tmp"));
        match OpenOptions::new().write(true).create_new(true).open(&tmp) {
            Ok(file) => return Ok((tmp, file)),
            Err(e) if e.kind() == io::ErrorKind::AlreadyExists => continue,
            Err(e) => return Err(e),
        }
    }
    Err(io::Error::new(
        io::ErrorKind::AlreadyExists,
        "no free temporary file name in the folder",
    ))
}

/// Writes every output or none (module docs).
pub fn write_all(outputs: &[(&Output, &[u8])]) -> Result<(), WriteError> {
    let fail = |o: &Output| {
        let (path, what) = (o.path.clone(), o.what.clone());
        move |source| WriteError::Io { path, what, source }
    };
    let mut staged = Vec::new();
    for (o, bytes) in outputs.iter().filter(|(o, _)| !o.through) {
        staged.push((*o, Staged::new(&o.target, bytes, true).map_err(fail(o))?));
    }
    for (o, bytes) in outputs.iter().filter(|(o, _)| o.through) {
        let mut file = OpenOptions::new()
            .write(true)
            .open(&o.target)
            .map_err(fail(o))?;
        file.write_all(bytes)
            .and_then(|()| file.flush())
            .map_err(fail(o))?;
    }
    let mut written = Vec::new();
    for (o, s) in staged {
        s.commit().map_err(|source| WriteError::Partial {
            path: o.path.clone(),
            what: o.what.clone(),
            source,
            written: written.clone(),
        })?;
        written.push(o.path.clone());
    }
    Ok(())
}

/// Plans and writes one output.
pub fn write_one(path: &Path, what: &str, bytes: &[u8]) -> Result<(), WriteError> {
    let output = Output::plan(path, what)?;
    write_all(&[(&output, bytes)])
}
