//! The two halves of multiple importance sampling that both estimators
//! (the path gather, `gather`, and the link gather's glossy part,
//! `link_gather`) share, written once:
//!
//! - [`light_sample`]: a point sampled on an emitter with a shadow ray,
//!   fr·cos·Le / p_light weighted by the power heuristic against the BSDF's
//!   density (Veach 1997, §9.2);
//! - [`punctual_direct`]: the lights without area, by one shadow ray
//!   each (a delta light needs no MIS weight);
//! - [`hit_emission`]: the emission met by a BSDF-sampled ray, weighted by
//!   the power heuristic against light sampling's density at the hit;
//! - [`sky_sample`] and [`miss_emission`]: the same two halves for the sky
//!   (an environment map, a light at infinity sampled by direction): a
//!   sky direction with a shadow ray, and the sky a BSDF-sampled ray that
//!   leaves the scene brings. [`light_sample`] takes one sky sample beside
//!   its emitter sample, from the same two numbers (each is unbiased on
//!   its own, so their sum is).

use glam::{DVec2, DVec3};

use crate::records::{GatherStats, SurfacePoint};
use crate::scene::GatherScene;
use trilux_color::Spectrum;

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

/// One light sample at `x` for the viewer direction `wo`: the emitter
/// `pick` and the point `u` on it, its radiance times `fr(ω_i)` (the
/// BSDF's fr·|cos θ_i|, or a part of it) over the light's solid-angle
/// density, weighted by the power heuristic against BSDF sampling when
/// `mis`. Zero when the point is behind the emitter, at x, of zero density
/// or black, or hidden; a value that is not a number (the emitter's
/// cosine, the density) counts as zero. With a sky, one sky sample
/// ([`sky_sample`], from `u`) is added.
#[allow(clippy::too_many_arguments)]
pub fn light_sample<S: GatherScene<N>, const N: usize>(
    scene: &S,
    x: &SurfacePoint<S::Locator>,
    wo: DVec3,
    pick: f64,
    u: DVec2,
    fr: impl Fn(DVec3) -> Spectrum<N>,
    mis: bool,
    stats: &mut GatherStats,
) -> Spectrum<N> {
    let sky = sky_sample(scene, x, u, &fr, |wi| scene.bsdf_pdf(x, wo, wi), mis, stats);
    sky + emitter_sample(scene, x, wo, pick, u, fr, mis, stats)
}

/// [`light_sample`]'s sample of a point on an emitter.
#[allow(clippy::too_many_arguments)]
fn emitter_sample<S: GatherScene<N>, const N: usize>(
    scene: &S,
    x: &SurfacePoint<S::Locator>,
    wo: DVec3,
    pick: f64,
    u: DVec2,
    fr: impl Fn(DVec3) -> Spectrum<N>,
    mis: bool,
    stats: &mut GatherStats,
) -> Spectrum<N> {
    let Some(ls) = scene.sample_light(x, pick, u) else {
        return Spectrum::zero();
    };
    let d = ls.point - x.point;
    let dist2 = d.length_squared();
    let dist = dist2.sqrt();
    let cos_light = if dist > 0.0 {
        ls.normal.dot(-d / dist)
    } else {
        0.0
    };
    if !(cos_light > 0.0 && ls.pdf_area > 0.0) || ls.radiance.is_black() {
        return Spectrum::zero();
    }
    let wi = d / dist;
    let f = fr(wi);
    if f.is_black() {
        return Spectrum::zero();
    }
    stats.shadow_rays += 1;
    let tau = scene.transmittance(x, ls.point);
    if tau <= 0.0 {
        return Spectrum::zero();
    }
    let pdf_light = ls.pdf_area * dist2 / cos_light;
    let w = if mis {
        power_heuristic(pdf_light, scene.bsdf_pdf(x, wo, wi))
    } else {
        1.0
    };
    f * ls.radiance * (tau * w / pdf_light)
}

/// One sky sample at `x`: a direction drawn from the sky's distribution
/// with `u`, fr(ω_i) L / p_sky with a shadow ray, weighted by the power
/// heuristic against the density `other` of the strategy that also
/// reaches the sky (BSDF or cosine sampling) when `mis`. Zero without a
/// sky, where fr is black or the sky hidden.
pub fn sky_sample<S: GatherScene<N>, const N: usize>(
    scene: &S,
    x: &SurfacePoint<S::Locator>,
    u: DVec2,
    fr: impl Fn(DVec3) -> Spectrum<N>,
    other: impl FnOnce(DVec3) -> f64,
    mis: bool,
    stats: &mut GatherStats,
) -> Spectrum<N> {
    let Some(s) = scene.sample_sky(x, u) else {
        return Spectrum::zero();
    };
    if !(s.pdf > 0.0 && s.pdf.is_finite()) || s.radiance.is_black() {
        return Spectrum::zero();
    }
    let f = fr(s.wi);
    if f.is_black() {
        return Spectrum::zero();
    }
    stats.shadow_rays += 1;
    let tau = scene.transmittance(x, s.end);
    if tau <= 0.0 {
        return Spectrum::zero();
    }
    let w = if mis {
        power_heuristic(s.pdf, other(s.wi))
    } else {
        1.0
    };
    f * s.radiance * (tau * w / s.pdf)
}

/// The sky a ray from `from` sampled with density `pdf` in direction `wi`
/// brings when it leaves the scene: L(ω) (through any panes) times the
/// sample's `weight`, weighted by the power heuristic against sky
/// sampling's density (zero without a sky).
pub fn miss_emission<S: GatherScene<N>, const N: usize>(
    scene: &S,
    from: DVec3,
    wi: DVec3,
    pdf: f64,
    weight: Spectrum<N>,
) -> Spectrum<N> {
    let (l, p_sky) = scene.sky(from, wi);
    if l.is_black() {
        return Spectrum::zero();
    }
    weight * l * power_heuristic(pdf, p_sky)
}

/// The direct light of every light without area at `x`: Σ fr(ω_i) E⊥ V
/// over the lights, `fr` the BSDF's fr·|cos θ_i| (or a part of it), one
/// shadow ray each (V the fraction it lets through, panes of glass
/// included). No MIS weight: a delta light has no density a BSDF
/// sample could share, and no ray ever meets it.
pub fn punctual_direct<S: GatherScene<N>, const N: usize>(
    scene: &S,
    x: &SurfacePoint<S::Locator>,
    fr: impl Fn(DVec3) -> Spectrum<N>,
    stats: &mut GatherStats,
) -> Spectrum<N> {
    let mut sum = Spectrum::zero();
    for k in 0..scene.punctual_count() {
        let Some(p) = scene.punctual_at(k, x) else {
            continue;
        };
        let f = fr(p.wi);
        if f.is_black() || p.irradiance.is_black() {
            continue;
        }
        stats.shadow_rays += 1;
        let tau = scene.transmittance(x, p.end);
        if tau > 0.0 {
            sum += f * p.irradiance * tau;
        }
    }
    sum
}

/// The sky a camera ray from `origin` that met nothing sees (black with
/// `hide_emitters`, which hides the sky in Mitsuba 3.9.1 too, or without
/// a sky).
pub(crate) fn sky_seen<S: GatherScene<N>, const N: usize>(
    scene: &S,
    origin: DVec3,
    dir: DVec3,
    hide_emitters: bool,
) -> Spectrum<N> {
    if hide_emitters {
        Spectrum::zero()
    } else {
        scene.sky(origin, dir).0
    }
}

/// Where a camera ray meets the scene. With `hide_emitters` (Mitsuba's
/// parameter) a ray that meets an emitting surface counts as a miss:
/// Mitsuba 3.9.1 renders it black, the light that surface reflects
/// included (measured on its Cornell box, docs/results.md).
pub(crate) fn eye_hit<S: GatherScene<N>, const N: usize>(
    scene: &S,
    origin: DVec3,
    dir: DVec3,
    hide_emitters: bool,
) -> Option<SurfacePoint<S::Locator>> {
    let xs = scene.intersect(origin, dir)?;
    let hidden = hide_emitters && scene.light_pdf_area(&xs) > 0.0;
    (!hidden).then_some(xs)
}

/// The emission a BSDF-sampled ray brings from its hit `xd` (seen from
/// direction `back`): Le times the sample's `weight` (fr·cos/pdf, or a part
/// of it), weighted by the power heuristic of the BSDF density `pdf`
/// against light sampling's density at `xd` (1 where light sampling cannot
/// reach it). `None` where `xd` does not emit towards the ray.
pub fn hit_emission<S: GatherScene<N>, const N: usize>(
    scene: &S,
    xd: &SurfacePoint<S::Locator>,
    back: DVec3,
    pdf: f64,
    weight: Spectrum<N>,
) -> Option<Spectrum<N>> {
    let le = scene.emitted(xd, back);
    if le.is_black() {
        return None;
    }
    let cos_d = xd.normal.dot(back).abs();
    let pdf_area = scene.light_pdf_area(xd);
    let w = if pdf_area > 0.0 && cos_d > 0.0 {
        power_heuristic(pdf, pdf_area * xd.t * xd.t / cos_d)
    } else {
        1.0
    };
    Some(weight * le * w)
}
