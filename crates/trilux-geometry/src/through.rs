//! Segments and rays through surfaces that let light through
//! ([`crate::transmission`]): visibility as a fraction, not 0 or 1.
//!
//! [`Geometry::transmittance`] walks a segment from one end to the other,
//! hit by hit in order along it, and multiplies the fractions τ(cos θ) of
//! the transmitting surfaces it crosses, each at its own angle; an opaque
//! hit makes it 0. A geometry without transmitting shapes answers by the
//! one occlusion query, 0 or 1, as [`Geometry::occluded`] does.
//! [`Geometry::intersect_through`] finds the first opaque hit of a ray and
//! the product of the fractions it crossed on its way there.
//!
//! A mask ([`Transmittance::Cutout`], [`Transmittance::Constant`]) is
//! partly a surface: where its opacity α(u, v) is 1 a ray stops on it,
//! where α is 0 it passes. A segment (visibility) takes the expected
//! fraction 1 − α at each crossing. A ray that looks for what it sees
//! ([`Geometry::intersect_through`]) does what Mitsuba's `mask` does, with
//! a choice made by a hash of the crossing (its point and the ray): it
//! stops there with probability α, its weight divided by α, and passes
//! with probability 1 − α. The surface reflects L_mask = α L_nested (the
//! loader's `blendbsdf` of black and the nested BSDF, weight α), so the
//! expected light the ray brings back is
//! (1 − α) L_behind + α · (1/α) · α L_nested = (1 − α) L_behind + α L_nested.
//! Where α is 0 or 1 the choice is certain: a binary cut-out is exact.

use glam::DVec3;

use crate::geometry::{Geometry, Hit, Ray};
use crate::transmission::Transmittance;

/// The most transmitting surfaces one query crosses; a segment crossing
/// more counts as blocked (no plausible scene stacks more panes).
pub const MAX_CROSSINGS: u32 = 64;

impl Geometry {
    /// Lets a fraction of the light through some shapes: `by_shape[i]`
    /// for shape `i` (shapes beyond the list and `None`s are opaque).
    pub fn set_transmission(&mut self, by_shape: &[Option<Transmittance>]) {
        self.transmitters = if by_shape.iter().any(Option::is_some) {
            by_shape.to_vec()
        } else {
            Vec::new()
        };
    }

    /// True when some shape lets light through.
    pub fn has_transmission(&self) -> bool {
        !self.transmitters.is_empty()
    }

    /// The transmittance of `shape`, if it lets light through.
    pub fn shape_transmittance(&self, shape: u32) -> Option<&Transmittance> {
        self.transmitters
            .get(shape as usize)
            .and_then(Option::as_ref)
    }

    /// The fraction of light that goes from `p` to `q` (1: nothing
    /// between; 0: something opaque), ends ignored as in
    /// [`Geometry::occluded`].
    pub fn transmittance(&self, p: DVec3, q: DVec3) -> f64 {
        self.transmittance_hint(p, q, &mut None)
    }

    /// [`Geometry::transmittance`] with the occlusion hint of
    /// [`Geometry::occluded_hint`] (used when no shape transmits).
    pub fn transmittance_hint(&self, p: DVec3, q: DVec3, hint: &mut Option<u32>) -> f64 {
        if !self.has_transmission() {
            return if self.occluded_hint(p, q, hint) {
                0.0
            } else {
                1.0
            };
        }
        let Some((ray, tmin, tmax)) = self.segment_interval(p, q) else {
            return 1.0;
        };
        match self.walk(&ray, tmin, tmax, Crossing::Expected) {
            (None, tau) => tau,
            (Some(_), _) => 0.0,
        }
    }

    /// The first opaque hit along `ray` within `t_max`, and the fraction of
    /// light the transmitting surfaces before it let through (the product
    /// over them; 1 when there are none). A cut-out stops the ray or lets
    /// it pass by a choice (module docs); where it stops it, the weight
    /// holds 1/α.
    pub fn intersect_through(&self, ray: &Ray, t_max: f64) -> Option<(Hit, f64)> {
        if !self.has_transmission() {
            return self.intersect(ray, t_max).map(|h| (h, 1.0));
        }
        let tmin = self.ray_tmin(ray)?;
        match self.walk(ray, tmin, t_max, Crossing::Chosen) {
            (Some(h), tau) => Some((h, tau)),
            (None, _) => None,
        }
    }

    /// [`Geometry::intersect_ignoring`] that also goes through every
    /// shape that lets light through: the first opaque hit of another
    /// shape than `shape` (the burial probes: a pane in front of a face
    /// does not cover it, the light passes).
    pub fn intersect_opaque_ignoring(&self, ray: &Ray, t_max: f64, shape: u32) -> Option<Hit> {
        if !self.has_transmission() {
            return self.intersect_ignoring(ray, t_max, shape);
        }
        let len = ray.dir.length();
        let mut tmin = self.ray_tmin(ray)?;
        for _ in 0..MAX_CROSSINGS {
            let (hit, s) = self.closest_ignoring(ray, tmin, t_max, shape)?;
            if self.shape_transmittance(s).is_none() {
                return Some(hit);
            }
            tmin = hit.t + self.epsilon_at(hit.point) / len;
        }
        None
    }

    /// Hits along `ray` in order from `tmin` to `tmax`: the first opaque
    /// one (if any) and the product of the transmittances crossed before
    /// it; a cut-out crossed as `crossing` says (module docs). More than
    /// [`MAX_CROSSINGS`] crossings count as zero light.
    fn walk(&self, ray: &Ray, mut tmin: f64, tmax: f64, crossing: Crossing) -> (Option<Hit>, f64) {
        let len = ray.dir.length();
        let mut tau = 1.0;
        for _ in 0..MAX_CROSSINGS {
            let Some((hit, shape)) = self.closest_in(ray, tmin, tmax) else {
                return (None, tau);
            };
            let Some(tr) = self.shape_transmittance(shape) else {
                return (Some(hit), tau);
            };
            let uv = || self.texcoord(hit.surface, hit.coord);
            let cos = hit.geometric_normal.dot(ray.dir).abs() / len;
            match (tr, crossing) {
                (Transmittance::Cutout(_) | Transmittance::Constant(_), Crossing::Chosen) => {
                    let alpha = 1.0 - tr.at_point(cos, uv);
                    if alpha > 0.0 && (alpha >= 1.0 || choice(ray, &hit) < alpha) {
                        return (Some(hit), tau / alpha);
                    }
                }
                _ => tau *= tr.at_point(cos, uv),
            }
            if tau <= 0.0 {
                return (None, 0.0);
            }
            // Past this surface: its own epsilon beyond the hit.
            tmin = hit.t + self.epsilon_at(hit.point) / len;
        }
        (None, 0.0)
    }
}

/// How a walk crosses a cut-out (module docs).
#[derive(Clone, Copy, PartialEq, Eq)]
enum Crossing {
    /// The expected fraction 1 − α (a segment's visibility).
    Expected,
    /// Stop with probability α, weight 1/α; else pass (a ray's hit).
    Chosen,
}

/// A number in [0, 1) decided by the crossing: the bits of the ray and of
/// the hit point mixed (SplitMix64's finaliser over each word).
fn choice(ray: &Ray, hit: &Hit) -> f64 {
    let words = [
        ray.origin.x,
        ray.origin.y,
        ray.origin.z,
        ray.dir.x,
        ray.dir.y,
        ray.dir.z,
        hit.point.x,
        hit.point.y,
        hit.point.z,
    ];
    let mut h = 0x9e37_79b9_7f4a_7c15u64;
    for w in words {
        h ^= w.to_bits();
        h = h.wrapping_add(0x9e37_79b9_7f4a_7c15);
        h = (h ^ (h >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        h = (h ^ (h >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        h ^= h >> 31;
    }
    (h >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}
