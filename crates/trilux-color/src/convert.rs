//! From a colour as written ([`ColorParam`]) to the spectrum of one solve.
//!
//! The same written value means different things for a reflectance, for an
//! emitter's radiance and for an unbounded quantity such as a conductor's η
//! and k, exactly as in Mitsuba 3 (docs/architecture.md, "Colour"; every RGB-mode rule below
//! was checked against Mitsuba 3.9.1's `scalar_rgb` variant on this machine):
//!
//! | written | [`Role::Reflectance`] | [`Role::Emission`] | [`Role::Unbounded`] |
//! |---|---|---|---|
//! | `<float v>` | v everywhere | v everywhere (spectral: v · D65) | v everywhere |
//! | `<rgb>` | as given (spectral: smooth, within 0…1) | as given (spectral: D65 · smooth) | as given (spectral: smooth, ≥ 0) |
//! | `<spectrum v>` | v everywhere | equal-energy v: RGB (1.20479, 0.948291, 0.908916)·v | v everywhere |
//! | `<spectrum λ:v …>` | RGB: under D65, clamped to 0…1; spectral: band averages | RGB: through XYZ, ≥ 0; spectral: band averages | RGB: under D65, ≥ 0; spectral: band averages |
//! | a named conductor (`Measured`) | RGB: through XYZ, no illuminant, ≥ 0 (Mitsuba's `ior_from_file`); spectral: band averages | same | same |
//!
//! Spectral band averages are weighted by the observer (x̄ + ȳ + z̄) within
//! each band ([`SampledSpectrum::observer_weighted_average`]).
//!
//! RGB mode reproduces Mitsuba's own quadrature ([`crate::cie::mitsuba`]), so
//! the classic Cornell white becomes (0.735013, 0.735625, 0.736264) and the
//! Cornell light (20.7108, 10.8546, 2.77115), as in Mitsuba. "Smooth" is
//! [`crate::upsample`].

use crate::ColorError;
use crate::cie::{SampledSpectrum, mitsuba};
use crate::param::ColorParam;
use crate::spectrum::Spectrum;
use crate::upsample::{smooth_emission, smooth_reflectance, smooth_unbounded};

/// What a colour value describes; decides how it converts.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Role {
    /// A reflectance (diffuse `reflectance`, `specular_reflectance`):
    /// bounded to [0, 1], seen under D65.
    Reflectance,
    /// Emitted radiance of an area emitter.
    Emission,
    /// A quantity without upper bound (η and k of a conductor); negative
    /// values act as Mitsuba's Fresnel term takes them (their magnitude).
    Unbounded,
}

fn check(v: f64) -> Result<f64, ColorError> {
    if !v.is_finite() {
        Err(ColorError::NotFinite)
    } else if v < 0.0 {
        Err(ColorError::Negative(v))
    } else {
        Ok(v)
    }
}

impl ColorParam {
    /// This value as a spectrum of `N` bands (3: RGB mode; otherwise
    /// spectral mode) in the given role. Non-finite values, negative ones
    /// (but in [`Role::Unbounded`]) and malformed sampled spectra are errors.
    pub fn to_spectrum<const N: usize>(&self, role: Role) -> Result<Spectrum<N>, ColorError> {
        if role == Role::Unbounded && self.values().iter().any(|v| *v < 0.0) {
            return self.signed_unbounded();
        }
        for v in self.values() {
            check(v)?;
        }
        if let ColorParam::Sampled(s) | ColorParam::Measured(s) = self {
            for &(l, _) in s {
                if !l.is_finite() {
                    return Err(ColorError::NotFinite);
                }
            }
        }
        let rgb_mode = N == 3;
        let out = if rgb_mode {
            let rgb: [f64; 3] = match self {
                ColorParam::Float(v) => [*v; 3],
                ColorParam::Rgb(c) => *c,
                ColorParam::Constant(v) => match role {
                    Role::Emission => {
                        let ee = equal_energy_rgb();
                        ee.map(|c| c * v)
                    }
                    _ => [*v; 3],
                },
                ColorParam::Sampled(s) => {
                    let s = SampledSpectrum::new(s)?;
                    match role {
                        Role::Reflectance => mitsuba::spectrum_to_srgb(&s, true, true),
                        Role::Unbounded => mitsuba::spectrum_to_srgb(&s, false, true),
                        Role::Emission => mitsuba::spectrum_to_srgb(&s, false, false),
                    }
                }
                // Mitsuba's `ior_from_file`: `spectrum_list_to_srgb(λ, v,
                // bounded = false, d65 = false)`, whatever the role.
                ColorParam::Measured(s) => {
                    mitsuba::spectrum_to_srgb(&SampledSpectrum::new(s)?, false, false)
                }
            };
            let mut a = [0.0; N];
            a[..3].copy_from_slice(&rgb);
            Spectrum(a)
        } else {
            match self {
                ColorParam::Float(v) => match role {
                    Role::Emission => smooth_emission::<N>([*v; 3]),
                    _ => Spectrum::splat(*v),
                },
                ColorParam::Constant(v) => Spectrum::splat(*v),
                ColorParam::Rgb(c) => match role {
                    Role::Reflectance => smooth_reflectance::<N>(*c),
                    Role::Unbounded => smooth_unbounded::<N>(*c),
                    Role::Emission => smooth_emission::<N>(*c),
                },
                ColorParam::Sampled(s) | ColorParam::Measured(s) => {
                    let s = SampledSpectrum::new(s)?;
                    let mut a = [0.0; N];
                    for (b, v) in a.iter_mut().enumerate() {
                        *v = s
                            .observer_weighted_average(
                                crate::bands::band_edge(N, b),
                                crate::bands::band_edge(N, b + 1),
                            )
                            .max(0.0);
                    }
                    Spectrum(a)
                }
            }
        };
        if out.is_finite() {
            Ok(out)
        } else {
            Err(ColorError::NotFinite)
        }
    }

    /// A conductor's η or k with negative values, as Mitsuba 3.9.1 takes
    /// them: its Fresnel term sees only η², k² and η²k², so a negative
    /// number, RGB channel or wavelength's value acts as its magnitude,
    /// except that a sampled spectrum is first converted to RGB in RGB
    /// mode, where Mitsuba clamps negative channels to 0 (checked against
    /// Mitsuba's `eval` in `scalar_rgb`: crates/trilux-scene/tests/negative_ior.rs).
    fn signed_unbounded<const N: usize>(&self) -> Result<Spectrum<N>, ColorError> {
        let magnitude = match self {
            ColorParam::Float(v) => ColorParam::Float(v.abs()),
            ColorParam::Constant(v) => ColorParam::Constant(v.abs()),
            ColorParam::Rgb(c) => ColorParam::Rgb(c.map(f64::abs)),
            ColorParam::Sampled(s) if N == 3 => {
                let rgb = mitsuba::spectrum_to_srgb(&SampledSpectrum::new(s)?, false, true);
                ColorParam::Rgb(rgb)
            }
            ColorParam::Sampled(s) => {
                ColorParam::Sampled(s.iter().map(|&(l, v)| (l, v.abs())).collect())
            }
            ColorParam::Measured(s) if N == 3 => {
                let rgb = mitsuba::spectrum_to_srgb(&SampledSpectrum::new(s)?, false, false);
                ColorParam::Rgb(rgb)
            }
            ColorParam::Measured(s) => {
                ColorParam::Measured(s.iter().map(|&(l, v)| (l, v.abs())).collect())
            }
        };
        magnitude.to_spectrum(Role::Unbounded)
    }

    /// This value as a reflectance (see [`Role::Reflectance`]).
    pub fn reflectance<const N: usize>(&self) -> Result<Spectrum<N>, ColorError> {
        self.to_spectrum(Role::Reflectance)
    }

    /// This value as an emitter's radiance (see [`Role::Emission`]).
    pub fn emission<const N: usize>(&self) -> Result<Spectrum<N>, ColorError> {
        self.to_spectrum(Role::Emission)
    }

    /// This value as an unbounded quantity (see [`Role::Unbounded`]).
    pub fn unbounded<const N: usize>(&self) -> Result<Spectrum<N>, ColorError> {
        self.to_spectrum(Role::Unbounded)
    }
}

/// Linear sRGB of the equal-energy spectrum of value 1 as Mitsuba 3 sets it
/// in RGB mode: its parser uses `xyz_to_srgb(1, 1, 1)`, the row sums of the
/// XYZ → sRGB matrix, = (1.204794, 0.948291, 0.908916).
pub fn equal_energy_rgb() -> [f64; 3] {
    crate::srgb::xyz_to_linear_srgb([1.0; 3])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mode::SPECTRAL_BANDS;

    const CORNELL_WHITE: &str = "400:0.343, 404:0.445, 408:0.551, 412:0.624, 416:0.665, 420:0.687, 424:0.708, 428:0.723, 432:0.715, 436:0.71, 440:0.745, 444:0.758, 448:0.739, 452:0.767, 456:0.777, 460:0.765, 464:0.751, 468:0.745, 472:0.748, 476:0.729, 480:0.745, 484:0.757, 488:0.753, 492:0.75, 496:0.746, 500:0.747, 504:0.735, 508:0.732, 512:0.739, 516:0.734, 520:0.725, 524:0.721, 528:0.733, 532:0.725, 536:0.732, 540:0.743, 544:0.744, 548:0.748, 552:0.728, 556:0.716, 560:0.733, 564:0.726, 568:0.713, 572:0.74, 576:0.754, 580:0.764, 584:0.752, 588:0.736, 592:0.734, 596:0.741, 600:0.74, 604:0.732, 608:0.745, 612:0.755, 616:0.751, 620:0.744, 624:0.731, 628:0.733, 632:0.744, 636:0.731, 640:0.712, 644:0.708, 648:0.729, 652:0.73, 656:0.727, 660:0.707, 664:0.703, 668:0.729, 672:0.75, 676:0.76, 680:0.751, 684:0.739, 688:0.724, 692:0.73, 696:0.74, 700:0.737";

    fn parse(s: &str) -> ColorParam {
        ColorParam::Sampled(
            s.split(',')
                .map(|p| {
                    let mut it = p.trim().split(':');
                    let l: f64 = it.next().unwrap().parse().unwrap();
                    let v: f64 = it.next().unwrap().parse().unwrap();
                    (l, v)
                })
                .collect(),
        )
    }

    fn close(a: [f64; 3], b: [f64; 3], rel: f64) {
        for k in 0..3 {
            assert!(
                (a[k] - b[k]).abs() <= rel * b[k].abs().max(1e-3),
                "{a:?} vs {b:?}"
            );
        }
    }

    // Expected values printed by Mitsuba 3.9.1 (scalar_rgb) for the same
    // XML values (mi.traverse of the loaded object); 6 significant digits.
    #[test]
    fn rgb_mode_matches_mitsuba() {
        let w: Spectrum<3> = parse(CORNELL_WHITE).reflectance().unwrap();
        close(w.0, [0.735013, 0.735625, 0.736264], 2e-6);
        let l: Spectrum<3> = parse("400:0, 500:8, 600:15.6, 700:18.4")
            .emission()
            .unwrap();
        close(l.0, [20.7108, 10.8546, 2.77115], 5e-6);
        let e: Spectrum<3> = ColorParam::Constant(1.0).emission().unwrap();
        close(e.0, [1.20479, 0.948291, 0.908916], 5e-6);
        let e: Spectrum<3> = ColorParam::Constant(2.5).emission().unwrap();
        close(e.0, [3.01198, 2.37073, 2.27229], 5e-6);
        let f: Spectrum<3> = ColorParam::Float(2.5).emission().unwrap();
        assert_eq!(f.0, [2.5; 3]);
        let c: Spectrum<3> = ColorParam::Constant(0.3).reflectance().unwrap();
        assert_eq!(c.0, [0.3; 3]);
        let flat: Spectrum<3> = parse("360:1, 830:1").reflectance().unwrap();
        close(flat.0, [0.998985, 0.998874, 0.998802], 2e-6);
        let sat: Spectrum<3> = parse("400:1, 500:0, 700:0").reflectance().unwrap();
        close(sat.0, [0.0284337, 0.0, 0.515323], 2e-5);
        let eta: Spectrum<3> = parse("400:1.5, 500:0.5, 600:2.5, 700:3.0")
            .unbounded()
            .unwrap();
        close(eta.0, [3.10261, 1.2672, 0.873268], 5e-6);
        let k: Spectrum<3> = parse("400:3, 700:4").unbounded().unwrap();
        close(k.0, [3.79017, 3.47572, 3.12077], 5e-6);
        let spec: Spectrum<3> = parse("400:3, 700:3").reflectance().unwrap();
        assert_eq!(spec.0, [1.0; 3]);
    }

    #[test]
    fn spectral_mode_rules() {
        let w: Spectrum<SPECTRAL_BANDS> = parse(CORNELL_WHITE).reflectance().unwrap();
        // Bands inside 400–700 nm average the data (0.665…0.777 past
        // 416 nm, 0.343 at 400); the outer bands (from 360 nm, to 830 nm)
        // average in the zero outside the data, so they are darker.
        let inner = Spectrum::<{ SPECTRAL_BANDS - 2 }>(std::array::from_fn(|i| w.0[i + 1]));
        assert!(inner.min_value() > 0.6 && inner.max_value() < 0.78, "{w:?}");
        for outer in [w.0[0], w.0[SPECTRAL_BANDS - 1]] {
            assert!(outer > 0.0 && outer < inner.min_value(), "{w:?}");
        }
        let ee: Spectrum<SPECTRAL_BANDS> = ColorParam::Constant(1.0).emission().unwrap();
        assert_eq!(ee.0, [1.0; SPECTRAL_BANDS]);
        let f: Spectrum<SPECTRAL_BANDS> = ColorParam::Float(1.0).emission().unwrap();
        close(f.to_linear_srgb(), [1.0, 1.0, 1.0], 3e-3);
        let r: Spectrum<SPECTRAL_BANDS> = ColorParam::Rgb([0.5, 0.4, 0.3]).emission().unwrap();
        close(r.to_linear_srgb(), [0.5, 0.4, 0.3], 1e-9);
        assert!(
            ColorParam::Float(-1.0)
                .reflectance::<SPECTRAL_BANDS>()
                .is_err()
        );
        assert!(
            ColorParam::Rgb([f64::NAN, 0.0, 0.0])
                .reflectance::<3>()
                .is_err()
        );
        assert!(
            ColorParam::Sampled(vec![(400.0, 1.0)])
                .emission::<3>()
                .is_err()
        );
    }
}
