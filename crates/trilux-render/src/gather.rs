//! Final gathering (paper §4.5, Fig. 11).
//!
//! A ray from the eye meets the scene at x_s. The radiance leaving x_s
//! towards the eye is
//!
//! L(x_s → eye) = Le(x_s → eye) + ∫ fr(ω_i, ω_o) L_in(x_s, ω_i) cos θ_i dω_i,
//!
//! and the paper's Eq. 7 estimates the integral with gather rays sampled from
//! fr·cos: a gather ray that meets the scene at x_d brings the radiance
//! leaving x_d towards x_s, which the view-independent **solution** knows
//! (the deepest node of hierarchy BA containing x_d and x_s). Here each
//! camera sample traces
//!
//! 1. one **light sample**: a point on an emitter, chosen by the scene, with
//!    a shadow ray; its contribution fr·cos·Le / p_light is weighted by the
//!    power heuristic against the BSDF's density;
//! 2. one **gather ray** sampled from the BSDF, weighted fr·cos/p_bsdf
//!    ([`crate::records::BsdfSample::weight`]; Eq. 7 is the special case fr·cos/p = ρ). At its
//!    hit x_d:
//!    - the **emitted** radiance Le(x_d → x_s) counts with the BSDF-sampling
//!      MIS weight (light sampling supplies the rest with its own weight);
//!    - the **reflected** radiance comes from the solution with weight 1.
//!
//! Emitters seen directly from the eye show their radiance. The sky (an
//! environment map, at infinity) is sampled beside the emitters, and a
//! gather ray that leaves the scene brings its radiance, MIS-weighted
//! (`crate::mis`).
//!
//! **Extra bounce.** The solution is piecewise constant over elements. Its
//! steps would show where a gather hit is close to x_s compared with the
//! size of the element it hits (corners), or where the BSDF lobe at x_s is
//! narrower than the solid angle that element subtends (near-mirrors). There
//! the reflected radiance at x_d is estimated by the same gather one level
//! deeper (light sampling + one gather ray whose hit reads the solution)
//! instead of by the solution itself ([`ExtraBounce`]).
//!
//! The scene, its materials, its emitters and the solution are reached only
//! through the traits of [`crate::scene`], so the estimator is tested on
//! analytic mock scenes and wired to trilux's geometry, BRDFs and solver by
//! an adapter ([`crate::solved`]).

use glam::DVec3;

use crate::mis::{eye_hit, hit_emission, light_sample, miss_emission, punctual_direct, sky_seen};
use crate::records::{GatherStats, SurfacePoint};
use crate::sampler::{PixelSampler, dims};
use crate::scene::SolutionGather;
use trilux_color::Spectrum;

/// A gather hit whose BSDF lobe subtends less than this solid angle (sr)
/// is near-specular: the path continues through it instead of reading the
/// solution there (`FinalGather::gather`; a roughconductor lobe of
/// roughness α subtends about 4πα², so this is α below about 0.056;
/// docs/rendering.md, "Near-specular surfaces").
pub(crate) const NEAR_SPECULAR_SR: f64 = 0.04;

/// The most gather levels a path continues through near-specular hits
/// (a closed mirror box reflects a path until it meets the light; after
/// this many levels the solution is read).
pub(crate) const MAX_SPECULAR_LEVELS: u32 = 48;

/// When to continue a gather path one bounce before reading the solution.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[non_exhaustive]
pub enum ExtraBounce {
    /// Always read the solution at the first gather hit (the paper's §4.5).
    Never,
    /// Where the solution's steps would show: the gather hit is
    /// closer than `close_factor` × the linear size of the element it hit,
    /// the BSDF lobe at x_s subtends less than the element's solid angle, or
    /// the hit surface is glossy (its stored radiance is constant over whole
    /// receiving elements, a lobe there is not) or smooth-shaded (the
    /// solution reflects about geometric normals, the BSDF about shading
    /// normals).
    Auto {
        /// Distance threshold in units of the hit element's linear size.
        close_factor: f64,
    },
    /// At every gather hit: the solution is read one bounce later, which
    /// dilutes its remaining bias (the default; docs/results.md measures
    /// what it buys and costs).
    #[default]
    Always,
}

/// The final-gather estimator for one scene.
pub struct FinalGather<'a, S> {
    /// The scene and its solution.
    pub scene: &'a S,
    /// The extra-bounce rule.
    pub extra: ExtraBounce,
    /// Camera rays that meet an emitter count as misses
    /// (`RenderSettings::hide_emitters`).
    pub hide_emitters: bool,
}

impl<'a, S> FinalGather<'a, S> {
    /// Radiance arriving at the eye along a camera ray (one sample).
    pub fn camera_sample<const N: usize>(
        &self,
        origin: DVec3,
        dir: DVec3,
        sampler: &PixelSampler,
        stats: &mut GatherStats,
    ) -> Spectrum<N>
    where
        S: SolutionGather<N>,
    {
        stats.camera_rays += 1;
        let Some(xs) = eye_hit(self.scene, origin, dir, self.hide_emitters) else {
            return sky_seen(self.scene, origin, dir, self.hide_emitters);
        };
        let wo = -dir;
        let le = self.scene.emitted(&xs, wo);
        let lr = self.gather(&xs, wo, 0, sampler, stats);
        let l = (le + lr) * self.scene.through(&xs);
        stats.finite_or_dropped(l)
    }

    /// Reflected radiance leaving `x` towards `wo`: light sample + gather
    /// ray, MIS-combined; gather hits read the solution (level 0 may
    /// continue one bounce by the [`ExtraBounce`] rule).
    pub(crate) fn gather<const N: usize>(
        &self,
        x: &SurfacePoint<S::Locator>,
        wo: DVec3,
        level: u32,
        sampler: &PixelSampler,
        stats: &mut GatherStats,
    ) -> Spectrum<N>
    where
        S: SolutionGather<N>,
    {
        let scene = self.scene;
        let base = if level < dims::GATHER_LEVELS {
            dims::GATHER
        } else {
            dims::DEEP_GATHER
        } + level * dims::PER_LEVEL;
        // 1. Light sampling with a shadow ray.
        let (pick, u) = (sampler.get1(base), sampler.get2(base + 1));
        let fr = |wi| scene.bsdf_cos(x, wi, wo);
        let mut l = light_sample(scene, x, wo, pick, u, fr, true, stats);
        l += punctual_direct(scene, x, fr, stats);

        // 2. A gather ray sampled from the BSDF.
        let Some(bs) = scene.sample_bsdf(x, wo, sampler.get2(base + 3)) else {
            return l;
        };
        if bs.pdf.is_nan() || bs.pdf <= 0.0 || bs.weight.is_black() {
            return l;
        }
        stats.gather_rays += 1;
        let Some(xd) = scene.intersect(x.point, bs.wi) else {
            return l + miss_emission(scene, x.point, bs.wi, bs.pdf, bs.weight);
        };
        let back = -bs.wi;
        // What panes of glass on the way let through.
        let weight = bs.weight * scene.through(&xd);
        // Emission at the gather hit, with the BSDF-sampling MIS weight.
        if let Some(le) = hit_emission(scene, &xd, back, bs.pdf, weight) {
            l += le;
        }
        // Reflected radiance at the gather hit: the solution, or one more
        // bounce where its steps would show, or through a near-specular
        // hit (whose lobe the solution cannot resolve).
        let specular =
            level < MAX_SPECULAR_LEVELS && scene.lobe_solid_angle(&xd, back) < NEAR_SPECULAR_SR;
        let lr = if specular || (level == 0 && self.wants_extra_bounce(x, wo, &xd)) {
            stats.extra_bounces += 1;
            self.gather(&xd, back, level + 1, sampler, stats)
        } else {
            scene.reflected(&xd, x)
        };
        l + weight * lr
    }

    /// The extra-bounce rule: would the piecewise-constant solution show here?
    fn wants_extra_bounce<const N: usize>(
        &self,
        xs: &SurfacePoint<S::Locator>,
        wo: DVec3,
        xd: &SurfacePoint<S::Locator>,
    ) -> bool
    where
        S: SolutionGather<N>,
    {
        match self.extra {
            ExtraBounce::Never => false,
            ExtraBounce::Always => true,
            ExtraBounce::Auto { close_factor } => {
                let size = self.scene.element_size(xd);
                if xd.t < close_factor * size {
                    return true;
                }
                let dir = (xd.point - xs.point) / xd.t.max(1e-300);
                // A glossy hit: the solution's radiance towards x_s is
                // piecewise constant over whole receiving elements, which a
                // lobe narrower than a hemisphere varies across (the mirror
                // image of a lamp in a glossy floor, seen from the ceiling).
                if self.scene.lobe_solid_angle(xd, -dir) < 2.0 * std::f64::consts::PI
                    || self.scene.shading_differs(xd)
                {
                    return true;
                }
                let cos_d = xd.normal.dot(dir).abs();
                let element_sr = size * size * cos_d / (xd.t * xd.t);
                self.scene.lobe_solid_angle(xs, wo) < element_sr
            }
        }
    }
}
