//! One side of a material: the one-sided models of Mitsuba 3's subset
//! (`diffuse`, `roughconductor`, `plastic`/`roughplastic`, `blendbsdf`) in the local frame of their
//! front side. Every function here assumes `wo.z > 0` and returns zero when
//! `wi.z ≤ 0` (no transmission).

use std::f64::consts::FRAC_1_PI;

use glam::{DVec2, DVec3};
use trilux_color::Spectrum;

use crate::fresnel::fresnel_conductor;
use crate::microfacet::{Microfacet, microfacet_albedo, unit_albedo};
use crate::plastic::Plastic;

/// A rough conductor, ready to evaluate.
#[derive(Clone, Debug, PartialEq)]
pub struct Conductor<const N: usize> {
    /// The microfacet distribution.
    pub microfacet: Microfacet,
    /// Real part of the index per band; `None` with `k` for Fresnel = 1.
    pub eta_k: Option<(Spectrum<N>, Spectrum<N>)>,
    /// Multiplies the Fresnel term.
    pub specular_reflectance: Spectrum<N>,
}

impl<const N: usize> Conductor<N> {
    /// F(cosθ) × specular_reflectance per band.
    fn fresnel(&self, cos: f64) -> Spectrum<N> {
        match &self.eta_k {
            None => self.specular_reflectance,
            Some((eta, k)) => {
                let mut f = [0.0; N];
                for (b, fb) in f.iter_mut().enumerate() {
                    *fb = fresnel_conductor(cos, eta[b], k[b]);
                }
                Spectrum(f) * self.specular_reflectance
            }
        }
    }

    /// fr(wi, wo) = D·G·F / (4 cosθi cosθo) (Mitsuba's `roughconductor`).
    pub fn eval(&self, wi: DVec3, wo: DVec3) -> Spectrum<N> {
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return Spectrum::zero();
        }
        let h = (wi + wo).normalize();
        if !h.is_finite() {
            return Spectrum::zero();
        }
        let d = self.microfacet.d(h);
        if d == 0.0 {
            return Spectrum::zero();
        }
        let g = self.microfacet.g(wi, wo, h);
        let s = d * g / (4.0 * wi.z * wo.z);
        if !(s.is_finite() && s > 0.0) {
            return Spectrum::zero();
        }
        // wi·h = wo·h in exact arithmetic; their mean is symmetric in (wi, wo)
        // bit for bit, so reciprocity holds exactly even where F is steep
        // (k ≈ 0 near total internal reflection).
        self.fresnel(0.5 * (wi.dot(h) + wo.dot(h))) * s
    }

    /// Samples wi from the microfacet normal distribution (see
    /// [`crate::microfacet`]).
    pub fn sample(&self, wo: DVec3, u: DVec2) -> Option<DVec3> {
        let m = self.microfacet.sample_normal(wo, u);
        let wi = crate::frame::reflect(wo, m);
        (wi.z > 0.0 && wi.is_finite()).then_some(wi)
    }

    /// The density of [`Conductor::sample`] per unit solid angle of wi.
    pub fn pdf(&self, wo: DVec3, wi: DVec3) -> f64 {
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return 0.0;
        }
        let h = (wi + wo).normalize();
        let dot = wo.dot(h);
        if dot.is_nan() || dot <= 0.0 {
            return 0.0;
        }
        let p = self.microfacet.normal_pdf(wo, h) / (4.0 * dot);
        if p.is_finite() { p } else { 0.0 }
    }

    /// Directional albedo ∫ fr(wi, wo) cosθi dωi ([`microfacet_albedo`]).
    pub fn albedo(&self, wo: DVec3) -> Spectrum<N> {
        if self.eta_k.is_none() {
            // Fresnel 1: the specular reflectance times the lobe's own
            // albedo, shared by every conductor of this roughness.
            return self.specular_reflectance * unit_albedo(&self.microfacet, wo.z);
        }
        microfacet_albedo(&self.microfacet, wo, |c| self.fresnel(c))
    }
}

/// One side of a material.
#[derive(Clone, Debug, PartialEq)]
pub enum Lobe<const N: usize> {
    /// Lambertian: fr = ρ/π.
    Diffuse {
        /// Reflectance ρ.
        rho: Spectrum<N>,
    },
    /// Rough conductor.
    Conductor(Conductor<N>),
    /// Plastic (smooth or rough coat).
    Plastic(Plastic<N>),
    /// (1 − weight)·first + weight·second.
    Blend {
        /// Weight of `second`.
        weight: f64,
        /// First lobe.
        first: Box<Lobe<N>>,
        /// Second lobe.
        second: Box<Lobe<N>>,
    },
}

impl<const N: usize> Lobe<N> {
    /// fr(wi, wo), everything.
    pub fn eval(&self, wi: DVec3, wo: DVec3) -> Spectrum<N> {
        match self {
            Lobe::Diffuse { rho } => {
                if wi.z > 0.0 && wo.z > 0.0 {
                    *rho * FRAC_1_PI
                } else {
                    Spectrum::zero()
                }
            }
            Lobe::Conductor(c) => c.eval(wi, wo),
            Lobe::Plastic(p) => p.eval(wi, wo),
            Lobe::Blend {
                weight,
                first,
                second,
            } => first.eval(wi, wo) * (1.0 - weight) + second.eval(wi, wo) * *weight,
        }
    }

    /// fr without the Lambertian parts.
    pub fn eval_glossy(&self, wi: DVec3, wo: DVec3) -> Spectrum<N> {
        match self {
            Lobe::Diffuse { .. } => Spectrum::zero(),
            Lobe::Conductor(c) => c.eval(wi, wo),
            Lobe::Plastic(p) => p.eval_coat(wi, wo),
            Lobe::Blend {
                weight,
                first,
                second,
            } => first.eval_glossy(wi, wo) * (1.0 - weight) + second.eval_glossy(wi, wo) * *weight,
        }
    }

    /// ρ_d: the reflectance of the Lambertian parts (fr_d = ρ_d/π).
    pub fn diffuse_albedo(&self) -> Spectrum<N> {
        match self {
            Lobe::Diffuse { rho } => *rho,
            Lobe::Conductor(_) => Spectrum::zero(),
            Lobe::Plastic(p) => p.diffuse_albedo(),
            Lobe::Blend {
                weight,
                first,
                second,
            } => first.diffuse_albedo() * (1.0 - weight) + second.diffuse_albedo() * *weight,
        }
    }

    /// True when a non-Lambertian part carries a non-zero weight.
    pub fn has_glossy(&self) -> bool {
        match self {
            Lobe::Diffuse { .. } => false,
            Lobe::Conductor(c) => !c.specular_reflectance.is_black(),
            Lobe::Plastic(p) => p.coat.is_some() && !p.specular_reflectance.is_black(),
            Lobe::Blend {
                weight,
                first,
                second,
            } => (*weight < 1.0 && first.has_glossy()) || (*weight > 0.0 && second.has_glossy()),
        }
    }

    /// Sets the roughness α of every conductor part (a textured roughness
    /// at one point: `trilux_brdf::textured`).
    pub(crate) fn set_alpha(&mut self, alpha: f64) {
        match self {
            Lobe::Conductor(c) => c.microfacet.alpha = alpha,
            Lobe::Blend { first, second, .. } => {
                first.set_alpha(alpha);
                second.set_alpha(alpha);
            }
            Lobe::Diffuse { .. } | Lobe::Plastic(_) => {}
        }
    }

    /// The smallest roughness α of a conductor part with non-zero weight
    /// (`None` when there is none): the narrowest lobe this side has.
    pub fn min_alpha(&self) -> Option<f64> {
        match self {
            Lobe::Diffuse { .. } => None,
            Lobe::Conductor(c) => Some(c.microfacet.alpha),
            Lobe::Plastic(p) => p.coat.map(|m| m.alpha),
            Lobe::Blend {
                weight,
                first,
                second,
            } => {
                let a = (*weight < 1.0).then(|| first.min_alpha()).flatten();
                let b = (*weight > 0.0).then(|| second.min_alpha()).flatten();
                match (a, b) {
                    (Some(x), Some(y)) => Some(x.min(y)),
                    (x, y) => x.or(y),
                }
            }
        }
    }

    /// True when this side reflects nothing.
    pub fn is_black(&self) -> bool {
        match self {
            Lobe::Diffuse { rho } => rho.is_black(),
            Lobe::Conductor(c) => c.specular_reflectance.is_black(),
            Lobe::Plastic(p) => p.base.is_black() && p.specular_reflectance.is_black(),
            Lobe::Blend {
                weight,
                first,
                second,
            } => (*weight >= 1.0 || first.is_black()) && (*weight <= 0.0 || second.is_black()),
        }
    }

    /// The mirror reflection of a smooth coat for viewer `wo`: its
    /// direction and weight (the fraction of light it reflects), `None`
    /// when there is none.
    pub fn delta(&self, wo: DVec3) -> Option<(DVec3, Spectrum<N>)> {
        match self {
            Lobe::Diffuse { .. } | Lobe::Conductor(_) => None,
            Lobe::Plastic(p) => p.delta(wo),
            Lobe::Blend {
                weight,
                first,
                second,
            } => {
                let a = first.delta(wo).map(|(d, w)| (d, w * (1.0 - weight)));
                let b = second.delta(wo).map(|(d, w)| (d, w * *weight));
                match (a, b) {
                    (Some((d, x)), Some((_, y))) => Some((d, x + y)),
                    (x, y) => x.or(y),
                }
            }
        }
    }

    /// Samples wi (without pdf or weight; see [`Lobe::pdf`]).
    pub(crate) fn sample_dir(&self, wo: DVec3, u: DVec2) -> Option<DVec3> {
        match self {
            Lobe::Diffuse { .. } => {
                let wi = square_to_cosine_hemisphere(u);
                (wi.z > 0.0).then_some(wi)
            }
            Lobe::Conductor(c) => c.sample(wo, u),
            Lobe::Plastic(p) => p.sample(wo, u),
            Lobe::Blend {
                weight,
                first,
                second,
            } => {
                // Pick a component with probability equal to its blend weight
                // (as Mitsuba does), reusing u.x rescaled.
                let w = *weight;
                if u.x < 1.0 - w {
                    let ux = (u.x / (1.0 - w)).min(1.0 - f64::EPSILON);
                    first.sample_dir(wo, DVec2::new(ux, u.y))
                } else {
                    let ux = ((u.x - (1.0 - w)) / w).clamp(0.0, 1.0 - f64::EPSILON);
                    second.sample_dir(wo, DVec2::new(ux, u.y))
                }
            }
        }
    }

    /// The density of `Lobe::sample_dir` per unit solid angle of wi.
    pub fn pdf(&self, wo: DVec3, wi: DVec3) -> f64 {
        match self {
            Lobe::Diffuse { .. } => {
                if wi.z > 0.0 && wo.z > 0.0 {
                    wi.z * FRAC_1_PI
                } else {
                    0.0
                }
            }
            Lobe::Conductor(c) => c.pdf(wo, wi),
            Lobe::Plastic(p) => p.pdf(wo, wi),
            Lobe::Blend {
                weight,
                first,
                second,
            } => {
                let mut p = 0.0;
                if *weight < 1.0 {
                    p += (1.0 - weight) * first.pdf(wo, wi);
                }
                if *weight > 0.0 {
                    p += weight * second.pdf(wo, wi);
                }
                p
            }
        }
    }

    /// Directional albedo ∫ fr cosθi dωi.
    pub fn albedo(&self, wo: DVec3) -> Spectrum<N> {
        if wo.z <= 0.0 {
            return Spectrum::zero();
        }
        match self {
            Lobe::Diffuse { rho } => *rho,
            Lobe::Conductor(c) => c.albedo(wo),
            Lobe::Plastic(p) => p.albedo(wo),
            Lobe::Blend {
                weight,
                first,
                second,
            } => {
                let mut a = Spectrum::zero();
                if *weight < 1.0 {
                    a += first.albedo(wo) * (1.0 - weight);
                }
                if *weight > 0.0 {
                    a += second.albedo(wo) * *weight;
                }
                a
            }
        }
    }
}

pub use crate::frame::square_to_cosine_hemisphere;
