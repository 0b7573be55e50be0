//! CIE colorimetry on continuous spectra: the 1931 2° observer at 1 nm, the
//! D65 illuminant, sampled (piecewise-linear) spectra and their exact XYZ.
//!
//! Conventions (docs/validation.md, "Colour"):
//! - the colour-matching functions are the CIE's 1 nm table over 360–830 nm,
//!   linear between the table's wavelengths and zero outside;
//! - XYZ of a spectrum s is ∫ s(λ) (x̄, ȳ, z̄)(λ) dλ / ∫ ȳ(λ) dλ, so that the
//!   equal-energy spectrum of value 1 has Y = 1 (Mitsuba 3's normalisation);
//! - a sampled spectrum is linear between its samples and zero outside its
//!   first and last wavelength (Mitsuba 3's rule).
//!
//! The integrals here are exact for these piecewise-linear functions (the
//! product of two linear pieces is integrated in closed form), so they are
//! the reference that the band reduction of [`crate::bands`] is measured
//! against, and what `cargo xtask color` compares with colour-science.

use crate::ColorError;
pub use crate::cie_data::{CIE_MAX_NM, CIE_MIN_NM, CIE1931_1NM, D65_5NM};

/// ∫ ȳ(λ) dλ over the 1 nm table (trapezoid rule, exact for the linear
/// interpolant), ≈ 106.857.
pub const CIE_Y_INTEGRAL: f64 = table_integral(360.0, 830.0)[1];

/// Σ ȳ(λ)·1 nm over the 471 rows of the 1 nm table (CIE summation), ≈ 106.857.
pub const CIE_Y_SUM: f64 = {
    let mut s = 0.0;
    let mut i = 0;
    while i < 471 {
        s += CIE1931_1NM[i][1];
        i += 1;
    }
    s
};

/// The colour-matching functions (x̄, ȳ, z̄) at `lambda` nm, linear between
/// the 1 nm table's entries, zero outside 360–830 nm.
pub fn cmf(lambda: f64) -> [f64; 3] {
    cmf_const(lambda)
}

const fn cmf_const(lambda: f64) -> [f64; 3] {
    if !(lambda >= CIE_MIN_NM && lambda <= CIE_MAX_NM) {
        return [0.0; 3];
    }
    let t = lambda - CIE_MIN_NM;
    let mut i = t as usize;
    if i > 469 {
        i = 469;
    }
    let w = t - i as f64;
    let a = CIE1931_1NM[i];
    let b = CIE1931_1NM[i + 1];
    [
        a[0] + (b[0] - a[0]) * w,
        a[1] + (b[1] - a[1]) * w,
        a[2] + (b[2] - a[2]) * w,
    ]
}

/// The CIE D65 relative spectral power at `lambda` nm (100 at 560 nm), linear
/// between the 5 nm table's entries, zero outside 360–830 nm.
pub const fn d65(lambda: f64) -> f64 {
    if !(lambda >= CIE_MIN_NM && lambda <= CIE_MAX_NM) {
        return 0.0;
    }
    let t = (lambda - CIE_MIN_NM) / 5.0;
    let mut i = t as usize;
    if i > 93 {
        i = 93;
    }
    let w = t - i as f64;
    D65_5NM[i] + (D65_5NM[i + 1] - D65_5NM[i]) * w
}

/// ∫ (x̄, ȳ, z̄) dλ over `[lo, hi]` ⊂ [360, 830] (exact for the linear
/// interpolant of the 1 nm table).
pub const fn table_integral(lo: f64, hi: f64) -> [f64; 3] {
    let mut acc = [0.0; 3];
    if hi.is_nan() || lo.is_nan() || hi <= lo {
        return acc;
    }
    let mut a = lo;
    while a < hi {
        // next integer wavelength strictly above a
        let mut b = (a as u64) as f64 + 1.0;
        if b > hi {
            b = hi;
        }
        let ca = cmf_const(a);
        let cb = cmf_const(b);
        let h = 0.5 * (b - a);
        acc[0] += h * (ca[0] + cb[0]);
        acc[1] += h * (ca[1] + cb[1]);
        acc[2] += h * (ca[2] + cb[2]);
        a = b;
    }
    acc
}

/// ∫ D65(λ) dλ over `[lo, hi]` (exact for the 5 nm linear interpolant).
pub const fn d65_integral(lo: f64, hi: f64) -> f64 {
    let mut acc = 0.0;
    if hi.is_nan() || lo.is_nan() || hi <= lo {
        return acc;
    }
    let mut a = lo;
    while a < hi {
        let mut b = ((a / 5.0) as u64) as f64 * 5.0 + 5.0;
        if b > hi {
            b = hi;
        }
        acc += 0.5 * (b - a) * (d65(a) + d65(b));
        a = b;
    }
    acc
}

/// A sampled spectrum: (wavelength nm, value) pairs, strictly ascending in
/// wavelength, linear in between and zero outside.
#[derive(Clone, Debug, PartialEq)]
pub struct SampledSpectrum {
    wavelengths: Vec<f64>,
    values: Vec<f64>,
}

impl SampledSpectrum {
    /// Validates the samples: at least two, finite, strictly ascending
    /// wavelengths. (Negative values are allowed here; the conversions
    /// decide what a negative reflectance or radiance means.)
    pub fn new(samples: &[(f64, f64)]) -> Result<Self, ColorError> {
        if samples.len() < 2 {
            return Err(ColorError::TooFewSamples(samples.len()));
        }
        for (i, &(l, v)) in samples.iter().enumerate() {
            if !l.is_finite() || !v.is_finite() {
                return Err(ColorError::NotFinite);
            }
            if i > 0 && l <= samples[i - 1].0 {
                return Err(ColorError::NotAscending(l));
            }
        }
        Ok(SampledSpectrum {
            wavelengths: samples.iter().map(|s| s.0).collect(),
            values: samples.iter().map(|s| s.1).collect(),
        })
    }

    /// The wavelengths, nm.
    pub fn wavelengths(&self) -> &[f64] {
        &self.wavelengths
    }

    /// The values.
    pub fn values(&self) -> &[f64] {
        &self.values
    }

    /// The value at `lambda` (linear between samples, zero outside).
    pub fn eval(&self, lambda: f64) -> f64 {
        let w = &self.wavelengths;
        let n = w.len();
        if !(lambda >= w[0] && lambda <= w[n - 1]) {
            return 0.0;
        }
        let i = w.partition_point(|&x| x <= lambda).clamp(1, n - 1) - 1;
        let t = (lambda - w[i]) / (w[i + 1] - w[i]);
        self.values[i] + (self.values[i + 1] - self.values[i]) * t
    }

    /// Break points of `self` and the 1 nm grid inside `[lo, hi]`, sorted.
    fn breaks(&self, lo: f64, hi: f64) -> Vec<f64> {
        let lo = lo.max(self.wavelengths[0]);
        let hi = hi.min(self.wavelengths[self.wavelengths.len() - 1]);
        let mut b = Vec::new();
        if hi.is_nan() || lo.is_nan() || hi <= lo {
            return b;
        }
        b.push(lo);
        let mut k = lo.floor() + 1.0;
        while k < hi {
            b.push(k);
            k += 1.0;
        }
        b.extend(
            self.wavelengths
                .iter()
                .copied()
                .filter(|&l| l > lo && l < hi),
        );
        b.push(hi);
        b.sort_by(f64::total_cmp);
        b.dedup();
        b
    }

    /// ∫ s(λ) dλ over `[lo, hi]`, exact.
    pub fn integral(&self, lo: f64, hi: f64) -> f64 {
        let b = self.breaks(lo, hi);
        b.windows(2)
            .map(|p| 0.5 * (p[1] - p[0]) * (self.eval(p[0]) + self.eval(p[1])))
            .sum()
    }

    /// The average of s over `[lo, hi]` (zero outside the samples counts).
    pub fn average(&self, lo: f64, hi: f64) -> f64 {
        if hi > lo {
            self.integral(lo, hi) / (hi - lo)
        } else {
            0.0
        }
    }

    /// ∫ s(λ)·(x̄, ȳ, z̄)(λ) dλ over 360–830 nm, exact for the linear
    /// interpolants (Simpson on each piece where both are linear).
    pub fn cmf_integral(&self) -> [f64; 3] {
        self.cmf_integral_range(CIE_MIN_NM, CIE_MAX_NM)
    }

    /// ∫ s(λ)·(x̄, ȳ, z̄)(λ) dλ over `[lo, hi]`, exact for the linear
    /// interpolants.
    pub fn cmf_integral_range(&self, lo: f64, hi: f64) -> [f64; 3] {
        let b = self.breaks(lo.max(CIE_MIN_NM), hi.min(CIE_MAX_NM));
        let mut acc = [0.0; 3];
        for p in b.windows(2) {
            let (a, c) = (p[0], p[1]);
            let (sa, sc) = (self.eval(a), self.eval(c));
            let (ca, cc) = (cmf(a), cmf(c));
            let h = (c - a) / 6.0;
            for k in 0..3 {
                acc[k] += h * (2.0 * sa * ca[k] + sa * cc[k] + sc * ca[k] + 2.0 * sc * cc[k]);
            }
        }
        acc
    }

    /// The average of s over `[lo, hi]` weighted by the observer's
    /// sensitivity w = x̄ + ȳ + z̄: ∫ s w dλ / ∫ w dλ. This is how a sampled
    /// spectrum becomes one spectral band: the band then has (nearly) the
    /// colour of the part of the spectrum it replaces, even where the
    /// spectrum has structure inside the band (a flat spectrum is exact).
    pub fn observer_weighted_average(&self, lo: f64, hi: f64) -> f64 {
        let num: f64 = self.cmf_integral_range(lo, hi).iter().sum();
        let den: f64 = table_integral(lo, hi).iter().sum();
        if den > 0.0 {
            num / den
        } else {
            self.average(lo, hi)
        }
    }

    /// CIE XYZ by the CIE's own rule for 1 nm data (CIE 015:2018 §7.3, as
    /// colour-science and ASTM E308 do): X = Σ s(λ) x̄(λ) Δλ over λ = 360, 361,
    /// …, 830 nm, normalised by Σ ȳ(λ) Δλ so that the equal-energy spectrum of
    /// value 1 has Y = 1 exactly. (It differs from the exact integral of the
    /// piecewise-linear functions, [`SampledSpectrum::cmf_integral`], only
    /// where the spectrum jumps to zero at its ends: half a nanometre's worth,
    /// ≈ 8e-5 relative for the Cornell light.)
    pub fn to_xyz(&self) -> [f64; 3] {
        let mut acc = [0.0; 3];
        for (i, c) in CIE1931_1NM.iter().enumerate() {
            let v = self.eval(CIE_MIN_NM + i as f64);
            for k in 0..3 {
                acc[k] += v * c[k];
            }
        }
        acc.map(|v| v / CIE_Y_SUM)
    }
}

/// Mitsuba 3's tables and quadrature, reproduced exactly so that RGB-mode
/// conversions give Mitsuba's numbers (`spectrum_list_to_srgb` in its
/// `core/spectrum.cpp`, checked against Mitsuba 3.9.1 on this machine).
///
/// Mitsuba integrates with 1000 equally spaced points over 360–830 nm, the
/// CIE functions linear between their 5 nm values, normalised by its
/// `MI_CIE_Y_NORMALIZATION` = 1/106.7502593994140625, D65 (for reflectances)
/// normalised by `MI_CIE_D65_NORMALIZATION` = 1/98.99741751876255.
pub mod mitsuba {
    use super::{CIE1931_1NM, D65_5NM, SampledSpectrum};

    /// Mitsuba's luminance normalisation of its 5 nm CMF quadrature.
    pub const CIE_Y_NORMALIZATION: f64 = 1.0 / 106.750_259_399_414_06;
    /// Mitsuba's normalisation of D65.
    pub const D65_NORMALIZATION: f64 = 1.0 / 98.997_417_518_762_55;

    fn lerp5(wl: f64, f: impl Fn(usize) -> f64) -> f64 {
        let t = (wl - 360.0) * (94.0 / 470.0);
        let i0 = (t.max(0.0) as usize).min(93);
        let w1 = t - i0 as f64;
        (1.0 - w1) * f(i0) + w1 * f(i0 + 1)
    }

    /// Mitsuba's `cie1931_xyz`: the 5 nm CIE values (every fifth row of the
    /// 1 nm table), linear in between.
    pub fn cmf_5nm(wl: f64) -> [f64; 3] {
        [0, 1, 2].map(|k| lerp5(wl, |i| CIE1931_1NM[5 * i][k]))
    }

    /// Mitsuba's `cie_d65` (normalised).
    pub fn d65_5nm(wl: f64) -> f64 {
        lerp5(wl, |i| D65_5NM[i]) * D65_NORMALIZATION
    }

    /// Mitsuba's `spectrum_list_to_srgb(wavelengths, values, bounded, d65)`:
    /// linear sRGB of a sampled spectrum. With `d65`, the spectrum is a
    /// reflectance seen under D65; `bounded` clamps to [0, 1], otherwise
    /// negative channels clamp to 0.
    pub fn spectrum_to_srgb(s: &SampledSpectrum, bounded: bool, d65: bool) -> [f64; 3] {
        let (lo, hi) = (
            s.wavelengths()[0],
            s.wavelengths()[s.wavelengths().len() - 1],
        );
        let mut xyz = [0.0; 3];
        const STEPS: usize = 1000;
        for i in 0..STEPS {
            let w = 360.0 + (i as f64 / (STEPS - 1) as f64) * 470.0;
            if w < lo || w > hi {
                continue;
            }
            let v = s.eval(w) * if d65 { d65_5nm(w) } else { 1.0 };
            let c = cmf_5nm(w);
            for k in 0..3 {
                xyz[k] += c[k] * v;
            }
        }
        let xyz = xyz.map(|v| v * (470.0 / STEPS as f64) * CIE_Y_NORMALIZATION);
        let rgb = crate::srgb::xyz_to_linear_srgb(xyz);
        if bounded {
            rgb.map(|c| c.clamp(0.0, 1.0))
        } else {
            rgb.map(|c| c.max(0.0))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn table_facts_from_validation_md() {
        let c = cmf(555.0);
        assert_eq!(c[1], 1.0);
        assert!((c[0] - 0.5120501).abs() < 1e-9);
        assert!((c[2] - 0.00575).abs() < 1e-8);
        assert_eq!(CIE1931_1NM.len(), 471);
        assert!((CIE_Y_INTEGRAL - 106.857).abs() < 1e-2, "{CIE_Y_INTEGRAL}");
    }

    #[test]
    fn equal_energy_chromaticity() {
        // docs/validation.md: equal-energy xy = (0.333314, 0.333288) with the 1 nm table.
        let s = SampledSpectrum::new(&[(360.0, 1.0), (830.0, 1.0)]).unwrap();
        let xyz = s.to_xyz();
        let sum: f64 = xyz.iter().sum();
        assert!((xyz[1] - 1.0).abs() < 1e-12);
        assert!((xyz[0] / sum - 0.333314).abs() < 2e-6, "{xyz:?}");
        assert!((xyz[1] / sum - 0.333288).abs() < 2e-6, "{xyz:?}");
    }

    #[test]
    fn d65_white_point() {
        // docs/validation.md: D65 with a perfect reflector: xy = (0.312726, 0.329023).
        let pts: Vec<(f64, f64)> = (0..95)
            .map(|i| (360.0 + 5.0 * i as f64, D65_5NM[i]))
            .collect();
        let s = SampledSpectrum::new(&pts).unwrap();
        let xyz = s.to_xyz();
        let sum: f64 = xyz.iter().sum();
        // The 1 nm CMFs against D65 interpolated linearly from 5 nm: xy agrees
        // with the tabulated white point to the 4th decimal.
        assert!((xyz[0] / sum - 0.312726).abs() < 1e-4, "{xyz:?}");
        assert!((xyz[1] / sum - 0.329023).abs() < 1e-4, "{xyz:?}");
    }

    #[test]
    fn sampled_eval_and_integral() {
        let s = SampledSpectrum::new(&[(400.0, 0.0), (500.0, 8.0), (600.0, 15.6)]).unwrap();
        assert_eq!(s.eval(450.0), 4.0);
        assert_eq!(s.eval(399.0), 0.0);
        assert_eq!(s.eval(601.0), 0.0);
        assert!((s.integral(300.0, 900.0) - (400.0 + 1180.0)).abs() < 1e-9);
        assert!(SampledSpectrum::new(&[(400.0, 1.0)]).is_err());
        assert!(SampledSpectrum::new(&[(500.0, 1.0), (400.0, 1.0)]).is_err());
        assert!(SampledSpectrum::new(&[(400.0, f64::NAN), (500.0, 1.0)]).is_err());
    }

    #[test]
    fn mitsuba_check_values() {
        // Mitsuba 3.9's value for the Cornell light in RGB mode is (20.7108, 10.8546, 2.77115).
        let s = SampledSpectrum::new(&[(400.0, 0.0), (500.0, 8.0), (600.0, 15.6), (700.0, 18.4)])
            .unwrap();
        let rgb = mitsuba::spectrum_to_srgb(&s, false, false);
        let want = [20.7108, 10.8546, 2.77115];
        for k in 0..3 {
            assert!((rgb[k] - want[k]).abs() < 1e-4 * want[k], "{rgb:?}");
        }
    }
}
