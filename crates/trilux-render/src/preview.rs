//! The preview estimator, [`Preview`]: no random rays at the pixel
//! (`link_gather`'s module docs, docs/rendering.md, "The preview").

use glam::DVec3;
use trilux_color::Spectrum;

use crate::glossy_fit::GlossyFits;
use crate::glossy_irradiance::GlossyIrradiance;
use crate::link_gather::Caches;
use crate::mis::eye_hit;
use crate::records::{GatherStats, LinkVisibility};
use crate::scene::SolutionGather;

/// The preview estimator: no random rays (module docs).
pub struct Preview<'a, S> {
    /// The scene and its solution.
    pub scene: &'a S,
    /// Camera rays that meet an emitter count as misses
    /// (`RenderSettings::hide_emitters`).
    pub hide_emitters: bool,
    /// The glossy light's fits, made as hits need them.
    pub fits: GlossyFits,
    /// E_g, the light glossy senders reflect onto Lambertian parts, per
    /// corner, made as hits need it.
    pub glossy_senders: GlossyIrradiance,
}

impl<S> Preview<'_, S> {
    /// Radiance arriving at the eye along a camera ray, without random
    /// rays.
    pub fn camera_sample<const N: usize>(
        &self,
        origin: DVec3,
        dir: DVec3,
        caches: &mut Caches<N>,
        stats: &mut GatherStats,
    ) -> Spectrum<N>
    where
        S: SolutionGather<N>,
    {
        stats.camera_rays += 1;
        let scene = self.scene;
        let Some(xs) = eye_hit(scene, origin, dir, self.hide_emitters) else {
            return Spectrum::zero();
        };
        let wo = -dir;
        let through = scene.through(&xs);
        let mut l = scene.emitted(&xs, wo);
        let rho = scene.diffuse_albedo(&xs, wo);
        if !rho.is_black()
            && let Some(e) =
                scene.solution_irradiance(&xs, wo, LinkVisibility::Cached, &mut caches.pixel, stats)
        {
            let e_g = if scene.has_glossy_faces() {
                self.glossy_senders.at(scene, &xs, wo, stats)
            } else {
                Spectrum::zero()
            };
            l += rho * (e + e_g);
        }
        if scene.is_glossy(&xs, wo) {
            l += self.fits.radiance(scene, &xs, wo, stats);
        }
        stats.finite_or_dropped(l * through)
    }
}
