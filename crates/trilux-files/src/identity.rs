//! Which file a path names, so that paths can be compared.
//!
//! Text comparison is not enough: `a/../b` and `b`, a hard link and its
//! original, a symbolic link and its target all name one file, and an
//! output that does not exist yet has no canonical path. A path is first
//! resolved by following its symbolic links ([`resolve`]); an existing file
//! is then known by its device and inode, a file still to be made by its
//! canonical folder and its name.

use std::fs::Metadata;
use std::io;
use std::path::{Path, PathBuf};

/// The most symbolic links followed for one path (Linux's own limit).
const MAX_LINKS: usize = 40;

/// What a path names, for comparing paths.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub enum FileIdentity {
    /// An existing file: its device and inode (its canonical path where
    /// those are not available).
    Existing(Key),
    /// A file that does not exist yet: its canonical folder and its name.
    New(PathBuf),
}

/// The identity of an existing file.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct Key(KeyInner);

#[cfg(unix)]
type KeyInner = (u64, u64);
#[cfg(not(unix))]
type KeyInner = PathBuf;

/// A path with its symbolic links followed.
#[derive(Debug)]
pub struct Resolved {
    /// The path of the file itself (no symbolic link left at the end).
    pub path: PathBuf,
    /// Its metadata, `None` when it does not exist.
    pub meta: Option<Metadata>,
}

/// Follows the symbolic links at the end of `path` (a dangling link
/// resolves to the path it names, which does not exist).
pub fn resolve(path: &Path) -> io::Result<Resolved> {
    let mut p = path.to_path_buf();
    for _ in 0..MAX_LINKS {
        let meta = match std::fs::symlink_metadata(&p) {
            Ok(m) => m,
            Err(e) if e.kind() == io::ErrorKind::NotFound => {
                return Ok(Resolved {
                    path: p,
                    meta: None,
                });
            }
            Err(e) => return Err(e),
        };
        if !meta.file_type().is_symlink() {
            return Ok(Resolved {
                path: p,
                meta: Some(meta),
            });
        }
        let link = std::fs::read_link(&p)?;
        let next = match p.parent() {
            Some(dir) if link.is_relative() => dir.join(link),
            _ => link,
        };
        if let Some(magic) = magic_link(&p, &next) {
            return Ok(magic);
        }
        p = next;
    }
    Err(io::Error::other(format!(
        "more than {MAX_LINKS} symbolic links to follow"
    )))
}

/// A link whose text names no path but the kernel follows all the same:
/// `/dev/stdout` is `/proc/self/fd/1`, whose text is `pipe:[1234]` when
/// stdout is a pipe. When `next` (the text followed) does not exist but
/// `link` opens, `link` itself is the path to write through, with the
/// metadata of what it opens (a pipe, a socket). A dangling link (nothing
/// opens) is not one.
fn magic_link(link: &Path, next: &Path) -> Option<Resolved> {
    if std::fs::symlink_metadata(next).is_ok() {
        return None;
    }
    let meta = std::fs::metadata(link).ok()?;
    Some(Resolved {
        path: link.to_path_buf(),
        meta: Some(meta),
    })
}

impl FileIdentity {
    /// The identity of what `path` names (module docs). Fails when the
    /// path's folder does not exist or cannot be read.
    pub fn of(path: &Path) -> io::Result<FileIdentity> {
        let r = resolve(path)?;
        match &r.meta {
            Some(meta) => Ok(FileIdentity::Existing(key(&r.path, meta)?)),
            None => {
                let name = r.path.file_name().ok_or_else(|| {
                    io::Error::new(io::ErrorKind::InvalidInput, "the path names no file")
                })?;
                let dir = match r.path.parent() {
                    Some(d) if !d.as_os_str().is_empty() => d,
                    _ => Path::new("."),
                };
                Ok(FileIdentity::New(std::fs::canonicalize(dir)?.join(name)))
            }
        }
    }
}

#[cfg(unix)]
fn key(_path: &Path, meta: &Metadata) -> io::Result<Key> {
    use std::os::unix::fs::MetadataExt;
    Ok(Key((meta.dev(), meta.ino())))
}

#[cfg(not(unix))]
fn key(path: &Path, _meta: &Metadata) -> io::Result<Key> {
    Ok(Key(std::fs::canonicalize(path)?))
}
