//! The records the final gather passes between a scene and its estimators
//! (Mitsuba 3 keeps its in `records.h`): a hit ([`SurfacePoint`]), a point
//! sampled on a light ([`LightSample`]), a direction sampled from a BSDF
//! ([`BsdfSample`]), a corner where the preview fits glossy light
//! ([`FitSite`]), how a link sum treats partial visibility
//! ([`LinkVisibility`]) and the counters of a render ([`GatherStats`]).
//!
//! A leaf: it names no estimator and no scene, so that the scene traits
//! (`scene`) and every estimator can name it.

use glam::DVec3;
use trilux_color::Spectrum;

use crate::sampler::PixelSampler;

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

/// A point where the preview fits the glossy light (a corner of the leaf
/// element around a hit), its weight in the hit's interpolation and the
/// key that names it in the scene (`link_gather`'s fit cache; it also
/// seeds the fit's samples).
#[derive(Clone, Copy, Debug)]
pub struct FitSite<L> {
    /// The corner as a surface point (`t` zero).
    pub point: SurfacePoint<L>,
    /// Its interpolation weight at the hit (the weights of a hit's sites
    /// sum to 1).
    pub weight: f64,
    /// The same number for the same corner seen from any element sharing
    /// it, on the same side; a different one for every other.
    pub key: FitKey,
}

/// What names a fitted corner ([`FitSite::key`]): the shape, the side,
/// the position and the shading normal rounded to f32 (so that elements
/// sharing a corner share its fit, and a crease keeps one per normal).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct FitKey {
    /// Index of the scene shape.
    pub shape: u32,
    /// True on the back side.
    pub back: bool,
    /// The position's coordinates as f32 bits (−0 as +0).
    pub position: [u32; 3],
    /// The unit shading normal's coordinates as f32 bits.
    pub normal: [u32; 3],
}

impl FitKey {
    /// The key of a corner of `shape` at `position` with unit shading
    /// normal `normal`, on the back side or not.
    pub fn new(shape: u32, back: bool, position: DVec3, normal: DVec3) -> Self {
        let bits = |v: DVec3| v.as_vec3().to_array().map(|x| (x + 0.0).to_bits());
        FitKey {
            shape,
            back,
            position: bits(position),
            normal: bits(normal),
        }
    }

    /// A 64-bit number of the key (FNV-1a over its words: the same on
    /// every run and machine), to seed the fit's samples.
    pub fn seed(&self) -> u64 {
        let words = [self.shape, u32::from(self.back)]
            .into_iter()
            .chain(self.position)
            .chain(self.normal);
        words.fold(0xcbf2_9ce4_8422_2325, |h, w| {
            (h ^ u64::from(w)).wrapping_mul(0x0100_0000_01b3)
        })
    }
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
    pub radiance: Spectrum<N>,
    /// Density of this point with respect to area, including the
    /// probability of having picked its emitter.
    pub pdf_area: f64,
}

/// The light a light without area brings to a point (a delta: it is
/// never sampled by density nor met by a ray).
#[derive(Clone, Copy, Debug)]
pub struct PunctualSample<const N: usize> {
    /// Unit direction from the point towards the light.
    pub wi: DVec3,
    /// Where a shadow ray towards it ends (the light, or beyond the scene
    /// for a directional light).
    pub end: DVec3,
    /// Irradiance on a plane facing the light (I falloff / r², or E).
    pub irradiance: Spectrum<N>,
}

/// A direction sampled on the sky (an environment map) from a point.
#[derive(Clone, Copy, Debug)]
pub struct SkyRay<const N: usize> {
    /// Unit direction from the point towards the sky.
    pub wi: DVec3,
    /// Where a shadow ray towards it ends (beyond the scene).
    pub end: DVec3,
    /// Radiance arriving from `wi`.
    pub radiance: Spectrum<N>,
    /// Solid-angle density of `wi`.
    pub pdf: f64,
}

/// A direction sampled from a BSDF at a surface point.
#[derive(Clone, Copy, Debug)]
pub struct BsdfSample<const N: usize> {
    /// Unit incident direction (towards where light comes from), world space.
    pub wi: DVec3,
    /// fr(ω_i, ω_o)·|cos θ_i| / pdf.
    pub weight: Spectrum<N>,
    /// Density of `wi` w.r.t. solid angle.
    pub pdf: f64,
}

/// How the link sum at a point resolves partial visibility.
#[derive(Clone, Copy, Debug)]
pub enum LinkVisibility<'a> {
    /// The visible fraction the solve measured for each link.
    Cached,
    /// As `Cached`, and near senders taken at their link's level without
    /// the near field's cut: for gather hits, whose error reaches the eye
    /// weighted by a reflection.
    Secondary,
    /// Shadow rays from the point to samples of each partly visible
    /// sender, drawn from `sampler` from dimension `dim` on.
    Traced {
        /// The pixel's sample sequence.
        sampler: &'a PixelSampler,
        /// First dimension the rays may use.
        dim: u32,
    },
}

/// Counters of one render.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[non_exhaustive]
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
    /// `l` if it is finite, else zero, counted as dropped (one sample's
    /// NaN or infinity must not poison a pixel).
    pub(crate) fn finite_or_dropped<const N: usize>(&mut self, l: Spectrum<N>) -> Spectrum<N> {
        if l.is_finite() {
            l
        } else {
            self.dropped += 1;
            Spectrum::zero()
        }
    }

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
