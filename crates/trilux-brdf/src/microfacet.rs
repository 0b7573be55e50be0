//! Microfacet distributions exactly as Mitsuba 3 evaluates them
//! (`include/mitsuba/render/microfacet.h`), isotropic only.
//!
//! - D: Beckmann exp(−tan²θ/α²)/(π α² cos⁴θ); GGX 1/(π α² (sin²θ/α² + cos²θ)²);
//!   both normalised so that ∫ D(m) cosθ_m dω_m = 1, and set to 0 where
//!   D·cosθ ≤ 1e-20 (Mitsuba's guard).
//! - Smith's *separable* shadowing-masking G = G1(wi, m)·G1(wo, m); for GGX the
//!   exact G1 = 2/(1 + √(1 + α² tan²θ)); for Beckmann Mitsuba's rational
//!   approximation in a = 1/(α tanθ): (3.535a + 2.181a²)/(1 + 2.276a + 2.577a²),
//!   1 for a ≥ 1.6 (< 0.35% from the exact erf form). G1 = 0 when v sees the
//!   back of m.
//!
//! Sampling (trilux's choice, documented; any exact pdf gives unbiased
//! estimates): GGX samples the distribution of *visible* normals exactly
//! (Heitz 2018), whose pdf is G1(wo, m)·max(0, wo·m)·D(m)/cosθ_o, the same
//! as Mitsuba's `sample_visible` default; Beckmann samples D(m)·cosθ_m
//! (its visible-normal sampler has no closed form, and Mitsuba's numerical
//! one is consistent only with the exact G1, not its rational one).

use std::f64::consts::PI;

use glam::{DVec2, DVec3};

use crate::params::Distribution;

/// An isotropic microfacet distribution with roughness α.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Microfacet {
    /// Normal distribution.
    pub distribution: Distribution,
    /// Roughness α (used as given; no remapping).
    pub alpha: f64,
}

impl Microfacet {
    /// The distribution of microfacet normals D(m) (per unit solid angle of
    /// m, normalised against cosθ_m).
    pub fn d(&self, m: DVec3) -> f64 {
        let a2 = self.alpha * self.alpha;
        let cos2 = m.z * m.z;
        let result = match self.distribution {
            Distribution::Beckmann => {
                (-(m.x * m.x + m.y * m.y) / (a2 * cos2)).exp() / (PI * a2 * cos2 * cos2)
            }
            Distribution::Ggx => {
                let t = (m.x * m.x + m.y * m.y) / a2 + cos2;
                1.0 / (PI * a2 * t * t)
            }
        };
        if result * m.z > 1e-20 && result.is_finite() {
            result
        } else {
            0.0
        }
    }

    /// Smith's one-direction masking G1(v, m).
    pub fn smith_g1(&self, v: DVec3, m: DVec3) -> f64 {
        if v.dot(m) * v.z <= 0.0 {
            return 0.0;
        }
        let xy_alpha_2 = self.alpha * self.alpha * (v.x * v.x + v.y * v.y);
        if xy_alpha_2 == 0.0 {
            return 1.0;
        }
        let tan_theta_alpha_2 = xy_alpha_2 / (v.z * v.z);
        match self.distribution {
            Distribution::Beckmann => {
                let a = 1.0 / tan_theta_alpha_2.sqrt();
                if a >= 1.6 {
                    1.0
                } else {
                    let a2 = a * a;
                    (3.535 * a + 2.181 * a2) / (1.0 + 2.276 * a + 2.577 * a2)
                }
            }
            Distribution::Ggx => 2.0 / (1.0 + (1.0 + tan_theta_alpha_2).sqrt()),
        }
    }

    /// Separable shadowing-masking G(wi, wo, m) = G1(wi, m)·G1(wo, m).
    pub fn g(&self, wi: DVec3, wo: DVec3, m: DVec3) -> f64 {
        self.smith_g1(wi, m) * self.smith_g1(wo, m)
    }

    /// Samples a microfacet normal for the viewer direction `wo` (local,
    /// wo.z > 0); see the module docs for the method.
    pub fn sample_normal(&self, wo: DVec3, u: DVec2) -> DVec3 {
        match self.distribution {
            Distribution::Ggx => sample_ggx_visible(wo, self.alpha, u),
            Distribution::Beckmann => {
                let tan2 = -self.alpha * self.alpha * (1.0 - u.x).max(f64::MIN_POSITIVE).ln();
                let cos = 1.0 / (1.0 + tan2).sqrt();
                let sin = (1.0 - cos * cos).max(0.0).sqrt();
                let phi = 2.0 * PI * u.y;
                DVec3::new(sin * phi.cos(), sin * phi.sin(), cos)
            }
        }
    }

    /// The density of [`Microfacet::sample_normal`] per unit solid angle of m.
    pub fn normal_pdf(&self, wo: DVec3, m: DVec3) -> f64 {
        match self.distribution {
            Distribution::Ggx => {
                if wo.z <= 0.0 {
                    return 0.0;
                }
                self.smith_g1(wo, m) * wo.dot(m).max(0.0) * self.d(m) / wo.z
            }
            Distribution::Beckmann => self.d(m) * m.z.max(0.0),
        }
    }
}

/// Heitz 2018, "Sampling the GGX Distribution of Visible Normals".
fn sample_ggx_visible(wo: DVec3, alpha: f64, u: DVec2) -> DVec3 {
    let vh = DVec3::new(alpha * wo.x, alpha * wo.y, wo.z).normalize();
    let lensq = vh.x * vh.x + vh.y * vh.y;
    let t1 = if lensq > 0.0 {
        DVec3::new(-vh.y, vh.x, 0.0) / lensq.sqrt()
    } else {
        DVec3::X
    };
    let t2 = vh.cross(t1);
    let r = u.x.sqrt();
    let phi = 2.0 * PI * u.y;
    let p1 = r * phi.cos();
    let mut p2 = r * phi.sin();
    let s = 0.5 * (1.0 + vh.z);
    p2 = (1.0 - s) * (1.0 - p1 * p1).max(0.0).sqrt() + s * p2;
    let nh = p1 * t1 + p2 * t2 + (1.0 - p1 * p1 - p2 * p2).max(0.0).sqrt() * vh;
    DVec3::new(alpha * nh.x, alpha * nh.y, nh.z.max(1e-12)).normalize()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// ∫ D(m) cosθ_m dω = 1, by a fine quadrature over θ (D is isotropic).
    #[test]
    fn distributions_are_normalised() {
        for distribution in [Distribution::Beckmann, Distribution::Ggx] {
            for alpha in [0.05, 0.2, 0.5, 1.0] {
                let mf = Microfacet {
                    distribution,
                    alpha,
                };
                // substitute t = tanθ... integrate in θ with many points.
                let n = 200_000;
                let mut sum = 0.0;
                for i in 0..n {
                    let th = (i as f64 + 0.5) / n as f64 * 0.5 * PI;
                    let m = DVec3::new(th.sin(), 0.0, th.cos());
                    sum += mf.d(m) * th.cos() * th.sin();
                }
                let integral = sum * 2.0 * PI * 0.5 * PI / n as f64;
                // GGX's tail beyond θ → 90° converges slowly; 1e-4 is the
                // quadrature's accuracy here.
                assert!(
                    (integral - 1.0).abs() < 2e-3,
                    "{distribution:?} {alpha}: {integral}"
                );
            }
        }
    }

    #[test]
    fn g1_limits() {
        let mf = Microfacet {
            distribution: Distribution::Beckmann,
            alpha: 0.3,
        };
        assert_eq!(mf.smith_g1(DVec3::Z, DVec3::Z), 1.0);
        let v = DVec3::new(0.99, 0.0, 0.141).normalize();
        let g = mf.smith_g1(v, DVec3::Z);
        assert!(g > 0.0 && g < 1.0);
        assert_eq!(mf.smith_g1(v, DVec3::new(-1.0, 0.0, 0.01).normalize()), 0.0);
    }
}
