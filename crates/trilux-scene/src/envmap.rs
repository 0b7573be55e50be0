//! Mitsuba 3's `envmap` emitter: radiance arriving from infinitely far
//! away, read from an equirectangular image (its parameters as Mitsuba
//! 3.9.1 defines them: `filename`, `scale`, `to_world`,
//! `mis_compensation`). Unlike the `constant` sky (`crate::environment`)
//! no surface stands for it: the solver and the renderer take it as a
//! distant light, sampled by direction (trilux-solver's `sky`;
//! docs/architecture.md, "Environment").
//!
//! The image is an OpenEXR file (its first RGB(A) layer, alpha ignored)
//! or a Radiance RGBE file (`.hdr`, flat or run-length encoded, `-Y +X`
//! orientation), the two high-dynamic-range formats Mitsuba 3.9.1 reads
//! as its `Bitmap`; the format is told by the file's first bytes.
//! `mis_compensation` changes only how Mitsuba samples the map, not the
//! light it gives: it is accepted and has no effect. `to_world` must be a
//! rotation (Mitsuba would stretch the sky's directions).

use std::path::{Path, PathBuf};

use glam::DMat3;
use serde::Serialize;

use crate::error::{Result, SceneError};
use crate::limits::{MAX_IMAGE_BYTES, MAX_RADIANCE, MAX_TEXTURE_TEXELS};
use crate::props::Props;
use crate::xml::Element;

/// An environment map as read: linear RGB texels, row-major from the top
/// (the +y pole), with its scale and orientation.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct EnvMap {
    /// The image file.
    pub file: PathBuf,
    /// Texels per row.
    pub width: usize,
    /// Rows.
    pub height: usize,
    /// Linear RGB radiance of each texel (before `scale`).
    #[serde(skip)]
    pub texels: Vec<[f32; 3]>,
    /// Mitsuba's `scale` (default 1).
    pub scale: f64,
    /// The rotation `to_world` (identity by default): Mitsuba's envmap frame
    /// has +y up and u along φ from −z towards +x.
    pub world_from_sky: DMat3,
}

/// Builds the map of a top-level `<emitter type="envmap">` whose relative
/// file name starts in `folder`; the image is read and checked here.
pub(crate) fn envmap(e: &Element, folder: &Path) -> Result<EnvMap> {
    e.check_attrs(&["type", "id", "name"])?;
    let props = Props::new(e)?;
    props.no_objects()?;
    props.float("sampling_weight")?;
    props.boolean("mis_compensation")?;
    let name = props.string("filename")?.ok_or_else(|| {
        SceneError::at(
            &e.loc,
            "<emitter type=\"envmap\"> needs <string name=\"filename\">",
        )
    })?;
    let scale = props.float("scale")?.unwrap_or(1.0);
    if !(scale.is_finite() && scale >= 0.0) {
        return Err(SceneError::at(
            &props.loc("scale"),
            format!("scale {scale} must be finite and not negative"),
        ));
    }
    let world_from_sky = match props.transform("to_world")? {
        None => DMat3::IDENTITY,
        Some(t) => {
            let m = DMat3::from_mat4(t.matrix);
            let off = (m.transpose() * m - DMat3::IDENTITY)
                .to_cols_array()
                .into_iter()
                .fold(0.0f64, |a, x| a.max(x.abs()));
            if !(off < 1e-6 && m.determinant() > 0.0) {
                return Err(SceneError::at(
                    &props.loc("to_world"),
                    "an envmap's to_world must be a rotation (no scale, shear or mirror)",
                ));
            }
            m
        }
    };
    let location = props.loc("filename");
    props.finish()?;
    let file = folder.join(&name);
    let at = |m: String| SceneError::at(&location, format!("{}: {m}", file.display()));
    let bytes = trilux_files::read_limited(&file, MAX_IMAGE_BYTES)
        .map_err(|err| at(format!("cannot read the environment map: {err}")))?;
    let (width, height, texels) = decode(&bytes).map_err(at)?;
    if height < 2 {
        return Err(at(format!(
            "an environment map needs at least 2 rows, this one has {height}"
        )));
    }
    if let Some(k) = texels.iter().position(|t| {
        t.iter()
            .any(|&c| !(c.is_finite() && c >= 0.0 && f64::from(c) * scale <= MAX_RADIANCE))
    }) {
        return Err(at(format!(
            "texel ({}, {}) is {:?}: every value must be finite, not negative and, scaled, at most {MAX_RADIANCE:e} (docs/limits.md)",
            k % width,
            k / width,
            texels[k]
        )));
    }
    Ok(EnvMap {
        file,
        width,
        height,
        texels,
        scale,
        world_from_sky,
    })
}

type Texels = (usize, usize, Vec<[f32; 3]>);

/// An OpenEXR or Radiance RGBE image, told by its first bytes.
fn decode(bytes: &[u8]) -> std::result::Result<Texels, String> {
    if bytes.starts_with(&[0x76, 0x2f, 0x31, 0x01]) {
        decode_exr(bytes)
    } else if bytes.starts_with(b"#?") {
        crate::rgbe::decode(bytes, MAX_TEXTURE_TEXELS)
    } else {
        Err(
            "not an OpenEXR or Radiance (.hdr) image (the first bytes are neither signature)"
                .into(),
        )
    }
}

fn decode_exr(bytes: &[u8]) -> std::result::Result<Texels, String> {
    use exr::prelude::*;
    let too_large = |w: usize, h: usize| (w as u64) * (h as u64) > MAX_TEXTURE_TEXELS;
    let image = read()
        .no_deep_data()
        .largest_resolution_level()
        .rgba_channels(
            |res, _| {
                let (w, h) = (res.width(), res.height());
                let n = if too_large(w, h) { 0 } else { w * h };
                (w, vec![[0f32; 3]; n])
            },
            |(w, px): &mut (usize, Vec<[f32; 3]>), pos, (r, g, b, _a): (f32, f32, f32, f32)| {
                if let Some(p) = px.get_mut(pos.y() * *w + pos.x()) {
                    *p = [r, g, b];
                }
            },
        )
        .first_valid_layer()
        .all_attributes()
        .from_buffered(std::io::Cursor::new(bytes))
        .map_err(|e| format!("malformed OpenEXR image: {e}"))?;
    let size = image.layer_data.size;
    let (w, h) = (size.width(), size.height());
    if too_large(w, h) {
        return Err(format!(
            "image of {w} × {h} texels is beyond the limit of {MAX_TEXTURE_TEXELS} texels (docs/limits.md)"
        ));
    }
    let (_, texels) = image.layer_data.channel_data.pixels;
    Ok((w, h, texels))
}
