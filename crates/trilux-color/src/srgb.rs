//! CIE XYZ ↔ linear sRGB ↔ sRGB-encoded values.
//!
//! The matrices are Mitsuba 3's (`xyz_to_srgb`, `srgb_to_xyz` in its
//! `core/spectrum.h`: Rec. 709 primaries, D65 white, six decimals), so that
//! RGB-mode conversions match Mitsuba to float precision. colour-science uses
//! IEC 61966-2-1's four-decimal matrix; the two differ by < 1e-4 relative
//! (`cargo xtask color` reports both).

/// XYZ → linear sRGB (Mitsuba 3's matrix).
pub const XYZ_TO_SRGB: [[f64; 3]; 3] = [
    [3.240479, -1.537150, -0.498535],
    [-0.969256, 1.875991, 0.041556],
    [0.055648, -0.204043, 1.057311],
];

/// Linear sRGB → XYZ (Mitsuba 3's matrix).
pub const SRGB_TO_XYZ: [[f64; 3]; 3] = [
    [0.412453, 0.357580, 0.180423],
    [0.212671, 0.715160, 0.072169],
    [0.019334, 0.119193, 0.950227],
];

fn mul(m: &[[f64; 3]; 3], v: [f64; 3]) -> [f64; 3] {
    [
        m[0][0] * v[0] + m[0][1] * v[1] + m[0][2] * v[2],
        m[1][0] * v[0] + m[1][1] * v[1] + m[1][2] * v[2],
        m[2][0] * v[0] + m[2][1] * v[1] + m[2][2] * v[2],
    ]
}

/// CIE XYZ → linear sRGB.
pub fn xyz_to_linear_srgb(xyz: [f64; 3]) -> [f64; 3] {
    mul(&XYZ_TO_SRGB, xyz)
}

/// Linear sRGB → CIE XYZ.
pub fn linear_srgb_to_xyz(rgb: [f64; 3]) -> [f64; 3] {
    mul(&SRGB_TO_XYZ, rgb)
}

/// Luminance Y of linear sRGB: the middle row of [`SRGB_TO_XYZ`], Rec. 709
/// weights to six decimals (Mitsuba 3's `luminance`). The one definition of
/// RGB luminance in trilux: equal, bit for bit, to
/// [`Spectrum::<3>::luminance`](crate::Spectrum::luminance) and to the `Y`
/// of [`linear_srgb_to_xyz`]. No clamping: a non-finite channel gives a
/// non-finite luminance.
pub fn luminance(rgb: [f64; 3]) -> f64 {
    let w = SRGB_TO_XYZ[1];
    w[0] * rgb[0] + w[1] * rgb[1] + w[2] * rgb[2]
}

/// The sRGB transfer function (IEC 61966-2-1): 12.92·C for C ≤ 0.0031308,
/// else 1.055·C^(1/2.4) − 0.055. Input clamped to [0, 1]; NaN gives 0.
pub fn encode_srgb(c: f64) -> f64 {
    let c = if c.is_nan() { 0.0 } else { c.clamp(0.0, 1.0) };
    if c <= 0.0031308 {
        12.92 * c
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    }
}

/// Inverse of [`encode_srgb`].
pub fn decode_srgb(e: f64) -> f64 {
    let e = if e.is_nan() { 0.0 } else { e.clamp(0.0, 1.0) };
    if e <= 0.04045 {
        e / 12.92
    } else {
        ((e + 0.055) / 1.055).powf(2.4)
    }
}

/// Linear sRGB → 8-bit sRGB-encoded (rounded to nearest; out-of-range values
/// clamp).
pub fn linear_srgb_to_u8(rgb: [f64; 3]) -> [u8; 3] {
    rgb.map(|c| (encode_srgb(c) * 255.0).round() as u8)
}

/// CIE XYZ → 8-bit sRGB-encoded.
pub fn xyz_to_srgb_u8(xyz: [f64; 3]) -> [u8; 3] {
    linear_srgb_to_u8(xyz_to_linear_srgb(xyz))
}

#[cfg(test)]
mod tests {
    #[test]
    fn luminance_is_the_y_of_xyz_and_white_is_one() {
        for rgb in [[1.0, 0.0, 0.0], [0.25, 0.5, 0.75], [3.0, -1.0, 2.0]] {
            // Bit for bit the Y that the XYZ conversion and the RGB-mode
            // spectrum compute.
            assert_eq!(luminance(rgb), linear_srgb_to_xyz(rgb)[1]);
            assert_eq!(luminance(rgb), crate::Spectrum::<3>(rgb).luminance());
        }
        // Rec. 709: the weights sum to 1 (to the matrix's six decimals), so
        // white has luminance 1, and green weighs most.
        assert!((luminance([1.0; 3]) - 1.0).abs() < 1e-5);
        assert!(luminance([0.0, 1.0, 0.0]) > 0.7);
    }

    use super::*;

    #[test]
    fn encoding_matches_the_standard() {
        // docs/validation.md: 0.5 → 0.735357.
        assert!((encode_srgb(0.5) - 0.735357).abs() < 1e-6);
        assert_eq!(encode_srgb(0.0), 0.0);
        assert!((encode_srgb(1.0) - 1.0).abs() < 1e-12);
        assert!((encode_srgb(0.002) - 0.02584).abs() < 1e-9);
        for i in 0..=100 {
            let c = i as f64 / 100.0;
            assert!((decode_srgb(encode_srgb(c)) - c).abs() < 1e-12);
        }
        assert_eq!(linear_srgb_to_u8([0.0, 1.0, 0.5]), [0, 255, 188]);
    }

    #[test]
    fn matrices_are_inverse_to_their_precision() {
        let v = [0.3, 0.6, 0.9];
        let back = xyz_to_linear_srgb(linear_srgb_to_xyz(v));
        for i in 0..3 {
            assert!((back[i] - v[i]).abs() < 2e-6, "{back:?}");
        }
    }

    #[test]
    fn d65_white_is_rgb_white() {
        // docs/validation.md: D65 XYZ/100 = (0.950469, 1, 1.088830) → ≈ (1, 1, 1).
        let rgb = xyz_to_linear_srgb([0.950469, 1.0, 1.088830]);
        for c in rgb {
            assert!((c - 1.0).abs() < 5e-4, "{rgb:?}");
        }
    }
}
