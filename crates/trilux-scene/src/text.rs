//! A scene file's bytes → its text: UTF-8 only (as Mitsuba's loader
//! expects), with the place of the first byte that is not, and a plain
//! word for UTF-16 files, which editors on some systems write by default;
//! and places in that text as lines and columns ([`Locator`]).

use std::path::Path;
use std::sync::Arc;

use crate::error::{Result, SceneError, SourceLocation};

/// The text of a scene file, or an error at the first byte that is not
/// UTF-8.
pub(crate) fn decode<'a>(bytes: &'a [u8], path: &Path) -> Result<&'a str> {
    let at = |offset: usize, message: String| {
        let (line, col) = line_col(&bytes[..offset]);
        let location = SourceLocation {
            file: Arc::from(path),
            line,
            col,
            pointer: None,
        };
        SceneError::at(&location, message)
    };
    let utf16 = bytes.starts_with(&[0xFF, 0xFE])
        || bytes.starts_with(&[0xFE, 0xFF])
        || (bytes.len() >= 2 && (bytes[0] == 0 || bytes[1] == 0));
    if utf16 {
        return Err(at(
            0,
            "the file is UTF-16; scene files are UTF-8 (convert it, e.g. iconv -f UTF-16 -t UTF-8)"
                .into(),
        ));
    }
    std::str::from_utf8(bytes).map_err(|e| {
        let offset = e.valid_up_to();
        at(
            offset,
            format!(
                "byte 0x{:02X} is not UTF-8; scene files are UTF-8",
                bytes[offset]
            ),
        )
    })
}

/// 1-based line and column (in characters) just after `before`, which is
/// valid UTF-8.
fn line_col(before: &[u8]) -> (u32, u32) {
    let text = std::str::from_utf8(before).unwrap_or("");
    let line = text.matches('\n').count() + 1;
    let last = text.rfind('\n').map_or(text, |i| &text[i + 1..]);
    let col = last.chars().count() + 1;
    (
        u32::try_from(line).unwrap_or(u32::MAX),
        u32::try_from(col).unwrap_or(u32::MAX),
    )
}

/// Lines and columns (1-based, columns in characters, as roxmltree
/// counts them) of byte offsets in one text.
///
/// The XML stage asks for the place of every element and attribute in
/// document order, so the scan resumes where the last one ended: locating
/// every element of a file reads it once. (Counting from the start of the
/// file for each element made a 3.2 MB scene take 45 s.) An offset before
/// the last one starts again from the beginning, which document order
/// never asks.
pub(crate) struct Locator<'a> {
    text: &'a [u8],
    byte: usize,
    line: u32,
    col: u32,
    /// Bytes read so far: the work of locating, at most the text's length
    /// when offsets come in order.
    pub scanned: usize,
}

impl<'a> Locator<'a> {
    /// A locator at the start of `text`.
    pub(crate) fn new(text: &'a str) -> Self {
        Locator {
            text: text.as_bytes(),
            byte: 0,
            line: 1,
            col: 1,
            scanned: 0,
        }
    }

    /// Line and column of byte `offset` (clamped to the text).
    pub(crate) fn at(&mut self, offset: usize) -> (u32, u32) {
        let offset = offset.min(self.text.len());
        if offset < self.byte {
            (self.byte, self.line, self.col) = (0, 1, 1);
        }
        let part = &self.text[self.byte..offset];
        for &b in part {
            if b == b'\n' {
                self.line = self.line.saturating_add(1);
                self.col = 1;
            } else if b & 0xC0 != 0x80 {
                // A character starts at every byte but UTF-8's
                // continuation bytes (10xxxxxx).
                self.col = self.col.saturating_add(1);
            }
        }
        self.scanned += part.len();
        self.byte = offset;
        (self.line, self.col)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn invalid_bytes_are_located() {
        let e = decode(b"<scene>\n  <a v=\"\xE9\"/>", Path::new("s.xml")).unwrap_err();
        assert_eq!(
            e.to_string(),
            "s.xml:2:9: byte 0xE9 is not UTF-8; scene files are UTF-8"
        );
        let e = decode(b"\xFF\xFE<\0s\0", Path::new("s.xml")).unwrap_err();
        assert!(
            e.to_string().starts_with("s.xml:1:1: the file is UTF-16"),
            "{e}"
        );
        let e = decode(b"<\0s\0", Path::new("s.xml")).unwrap_err();
        assert!(
            e.to_string().starts_with("s.xml:1:1: the file is UTF-16"),
            "{e}"
        );
        assert_eq!(decode(b"<scene/>", Path::new("s.xml")).unwrap(), "<scene/>");
    }
}
