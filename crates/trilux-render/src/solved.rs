//! The final gather wired to trilux's own layers: [`SolvedScene`]
//! implements [`GatherScene`] and [`SolutionGather`] with a prepared scene (geometry, materials,
//! emitters: `trilux_solver::PreparedScene`) and a solution
//! ([`RadianceSolution`]: the solver's, or a stand-in).
//!
//! - Rays: `Geometry::intersect_through` (exact for analytic shapes, its
//!   own self-intersection epsilon; straight through surfaces that let
//!   light through, the fraction they let through kept in the hit's
//!   [`HitLocator::through`]), shadow rays `Geometry::transmittance`.
//! - Materials: `Bsdf<N>` in the shading frame of the hit (z = shading
//!   normal on the front side, turned by the material's normal or bump
//!   map if it has one: `PreparedScene::normal_map`), textured ones at the hit's texture
//!   coordinates (`PreparedScene::shading`); it reflects on the viewer's side (black from
//!   the back unless `twosided`), as in Mitsuba.
//! - Emitters: one-sided Lambertian area emitters on the front side. Light
//!   sampling picks an emitting input surface with probability ∝ its area ×
//!   the luminance of its radiance, then a point uniformly by area
//!   (`ElementForest::sample_surface`; the MIS weight at a gather hit on an
//!   emitter uses the same density, 1/area × pick probability).
//! - Solution lookup: the face a light path leaves from and the face it
//!   arrives on are passed with the points (the solver keeps both faces of
//!   two-sided surfaces apart).
//! - Extra-bounce rule inputs: the element size is √area of the deepest
//!   element of the geometry tree (after the solve's subdivisions) that
//!   contains the hit; the lobe solid angle of a roughconductor part with
//!   roughness α is taken as 4πα² (its lobe in ω_i is about 2α wide), 2π for
//!   a diffuse-only side.

use std::sync::Arc;

use glam::{DVec2, DVec3};
use trilux_brdf::{Bsdf, Frame, Shading, TangentFrame};
use trilux_color::Spectrum;
use trilux_geometry::{
    ElementDomain, ElementForest, ElementId, FaceElement, FaceId, Geometry, Hit, Piece, Ray, Side,
    SurfaceCoord, SurfaceId,
};
use trilux_solver::{PreparedScene, SurfaceSite};

use crate::link_sum::{LinkCache, LinkField, Receiver, link_sum};
use crate::records::{
    BsdfSample, FitKey, FitSite, GatherStats, LightSample, LinkVisibility, PunctualSample, SkyRay,
    SurfacePoint,
};
use crate::scene::{GatherScene, SolutionGather};
use crate::solution::RadianceSolution;

/// Where a ray met the scene, as [`SolvedScene`] needs it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HitLocator {
    /// The input surface.
    pub surface: SurfaceId,
    /// The point in its coordinates.
    pub coord: SurfaceCoord,
    /// Unit shading normal, front side.
    pub shading_normal: DVec3,
    /// Index of the scene shape.
    pub shape: u32,
    /// The fraction of light the surfaces the ray went through before
    /// this hit let through (panes of glass; 1 without them).
    pub through: f64,
}

/// The lobe solid angle of one side of a material: 4πα² for a
/// roughconductor part of roughness α (its lobe in ω_i is about 2α wide),
/// 2π for a diffuse-only side.
fn lobe_sr<const N: usize>(bsdf: &Bsdf<N>, side: Side) -> f64 {
    match bsdf.min_alpha(side) {
        Some(a) => (4.0 * std::f64::consts::PI * a * a).min(2.0 * std::f64::consts::PI),
        None => 2.0 * std::f64::consts::PI,
    }
}

/// A scene and its solution, ready for the final gather.
pub struct SolvedScene<'a, const N: usize, S> {
    scene: &'a PreparedScene<N>,
    solution: &'a S,
    /// Lobe solid angle per shape and side [front, back].
    lobe_sr: Vec<[f64; 2]>,
    /// Emitting input surfaces with their cumulative pick probabilities.
    emitters: Vec<(SurfaceId, f64)>,
    /// Pick probability / area, by surface index (0 when not emitting).
    light_density: Vec<f64>,
    /// The link sums' point form factors and leaf links.
    links: LinkField<N>,
    /// Some material has a glossy part on some side.
    glossy_faces: bool,
}

impl<'a, const N: usize, S: RadianceSolution<N>> SolvedScene<'a, N, S> {
    /// The gather over the scene of `solution`, with its light.
    pub fn new(solution: &'a S) -> Self {
        let scene = solution.scene();
        let lobe_sr = scene
            .materials()
            .iter()
            .map(|b| [lobe_sr(b, Side::Front), lobe_sr(b, Side::Back)])
            .collect();
        let surfaces = scene.geometry().surfaces();
        let mut weights = Vec::new();
        for (k, surf) in surfaces.iter().enumerate() {
            let le = scene.emission()[surf.shape as usize];
            if le.is_black() {
                continue;
            }
            let w = surf.area() * le.luminance().max(le.max_value() * 1e-3);
            if w > 0.0 && w.is_finite() {
                weights.push((SurfaceId(k as u32), w));
            }
        }
        let total: f64 = weights.iter().map(|(_, w)| w).sum();
        let mut light_density = vec![0.0; surfaces.len()];
        let mut emitters = Vec::with_capacity(weights.len());
        let mut acc = 0.0;
        for (id, w) in weights {
            let p = w / total;
            acc += p;
            emitters.push((id, acc));
            light_density[id.index()] = p / surfaces[id.index()].area();
        }
        if let Some(last) = emitters.last_mut() {
            last.1 = 1.0;
        }
        let links = if solution.has_links() {
            let forest = solution.forest();
            let ff = trilux_geometry::PointFormFactors::new(forest);
            LinkField::new(ff, forest.element_count())
        } else {
            let forest = ElementForest::new(Arc::clone(scene.geometry()));
            LinkField::new(trilux_geometry::PointFormFactors::new(&forest), 0)
        };
        let glossy_faces = scene
            .materials()
            .iter()
            .any(|b| Side::BOTH.iter().any(|&s| b.has_glossy(s)));
        Self {
            scene,
            solution,
            lobe_sr,
            emitters,
            light_density,
            links,
            glossy_faces,
        }
    }

    fn geom(&self) -> &Geometry {
        self.scene.geometry()
    }

    /// The material at the hit (a textured one evaluated at the hit's
    /// texture coordinates).
    fn bsdf(&self, at: &SurfacePoint<HitLocator>) -> Shading<'_, N> {
        let l = &at.locator;
        self.scene.shading(l.shape as usize, l.surface, l.coord)
    }

    /// The shading normal at `hit` on `shape`: the geometry's, turned by
    /// the material's normal or bump map where it has one
    /// (`trilux_brdf::normal_map`), as seen along the ray's direction
    /// `dir`. The solution was computed with the geometric normal; the
    /// render reads it with this one.
    fn shading_normal(&self, hit: &Hit, shape: u32, dir: DVec3) -> DVec3 {
        let geom = self.geom();
        // The texture coordinates only where a map needs them: most
        // shapes have none, and this runs for every camera and gather hit.
        let Some(map) = self.scene.normal_map(shape as usize) else {
            return hit.shading_normal;
        };
        let Some(uv) = geom.texcoord(hit.surface, hit.coord) else {
            return hit.shading_normal;
        };
        let at = TangentFrame {
            n: hit.shading_normal,
            ng: hit.geometric_normal,
            dp_duv: geom.uv_partials(hit.surface, hit.coord),
        };
        match (-dir).try_normalize() {
            Some(wo) => map.perturb(&at, uv, wo),
            None => hit.shading_normal,
        }
    }

    fn site(p: &SurfacePoint<HitLocator>, side: Side) -> SurfaceSite {
        SurfaceSite {
            face: FaceId::new(p.locator.surface, side),
            coord: p.locator.coord,
        }
    }

    /// The sites of a transfer from `from` to `towards`: each point on the
    /// side of its surface that faces the other.
    fn sites(
        from: &SurfacePoint<HitLocator>,
        towards: &SurfacePoint<HitLocator>,
    ) -> (SurfaceSite, SurfaceSite) {
        let d = towards.point - from.point;
        let from_side = Side::from_back(from.normal.dot(d) < 0.0);
        let to_side = Side::from_back(towards.normal.dot(-d) < 0.0);
        (Self::site(from, from_side), Self::site(towards, to_side))
    }

    /// The lights without area's part of the link sum at `at` seen from
    /// `side`: Σ E⊥ cos θ / π V (cos about the shading normal, as the
    /// Lambertian BSDF takes it), one shadow ray per light; they have no
    /// gather links.
    fn punctual_irradiance(
        &self,
        at: &SurfacePoint<HitLocator>,
        side: Side,
        stats: &mut GatherStats,
    ) -> Spectrum<N> {
        let sign = side.sign();
        let lambert = |wi: DVec3| {
            let cos = sign * at.locator.shading_normal.dot(wi);
            if cos <= 0.0 || sign * at.normal.dot(wi) <= 0.0 {
                Spectrum::zero()
            } else {
                Spectrum::splat(cos / std::f64::consts::PI)
            }
        };
        crate::mis::punctual_direct(self, at, lambert, stats)
    }

    /// The link sum at `at`, seen from `side`, in the leaf `leaf`.
    fn link_sum_at(
        &self,
        at: &SurfacePoint<HitLocator>,
        side: Side,
        leaf: ElementId,
        visibility: LinkVisibility<'_>,
        cache: &mut LinkCache<N>,
        stats: &mut GatherStats,
    ) -> Spectrum<N> {
        let receiver = Receiver {
            x: at.point,
            n: at.locator.shading_normal * side.sign(),
            coord: at.locator.coord,
            leaf: FaceElement::new(leaf, side),
        };
        link_sum(
            self.solution,
            &self.links,
            &receiver,
            visibility,
            cache,
            stats,
        )
    }
}

impl<const N: usize, S: RadianceSolution<N>> GatherScene<N> for SolvedScene<'_, N, S> {
    type Locator = HitLocator;

    fn intersect(&self, origin: DVec3, dir: DVec3) -> Option<SurfacePoint<HitLocator>> {
        let geom = self.geom();
        let (hit, through) = geom.intersect_through(&Ray { origin, dir }, f64::INFINITY)?;
        let shape = geom.surface(hit.surface).shape;
        Some(SurfacePoint {
            point: hit.point,
            normal: hit.geometric_normal,
            t: hit.t * dir.length(),
            locator: HitLocator {
                surface: hit.surface,
                coord: hit.coord,
                shading_normal: self.shading_normal(&hit, shape, dir),
                shape,
                through,
            },
        })
    }

    fn punctual_count(&self) -> usize {
        self.scene.lights().len()
    }

    fn punctual_at(
        &self,
        k: usize,
        reference: &SurfacePoint<HitLocator>,
    ) -> Option<PunctualSample<N>> {
        let (a, irradiance) = self.scene.lights().get(k)?.at(reference.point)?;
        Some(PunctualSample {
            wi: a.wi,
            end: self.scene.shadow_end(reference.point, &a)?,
            irradiance,
        })
    }

    fn sky(&self, from: DVec3, wi: DVec3) -> (Spectrum<N>, f64) {
        let Some(s) = self.scene.sky() else {
            return (Spectrum::zero(), 0.0);
        };
        let l = s.radiance(wi);
        // The ray met nothing opaque; the panes it crossed (if the scene
        // has any) take their share, walked again from `from`.
        let geom = self.geom();
        let tau = if geom.has_transmission() && !l.is_black() {
            geom.transmittance(from, self.scene.sky_end(from, wi))
        } else {
            1.0
        };
        (l * tau, s.pdf(wi))
    }

    fn sample_sky(&self, reference: &SurfacePoint<HitLocator>, u: DVec2) -> Option<SkyRay<N>> {
        let s = self.scene.sky()?.sample(u)?;
        Some(SkyRay {
            wi: s.wi,
            end: self.scene.sky_end(reference.point, s.wi),
            radiance: s.radiance,
            pdf: s.pdf,
        })
    }

    fn unoccluded(&self, from: &SurfacePoint<HitLocator>, to: DVec3) -> bool {
        !self.geom().occluded(from.point, to)
    }

    fn transmittance(&self, from: &SurfacePoint<HitLocator>, to: DVec3) -> f64 {
        self.geom().transmittance(from.point, to)
    }

    fn through(&self, at: &SurfacePoint<HitLocator>) -> f64 {
        at.locator.through
    }

    fn emitted(&self, at: &SurfacePoint<HitLocator>, wo: DVec3) -> Spectrum<N> {
        if at.normal.dot(wo) > 0.0 {
            self.scene.emission()[at.locator.shape as usize]
        } else {
            Spectrum::zero()
        }
    }

    fn sample_light(
        &self,
        reference: &SurfacePoint<HitLocator>,
        pick: f64,
        u: DVec2,
    ) -> Option<LightSample<N>> {
        if self.emitters.is_empty() {
            return None;
        }
        let k = self
            .emitters
            .partition_point(|&(_, c)| c <= pick)
            .min(self.emitters.len() - 1);
        let surface = self.emitters[k].0;
        let s = self.solution.forest().sample_surface(surface, u);
        let shape = self.geom().surface(surface).shape as usize;
        let le = self.scene.emission()[shape];
        let front = s.normal.dot(reference.point - s.point) > 0.0;
        Some(LightSample {
            point: s.point,
            normal: s.normal,
            radiance: if front { le } else { Spectrum::zero() },
            pdf_area: self.light_density[surface.index()],
        })
    }

    fn light_pdf_area(&self, at: &SurfacePoint<HitLocator>) -> f64 {
        self.light_density[at.locator.surface.index()]
    }

    fn bsdf_cos(&self, at: &SurfacePoint<HitLocator>, wi: DVec3, wo: DVec3) -> Spectrum<N> {
        let frame = Frame::from_normal(at.locator.shading_normal);
        let (wi, wo) = (frame.to_local(wi), frame.to_local(wo));
        self.bsdf(at).eval(wi, wo) * wi.z.abs()
    }

    fn sample_bsdf(
        &self,
        at: &SurfacePoint<HitLocator>,
        wo: DVec3,
        u: DVec2,
    ) -> Option<BsdfSample<N>> {
        let frame = Frame::from_normal(at.locator.shading_normal);
        let s = self.bsdf(at).sample(frame.to_local(wo), u)?;
        let wi = frame.to_world(s.wi);
        // A direction on the other side of the true surface than the
        // viewer would pass through it (possible with shading normals).
        if wi.dot(at.normal) * wo.dot(at.normal) <= 0.0 {
            return None;
        }
        Some(BsdfSample {
            wi,
            weight: s.weight,
            pdf: s.pdf,
        })
    }

    fn bsdf_pdf(&self, at: &SurfacePoint<HitLocator>, wo: DVec3, wi: DVec3) -> f64 {
        let frame = Frame::from_normal(at.locator.shading_normal);
        self.bsdf(at).pdf(frame.to_local(wo), frame.to_local(wi))
    }

    fn reflected(
        &self,
        from: &SurfacePoint<HitLocator>,
        towards: &SurfacePoint<HitLocator>,
    ) -> Spectrum<N> {
        let (from, towards) = Self::sites(from, towards);
        self.solution.reflected(&from, &towards)
    }

    fn lobe_solid_angle(&self, at: &SurfacePoint<HitLocator>, wo: DVec3) -> f64 {
        let back = usize::from(at.normal.dot(wo) < 0.0);
        self.lobe_sr[at.locator.shape as usize][back]
    }
}

impl<const N: usize, S: RadianceSolution<N>> SolutionGather<N> for SolvedScene<'_, N, S> {
    fn element_size(&self, at: &SurfacePoint<HitLocator>) -> f64 {
        let forest = self.solution.forest();
        let e = forest.locate(at.locator.surface, at.locator.coord);
        forest.element(e).area.sqrt()
    }

    fn shading_differs(&self, at: &SurfacePoint<HitLocator>) -> bool {
        // More than about 1° apart.
        at.locator.shading_normal.dot(at.normal).abs() < 0.9998
    }

    fn diffuse_albedo(&self, at: &SurfacePoint<HitLocator>, wo: DVec3) -> Spectrum<N> {
        self.bsdf(at).diffuse_albedo(viewer_side(at, wo))
    }

    fn solution_irradiance(
        &self,
        at: &SurfacePoint<HitLocator>,
        wo: DVec3,
        visibility: LinkVisibility<'_>,
        cache: &mut LinkCache<N>,
        stats: &mut GatherStats,
    ) -> Option<Spectrum<N>> {
        if !self.solution.has_links() {
            return None;
        }
        let side = viewer_side(at, wo);
        let leaf = self
            .solution
            .forest()
            .locate(at.locator.surface, at.locator.coord);
        let sum = self.link_sum_at(at, side, leaf, visibility, cache, stats);
        Some(sum + self.punctual_irradiance(at, side, stats))
    }

    fn near_correction(
        &self,
        at: &SurfacePoint<HitLocator>,
        wo: DVec3,
        coarse_near: &[FaceElement],
        cache: &mut LinkCache<N>,
        stats: &mut GatherStats,
    ) -> Option<Spectrum<N>> {
        let side = viewer_side(at, wo);
        let forest = self.solution.forest();
        let leaf = forest.locate(at.locator.surface, at.locator.coord);
        let mut e = Some(leaf);
        let sender = loop {
            let c = e?;
            if coarse_near.contains(&FaceElement::new(c, side)) {
                break c;
            }
            e = forest.element(c).parent;
        };
        let rho = self.bsdf(at).diffuse_albedo(side);
        let sum = self.link_sum_at(at, side, leaf, LinkVisibility::Secondary, cache, stats);
        let face = FaceId::new(at.locator.surface, side);
        let le = match side {
            Side::Front => self.scene.emission()[at.locator.shape as usize],
            Side::Back => Spectrum::zero(),
        };
        let average = self.solution.face_radiance(face, sender) - le;
        Some(rho * sum - average)
    }

    fn is_glossy(&self, at: &SurfacePoint<HitLocator>, wo: DVec3) -> bool {
        self.bsdf(at).has_glossy(viewer_side(at, wo))
    }

    fn glossy_cos(&self, at: &SurfacePoint<HitLocator>, wi: DVec3, wo: DVec3) -> Spectrum<N> {
        let frame = Frame::from_normal(at.locator.shading_normal);
        let (wi, wo) = (frame.to_local(wi), frame.to_local(wo));
        // fr less ρ_d/π: the glossy part, and for plastics also the base
        // term's departure from Lambertian (trilux_brdf::plastic).
        self.bsdf(at).eval_non_lambertian(wi, wo) * wi.z.abs()
    }

    fn glossy_fan(
        &self,
        at: &SurfacePoint<HitLocator>,
        wi: DVec3,
        wos: &[DVec3],
        glossy: &mut Vec<Spectrum<N>>,
    ) -> f64 {
        let frame = Frame::from_normal(at.locator.shading_normal);
        let bsdf = self.bsdf(at);
        let wi = frame.to_local(wi);
        glossy.clear();
        let mut pdf = 0.0;
        for &wo in wos {
            let wo = frame.to_local(wo);
            glossy.push(bsdf.eval_non_lambertian(wi, wo) * wi.z.abs());
            pdf += bsdf.pdf(wo, wi);
        }
        pdf / wos.len().max(1) as f64
    }

    fn reflected_glossy(
        &self,
        from: &SurfacePoint<HitLocator>,
        towards: &SurfacePoint<HitLocator>,
    ) -> Spectrum<N> {
        let (from, towards) = Self::sites(from, towards);
        self.solution.reflected_glossy(&from, &towards)
    }

    fn cosine_pdf(&self, at: &SurfacePoint<HitLocator>, wo: DVec3, wi: DVec3) -> f64 {
        let sign = viewer_side(at, wo).sign();
        let cos = sign * at.locator.shading_normal.dot(wi);
        if cos <= 0.0 || sign * at.normal.dot(wi) <= 0.0 {
            0.0
        } else {
            cos / std::f64::consts::PI
        }
    }

    fn sample_cosine(&self, at: &SurfacePoint<HitLocator>, wo: DVec3, u: DVec2) -> Option<DVec3> {
        let n = at.locator.shading_normal * viewer_side(at, wo).sign();
        let local = trilux_brdf::lobe::square_to_cosine_hemisphere(u);
        let wi = Frame::from_normal(n).to_world(local);
        (wi.dot(at.normal) * wo.dot(at.normal) > 0.0).then_some(wi)
    }

    fn has_glossy_faces(&self) -> bool {
        self.glossy_faces
    }

    fn has_links(&self) -> bool {
        self.solution.has_links()
    }

    fn fit_sites(&self, at: &SurfacePoint<HitLocator>, wo: DVec3) -> Vec<FitSite<HitLocator>> {
        let forest = self.solution.forest();
        let l = at.locator;
        let leaf = forest.locate(l.surface, l.coord);
        let corners = match (forest.element(leaf).domain, l.coord) {
            (ElementDomain::Rect { min, max }, SurfaceCoord::Uv(p)) => rect_corners(min, max, p),
            (ElementDomain::Cluster { .. }, SurfaceCoord::Triangle { index, bary }) => {
                piece_corners(forest.element_pieces(leaf), index, bary)
            }
            _ => Vec::new(),
        };
        let back = viewer_side(at, wo) == Side::Back;
        corners
            .into_iter()
            .filter(|&(_, weight)| weight > 0.0)
            .filter_map(|(coord, weight)| {
                // The bake's vertex normal: the geometric one (module
                // `tessellate` of trilux-bake).
                let p = self.geom().surface_point(l.surface, coord)?;
                Some(FitSite {
                    point: SurfacePoint {
                        point: p.point,
                        normal: p.normal,
                        t: 0.0,
                        locator: HitLocator {
                            coord,
                            shading_normal: p.normal,
                            ..l
                        },
                    },
                    weight,
                    key: FitKey::new(l.shape, back, p.point, p.normal),
                })
            })
            .collect()
    }
}

/// The corners of the (u, v) rectangle [min, max] and the bilinear
/// weights of `p` in it.
fn rect_corners(min: DVec2, max: DVec2, p: DVec2) -> Vec<(SurfaceCoord, f64)> {
    let size = max - min;
    let t = ((p - min) / size.max(DVec2::splat(f64::MIN_POSITIVE))).clamp(DVec2::ZERO, DVec2::ONE);
    vec![
        (SurfaceCoord::Uv(min), (1.0 - t.x) * (1.0 - t.y)),
        (
            SurfaceCoord::Uv(DVec2::new(max.x, min.y)),
            t.x * (1.0 - t.y),
        ),
        (SurfaceCoord::Uv(max), t.x * t.y),
        (
            SurfaceCoord::Uv(DVec2::new(min.x, max.y)),
            (1.0 - t.x) * t.y,
        ),
    ]
}

/// The corners of the piece of triangle `index` that holds `bary` (the
/// one it lies deepest inside, when rounding puts it on none) and its
/// barycentric weights there.
fn piece_corners(pieces: &[Piece], index: u32, bary: DVec2) -> Vec<(SurfaceCoord, f64)> {
    let weights = |c: &[DVec2; 3]| {
        let (e1, e2, d) = (c[1] - c[0], c[2] - c[0], bary - c[0]);
        let det = e1.perp_dot(e2);
        if det.abs() <= f64::MIN_POSITIVE {
            return [1.0, 0.0, 0.0];
        }
        let (w1, w2) = (d.perp_dot(e2) / det, e1.perp_dot(d) / det);
        [1.0 - w1 - w2, w1, w2]
    };
    let inside = |w: &[f64; 3]| w.iter().copied().fold(f64::INFINITY, f64::min);
    let best = pieces
        .iter()
        .filter(|p| p.triangle == index)
        .map(|p| (p, weights(&p.bary)))
        .max_by(|a, b| inside(&a.1).total_cmp(&inside(&b.1)));
    let Some((piece, w)) = best else {
        return Vec::new();
    };
    // Clamped into the piece and renormalised.
    let w = w.map(|x| x.max(0.0));
    let sum = w.iter().sum::<f64>().max(f64::MIN_POSITIVE);
    (0..3)
        .map(|k| {
            let coord = SurfaceCoord::Triangle {
                index,
                bary: piece.bary[k],
            };
            (coord, w[k] / sum)
        })
        .collect()
}

/// The side of `at`'s surface the viewer direction `wo` is on (geometric).
fn viewer_side(at: &SurfacePoint<HitLocator>, wo: DVec3) -> Side {
    Side::from_back(at.normal.dot(wo) < 0.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The corners' weights are an interpolation: non-negative, summing to
    /// one, and reproducing the point (Σ w_k c_k = p), for a rectangle
    /// and for a piece of a triangle, whichever piece of the triangle the
    /// point lies in.
    #[test]
    fn corner_weights_interpolate_the_point() {
        let at = |c: SurfaceCoord| match c {
            SurfaceCoord::Uv(p) | SurfaceCoord::Triangle { bary: p, .. } => p,
        };
        let check = |corners: Vec<(SurfaceCoord, f64)>, p: DVec2| {
            assert!(!corners.is_empty());
            let sum: f64 = corners.iter().map(|c| c.1).sum();
            let mean: DVec2 = corners.iter().map(|&(c, w)| at(c) * w).sum();
            assert!(corners.iter().all(|c| c.1 >= 0.0), "{corners:?}");
            assert!((sum - 1.0).abs() < 1e-12, "{sum}");
            assert!((mean - p).length() < 1e-12, "{mean} vs {p}");
        };
        let (min, max) = (DVec2::new(0.25, 0.5), DVec2::new(0.5, 0.75));
        for p in [DVec2::new(0.3, 0.6), min, max, DVec2::new(0.49, 0.51)] {
            check(rect_corners(min, max, p), p);
        }
        // Triangle 7 split into its four midpoint pieces, and another
        // triangle's piece that must not be taken.
        let (a, b, c) = (DVec2::ZERO, DVec2::X, DVec2::Y);
        let (ab, bc, ca) = ((a + b) / 2.0, (b + c) / 2.0, (c + a) / 2.0);
        let piece = |triangle, bary| Piece { triangle, bary };
        let pieces = [
            piece(3, [a, b, c]),
            piece(7, [a, ab, ca]),
            piece(7, [ab, b, bc]),
            piece(7, [ca, bc, c]),
            piece(7, [bc, ca, ab]),
        ];
        for p in [
            DVec2::new(0.1, 0.1),
            DVec2::new(0.6, 0.2),
            DVec2::new(0.3, 0.3),
        ] {
            let corners = piece_corners(&pieces, 7, p);
            assert!(
                corners
                    .iter()
                    .all(|c| matches!(c.0, SurfaceCoord::Triangle { index: 7, .. }))
            );
            check(corners, p);
        }
    }
}
