//! Surfaces that let light through: Mitsuba 3's `thindielectric` (a pane
//! of glass) and `mask` (an opacity). A `thindielectric` becomes a black surface whose shape lets the Fresnel fraction
//! of a thin slab through, undeviated (trilux-geometry's
//! `transmission`), in the solve's visibility and in the render alike.
//!
//! | plugin | parameters (default) |
//! |---|---|
//! | `thindielectric` | `int_ior` (`bk7`: 1.5046) / `ext_ior` (`air`: 1.000277), as a float or one of Mitsuba's named indices; `specular_reflectance` (1), `specular_transmittance` (1), grey, in \[0, 1\] |
//! | `mask` | `opacity` (0.5), a float in \[0, 1\] or a `bitmap` (`checkerboard`) texture; one nested BSDF |
//!
//! Mitsuba's `mask` (an opacity) reflects opacity × its nested BSDF and
//! lets 1 − opacity through, whatever the angle
//! (`Transmittance::Constant`); the nested BSDF becomes a `blendbsdf` of
//! black and itself with weight opacity (inside a nested `twosided`, on
//! each side). A textured opacity (leaves cut out of a quad) is the
//! `blendbsdf`'s textured weight, and the shape a cut-out
//! ([`crate::cutout`]) that lets 1 − opacity(u, v) through at each
//! crossing; the solve reflects with each element's mean opacity (the
//! textured weight averaged over the element, as every texture is).
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

use trilux_brdf::{Branch, BsdfParams, SlotKind};
use trilux_color::ColorParam;
use trilux_geometry::Transmittance;

use crate::error::{Result, SceneError};
use crate::ior::ior;
use crate::props::Props;
use crate::textures::TextureRequest;
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
        // A textured opacity is a cut-out, made once its image is read.
        "mask" if textured_opacity(e) => None,
        "mask" => Some(Transmittance::Constant(1.0 - opacity(&Props::new(e)?)?)),
        _ => None,
    })
}

/// True when a `mask` element's opacity is a texture.
fn textured_opacity(e: &Element) -> bool {
    e.children.iter().any(|c| c.tag == "texture")
}

/// A `mask`'s constant `opacity` (Mitsuba's default 0.5): a float in
/// [0, 1].
pub(crate) fn opacity(props: &Props<'_>) -> Result<f64> {
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

/// Moves the texture requests from `start` on, made for the nested BSDF
/// `inner` of a mask as the second branch of its `blendbsdf`, to where
/// [`masked`] puts that BSDF: inside a `twosided`, the blend is on each
/// side ([Second, Front, …] → [Front, Second, …], and [Back, Second, …]
/// too when one BSDF served both sides; [Second, Back, …] → [Back,
/// Second, …]).
pub(crate) fn move_into_mask(requests: &mut Vec<TextureRequest>, start: usize, inner: &BsdfParams) {
    let BsdfParams::TwoSided { back, .. } = inner else {
        return;
    };
    let one_for_both = back.is_none();
    let moved: Vec<TextureRequest> = requests.drain(start..).collect();
    for mut r in moved {
        let side = r.path.get(1).copied().unwrap_or(Branch::Front);
        let rest = r.path.get(2..).unwrap_or_default().to_vec();
        r.path = [vec![side, Branch::Second], rest.clone()].concat();
        if one_for_both {
            let mut back = r.clone();
            back.path = [vec![Branch::Back, Branch::Second], rest].concat();
            requests.push(back);
        }
        requests.push(r);
    }
}

/// The textured opacity `request` as the weight of every `blendbsdf`
/// [`masked`] made (one per side inside a `twosided`).
pub(crate) fn opacity_slots(request: &TextureRequest, masked: &BsdfParams) -> Vec<TextureRequest> {
    let paths = match masked {
        BsdfParams::TwoSided { .. } => vec![vec![Branch::Front], vec![Branch::Back]],
        _ => vec![Vec::new()],
    };
    paths
        .into_iter()
        .map(|path| TextureRequest {
            path,
            kind: SlotKind::Weight,
            ..request.clone()
        })
        .collect()
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
