//! The solution as a control variate: an unbiased estimator whatever the
//! solution's error (Szirmay-Kalos, Csonka & Antal 2001; docs/rendering.md,
//! "The control variate").
//!
//! A camera ray meets the scene at x_s. With ω sampled from the BSDF
//! (density p), x_d(ω) the first hit along ω and w(ω) = fr·cos/p, the
//! reflected radiance towards the eye is
//!
//! L_r(x_s) = L_direct + E_ω[w L_r(x_d → x_s)]
//!          = L_direct + E_ω[w L̃(x_d → x_s)] + E_ω[w (L_r − L̃)(x_d → x_s)],
//!
//! L̃ the solution's reflected radiance at the gather hit (exactly
//! `GatherScene::reflected`, a pure function of the two points). Each
//! camera sample estimates
//!
//! - L_direct by one light sample and the BSDF ray's emission, MIS-combined;
//! - the **control** E[w L̃] by M BSDF-sampled *lookup* rays ω_0..ω_{M−1},
//!   each a ray and one solution lookup, averaged;
//! - the **residual** E[w (L_r − L̃)] along ω_0 alone: a path traced from
//!   x_d(ω_0) (light sampling, MIS, Russian roulette) less L̃ there.
//!
//! The control and the subtracted term are the same function of ω under the
//! same density, so their expectations are equal and the sum's expectation
//! is the true L_r: a solution scaled by 0.5 (or zero) changes the
//! variance, never the mean. With M = 1 the estimator is the path tracer;
//! each further lookup costs one ray and replaces the first bounce's
//! directional noise by the solution's, 1/M of it.
//!
//! Being unbiased whatever L̃ is, it also honours a limit on path length
//! (Mitsuba's `max_depth`) that the solution, which carries every bounce,
//! cannot: the path and the direct terms stop at the limit and the lookups,
//! added and subtracted alike, still cancel in the mean.

use glam::{DVec2, DVec3};
use trilux_color::Spectrum;

use crate::mis::{eye_hit, hit_emission, light_sample, miss_emission, punctual_direct, sky_seen};
use crate::records::{BsdfSample, GatherStats, SurfacePoint};
use crate::sampler::{PixelSampler, dims};
use crate::scene::GatherScene;

/// The most lookup rays per camera sample (their sample dimensions).
pub const MAX_LOOKUPS: u32 = 32;

/// Lookup rays per camera sample by default. Not the best at equal time:
/// on the Cornell box and paper-scene1, M = 1 (the plain path tracer) was
/// (docs/results.md, "The control variate"); 4 shows the control's effect
/// per sample.
pub const DEFAULT_LOOKUPS: u32 = 4;

/// Path vertices (from the camera hit, which is vertex 1) before Russian
/// roulette starts.
const RR_DEPTH: u32 = 3;

/// Highest survival probability under Russian roulette.
const RR_MAX: f64 = 0.95;

/// A hard stop on path length: reached with probability below 0.95^250
/// (about 3e-6) under Russian roulette, so its bias is far below any
/// reference's noise; it guards against a cycle of lossless bounces.
const MAX_VERTICES: u32 = 256;

/// The control-variate estimator (module docs).
pub struct ControlVariate<'a, S> {
    /// The scene and its solution.
    pub scene: &'a S,
    /// M, the lookup rays per camera sample (1..=[`MAX_LOOKUPS`]).
    pub lookups: u32,
    /// The longest path counted, in segments from the eye (Mitsuba's
    /// `max_depth`); `None`: every length.
    pub max_depth: Option<u32>,
    /// Camera rays that meet an emitter count as misses
    /// (`RenderSettings::hide_emitters`).
    pub hide_emitters: bool,
}

impl<S> ControlVariate<'_, S> {
    /// Radiance arriving at the eye along a camera ray (one sample).
    pub fn camera_sample<const N: usize>(
        &self,
        origin: DVec3,
        dir: DVec3,
        sampler: &PixelSampler,
        stats: &mut GatherStats,
    ) -> Spectrum<N>
    where
        S: GatherScene<N>,
    {
        stats.camera_rays += 1;
        if self.max_depth == Some(0) {
            return Spectrum::zero();
        }
        let Some(xs) = eye_hit(self.scene, origin, dir, self.hide_emitters) else {
            return sky_seen(self.scene, origin, dir, self.hide_emitters);
        };
        let wo = -dir;
        let mut l = self.scene.emitted(&xs, wo);
        if self.max_depth.is_none_or(|d| d >= 2) {
            l += self.reflected(&xs, wo, sampler, stats);
        }
        stats.finite_or_dropped(l * self.scene.through(&xs))
    }

    /// Reflected radiance leaving the camera hit `xs` towards `wo`: direct
    /// light, the control's lookups and the residual path (module docs).
    fn reflected<const N: usize>(
        &self,
        xs: &SurfacePoint<S::Locator>,
        wo: DVec3,
        sampler: &PixelSampler,
        stats: &mut GatherStats,
    ) -> Spectrum<N>
    where
        S: GatherScene<N>,
    {
        let scene = self.scene;
        let base = dims::GATHER;
        let (pick, u) = (sampler.get1(base), sampler.get2(base + 1));
        let fr = |wi| scene.bsdf_cos(xs, wi, wo);
        let mut l = light_sample(scene, xs, wo, pick, u, fr, true, stats);
        l += punctual_direct(scene, xs, fr, stats);
        let m = self.lookups.clamp(1, MAX_LOOKUPS);
        // Lookups 1..M: the control's other terms, w L̃ each.
        let mut control = Spectrum::zero();
        for j in 1..m {
            let u = sampler.get2(dims::CONTROL_LOOKUPS + 2 * (j - 1));
            if let Some((bs, Some(xd))) = self.gather_ray(xs, wo, u, stats) {
                control += bs.weight * scene.reflected(&xd, xs);
            }
        }
        // Lookup 0, shared with the residual: w L̃ (1/M of the control)
        // less w L̃ (the residual's subtracted term), plus w L_r by a path.
        let (bs, xd) = match self.gather_ray(xs, wo, sampler.get2(base + 3), stats) {
            Some((bs, Some(xd))) => (bs, xd),
            // A ray that leaves the scene brings the sky, and nothing
            // reflected.
            Some((bs, None)) => {
                let sky = miss_emission(scene, xs.point, bs.wi, bs.pdf, bs.weight);
                return l + sky + control * (1.0 / f64::from(m));
            }
            None => return l + control * (1.0 / f64::from(m)),
        };
        let back = -bs.wi;
        if let Some(le) = hit_emission(scene, &xd, back, bs.pdf, bs.weight) {
            l += le;
        }
        let own = scene.reflected(&xd, xs);
        let path = self.path(xd, back, bs.weight, sampler, stats);
        let lookups = (control + bs.weight * own) * (1.0 / f64::from(m));
        l + lookups + path - bs.weight * own
    }

    /// A direction sampled from the BSDF at `x` with `u` and the hit it
    /// leads to (`None` when the ray leaves the scene); `None` when the
    /// sample yields nothing.
    #[allow(clippy::type_complexity)]
    fn gather_ray<const N: usize>(
        &self,
        x: &SurfacePoint<S::Locator>,
        wo: DVec3,
        u: DVec2,
        stats: &mut GatherStats,
    ) -> Option<(BsdfSample<N>, Option<SurfacePoint<S::Locator>>)>
    where
        S: GatherScene<N>,
    {
        let mut bs = self.scene.sample_bsdf(x, wo, u)?;
        if bs.pdf.is_nan() || bs.pdf <= 0.0 || bs.weight.is_black() {
            return None;
        }
        stats.gather_rays += 1;
        let xd = self.scene.intersect(x.point, bs.wi);
        if let Some(xd) = &xd {
            // What panes of glass on the way let through.
            bs.weight *= self.scene.through(xd);
        }
        Some((bs, xd))
    }

    /// β times the reflected radiance leaving `x` (vertex 2 of the path)
    /// towards `wo`, path-traced: at each vertex a light sample and a BSDF
    /// ray whose emission is MIS-weighted, Russian roulette from vertex
    /// [`RR_DEPTH`] on. Vertex k's light sample and the emission its BSDF
    /// ray meets both end paths of k + 1 segments, so under a `max_depth` D
    /// the walk stops before vertex D (as Mitsuba's path integrator does).
    fn path<const N: usize>(
        &self,
        mut x: SurfacePoint<S::Locator>,
        mut wo: DVec3,
        mut beta: Spectrum<N>,
        sampler: &PixelSampler,
        stats: &mut GatherStats,
    ) -> Spectrum<N>
    where
        S: GatherScene<N>,
    {
        let scene = self.scene;
        let mut l = Spectrum::zero();
        let end = self.max_depth.map_or(MAX_VERTICES, |d| d.min(MAX_VERTICES));
        for vertex in 2..end {
            let base = dims::PATH + (vertex - 2) * dims::PER_PATH_VERTEX;
            if vertex >= RR_DEPTH {
                let q = beta.max_value().min(RR_MAX);
                if q.is_nan() || q <= 0.0 || sampler.get1(base + 5) >= q {
                    break;
                }
                beta *= 1.0 / q;
            }
            let (pick, u) = (sampler.get1(base), sampler.get2(base + 1));
            let fr = |wi| scene.bsdf_cos(&x, wi, wo);
            l += beta * light_sample(scene, &x, wo, pick, u, fr, true, stats);
            l += beta * punctual_direct(scene, &x, fr, stats);
            let Some((bs, xn)) = self.gather_ray(&x, wo, sampler.get2(base + 3), stats) else {
                break;
            };
            beta *= bs.weight;
            let Some(xn) = xn else {
                l += miss_emission(scene, x.point, bs.wi, bs.pdf, beta);
                break;
            };
            let back = -bs.wi;
            if let Some(le) = hit_emission(scene, &xn, back, bs.pdf, beta) {
                l += le;
            }
            (x, wo) = (xn, back);
        }
        l
    }
}
