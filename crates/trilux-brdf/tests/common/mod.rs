//! Shared helpers for trilux-brdf's integration tests.
#![allow(dead_code)]

use glam::{DVec2, DVec3};
use trilux_brdf::{BsdfParams, Distribution, RoughConductorParams};
use trilux_color::ColorParam;

/// SplitMix64: a small deterministic generator (tests must be repeatable).
pub struct Rng(pub u64);

impl Rng {
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in [0, 1).
    pub fn f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }
    pub fn vec2(&mut self) -> DVec2 {
        DVec2::new(self.f64(), self.f64())
    }
}

/// A direction with polar angle `theta_deg` in the xz plane, upper hemisphere.
pub fn dir_deg(theta_deg: f64) -> DVec3 {
    let t = theta_deg.to_radians();
    DVec3::new(t.sin(), 0.0, t.cos())
}

pub fn conductor(distribution: Distribution, alpha: f64) -> BsdfParams {
    BsdfParams::RoughConductor(RoughConductorParams {
        distribution,
        alpha,
        eta_k: None,
        specular_reflectance: ColorParam::Float(1.0),
    })
}

pub fn gold(distribution: Distribution, alpha: f64) -> BsdfParams {
    BsdfParams::RoughConductor(RoughConductorParams {
        distribution,
        alpha,
        eta_k: Some((
            ColorParam::Rgb([0.143, 0.374, 1.442]),
            ColorParam::Rgb([3.983, 2.385, 1.603]),
        )),
        specular_reflectance: ColorParam::Float(1.0),
    })
}

pub fn diffuse(rho: f64) -> BsdfParams {
    BsdfParams::Diffuse {
        reflectance: ColorParam::Float(rho),
    }
}

/// Complementary error function (Abramowitz & Stegun 7.1.26 on |x|,
/// absolute error < 1.5e-7).
pub fn erfc(x: f64) -> f64 {
    let z = x.abs();
    let t = 1.0 / (1.0 + 0.327_591_1 * z);
    let poly = t
        * (0.254_829_592
            + t * (-0.284_496_736
                + t * (1.421_413_741 + t * (-1.453_152_027 + t * 1.061_405_429))));
    let r = poly * (-z * z).exp();
    if x >= 0.0 { r } else { 2.0 - r }
}

/// Upper tail P(χ²_k ≥ x) by the Wilson–Hilferty normal approximation
/// (good to a few percent of p for k ≥ 10, which is all a test threshold
/// needs).
pub fn chi2_sf(x: f64, k: f64) -> f64 {
    let z = ((x / k).cbrt() - (1.0 - 2.0 / (9.0 * k))) / (2.0 / (9.0 * k)).sqrt();
    0.5 * erfc(z / std::f64::consts::SQRT_2)
}
