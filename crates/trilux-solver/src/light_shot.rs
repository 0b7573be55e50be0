//! The shot of a light without area (docs/solver.md, "Lights without
//! area"): a source like a face, shot once, first (it is the largest). A
//! point-to-element transfer into every leaf element of every face: the
//! flux ∫ E dA over the element's exposed part, E = I cos θ / r² (E cos θ
//! for a directional light) with a shadow ray per point, 16 stratified
//! points per leaf. The Lambertian share ρ_d goes into the two-point
//! radiance as for a pair link; the glossy share (the directional albedo
//! for the light's direction less ρ_d) joins it, its energy kept and its
//! direction lost (a smooth plastic's coat is carried the same way); the
//! rest is absorbed, and what misses every element escapes. The sky
//! (an environment map) is shot the same way, its deposits `sky_shot`'s.

use glam::{DVec2, DVec3};
use rayon::prelude::*;
use trilux_brdf::Frame;
use trilux_color::Spectrum;
use trilux_geometry::{ElementId, FaceId, SurfaceSample};

use crate::lights::PreparedLight;
use crate::solver::{Solver, Source};

/// Stratified points per leaf element and light (4 × 4).
pub(crate) const POINTS_PER_SIDE: u32 = 4;

/// What one leaf element of one face receives from a light.
pub(crate) struct Deposit<const N: usize> {
    pub face: FaceId,
    pub leaf: ElementId,
    /// ∫ E dA over the leaf's exposed part.
    pub arrived: Spectrum<N>,
    /// Unit direction towards the light from the leaf's centre (the
    /// sky's: the mean direction its light arrives from).
    pub wi: DVec3,
}

impl<const N: usize> Solver<N> {
    /// Shoots light `k` (module docs); returns the number of elements it
    /// lit.
    pub(crate) fn shoot_light(&mut self, k: usize) -> usize {
        let phi = std::mem::take(&mut self.state.light_flux[k]);
        self.state.queue.touch(Source::Light(k as u32));
        // Every watt a light shoots is emission.
        self.state.interreflection.book_shot(phi, Spectrum::zero());
        let faces: Vec<FaceId> = self.setup.faces.iter().map(|(f, _)| f).collect();
        // Light k past the lights without area is the sky (`sky_shot`).
        let deposits: Vec<Deposit<N>> = match self.setup.scene.lights().get(k) {
            Some(light) => faces
                .par_iter()
                .flat_map_iter(|&f| self.light_deposits(light, f))
                .collect(),
            None => faces
                .par_iter()
                .flat_map_iter(|&f| self.sky_deposits(f))
                .collect(),
        };
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
        self.state.ledger.book_shot(phi, total, absorbed);
        deposits.len()
    }

    /// The leaves of face `f` with an exposed part (the others receive
    /// nothing).
    pub(crate) fn lit_leaves(&self, f: FaceId) -> impl Iterator<Item = ElementId> + '_ {
        let forest = self.setup.forest();
        forest
            .leaves(forest.root(f.surface()))
            .into_iter()
            .filter(move |leaf| self.setup.exposed_area[f.side()][leaf.index()] > 0.0)
    }

    /// The points a light shot samples on `leaf` of face `f`: the centres
    /// of a [`POINTS_PER_SIDE`]² grid over its parameter square, with their
    /// index, less those buried in another surface or of zero density.
    pub(crate) fn leaf_points(
        &self,
        f: FaceId,
        leaf: ElementId,
    ) -> impl Iterator<Item = (u32, SurfaceSample)> + '_ {
        let n = POINTS_PER_SIDE;
        let forest = self.setup.forest();
        (0..n * n).filter_map(move |s| {
            let u = DVec2::new(
                (f64::from(s % n) + 0.5) / f64::from(n),
                (f64::from(s / n) + 0.5) / f64::from(n),
            );
            let y = forest.sample_element(leaf, u);
            let buried = self
                .setup
                .burial
                .as_ref()
                .is_some_and(|m| m.is_buried(f, y.coord));
            (y.pdf_area > 0.0 && !buried).then_some((s, y))
        })
    }

    /// What light `light` brings to each leaf of face `f` (leaves it
    /// does not reach are left out).
    fn light_deposits(&self, light: &PreparedLight<N>, f: FaceId) -> Vec<Deposit<N>> {
        let forest = self.setup.forest();
        let geometry = forest.geometry();
        let sign = f.side().sign();
        let n = POINTS_PER_SIDE;
        let mut out = Vec::new();
        for leaf in self.lit_leaves(f) {
            let mut arrived = Spectrum::<N>::zero();
            for (_, y) in self.leaf_points(f, leaf) {
                let Some((a, e)) = light.at(y.point) else {
                    continue;
                };
                let cos = sign * y.normal.dot(a.wi);
                let end = self.setup.scene.shadow_end(y.point, &a);
                // The fraction the segment lets through (panes of glass:
                // trilux_geometry::transmission), 0 when blocked.
                let tau = match end {
                    Some(end) if cos > 0.0 => geometry.transmittance(y.point, end),
                    _ => 0.0,
                };
                if tau <= 0.0 {
                    continue;
                }
                arrived += e * (tau * cos / y.pdf_area);
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
            self.state.queue.touch(Source::Radiosity(d.face));
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
