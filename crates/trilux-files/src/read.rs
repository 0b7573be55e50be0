//! Bounded reads of regular files.
//!
//! A scene, a mesh or a solution is read whole, so a file that never ends
//! (`/dev/zero`, `/dev/urandom`, a FIFO) or one far larger than anything
//! trilux can use must be refused before reading, not after the memory is
//! gone. The kind of file is checked before it is opened (opening a FIFO
//! would block) and again on the open file; the read itself stops one byte
//! past the limit whatever the size said, so a file that grows while it is
//! read is refused too.

use std::fs::{File, Metadata};
use std::io::Read;
use std::path::Path;

use crate::human_bytes;

/// Why a file could not be read (the caller names the file and its role).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ReadError {
    /// The operating system refused (missing file, no permission, ...).
    #[error("{0}")]
    Io(#[from] std::io::Error),
    /// The path names something other than a regular file.
    #[error("it is {kind}, not a regular file")]
    NotRegular {
        /// What it is ("a folder", "a FIFO", "a character device", ...).
        kind: &'static str,
    },
    /// The file is larger than the limit for its role.
    #[error("it is {} or more, and the limit is {} (docs/limits.md)", human_bytes(*size), human_bytes(*limit))]
    TooLarge {
        /// Its size in bytes (at least; a growing file stops being read).
        size: u64,
        /// The limit in bytes.
        limit: u64,
    },
}

/// What kind of non-regular file `meta` describes, for messages.
pub(crate) fn kind_of(meta: &Metadata) -> &'static str {
    let t = meta.file_type();
    if t.is_dir() {
        return "a folder";
    }
    if t.is_symlink() {
        return "a symbolic link";
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if t.is_fifo() {
            return "a FIFO";
        }
        if t.is_char_device() {
            return "a character device";
        }
        if t.is_block_device() {
            return "a block device";
        }
        if t.is_socket() {
            return "a socket";
        }
    }
    if t.is_file() {
        "a regular file"
    } else {
        "a special file"
    }
}

/// The whole content of the regular file at `path` (symbolic links
/// followed), refused when it is not a regular file or holds more than
/// `limit` bytes.
pub fn read_limited(path: &Path, limit: u64) -> Result<Vec<u8>, ReadError> {
    let meta = std::fs::metadata(path)?;
    check(&meta, limit)?;
    let file = File::open(path)?;
    let meta = file.metadata()?;
    check(&meta, limit)?;
    // The size is a hint: never trust it beyond the limit.
    let capacity = usize::try_from(meta.len().min(limit)).unwrap_or(0);
    let mut bytes = Vec::with_capacity(capacity);
    file.take(limit.saturating_add(1)).read_to_end(&mut bytes)?;
    if bytes.len() as u64 > limit {
        return Err(ReadError::TooLarge {
            size: bytes.len() as u64,
            limit,
        });
    }
    Ok(bytes)
}

fn check(meta: &Metadata, limit: u64) -> Result<(), ReadError> {
    if !meta.is_file() {
        return Err(ReadError::NotRegular {
            kind: kind_of(meta),
        });
    }
    if meta.len() > limit {
        return Err(ReadError::TooLarge {
            size: meta.len(),
            limit,
        });
    }
    Ok(())
}
