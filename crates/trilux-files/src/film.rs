//! What a rendered film may cost in memory (docs/limits.md): the limits a
//! scene file's film and a film size given on the command line are both
//! checked against, before a render allocates anything.

/// Longest film edge in pixels (32 768) and most pixels (2^26 = 67 M, e.g.
/// 8192 × 8192): the render keeps about 60 bytes per pixel (filter sums and
/// weights, the image, its encoded files), 4 GB at the limit.
pub const MAX_FILM_EDGE: u32 = 32_768;

/// Most camera samples per pixel (65 536): the render's low-discrepancy
/// sequence has that many points per pixel. A scene's `sample_count` and
/// `--spp` are both checked against it before any work.
pub const MAX_SAMPLES_PER_PIXEL: u32 = 1 << 16;

/// Most film pixels (see [`MAX_FILM_EDGE`]).
pub const MAX_FILM_PIXELS: u64 = 1 << 26;

/// Bytes a render keeps per film pixel, about (see [`MAX_FILM_EDGE`]).
pub const FILM_BYTES_PER_PIXEL: u64 = 60;

/// Refuses a film size outside the limits, saying what the limits are and
/// what the size would need.
pub fn check_film(width: u32, height: u32) -> Result<(), String> {
    if width == 0 || height == 0 {
        return Err(format!(
            "film size {width} × {height} must be at least 1 × 1"
        ));
    }
    let pixels = u64::from(width) * u64::from(height);
    if width > MAX_FILM_EDGE || height > MAX_FILM_EDGE || pixels > MAX_FILM_PIXELS {
        return Err(format!(
            "film size {width} × {height} ({pixels} pixels, about {} of memory) is beyond the limits: {MAX_FILM_EDGE} pixels a side and {MAX_FILM_PIXELS} pixels in all (8192 × 8192, about {}) (docs/limits.md)",
            crate::human_bytes(pixels.saturating_mul(FILM_BYTES_PER_PIXEL)),
            crate::human_bytes(MAX_FILM_PIXELS * FILM_BYTES_PER_PIXEL),
        ));
    }
    Ok(())
}
