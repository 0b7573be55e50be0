//! The renderer's estimate of glossy light, for directional bakes: a
//! [`trilux_bake::GlossyLight`] that asks the link gather for the glossy
//! light of every direction of a point from one set of incident samples
//! (`LinkGather::glossy_directions`: BSDF-sampled gather rays from the
//! mixture of the directions' lobes and light samples, each gather hit
//! read as the full render reads it, through its links and one more
//! glossy level). The bake's glossy light is thus the full render's,
//! fitted; each sample's cost is paid once per point, not per direction.
//! Its samples are seeded as the preview's fits are
//! (`trilux_render::glossy_fit::fit_sampler`), which fit the same form at
//! the corners of leaf elements.
//!
//! It is also the bake's [`trilux_bake::GatheredLight`]: at a vertex, the
//! link sum with the visibility the solve measured (no rays) and E_g
//! (`trilux_render::glossy_irradiance`), as the preview reads a diffuse
//! hit.

use glam::DVec3;
use rayon::prelude::*;
use trilux_bake::{GatheredLight, GlossyLight, GlossyPoint, GlossySamples};
use trilux_color::Spectrum;
use trilux_geometry::Side;
use trilux_render::gather::{ExtraBounce, FinalGather};
use trilux_render::glossy_fit::fit_sampler;
use trilux_render::glossy_irradiance::glossy_irradiance_at;
use trilux_render::link_gather::{Caches, IncidentSamples, LinkGather};
use trilux_render::scene::SolutionGather;
use trilux_render::solved::HitLocator;
use trilux_render::{GatherStats, LinkVisibility, SolvedScene, SurfacePoint};
use trilux_solver::Solution;

/// The render's glossy light over a solution.
pub(crate) struct RenderedGlossy<'a, const N: usize> {
    scene: SolvedScene<'a, N, Solution<N>>,
}

impl<'a, const N: usize> RenderedGlossy<'a, N> {
    pub(crate) fn new(solution: &'a Solution<N>) -> Self {
        RenderedGlossy {
            scene: SolvedScene::new(solution),
        }
    }

    /// Glossy radiance at `p` towards each of `dirs`.
    fn at(
        &self,
        p: &GlossyPoint,
        dirs: &[DVec3],
        samples: GlossySamples,
        caches: &mut Caches<N>,
    ) -> Vec<[f64; 3]> {
        let gather = LinkGather {
            scene: &self.scene,
            fallback: FinalGather {
                scene: &self.scene,
                extra: ExtraBounce::default(),
                hide_emitters: false,
            },
            glossy_scene: true,
        };
        let x = surface_point(p);
        let mut stats = GatherStats::default();
        let mut sampler = fit_sampler(p.key);
        let counts = IncidentSamples {
            gather: samples.gather,
            light: samples.light,
            links: samples.links,
        };
        gather
            .glossy_directions(&x, dirs, counts, &mut sampler, caches, &mut stats)
            .iter()
            .map(|l| l.to_linear_srgb())
            .collect()
    }
}

/// The renderer's surface point at the bake's point `p`.
fn surface_point(p: &GlossyPoint) -> SurfacePoint<HitLocator> {
    SurfacePoint {
        point: p.point,
        normal: p.normal,
        t: 0.0,
        locator: HitLocator {
            surface: p.surface,
            coord: p.coord,
            shading_normal: p.normal,
            shape: p.shape,
            through: 1.0,
        },
    }
}

impl<const N: usize> GatheredLight for RenderedGlossy<'_, N> {
    fn irradiance(&self, points: &[GlossyPoint]) -> Option<Vec<[f64; 3]>> {
        if !self.scene.has_links() {
            return None;
        }
        let glossy = self.scene.has_glossy_faces();
        let light = points
            .par_iter()
            .map_init(Caches::<N>::default, |caches, p| {
                let x = surface_point(p);
                let wo = p.normal * p.side.sign();
                let mut stats = GatherStats::default();
                let Some(e) = self.scene.solution_irradiance(
                    &x,
                    wo,
                    LinkVisibility::Cached,
                    &mut caches.pixel,
                    &mut stats,
                ) else {
                    return [0.0; 3];
                };
                let back = p.side == Side::Back;
                let e_g = match glossy {
                    true => glossy_irradiance_at(&self.scene, &x, back, p.key, &mut stats),
                    false => Spectrum::zero(),
                };
                (e + e_g).to_linear_srgb()
            })
            .collect();
        Some(light)
    }
}

impl<const N: usize> GlossyLight for RenderedGlossy<'_, N> {
    fn outgoing(
        &self,
        points: &[GlossyPoint],
        directions: &[DVec3],
        samples: GlossySamples,
    ) -> Vec<[f64; 3]> {
        let per = directions.len().checked_div(points.len()).unwrap_or(0);
        if per == 0 {
            return Vec::new();
        }
        points
            .par_iter()
            .zip(directions.par_chunks(per))
            .map_init(Caches::<N>::default, |caches, (p, dirs)| {
                self.at(p, dirs, samples, caches)
            })
            .flatten_iter()
            .collect()
    }
}
