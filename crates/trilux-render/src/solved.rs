//! The final gather wired to trilux's own layers: [`SolvedScene`]
//! implements [`GatherScene`] with trilux-geometry (rays, surface sampling,
//! element lookup), trilux-brdf (materials), trilux-color (emission) and a
//! solution ([`RadianceSolution`]: the solver's, or a stand-in).
//!
//! - Rays: `SceneGeometry::intersect` (exact for analytic shapes, its own
//!   self-intersection epsilon), shadow rays `SceneGeometry::occluded`.
//! - Materials: `Bsdf<N>` in the shading frame of the hit (z = shading
//!   normal on the front side); it reflects on the viewer's side (black from
//!   the back unless `twosided`), as in Mitsuba.
//! - Emitters: one-sided Lambertian area emitters on the front side. Light
//!   sampling picks an emitting input surface with probability ∝ its area ×
//!   the luminance of its radiance, then a point uniformly by area
//!   (`SceneGeometry::sample_surface`; the MIS weight at a gather hit on an
//!   emitter uses the same density, 1/area × pick probability).
//! - Solution lookup: the face a light path leaves from and the face it
//!   arrives on are passed with the points (the solver keeps both faces of
//!   two-sided surfaces apart).
//! - Extra-bounce rule inputs: the element size is √area of the deepest
//!   element of the geometry tree (after the solve's subdivisions) that
//!   contains the hit; the lobe solid angle of a roughconductor part with
//!   roughness α is taken as 4πα² (its lobe in ω_i is about 2α wide), 2π for
//!   a diffuse-only side.

use glam::{DVec2, DVec3};
use trilux_brdf::{Bsdf, BsdfParams, Frame};
use trilux_color::Spectrum;
use trilux_geometry::{Ray, SceneGeometry, SurfaceCoord, SurfaceId};

use crate::error::RenderError;
use crate::gather::{BsdfSample, GatherScene, LightSample, SurfacePoint};

/// One end of a solution query: a point of an input surface and the face
/// light leaves from (or arrives on).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Site {
    /// The input surface.
    pub surface: SurfaceId,
    /// The point in the surface's coordinates.
    pub coord: SurfaceCoord,
    /// True for the back face (against the geometric normal).
    pub back: bool,
}

/// What the renderer needs of a view-independent solution.
pub trait RadianceSolution<const N: usize>: Sync {
    /// The geometry the solution refers to (with the solve's subdivisions).
    fn geometry(&self) -> &SceneGeometry;
    /// Reflected radiance (emission excluded) leaving `from` towards `to`.
    fn reflected(&self, from: &Site, to: &Site) -> Spectrum<N>;
}

/// A stand-in solution that knows no indirect light (every reflected
/// radiance is zero): the final gather then renders direct lighting only.
/// Also answers a constant, for tests (`constant`).
pub struct DirectOnly<const N: usize> {
    /// The scene's geometry.
    pub geometry: SceneGeometry,
    /// The reflected radiance it answers everywhere (zero: direct only).
    pub constant: Spectrum<N>,
}

impl<const N: usize> RadianceSolution<N> for DirectOnly<N> {
    fn geometry(&self) -> &SceneGeometry {
        &self.geometry
    }
    fn reflected(&self, _from: &Site, _to: &Site) -> Spectrum<N> {
        self.constant
    }
}

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
}

/// Per-shape data prepared once.
struct ShapeData<const N: usize> {
    bsdf: Bsdf<N>,
    emission: Option<Spectrum<N>>,
    /// Lobe solid angle per side [front, back].
    lobe_sr: [f64; 2],
}

/// A scene and its solution, ready for the final gather.
pub struct SolvedScene<'a, const N: usize, S> {
    solution: &'a S,
    shapes: Vec<ShapeData<N>>,
    /// Emitting input surfaces with their cumulative pick probabilities.
    emitters: Vec<(SurfaceId, f64)>,
    /// Pick probability / area, by surface index (0 when not emitting).
    light_density: Vec<f64>,
}

/// Smallest roughconductor α on `back` (false: front) of `p`, if any.
fn min_alpha(p: &BsdfParams, back: bool) -> Option<f64> {
    match p {
        BsdfParams::Diffuse { .. } => None,
        BsdfParams::RoughConductor(rc) => (!back).then_some(rc.alpha),
        BsdfParams::Blend {
            first,
            second,
            weight,
        } => {
            let a = if *weight < 1.0 {
                min_alpha(first, back)
            } else {
                None
            };
            let b = if *weight > 0.0 {
                min_alpha(second, back)
            } else {
                None
            };
            match (a, b) {
                (Some(x), Some(y)) => Some(x.min(y)),
                (x, y) => x.or(y),
            }
        }
        BsdfParams::TwoSided { front, back: b } => {
            if back {
                min_alpha(b.as_deref().unwrap_or(front), false)
            } else {
                min_alpha(front, false)
            }
        }
    }
}

fn lobe_sr(p: &BsdfParams, back: bool) -> f64 {
    match min_alpha(p, back) {
        Some(a) => (4.0 * std::f64::consts::PI * a * a).min(2.0 * std::f64::consts::PI),
        None => 2.0 * std::f64::consts::PI,
    }
}

impl<'a, const N: usize, S: RadianceSolution<N>> SolvedScene<'a, N, S> {
    /// Prepares materials and emitters of `scene` for the geometry and
    /// light of `solution`.
    pub fn new(scene: &trilux_scene::Scene, solution: &'a S) -> Result<Self, RenderError> {
        let geom = solution.geometry();
        let mut shapes = Vec::with_capacity(scene.shapes.len());
        for (i, s) in scene.shapes.iter().enumerate() {
            let bsdf = Bsdf::new(&s.bsdf)
                .map_err(|e| RenderError::Scene(format!("shape {i} ({}): {e}", s.location)))?;
            let emission = match &s.emitter {
                Some(em) => Some(em.radiance.emission::<N>().map_err(|e| {
                    RenderError::Scene(format!("emitter of shape {i} ({}): {e}", em.location))
                })?),
                None => None,
            };
            shapes.push(ShapeData {
                bsdf,
                emission,
                lobe_sr: [lobe_sr(&s.bsdf, false), lobe_sr(&s.bsdf, true)],
            });
        }
        let surfaces = geom.surfaces();
        let mut weights = Vec::new();
        for (k, surf) in surfaces.iter().enumerate() {
            let Some(data) = shapes.get(surf.shape as usize) else {
                return Err(RenderError::Scene(format!(
                    "input surface {k} names shape {} of {}",
                    surf.shape,
                    shapes.len()
                )));
            };
            if let Some(le) = data.emission {
                let w = surf.area() * le.luminance().max(le.max_value() * 1e-3);
                if w > 0.0 && w.is_finite() {
                    weights.push((SurfaceId(k as u32), w));
                }
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
        Ok(Self {
            solution,
            shapes,
            emitters,
            light_density,
        })
    }

    fn geom(&self) -> &SceneGeometry {
        self.solution.geometry()
    }

    fn site(p: &SurfacePoint<HitLocator>, back: bool) -> Site {
        Site {
            surface: p.locator.surface,
            coord: p.locator.coord,
            back,
        }
    }
}

impl<const N: usize, S: RadianceSolution<N>> GatherScene<N> for SolvedScene<'_, N, S> {
    type Locator = HitLocator;

    fn intersect(&self, origin: DVec3, dir: DVec3) -> Option<SurfacePoint<HitLocator>> {
        let geom = self.geom();
        let hit = geom.intersect(&Ray { origin, dir }, f64::INFINITY)?;
        let shape = geom.surface(hit.surface).shape;
        Some(SurfacePoint {
            point: hit.point,
            normal: hit.geometric_normal,
            t: hit.t * dir.length(),
            locator: HitLocator {
                surface: hit.surface,
                coord: hit.coord,
                shading_normal: hit.shading_normal,
                shape,
            },
        })
    }

    fn unoccluded(&self, from: &SurfacePoint<HitLocator>, to: DVec3) -> bool {
        !self.geom().occluded(from.point, to)
    }

    fn emitted(&self, at: &SurfacePoint<HitLocator>, wo: DVec3) -> [f64; N] {
        match self.shapes[at.locator.shape as usize].emission {
            Some(le) if at.normal.dot(wo) > 0.0 => le.0,
            _ => [0.0; N],
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
        let geom = self.geom();
        let s = geom.sample_surface(surface, u);
        let shape = geom.surface(surface).shape as usize;
        let le = self.shapes[shape].emission?;
        let front = s.normal.dot(reference.point - s.point) > 0.0;
        Some(LightSample {
            point: s.point,
            normal: s.normal,
            radiance: if front { le.0 } else { [0.0; N] },
            pdf_area: self.light_density[surface.index()],
        })
    }

    fn light_pdf_area(&self, at: &SurfacePoint<HitLocator>) -> f64 {
        self.light_density[at.locator.surface.index()]
    }

    fn bsdf_cos(&self, at: &SurfacePoint<HitLocator>, wi: DVec3, wo: DVec3) -> [f64; N] {
        let frame = Frame::from_normal(at.locator.shading_normal);
        let (wi, wo) = (frame.to_local(wi), frame.to_local(wo));
        (self.shapes[at.locator.shape as usize].bsdf.eval(wi, wo) * wi.z.abs()).0
    }

    fn sample_bsdf(
        &self,
        at: &SurfacePoint<HitLocator>,
        wo: DVec3,
        u: DVec2,
    ) -> Option<BsdfSample<N>> {
        let frame = Frame::from_normal(at.locator.shading_normal);
        let s = self.shapes[at.locator.shape as usize]
            .bsdf
            .sample(frame.to_local(wo), u)?;
        let wi = frame.to_world(s.wi);
        // A direction on the other side of the true surface than the
        // viewer would pass through it (possible with shading normals).
        if wi.dot(at.normal) * wo.dot(at.normal) <= 0.0 {
            return None;
        }
        Some(BsdfSample {
            wi,
            weight: s.weight.0,
            pdf: s.pdf,
        })
    }

    fn bsdf_pdf(&self, at: &SurfacePoint<HitLocator>, wo: DVec3, wi: DVec3) -> f64 {
        let frame = Frame::from_normal(at.locator.shading_normal);
        self.shapes[at.locator.shape as usize]
            .bsdf
            .pdf(frame.to_local(wo), frame.to_local(wi))
    }

    fn reflected(
        &self,
        from: &SurfacePoint<HitLocator>,
        towards: &SurfacePoint<HitLocator>,
    ) -> [f64; N] {
        let d = towards.point - from.point;
        let from_back = from.normal.dot(d) < 0.0;
        let to_back = towards.normal.dot(-d) < 0.0;
        self.solution
            .reflected(&Self::site(from, from_back), &Self::site(towards, to_back))
            .0
    }

    fn element_size(&self, at: &SurfacePoint<HitLocator>) -> f64 {
        let geom = self.geom();
        let e = geom.locate(at.locator.surface, at.locator.coord);
        geom.element(e).area.sqrt()
    }

    fn lobe_solid_angle(&self, at: &SurfacePoint<HitLocator>, wo: DVec3) -> f64 {
        let back = usize::from(at.normal.dot(wo) < 0.0);
        self.shapes[at.locator.shape as usize].lobe_sr[back]
    }

    fn shading_differs(&self, at: &SurfacePoint<HitLocator>) -> bool {
        // More than about 1° apart.
        at.locator.shading_normal.dot(at.normal).abs() < 0.9998
    }
}

/// The solver's solution answers the renderer's queries directly.
impl<const N: usize> RadianceSolution<N> for trilux_solver::Solution<N> {
    fn geometry(&self) -> &SceneGeometry {
        trilux_solver::Solution::geometry(self)
    }
    fn reflected(&self, from: &Site, to: &Site) -> Spectrum<N> {
        let site = |s: &Site| trilux_solver::SurfaceSite {
            surface: s.surface,
            coord: s.coord,
            back: s.back,
        };
        self.radiance(&site(from), &site(to))
    }
}

/// Solves a loaded scene with the solver (a convenience for tests, examples
/// and tools; the `trilux` command drives the solver itself).
pub fn solve_scene<const N: usize>(
    scene: &trilux_scene::Scene,
    settings: trilux_solver::SolverSettings,
) -> Result<trilux_solver::Solution<N>, RenderError> {
    let input = trilux_solver::SceneInput::from_scene(scene);
    let solver = trilux_solver::Solver::<N>::new(&input.as_input(), settings)
        .map_err(|e| RenderError::Scene(format!("{}: {e}", scene.path.display())))?;
    Ok(solver.solve(|_| {}))
}
