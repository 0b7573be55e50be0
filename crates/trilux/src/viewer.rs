//! `trilux view FILE.glb [--port N] [--open]`: an existing bake in
//! trilux's viewer on localhost, without solving again (the server of
//! `bake --open`, `serve`). The file is checked to be a glTF binary
//! before anything is served, so a wrong file is one located error line
//! here rather than a failure in the browser.

use std::path::PathBuf;

use anyhow::{Result, anyhow};
use clap::Args;

/// Arguments of `trilux view`.
#[derive(Debug, Args)]
pub struct ViewArgs {
    /// The glTF binary (.glb) to show, e.g. one `trilux bake` wrote.
    pub file: PathBuf,
    /// The port to serve on (default: any free one).
    #[arg(long)]
    pub port: Option<u16>,
    /// Open the address in the system browser ($BROWSER, else xdg-open);
    /// where there is none, say so and keep serving.
    #[arg(long)]
    pub open: bool,
}

/// Runs `trilux view`.
pub fn run(args: &ViewArgs) -> Result<()> {
    let glb = std::fs::read(&args.file)
        .map_err(|e| anyhow!("{}: cannot read: {e}", args.file.display()))?;
    check_glb(&glb).map_err(|e| anyhow!("{}: {e}", args.file.display()))?;
    let listener = crate::serve::listen(args.port.unwrap_or(0))?;
    crate::serve::serve(listener, &glb, args.open)
}

/// The chunk type of a glTF binary's JSON chunk ("JSON", little-endian).
const JSON_CHUNK: u32 = 0x4E4F_534A;

/// Checks the glTF 2.0 binary container (glTF 2.0 §4.4): the 12-byte
/// header (magic, version 2, the file's length), a first chunk of JSON
/// whose `asset.version` is 2.x. The viewer reads the rest; a file that
/// passes here and fails there is reported on the page.
pub fn check_glb(bytes: &[u8]) -> Result<(), String> {
    let word = |at: usize| -> Option<u32> {
        let b = bytes.get(at..at + 4)?;
        Some(u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    };
    if !bytes.starts_with(b"glTF") {
        return Err(
            "byte 0: not a glTF binary (.glb): it does not begin with \"glTF\" (a .gltf must be packed into a .glb first)"
                .into(),
        );
    }
    let (Some(version), Some(length)) = (word(4), word(8)) else {
        return Err(format!(
            "byte {}: the file ends inside the 12-byte glTF header",
            bytes.len()
        ));
    };
    if version != 2 {
        return Err(format!("byte 4: glTF binary version {version}, not 2"));
    }
    if u64::from(length) != bytes.len() as u64 {
        return Err(format!(
            "byte 8: the header gives a length of {length} bytes, the file has {}",
            bytes.len()
        ));
    }
    let (Some(chunk), Some(kind)) = (word(12), word(16)) else {
        return Err("byte 12: no JSON chunk after the header".into());
    };
    if kind != JSON_CHUNK {
        return Err(format!(
            "byte 16: the first chunk is of type {kind:#010x}, not JSON"
        ));
    }
    let json = usize::try_from(chunk)
        .ok()
        .and_then(|n| bytes.get(20..20usize.checked_add(n)?))
        .ok_or_else(|| {
            format!("byte 12: the JSON chunk's length {chunk} runs past the file's end")
        })?;
    let doc: serde_json::Value =
        serde_json::from_slice(json).map_err(|e| format!("JSON chunk (byte 20 on): {e}"))?;
    match doc.pointer("/asset/version").and_then(|v| v.as_str()) {
        Some(v) if v.starts_with("2.") => Ok(()),
        Some(v) => Err(format!("JSON chunk: asset.version is \"{v}\", not 2.x")),
        None => Err("JSON chunk: no asset.version (every glTF has one)".into()),
    }
}
