//! Lights without area ([`PreparedLight`]: Mitsuba's `point`, `spot`,
//! `directional`, glTF's punctual lights) and their shot (docs/solver.md,
//! "Lights without area").
//!
//! A light is a source like a face: its flux Φ (4π I for a point, I ∫
//! falloff dω for a spot, E π R² over the scene's bounding sphere for a
//! directional light, as Mitsuba counts it) is residual until it is shot,
//! and it is shot once, first (it is the largest source). Its shot is a
//! point-to-element transfer into every leaf element of every face: the
//! flux ∫ E dA over the element's exposed part, E = I cos θ / r² (E cos θ
//! for a directional light) with a shadow ray per point, 16 stratified
//! points per leaf. The Lambertian share ρ_d goes into the two-point
//! radiance as for a pair link; the glossy share (the directional albedo
//! for the light's direction less ρ_d) joins it, its energy kept and its
//! direction lost (a smooth plastic's coat is carried the same way); the
//! rest is absorbed, and what misses every element escapes.

use glam::{DVec2, DVec3};
use rayon::prelude::*;
use thiserror::Error;
use trilux_brdf::Frame;
use trilux_color::{ColorParam, Spectrum};
use trilux_geometry::{Arrival, ElementId, FaceId, Geometry, Punctual};

use crate::solver::Solver;

/// Stratified points per leaf element and light (4 × 4).
const POINTS_PER_SIDE: u32 = 4;

/// A light without area, its intensity in the solve's bands.
#[derive(Clone, Debug, PartialEq)]
pub struct PreparedLight<const N: usize> {
    /// Where it is and how its intensity varies with direction.
    pub punctual: Punctual,
    /// Radiant intensity (W sr⁻¹; irradiance W m⁻² for a directional
    /// light) per band.
    pub intensity: Spectrum<N>,
}

/// A light whose intensity cannot be used in these bands.
#[derive(Debug, Error)]
#[error("light {index}: {problem}")]
pub struct LightError {
    /// Index of the light in the list given.
    pub index: usize,
    /// What is wrong.
    pub problem: String,
}

impl<const N: usize> PreparedLight<N> {
    /// Converts `intensity` to bands (as an emitter's radiance, Mitsuba's
    /// `texture_d65`); refuses one that is negative or not finite.
    pub fn new(
        index: usize,
        punctual: Punctual,
        intensity: &ColorParam,
    ) -> Result<Self, LightError> {
        let i = intensity.emission::<N>().map_err(|e| LightError {
            index,
            problem: e.to_string(),
        })?;
        if !(i.is_finite() && i.is_non_negative() && i.max_value() <= 1e30) {
            return Err(LightError {
                index,
                problem: "intensity must be finite, non-negative and at most 1e30 in every band"
                    .into(),
            });
        }
        Ok(PreparedLight {
            punctual,
            intensity: i,
        })
    }

    /// The light reaching `x` and the irradiance it brings to a plane
    /// facing it (I falloff / r², or E).
    pub fn at(&self, x: DVec3) -> Option<(Arrival, Spectrum<N>)> {
        let a = self.punctual.arrival(x)?;
        Some((a, self.intensity * a.factor))
    }

    /// The flux it sends into a scene whose bounding sphere has radius
    /// `scene_radius`.
    pub fn flux(&self, scene_radius: f64) -> Spectrum<N> {
        self.intensity * self.punctual.flux_factor(scene_radius)
    }
}

/// The radius of the bounding sphere of `geometry`'s box (Mitsuba's
/// `bbox().bounding_sphere()`), and how far a shadow ray towards a
/// directional light must reach to leave the scene.
pub fn scene_radius(geometry: &Geometry) -> f64 {
    let b = geometry.bounds();
    0.5 * (b.max - b.min).length()
}

/// The point a shadow ray from `x` towards the light of `a` ends at:
/// the light, or beyond the scene for a directional light.
pub fn shadow_end(geometry: &Geometry, x: DVec3, a: &Arrival) -> DVec3 {
    if a.distance.is_finite() {
        x + a.wi * a.distance
    } else {
        let b = geometry.bounds();
        let reach = (b.max - b.min).length() + (x - 0.5 * (b.max + b.min)).length() + 1.0;
        x + a.wi * reach
    }
}

/// What one leaf element of one face receives from a light.
struct Deposit<const N: usize> {
    face: FaceId,
    leaf: ElementId,
    /// ∫ E dA over the leaf's exposed part.
    arrived: Spectrum<N>,
    /// Unit direction towards the light from the leaf's centre.
    wi: DVec3,
}

impl<const N: usize> Solver<N> {
    /// Shoots light `k` (module docs); returns the number of elements it
    /// lit.
    pub(crate) fn shoot_light(&mut self, k: usize) -> usize {
        let phi = std::mem::take(&mut self.state.light_flux[k]);
        // Every watt a light shoots is emission.
        self.state.interreflection.book_shot(phi, Spectrum::zero());
        let light = self.setup.scene.lights()[k].clone();
        let faces: Vec<FaceId> = self.setup.faces.iter().map(|(f, _)| f).collect();
        let deposits: Vec<Deposit<N>> = faces
            .par_iter()
            .flat_map_iter(|&f| self.light_deposits(&light, f))
            .collect();
        let mut total = Spectrum::<N>::zero();
        let mut absorbed = Spectrum::<N>::zero();
        for d in &deposits {
            let reflected = self.receive_light(d);
            total += d.arrived;
            absorbed += d.arrived - reflected;
            self.state
                .interreflection
                .book_group(d.face, d.arrived, reflected, Spectrum::zero());
        }
        let escaped = phi - total;
        for b in 0..N {
            self.state.ledger.escaped[b] += escaped[b];
            self.state.ledger.absorbed[b] += absorbed[b];
        }
        let rel = escaped.min_value() / phi.max_value().max(1e-300);
        self.state.ledger.min_shot_escaped = self.state.ledger.min_shot_escaped.min(rel);
        deposits.len()
    }

    /// What light `light` brings to each leaf of face `f` (leaves it
    /// does not reach are left out).
    fn light_deposits(&self, light: &PreparedLight<N>, f: FaceId) -> Vec<Deposit<N>> {
        let forest = self.setup.forest();
        let geometry = forest.geometry();
        let sign = f.side().sign();
        let n = POINTS_PER_SIDE;
        let mut out = Vec::new();
        for leaf in forest.leaves(forest.root(f.surface())) {
            if self.setup.exposed_area[f.side()][leaf.index()] <= 0.0 {
                continue;
            }
            let mut arrived = Spectrum::<N>::zero();
            for s in 0..n * n {
                let u = DVec2::new(
                    (f64::from(s % n) + 0.5) / f64::from(n),
                    (f64::from(s / n) + 0.5) / f64::from(n),
                );
                let y = forest.sample_element(leaf, u);
                if y.pdf_area <= 0.0
                    || self
                        .setup
                        .burial
                        .as_ref()
                        .is_some_and(|m| m.is_buried(f, y.coord))
                {
                    continue;
                }
                let Some((a, e)) = light.at(y.point) else {
                    continue;
                };
                let cos = sign * y.normal.dot(a.wi);
                if cos <= 0.0 || geometry.occluded(y.point, shadow_end(geometry, y.point, &a)) {
                    continue;
                }
                arrived += e * (cos / y.pdf_area);
            }
            if arrived.max_value() > 0.0 {
                let centre = forest.element(leaf).centre;
                let wi = light
                    .punctual
                    .arrival(centre)
                    .map_or(sign * forest.element(leaf).normal, |a| a.wi);
                out.push(Deposit {
                    face: f,
                    leaf,
                    arrived: arrived * (1.0 / f64::from(n * n)),
                    wi,
                });
            }
        }
        out
    }

    /// Puts what deposit `d` reflects into its face's two-point radiance
    /// (the Lambertian share, and the glossy share as Lambertian light);
    /// returns the flux reflected.
    fn receive_light(&mut self, d: &Deposit<N>) -> Spectrum<N> {
        let face = &self.setup.faces[d.face];
        let (rho, g) = match &self.setup.textures {
            Some(t) => (
                t.rho(d.face, d.leaf).unwrap_or(face.rho_d),
                t.glossy(d.face, d.leaf),
            ),
            None => (face.rho_d, Spectrum::splat(1.0)),
        };
        let rho_d = (rho * self.light_shading_factor(d.leaf, d.wi)).min(Spectrum::splat(1.0));
        let glossy = if face.stored {
            let normal = self.setup.forest().element(d.leaf).normal * d.face.side().sign();
            let wi = Frame::from_normal(normal).to_local(d.wi);
            (self.setup.albedo[face.shape].albedo(wi) - face.rho_d).max(Spectrum::zero()) * g
        } else {
            Spectrum::zero()
        };
        let reflected = (d.arrived * (rho_d + glossy)).min(d.arrived);
        let side = d.face.side();
        let aj = self.setup.exposed_area[side][d.leaf.index()];
        if !reflected.is_black() && aj > 0.0 {
            let dl = reflected * (1.0 / (std::f64::consts::PI * aj));
            self.state.field.gathered[side][d.leaf.index()] += dl;
            self.state.face_flux[d.face] += reflected;
        }
        self.state.used[d.leaf.index()] = true;
        let min = (d.arrived - reflected).min_value() / d.arrived.max_value().max(1e-300);
        self.state.ledger.min_element_absorbed = self.state.ledger.min_element_absorbed.min(min);
        reflected
    }

    /// The shading-normal factor of a chart element for light from `wi`
    /// (docs/solver.md, "Shading normals of smooth meshes").
    fn light_shading_factor(&self, j: ElementId, wi: DVec3) -> f64 {
        let Some((s, g)) = self.setup.shading[j.index()] else {
            return 1.0;
        };
        let (ds, dg) = (s.dot(wi), g.dot(wi));
        if dg.abs() <= 1e-12 * g.length() || ds * dg <= 0.0 {
            return 1.0;
        }
        (ds / dg).clamp(0.25, 4.0)
    }
}
