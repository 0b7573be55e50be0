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
//!    ([`BsdfSample::weight`]; Eq. 7 is the special case fr·cos/p = ρ). At its
//!    hit x_d:
//!    - the **emitted** radiance Le(x_d → x_s) counts with the BSDF-sampling
//!      MIS weight (light sampling supplies the rest with its own weight);
//!    - the **reflected** radiance comes from the solution with weight 1.
//!
//! Emitters seen directly from the eye show their radiance.
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
//! through [`GatherScene`], so the estimator is tested on analytic mock
//! scenes and wired to trilux's geometry, BRDFs and solver by an adapter.

use glam::{DVec2, DVec3};

use crate::bands;
use crate::sampler::{PixelSampler, dims};

/// Where a ray met a surface.
#[derive(Clone, Copy, Debug)]
pub struct SurfacePoint<L> {
    /// The hit point in world space.
    pub point: DVec3,
    /// Unit geometric normal of the surface's front side.
    pub normal: DVec3,
    /// Distance along the ray.
    pub t: f64,
    /// What the scene needs to find this point's material, emitter and
    /// solution elements again (for trilux: surface id and surface coordinate).
    pub locator: L,
}

/// A point sampled on an emitter for light sampling.
#[derive(Clone, Copy, Debug)]
pub struct LightSample<const N: usize> {
    /// The point on the emitter.
    pub point: DVec3,
    /// Unit front normal of the emitter at the point.
    pub normal: DVec3,
    /// Emitted radiance from `point` towards the reference point (zero when
    /// the reference lies behind the emitter).
    pub radiance: [f64; N],
    /// Density of this point with respect to area, including the
    /// probability of having picked its emitter.
    pub pdf_area: f64,
}

/// A direction sampled from a BSDF at a surface point.
#[derive(Clone, Copy, Debug)]
pub struct BsdfSample<const N: usize> {
    /// Unit incident direction (towards where light comes from), world space.
    pub wi: DVec3,
    /// fr(ω_i, ω_o)·|cos θ_i| / pdf.
    pub weight: [f64; N],
    /// Density of `wi` w.r.t. solid angle.
    pub pdf: f64,
}

/// A gather hit whose BSDF lobe subtends less than this solid angle (sr)
/// is near-specular: the path continues through it instead of reading the
/// solution there ([`FinalGather::gather`]; a roughconductor lobe of
/// roughness α subtends about 4πα², so this is α below about 0.056;
/// docs/rendering.md, "Near-specular surfaces").
pub const NEAR_SPECULAR_SR: f64 = 0.04;

/// The most gather levels a path continues through near-specular hits
/// (a closed mirror box reflects a path until it meets the light; after
/// this many levels the solution is read).
pub const MAX_SPECULAR_LEVELS: u32 = 48;

/// When to continue a gather path one bounce before reading the solution.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
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

/// Everything the final gather needs from a scene and its solution.
///
/// Directions are world-space unit vectors pointing *away* from the surface
/// point in question: `wo` towards the viewer, `wi` towards where light
/// comes from (trilux-brdf's convention).
pub trait GatherScene<const N: usize>: Sync {
    /// Identifies a surface point for the scene (materials, solution lookup).
    type Locator: Copy + Send + Sync;

    /// Closest hit along the ray from `origin` in unit direction `dir`;
    /// the scene offsets or otherwise avoids re-hitting the surface that
    /// `origin` lies on.
    fn intersect(&self, origin: DVec3, dir: DVec3) -> Option<SurfacePoint<Self::Locator>>;

    /// True when nothing blocks the segment from `from` (a surface point) to
    /// `to` (a point on an emitter).
    fn unoccluded(&self, from: &SurfacePoint<Self::Locator>, to: DVec3) -> bool;

    /// Radiance emitted from `at` in direction `wo` (zero if `at` is not on
    /// an emitter or `wo` leaves its back side).
    fn emitted(&self, at: &SurfacePoint<Self::Locator>, wo: DVec3) -> [f64; N];

    /// Samples a point on an emitter as seen from `reference`; `pick` picks
    /// the emitter, `u` the point on it. `None` when there is nothing to
    /// sample.
    fn sample_light(
        &self,
        reference: &SurfacePoint<Self::Locator>,
        pick: f64,
        u: DVec2,
    ) -> Option<LightSample<N>>;

    /// The area density [`GatherScene::sample_light`] has at `at` (zero when
    /// `at` is not on an emitter).
    fn light_pdf_area(&self, at: &SurfacePoint<Self::Locator>) -> f64;

    /// fr(ω_i, ω_o)·|cos θ_i| at `at` (cosine with the shading normal).
    fn bsdf_cos(&self, at: &SurfacePoint<Self::Locator>, wi: DVec3, wo: DVec3) -> [f64; N];

    /// Samples ω_i from fr·cos at `at` for the viewer direction `wo`.
    fn sample_bsdf(
        &self,
        at: &SurfacePoint<Self::Locator>,
        wo: DVec3,
        u: DVec2,
    ) -> Option<BsdfSample<N>>;

    /// The density [`GatherScene::sample_bsdf`] has for `wi`.
    fn bsdf_pdf(&self, at: &SurfacePoint<Self::Locator>, wo: DVec3, wi: DVec3) -> f64;

    /// The solution: radiance *reflected* (emission excluded) at `from`
    /// (x_d) towards `towards` (x_s).
    fn reflected(
        &self,
        from: &SurfacePoint<Self::Locator>,
        towards: &SurfacePoint<Self::Locator>,
    ) -> [f64; N];

    /// Linear size (√area) of the solution's element that contains `at`.
    fn element_size(&self, at: &SurfacePoint<Self::Locator>) -> f64;

    /// Solid angle (sr) of the BSDF lobe at `at` for viewer direction `wo`;
    /// 2π for a diffuse surface.
    fn lobe_solid_angle(&self, at: &SurfacePoint<Self::Locator>, wo: DVec3) -> f64;

    /// True where the shading normal differs from the geometric one
    /// (smooth-shaded meshes): the solution's radiance there was computed
    /// with the geometric normal, the BSDF's with the shading normal.
    fn shading_differs(&self, _at: &SurfacePoint<Self::Locator>) -> bool {
        false
    }

    /// The Lambertian part's reflectance ρ_d at `at` on the side of `wo`
    /// (zero where there is none).
    fn diffuse_albedo(&self, _at: &SurfacePoint<Self::Locator>, _wo: DVec3) -> [f64; N] {
        [0.0; N]
    }

    /// The radiance arriving at `at` (on the side of `wo`) from the
    /// solution's senders, Σ_i L_i F(x → i) V(x, i), so that ρ_d times it
    /// is the Lambertian reflected radiance (`link_gather`), reusing what
    /// `cache` holds for the same leaf; `None` when the scene has no
    /// solution links to gather.
    fn solution_irradiance(
        &self,
        _at: &SurfacePoint<Self::Locator>,
        _wo: DVec3,
        _visibility: crate::link_gather::LinkVisibility<'_>,
        _cache: &mut crate::link_sum::LinkCache<N>,
        _stats: &mut GatherStats,
    ) -> Option<[f64; N]> {
        None
    }

    /// Where the gather hit `at` (seen from `wo`) lies in one of
    /// `coarse_near`, the senders a link sum took at their average close to
    /// its point: the Lambertian radiance there from the link sum at `at`
    /// less the average the links give that sender, so that a cosine ray's
    /// mean corrects the average (`link_gather`, near-field correction).
    /// `None` elsewhere.
    fn near_correction(
        &self,
        _at: &SurfacePoint<Self::Locator>,
        _wo: DVec3,
        _coarse_near: &[trilux_geometry::FaceElement],
        _cache: &mut crate::link_sum::LinkCache<N>,
        _stats: &mut GatherStats,
    ) -> Option<[f64; N]> {
        None
    }

    /// True when the BSDF at `at` has a glossy part on the side of `wo`.
    fn is_glossy(&self, _at: &SurfacePoint<Self::Locator>, _wo: DVec3) -> bool {
        false
    }

    /// The glossy part fr_glossy(ω_i, ω_o)·|cos θ_i| of [`Self::bsdf_cos`].
    fn glossy_cos(&self, _at: &SurfacePoint<Self::Locator>, _wi: DVec3, _wo: DVec3) -> [f64; N] {
        [0.0; N]
    }

    /// The solution's reflected radiance at `from` towards `towards`
    /// without its Lambertian part (the stored glossy radiance).
    fn reflected_glossy(
        &self,
        _from: &SurfacePoint<Self::Locator>,
        _towards: &SurfacePoint<Self::Locator>,
    ) -> [f64; N] {
        [0.0; N]
    }

    /// A direction sampled with density cos θ/π about the normal on the
    /// side of `wo` (the Lambertian part's importance), `None` below the
    /// surface.
    fn sample_cosine(
        &self,
        _at: &SurfacePoint<Self::Locator>,
        _wo: DVec3,
        _u: DVec2,
    ) -> Option<DVec3> {
        None
    }

    /// True when some face of the scene has a glossy part.
    fn has_glossy_faces(&self) -> bool {
        false
    }

    /// True when the scene's solution has gather links (else the link
    /// gather hands every sample to the path gather).
    fn has_links(&self) -> bool {
        false
    }

    /// The mirror direction of `wo` about the shading normal at `at` and
    /// the glossy part's directional albedo there (for previews).
    fn mirror(&self, _at: &SurfacePoint<Self::Locator>, _wo: DVec3) -> Option<(DVec3, [f64; N])> {
        None
    }
}

/// The power heuristic (β = 2) weight of a strategy with density `a`
/// against one with density `b`.
pub fn power_heuristic(a: f64, b: f64) -> f64 {
    let a2 = a * a;
    let b2 = b * b;
    if a2 + b2 > 0.0 && (a2 + b2).is_finite() {
        a2 / (a2 + b2)
    } else if a.is_infinite() {
        1.0
    } else {
        0.0
    }
}

/// Counters of one render.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct GatherStats {
    /// Camera rays traced.
    pub camera_rays: u64,
    /// Gather rays traced (all levels).
    pub gather_rays: u64,
    /// Shadow rays traced.
    pub shadow_rays: u64,
    /// Gather hits that continued one bounce instead of reading the solution.
    pub extra_bounces: u64,
    /// Samples dropped because a value was not finite (should stay 0).
    pub dropped: u64,
    /// Senders of gather links evaluated (point form factors).
    pub link_senders: u64,
    /// Cosine rays that corrected a near sender's average.
    pub near_corrections: u64,
}

impl GatherStats {
    /// Adds another set of counters.
    pub fn add(&mut self, o: &GatherStats) {
        self.camera_rays += o.camera_rays;
        self.gather_rays += o.gather_rays;
        self.shadow_rays += o.shadow_rays;
        self.extra_bounces += o.extra_bounces;
        self.dropped += o.dropped;
        self.link_senders += o.link_senders;
        self.near_corrections += o.near_corrections;
    }
}

/// The final-gather estimator for one scene.
pub struct FinalGather<'a, S> {
    /// The scene and its solution.
    pub scene: &'a S,
    /// The extra-bounce rule.
    pub extra: ExtraBounce,
}

impl<'a, S> FinalGather<'a, S> {
    /// Radiance arriving at the eye along a camera ray (one sample).
    pub fn camera_sample<const N: usize>(
        &self,
        origin: DVec3,
        dir: DVec3,
        sampler: &PixelSampler,
        stats: &mut GatherStats,
    ) -> [f64; N]
    where
        S: GatherScene<N>,
    {
        stats.camera_rays += 1;
        let Some(xs) = self.scene.intersect(origin, dir) else {
            return bands::zero();
        };
        let wo = -dir;
        let le = self.scene.emitted(&xs, wo);
        let lr = self.gather(&xs, wo, 0, sampler, stats);
        let l = bands::add(le, lr);
        if bands::is_finite(&l) {
            l
        } else {
            stats.dropped += 1;
            bands::zero()
        }
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
    ) -> [f64; N]
    where
        S: GatherScene<N>,
    {
        let scene = self.scene;
        let base = if level < dims::GATHER_LEVELS {
            dims::GATHER
        } else {
            dims::DEEP_GATHER
        } + level * dims::PER_LEVEL;
        let mut l = bands::zero::<N>();

        // 1. Light sampling with a shadow ray.
        if let Some(ls) = scene.sample_light(x, sampler.get1(base), sampler.get2(base + 1)) {
            let d = ls.point - x.point;
            let dist2 = d.length_squared();
            let dist = dist2.sqrt();
            let cos_light = if dist > 0.0 {
                ls.normal.dot(-d / dist)
            } else {
                0.0
            };
            if cos_light > 0.0 && ls.pdf_area > 0.0 && !bands::is_black(&ls.radiance) {
                let wi = d / dist;
                let f = scene.bsdf_cos(x, wi, wo);
                if !bands::is_black(&f) {
                    stats.shadow_rays += 1;
                    if scene.unoccluded(x, ls.point) {
                        let pdf_light = ls.pdf_area * dist2 / cos_light;
                        let w = power_heuristic(pdf_light, scene.bsdf_pdf(x, wo, wi));
                        l = bands::add(l, bands::scale(bands::mul(f, ls.radiance), w / pdf_light));
                    }
                }
            }
        }

        // 2. A gather ray sampled from the BSDF.
        let Some(bs) = scene.sample_bsdf(x, wo, sampler.get2(base + 3)) else {
            return l;
        };
        if bs.pdf.is_nan() || bs.pdf <= 0.0 || bands::is_black(&bs.weight) {
            return l;
        }
        stats.gather_rays += 1;
        let Some(xd) = scene.intersect(x.point, bs.wi) else {
            return l;
        };
        let back = -bs.wi;
        // Emission at the gather hit, with the BSDF-sampling MIS weight.
        let le = scene.emitted(&xd, back);
        if !bands::is_black(&le) {
            let cos_d = xd.normal.dot(back).abs();
            let pdf_area = scene.light_pdf_area(&xd);
            let w = if pdf_area > 0.0 && cos_d > 0.0 {
                power_heuristic(bs.pdf, pdf_area * xd.t * xd.t / cos_d)
            } else {
                1.0
            };
            l = bands::add(l, bands::scale(bands::mul(bs.weight, le), w));
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
        bands::add(l, bands::mul(bs.weight, lr))
    }

    /// The extra-bounce rule: would the piecewise-constant solution show here?
    fn wants_extra_bounce<const N: usize>(
        &self,
        xs: &SurfacePoint<S::Locator>,
        wo: DVec3,
        xd: &SurfacePoint<S::Locator>,
    ) -> bool
    where
        S: GatherScene<N>,
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
