//! The preview's glossy light: the directional bake's representation,
//! read at a hit (docs/rendering.md, "The preview").
//!
//! The bake stores per vertex of a glossy side the glossy radiance
//! L_g(x, ω_o) as order-2 spherical harmonics plus one spherical Gaussian
//! (`trilux_geometry::glossy_fit`), fitted to [`FIT_DIRECTIONS`]
//! directions over the hemisphere whose values the link gather estimates
//! from one set of incident samples ([`LinkGather::glossy_directions`]);
//! a viewer interpolates the fitted coefficients across each triangle and
//! evaluates them towards the eye, clamped at zero. The preview does the
//! same at every glossy hit: [`fit_point`] (the one function both call,
//! with the same estimator, counts, directions and fitting code) at the
//! corners of the hit's leaf element ([`SolutionGather::fit_sites`]), the
//! records interpolated with the hit's weights, then evaluated towards
//! the eye. So `--preview` and the viewer agree up to the samples' noise
//! and the tessellation (the bake's display cells are finer than a
//! leaf on curved surfaces).
//!
//! Fits are made once per corner and kept ([`GlossyFits`]): lazily, at
//! the first hit that needs them, shared by all threads (a corner being
//! fitted makes the others wait for it, not fit it again), and seeded by
//! the corner's key alone ([`FitKey::seed`]), so the image is the same
//! whatever the threads' order: noise-free as the rest of the preview.

use std::collections::HashMap;
use std::hash::{BuildHasher, BuildHasherDefault, DefaultHasher};
use std::sync::{Arc, Mutex, OnceLock};

use glam::DVec3;
use trilux_color::Spectrum;
use trilux_color::upsample::smooth_emission;
use trilux_geometry::glossy_fit::lobe::{fit_lobe, lobe_eval};
use trilux_geometry::glossy_fit::sh::{GlossyRecord, SLOTS, hemisphere_directions};
use trilux_geometry::glossy_fit::{FIT_DIRECTIONS, FIT_GATHER_SAMPLES, FIT_LIGHT_SAMPLES};

use crate::gather::{ExtraBounce, FinalGather};
use crate::link_gather::{Caches, IncidentSamples, LinkGather};
use crate::records::{FitKey, FitSite, GatherStats, SurfacePoint};
use crate::sampler::PixelSampler;
use crate::scene::SolutionGather;

/// The incident samples of a fit by default: the bake's
/// (`trilux_geometry::glossy_fit`), gather hits read from the solution.
pub const FIT_SAMPLES: IncidentSamples = IncidentSamples {
    gather: FIT_GATHER_SAMPLES,
    light: FIT_LIGHT_SAMPLES,
    links: false,
};

/// The sample sequence of the fit seeded by `seed` (a corner's
/// [`FitKey::seed`], a bake vertex's key).
pub fn fit_sampler(seed: u64) -> PixelSampler {
    // The seed folds into the sampler's two indices.
    let (lo, hi) = (seed as u32, (seed >> 32) as u32);
    PixelSampler::new(hi ^ 0x9e37_79b9, lo, 0)
}

/// The glossy light at the surface point `x` on the side of the unit
/// normal `side_normal`, fitted (module docs): the link gather's estimate
/// towards `directions` directions spread over that hemisphere, from
/// `counts` incident samples drawn from `sampler`, in linear Rec. 709,
/// fitted as harmonics plus a lobe. `None` when there are too few
/// directions to fit.
pub fn fit_point<S: SolutionGather<N>, const N: usize>(
    gather: &LinkGather<'_, S>,
    x: &SurfacePoint<S::Locator>,
    side_normal: DVec3,
    (counts, directions): (IncidentSamples, usize),
    sampler: &mut PixelSampler,
    stats: &mut GatherStats,
) -> Option<GlossyRecord> {
    let dirs = hemisphere_directions(side_normal, directions);
    let mut caches = Caches::<N>::default();
    let values: Vec<[f64; 3]> = gather
        .glossy_directions(x, &dirs, counts, sampler, &mut caches, stats)
        .iter()
        .map(Spectrum::to_linear_srgb)
        .collect();
    fit_lobe(&dirs, &values)
}

/// A value per fitted corner, made once at the first call that needs it
/// and shared by the threads (module docs): the preview's glossy fits,
/// and its glossy senders' irradiance (`glossy_irradiance`).
pub struct CornerCache<T> {
    shards: Vec<Mutex<HashMap<FitKey, Arc<OnceLock<T>>>>>,
}

/// Lock shards of a corner cache (threads filling different corners
/// rarely wait for each other).
const SHARDS: usize = 64;

impl<T> Default for CornerCache<T> {
    fn default() -> Self {
        CornerCache {
            shards: (0..SHARDS).map(|_| Mutex::default()).collect(),
        }
    }
}

impl<T: Clone> CornerCache<T> {
    /// The value of corner `key`, made by `make` at the first call (a
    /// caller asking for a corner being made waits for it).
    pub fn get_or_make(&self, key: FitKey, make: impl FnOnce() -> T) -> T {
        let hasher = BuildHasherDefault::<DefaultHasher>::default();
        let shard = (hasher.hash_one(key) % SHARDS as u64) as usize;
        let slot = {
            let mut map = self.shards[shard]
                .lock()
                .unwrap_or_else(std::sync::PoisonError::into_inner);
            Arc::clone(map.entry(key).or_default())
        };
        slot.get_or_init(make).clone()
    }

    /// Corners made or being made.
    pub fn len(&self) -> usize {
        self.shards
            .iter()
            .map(|s| s.lock().map_or(0, |m| m.len()))
            .sum()
    }

    /// True before the first corner.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// The preview's fits, per corner (module docs).
pub struct GlossyFits {
    counts: IncidentSamples,
    directions: usize,
    cache: CornerCache<Option<GlossyRecord>>,
}

impl Default for GlossyFits {
    /// The bake's counts and directions.
    fn default() -> Self {
        Self::new(FIT_SAMPLES, FIT_DIRECTIONS)
    }
}

impl GlossyFits {
    /// An empty cache whose fits take `counts` incident samples towards
    /// `directions` directions each.
    pub fn new(counts: IncidentSamples, directions: usize) -> Self {
        GlossyFits {
            counts,
            directions,
            cache: CornerCache::default(),
        }
    }

    /// Corners fitted so far.
    pub fn len(&self) -> usize {
        self.cache.len()
    }

    /// True before the first fit.
    pub fn is_empty(&self) -> bool {
        self.cache.is_empty()
    }

    /// The glossy radiance leaving `at` towards `wo` as a viewer shows the
    /// bake's: the fits at `at`'s sites interpolated, evaluated towards
    /// `wo` and clamped at zero (where the scene gives no site, a fit at
    /// `at` itself).
    pub fn radiance<S: SolutionGather<N>, const N: usize>(
        &self,
        scene: &S,
        at: &SurfacePoint<S::Locator>,
        wo: DVec3,
        stats: &mut GatherStats,
    ) -> Spectrum<N> {
        let mut mixed: GlossyRecord = [[0.0; 3]; SLOTS];
        let sites = scene.fit_sites(at, wo);
        if sites.is_empty() {
            // No elements: a fit at the hit itself, not kept.
            let back = at.normal.dot(wo) < 0.0;
            let site = FitSite {
                point: *at,
                weight: 1.0,
                key: FitKey::new(u32::MAX, back, at.point, at.normal),
            };
            mixed = self.fit(scene, &site, stats).unwrap_or(mixed);
        }
        for site in &sites {
            if let Some(record) = self.record(scene, site, stats) {
                for (m, r) in mixed.iter_mut().zip(record) {
                    for ch in 0..3 {
                        m[ch] += site.weight * r[ch];
                    }
                }
            }
        }
        let rgb = lobe_eval(&mixed, wo).map(|x| if x > 0.0 { x } else { 0.0 });
        if N == 3 {
            Spectrum::from_fn(|c| rgb[c])
        } else {
            smooth_emission(rgb)
        }
    }

    /// The fit at `site`, made at the first call.
    fn record<S: SolutionGather<N>, const N: usize>(
        &self,
        scene: &S,
        site: &FitSite<S::Locator>,
        stats: &mut GatherStats,
    ) -> Option<GlossyRecord> {
        self.cache
            .get_or_make(site.key, || self.fit(scene, site, stats))
    }

    /// A fit at `site`, uncached.
    fn fit<S: SolutionGather<N>, const N: usize>(
        &self,
        scene: &S,
        site: &FitSite<S::Locator>,
        stats: &mut GatherStats,
    ) -> Option<GlossyRecord> {
        let gather = LinkGather {
            scene,
            fallback: FinalGather {
                scene,
                extra: ExtraBounce::default(),
                hide_emitters: false,
            },
            glossy_scene: true,
        };
        let x = &site.point;
        let side = if site.key.back { -1.0 } else { 1.0 };
        let mut sampler = fit_sampler(site.key.seed());
        let sizes = (self.counts, self.directions);
        fit_point(&gather, x, x.normal * side, sizes, &mut sampler, stats)
    }
}
