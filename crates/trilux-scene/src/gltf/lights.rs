//! glTF's `KHR_lights_punctual` lights, placed by their nodes. Units as
//! trilux reads glTF's emission (`emissiveFactor` × strength, in nits,
//! is taken as radiance one for one): a point or spot light's `intensity`
//! in candela is its radiant intensity (W sr⁻¹), a directional light's in
//! lux its irradiance (W m⁻²), both times `color`. A light shines along
//! its node's −z. `range` is ignored with a warning (glTF lets renderers
//! ignore it: the light then falls off as 1/r² to infinity, as Mitsuba's
//! do). A spot's falloff is glTF's own (`SpotFalloff::Gltf`), which
//! Mitsuba's spot (linear in the angle) cannot represent.

use glam::{DMat3, DMat4, DVec3};
use trilux_color::ColorParam;
use trilux_geometry::{Punctual, SpotFalloff, coordinate_system};

use crate::error::SourceLocation;
use crate::scene::Light;

/// The light of a node placed by `world`, or why it is refused; a
/// warning when its `range` is ignored.
pub(super) fn light(
    light: &gltf::khr_lights_punctual::Light<'_>,
    world: DMat4,
    location: SourceLocation,
) -> Result<(Light, Option<String>), String> {
    let name = light
        .name()
        .map_or(format!("#{}", light.index()), |n| format!("\"{n}\""));
    let intensity = f64::from(light.intensity());
    let color = light.color().map(f64::from);
    if intensity < 0.0 || !intensity.is_finite() {
        return Err(format!(
            "light {name}: intensity must be finite and not negative, found {intensity}"
        ));
    }
    if color.iter().any(|c| *c < 0.0 || !c.is_finite()) {
        return Err(format!(
            "light {name}: color must be finite and not negative, found {color:?}"
        ));
    }
    let position = world.w_axis.truncate();
    let direction = world.transform_vector3(-DVec3::Z).normalize_or_zero();
    let punctual = match light.kind() {
        gltf::khr_lights_punctual::Kind::Point => Punctual::Point { position },
        gltf::khr_lights_punctual::Kind::Directional => {
            if direction == DVec3::ZERO || !direction.is_finite() {
                return Err(format!(
                    "directional light {name}: its node's transform has no direction (a zero scale?)"
                ));
            }
            Punctual::Directional { direction }
        }
        gltf::khr_lights_punctual::Kind::Spot {
            inner_cone_angle,
            outer_cone_angle,
        } => {
            let (inner, outer) = (f64::from(inner_cone_angle), f64::from(outer_cone_angle));
            if !(0.0..outer).contains(&inner)
                || outer > std::f64::consts::FRAC_PI_2
                || outer.is_nan()
            {
                return Err(format!(
                    "spot light {name}: glTF needs 0 ≤ innerConeAngle < outerConeAngle ≤ π/2, found {inner} and {outer}"
                ));
            }
            if direction == DVec3::ZERO || !direction.is_finite() {
                return Err(format!(
                    "spot light {name}: its node's transform has no direction (a zero scale?)"
                ));
            }
            let (t, b) = coordinate_system(direction);
            Punctual::Spot {
                position,
                light_from_world: DMat3::from_cols(t, b, direction).transpose(),
                falloff: SpotFalloff::Gltf {
                    inner_cone_angle: inner,
                    outer_cone_angle: outer,
                },
            }
        }
    };
    let warning = light.range().map(|r| {
        format!("light {name}: range {r} is ignored (the light falls off as 1/r² without a cut-off, as in Mitsuba)")
    });
    let rgb = [
        color[0] * intensity,
        color[1] * intensity,
        color[2] * intensity,
    ];
    Ok((
        Light {
            punctual,
            intensity: ColorParam::Rgb(rgb),
            location,
        },
        warning,
    ))
}
