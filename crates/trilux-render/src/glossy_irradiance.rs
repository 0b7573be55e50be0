//! The preview's E_g: the light glossy senders reflect onto a Lambertian
//! point, which the solution's gather links do not hold (`link_gather`,
//! module docs; the link gather traces a cosine ray per sample for it).
//!
//! Without it the preview missed, on diffuse surfaces, all light that
//! reached them by a glossy reflection: 14 % of paper-scene2's diffuse
//! pixels (its glossy cylinder lights the floor), 63 % of the glossy
//! tube's (docs/results.md, "The preview"). It is read as the bake reads
//! light, at corners: at each corner of the hit's leaf element
//! ([`SolutionGather::fit_sites`]) the mean over [`COSINE_RAYS`]
//! cosine-distributed rays of the glossy radiance the solution stores
//! where a ray meets a glossy part (`reflected_glossy`, the link gather's
//! own reading below the camera hit), E_g = (1/K) Σ L_g (the density cos θ/π
//! cancels the cosine and the 1/π of a Lambertian reflection), then
//! interpolated with the hit's weights. Made once per corner, seeded by
//! the corner's key, shared by the threads ([`CornerCache`]): no noise
//! from pixel to pixel, the same image whatever the threads' order.

use glam::DVec3;
use trilux_color::Spectrum;

use crate::glossy_fit::{CornerCache, fit_sampler};
use crate::records::{FitSite, GatherStats, SurfacePoint};
use crate::sampler::dims;
use crate::scene::SolutionGather;

/// Cosine rays per corner.
pub const COSINE_RAYS: u32 = 64;

/// The preview's E_g per corner (module docs), in bands.
#[derive(Default)]
pub struct GlossyIrradiance {
    cache: CornerCache<Vec<f64>>,
}

impl GlossyIrradiance {
    /// E_g at the Lambertian `at` on the side of `wo` (zero where the
    /// scene gives no corners).
    pub fn at<S: SolutionGather<N>, const N: usize>(
        &self,
        scene: &S,
        at: &SurfacePoint<S::Locator>,
        wo: DVec3,
        stats: &mut GatherStats,
    ) -> Spectrum<N> {
        let mut e = Spectrum::zero();
        for site in scene.fit_sites(at, wo) {
            let bands = self
                .cache
                .get_or_make(site.key, || corner(scene, &site, stats).0.to_vec());
            e += Spectrum::from_fn(|b| bands.get(b).copied().unwrap_or(0.0)) * site.weight;
        }
        e
    }

    /// Corners estimated so far.
    pub fn len(&self) -> usize {
        self.cache.len()
    }

    /// True before the first corner.
    pub fn is_empty(&self) -> bool {
        self.cache.is_empty()
    }
}

/// E_g at one corner: [`COSINE_RAYS`] cosine rays on its side.
fn corner<S: SolutionGather<N>, const N: usize>(
    scene: &S,
    site: &FitSite<S::Locator>,
    stats: &mut GatherStats,
) -> Spectrum<N> {
    glossy_irradiance_at(scene, &site.point, site.key.back, site.key.seed(), stats)
}

/// E_g at the Lambertian point `x` on its back side when `back`, else its
/// front (module docs): [`COSINE_RAYS`] cosine rays drawn from the
/// sequence `seed` names. The bake reads its vertices' light with it.
pub fn glossy_irradiance_at<S: SolutionGather<N>, const N: usize>(
    scene: &S,
    x: &SurfacePoint<S::Locator>,
    back: bool,
    seed: u64,
    stats: &mut GatherStats,
) -> Spectrum<N> {
    let up = x.normal * if back { -1.0 } else { 1.0 };
    let mut sampler = fit_sampler(seed);
    let mut sum = Spectrum::zero();
    for k in 0..COSINE_RAYS {
        sampler.start_sample(k);
        let Some(wi) = scene.sample_cosine(x, up, sampler.get2(dims::GLOSSY_SENDERS)) else {
            continue;
        };
        stats.gather_rays += 1;
        let Some(xd) = scene.intersect(x.point, wi) else {
            continue;
        };
        if scene.is_glossy(&xd, -wi) {
            // Through any panes the ray crossed before x_d.
            sum += scene.reflected_glossy(&xd, x) * scene.through(&xd);
        }
    }
    sum * (1.0 / f64::from(COSINE_RAYS))
}
