//! Punctual lights as geometry: where light without area comes from and
//! how its intensity varies with direction (Mitsuba 3's `point`, `spot`
//! and `directional`, glTF's `KHR_lights_punctual`). Plain data, with the
//! one function every layer needs, [`Punctual::arrival`]: the direction,
//! distance and geometric factor of the light reaching a point. The colour
//! (intensity or irradiance) lives with the scene and the solver.

use std::f64::consts::PI;

use glam::{DMat3, DVec3};
use serde::Serialize;

/// How a spot's intensity falls off away from its axis.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub enum SpotFalloff {
    /// Mitsuba 3.9.1's `spot`: 1 within `beam_width` of the axis, then
    /// linear in the angle down to 0 at `cutoff_angle` (radians), and 0
    /// from there on (strictly: the cutoff itself is dark).
    Mitsuba {
        /// The angle beyond which the spot is dark.
        cutoff_angle: f64,
        /// The angle within which it is at full intensity.
        beam_width: f64,
    },
    /// glTF's `KHR_lights_punctual` spot: the specification's falloff,
    /// t² with t = clamp((cos θ − cos outer) / max(0.001, cos inner −
    /// cos outer), 0, 1), quadratic in the cosine (Mitsuba's is linear in
    /// the angle: the two cannot stand for each other).
    Gltf {
        /// `innerConeAngle` (radians).
        inner_cone_angle: f64,
        /// `outerConeAngle` (radians).
        outer_cone_angle: f64,
    },
}

impl SpotFalloff {
    /// The falloff for a direction at angle θ from the axis (`cos_theta`).
    pub fn eval(&self, cos_theta: f64) -> f64 {
        match *self {
            SpotFalloff::Mitsuba {
                cutoff_angle,
                beam_width,
            } => {
                if cos_theta <= cutoff_angle.cos() {
                    0.0
                } else if cos_theta >= beam_width.cos() {
                    1.0
                } else {
                    let theta = cos_theta.clamp(-1.0, 1.0).acos();
                    ((cutoff_angle - theta) / (cutoff_angle - beam_width)).clamp(0.0, 1.0)
                }
            }
            SpotFalloff::Gltf {
                inner_cone_angle,
                outer_cone_angle,
            } => {
                let (ci, co) = (inner_cone_angle.cos(), outer_cone_angle.cos());
                let t = ((cos_theta - co) / (ci - co).max(0.001)).clamp(0.0, 1.0);
                t * t
            }
        }
    }

    /// ∫ falloff dω over the sphere (sr): a spot of intensity I sends
    /// I times this (midpoint rule in θ, 4096 steps over the lit cone).
    pub fn solid_angle(&self) -> f64 {
        let end = match *self {
            SpotFalloff::Mitsuba { cutoff_angle, .. } => cutoff_angle,
            SpotFalloff::Gltf {
                outer_cone_angle, ..
            } => outer_cone_angle,
        }
        .clamp(0.0, PI);
        let n = 4096;
        let h = end / f64::from(n);
        let sum: f64 = (0..n)
            .map(|k| {
                let t = (f64::from(k) + 0.5) * h;
                self.eval(t.cos()) * t.sin()
            })
            .sum();
        2.0 * PI * sum * h
    }
}

/// A light without area, placed in the world.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub enum Punctual {
    /// Equal intensity in every direction from `position`.
    Point {
        /// Where the light is.
        position: DVec3,
    },
    /// Intensity along the light's +z axis, falling off away from it.
    Spot {
        /// Where the light is.
        position: DVec3,
        /// The inverse of the light's linear map (Mitsuba's `to_world`
        /// without its translation): a direction d from the light is at
        /// angle θ from the axis with cos θ = normalize(M d).z, as Mitsuba
        /// computes it (a scaled `to_world` widens or narrows the cone).
        light_from_world: DMat3,
        /// The falloff.
        falloff: SpotFalloff,
    },
    /// Parallel light travelling along `direction` (unit), from beyond the
    /// scene: the sun.
    Directional {
        /// The unit direction light travels in.
        direction: DVec3,
    },
}

/// Light from a punctual light reaching a point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Arrival {
    /// Unit direction from the point towards the light.
    pub wi: DVec3,
    /// Distance to the light (`f64::INFINITY` for a directional light).
    pub distance: f64,
    /// The factor by which the light's intensity (or, for a directional
    /// light, its irradiance) is multiplied to give the irradiance on a
    /// plane facing the light: falloff / r² (1 for a directional light).
    pub factor: f64,
}

impl Punctual {
    /// The light reaching `x`; `None` where none does (outside a spot's
    /// cone, or at the light itself).
    pub fn arrival(&self, x: DVec3) -> Option<Arrival> {
        match *self {
            Punctual::Point { position } => towards(position, x, 1.0),
            Punctual::Spot {
                position,
                light_from_world,
                falloff,
            } => {
                let local = (light_from_world * (x - position)).normalize_or_zero();
                let f = falloff.eval(local.z);
                if f > 0.0 {
                    towards(position, x, f)
                } else {
                    None
                }
            }
            Punctual::Directional { direction } => Some(Arrival {
                wi: -direction,
                distance: f64::INFINITY,
                factor: 1.0,
            }),
        }
    }

    /// The flux the light sends per unit of its intensity (W per W sr⁻¹:
    /// 4π for a point, the spot's [`SpotFalloff::solid_angle`]), or, for a
    /// directional light, per unit irradiance: π R² over the scene's
    /// bounding sphere of radius `scene_radius` (as Mitsuba's power of a
    /// directional emitter).
    pub fn flux_factor(&self, scene_radius: f64) -> f64 {
        match self {
            Punctual::Point { .. } => 4.0 * PI,
            Punctual::Spot { falloff, .. } => falloff.solid_angle(),
            Punctual::Directional { .. } => PI * scene_radius * scene_radius,
        }
    }
}

/// The arrival from a light at `position` with falloff `f` at `x`.
fn towards(position: DVec3, x: DVec3, f: f64) -> Option<Arrival> {
    let d = position - x;
    let r2 = d.length_squared();
    if r2 <= 0.0 || !r2.is_finite() {
        return None;
    }
    let r = r2.sqrt();
    Some(Arrival {
        wi: d / r,
        distance: r,
        factor: f / r2,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Mitsuba 3.9.1's own values (its `sample_direction` at a distance of
    /// 1 for cutoff 30°, beam 10°): 1 to 10°, 0.9 at 12°, 0.5 at 20°,
    /// 0.05 at 29°, 0 from 30°.
    #[test]
    fn mitsuba_spot_falloff_matches_mitsuba() {
        let f = SpotFalloff::Mitsuba {
            cutoff_angle: 30f64.to_radians(),
            beam_width: 10f64.to_radians(),
        };
        for (deg, want) in [
            (0.0, 1.0),
            (10.0, 1.0),
            (12.0, 0.9),
            (15.0, 0.75),
            (20.0, 0.5),
            (29.0, 0.05),
            (30.0, 0.0),
            (31.0, 0.0),
        ] {
            let got = f.eval(f64::to_radians(deg).cos());
            assert!((got - want).abs() < 1e-6, "{deg}°: {got} against {want}");
        }
    }

    /// A hard-edged spot (beam ≥ cutoff) sends I × its cone's solid angle
    /// 2π(1 − cos cutoff); a point sends 4π I.
    #[test]
    fn flux_factors_are_the_closed_forms() {
        let c = 0.5f64;
        let hard = SpotFalloff::Mitsuba {
            cutoff_angle: c,
            beam_width: c,
        };
        let want = 2.0 * PI * (1.0 - c.cos());
        assert!((hard.solid_angle() / want - 1.0).abs() < 1e-5);
        // glTF: ∫ t² dω with t linear in cos θ between cos outer and cos
        // inner = 2π (ci − co)/3 + 2π (1 − ci).
        let (i, o) = (0.3f64, 0.6f64);
        let g = SpotFalloff::Gltf {
            inner_cone_angle: i,
            outer_cone_angle: o,
        };
        let want = 2.0 * PI * ((i.cos() - o.cos()) / 3.0 + 1.0 - i.cos());
        assert!((g.solid_angle() / want - 1.0).abs() < 1e-5);
        let p = Punctual::Point {
            position: DVec3::ZERO,
        };
        assert_eq!(p.flux_factor(1.0), 4.0 * PI);
    }

    /// A point light's arrival is 1/r² along the unit direction to it.
    #[test]
    fn point_arrival_is_inverse_square() {
        let p = Punctual::Point {
            position: DVec3::new(0.0, 0.0, 2.0),
        };
        let a = p
            .arrival(DVec3::ZERO)
            .unwrap_or_else(|| panic!("no arrival"));
        assert!((a.factor - 0.25).abs() < 1e-15);
        assert!((a.wi - DVec3::Z).length() < 1e-15);
        assert!(p.arrival(DVec3::new(0.0, 0.0, 2.0)).is_none());
    }
}
