//! Writing what the commands produce: images, statistics JSON.

use std::path::Path;

use anyhow::{Context, Result};
use trilux_render::Image;

/// The statistics JSON: the solver's figures plus the render time.
pub fn stats_json(stats: &trilux_solver::SolveStats, render_seconds: f64) -> serde_json::Value {
    let mut value = serde_json::to_value(stats).unwrap_or(serde_json::Value::Null);
    if let Some(map) = value.as_object_mut() {
        map.insert("render_seconds".into(), serde_json::json!(render_seconds));
    }
    value
}

/// Writes JSON atomically (temporary file, then rename).
pub fn write_json(path: &Path, value: &impl serde::Serialize) -> Result<()> {
    let text = serde_json::to_string_pretty(value)?;
    let tmp = path.with_extension("tmp-trilux");
    std::fs::write(&tmp, text).with_context(|| format!("{}: cannot write", path.display()))?;
    std::fs::rename(&tmp, path).map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        anyhow::anyhow!("{}: cannot write: {e}", path.display())
    })
}

/// Writes the EXR and, if asked, the PNG (exposure 0, clamped).
pub fn write_images(image: &Image, exr: &Path, png: Option<&Path>) -> Result<()> {
    image.write_exr(exr)?;
    if let Some(png) = png {
        image.write_png(png, 0.0)?;
    }
    Ok(())
}
