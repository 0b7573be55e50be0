//! The spectral bands of spectral mode and the band-integrated CIE functions.
//!
//! `N` bands split 400–700 nm into equal parts (30 nm for the paper's 10);
//! the first band reaches down to 360 nm and the last up to 830 nm, the
//! ends of the CIE table, so that no part of the visible spectrum is lost
//! (cutting at 400–700 loses 0.4% of R and 0.6% of B for a flat spectrum:
//! docs/validation.md, "Colour"). A band value is the average of the spectrum over the band.
//! Its colour is Σ_b s_b ∫_b (x̄, ȳ, z̄) dλ / ∫ ȳ dλ, which is exact for any
//! spectrum that is constant over each band (in particular a flat one), and
//! an approximation otherwise whose error `cargo xtask color` measures.
//!
//! All tables here are computed at compile time from the 1 nm CIE table.

use crate::cie::{CIE_MAX_NM, CIE_MIN_NM, CIE_Y_INTEGRAL, d65_integral, table_integral};

/// Band layout and band-integrated CIE data for `N` spectral bands.
#[derive(Clone, Copy, Debug)]
pub struct Bands<const N: usize> {
    /// ∫ (x̄, ȳ, z̄) dλ over each band, divided by ∫ ȳ dλ (so that
    /// Σ_b of the middle column is 1).
    pub cmf: [[f64; 3]; N],
    /// The average of D65 over each band, normalised so that the band D65
    /// spectrum has luminance 1.
    pub d65: [f64; N],
}

/// The lower edge of band `i` of `n` (and the upper edge of band `i − 1`),
/// in nm.
pub const fn band_edge(n: usize, i: usize) -> f64 {
    if i == 0 {
        CIE_MIN_NM
    } else if i >= n {
        CIE_MAX_NM
    } else {
        400.0 + 300.0 * i as f64 / n as f64
    }
}

impl<const N: usize> Bands<N> {
    const TABLE: Bands<N> = Self::compute();

    const fn compute() -> Bands<N> {
        let mut cmf = [[0.0; 3]; N];
        let mut d65 = [0.0; N];
        let mut y = 0.0;
        let mut i = 0;
        while i < N {
            let (lo, hi) = (band_edge(N, i), band_edge(N, i + 1));
            let c = table_integral(lo, hi);
            cmf[i] = [
                c[0] / CIE_Y_INTEGRAL,
                c[1] / CIE_Y_INTEGRAL,
                c[2] / CIE_Y_INTEGRAL,
            ];
            d65[i] = d65_integral(lo, hi) / (hi - lo);
            y += d65[i] * cmf[i][1];
            i += 1;
        }
        let mut i = 0;
        while i < N {
            d65[i] /= y;
            i += 1;
        }
        Bands { cmf, d65 }
    }

    /// The tables for `N` bands (computed at compile time).
    pub const fn get() -> &'static Bands<N> {
        &Self::TABLE
    }

    /// Band edges in nm (`N + 1` values), for stats (`wavelengths_nm`).
    pub fn edges() -> Vec<f64> {
        (0..=N).map(|i| band_edge(N, i)).collect()
    }

    /// CIE XYZ of a band spectrum's values (equal-energy 1 → Y = 1).
    /// ([`Spectrum::to_xyz`](crate::Spectrum::to_xyz) calls this: the
    /// tables work on plain band values, the spectrum type sits above.)
    pub fn to_xyz(&self, s: &[f64; N]) -> [f64; 3] {
        let mut xyz = [0.0; 3];
        for b in 0..N {
            for k in 0..3 {
                xyz[k] += s[b] * self.cmf[b][k];
            }
        }
        xyz
    }

    /// The band values of D65 (luminance 1).
    pub fn d65(&self) -> [f64; N] {
        self.d65
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mode::SPECTRAL_BANDS;

    #[test]
    fn ten_bands_layout() {
        let e = Bands::<10>::edges();
        assert_eq!(e.len(), 11);
        assert_eq!(e[0], 360.0);
        assert_eq!(e[1], 430.0);
        assert_eq!(e[9], 670.0);
        assert_eq!(e[10], 830.0);
        // The default layout: 400–700 nm in 300/N nm steps, outer bands
        // stretched to the CIE table's ends.
        let e = Bands::<SPECTRAL_BANDS>::edges();
        let step = 300.0 / SPECTRAL_BANDS as f64;
        assert_eq!(e.len(), SPECTRAL_BANDS + 1);
        assert_eq!((e[0], e[SPECTRAL_BANDS]), (360.0, 830.0));
        for i in 1..SPECTRAL_BANDS {
            assert!((e[i] - (400.0 + step * i as f64)).abs() < 1e-12, "{e:?}");
        }
    }

    #[test]
    fn flat_spectrum_is_exact() {
        let b = Bands::<SPECTRAL_BANDS>::get();
        let xyz = b.to_xyz(&[1.0; SPECTRAL_BANDS]);
        assert!((xyz[1] - 1.0).abs() < 1e-12);
        let sum: f64 = xyz.iter().sum();
        assert!((xyz[0] / sum - 0.333314).abs() < 2e-6);
        assert!((xyz[1] / sum - 0.333288).abs() < 2e-6);
    }

    #[test]
    fn d65_band_spectrum_is_white() {
        let b = Bands::<10>::get();
        let rgb = crate::srgb::xyz_to_linear_srgb(b.to_xyz(&b.d65()));
        // Averaging the spiky D65 over 30 nm bands (the first one 360–430 nm)
        // costs about 3.4% in blue: measured (0.9958, 1.0047, 0.9658).
        for c in rgb {
            assert!((c - 1.0).abs() < 0.04, "{rgb:?}");
        }
    }
}
