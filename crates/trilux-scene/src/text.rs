//! A scene file's bytes → its text: UTF-8 only (as Mitsuba's loader
//! expects), with the place of the first byte that is not, and a plain
//! word for UTF-16 files, which editors on some systems write by default.

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
