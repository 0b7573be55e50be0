//! Comparing a render with a reference image (golden tests, sweeps).
//!
//! - Relative RMSE: `sqrt(Σ (a − r)² / Σ r²)` over the pixels not masked and
//!   the three channels: the RMS error normalised by the RMS of the
//!   reference (robust against dark pixels, unlike a per-pixel ratio).
//! - Mean ratio: `Σ a / Σ r` over the same pixels and channels (energy bias).
//!
//! Both are also reported over all pixels. The mask (an image of the same
//! size, > 0.5 in its first channel = masked) leaves out pixels where an
//! emitter is directly visible, whose values are the emitters' radiance and
//! would dominate both sums.

use crate::error::RenderError;
use crate::image::Image;

/// The metrics of one image against its reference.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Comparison {
    /// Relative RMSE over unmasked pixels.
    pub rel_rmse: f64,
    /// Relative RMSE over all pixels.
    pub rel_rmse_all: f64,
    /// mean(image) / mean(reference) over unmasked pixels.
    pub mean_ratio: f64,
    /// mean(image) / mean(reference) over all pixels.
    pub mean_ratio_all: f64,
    /// Number of masked pixels.
    pub masked: usize,
}

/// Compares `image` with `reference`, leaving out pixels where `mask` is set.
pub fn compare(
    image: &Image,
    reference: &Image,
    mask: Option<&Image>,
) -> Result<Comparison, RenderError> {
    let size = |i: &Image| (i.width(), i.height());
    if size(image) != size(reference) {
        return Err(RenderError::Settings(format!(
            "image is {:?} but the reference is {:?}",
            size(image),
            size(reference)
        )));
    }
    if let Some(m) = mask
        && size(m) != size(reference)
    {
        return Err(RenderError::Settings(format!(
            "mask is {:?} but the reference is {:?}",
            size(m),
            size(reference)
        )));
    }
    let mut acc = [[0.0f64; 4]; 2]; // [unmasked, all] × [Σd², Σr², Σa, Σr]
    let mut masked = 0;
    for (k, (a, r)) in image.pixels().iter().zip(reference.pixels()).enumerate() {
        let is_masked = mask.is_some_and(|m| m.pixels()[k][0] > 0.5);
        masked += usize::from(is_masked);
        for c in 0..3 {
            let (a, r) = (a[c] as f64, r[c] as f64);
            let terms = [(a - r) * (a - r), r * r, a, r];
            for (set, acc) in acc.iter_mut().enumerate() {
                if set == 1 || !is_masked {
                    for (s, t) in acc.iter_mut().zip(terms) {
                        *s += t;
                    }
                }
            }
        }
    }
    let rmse = |a: &[f64; 4]| (a[0] / a[1]).sqrt();
    let ratio = |a: &[f64; 4]| a[2] / a[3];
    Ok(Comparison {
        rel_rmse: rmse(&acc[0]),
        rel_rmse_all: rmse(&acc[1]),
        mean_ratio: ratio(&acc[0]),
        mean_ratio_all: ratio(&acc[1]),
        masked,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn img(v: &[f32]) -> Image {
        Image::from_pixels(v.len() as u32, 1, v.iter().map(|&x| [x, x, x]).collect()).unwrap()
    }

    #[test]
    fn metrics_follow_their_definitions() {
        let r = img(&[1.0, 2.0, 3.0, 100.0]);
        let same = compare(&r, &r, None).unwrap();
        assert_eq!((same.rel_rmse, same.mean_ratio), (0.0, 1.0));
        // 10 % brighter everywhere: relRMSE 0.1, ratio 1.1.
        let a = img(&[1.1, 2.2, 3.3, 110.0]);
        let c = compare(&a, &r, None).unwrap();
        assert!((c.rel_rmse - 0.1).abs() < 1e-6 && (c.mean_ratio - 1.1).abs() < 1e-6);
        // Masking the bright pixel leaves sqrt(Σ d² / Σ r²) over the rest.
        let b = img(&[1.0, 2.0, 4.0, 0.0]);
        let m = img(&[0.0, 0.0, 0.0, 1.0]);
        let c = compare(&b, &r, Some(&m)).unwrap();
        assert!((c.rel_rmse - (1.0f64 / 14.0).sqrt()).abs() < 1e-9);
        assert!((c.mean_ratio - 7.0 / 6.0).abs() < 1e-9);
        assert_eq!(c.masked, 1);
        assert!(compare(&img(&[1.0]), &r, None).is_err());
    }
}
