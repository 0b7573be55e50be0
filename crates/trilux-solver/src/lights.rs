//! Lights without area ([`PreparedLight`]: Mitsuba's `point`, `spot`,
//! `directional`, glTF's punctual lights) as the solver and the renderer
//! take them: intensity in bands, flux, the light reaching a point and
//! where its shadow ray ends. Their shot is `light_shot`'s
//! (docs/solver.md, "Lights without area").
//!
//! A light's flux Φ is 4π I for a point, I ∫ falloff dω for a spot and
//! E π R² over the scene's bounding sphere for a directional light, as
//! Mitsuba counts it.

use glam::DVec3;
use thiserror::Error;
use trilux_color::{ColorParam, Spectrum};
use trilux_geometry::{Arrival, Bounds, Geometry, Punctual};

/// A light without area, its intensity in the solve's bands.
#[derive(Clone, Debug, PartialEq)]
pub struct PreparedLight<const N: usize> {
    /// Where it is and how its intensity varies with direction.
    pub punctual: Punctual,
    /// Radiant intensity (W sr⁻¹; irradiance W m⁻² for a directional
    /// light) per band.
    pub intensity: Spectrum<N>,
}

/// A light whose intensity cannot be used in these bands.
#[derive(Debug, Error)]
#[error("light {index}: {problem}")]
pub struct LightError {
    /// Index of the light in the list given.
    pub index: usize,
    /// What is wrong.
    pub problem: String,
}

impl<const N: usize> PreparedLight<N> {
    /// Converts `intensity` to bands (as an emitter's radiance, Mitsuba's
    /// `texture_d65`); refuses one that is negative or not finite.
    pub fn new(
        index: usize,
        punctual: Punctual,
        intensity: &ColorParam,
    ) -> Result<Self, LightError> {
        let i = intensity.emission::<N>().map_err(|e| LightError {
            index,
            problem: e.to_string(),
        })?;
        if !(i.is_finite() && i.is_non_negative() && i.max_value() <= 1e30) {
            return Err(LightError {
                index,
                problem: "intensity must be finite, non-negative and at most 1e30 in every band"
                    .into(),
            });
        }
        Ok(PreparedLight {
            punctual,
            intensity: i,
        })
    }

    /// The light reaching `x` and the irradiance it brings to a plane
    /// facing it (I falloff / r², or E).
    pub fn at(&self, x: DVec3) -> Option<(Arrival, Spectrum<N>)> {
        let a = self.punctual.arrival(x)?;
        Some((a, self.intensity * a.factor))
    }

    /// The flux it sends into a scene whose bounding sphere has radius
    /// `scene_radius`.
    pub fn flux(&self, scene_radius: f64) -> Spectrum<N> {
        self.intensity * self.punctual.flux_factor(scene_radius)
    }
}

/// The radius of the bounding sphere of `geometry`'s box (Mitsuba's
/// `bbox().bounding_sphere()`), and how far a shadow ray towards a
/// directional light must reach to leave the scene.
pub fn scene_radius(geometry: &Geometry) -> f64 {
    let b = geometry.bounds();
    0.5 * (b.max - b.min).length()
}

/// The point a shadow ray from `x` towards the light of `a` ends at:
/// the light, or beyond the scene for a directional light. With an
/// `enclosure` (the box standing for a `constant` sky, which nothing
/// crosses), a directional light's ray ends just inside it instead: the
/// sun shines through the sky, whose box would otherwise shadow everything
/// (the scene's contents lie at least 0.1 % of its diagonal inside it).
/// `None` when `x` is on the enclosure facing out, where no sun shines
/// (the sky's box would otherwise take the sun on both of its sides).
pub fn shadow_end(
    geometry: &Geometry,
    enclosure: Option<&Bounds>,
    x: DVec3,
    a: &Arrival,
) -> Option<DVec3> {
    if a.distance.is_finite() {
        return Some(x + a.wi * a.distance);
    }
    if let Some(b) = enclosure {
        let exit = (0..3)
            .map(|k| {
                let (d, lo, hi) = (a.wi[k], b.min[k], b.max[k]);
                if d > 0.0 {
                    (hi - x[k]) / d
                } else if d < 0.0 {
                    (lo - x[k]) / d
                } else {
                    f64::INFINITY
                }
            })
            .fold(f64::INFINITY, f64::min);
        let margin = 1e-4 * (b.max - b.min).length();
        return (exit > margin).then(|| x + a.wi * (exit - margin));
    }
    let b = geometry.bounds();
    let reach = (b.max - b.min).length() + (x - 0.5 * (b.max + b.min)).length() + 1.0;
    Some(x + a.wi * reach)
}
