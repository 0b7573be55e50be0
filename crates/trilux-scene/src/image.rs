//! Texture images: PNG (the `png` crate) and JPEG (`zune-jpeg`) files into
//! linear RGB texels ([`trilux_brdf::Texture`]).
//!
//! The format is told by the file's first bytes, not its name. Grey images
//! give grey texels; an alpha channel is dropped (as Mitsuba's `bitmap`
//! drops it), unless the alpha channel is what is asked for (glTF's
//! `alphaMode` `MASK`: [`Sampling::alpha`], linear, in every channel; 1
//! for an image without one); 16-bit PNG channels keep their precision. Unless `raw`, the
//! values are sRGB-encoded and decoded with the sRGB transfer function
//! (IEC 61966-2-1), as Mitsuba 3 decodes a `bitmap` without `raw` and as
//! glTF defines base colour textures; `raw` values are used as they are
//! (divided by 255 or 65535). [`Sampling::channel`] takes one colour
//! channel into all three (glTF's metallicRoughnessTexture).
//!
//! Bounded: the file by [`MAX_IMAGE_BYTES`] (read by the caller), the image
//! by [`MAX_TEXTURE_TEXELS`], checked from its header before it is decoded.

use trilux_brdf::{Filter, Texture, Wrap};

pub use crate::limits::MAX_IMAGE_BYTES;
use crate::limits::MAX_TEXTURE_TEXELS;

/// How a texture is looked up and whether its values are sRGB-encoded.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Sampling {
    /// Wrap modes for u and v.
    pub wrap: [Wrap; 2],
    /// Filter.
    pub filter: Filter,
    /// Values used as stored (no sRGB decoding).
    pub raw: bool,
    /// The alpha channel instead of the colour (linear whatever `raw`).
    pub alpha: bool,
    /// One colour channel (0 red, 1 green, 2 blue) in every channel
    /// instead of the colour: glTF's metalness (blue) and roughness
    /// (green). A grey image has its grey in every channel.
    pub channel: Option<u8>,
}

/// Why an image could not be decoded (the caller names the file).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ImageError {
    /// Neither PNG nor JPEG.
    #[error("not a PNG or JPEG image (the first bytes are neither signature)")]
    Format,
    /// The decoder refused the data.
    #[error("malformed {format} image: {reason}")]
    Decode {
        /// PNG or JPEG.
        format: &'static str,
        /// The decoder's reason.
        reason: String,
    },
    /// Too many texels.
    #[error(
        "image of {width} × {height} texels is beyond the limit of {MAX_TEXTURE_TEXELS} texels (docs/limits.md)"
    )]
    TooLarge {
        /// Width.
        width: u64,
        /// Height.
        height: u64,
    },
    /// The texels could not make a texture.
    #[error("{0}")]
    Texture(#[from] trilux_brdf::BrdfError),
}

/// The sRGB transfer function's inverse: encoded value in [0, 1] → linear.
pub(crate) fn srgb_to_linear(v: f64) -> f64 {
    if v <= 0.04045 {
        v / 12.92
    } else {
        ((v + 0.055) / 1.055).powf(2.4)
    }
}

/// Decodes a PNG or JPEG image into a texture.
pub fn decode(bytes: &[u8], sampling: Sampling) -> Result<Texture, ImageError> {
    decode_counted(bytes, sampling).map(|(t, _)| t)
}

/// [`decode`], with the image's channel count (1 grey, 2 grey and alpha,
/// 3 RGB, 4 RGB and alpha).
pub fn decode_counted(bytes: &[u8], sampling: Sampling) -> Result<(Texture, usize), ImageError> {
    let (width, height, channels, values, max) = if bytes.starts_with(b"\x89PNG\r\n\x1a\n") {
        decode_png(bytes)?
    } else if bytes.starts_with(&[0xFF, 0xD8]) {
        decode_jpeg(bytes)?
    } else {
        return Err(ImageError::Format);
    };
    let lut: Vec<f32> = (0..=max)
        .map(|v| {
            let x = f64::from(v) / f64::from(max);
            (if sampling.raw { x } else { srgb_to_linear(x) }) as f32
        })
        .collect();
    let texels = values
        .chunks_exact(channels)
        .map(|px| {
            let c = |i: usize| lut[usize::from(px[i])];
            if sampling.alpha {
                // Grey and alpha, or RGB and alpha: the last channel.
                let a = match channels {
                    2 | 4 => f64::from(px[channels - 1]) / f64::from(max),
                    _ => 1.0,
                };
                [a as f32; 3]
            } else if let (Some(k), true) = (sampling.channel, channels >= 3) {
                [c(usize::from(k.min(2))); 3]
            } else if channels >= 3 {
                [c(0), c(1), c(2)]
            } else {
                [c(0); 3]
            }
        })
        .collect();
    Ok((
        Texture::new(width, height, texels, sampling.wrap, sampling.filter)?,
        channels,
    ))
}

fn check_size(width: u32, height: u32) -> Result<(), ImageError> {
    if u64::from(width) * u64::from(height) > MAX_TEXTURE_TEXELS {
        return Err(ImageError::TooLarge {
            width: width.into(),
            height: height.into(),
        });
    }
    Ok(())
}

type Decoded = (u32, u32, usize, Vec<u16>, u16);

fn decode_png(bytes: &[u8]) -> Result<Decoded, ImageError> {
    let err = |e: png::DecodingError| ImageError::Decode {
        format: "PNG",
        reason: e.to_string(),
    };
    let mut decoder = png::Decoder::new(std::io::Cursor::new(bytes));
    // Palettes to RGB, low bit depths to 8 bits, tRNS to alpha; 16 bits kept.
    decoder.set_transformations(png::Transformations::EXPAND);
    let header = decoder.read_header_info().map_err(err)?;
    check_size(header.width, header.height)?;
    let mut reader = decoder.read_info().map_err(err)?;
    let size = reader
        .output_buffer_size()
        .ok_or_else(|| ImageError::Decode {
            format: "PNG",
            reason: "the image's size overflows".into(),
        })?;
    let mut buf = vec![0; size];
    let frame = reader.next_frame(&mut buf).map_err(err)?;
    let channels = frame.color_type.samples();
    let data = &buf[..frame.buffer_size()];
    let (values, max) = match frame.bit_depth {
        png::BitDepth::Sixteen => (
            data.chunks_exact(2)
                .map(|b| u16::from_be_bytes([b[0], b[1]]))
                .collect(),
            u16::MAX,
        ),
        _ => (data.iter().map(|&b| u16::from(b)).collect(), 255),
    };
    Ok((frame.width, frame.height, channels, values, max))
}

fn decode_jpeg(bytes: &[u8]) -> Result<Decoded, ImageError> {
    use zune_jpeg::zune_core::colorspace::ColorSpace;
    use zune_jpeg::zune_core::options::DecoderOptions;
    let err = |e: zune_jpeg::errors::DecodeErrors| ImageError::Decode {
        format: "JPEG",
        reason: e.to_string(),
    };
    let options = DecoderOptions::default().jpeg_set_out_colorspace(ColorSpace::RGB);
    let mut decoder = zune_jpeg::JpegDecoder::new_with_options(bytes, options);
    decoder.decode_headers().map_err(err)?;
    let (width, height) = decoder.dimensions().ok_or_else(|| ImageError::Decode {
        format: "JPEG",
        reason: "no image size in its header".into(),
    })?;
    let (width, height) = (width as u32, height as u32);
    check_size(width, height)?;
    // RGB is asked for, but a one-component (grayscale) JPEG decodes to
    // one channel (the decoder keeps Luma): read as Mitsuba reads it, a
    // one-channel bitmap whose value stands for R = G = B (`decode`).
    let channels = decoder
        .get_output_colorspace()
        .map_or(3, |c| c.num_components());
    let pixels = decoder.decode().map_err(err)?;
    if !matches!(channels, 1 | 3)
        || pixels.len() as u64 != u64::from(width) * u64::from(height) * channels as u64
    {
        return Err(ImageError::Decode {
            format: "JPEG",
            reason: "the decoded image has the wrong size".into(),
        });
    }
    Ok((
        width,
        height,
        channels,
        pixels.into_iter().map(u16::from).collect(),
        255,
    ))
}
