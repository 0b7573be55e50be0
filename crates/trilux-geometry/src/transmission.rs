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
//! - a **constant** fraction (Mitsuba's `mask`: 1 − opacity);
//! - a **cut-out** ([`Cutout`]): 1 − α(u, v), an opacity α read at each
//!   crossing's texture coordinates (Mitsuba's `mask` with a bitmap
//!   `opacity`, glTF's `alphaMode` `MASK`: leaves, fabric, railings).
//!
//! Mitsuba's `mask` passes a ray straight on with probability 1 − α(u, v)
//! (a null interaction) and otherwise interacts with its nested BSDF; the
//! expected light a segment carries across it is the fraction 1 − α at
//! the crossing point, which is what visibility takes.
//!
//! The queries that multiply these fractions along segments and rays are
//! in the `through` module.

use std::fmt;
use std::sync::Arc;

use glam::DVec2;
use serde::{Serialize, Serializer};

/// An opacity that varies over a surface: α(u, v) in [0, 1] at the
/// surface's texture coordinates ([`crate::Geometry::texcoord`]). The
/// scene layer implements it over its textures (this crate knows no
/// image).
pub trait OpacityMap: Send + Sync + fmt::Debug {
    /// α at texture coordinates `uv`, in [0, 1].
    fn opacity(&self, uv: DVec2) -> f64;
    /// The mean of α over the map (what stands for it where one value is
    /// needed), in [0, 1].
    fn mean(&self) -> f64;
    /// A hash of the map's content, stable across machines (it enters a
    /// solution's content hash).
    fn content_hash(&self) -> u64;
}

/// A cut-out's opacity map, shared (module docs).
#[derive(Clone, Debug)]
pub struct Cutout(pub Arc<dyn OpacityMap>);

impl Cutout {
    /// The fraction let through at texture coordinates `uv`, 1 − α(uv),
    /// in [0, 1] (a NaN reads as opaque).
    pub fn fraction(&self, uv: DVec2) -> f64 {
        let t = 1.0 - self.0.opacity(uv);
        if t.is_nan() { 0.0 } else { t.clamp(0.0, 1.0) }
    }
}

impl PartialEq for Cutout {
    fn eq(&self, other: &Self) -> bool {
        Arc::ptr_eq(&self.0, &other.0) || self.0.content_hash() == other.0.content_hash()
    }
}

/// A cut-out serialises as its content hash (what a scene's hash needs).
impl Serialize for Cutout {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        self.0.content_hash().serialize(s)
    }
}

/// The fraction of light a surface lets through, undeviated (module docs).
#[derive(Clone, Debug, PartialEq, Serialize)]
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
    /// 1 − α(u, v) at each crossing, whatever the angle.
    Cutout(Cutout),
}

impl Transmittance {
    /// The fraction let through at |cos θ| = `cos` (in [0, 1]); for a
    /// [`Cutout`], which varies over the surface, 1 − its mean opacity
    /// (the crossings take [`Transmittance::at_point`]).
    pub fn at(&self, cos: f64) -> f64 {
        let t = match self {
            Transmittance::ThinSlab { eta, scale } => (1.0 - slab_reflectance(cos, *eta)) * scale,
            Transmittance::Constant(t) => *t,
            Transmittance::Cutout(c) => 1.0 - c.0.mean(),
        };
        if t.is_nan() { 0.0 } else { t.clamp(0.0, 1.0) }
    }

    /// The fraction let through at a crossing at |cos θ| = `cos` and
    /// texture coordinates `uv()` (the origin when the surface has none,
    /// as Mitsuba reads them), which only a cut-out asks for.
    pub fn at_point(&self, cos: f64, uv: impl FnOnce() -> Option<DVec2>) -> f64 {
        match self {
            Transmittance::Cutout(c) => c.fraction(uv().unwrap_or(DVec2::ZERO)),
            other => other.at(cos),
        }
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
        // A ray goes on through the pane, and through the mask to the
        // opaque plate or stops on it (probability 1/2, weight 2: the
        // `through` module).
        let ray = Ray {
            origin: o,
            dir: DVec3::Z,
        };
        let (hit, through) = g.intersect_through(&ray, f64::INFINITY).unwrap();
        if (hit.point.z - 3.0).abs() < 1e-12 {
            assert!((through - normal).abs() < 1e-15);
        } else {
            assert!((hit.point.z - 2.0).abs() < 1e-12);
            assert!((through - 2.0 * normal).abs() < 1e-15);
        }
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

    /// α(u, v) = u (a ramp across the rectangle), or a checkerboard of
    /// `cells` × `cells` squares, opaque where ⌊cells·u⌋ + ⌊cells·v⌋ is
    /// even, or the constant `alpha`.
    #[derive(Debug)]
    enum Map {
        Ramp,
        Checker(f64),
        Constant(f64),
    }

    impl OpacityMap for Map {
        fn opacity(&self, uv: glam::DVec2) -> f64 {
            match *self {
                Map::Ramp => uv.x,
                Map::Checker(n) => {
                    let k = (n * uv.x).floor() + (n * uv.y).floor();
                    if k.rem_euclid(2.0) == 0.0 { 1.0 } else { 0.0 }
                }
                Map::Constant(a) => a,
            }
        }
        fn mean(&self) -> f64 {
            match *self {
                Map::Constant(a) => a,
                _ => 0.5,
            }
        }
        fn content_hash(&self) -> u64 {
            0
        }
    }

    fn cutout(map: Map) -> Transmittance {
        Transmittance::Cutout(Cutout(Arc::new(map)))
    }

    #[test]
    fn a_segment_takes_one_minus_the_opacity_where_it_crosses_a_cutout() {
        // A ramp α = u = x/2 + 1/2 at z = 1 (Mitsuba's rectangle uv), an
        // opaque plate at z = 3: a vertical segment at x lets 1 − α
        // through, a slanted one the value where it crosses z = 1.
        let mut g = plates(&[1.0, 3.0]);
        g.set_transmission(&[Some(cutout(Map::Ramp)), None]);
        for x in [-0.9, -0.5, 0.0, 0.3, 0.7] {
            let p = DVec3::new(x, 0.2, 0.0);
            let want = 1.0 - (x / 2.0 + 0.5);
            let t = g.transmittance(p, DVec3::new(x, 0.2, 2.0));
            assert!((t - want).abs() < 1e-12, "x {x}: {t} against {want}");
            // From (x, 0, 0) to (x + 0.4, 0, 2): crosses z = 1 at x + 0.2.
            let t = g.transmittance(p, DVec3::new(x + 0.4, 0.2, 2.0));
            let want = 1.0 - ((x + 0.2) / 2.0 + 0.5);
            assert!((t - want).abs() < 1e-12, "slanted x {x}");
        }
        // Without texture coordinates in the way: the plate behind blocks.
        assert_eq!(g.transmittance(DVec3::ZERO, DVec3::new(0.0, 0.0, 3.5)), 0.0);
    }

    #[test]
    fn a_binary_cutout_stops_a_ray_where_it_is_opaque_only() {
        // A 4 × 4 checkerboard at z = 1 over an opaque plate at z = 2:
        // rays through the centres of the 16 cells stop on the cut-out
        // (weight 1) in the 8 opaque cells and reach the plate (weight 1)
        // in the others; the segments' fractions are 0 and 1.
        let mut g = plates(&[1.0, 2.0]);
        g.set_transmission(&[Some(cutout(Map::Checker(4.0))), None]);
        let mut stopped = 0;
        for i in 0..4 {
            for j in 0..4 {
                let (u, v) = ((i as f64 + 0.5) / 4.0, (j as f64 + 0.5) / 4.0);
                let (x, y) = (2.0 * u - 1.0, 2.0 * v - 1.0);
                let ray = Ray {
                    origin: DVec3::new(x, y, 0.0),
                    dir: DVec3::Z,
                };
                let (hit, w) = g.intersect_through(&ray, f64::INFINITY).unwrap();
                assert_eq!(w, 1.0);
                let opaque = (i + j) % 2 == 0;
                let z = if opaque { 1.0 } else { 2.0 };
                assert!((hit.point.z - z).abs() < 1e-12, "cell {i} {j}");
                stopped += usize::from(opaque);
                let t = g.transmittance(ray.origin, DVec3::new(x, y, 1.5));
                assert_eq!(t, if opaque { 0.0 } else { 1.0 });
            }
        }
        assert_eq!(stopped, 8);
    }

    #[test]
    fn a_ray_stops_on_a_partial_cutout_with_probability_alpha_and_weight_one_over_alpha() {
        // α = 0.3 everywhere: of many rays, about 30 % stop on the cut-out,
        // each weighted 1/α, so the mean weight of those stopped is 1 in
        // expectation (Mitsuba's `mask` sampled); the others reach the
        // plate behind with weight 1. The choice is a hash of each ray:
        // 4096 rays, binomial deviation 0.007 on the fraction.
        let mut g = plates(&[1.0, 2.0]);
        g.set_transmission(&[Some(cutout(Map::Constant(0.3))), None]);
        let n = 4096;
        let (mut on_mask, mut weight) = (0, 0.0);
        for k in 0..n {
            let (u, v) = (
                ((k % 64) as f64 + 0.5) / 64.0,
                ((k / 64) as f64 + 0.5) / 64.0,
            );
            let ray = Ray {
                origin: DVec3::new(1.8 * u - 0.9, 1.8 * v - 0.9, 0.0),
                dir: DVec3::new(0.01, -0.02, 1.0),
            };
            let (hit, w) = g.intersect_through(&ray, f64::INFINITY).unwrap();
            if (hit.point.z - 1.0).abs() < 1e-9 {
                on_mask += 1;
                assert!((w - 1.0 / 0.3).abs() < 1e-12);
                weight += w;
            } else {
                assert_eq!(w, 1.0);
            }
        }
        let fraction = on_mask as f64 / n as f64;
        assert!((fraction - 0.3).abs() < 0.03, "{fraction}");
        assert!(
            (weight / n as f64 - 1.0).abs() < 0.1,
            "{}",
            weight / n as f64
        );
        // The mean stands for the map where one value is needed.
        assert!((cutout(Map::Constant(0.3)).at(0.5) - 0.7).abs() < 1e-15);
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
