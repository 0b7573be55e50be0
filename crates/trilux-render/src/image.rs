//! Finished images and their files.
//!
//! - EXR: linear float RGB (32-bit float per channel, ZIP compression in
//!   blocks of 16 scan lines), the values exactly as rendered (spectral
//!   renders converted to linear sRGB).
//! - PNG: 8-bit sRGB. Tone map: each linear value is multiplied by
//!   2^exposure, **clamped** to [0, 1], then encoded with the sRGB transfer
//!   curve (IEC 61966-2-1) and rounded. No other curve is applied.
//!
//! An image with a pixel that is not finite is never written: encoding it
//! is an error. Files are written with `trilux_files` (a symbolic link's
//! target is replaced, a FIFO or device written through, a regular file
//! replaced only once the new one is complete); a caller with several
//! outputs encodes each ([`Image::exr_bytes`], [`Image::png_bytes`]) and
//! writes them all or none with `trilux_files::write_all`.

use std::io::Cursor;
use std::path::Path;

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

    /// The `w` × `h` pixels at (`x`, `y`), which must lie within.
    pub(crate) fn window(&self, x: u32, y: u32, w: u32, h: u32) -> Self {
        let row = |j: u32| {
            let start = (y + j) as usize * self.width as usize + x as usize;
            self.pixels[start..start + w as usize].iter().copied()
        };
        Self {
            width: w,
            height: h,
            pixels: (0..h).flat_map(row).collect(),
        }
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

    /// Mutable pixels, row-major from the top-left.
    pub fn pixels_mut(&mut self) -> &mut [[f32; 3]] {
        &mut self.pixels
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

    /// The first pixel that is not finite, as (x, y), if any.
    pub fn first_non_finite(&self) -> Option<(u32, u32)> {
        let i = self
            .pixels
            .iter()
            .position(|p| !p.iter().all(|c| c.is_finite()))?;
        let w = self.width as usize;
        Some(((i % w) as u32, (i / w) as u32))
    }

    /// Refuses an image with a pixel that is not finite.
    fn check_finite(&self) -> Result<(), RenderError> {
        match self.first_non_finite() {
            None => Ok(()),
            Some((x, y)) => Err(RenderError::NonFinitePixel {
                x,
                y,
                value: self.get(x, y),
            }),
        }
    }

    /// The OpenEXR file of this image (linear float RGB, ZIP).
    pub fn exr_bytes(&self) -> Result<Vec<u8>, RenderError> {
        self.exr_bytes_with(&[])
    }

    /// The OpenEXR file of this image with `attributes` (name, text) as
    /// string attributes of its header, so that a file carries how it was
    /// made; `software` sets the standard attribute of that name. Texts
    /// must be Latin-1 (the header's strings are bytes), names shorter
    /// than 32 bytes (longer ones need OpenEXR's long-names flag).
    pub fn exr_bytes_with(&self, attributes: &[(&str, &str)]) -> Result<Vec<u8>, RenderError> {
        use exr::prelude::{AttributeValue, Text};
        use exr::prelude::{Encoding, Image as ExrImage, SpecificChannels, Vec2, WritableImage};
        self.check_finite()?;
        let w = self.width as usize;
        let channels = SpecificChannels::rgb(|Vec2(x, y): Vec2<usize>| {
            let p = self.pixels[y * w + x];
            (p[0], p[1], p[2])
        });
        let mut image = ExrImage::from_encoded_channels(
            (w, self.height as usize),
            Encoding::SMALL_LOSSLESS,
            channels,
        );
        let encode = |what: &str| RenderError::Encode {
            format: "EXR",
            reason: format!("the header attribute {what} is not Latin-1 text"),
        };
        let header = &mut image.layer_data.attributes;
        for (name, text) in attributes {
            let value = Text::new_or_none(text).ok_or_else(|| encode(name))?;
            if *name == "software" {
                header.software_name = Some(value);
            } else {
                let key = Text::new_or_none(name).ok_or_else(|| encode(name))?;
                header.other.insert(key, AttributeValue::Text(value));
            }
        }
        let mut bytes = Cursor::new(Vec::new());
        image
            .write()
            .to_buffered(&mut bytes)
            .map_err(|e| RenderError::Encode {
                format: "EXR",
                reason: e.to_string(),
            })?;
        Ok(bytes.into_inner())
    }

    /// Writes linear float RGB OpenEXR (module docs).
    pub fn write_exr(&self, path: &Path) -> Result<(), RenderError> {
        let bytes = self.exr_bytes()?;
        trilux_files::write_one(path, "EXR image", &bytes).map_err(RenderError::from)
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

    /// The 8-bit sRGB PNG file of this image (tone map: see the module
    /// docs).
    pub fn png_bytes(&self, exposure: f64) -> Result<Vec<u8>, RenderError> {
        self.check_finite()?;
        let data = self.to_srgb8(exposure);
        let mut bytes = Vec::new();
        let encode = |e: png::EncodingError| RenderError::Encode {
            format: "PNG",
            reason: e.to_string(),
        };
        {
            let mut enc = png::Encoder::new(&mut bytes, self.width, self.height);
            enc.set_color(png::ColorType::Rgb);
            enc.set_depth(png::BitDepth::Eight);
            enc.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
            let mut w = enc.write_header().map_err(encode)?;
            w.write_image_data(&data).map_err(encode)?;
        }
        Ok(bytes)
    }

    /// Writes an 8-bit sRGB PNG (module docs).
    pub fn write_png(&self, path: &Path, exposure: f64) -> Result<(), RenderError> {
        let bytes = self.png_bytes(exposure)?;
        trilux_files::write_one(path, "PNG image", &bytes).map_err(RenderError::from)
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
    use std::path::PathBuf;

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
        // A folder in place of the output file is refused.
        std::fs::create_dir_all(d.join("taken.exr")).unwrap();
        assert!(img.write_exr(&d.join("taken.exr")).is_err());
        let left: Vec<_> = std::fs::read_dir(&d).unwrap().collect();
        assert_eq!(left.len(), 1, "only the folder we made: {left:?}");
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn exr_is_zip_compressed_as_documented() {
        let img = Image::from_pixels(3, 2, vec![[0.5, 1.0, 2.0]; 6]).unwrap();
        let bytes = img.exr_bytes().unwrap();
        let meta = exr::meta::MetaData::read_from_buffered(Cursor::new(&bytes), false).unwrap();
        assert_eq!(
            meta.headers[0].compression,
            exr::compression::Compression::ZIP16
        );
    }

    #[test]
    fn header_attributes_read_back_and_leave_the_pixels_alone() {
        use exr::meta::attribute::{AttributeValue, Text};
        let img = Image::from_pixels(3, 2, vec![[0.5, 1.0, 2.0]; 6]).unwrap();
        let bytes = img
            .exr_bytes_with(&[("software", "trilux x"), ("trilux.a", "[1,2]")])
            .unwrap();
        let meta = exr::meta::MetaData::read_from_buffered(Cursor::new(&bytes), false).unwrap();
        let own = &meta.headers[0].own_attributes;
        assert_eq!(own.software_name, Some(Text::from("trilux x")));
        assert_eq!(
            own.other.get(&Text::from("trilux.a")),
            Some(&AttributeValue::Text(Text::from("[1,2]")))
        );
        let d = tmpdir("attributes");
        std::fs::write(d.join("a.exr"), &bytes).unwrap();
        assert_eq!(Image::read_exr(&d.join("a.exr")).unwrap(), img);
        std::fs::remove_dir_all(&d).unwrap();
        // Text beyond Latin-1 has no bytes in a header: refused, not mangled.
        assert!(img.exr_bytes_with(&[("trilux.b", "日本")]).is_err());
    }

    #[test]
    fn a_non_finite_pixel_is_never_written() {
        let d = tmpdir("non-finite");
        for bad in [f32::INFINITY, f32::NAN, f32::NEG_INFINITY] {
            let mut img = Image::black(3, 2);
            img.pixels_mut()[4] = [0.0, bad, 0.0];
            let e = img.exr_bytes().unwrap_err();
            assert!(
                e.to_string().starts_with("pixel (1, 1) is not finite"),
                "{e}"
            );
            assert!(img.png_bytes(0.0).is_err());
            assert!(img.write_exr(&d.join("x.exr")).is_err());
        }
        assert_eq!(std::fs::read_dir(&d).unwrap().count(), 0);
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
