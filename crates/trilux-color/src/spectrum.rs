//! The spectrum that carries light: `N` bands, fixed at compile time.
//!
//! `Spectrum<3>` is an RGB-mode value (linear sRGB, Rec. 709 primaries, as in
//! Mitsuba 3's `*_rgb` variants). `Spectrum<N>` for any other `N` is a
//! spectral-mode value whose bands are laid out by [`crate::bands`]: `N` equal
//! bands over 400–700 nm with the outer two reaching 360 and 830 nm (the
//! paper used 10). Each band holds the *average* of the spectral quantity
//! over the band, so that a flat spectrum has the same value in every band.
//!
//! The arithmetic is per band (Hadamard products for reflection), in `f64`
//! so that energy sums and the solver's ledger lose nothing.

use std::fmt;
use std::ops::{
    Add, AddAssign, Div, DivAssign, Index, IndexMut, Mul, MulAssign, Neg, Sub, SubAssign,
};

use serde::de::{Deserializer, Error as _};
use serde::ser::{SerializeTuple, Serializer};
use serde::{Deserialize, Serialize};

use crate::mode::Mode;

/// A spectral (or RGB) quantity with `N` bands.
#[derive(Clone, Copy, PartialEq)]
pub struct Spectrum<const N: usize>(pub [f64; N]);

/// The RGB-mode spectrum (linear sRGB).
pub type Rgb = Spectrum<3>;

impl<const N: usize> Spectrum<N> {
    /// The colour mode this band count stands for: 3 bands are RGB, any
    /// other count is spectral.
    pub const MODE: Mode = if N == 3 { Mode::Rgb } else { Mode::Spectral };

    /// Number of bands.
    pub const BANDS: usize = N;

    /// All bands zero.
    pub const fn zero() -> Self {
        Spectrum([0.0; N])
    }

    /// All bands `v`.
    pub const fn splat(v: f64) -> Self {
        Spectrum([v; N])
    }

    /// From the band values.
    pub const fn new(v: [f64; N]) -> Self {
        Spectrum(v)
    }

    /// Band `i` set to `f(i)`.
    pub fn from_fn(f: impl FnMut(usize) -> f64) -> Self {
        Spectrum(std::array::from_fn(f))
    }

    /// The band values.
    pub const fn to_array(self) -> [f64; N] {
        self.0
    }

    /// The band values as a slice.
    pub fn as_slice(&self) -> &[f64] {
        &self.0
    }

    /// Applies `f` to every band.
    pub fn map(self, f: impl Fn(f64) -> f64) -> Self {
        Spectrum(self.0.map(f))
    }

    /// Combines two spectra band by band.
    pub fn zip_with(self, other: Self, f: impl Fn(f64, f64) -> f64) -> Self {
        let mut out = self.0;
        for (o, b) in out.iter_mut().zip(other.0) {
            *o = f(*o, b);
        }
        Spectrum(out)
    }

    /// The largest band value.
    pub fn max_value(&self) -> f64 {
        self.0.iter().copied().fold(f64::NEG_INFINITY, f64::max)
    }

    /// The smallest band value.
    pub fn min_value(&self) -> f64 {
        self.0.iter().copied().fold(f64::INFINITY, f64::min)
    }

    /// The arithmetic mean of the bands.
    pub fn average(&self) -> f64 {
        self.0.iter().sum::<f64>() / N as f64
    }

    /// The sum of the bands.
    pub fn sum(&self) -> f64 {
        self.0.iter().sum()
    }

    /// Band-wise maximum.
    pub fn max(self, other: Self) -> Self {
        self.zip_with(other, f64::max)
    }

    /// Band-wise minimum.
    pub fn min(self, other: Self) -> Self {
        self.zip_with(other, f64::min)
    }

    /// Clamps every band into `[lo, hi]`.
    pub fn clamp(self, lo: f64, hi: f64) -> Self {
        self.map(|v| v.clamp(lo, hi))
    }

    /// Band-wise absolute value.
    pub fn abs(self) -> Self {
        self.map(f64::abs)
    }

    /// True when every band is exactly zero.
    pub fn is_black(&self) -> bool {
        self.0.iter().all(|&v| v == 0.0)
    }

    /// True when every band is finite.
    pub fn is_finite(&self) -> bool {
        self.0.iter().all(|v| v.is_finite())
    }

    /// True when no band is negative (NaN counts as negative).
    pub fn is_non_negative(&self) -> bool {
        self.0.iter().all(|&v| v >= 0.0)
    }

    /// CIE 1931 XYZ of this value, normalised so that the equal-energy
    /// spectrum of value 1 has Y = 1 (RGB mode: through the sRGB matrix;
    /// spectral mode: through the band-integrated colour-matching functions).
    pub fn to_xyz(&self) -> [f64; 3] {
        if N == 3 {
            crate::srgb::linear_srgb_to_xyz([self.0[0], self.0[1], self.0[2]])
        } else {
            crate::bands::Bands::<N>::get().to_xyz(&self.0)
        }
    }

    /// Linear sRGB (Rec. 709 primaries, D65 white) of this value. In RGB mode
    /// the identity.
    pub fn to_linear_srgb(&self) -> [f64; 3] {
        if N == 3 {
            [self.0[0], self.0[1], self.0[2]]
        } else {
            crate::srgb::xyz_to_linear_srgb(self.to_xyz())
        }
    }

    /// The luminance Y of this value (for comparisons and the photometric
    /// refinement criterion). Equal-energy 1 and RGB (1, 1, 1) both give 1
    /// (up to the matrices' rounding).
    pub fn luminance(&self) -> f64 {
        self.to_xyz()[1]
    }
}

impl<const N: usize> Default for Spectrum<N> {
    fn default() -> Self {
        Self::zero()
    }
}

impl<const N: usize> fmt::Debug for Spectrum<N> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "Spectrum{:?}", self.0)
    }
}

impl<const N: usize> From<[f64; N]> for Spectrum<N> {
    fn from(v: [f64; N]) -> Self {
        Spectrum(v)
    }
}

impl<const N: usize> Index<usize> for Spectrum<N> {
    type Output = f64;
    fn index(&self, i: usize) -> &f64 {
        &self.0[i]
    }
}

impl<const N: usize> IndexMut<usize> for Spectrum<N> {
    fn index_mut(&mut self, i: usize) -> &mut f64 {
        &mut self.0[i]
    }
}

macro_rules! binop {
    ($tr:ident, $f:ident, $tra:ident, $fa:ident, $op:tt) => {
        impl<const N: usize> $tr for Spectrum<N> {
            type Output = Self;
            #[inline]
            fn $f(self, rhs: Self) -> Self {
                self.zip_with(rhs, |a, b| a $op b)
            }
        }
        impl<const N: usize> $tr<f64> for Spectrum<N> {
            type Output = Self;
            #[inline]
            fn $f(self, rhs: f64) -> Self {
                self.map(|a| a $op rhs)
            }
        }
        impl<const N: usize> $tra for Spectrum<N> {
            #[inline]
            fn $fa(&mut self, rhs: Self) {
                *self = *self $op rhs;
            }
        }
        impl<const N: usize> $tra<f64> for Spectrum<N> {
            #[inline]
            fn $fa(&mut self, rhs: f64) {
                *self = *self $op rhs;
            }
        }
    };
}

binop!(Add, add, AddAssign, add_assign, +);
binop!(Sub, sub, SubAssign, sub_assign, -);
binop!(Mul, mul, MulAssign, mul_assign, *);
binop!(Div, div, DivAssign, div_assign, /);

impl<const N: usize> Mul<Spectrum<N>> for f64 {
    type Output = Spectrum<N>;
    #[inline]
    fn mul(self, rhs: Spectrum<N>) -> Spectrum<N> {
        rhs * self
    }
}

impl<const N: usize> Neg for Spectrum<N> {
    type Output = Self;
    #[inline]
    fn neg(self) -> Self {
        self.map(|a| -a)
    }
}

impl<const N: usize> std::iter::Sum for Spectrum<N> {
    fn sum<I: Iterator<Item = Self>>(iter: I) -> Self {
        iter.fold(Self::zero(), |a, b| a + b)
    }
}

impl<const N: usize> Serialize for Spectrum<N> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut t = s.serialize_tuple(N)?;
        for v in &self.0 {
            t.serialize_element(v)?;
        }
        t.end()
    }
}

impl<'de, const N: usize> Deserialize<'de> for Spectrum<N> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let v: Vec<f64> = Vec::deserialize(d)?;
        let arr: [f64; N] = v
            .try_into()
            .map_err(|v: Vec<f64>| D::Error::invalid_length(v.len(), &"N band values"))?;
        Ok(Spectrum(arr))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mode::SPECTRAL_BANDS;

    #[test]
    fn arithmetic_is_per_band() {
        let a = Spectrum([1.0, 2.0, 3.0]);
        let b = Spectrum([2.0, 4.0, 8.0]);
        assert_eq!((a * b).0, [2.0, 8.0, 24.0]);
        assert_eq!((b / a).0, [2.0, 2.0, 8.0 / 3.0]);
        assert_eq!((a + 1.0).0, [2.0, 3.0, 4.0]);
        assert_eq!((2.0 * a).0, [2.0, 4.0, 6.0]);
        assert_eq!(a.max_value(), 3.0);
        assert_eq!(a.min_value(), 1.0);
        assert!(Spectrum::<SPECTRAL_BANDS>::zero().is_black());
        assert!(!Spectrum([f64::NAN, 0.0, 0.0]).is_finite());
    }

    #[test]
    fn modes_follow_band_count() {
        assert_eq!(Spectrum::<3>::MODE, Mode::Rgb);
        assert_eq!(Spectrum::<SPECTRAL_BANDS>::MODE, Mode::Spectral);
    }

    #[test]
    fn serde_round_trip() {
        let a = Spectrum::<SPECTRAL_BANDS>(std::array::from_fn(|i| 0.25 * i as f64 - 0.5));
        let j = serde_json::to_string(&a).unwrap();
        let b: Spectrum<SPECTRAL_BANDS> = serde_json::from_str(&j).unwrap();
        assert_eq!(a, b);
        assert!(serde_json::from_str::<Spectrum<3>>(&j).is_err());
    }
}
