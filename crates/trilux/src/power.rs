//! Emitted power per band, P = π · L · A for each one-sided Lambertian area
//! emitter (radiance L, area A), summed over the emitters.
//!
//! PROVISIONAL colour conversion, until trilux-color's `Spectrum` and its
//! `ColorParam` conversions land (branch `brdf`); then replace
//! [`emission_bands`] by trilux-color's emission conversion:
//! - RGB mode: `<float>`/`<rgb>` as written; a constant `<spectrum>` as
//!   Mitsuba's equal-energy spectrum (1.20479, 0.948291, 0.908916) × v; a
//!   sampled spectrum through CIE 1931 XYZ (Wyman, Sloan & Shirley's 2013
//!   multi-lobe fit of the colour-matching functions, integrated at 1 nm over
//!   360–830 nm, normalised so that a flat spectrum has Y = 1) to linear sRGB
//!   with Mitsuba's matrix. The fit is within about 1% of the CIE tables.
//! - spectral mode: 10 bands of 30 nm from 400 to 700 nm, the outer bands
//!   reaching 360 and 830 nm; each band holds the mean of the spectrum over
//!   it; `<float>` and constant spectra are flat; `<rgb>` is flat at the mean
//!   of its channels (a crude stand-in for Jakob & Hanika's model).

use trilux_color::ColorParam;
use trilux_scene::{Scene, surface_area};

use crate::ModeArg;

/// Band edges of the provisional spectral mode (nm).
pub const BAND_EDGES: [f64; 11] = [
    360.0, 430.0, 460.0, 490.0, 520.0, 550.0, 580.0, 610.0, 640.0, 670.0, 830.0,
];

/// Total emitted power per band (W): Σ π · L · A over the area emitters.
pub fn emitted_power(scene: &Scene, mode: ModeArg) -> Vec<f64> {
    let bands = match mode {
        ModeArg::Rgb => 3,
        ModeArg::Spectral => BAND_EDGES.len() - 1,
    };
    let mut total = vec![0.0; bands];
    for (_, s) in scene.emitters() {
        let Some(emitter) = &s.emitter else { continue };
        let area = surface_area(&s.shape);
        for (t, l) in total
            .iter_mut()
            .zip(emission_bands(&emitter.radiance, mode))
        {
            *t += std::f64::consts::PI * l * area;
        }
    }
    total
}

/// PROVISIONAL: an emitted radiance as band values (see the module docs).
pub fn emission_bands(c: &ColorParam, mode: ModeArg) -> Vec<f64> {
    match (mode, c) {
        (ModeArg::Rgb, ColorParam::Float(v)) => vec![*v; 3],
        (ModeArg::Rgb, ColorParam::Rgb(rgb)) => rgb.to_vec(),
        (ModeArg::Rgb, ColorParam::Constant(v)) => {
            [1.20479, 0.948291, 0.908916].map(|e| e * v).to_vec()
        }
        (ModeArg::Rgb, ColorParam::Sampled(s)) => xyz_to_linear_srgb(spectrum_to_xyz(s)).to_vec(),
        (ModeArg::Spectral, ColorParam::Float(v) | ColorParam::Constant(v)) => {
            vec![*v; BAND_EDGES.len() - 1]
        }
        (ModeArg::Spectral, ColorParam::Rgb(rgb)) => {
            vec![(rgb[0] + rgb[1] + rgb[2]) / 3.0; BAND_EDGES.len() - 1]
        }
        (ModeArg::Spectral, ColorParam::Sampled(s)) => BAND_EDGES
            .windows(2)
            .map(|w| band_mean(s, w[0], w[1]))
            .collect(),
    }
}

/// A sampled spectrum at `l` nm: linear between samples, zero outside.
fn eval(s: &[(f64, f64)], l: f64) -> f64 {
    let (Some(&(first, _)), Some(&(last, _))) = (s.first(), s.last()) else {
        return 0.0;
    };
    if l < first || l > last {
        return 0.0;
    }
    let i = s.partition_point(|&(w, _)| w <= l).clamp(1, s.len() - 1);
    let (l0, v0) = s[i - 1];
    let (l1, v1) = s[i];
    if l1 == l0 {
        return v0;
    }
    v0 + (v1 - v0) * (l - l0) / (l1 - l0)
}

/// Mean of the spectrum over [a, b] (midpoint rule, 0.1 nm steps).
fn band_mean(s: &[(f64, f64)], a: f64, b: f64) -> f64 {
    let n = ((b - a) * 10.0).round() as usize;
    let h = (b - a) / n as f64;
    (0..n)
        .map(|i| eval(s, a + (i as f64 + 0.5) * h))
        .sum::<f64>()
        / n as f64
}

fn lobe(l: f64, mu: f64, s1: f64, s2: f64) -> f64 {
    let t = (l - mu) / if l < mu { s1 } else { s2 };
    (-0.5 * t * t).exp()
}

/// Wyman, Sloan & Shirley (2013) multi-lobe fit of the CIE 1931 2° CMFs.
fn cmf(l: f64) -> [f64; 3] {
    [
        1.056 * lobe(l, 599.8, 37.9, 31.0) + 0.362 * lobe(l, 442.0, 16.0, 26.7)
            - 0.065 * lobe(l, 501.1, 20.4, 26.2),
        0.821 * lobe(l, 568.8, 46.9, 40.5) + 0.286 * lobe(l, 530.9, 16.3, 31.1),
        1.217 * lobe(l, 437.0, 11.8, 36.0) + 0.681 * lobe(l, 459.0, 26.0, 13.8),
    ]
}

/// CIE XYZ of an emission spectrum, normalised so that a flat spectrum of
/// value 1 has Y = 1 (Mitsuba divides by the integral of ȳ the same way).
fn spectrum_to_xyz(s: &[(f64, f64)]) -> [f64; 3] {
    let mut xyz = [0.0; 3];
    let mut y_integral = 0.0;
    for l in 360..=830 {
        let l = l as f64;
        let c = cmf(l);
        let v = eval(s, l);
        for k in 0..3 {
            xyz[k] += v * c[k];
        }
        y_integral += c[1];
    }
    xyz.map(|x| x / y_integral)
}

/// CIE XYZ → linear sRGB (D65), the matrix Mitsuba 3 uses.
fn xyz_to_linear_srgb([x, y, z]: [f64; 3]) -> [f64; 3] {
    [
        3.240479 * x - 1.537150 * y - 0.498535 * z,
        -0.969256 * x + 1.875991 * y + 0.041556 * z,
        0.055648 * x - 0.204043 * y + 1.057311 * z,
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// design.md §3's check value: the classic Cornell light in RGB mode is
    /// linear sRGB (20.7108, 10.8546, 2.77115) (Mitsuba 3, CIE 1 nm tables).
    /// Tolerance 3% relative: the provisional CMF fit, not the CIE table.
    #[test]
    fn cornell_light_in_rgb_is_near_mitsubas_value() {
        let light = ColorParam::Sampled(vec![
            (400.0, 0.0),
            (500.0, 8.0),
            (600.0, 15.6),
            (700.0, 18.4),
        ]);
        let rgb = emission_bands(&light, ModeArg::Rgb);
        let expected = [20.7108, 10.8546, 2.77115];
        for (got, want) in rgb.iter().zip(expected) {
            assert!((got - want).abs() <= 0.03 * want, "{rgb:?} vs {expected:?}");
        }
    }

    /// A flat spectrum has the same mean in every band.
    #[test]
    fn flat_spectrum_bands() {
        let flat = ColorParam::Sampled(vec![(300.0, 2.0), (900.0, 2.0)]);
        for v in emission_bands(&flat, ModeArg::Spectral) {
            assert!((v - 2.0).abs() < 1e-12);
        }
    }

    /// Linear interpolation and zero outside the samples (Mitsuba's rule).
    #[test]
    fn sampled_spectrum_is_linear_and_zero_outside() {
        let s = [(400.0, 0.0), (500.0, 8.0)];
        assert_eq!(eval(&s, 450.0), 4.0);
        assert_eq!(eval(&s, 399.0), 0.0);
        assert_eq!(eval(&s, 501.0), 0.0);
        assert_eq!(eval(&s, 500.0), 8.0);
    }
}
