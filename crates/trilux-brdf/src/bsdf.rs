//! A material ready to evaluate: [`Bsdf<N>`], its two sides and its sampling.
//!
//! Local frame: z is the front normal; `wi` points towards the light and `wo`
//! towards the viewer, both away from the surface. The side that reflects is
//! the viewer's: `wo.z > 0` uses the front lobe, `wo.z < 0` the back lobe (with
//! both directions mirrored through the surface, as Mitsuba's `twosided`
//! does). Light and viewer on opposite sides give zero (no transmission in
//! this subset). One-sided materials (everything but `twosided`) are black
//! seen from the back, as in Mitsuba.

use glam::{DVec2, DVec3};
use trilux_color::{ColorParam, Spectrum};
use trilux_frame::Side;

use crate::error::BrdfError;
use crate::lobe::{Conductor, Lobe};
use crate::microfacet::Microfacet;
use crate::params::{BsdfParams, PlasticParams};
use crate::plastic::Plastic;

/// A sampled light direction for a given viewer direction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BsdfSample<const N: usize> {
    /// The sampled direction towards the light (local frame).
    pub wi: DVec3,
    /// fr(wi, wo)·|cosθi| / pdf.
    pub weight: Spectrum<N>,
    /// Density of wi per unit solid angle.
    pub pdf: f64,
}

/// A material of the supported Mitsuba 3 subset, with `N` bands.
#[derive(Clone, Debug, PartialEq)]
pub struct Bsdf<const N: usize> {
    front: Option<Lobe<N>>,
    back: Option<Lobe<N>>,
}

fn color<const N: usize>(
    what: &'static str,
    c: &ColorParam,
    role: trilux_color::Role,
) -> Result<Spectrum<N>, BrdfError> {
    c.to_spectrum::<N>(role)
        .map_err(|source| BrdfError::Color { what, source })
}

fn lobe<const N: usize>(p: &BsdfParams) -> Result<Lobe<N>, BrdfError> {
    use trilux_color::Role;
    Ok(match p {
        BsdfParams::Diffuse { reflectance } => Lobe::Diffuse {
            rho: color("diffuse reflectance", reflectance, Role::Reflectance)?,
        },
        BsdfParams::RoughConductor(rc) => {
            if !(rc.alpha.is_finite() && rc.alpha > 0.0) {
                return Err(BrdfError::BadAlpha(rc.alpha));
            }
            let eta_k = match &rc.eta_k {
                None => None,
                Some((eta, k)) => Some((
                    color("roughconductor eta", eta, Role::Unbounded)?,
                    color("roughconductor k", k, Role::Unbounded)?,
                )),
            };
            Lobe::Conductor(Conductor {
                microfacet: Microfacet {
                    distribution: rc.distribution,
                    alpha: rc.alpha,
                },
                eta_k,
                specular_reflectance: color(
                    "roughconductor specular_reflectance",
                    &rc.specular_reflectance,
                    Role::Reflectance,
                )?,
            })
        }
        BsdfParams::Plastic(pp) => Lobe::Plastic(plastic(pp)?),
        BsdfParams::Blend {
            weight,
            first,
            second,
        } => {
            if !(weight.is_finite() && (0.0..=1.0).contains(weight)) {
                return Err(BrdfError::BadWeight(*weight));
            }
            Lobe::Blend {
                weight: *weight,
                first: Box::new(lobe(first)?),
                second: Box::new(lobe(second)?),
            }
        }
        BsdfParams::TwoSided { .. } => return Err(BrdfError::NestedTwoSided),
    })
}

/// The plastic side of `pp`, its parameters checked.
pub(crate) fn plastic<const N: usize>(pp: &PlasticParams) -> Result<Plastic<N>, BrdfError> {
    use trilux_color::Role;
    for ior in [pp.int_ior, pp.ext_ior] {
        if !(ior.is_finite() && ior > 0.0) {
            return Err(BrdfError::BadIor(ior));
        }
    }
    if pp.coat.is_some() && pp.int_ior == pp.ext_ior {
        return Err(BrdfError::BadIor(pp.int_ior));
    }
    let coat = match pp.coat {
        None => None,
        Some((distribution, alpha)) => {
            if !(alpha.is_finite() && alpha > 0.0) {
                return Err(BrdfError::BadAlpha(alpha));
            }
            Some(Microfacet {
                distribution,
                alpha,
            })
        }
    };
    let diffuse: Spectrum<N> = color(
        "plastic diffuse_reflectance",
        &pp.diffuse_reflectance,
        Role::Reflectance,
    )?;
    let specular: Spectrum<N> = color(
        "plastic specular_reflectance",
        &pp.specular_reflectance,
        Role::Reflectance,
    )?;
    let mean = |s: &Spectrum<N>| s.0.iter().sum::<f64>() / N as f64;
    Ok(Plastic::new(
        diffuse,
        specular,
        pp.int_ior / pp.ext_ior,
        pp.nonlinear,
        coat,
        (mean(&diffuse), mean(&specular)),
    ))
}

impl<const N: usize> Bsdf<N> {
    /// Builds the material from its parameters (colours converted for `N`
    /// bands by [`trilux_color::convert`]).
    pub fn new(params: &BsdfParams) -> Result<Self, BrdfError> {
        match params {
            BsdfParams::TwoSided { front, back } => {
                let f = lobe(front)?;
                let b = match back {
                    Some(b) => lobe(b)?,
                    None => f.clone(),
                };
                Ok(Bsdf {
                    front: Some(f),
                    back: Some(b),
                })
            }
            other => Ok(Bsdf {
                front: Some(lobe(other)?),
                back: None,
            }),
        }
    }

    /// The smallest roughness α of a conductor part of one side (`None`
    /// for a side without one, or a black back).
    pub fn min_alpha(&self, side: Side) -> Option<f64> {
        self.side(side).and_then(Lobe::min_alpha)
    }

    /// This material with roughness `alpha` for the conductor parts of the
    /// sides in `sides` (a textured roughness at one point; `alpha` must be
    /// finite and positive, as a `roughconductor`'s).
    pub fn with_alpha(&self, sides: &trilux_frame::Sided<bool>, alpha: f64) -> Self {
        let mut out = self.clone();
        for (on, lobe) in [(sides.front, &mut out.front), (sides.back, &mut out.back)] {
            if let (true, Some(l)) = (on, lobe.as_mut()) {
                l.set_alpha(alpha);
            }
        }
        out
    }

    fn side(&self, side: Side) -> Option<&Lobe<N>> {
        match side {
            Side::Front => self.front.as_ref(),
            Side::Back => self.back.as_ref(),
        }
    }

    /// The lobe that reflects for viewer `wo`, with the directions mirrored
    /// into its upper hemisphere; `None` for opposite sides or a black side.
    fn oriented(&self, wi: DVec3, wo: DVec3) -> Option<(&Lobe<N>, DVec3, DVec3)> {
        let flip = |v: DVec3| DVec3::new(v.x, v.y, -v.z);
        match Side::of_local(wo)? {
            Side::Front if wi.z > 0.0 => self.front.as_ref().map(|l| (l, wi, wo)),
            Side::Back if wi.z < 0.0 => self.back.as_ref().map(|l| (l, flip(wi), flip(wo))),
            _ => None,
        }
    }

    fn finite(s: Spectrum<N>) -> Spectrum<N> {
        if s.is_finite() { s } else { Spectrum::zero() }
    }

    /// fr(wi, wo), without the cosine.
    pub fn eval(&self, wi: DVec3, wo: DVec3) -> Spectrum<N> {
        match self.oriented(wi, wo) {
            Some((l, wi, wo)) => Self::finite(l.eval(wi, wo)),
            None => Spectrum::zero(),
        }
    }

    /// The non-Lambertian part of fr(wi, wo).
    pub fn eval_glossy(&self, wi: DVec3, wo: DVec3) -> Spectrum<N> {
        match self.oriented(wi, wo) {
            Some((l, wi, wo)) => Self::finite(l.eval_glossy(wi, wo)),
            None => Spectrum::zero(),
        }
    }

    /// fr less its Lambertian part ρ_d/π: what a gather must estimate
    /// beyond the solution's Lambertian radiance. It equals
    /// [`Bsdf::eval_glossy`] except for plastics, whose base term is not
    /// Lambertian (it may be negative there; see [`crate::plastic`]).
    pub fn eval_non_lambertian(&self, wi: DVec3, wo: DVec3) -> Spectrum<N> {
        match self.oriented(wi, wo) {
            Some((l, wi, wo)) => {
                Self::finite(l.eval(wi, wo) - l.diffuse_albedo() * std::f64::consts::FRAC_1_PI)
            }
            None => Spectrum::zero(),
        }
    }

    /// The mirror reflection of a smooth coat (`plastic`) for viewer `wo`
    /// (local frame): the direction towards the light and the fraction
    /// reflected, which [`Bsdf::eval`] and [`Bsdf::sample`] leave out (a
    /// delta lobe). `None` for materials without one.
    pub fn delta_reflection(&self, wo: DVec3) -> Option<(DVec3, Spectrum<N>)> {
        let side = Side::of_local(wo)?;
        let l = self.side(side)?;
        let sign = if side == Side::Front { 1.0 } else { -1.0 };
        let (wi, w) = l.delta(DVec3::new(wo.x, wo.y, wo.z * sign))?;
        Some((DVec3::new(wi.x, wi.y, wi.z * sign), w))
    }

    /// The Lambertian part's BRDF value fr_d = ρ_d/π on `side` (a constant).
    pub fn diffuse_reflectance(&self, side: Side) -> Spectrum<N> {
        self.diffuse_albedo(side) * std::f64::consts::FRAC_1_PI
    }

    /// The Lambertian part's reflectance ρ_d on `side` (fr_d = ρ_d/π).
    pub fn diffuse_albedo(&self, side: Side) -> Spectrum<N> {
        self.side(side)
            .map_or(Spectrum::zero(), Lobe::diffuse_albedo)
    }

    /// True when `side` has a non-Lambertian part.
    pub fn has_glossy(&self, side: Side) -> bool {
        self.side(side).is_some_and(Lobe::has_glossy)
    }

    /// True when `side` reflects nothing.
    pub fn is_black(&self, side: Side) -> bool {
        self.side(side).is_none_or(Lobe::is_black)
    }

    /// Samples a light direction wi for the viewer direction `wo` from
    /// (approximately) fr·cos; `u` uniform in [0, 1)². `None` when the
    /// sample carries nothing (back side of a one-sided material, a
    /// microfacet sample below the horizon).
    pub fn sample(&self, wo: DVec3, u: DVec2) -> Option<BsdfSample<N>> {
        let side = Side::of_local(wo)?;
        let l = self.side(side)?;
        let sign = if side == Side::Front { 1.0 } else { -1.0 };
        let wo_l = DVec3::new(wo.x, wo.y, wo.z * sign);
        let u = u.clamp(DVec2::ZERO, DVec2::splat(1.0 - f64::EPSILON));
        let wi_l = l.sample_dir(wo_l, u)?;
        let pdf = l.pdf(wo_l, wi_l);
        if !(pdf > 0.0 && pdf.is_finite()) {
            return None;
        }
        let f = l.eval(wi_l, wo_l);
        let weight = f * (wi_l.z / pdf);
        if !weight.is_finite() {
            return None;
        }
        Some(BsdfSample {
            wi: DVec3::new(wi_l.x, wi_l.y, wi_l.z * sign),
            weight,
            pdf,
        })
    }

    /// The density of [`Bsdf::sample`] producing `wi` for viewer `wo`, per
    /// unit solid angle.
    pub fn pdf(&self, wo: DVec3, wi: DVec3) -> f64 {
        match self.oriented(wi, wo) {
            Some((l, wi, wo)) => {
                let p = l.pdf(wo, wi);
                if p.is_finite() { p } else { 0.0 }
            }
            None => 0.0,
        }
    }

    /// Directional albedo ∫ fr(wi, wo) |cosθi| dωi for viewer `wo`: the
    /// fraction of light arriving from all directions (or, by reciprocity,
    /// leaving towards all directions) that is reflected, a smooth coat's
    /// mirror included. ≤ 1 per band.
    pub fn albedo(&self, wo: DVec3) -> Spectrum<N> {
        let Some(side) = Side::of_local(wo) else {
            return Spectrum::zero();
        };
        match self.side(side) {
            Some(l) => Self::finite(l.albedo(DVec3::new(wo.x, wo.y, wo.z.abs()))),
            None => Spectrum::zero(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::{Distribution, RoughConductorParams};

    fn diffuse(v: f64) -> BsdfParams {
        BsdfParams::Diffuse {
            reflectance: ColorParam::Float(v),
        }
    }

    #[test]
    fn sides() {
        let one: Bsdf<3> = Bsdf::new(&diffuse(0.5)).unwrap();
        let up = DVec3::new(0.0, 0.6, 0.8);
        let down = DVec3::new(0.0, 0.6, -0.8);
        assert!((one.eval(up, DVec3::Z).0[0] - 0.5 / std::f64::consts::PI).abs() < 1e-15);
        assert!(one.eval(down, -DVec3::Z).is_black());
        assert!(one.eval(up, -DVec3::Z).is_black());
        assert!(one.is_black(Side::Back) && !one.is_black(Side::Front));
        let two: Bsdf<3> = Bsdf::new(&BsdfParams::TwoSided {
            front: Box::new(diffuse(0.5)),
            back: Some(Box::new(diffuse(0.25))),
        })
        .unwrap();
        assert!((two.eval(down, -DVec3::Z).0[0] - 0.25 / std::f64::consts::PI).abs() < 1e-15);
        assert!(two.eval(up, -DVec3::Z).is_black());
        assert_eq!(two.diffuse_albedo(Side::Back).0, [0.25; 3]);
    }

    #[test]
    fn bad_parameters_are_errors() {
        let bad = BsdfParams::RoughConductor(RoughConductorParams {
            distribution: Distribution::Ggx,
            alpha: f64::NAN,
            eta_k: None,
            specular_reflectance: ColorParam::Float(1.0),
        });
        assert!(Bsdf::<3>::new(&bad).is_err());
        let nested = BsdfParams::TwoSided {
            front: Box::new(BsdfParams::TwoSided {
                front: Box::new(diffuse(0.5)),
                back: None,
            }),
            back: None,
        };
        assert_eq!(Bsdf::<3>::new(&nested), Err(BrdfError::NestedTwoSided));
        let w = BsdfParams::Blend {
            weight: 1.5,
            first: Box::new(diffuse(0.5)),
            second: Box::new(diffuse(0.5)),
        };
        assert!(Bsdf::<{ trilux_color::SPECTRAL_BANDS }>::new(&w).is_err());
        assert!(Bsdf::<3>::new(&diffuse(-0.5)).is_err());
    }
}
