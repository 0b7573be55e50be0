//! Rendering from the solution's links: the final gather of hierarchical
//! radiosity, at pixel resolution (Lischinski, Tampieri & Greenberg 1993;
//! Smits, Arvo & Greenberg 1994).
//!
//! A camera ray meets the scene at x_s. Its radiance towards the eye is
//!
//! L(x_s → eye) = Le + ρ_d(x_s) [Σ_i L_i F(x_s → i) V(x_s, i) + E_g(x_s)]
//!              + L_glossy(x_s → eye),
//!
//! - the **link sum** runs over the solution's gather links into the
//!   elements containing x_s (`trilux_solver::gather_links`, [`link_sum`]):
//!   every Lambertian sender element i with its final radiance L_i
//!   (emitters included, so the sum holds the direct light too), F the
//!   point-to-element form factor computed exactly at x_s, V the link's
//!   visible fraction — 1 where its shadow rays all passed, traced per
//!   camera sample where it is partial. It has no Monte Carlo noise but in
//!   penumbrae.
//! - **E_g**, the light that glossy senders reflect onto x_s, is not in the
//!   links (a glossy sender's stored radiance is constant over whole
//!   receiving elements, which would show as blocks): one cosine-sampled
//!   ray from x_s, and where it meets a glossy part, that part's glossy
//!   radiance towards x_s estimated as below. Scenes without glossy faces
//!   skip it.
//! - **L_glossy**, the glossy part of the BSDF at x_s, is estimated as the
//!   paper's §4.5 does, by a BSDF-sampled gather ray with light sampling
//!   (combined by MIS) weighting fr_glossy only. The gather hit x_d brings
//!   its emission (MIS-weighted) and its reflected radiance towards x_s:
//!   the link sum at x_d (with the links' own visibility) times ρ_d(x_d),
//!   plus its own glossy part, one level deeper; beyond that level the
//!   solution is read directly.
//! - The **sky** (an environment map) is not in the links either: the
//!   Lambertian part takes one sky sample, MIS-combined with the cosine
//!   ray (which then is always traced) leaving the scene; the glossy part
//!   takes it with its light sample and its gather ray's misses
//!   (`crate::mis`).
//!
//! `preview::Preview` drops every random ray at the pixel: the link sum with the
//! links' own visibility at x_s plus E_g read at the corners of x_s's
//! leaf element (module `glossy_irradiance`), and for a glossy x_s the directional
//! bake's representation of L_glossy (harmonics plus a lobe fitted at the
//! corners of x_s's leaf element, made once per corner with fixed seeds
//! and shared: module `glossy_fit`), so that the preview and a viewer of
//! the bake read the same light. A noise-free (not shadow-exact) view for
//! walkthroughs.
//!
//! [`link_sum`]: crate::link_sum

use glam::{DVec2, DVec3};

use crate::gather::FinalGather;
use crate::link_sum::LinkCache;
use crate::mis::{
    eye_hit, hit_emission, light_sample, miss_emission, punctual_direct, sky_sample, sky_seen,
};
use crate::records::{GatherStats, LinkVisibility, SurfacePoint};
use crate::sampler::{PixelSampler, dims};
use crate::scene::SolutionGather;
use trilux_color::Spectrum;

/// What one camera sample of the link gather may reuse: the pixel's link
/// cache (primary hits) and a scratch cache (gather hits).
#[derive(Clone, Debug, Default)]
pub struct Caches<const N: usize> {
    /// The current pixel's primary-hit cache.
    pub pixel: LinkCache<N>,
    /// Scratch space for gather hits.
    pub scratch: LinkCache<N>,
}

/// Gather levels below the camera hit at which the link sum is still
/// evaluated; deeper hits read the solution directly.
const LINK_LEVELS: u32 = 1;

/// The link-gather estimator (module docs), with the path gather for
/// scenes without links.
pub struct LinkGather<'a, S> {
    /// The scene and its solution.
    pub scene: &'a S,
    /// The path gather, for a point the links cannot serve.
    pub fallback: FinalGather<'a, S>,
    /// True when some face of the scene is glossy (the E_g term is needed).
    pub glossy_scene: bool,
}

/// One camera sample's state while the link gather evaluates it.
struct Walk<'s, const N: usize> {
    sampler: &'s PixelSampler,
    caches: &'s mut Caches<N>,
    stats: &'s mut GatherStats,
}

impl<S> LinkGather<'_, S> {
    /// Radiance arriving at the eye along a camera ray (one sample).
    pub fn camera_sample<const N: usize>(
        &self,
        origin: DVec3,
        dir: DVec3,
        sampler: &PixelSampler,
        caches: &mut Caches<N>,
        stats: &mut GatherStats,
    ) -> Spectrum<N>
    where
        S: SolutionGather<N>,
    {
        if !self.scene.has_links() {
            return self.fallback.camera_sample(origin, dir, sampler, stats);
        }
        stats.camera_rays += 1;
        let Some(xs) = eye_hit(self.scene, origin, dir, self.fallback.hide_emitters) else {
            return sky_seen(self.scene, origin, dir, self.fallback.hide_emitters);
        };
        let wo = -dir;
        let scene = self.scene;
        let through = scene.through(&xs);
        let mut w = Walk {
            sampler,
            caches,
            stats,
        };
        let mut l = scene.emitted(&xs, wo);
        let rho = scene.diffuse_albedo(&xs, wo);
        if !rho.is_black() {
            let visibility = LinkVisibility::Traced {
                sampler,
                dim: dims::LINKS,
            };
            match scene.solution_irradiance(&xs, wo, visibility, &mut w.caches.pixel, w.stats) {
                Some(e) => {
                    let e = e + self.cosine_ray(&xs, wo, 0, &mut w);
                    l += rho * e;
                }
                // No links here: the path gather serves the whole BSDF.
                None => {
                    let lr = self.fallback.gather(&xs, wo, 0, sampler, w.stats);
                    return w.stats.finite_or_dropped((l + lr) * through);
                }
            }
        }
        if scene.is_glossy(&xs, wo) {
            l += self.glossy(&xs, wo, 0, &mut w);
        }
        w.stats.finite_or_dropped(l * through)
    }

    /// One sample of the glossy part of the radiance leaving `x` towards
    /// `wo`: the estimate a camera sample makes at its hit (module docs),
    /// for directional bakes that fit it over many directions.
    pub fn glossy_sample<const N: usize>(
        &self,
        x: &SurfacePoint<S::Locator>,
        wo: DVec3,
        sampler: &PixelSampler,
        caches: &mut Caches<N>,
        stats: &mut GatherStats,
    ) -> Spectrum<N>
    where
        S: SolutionGather<N>,
    {
        let mut w = Walk {
            sampler,
            caches,
            stats,
        };
        let l = self.glossy(x, wo, 0, &mut w);
        w.stats.finite_or_dropped(l)
    }

    /// The glossy part of the radiance leaving `x` towards each of `wos`
    /// (unit vectors), from one set of incident samples shared by all of
    /// them (for directional bakes): `counts.gather` BSDF-sampled gather
    /// rays, sample k drawn from the lobe of direction ⌊(k + u)·D/K⌋ (the
    /// strata together draw from the mixture of all D lobes), and
    /// `counts.light` light samples (each with a sky sample, where there is a
    /// sky: the sky as `light_sample` takes it). Every sample serves every direction,
    /// weighted by the balance heuristic over the lobe mixture and light
    /// sampling (Veach's multi-sample estimator, unbiased): what a sample
    /// brings (the gather hit read as [`LinkGather::glossy_sample`] reads
    /// it, or from the solution: `counts.links`) is paid for once, not
    /// once per direction.
    pub fn glossy_directions<const N: usize>(
        &self,
        x: &SurfacePoint<S::Locator>,
        wos: &[DVec3],
        counts: IncidentSamples,
        sampler: &mut PixelSampler,
        caches: &mut Caches<N>,
        stats: &mut GatherStats,
    ) -> Vec<Spectrum<N>>
    where
        S: SolutionGather<N>,
    {
        let mut out = vec![Spectrum::zero(); wos.len()];
        if wos.is_empty() {
            return out;
        }
        let (ng, nl) = (f64::from(counts.gather), f64::from(counts.light));
        let scene = self.scene;
        let mut fan = Vec::with_capacity(wos.len());
        let mut add = |fan: &[Spectrum<N>], l: Spectrum<N>| {
            for (o, f) in out.iter_mut().zip(fan) {
                *o += *f * l;
            }
        };
        for k in 0..counts.gather {
            sampler.start_sample(k);
            let stratum = (f64::from(k) + sampler.get1(dims::GATHER)) / ng;
            let j = ((stratum * wos.len() as f64) as usize).min(wos.len() - 1);
            let Some(bs) = scene.sample_bsdf(x, wos[j], sampler.get2(dims::GATHER + 1)) else {
                continue;
            };
            if !(bs.pdf.is_finite() && bs.pdf > 0.0) {
                continue;
            }
            let p_mix = scene.glossy_fan(x, bs.wi, wos, &mut fan);
            if p_mix <= 0.0 {
                continue;
            }
            stats.gather_rays += 1;
            let Some(xd) = scene.intersect(x.point, bs.wi) else {
                // The sky (through any panes), balanced against its samples.
                let (le, p_sky) = scene.sky(x.point, bs.wi);
                if !le.is_black() {
                    add(&fan, le * (1.0 / (ng * p_mix + nl * p_sky)));
                }
                continue;
            };
            let back = -bs.wi;
            let through = scene.through(&xd);
            let mut w = Walk {
                sampler: &*sampler,
                caches: &mut *caches,
                stats: &mut *stats,
            };
            let level = if counts.links { 1 } else { LINK_LEVELS + 1 };
            let mut l = self.reflected_at(&xd, x, back, level, &mut w) * (through / (ng * p_mix));
            let le = scene.emitted(&xd, back);
            if !le.is_black() {
                let p_light = light_density(scene, &xd, back);
                l += le * (through / (ng * p_mix + nl * p_light));
            }
            add(&fan, l);
        }
        for k in 0..counts.light {
            sampler.start_sample(counts.gather + k);
            let (pick, u) = (
                sampler.get1(dims::GATHER + 3),
                sampler.get2(dims::GATHER + 4),
            );
            if let Some((wi, le, p_light)) = unoccluded_light(scene, x, pick, u, stats) {
                let p_mix = scene.glossy_fan(x, wi, wos, &mut fan);
                add(&fan, le * (1.0 / (nl * p_light + ng * p_mix)));
            }
            // With a sky, one sky sample beside each light sample, as
            // `light_sample` takes.
            if let Some((wi, le, p_sky)) = unoccluded_sky(scene, x, u, stats) {
                let p_mix = scene.glossy_fan(x, wi, wos, &mut fan);
                add(&fan, le * (1.0 / (nl * p_sky + ng * p_mix)));
            }
        }
        // Lights without area: one shadow ray each, no MIS (no ray meets
        // them), as `punctual_direct` for a single direction.
        for k in 0..scene.punctual_count() {
            let Some(p) = scene.punctual_at(k, x) else {
                continue;
            };
            if p.irradiance.is_black() {
                continue;
            }
            stats.shadow_rays += 1;
            let tau = scene.transmittance(x, p.end);
            if tau > 0.0 {
                scene.glossy_fan(x, p.wi, wos, &mut fan);
                add(&fan, p.irradiance * tau);
            }
        }
        out.iter().map(|&l| stats.finite_or_dropped(l)).collect()
    }

    /// The cosine ray's share of the irradiance at a Lambertian `x` at
    /// gather `level` (module docs): E_g, the glossy radiance it brings,
    /// and at the camera hit the near-field correction where it meets a
    /// sender the link sum took at its average. Estimated one level deeper
    /// from the camera hit, read from the solution's stored radiance from a
    /// gather hit. Not traced when neither is needed.
    fn cosine_ray<const N: usize>(
        &self,
        x: &SurfacePoint<S::Locator>,
        wo: DVec3,
        level: u32,
        w: &mut Walk<'_, N>,
    ) -> Spectrum<N>
    where
        S: SolutionGather<N>,
    {
        let correct = level == 0 && !w.caches.pixel.coarse_near().is_empty();
        let traced = self.glossy_scene || correct;
        let scene = self.scene;
        // The sky's share (not in the links): one sky sample, MIS-weighted
        // against the cosine ray where that is traced.
        let kernel = |wi| scene.cosine_pdf(x, wo, wi);
        let sky = sky_sample(
            scene,
            x,
            w.sampler.get2(dims::sky(level)),
            |wi| Spectrum::splat(kernel(wi)),
            kernel,
            traced,
            w.stats,
        );
        if !traced {
            return sky;
        }
        let u = w.sampler.get2(dims::GLOSSY_SENDERS + 2 * level);
        let Some(wi) = scene.sample_cosine(x, wo, u) else {
            return sky;
        };
        w.stats.gather_rays += 1;
        // With density cos θ/π the estimate of (1/π) ∫ L cos dω is L.
        let Some(xd) = scene.intersect(x.point, wi) else {
            return sky + miss_emission(scene, x.point, wi, kernel(wi), Spectrum::splat(1.0));
        };
        let back = -wi;
        let through = scene.through(&xd);
        let mut e = Spectrum::zero();
        if correct {
            let Caches { pixel, scratch } = &mut *w.caches;
            let near = pixel.coarse_near();
            if let Some(c) = scene.near_correction(&xd, back, near, scratch, w.stats) {
                w.stats.near_corrections += 1;
                e += c;
            }
        }
        if self.glossy_scene && scene.is_glossy(&xd, back) {
            let g = if level == 0 {
                self.glossy(&xd, back, 1, w)
            } else {
                scene.reflected_glossy(&xd, x)
            };
            e += g;
        }
        sky + e * through
    }

    /// The glossy part of the reflected radiance at `x` towards `wo`, at
    /// gather `level`: one light sample and one BSDF-sampled gather ray,
    /// MIS-combined, each weighting fr_glossy.
    fn glossy<const N: usize>(
        &self,
        x: &SurfacePoint<S::Locator>,
        wo: DVec3,
        level: u32,
        w: &mut Walk<'_, N>,
    ) -> Spectrum<N>
    where
        S: SolutionGather<N>,
    {
        let scene = self.scene;
        let base = dims::GATHER + level * dims::PER_LEVEL;
        let (pick, u) = (w.sampler.get1(base), w.sampler.get2(base + 1));
        let fr = |wi| scene.glossy_cos(x, wi, wo);
        let mut l = light_sample(scene, x, wo, pick, u, fr, true, w.stats);
        l += punctual_direct(scene, x, fr, w.stats);
        let Some(bs) = scene.sample_bsdf(x, wo, w.sampler.get2(base + 3)) else {
            return l;
        };
        if bs.pdf.is_nan() || bs.pdf <= 0.0 {
            return l;
        }
        let f = scene.glossy_cos(x, bs.wi, wo);
        if f.is_black() {
            return l;
        }
        w.stats.gather_rays += 1;
        let weight = f * (1.0 / bs.pdf);
        let Some(xd) = scene.intersect(x.point, bs.wi) else {
            return l + miss_emission(scene, x.point, bs.wi, bs.pdf, weight);
        };
        let back = -bs.wi;
        let weight = weight * scene.through(&xd);
        if let Some(le) = hit_emission(scene, &xd, back, bs.pdf, weight) {
            l += le;
        }
        let lr = self.reflected_at(&xd, x, back, level + 1, w);
        l + weight * lr
    }

    /// The reflected radiance leaving a gather hit `xd` towards `x` (in
    /// direction `towards`), at gather `level`: the link sum at xd times
    /// ρ_d(xd) and xd's own glossy part, or, deeper than
    /// [`LINK_LEVELS`], the solution's own reading.
    fn reflected_at<const N: usize>(
        &self,
        xd: &SurfacePoint<S::Locator>,
        x: &SurfacePoint<S::Locator>,
        towards: DVec3,
        level: u32,
        w: &mut Walk<'_, N>,
    ) -> Spectrum<N>
    where
        S: SolutionGather<N>,
    {
        let scene = self.scene;
        if level > LINK_LEVELS {
            return scene.reflected(xd, x);
        }
        let Some(mut lambertian) =
            lambertian_at(scene, xd, towards, &mut w.caches.scratch, w.stats)
        else {
            return scene.reflected(xd, x);
        };
        let rho = scene.diffuse_albedo(xd, towards);
        if !rho.is_black() {
            let e_g = self.cosine_ray(xd, towards, level, w);
            lambertian += rho * e_g;
        }
        let glossy = if scene.is_glossy(xd, towards) {
            self.glossy(xd, towards, level, w)
        } else {
            Spectrum::zero()
        };
        lambertian + glossy
    }
}

/// Incident samples per point of [`LinkGather::glossy_directions`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct IncidentSamples {
    /// BSDF-sampled gather rays.
    pub gather: u32,
    /// Light samples (shadow rays).
    pub light: u32,
    /// Read a gather hit's reflected light through its links (the full
    /// render's reading, one glossy level deeper); without, the solution's
    /// own radiance there (no link sum: many times cheaper, element-sized
    /// detail in reflections lost).
    pub links: bool,
}

/// The solid-angle density with which light sampling reaches the emitting
/// `xd` seen from direction `back` (0 where it cannot).
fn light_density<S: SolutionGather<N>, const N: usize>(
    scene: &S,
    xd: &SurfacePoint<S::Locator>,
    back: DVec3,
) -> f64 {
    let cos_d = xd.normal.dot(back).abs();
    let pdf_area = scene.light_pdf_area(xd);
    if pdf_area > 0.0 && cos_d > 0.0 {
        pdf_area * xd.t * xd.t / cos_d
    } else {
        0.0
    }
}

/// A point sampled on an emitter from `x` and visible from it: the unit
/// direction to it, its radiance and the solid-angle density.
fn unoccluded_light<S: SolutionGather<N>, const N: usize>(
    scene: &S,
    x: &SurfacePoint<S::Locator>,
    pick: f64,
    u: glam::DVec2,
    stats: &mut GatherStats,
) -> Option<(DVec3, Spectrum<N>, f64)> {
    let ls = scene.sample_light(x, pick, u)?;
    let d = ls.point - x.point;
    let dist2 = d.length_squared();
    let dist = dist2.sqrt();
    if dist <= 0.0 || ls.radiance.is_black() {
        return None;
    }
    let cos_light = ls.normal.dot(-d / dist);
    if !(cos_light > 0.0 && ls.pdf_area > 0.0) {
        return None;
    }
    stats.shadow_rays += 1;
    let tau = scene.transmittance(x, ls.point);
    if tau <= 0.0 {
        return None;
    }
    Some((d / dist, ls.radiance * tau, ls.pdf_area * dist2 / cos_light))
}

/// A sky sample at `x` drawn with `u`: its direction, its radiance times
/// the panes' fraction and its solid-angle density (`None` without a sky,
/// or hidden).
fn unoccluded_sky<S: SolutionGather<N>, const N: usize>(
    scene: &S,
    x: &SurfacePoint<S::Locator>,
    u: DVec2,
    stats: &mut GatherStats,
) -> Option<(DVec3, Spectrum<N>, f64)> {
    let s = scene.sample_sky(x, u)?;
    if !(s.pdf > 0.0 && s.pdf.is_finite()) || s.radiance.is_black() {
        return None;
    }
    stats.shadow_rays += 1;
    let tau = scene.transmittance(x, s.end);
    (tau > 0.0).then(|| (s.wi, s.radiance * tau, s.pdf))
}

/// ρ_d(xd) times the link sum at `xd` with the links' own visibility
/// (`None` where the scene has no links).
fn lambertian_at<S: SolutionGather<N>, const N: usize>(
    scene: &S,
    xd: &SurfacePoint<S::Locator>,
    towards: DVec3,
    scratch: &mut LinkCache<N>,
    stats: &mut GatherStats,
) -> Option<Spectrum<N>> {
    let rho = scene.diffuse_albedo(xd, towards);
    if rho.is_black() {
        return Some(Spectrum::zero());
    }
    scene
        .solution_irradiance(xd, towards, LinkVisibility::Secondary, scratch, stats)
        .map(|e| rho * e)
}
