//! Surfaces that let light through: Mitsuba 3's `thindielectric` (a pane
//! of glass) and `mask` (an opacity). A `thindielectric` becomes a black surface whose shape lets the Fresnel fraction
//! of a thin slab through, undeviated (trilux-geometry's
//! `transmission`), in the solve's visibility and in the render alike.
//!
//! | plugin | parameters (default) |
//! |---|---|
//! | `thindielectric` | `int_ior` (`bk7`: 1.5046) / `ext_ior` (`air`: 1.000277), as a float or one of Mitsuba's named indices; `specular_reflectance` (1), `specular_transmittance` (1), grey, in \[0, 1\] |
//! | `mask` | `opacity` (0.5), a float in \[0, 1\]; one nested BSDF, without textures |
//!
//! Mitsuba's `mask` (an opacity) reflects opacity × its nested BSDF and
//! lets 1 − opacity through, whatever the angle
//! (`Transmittance::Constant`); the nested BSDF becomes a `blendbsdf` of
//! black and itself with weight opacity (inside a nested `twosided`, on
//! each side). A bitmap opacity (leaves cut out of a quad) varies over
//! the surface, which a per-shape fraction cannot hold: refused.
//!
//! A thin slab's reflection (R = 2r/(1 + r) of the light arriving) is not
//! carried: neither the solve nor the render reflects light off the pane
//! (docs/solver.md, "Panes of glass").
//!
//! Refused, each with one located line: `dielectric` and
//! `roughdielectric` (refraction through a thick object: neither the solve
//! nor the render follows a bent path; a pane should be a
//! `thindielectric`), a `thindielectric` nested in another BSDF (its
//! transmission belongs to the shape), a coloured or textured
//! `specular_reflectance` or `specular_transmittance`.

use trilux_brdf::BsdfParams;
use trilux_color::ColorParam;
use trilux_geometry::Transmittance;

use crate::error::{Result, SceneError};
use crate::ior::ior;
use crate::props::Props;
use crate::xml::Element;

/// The BSDF plugins that only [`crate::glass`] handles.
pub(crate) const TRANSMITTING: [&str; 2] = ["thindielectric", "mask"];

/// The plugins refused with their reason.
pub(crate) const REFRACTING: [&str; 2] = ["dielectric", "roughdielectric"];

/// The transmittance of a `thindielectric` element, its parameters checked
/// (module docs); `props` are consumed as `build_bsdf` requires.
pub(crate) fn thin_dielectric(props: &Props<'_>) -> Result<Transmittance> {
    props.no_objects()?;
    let int_ior = ior(props, "int_ior", "bk7")?;
    let ext_ior = ior(props, "ext_ior", "air")?;
    grey(props, "specular_reflectance")?;
    let scale = grey(props, "specular_transmittance")?;
    Ok(Transmittance::ThinSlab {
        eta: int_ior / ext_ior,
        scale,
    })
}

/// The transmittance of a shape's `<bsdf>` element, if it lets light
/// through (`None` for every other plugin).
pub(crate) fn transmission(e: &Element) -> Result<Option<Transmittance>> {
    Ok(match e.plugin_type()? {
        "thindielectric" => Some(thin_dielectric(&Props::new(e)?)?),
        "mask" => Some(Transmittance::Constant(1.0 - opacity(&Props::new(e)?)?)),
        _ => None,
    })
}

/// A `mask`'s `opacity` (Mitsuba's default 0.5): a float in [0, 1]; a
/// texture is refused (module docs).
pub(crate) fn opacity(props: &Props<'_>) -> Result<f64> {
    if let Some(t) = props.objects.iter().find(|o| o.tag == "texture") {
        return Err(SceneError::at(
            &t.loc,
            "a mask's opacity must be a float here: a texture varies over the surface, which trilux's per-shape transmittance cannot hold",
        ));
    }
    let loc = props.loc("opacity");
    let o = props.float("opacity")?.unwrap_or(0.5);
    if !(0.0..=1.0).contains(&o) {
        return Err(SceneError::at(
            &loc,
            format!("opacity must lie in [0, 1], found {o}"),
        ));
    }
    Ok(o)
}

/// The BSDF a mask of `opacity` reflects with: `inner` × opacity (on each
/// side of a `twosided`).
pub(crate) fn masked(opacity: f64, inner: BsdfParams) -> BsdfParams {
    let dim = |b: BsdfParams| BsdfParams::Blend {
        weight: opacity,
        first: Box::new(BsdfParams::Diffuse {
            reflectance: ColorParam::Float(0.0),
        }),
        second: Box::new(b),
    };
    match inner {
        BsdfParams::TwoSided { front, back } => BsdfParams::TwoSided {
            front: Box::new(dim(*front.clone())),
            back: Some(Box::new(dim(*back.unwrap_or(front)))),
        },
        other => dim(other),
    }
}

/// The error for a refracting plugin at the element's `type`.
pub(crate) fn refused(e: &Element, kind: &str) -> Result<SceneError> {
    Ok(SceneError::at(
        &e.required("type")?.loc,
        format!(
            "bsdf plugin \"{kind}\" refracts light through a thick object, which trilux does not follow (neither its solve nor its render bends a path); a pane of glass is a \"thindielectric\""
        ),
    ))
}

/// The error for a transmitting plugin nested in another BSDF.
pub(crate) fn nested(e: &Element, kind: &str) -> Result<SceneError> {
    Ok(SceneError::at(
        &e.required("type")?.loc,
        format!(
            "a \"{kind}\" cannot be nested in another BSDF: the light it lets through belongs to its shape (give it to the <shape> directly)"
        ),
    ))
}

/// A grey factor `name` in [0, 1] (Mitsuba's default 1): a float, or a
/// colour whose values are all equal.
fn grey(props: &Props<'_>, name: &str) -> Result<f64> {
    let loc = props.loc(name);
    let c = props.color(name)?.unwrap_or(ColorParam::Float(1.0));
    let values = c.values();
    let first = values.first().copied().unwrap_or(1.0);
    if values.iter().any(|&v| v != first) {
        return Err(SceneError::at(
            &loc,
            format!("{name} of a thindielectric must be grey (one value for every wavelength)"),
        ));
    }
    if !(0.0..=1.0).contains(&first) {
        return Err(SceneError::at(
            &loc,
            format!("{name} must lie in [0, 1], found {first}"),
        ));
    }
    Ok(first)
}
