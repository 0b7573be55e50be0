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
    pub fn shape_transmittance(&self, shape: u32) -> Option<Transmittance> {
        self.transmitters.get(shape as usize).copied().flatten()
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
        match self.walk(&ray, tmin, tmax) {
            (None, tau) => tau,
            (Some(_), _) => 0.0,
        }
    }

    /// The first opaque hit along `ray` within `t_max`, and the fraction of
    /// light the transmitting surfaces before it let through (the product
    /// over them; 1 when there are none).
    pub fn intersect_through(&self, ray: &Ray, t_max: f64) -> Option<(Hit, f64)> {
        if !self.has_transmission() {
            return self.intersect(ray, t_max).map(|h| (h, 1.0));
        }
        let tmin = self.ray_tmin(ray)?;
        match self.walk(ray, tmin, t_max) {
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
    /// it. More than [`MAX_CROSSINGS`] crossings count as zero light.
    fn walk(&self, ray: &Ray, mut tmin: f64, tmax: f64) -> (Option<Hit>, f64) {
        let len = ray.dir.length();
        let mut tau = 1.0;
        for _ in 0..MAX_CROSSINGS {
            let Some((hit, shape)) = self.closest_in(ray, tmin, tmax) else {
                return (None, tau);
            };
            let Some(tr) = self.shape_transmittance(shape) else {
                return (Some(hit), tau);
            };
            tau *= tr.at(hit.geometric_normal.dot(ray.dir).abs() / len);
            if tau <= 0.0 {
                return (None, 0.0);
            }
            // Past this surface: its own epsilon beyond the hit.
            tmin = hit.t + self.epsilon_at(hit.point) / len;
        }
        (None, 0.0)
    }
}
