//! Mitsuba 3's emitters without area, top-level `<emitter>`s: `point`
//! (`intensity`, `position` or `to_world`), `spot` (`intensity`,
//! `cutoff_angle`, `beam_width`, `to_world`) and `directional`
//! (`irradiance`, `direction` or `to_world`), with Mitsuba 3.9.1's
//! defaults and conventions (a spot and a directional light point along
//! their `to_world`'s +z). Mitsuba loads negative intensities, zero
//! directions and any cutoff; trilux refuses them, each at its place.

use glam::{DMat3, DMat4, DVec3};
use trilux_geometry::limits::MAX_COORDINATE;
use trilux_geometry::{Punctual, SpotFalloff};

use crate::error::{Result, SceneError};
use crate::props::Props;
use crate::scene::Light;
use crate::xml::Element;

/// Builds a top-level `<emitter>` of type `point`, `spot` or
/// `directional`.
pub(crate) fn light(e: &Element) -> Result<Light> {
    e.check_attrs(&["type", "id", "name"])?;
    let props = Props::new(e)?;
    // How often Mitsuba's light sampling picks this emitter: its noise,
    // not its image.
    props.float("sampling_weight")?;
    let (punctual, intensity) = match e.plugin_type()? {
        "point" => (
            point(&props)?,
            crate::material::emitted_strength(&props, "intensity")?,
        ),
        "spot" => (
            spot(&props)?,
            crate::material::emitted_strength(&props, "intensity")?,
        ),
        _ => (
            directional(&props)?,
            crate::material::emitted_strength(&props, "irradiance")?,
        ),
    };
    props.finish()?;
    Ok(Light {
        punctual,
        intensity,
        location: e.loc.clone(),
    })
}

/// `to_world`, checked: finite, within the coordinate limit, not singular.
fn to_world(props: &Props<'_>) -> Result<Option<DMat4>> {
    let Some(t) = props.transform("to_world")? else {
        return Ok(None);
    };
    let m = t.matrix;
    let largest = m
        .to_cols_array()
        .into_iter()
        .map(f64::abs)
        .fold(0.0, f64::max);
    let l = DMat3::from_mat4(m);
    if largest > MAX_COORDINATE || l.determinant().abs() <= 1e-300 {
        return Err(SceneError::at(
            &props.loc("to_world"),
            "to_world is singular or beyond the coordinate limit (docs/limits.md)",
        ));
    }
    Ok(Some(m))
}

/// One of two ways to place a light, as Mitsuba allows only one.
fn not_both(props: &Props<'_>, other: &str) -> Result<()> {
    if props.has(other) && props.has("to_world") {
        return Err(SceneError::at(
            &props.loc(other),
            format!("only one of \"{other}\" and \"to_world\" can be given (Mitsuba refuses both)"),
        ));
    }
    Ok(())
}

fn point(props: &Props<'_>) -> Result<Punctual> {
    not_both(props, "position")?;
    let position = match (props.vec3("position")?, to_world(props)?) {
        (Some(p), _) => p,
        (None, Some(m)) => m.w_axis.truncate(),
        (None, None) => DVec3::ZERO,
    };
    if position.abs().max_element() > MAX_COORDINATE {
        return Err(SceneError::at(
            &props.loc("position"),
            "position is beyond the coordinate limit (docs/limits.md)",
        ));
    }
    Ok(Punctual::Point { position })
}

fn spot(props: &Props<'_>) -> Result<Punctual> {
    if let Some(o) = props.objects.first() {
        return Err(SceneError::at(
            &o.loc,
            format!(
                "a spot's {} (a projected image) is not supported: remove it to light with the spot's intensity alone",
                o.describe()
            ),
        ));
    }
    let m = to_world(props)?.unwrap_or(DMat4::IDENTITY);
    let cutoff = props.float("cutoff_angle")?.unwrap_or(20.0);
    if cutoff <= 0.0 || cutoff >= 180.0 {
        return Err(SceneError::at(
            &props.loc("cutoff_angle"),
            format!("cutoff_angle must be in (0, 180) degrees, found {cutoff}"),
        ));
    }
    let beam = props.float("beam_width")?.unwrap_or(cutoff * 0.75);
    if !(0.0..180.0).contains(&beam) {
        return Err(SceneError::at(
            &props.loc("beam_width"),
            format!("beam_width must be in [0, 180) degrees, found {beam}"),
        ));
    }
    Ok(Punctual::Spot {
        position: m.w_axis.truncate(),
        light_from_world: DMat3::from_mat4(m).inverse(),
        falloff: SpotFalloff::Mitsuba {
            cutoff_angle: cutoff.to_radians(),
            beam_width: beam.to_radians(),
        },
    })
}

fn directional(props: &Props<'_>) -> Result<Punctual> {
    not_both(props, "direction")?;
    let (d, name) = match (props.vec3("direction")?, to_world(props)?) {
        (Some(d), _) => (d, "direction"),
        (None, Some(m)) => (m.z_axis.truncate(), "to_world"),
        (None, None) => (DVec3::Z, "direction"),
    };
    let direction = d.normalize_or_zero();
    if direction == DVec3::ZERO || !direction.is_finite() {
        return Err(SceneError::at(
            &props.loc(name),
            "a directional light's direction must not be zero",
        ));
    }
    Ok(Punctual::Directional { direction })
}
