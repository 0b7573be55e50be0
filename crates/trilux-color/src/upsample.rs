//! RGB → smooth band spectrum, for RGB values in a spectral scene.
//!
//! Method (trilux's own; Mitsuba's spectral variants use Jakob & Hanika 2019,
//! which needs a precomputed coefficient table): the band spectrum `s` with
//! the smallest squared second differences Σ (s_{b−1} − 2 s_b + s_{b+1})²
//! (the smoothest) among those whose colour is exactly the given linear sRGB
//! value, M s = rgb. It is the solution of a small linear KKT system, so the
//! map is linear in rgb, and the round trip rgb → s → rgb is exact until
//! clamping.
//!
//! - A *reflectance* uses M = the colour of the band reflectance under the
//!   band D65 illuminant, each row scaled so that the flat spectrum 1 maps to
//!   (1, 1, 1) (a white balance that absorbs the 10-band error on D65, up to
//!   3.4% in blue). Grey rgb therefore gives an exactly flat spectrum, and
//!   white stays 1. It then clamps to [0, 1], which is where the round trip
//!   loses: saturated colours whose smooth spectrum would dip below zero or
//!   rise above one. The measured worst round-trip error over the RGB cube
//!   (11³ grid) is in docs/results.md and bounded by this module's tests.
//! - An *emission* is D65 × s with M unbalanced, so that its colour is
//!   exactly rgb (as Mitsuba's spectral variants multiply the upsampled
//!   spectrum by D65).

use crate::bands::Bands;
use crate::spectrum::Spectrum;

/// The 3 × N matrix taking a band reflectance seen under band D65 to linear
/// sRGB (unbalanced: the flat spectrum 1 maps to the band D65's colour).
pub fn reflectance_to_srgb_matrix<const N: usize>() -> [[f64; N]; 3] {
    let b = Bands::<N>::get();
    let mut m = [[0.0; N]; 3];
    for band in 0..N {
        let xyz = b.cmf[band].map(|v| v * b.d65[band]);
        let rgb = crate::srgb::xyz_to_linear_srgb(xyz);
        for c in 0..3 {
            m[c][band] = rgb[c];
        }
    }
    m
}

/// [`reflectance_to_srgb_matrix`] with each row scaled so that the flat
/// spectrum 1 maps to (1, 1, 1).
pub fn balanced_reflectance_matrix<const N: usize>() -> [[f64; N]; 3] {
    let mut m = reflectance_to_srgb_matrix::<N>();
    for row in m.iter_mut() {
        let sum: f64 = row.iter().sum();
        for v in row.iter_mut() {
            *v /= sum;
        }
    }
    m
}

/// Linear sRGB of a band reflectance (white-balanced: flat 1 → (1, 1, 1)),
/// the inverse of [`smooth_reflectance`] before clamping.
pub fn reflectance_to_srgb<const N: usize>(s: &Spectrum<N>) -> [f64; 3] {
    let m = balanced_reflectance_matrix::<N>();
    [0, 1, 2].map(|c| (0..N).map(|b| m[c][b] * s.0[b]).sum())
}

/// The smoothest band reflectance whose (balanced) colour is `rgb`;
/// unclamped, so it may leave [0, 1] for saturated colours.
pub fn smooth_reflectance<const N: usize>(rgb: [f64; 3]) -> Spectrum<N> {
    smoothest(&balanced_reflectance_matrix::<N>(), rgb)
}

/// D65 × the smoothest non-negative band spectrum s whose colour as an
/// emission D65 × s is `rgb` (exact unless s had to be clamped at 0).
pub fn smooth_emission<const N: usize>(rgb: [f64; 3]) -> Spectrum<N> {
    let s = smoothest(&reflectance_to_srgb_matrix::<N>(), rgb).max(Spectrum::zero());
    s * Bands::<N>::get().d65_spectrum()
}

/// The smoothest spectrum with m s = rgb.
fn smoothest<const N: usize>(m: &[[f64; N]; 3], rgb: [f64; 3]) -> Spectrum<N> {
    let n = N + 3;
    // KKT system [2Q Mᵀ; M 0] [s; λ] = [0; rgb], Q = DᵀD (second differences).
    let mut a = vec![vec![0.0; n + 1]; n];
    for i in 1..N.saturating_sub(1) {
        let d = [(i - 1, 1.0), (i, -2.0), (i + 1, 1.0)];
        for &(p, vp) in &d {
            for &(q, vq) in &d {
                a[p][q] += 2.0 * vp * vq;
            }
        }
    }
    for c in 0..3 {
        for b in 0..N {
            a[b][N + c] = m[c][b];
            a[N + c][b] = m[c][b];
        }
        a[N + c][n] = rgb[c];
    }
    let x = solve(a);
    let mut s = [0.0; N];
    s.copy_from_slice(&x[..N]);
    Spectrum(s)
}

/// Gaussian elimination with partial pivoting on an augmented matrix.
fn solve(mut a: Vec<Vec<f64>>) -> Vec<f64> {
    let n = a.len();
    for col in 0..n {
        let piv = (col..n)
            .max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))
            .unwrap_or(col);
        a.swap(col, piv);
        let p = a[col][col];
        if p.abs() < 1e-300 {
            continue;
        }
        for row in 0..n {
            if row != col {
                let f = a[row][col] / p;
                if f != 0.0 {
                    for k in col..=n {
                        a[row][k] -= f * a[col][k];
                    }
                }
            }
        }
    }
    (0..n)
        .map(|i| {
            if a[i][i] != 0.0 {
                a[i][n] / a[i][i]
            } else {
                0.0
            }
        })
        .collect()
}

/// Largest absolute round-trip error |rgb − M·clamp(s(rgb))| over an 11³ grid
/// of the RGB cube, for reflectances (clamped to [0, 1]).
pub fn reflectance_round_trip_error<const N: usize>() -> f64 {
    let mut worst: f64 = 0.0;
    for r in 0..=10 {
        for g in 0..=10 {
            for b in 0..=10 {
                let rgb = [r, g, b].map(|v| v as f64 / 10.0);
                let s = smooth_reflectance::<N>(rgb).clamp(0.0, 1.0);
                let back = reflectance_to_srgb(&s);
                for c in 0..3 {
                    worst = worst.max((back[c] - rgb[c]).abs());
                }
            }
        }
    }
    worst
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exact_round_trip_before_clamping() {
        for rgb in [
            [0.5, 0.5, 0.5],
            [0.2, 0.6, 0.3],
            [0.9, 0.1, 0.4],
            [1.0, 1.0, 1.0],
        ] {
            let s = smooth_reflectance::<10>(rgb);
            let back = reflectance_to_srgb(&s);
            for c in 0..3 {
                assert!(
                    (back[c] - rgb[c]).abs() < 1e-10,
                    "{rgb:?} → {s:?} → {back:?}"
                );
            }
        }
    }

    #[test]
    fn grey_is_nearly_flat() {
        let s = smooth_reflectance::<10>([0.5, 0.5, 0.5]);
        assert!(s.max_value() - s.min_value() < 1e-12, "{s:?}");
        let w = smooth_reflectance::<10>([1.0, 1.0, 1.0]);
        assert!((w.min_value() - 1.0).abs() < 1e-12 && (w.max_value() - 1.0).abs() < 1e-12);
    }

    #[test]
    fn emission_colour_is_exact() {
        for rgb in [[1.0, 1.0, 1.0], [0.5, 0.4, 0.3], [5.0, 2.0, 1.0]] {
            let e = smooth_emission::<10>(rgb);
            let back = e.to_linear_srgb();
            for c in 0..3 {
                assert!(
                    (back[c] - rgb[c]).abs() < 1e-9 * rgb[c].max(1.0),
                    "{back:?}"
                );
            }
        }
        // A saturated green needs the clamp at zero: 1.3% error in red (measured).
        let back = smooth_emission::<10>([0.2, 0.6, 0.3]).to_linear_srgb();
        assert!((back[0] - 0.2).abs() < 5e-3, "{back:?}");
    }

    #[test]
    fn clamped_round_trip_error_is_bounded() {
        // Measured: see docs/results.md. Pastel and mid colours are exact;
        // the worst cases are saturated primaries.
        let e = reflectance_round_trip_error::<10>();
        assert!(e < 0.25, "worst round-trip error {e}");
    }
}
