//! Reconstruction filters (a scene's `<rfilter>`), exactly as Mitsuba 3's
//! `hdrfilm` applies them: the parameters a scene gives (trilux-scene) and
//! the weights the film (trilux-render) splats with.
//!
//! A sample at film position p (pixels) contributes to every pixel whose
//! centre c lies within the filter's radius on both axes, with the separable
//! weight w(c_x − p_x) · w(c_y − p_y); each pixel is then divided by the sum of
//! the weights it received.
//!
//! - Gaussian (Mitsuba's default): stddev σ (0.5 px), radius r = 4σ,
//!   w(d) = max(0, exp(−d²/(2σ²)) − exp(−r²/(2σ²))).
//! - Box: radius 0.5 px, w(d) = 1 for |d| ≤ 0.5.
//! - Tent: radius r (1 px), w(d) = max(0, 1 − |d|/r).
//! - Mitchell–Netravali with parameters B, C (1/3 each), radius 2 px: the
//!   cubic (1/6)((12 − 9B − 6C)|d|³ + (−18 + 12B + 6C)d² + 6 − 2B) for
//!   |d| < 1, (1/6)((−B − 6C)|d|³ + (6B + 30C)d² + (−12B − 48C)|d| + 8B +
//!   24C) for 1 ≤ |d| < 2. Catmull–Rom is B = 0, C = 1/2.
//! - Lanczos with `lobes` a (3), radius a: w(d) = sinc(πd) sinc(πd/a).
//!
//! The film splats with the filter *discretized* as Mitsuba 3.9.1's image
//! block does ([`ReconstructionFilter::eval_discretized`]): |d| falls into
//! one of 31 equal bins over [0, r) and takes w at the bin's lower edge.
//! The step matters where the image has an edge within the radius: a film
//! sampled beyond its border (`sample_border`) gives its edge column 0.166
//! of an emitter just outside with the steps, 0.158 with the exact w;
//! Mitsuba gives 0.166 (docs/results.md).
//!
//! Mitchell, Catmull–Rom and Lanczos have negative lobes, as in Mitsuba: a
//! pixel's weights can sum to less than its largest one, and its value can
//! ring below zero next to a sharp edge.

use serde::Serialize;

/// Bins of the discretized filter over its radius (Mitsuba's
/// `MI_FILTER_RESOLUTION`).
const FILTER_RESOLUTION: u32 = 31;

/// A separable reconstruction filter.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
#[serde(rename_all = "lowercase")]
#[non_exhaustive]
pub enum ReconstructionFilter {
    /// Mitsuba's `gaussian` with standard deviation `stddev` (default 0.5)
    /// and radius 4·stddev.
    Gaussian {
        /// Standard deviation in pixels.
        stddev: f64,
    },
    /// Mitsuba's `box`: each sample lands in its own pixel.
    Box,
    /// Mitsuba's `tent`.
    Tent {
        /// Radius in pixels.
        radius: f64,
    },
    /// Mitsuba's `mitchell` (and `catmullrom`: B = 0, C = 1/2).
    Mitchell {
        /// Blur parameter B.
        b: f64,
        /// Ringing parameter C.
        c: f64,
    },
    /// Mitsuba's `lanczos`.
    Lanczos {
        /// Lobes on each side (the radius in pixels).
        lobes: u32,
    },
}

impl Default for ReconstructionFilter {
    /// Mitsuba's default: Gaussian with stddev 0.5 px.
    fn default() -> Self {
        Self::Gaussian { stddev: 0.5 }
    }
}

impl ReconstructionFilter {
    /// Pixels sampled beyond each edge of the film under Mitsuba's
    /// `sample_border`: its `border_size`, ⌈radius − ½⌉ (0 for the box,
    /// 2 for the default Gaussian, as Mitsuba 3.9.1 reports).
    pub fn border_size(&self) -> u32 {
        (self.radius() - 0.5).ceil().max(0.0) as u32
    }

    /// Radius in pixels beyond which the weight is zero.
    pub fn radius(&self) -> f64 {
        match *self {
            Self::Gaussian { stddev } => 4.0 * stddev,
            Self::Box => 0.5,
            Self::Tent { radius } => radius,
            Self::Mitchell { .. } => 2.0,
            Self::Lanczos { lobes } => f64::from(lobes),
        }
    }

    /// The one-axis weight the film splats with: [`Self::eval`] at the
    /// lower edge of the bin of |d| among 31 equal bins over [0, radius),
    /// zero beyond (Mitsuba 3.9.1's `eval_discretized`).
    pub fn eval_discretized(&self, d: f64) -> f64 {
        let r = self.radius();
        let n = f64::from(FILTER_RESOLUTION);
        let bin = (d.abs() * n / r).floor();
        if bin.is_nan() || bin >= n {
            0.0
        } else {
            self.eval(bin * r / n)
        }
    }

    /// One-axis weight at offset `d` (pixels) from the sample.
    pub fn eval(&self, d: f64) -> f64 {
        let x = d.abs();
        match *self {
            Self::Gaussian { stddev } => {
                let alpha = -1.0 / (2.0 * stddev * stddev);
                let r = self.radius();
                ((alpha * d * d).exp() - (alpha * r * r).exp()).max(0.0)
            }
            Self::Box => f64::from(u8::from(x <= 0.5)),
            Self::Tent { radius } => (1.0 - x / radius).max(0.0),
            Self::Mitchell { b, c } => mitchell(x, b, c),
            Self::Lanczos { lobes } => {
                let a = f64::from(lobes);
                if x >= a {
                    0.0
                } else {
                    sinc(std::f64::consts::PI * x) * sinc(std::f64::consts::PI * x / a)
                }
            }
        }
    }
}

/// The Mitchell–Netravali cubic at |d| = `x` (module docs).
fn mitchell(x: f64, b: f64, c: f64) -> f64 {
    let (x2, x3) = (x * x, x * x * x);
    let w = if x < 1.0 {
        (12.0 - 9.0 * b - 6.0 * c) * x3 + (-18.0 + 12.0 * b + 6.0 * c) * x2 + (6.0 - 2.0 * b)
    } else if x < 2.0 {
        (-b - 6.0 * c) * x3
            + (6.0 * b + 30.0 * c) * x2
            + (-12.0 * b - 48.0 * c) * x
            + (8.0 * b + 24.0 * c)
    } else {
        0.0
    };
    w / 6.0
}

/// sin(x)/x, 1 at 0.
fn sinc(x: f64) -> f64 {
    if x.abs() < 1e-8 { 1.0 } else { x.sin() / x }
}

#[cfg(test)]
mod tests {
    #[test]
    fn the_discretized_gaussian_is_mitsubas() {
        // Mitsuba 3.9.1's `eval_discretized` of its default Gaussian
        // (scalar_rgb, `mi.load_dict({'type': 'gaussian'})`): single
        // precision and its own exp differ from the exact w by up to 4e-4.
        let f = ReconstructionFilter::default();
        for (d, mitsuba) in [
            (0.0, 0.999_247_1),
            (0.05, 0.999_247_1),
            (0.6, 0.509_314_1),
            (1.0, 0.153_261_3),
            (1.7, 0.003_252_9),
            (1.99, 0.000_220_8),
        ] {
            let w = f.eval_discretized(d);
            assert!((w - mitsuba).abs() < 5e-4, "d = {d}: {w} against {mitsuba}");
        }
        // At the radius and beyond, and for a NaN offset: nothing.
        assert_eq!(f.eval_discretized(2.0), 0.0);
        assert_eq!(f.eval_discretized(f64::NAN), 0.0);
    }

    use super::*;

    #[test]
    fn gaussian_is_mitsubas_formula() {
        let f = ReconstructionFilter::default();
        assert_eq!(f.radius(), 2.0);
        // Independent evaluation of max(0, exp(-d²/0.5) - exp(-4/0.5)).
        for d in [0.0, 0.3, 0.5, 1.0, 1.7, 2.0, 2.5] {
            let expected = ((-d * d / 0.5f64).exp() - (-8.0f64).exp()).max(0.0);
            assert!((f.eval(d) - expected).abs() < 1e-15, "d = {d}");
        }
        assert_eq!(f.eval(2.0), 0.0);
        assert_eq!(f.eval(-3.0), 0.0);
    }

    /// Weights Mitsuba 3.9.1 gives (`mi.load_dict({'type': ...}).eval(d)`,
    /// scalar_rgb, single precision: 1e-6).
    #[test]
    fn the_other_filters_are_mitsubas() {
        let d = [0.0, 0.25, 0.5, 0.99, 1.0, 1.5, 1.99, 2.5, 3.0];
        let cases: [(ReconstructionFilter, [f64; 9]); 5] = [
            (
                ReconstructionFilter::Tent { radius: 1.5 },
                [1.0, 0.833333, 0.666667, 0.34, 0.333333, 0.0, 0.0, 0.0, 0.0],
            ),
            (
                ReconstructionFilter::Mitchell {
                    b: 1.0 / 3.0,
                    c: 1.0 / 3.0,
                },
                [
                    0.888889, 0.782118, 0.534722, 0.060704, 0.055556, -0.034722, -3.3e-05, 0.0, 0.0,
                ],
            ),
            (
                ReconstructionFilter::Mitchell { b: 0.0, c: 0.5 },
                [
                    1.0, 0.867188, 0.5625, 0.005198, 0.0, -0.0625, -4.9e-05, 0.0, 0.0,
                ],
            ),
            (
                ReconstructionFilter::Lanczos { lobes: 3 },
                [
                    1.0, 0.890067, 0.607927, 0.008385, 0.0, -0.135095, -0.0021, 0.024317, 0.0,
                ],
            ),
            (
                ReconstructionFilter::Lanczos { lobes: 2 },
                [
                    1.0, 0.877354, 0.573159, 0.006494, 0.0, -0.063684, -2.5e-05, 0.0, 0.0,
                ],
            ),
        ];
        for (f, want) in cases {
            for (x, w) in d.iter().zip(want) {
                assert!(
                    (f.eval(*x) - w).abs() < 1e-6,
                    "{f:?} at {x}: {} vs {w}",
                    f.eval(*x)
                );
                assert_eq!(f.eval(*x), f.eval(-x), "{f:?} is even");
            }
        }
        let mitchell = ReconstructionFilter::Mitchell { b: 0.5, c: 0.25 };
        for (x, w) in [0.0, 0.3, 0.6, 1.2, 1.7]
            .iter()
            .zip([0.833333, 0.702833, 0.419333, 0.010667, -0.0135])
        {
            assert!((mitchell.eval(*x) - w).abs() < 1e-6, "B 0.5, C 0.25 at {x}");
        }
    }

    #[test]
    fn box_covers_one_pixel() {
        let f = ReconstructionFilter::Box;
        assert_eq!(f.eval(0.49), 1.0);
        assert_eq!(f.eval(-0.49), 1.0);
        assert_eq!(f.eval(0.51), 0.0);
    }
}
