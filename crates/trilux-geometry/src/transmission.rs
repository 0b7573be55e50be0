//! Surfaces that let part of the light through: visibility as a fraction,
//! not 0 or 1.
//!
//! A shape may carry a [`Transmittance`]: the fraction τ(cos θ) of the
//! light that crosses it straight on, undeviated, where θ is the angle
//! between the segment and the surface's normal. Two kinds exist:
//!
//! - a **thin dielectric slab** (Mitsuba 3's `thindielectric`, a pane of
//!   glass): one interface reflects the unpolarised Fresnel fraction
//!   r(cos θ, η) (Mitsuba's `fresnel`), and the light bouncing between the
//!   slab's two parallel faces sums to the geometric series
//!
//!   R = r + (1 − r)² r Σₖ r²ᵏ = r + (1 − r)² r / (1 − r²) = 2r / (1 + r),
//!   T = (1 − r)² Σₖ r²ᵏ = (1 − r)² / (1 − r²) = (1 − r) / (1 + r) = 1 − R,
//!
//!   so τ = T · `scale` (Mitsuba's `specular_transmittance`, grey);
//! - a **constant** fraction (Mitsuba's `mask`: 1 − opacity).
//!
//! The queries that multiply these fractions along segments and rays are
//! in the `through` module.

use serde::{Deserialize, Serialize};

/// The fraction of light a surface lets through, undeviated (module docs).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[non_exhaustive]
pub enum Transmittance {
    /// A thin dielectric slab of relative index of refraction `eta`
    /// (interior over exterior), its transmission scaled by `scale`.
    ThinSlab {
        /// η = int_ior / ext_ior (> 0).
        eta: f64,
        /// Mitsuba's `specular_transmittance` (grey, in [0, 1]).
        scale: f64,
    },
    /// A fixed fraction in [0, 1], whatever the angle.
    Constant(f64),
}

impl Transmittance {
    /// The fraction let through at |cos θ| = `cos` (in [0, 1]).
    pub fn at(&self, cos: f64) -> f64 {
        let t = match *self {
            Transmittance::ThinSlab { eta, scale } => (1.0 - slab_reflectance(cos, eta)) * scale,
            Transmittance::Constant(t) => t,
        };
        if t.is_nan() { 0.0 } else { t.clamp(0.0, 1.0) }
    }
}

/// Unpolarised Fresnel reflectance of one dielectric interface at
/// |cos θ_i| = `cos`, relative index `eta`, arriving from outside
/// (Mitsuba 3's `fresnel`: 1 under total internal reflection and at
/// grazing incidence, 0 for matched indices).
pub fn fresnel_dielectric(cos: f64, eta: f64) -> f64 {
    let ci = cos.abs().min(1.0);
    if eta == 1.0 {
        return 0.0;
    }
    if ci == 0.0 || eta.is_nan() || eta <= 0.0 {
        return 1.0;
    }
    let ct2 = 1.0 - (1.0 - ci * ci) / (eta * eta);
    if ct2 <= 0.0 {
        return 1.0;
    }
    let ct = ct2.sqrt();
    let a_s = (ci - eta * ct) / (ci + eta * ct);
    let a_p = (ct - eta * ci) / (ct + eta * ci);
    (0.5 * (a_s * a_s + a_p * a_p)).clamp(0.0, 1.0)
}

/// Reflectance of a thin slab with its inter-reflections, R = 2r / (1 + r)
/// (module docs), r the one interface's [`fresnel_dielectric`].
pub fn slab_reflectance(cos: f64, eta: f64) -> f64 {
    let r = fresnel_dielectric(cos, eta);
    2.0 * r / (1.0 + r)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::face::FaceElement;
    use crate::forest::ElementForest;
    use crate::geometry::{Geometry, Ray};
    use crate::ids::SurfaceId;
    use crate::shape::{Shape, ShapeKind};
    use crate::visibility::Visibility;
    use glam::DMat4;
    use glam::DVec3;
    use std::sync::Arc;

    /// Unit squares (2 × 2) at heights `zs`, normal +z.
    fn plates(zs: &[f64]) -> Geometry {
        let shapes: Vec<Shape> = zs
            .iter()
            .map(|&z| Shape {
                kind: ShapeKind::Rectangle,
                world_from_object: DMat4::from_translation(DVec3::new(0.0, 0.0, z)),
                flip_normals: false,
            })
            .collect();
        Geometry::build(&shapes).unwrap()
    }

    const GLASS: Transmittance = Transmittance::ThinSlab {
        eta: 1.5,
        scale: 1.0,
    };

    #[test]
    fn a_segment_multiplies_the_panes_it_crosses() {
        let mut g = plates(&[1.0, 2.0, 3.0]);
        g.set_transmission(&[Some(GLASS), Some(Transmittance::Constant(0.5)), None]);
        let o = DVec3::ZERO;
        let normal = GLASS.at(1.0);
        assert!((g.transmittance(o, DVec3::new(0.0, 0.0, 1.5)) - normal).abs() < 1e-15);
        assert!((g.transmittance(o, DVec3::new(0.0, 0.0, 2.5)) - 0.5 * normal).abs() < 1e-15);
        assert_eq!(g.transmittance(o, DVec3::new(0.0, 0.0, 3.5)), 0.0);
        // Oblique: the pane's fraction at the segment's angle.
        let q = DVec3::new(0.6, 0.0, 1.5);
        let cos = 1.5 / q.length();
        assert!((g.transmittance(o, q) - GLASS.at(cos)).abs() < 1e-12);
        // A ray goes on through both to the opaque plate.
        let ray = Ray {
            origin: o,
            dir: DVec3::Z,
        };
        let (hit, through) = g.intersect_through(&ray, f64::INFINITY).unwrap();
        assert!((hit.point.z - 3.0).abs() < 1e-12);
        assert!((through - 0.5 * normal).abs() < 1e-15);
        // Without transmitters, the occlusion query's 0 or 1.
        let opaque = plates(&[1.0]);
        assert_eq!(opaque.transmittance(o, DVec3::new(0.0, 0.0, 1.5)), 0.0);
        assert_eq!(opaque.transmittance(o, DVec3::new(0.0, 0.0, 0.5)), 1.0);
    }

    #[test]
    fn visibility_is_the_mean_fraction_let_through() {
        // Two plates facing each other with a mask letting a quarter
        // through between them, wider than both: every segment crosses it.
        let shapes = [
            Shape {
                kind: ShapeKind::Rectangle,
                world_from_object: DMat4::IDENTITY,
                flip_normals: false,
            },
            Shape {
                kind: ShapeKind::Rectangle,
                world_from_object: DMat4::from_translation(DVec3::new(0.0, 0.0, 0.5))
                    * DMat4::from_scale(DVec3::new(3.0, 3.0, 1.0)),
                flip_normals: false,
            },
            Shape {
                kind: ShapeKind::Rectangle,
                world_from_object: DMat4::from_translation(DVec3::Z),
                flip_normals: true,
            },
        ];
        let mut g = Geometry::build(&shapes).unwrap();
        g.set_transmission(&[None, Some(Transmittance::Constant(0.25)), None]);
        let forest = ElementForest::new(Arc::new(g));
        let (a, b) = (forest.root(SurfaceId(0)), forest.root(SurfaceId(2)));
        let vis = Visibility::new(&forest, None);
        let (fa, fb) = (FaceElement::front(a), FaceElement::front(b));
        assert!((vis.fraction(fa, fb, 64) - 0.25).abs() < 1e-15);
        assert!((vis.weighted(fa, fb, 64) - 0.25).abs() < 1e-12);
    }

    #[test]
    fn a_slab_sums_its_inter_reflections() {
        // Normal incidence on glass of η = 1.5: r = ((η−1)/(η+1))² = 0.04,
        // R = 2r/(1+r) = 0.0769..., T = 1 − R.
        let r: f64 = 0.04;
        assert!((fresnel_dielectric(1.0, 1.5) - r).abs() < 1e-15);
        let series: f64 = r + (1.0 - r).powi(2) * r * (0..50).map(|k| r.powi(2 * k)).sum::<f64>();
        assert!((slab_reflectance(1.0, 1.5) - series).abs() < 1e-15);
        let t = Transmittance::ThinSlab {
            eta: 1.5,
            scale: 1.0,
        };
        assert!((t.at(1.0) - (1.0 - r) * (1.0 - r) / (1.0 - r * r)).abs() < 1e-15);
        // Grazing: all reflected; matched indices: all through.
        assert_eq!(t.at(0.0), 0.0);
        let matched = Transmittance::ThinSlab {
            eta: 1.0,
            scale: 0.5,
        };
        assert_eq!(matched.at(0.3), 0.5);
    }
}
