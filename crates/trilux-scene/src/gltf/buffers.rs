//! glTF buffers: the bytes behind accessors and images, read when the
//! scene is finished.
//!
//! A buffer is the `.glb` file's binary chunk (no `uri`), a `data:` URI
//! (base64), or a file named relative to the glTF file (percent-encoded, as
//! URIs are). Files are read with bounds ([`MAX_GLB_BYTES`] each,
//! [`MAX_GLTF_BUFFER_BYTES`] in all); a buffer shorter than its
//! `byteLength` is an error. Each buffer is read once, when first used.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use crate::error::{Result, SceneError, SourceLocation};
use crate::limits::{MAX_GLB_BYTES, MAX_GLTF_BUFFER_BYTES};

/// Decodes standard base64 (`+/`, `=` padding; line breaks and spaces
/// skipped). `None` on any other character or a bad length.
pub(crate) fn base64(text: &str) -> Option<Vec<u8>> {
    let mut out = Vec::with_capacity(text.len() / 4 * 3);
    let (mut acc, mut bits, mut pad) = (0u32, 0u32, 0usize);
    for c in text.bytes() {
        let v = match c {
            b'A'..=b'Z' => c - b'A',
            b'a'..=b'z' => c - b'a' + 26,
            b'0'..=b'9' => c - b'0' + 52,
            b'+' => 62,
            b'/' => 63,
            b'=' => {
                pad += 1;
                continue;
            }
            b' ' | b'\n' | b'\r' | b'\t' => continue,
            _ => return None,
        };
        if pad > 0 {
            return None;
        }
        acc = (acc << 6) | u32::from(v);
        bits += 6;
        if bits >= 8 {
            bits -= 8;
            out.push((acc >> bits) as u8);
        }
    }
    (pad <= 2 && bits < 6).then_some(out)
}

/// The payload of a `data:` URI, if `uri` is one (only base64 payloads).
pub(crate) fn data_uri(uri: &str) -> Option<std::result::Result<Vec<u8>, &'static str>> {
    let rest = uri.strip_prefix("data:")?;
    Some(match rest.split_once(',') {
        Some((header, payload)) if header.ends_with(";base64") => {
            base64(payload).ok_or("the data URI is not valid base64")
        }
        _ => Err("only base64 data URIs are supported"),
    })
}

/// `uri` with its %XX escapes decoded, as a path relative to `folder`.
pub(crate) fn relative_path(folder: &Path, uri: &str) -> std::result::Result<PathBuf, String> {
    if uri.contains("://") || uri.starts_with('/') {
        return Err(format!(
            "\"{}\" is not a relative file name (only files beside the glTF file and data URIs are read)",
            crate::error::elide(uri, 200)
        ));
    }
    let bytes = uri.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' {
            let hex = bytes
                .get(i + 1..i + 3)
                .and_then(|h| std::str::from_utf8(h).ok())
                .and_then(|h| u8::from_str_radix(h, 16).ok())
                .ok_or_else(|| "a malformed %-escape in a URI".to_string())?;
            out.push(hex);
            i += 3;
        } else {
            out.push(bytes[i]);
            i += 1;
        }
    }
    let name =
        String::from_utf8(out).map_err(|_| "a URI that is not UTF-8 once decoded".to_string())?;
    Ok(folder.join(name))
}

/// The buffers of one glTF file, read on first use.
#[derive(Debug)]
pub(crate) struct Buffers {
    file: Arc<Path>,
    folder: PathBuf,
    blob: Option<Arc<[u8]>>,
    loaded: Vec<Option<Arc<[u8]>>>,
    total: u64,
}

impl Buffers {
    pub fn new(file: Arc<Path>, blob: Option<Vec<u8>>, count: usize) -> Self {
        let folder = file.parent().map(Path::to_path_buf).unwrap_or_default();
        Buffers {
            file,
            folder,
            blob: blob.map(Arc::from),
            loaded: vec![None; count],
            total: 0,
        }
    }

    fn at(&self, index: usize, message: impl Into<String>) -> SceneError {
        SceneError::at(
            &SourceLocation::json(&self.file, format!("/buffers/{index}")),
            message,
        )
    }

    /// The bytes of buffer `buffer` (at least its `byteLength`).
    pub fn get(&mut self, buffer: &gltf::Buffer<'_>) -> Result<Arc<[u8]>> {
        let index = buffer.index();
        if let Some(Some(b)) = self.loaded.get(index) {
            return Ok(Arc::clone(b));
        }
        let bytes: Arc<[u8]> = match buffer.source() {
            gltf::buffer::Source::Bin => self.blob.clone().ok_or_else(|| {
                self.at(
                    index,
                    "the buffer has no uri and the file has no binary chunk",
                )
            })?,
            gltf::buffer::Source::Uri(uri) => match data_uri(uri) {
                Some(r) => Arc::from(r.map_err(|m| self.at(index, m))?),
                None => {
                    let path = relative_path(&self.folder, uri).map_err(|m| self.at(index, m))?;
                    let bytes = trilux_files::read_limited(&path, MAX_GLB_BYTES).map_err(|e| {
                        self.at(index, format!("cannot read buffer {}: {e}", path.display()))
                    })?;
                    Arc::from(bytes)
                }
            },
        };
        if bytes.len() < buffer.length() {
            return Err(self.at(
                index,
                format!(
                    "the buffer holds {} bytes, fewer than its byteLength {}",
                    bytes.len(),
                    buffer.length()
                ),
            ));
        }
        self.total += bytes.len() as u64;
        if self.total > MAX_GLTF_BUFFER_BYTES {
            return Err(self.at(
                index,
                format!("the file's buffers hold more than {MAX_GLTF_BUFFER_BYTES} bytes in all (docs/limits.md)"),
            ));
        }
        if let Some(slot) = self.loaded.get_mut(index) {
            *slot = Some(Arc::clone(&bytes));
        }
        Ok(bytes)
    }

    /// The bytes of buffer view `view`, within its buffer.
    pub fn view(&mut self, view: &gltf::buffer::View<'_>) -> Result<Arc<[u8]>> {
        let bytes = self.get(&view.buffer())?;
        let (start, len) = (view.offset(), view.length());
        let end = start
            .checked_add(len)
            .filter(|&e| e <= view.buffer().length());
        match end {
            Some(end) => Ok(Arc::from(&bytes[start..end])),
            None => Err(SceneError::at(
                &SourceLocation::json(&self.file, format!("/bufferViews/{}", view.index())),
                format!(
                    "the view's bytes {start}..{start}+{len} lie outside its buffer of {} bytes",
                    view.buffer().length()
                ),
            )),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_round_trips() {
        assert_eq!(base64("aGVsbG8=").as_deref(), Some(&b"hello"[..]));
        assert_eq!(base64("aGVsbG8h").as_deref(), Some(&b"hello!"[..]));
        assert_eq!(base64("").as_deref(), Some(&b""[..]));
        assert!(base64("aGV*").is_none());
        assert!(base64("a=b").is_none());
        assert_eq!(
            relative_path(Path::new("d"), "my%20mesh.bin").unwrap(),
            Path::new("d/my mesh.bin")
        );
        assert!(relative_path(Path::new("d"), "http://x/y.bin").is_err());
        assert!(relative_path(Path::new("d"), "a%2").is_err());
    }
}
