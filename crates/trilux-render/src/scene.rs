//! What the final gather asks of a scene and its solution, in two traits
//! (pbrt-v4 keeps such interfaces apart from their implementations):
//!
//! - [`GatherScene`], the core: rays, emitters, the BSDF and the solution's
//!   reflected radiance. The path gather of paper §4.5 needs nothing else
//!   but the inputs of its extra-bounce rule, so an analytic scene written
//!   by hand can be rendered and checked against a closed form.
//! - [`SolutionGather`], what only a scene backed by a full solution
//!   provides: the solution's gather links and glossy radiance, the
//!   Lambertian albedo, element sizes and shading normals. Every method is
//!   required: a scene without links or glossy parts says so explicitly
//!   (`has_links` false, `is_glossy` false), so no estimator path is turned
//!   off by a default nobody chose.
//!
//! Directions are world-space unit vectors pointing *away* from the surface
//! point in question: `wo` towards the viewer, `wi` towards where light
//! comes from (trilux-brdf's convention).

use glam::{DVec2, DVec3};
use trilux_color::Spectrum;
use trilux_geometry::FaceElement;

use crate::link_sum::LinkCache;
use crate::records::{
    BsdfSample, FitSite, GatherStats, LightSample, LinkVisibility, PunctualSample, SkyRay,
    SurfacePoint,
};

/// Everything the path gather needs from a scene and its solution.
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

    /// The fraction of light that goes from `to` to `from` along the
    /// segment: 1 where nothing lies between, 0 where something opaque
    /// does, between for surfaces that let light through (panes of glass).
    /// By default [`GatherScene::unoccluded`]'s 0 or 1.
    fn transmittance(&self, from: &SurfacePoint<Self::Locator>, to: DVec3) -> f64 {
        if self.unoccluded(from, to) { 1.0 } else { 0.0 }
    }

    /// The fraction of light that the surfaces a ray crossed before it met
    /// `at` ([`GatherScene::intersect`] goes through those that let light
    /// through) let through: everything leaving `at` towards the ray's
    /// origin arrives times this. By default 1 (no such surfaces).
    fn through(&self, _at: &SurfacePoint<Self::Locator>) -> f64 {
        1.0
    }

    /// Radiance emitted from `at` in direction `wo` (zero if `at` is not on
    /// an emitter or `wo` leaves its back side).
    fn emitted(&self, at: &SurfacePoint<Self::Locator>, wo: DVec3) -> Spectrum<N>;

    /// Samples a point on an emitter as seen from `reference`; `pick` picks
    /// the emitter, `u` the point on it. `None` when there is nothing to
    /// sample.
    fn sample_light(
        &self,
        reference: &SurfacePoint<Self::Locator>,
        pick: f64,
        u: DVec2,
    ) -> Option<LightSample<N>>;

    /// The number of lights without area (point, spot, directional).
    fn punctual_count(&self) -> usize;

    /// The light that light `k` without area brings to `reference`
    /// (`None` where it brings none, as outside a spot's cone).
    fn punctual_at(
        &self,
        k: usize,
        reference: &SurfacePoint<Self::Locator>,
    ) -> Option<PunctualSample<N>>;

    /// The sky's radiance arriving at `from` from unit direction `wi` (a
    /// ray from `from` that leaves the scene), times what the surfaces it
    /// went through let through (panes of glass), and the solid-angle
    /// density with which [`GatherScene::sample_sky`] draws `wi`; zero and
    /// zero without a sky.
    fn sky(&self, from: DVec3, wi: DVec3) -> (Spectrum<N>, f64);

    /// A direction drawn from the sky's distribution with `u`, as seen
    /// from `reference`; `None` without a sky.
    fn sample_sky(&self, reference: &SurfacePoint<Self::Locator>, u: DVec2) -> Option<SkyRay<N>>;

    /// The area density [`GatherScene::sample_light`] has at `at` (zero when
    /// `at` is not on an emitter).
    fn light_pdf_area(&self, at: &SurfacePoint<Self::Locator>) -> f64;

    /// fr(ω_i, ω_o)·|cos θ_i| at `at` (cosine with the shading normal).
    fn bsdf_cos(&self, at: &SurfacePoint<Self::Locator>, wi: DVec3, wo: DVec3) -> Spectrum<N>;

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
    ) -> Spectrum<N>;

    /// Solid angle (sr) of the BSDF lobe at `at` for viewer direction `wo`;
    /// 2π for a diffuse surface.
    fn lobe_solid_angle(&self, at: &SurfacePoint<Self::Locator>, wo: DVec3) -> f64;
}

/// What a scene backed by a full solution adds to [`GatherScene`]: the
/// inputs of the extra-bounce rule, and the solution's links and glossy
/// radiance that the link gather and the preview read. No method has a
/// default.
pub trait SolutionGather<const N: usize>: GatherScene<N> {
    /// Linear size (√area) of the solution's element that contains `at`.
    fn element_size(&self, at: &SurfacePoint<Self::Locator>) -> f64;

    /// True where the shading normal differs from the geometric one
    /// (smooth-shaded meshes): the solution's radiance there was computed
    /// with the geometric normal, the BSDF's with the shading normal.
    fn shading_differs(&self, at: &SurfacePoint<Self::Locator>) -> bool;

    /// True when the scene's solution has gather links (else the link
    /// gather hands every sample to the path gather).
    fn has_links(&self) -> bool;

    /// True when some face of the scene has a glossy part.
    fn has_glossy_faces(&self) -> bool;

    /// The density cos θ/π with which [`SolutionGather::sample_cosine`]
    /// draws `wi` at `at` for the viewer direction `wo` (zero where it
    /// cannot), the kernel of the Lambertian part's irradiance.
    fn cosine_pdf(&self, at: &SurfacePoint<Self::Locator>, wo: DVec3, wi: DVec3) -> f64;

    /// The Lambertian part's reflectance ρ_d at `at` on the side of `wo`
    /// (zero where there is none).
    fn diffuse_albedo(&self, at: &SurfacePoint<Self::Locator>, wo: DVec3) -> Spectrum<N>;

    /// The radiance arriving at `at` (on the side of `wo`) from the
    /// solution's senders, Σ_i L_i F(x → i) V(x, i), so that ρ_d times it
    /// is the Lambertian reflected radiance (`link_gather`), reusing what
    /// `cache` holds for the same leaf; `None` when the scene has no
    /// solution links to gather.
    fn solution_irradiance(
        &self,
        at: &SurfacePoint<Self::Locator>,
        wo: DVec3,
        visibility: LinkVisibility<'_>,
        cache: &mut LinkCache<N>,
        stats: &mut GatherStats,
    ) -> Option<Spectrum<N>>;

    /// Where the gather hit `at` (seen from `wo`) lies in one of
    /// `coarse_near`, the senders a link sum took at their average close to
    /// its point: the Lambertian radiance there from the link sum at `at`
    /// less the average the links give that sender, so that a cosine ray's
    /// mean corrects the average (`link_gather`, near-field correction).
    /// `None` elsewhere.
    fn near_correction(
        &self,
        at: &SurfacePoint<Self::Locator>,
        wo: DVec3,
        coarse_near: &[FaceElement],
        cache: &mut LinkCache<N>,
        stats: &mut GatherStats,
    ) -> Option<Spectrum<N>>;

    /// True when the BSDF at `at` has a glossy part on the side of `wo`.
    fn is_glossy(&self, at: &SurfacePoint<Self::Locator>, wo: DVec3) -> bool;

    /// The part of [`GatherScene::bsdf_cos`] beyond the Lambertian ρ_d/π,
    /// (fr − ρ_d/π)·|cos θ_i|: the glossy part, and for plastics also their
    /// base term's departure from Lambertian (which may be negative).
    fn glossy_cos(&self, at: &SurfacePoint<Self::Locator>, wi: DVec3, wo: DVec3) -> Spectrum<N>;

    /// For one incident `wi` at `at` and every one of `wos`:
    /// [`SolutionGather::glossy_cos`] into `glossy`, and the mean over
    /// `wos` of [`GatherScene::bsdf_pdf`] returned. A scene may resolve
    /// the material (its textures) once for all of them.
    fn glossy_fan(
        &self,
        at: &SurfacePoint<Self::Locator>,
        wi: DVec3,
        wos: &[DVec3],
        glossy: &mut Vec<Spectrum<N>>,
    ) -> f64 {
        glossy.clear();
        glossy.extend(wos.iter().map(|&wo| self.glossy_cos(at, wi, wo)));
        let sum: f64 = wos.iter().map(|&wo| self.bsdf_pdf(at, wo, wi)).sum();
        sum / wos.len().max(1) as f64
    }

    /// The solution's reflected radiance at `from` towards `towards`
    /// without its Lambertian part (the stored glossy radiance).
    fn reflected_glossy(
        &self,
        from: &SurfacePoint<Self::Locator>,
        towards: &SurfacePoint<Self::Locator>,
    ) -> Spectrum<N>;

    /// A direction sampled with density cos θ/π about the normal on the
    /// side of `wo` (the Lambertian part's importance), `None` below the
    /// surface.
    fn sample_cosine(&self, at: &SurfacePoint<Self::Locator>, wo: DVec3, u: DVec2)
    -> Option<DVec3>;

    /// Where the preview fits the glossy light around `at` seen from `wo`
    /// (`glossy_fit`): the corners of the leaf element containing `at`
    /// (of the triangle of its mesh piece, or of its (u, v) rectangle)
    /// with `at`'s barycentric or bilinear weights, on the side of `wo`.
    /// Empty where the scene has no elements to fit at.
    fn fit_sites(&self, at: &SurfacePoint<Self::Locator>, wo: DVec3)
    -> Vec<FitSite<Self::Locator>>;
}
