//! Finished images and their files.
//!
//! - EXR: linear float RGB (32-bit float per channel, ZIP compression), the
//!   values exactly as rendered (spectral renders converted to linear sRGB).
//! - PNG: 8-bit sRGB. Tone map: each linear value is multiplied by
//!   2^exposure, **clamped** to [0, 1], then encoded with the sRGB transfer
//!   curve (IEC 61966-2-1) and rounded. No other curve is applied.
//!
//! Writes are atomic: the data go to a temporary file in the same folder,
//! which is renamed over the destination only when complete. A failed write
//! removes the temporary file, so no half-written image is ever left.

use std::path::{Path, PathBuf};

use crate::error::RenderError;

/// A linear RGB image, row-major from the top-left pixel.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    width: u32,
    height: u32,
    pixels: Vec<[f32; 3]>,
}

/// The sRGB transfer curve (linear → encoded), for values in [0, 1].
pub fn srgb_encode(linear: f64) -> f64 {
    if linear <= 0.003_130_8 {
        12.92 * linear
    } else {
        1.055 * linear.powf(1.0 / 2.4) - 0.055
    }
}

fn write_err(path: &Path, reason: impl ToString) -> RenderError {
    RenderError::Write {
        path: path.to_path_buf(),
        reason: reason.to_string(),
    }
}

/// Runs `write` on a temporary path beside `path`, then renames it to
/// `path`. On failure the temporary file is removed.
pub fn write_atomically(
    path: &Path,
    write: impl FnOnce(&Path) -> Result<(), String>,
) -> Result<(), RenderError> {
    let name = path
        .file_name()
        .ok_or_else(|| write_err(path, "not a file name"))?
        .to_string_lossy()
        .into_owned();
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    if !dir.is_dir() {
        return Err(write_err(path, "the folder does not exist"));
    }
    // Keep the extension last: the exr crate picks nothing from it, but
    // other tools looking at a stray temporary file would.
    let tmp = dir.join(format!(".{name}.tmp-{}", std::process::id()));
    let result = write(&tmp).and_then(|()| std::fs::rename(&tmp, path).map_err(|e| e.to_string()));
    if let Err(reason) = result {
        let _ = std::fs::remove_file(&tmp);
        return Err(write_err(path, reason));
    }
    Ok(())
}

impl Image {
    /// An image from row-major pixels; `pixels.len()` must be width·height.
    pub fn from_pixels(
        width: u32,
        height: u32,
        pixels: Vec<[f32; 3]>,
    ) -> Result<Self, RenderError> {
        if width == 0 || height == 0 || pixels.len() != width as usize * height as usize {
            return Err(RenderError::Settings(format!(
                "{} pixels do not make a {width}x{height} image",
                pixels.len()
            )));
        }
        Ok(Self {
            width,
            height,
            pixels,
        })
    }

    /// A black image.
    pub fn black(width: u32, height: u32) -> Self {
        Self {
            width: width.max(1),
            height: height.max(1),
            pixels: vec![[0.0; 3]; width.max(1) as usize * height.max(1) as usize],
        }
    }

    /// Width in pixels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Height in pixels.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// All pixels, row-major from the top-left.
    pub fn pixels(&self) -> &[[f32; 3]] {
        &self.pixels
    }

    /// Pixel (x, y).
    pub fn get(&self, x: u32, y: u32) -> [f32; 3] {
        self.pixels[y as usize * self.width as usize + x as usize]
    }

    /// Mean of each channel over the image (f64 accumulation).
    pub fn mean(&self) -> [f64; 3] {
        let mut m = [0.0f64; 3];
        for p in &self.pixels {
            for c in 0..3 {
                m[c] += p[c] as f64;
            }
        }
        m.map(|v| v / self.pixels.len() as f64)
    }

    /// Writes linear float RGB OpenEXR, atomically.
    pub fn write_exr(&self, path: &Path) -> Result<(), RenderError> {
        write_atomically(path, |tmp| {
            let w = self.width as usize;
            exr::prelude::write_rgb_file(tmp, w, self.height as usize, |x, y| {
                let p = self.pixels[y * w + x];
                (p[0], p[1], p[2])
            })
            .map_err(|e| e.to_string())
        })
    }

    /// Encodes 8-bit sRGB: clamp(value · 2^exposure, 0, 1), sRGB curve.
    pub fn to_srgb8(&self, exposure: f64) -> Vec<u8> {
        let k = 2f64.powf(exposure);
        let mut out = Vec::with_capacity(self.pixels.len() * 3);
        for p in &self.pixels {
            for &c in p {
                let v = (c as f64 * k).clamp(0.0, 1.0);
                // NaN never reaches here from the renderer; map it to 0 anyway.
                let v = if v.is_nan() { 0.0 } else { v };
                out.push((srgb_encode(v) * 255.0 + 0.5).floor() as u8);
            }
        }
        out
    }

    /// Writes an 8-bit sRGB PNG (tone map: see the module docs), atomically.
    pub fn write_png(&self, path: &Path, exposure: f64) -> Result<(), RenderError> {
        let data = self.to_srgb8(exposure);
        let mut bytes = Vec::new();
        {
            let mut enc = png::Encoder::new(&mut bytes, self.width, self.height);
            enc.set_color(png::ColorType::Rgb);
            enc.set_depth(png::BitDepth::Eight);
            enc.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
            let mut w = enc.write_header().map_err(|e| write_err(path, e))?;
            w.write_image_data(&data).map_err(|e| write_err(path, e))?;
        }
        write_atomically(path, |tmp| {
            std::fs::write(tmp, &bytes).map_err(|e| e.to_string())
        })
    }

    /// Reads the first RGB(A) layer of an OpenEXR file (alpha ignored).
    pub fn read_exr(path: &Path) -> Result<Self, RenderError> {
        let read_err = |reason: String| RenderError::Read {
            path: path.to_path_buf(),
            reason,
        };
        let img = exr::prelude::read_first_rgba_layer_from_file(
            path,
            |res, _| (res.width(), vec![[0f32; 3]; res.width() * res.height()]),
            |(w, px): &mut (usize, Vec<[f32; 3]>), pos, (r, g, b, _a): (f32, f32, f32, f32)| {
                px[pos.y() * *w + pos.x()] = [r, g, b];
            },
        )
        .map_err(|e| read_err(e.to_string()))?;
        let size = img.layer_data.size;
        let (_, pixels) = img.layer_data.channel_data.pixels;
        Image::from_pixels(size.width() as u32, size.height() as u32, pixels)
            .map_err(|e| read_err(e.to_string()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tmpdir(tag: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("trilux-render-{tag}-{}", std::process::id()));
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    #[test]
    fn exr_round_trip_is_exact() {
        let d = tmpdir("exr");
        let px: Vec<[f32; 3]> = (0..12).map(|i| [i as f32 * 0.1, 2.5e3, 1e-7]).collect();
        let img = Image::from_pixels(4, 3, px).unwrap();
        let p = d.join("a.exr");
        img.write_exr(&p).unwrap();
        assert_eq!(Image::read_exr(&p).unwrap(), img);
        // Only the file itself is left in the folder.
        assert_eq!(std::fs::read_dir(&d).unwrap().count(), 1);
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn unwritable_paths_are_errors_and_leave_nothing() {
        let img = Image::black(2, 2);
        let d = tmpdir("bad");
        let missing = d.join("no/such/folder/x.exr");
        assert!(img.write_exr(&missing).is_err());
        assert!(img.write_png(&d.join("no/x.png"), 0.0).is_err());
        // A folder in place of the output file: the rename fails.
        std::fs::create_dir_all(d.join("taken.exr")).unwrap();
        assert!(img.write_exr(&d.join("taken.exr")).is_err());
        let left: Vec<_> = std::fs::read_dir(&d).unwrap().collect();
        assert_eq!(left.len(), 1, "only the folder we made: {left:?}");
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn png_tone_map_clamps_and_encodes_srgb() {
        let img = Image::from_pixels(4, 1, vec![[0.0; 3], [0.5; 3], [1.0; 3], [7.0; 3]]).unwrap();
        let b = img.to_srgb8(0.0);
        // sRGB(0.5) = 1.055·0.5^(1/2.4) − 0.055 = 0.735357 → 188.
        assert_eq!(
            &b[..],
            &[0, 0, 0, 188, 188, 188, 255, 255, 255, 255, 255, 255]
        );
        // Exposure +1 doubles: 0.5 → 1.0.
        assert_eq!(img.to_srgb8(1.0)[3], 255);
    }
}
