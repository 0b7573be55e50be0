//! `<bsdf>` elements → [`BsdfParams`], with Mitsuba 3's parameters and
//! defaults:
//!
//! | plugin | parameters (default) |
//! |---|---|
//! | `diffuse` | `reflectance` (0.5) |
//! | `roughconductor` | `distribution` (`beckmann` \| `ggx`), `alpha` (0.1) or `alpha_u` = `alpha_v`, `material` (`none`: Fresnel = 1), `eta` (0) / `k` (1), `specular_reflectance` (1); `sample_visible` ignored |
//! | `blendbsdf` | `weight` (required, in \[0, 1\]), two nested BSDFs |
//! | `twosided` | one nested BSDF (both sides) or two (front, back) |
//!
//! Refused: other plugins, anisotropic roughness (`alpha_u` ≠ `alpha_v`),
//! named conductor materials, textures, `alpha` ≤ 0, negative or NaN values,
//! and reflectances above 1 (they would create energy and keep the solver
//! from converging; Mitsuba renders them, trilux refuses them).

use trilux_brdf::{BsdfParams, Distribution, RoughConductorParams};
use trilux_color::ColorParam;

use crate::error::{Result, SceneError, SourceLocation};
use crate::props::Props;
use crate::xml::Element;

/// Builds the BSDF of a `<bsdf>` element (references already resolved).
pub(crate) fn build_bsdf(e: &Element) -> Result<BsdfParams> {
    e.check_attrs(&["type", "id", "name"])?;
    let props = Props::new(e)?;
    let bsdf = match e.plugin_type()? {
        "diffuse" => {
            props.no_objects()?;
            let reflectance = reflectance(&props, "reflectance", 0.5)?;
            BsdfParams::Diffuse { reflectance }
        }
        "roughconductor" => {
            props.no_objects()?;
            BsdfParams::RoughConductor(rough_conductor(&props)?)
        }
        "blendbsdf" => {
            let [first, second] = nested::<2>(&props, "exactly two nested BSDFs")?;
            let weight = props.float("weight")?.ok_or_else(|| {
                SceneError::at(
                    &e.loc,
                    "<bsdf type=\"blendbsdf\"> needs a <float name=\"weight\">",
                )
            })?;
            if !(0.0..=1.0).contains(&weight) {
                return Err(SceneError::at(
                    &props.loc("weight"),
                    format!("blendbsdf weight must lie in [0, 1], found {weight}"),
                ));
            }
            BsdfParams::Blend {
                weight,
                first: Box::new(build_bsdf(first)?),
                second: Box::new(build_bsdf(second)?),
            }
        }
        "twosided" => match props.objects.as_slice() {
            [front] => BsdfParams::TwoSided {
                front: Box::new(build_nested(front)?),
                back: None,
            },
            [front, back] => BsdfParams::TwoSided {
                front: Box::new(build_nested(front)?),
                back: Some(Box::new(build_nested(back)?)),
            },
            _ => {
                return Err(SceneError::at(
                    &e.loc,
                    "<bsdf type=\"twosided\"> needs one or two nested BSDFs",
                ));
            }
        },
        other => {
            return Err(SceneError::at(
                &e.required("type")?.loc,
                format!(
                    "unknown bsdf plugin \"{other}\" (supported: diffuse, roughconductor, blendbsdf, twosided)"
                ),
            ));
        }
    };
    props.finish()?;
    Ok(bsdf)
}

fn build_nested(e: &Element) -> Result<BsdfParams> {
    if e.tag != "bsdf" {
        return Err(SceneError::at(
            &e.loc,
            format!("expected a nested <bsdf>, found {}", e.describe()),
        ));
    }
    build_bsdf(e)
}

/// Exactly `N` nested `<bsdf>` elements.
fn nested<'a, const N: usize>(props: &Props<'a>, what: &str) -> Result<[&'a Element; N]> {
    let owner = props.owner();
    for o in &props.objects {
        if o.tag != "bsdf" {
            return Err(SceneError::at(
                &o.loc,
                format!("{} cannot contain {}", owner.describe(), o.describe()),
            ));
        }
    }
    <[&Element; N]>::try_from(props.objects.as_slice()).map_err(|_| {
        SceneError::at(
            &owner.loc,
            format!(
                "{} needs {what}, found {}",
                owner.describe(),
                props.objects.len()
            ),
        )
    })
}

/// A reflectance in [0, 1] (every channel or sample), default `default`.
fn reflectance(props: &Props<'_>, name: &str, default: f64) -> Result<ColorParam> {
    let c = props.color(name)?.unwrap_or(ColorParam::Float(default));
    check_color(&c, &props.loc(name), name, Some(1.0))?;
    Ok(c)
}

/// Checks that every value is ≥ 0 (and ≤ `max` when given).
pub(crate) fn check_color(
    c: &ColorParam,
    loc: &SourceLocation,
    name: &str,
    max: Option<f64>,
) -> Result<()> {
    for v in c.values() {
        if v < 0.0 {
            return Err(SceneError::at(
                loc,
                format!("{name} must not be negative, found {v}"),
            ));
        }
        if let Some(m) = max
            && v > m
        {
            return Err(SceneError::at(
                loc,
                format!("{name} must not exceed {m}, found {v} (it would create energy)"),
            ));
        }
    }
    Ok(())
}

fn rough_conductor(props: &Props<'_>) -> Result<RoughConductorParams> {
    let distribution = match props.string("distribution")?.as_deref() {
        None | Some("beckmann") => Distribution::Beckmann,
        Some("ggx") => Distribution::Ggx,
        Some(other) => {
            return Err(SceneError::at(
                &props.loc("distribution"),
                format!("unknown microfacet distribution \"{other}\" (beckmann or ggx)"),
            ));
        }
    };
    let alpha = match (
        props.float("alpha")?,
        props.float("alpha_u")?,
        props.float("alpha_v")?,
    ) {
        (Some(a), None, None) => a,
        (None, None, None) => 0.1,
        (None, Some(u), Some(v)) if u == v => u,
        (None, Some(u), Some(v)) => {
            return Err(SceneError::at(
                &props.loc("alpha_v"),
                format!("anisotropic roughness is not supported (alpha_u = {u}, alpha_v = {v})"),
            ));
        }
        (None, _, _) => {
            return Err(SceneError::at(
                &props.owner().loc,
                "give both alpha_u and alpha_v (or alpha)",
            ));
        }
        (Some(_), _, _) => {
            return Err(SceneError::at(
                &props.loc("alpha"),
                "give either alpha or alpha_u/alpha_v, not both",
            ));
        }
    };
    let alpha_loc = if props.has("alpha") {
        props.loc("alpha")
    } else {
        props.loc("alpha_u")
    };
    if alpha <= 0.0 {
        return Err(SceneError::at(
            &alpha_loc,
            format!("roughness alpha must be positive, found {alpha}"),
        ));
    }
    match props.string("material")?.as_deref() {
        None | Some("none") => {}
        Some(other) => {
            return Err(SceneError::at(
                &props.loc("material"),
                format!(
                    "named conductor materials are not supported (\"{other}\"): give eta and k, or material=\"none\""
                ),
            ));
        }
    }
    let eta = props.color("eta")?;
    let k = props.color("k")?;
    for (c, name) in [(&eta, "eta"), (&k, "k")] {
        if let Some(c) = c {
            check_color(c, &props.loc(name), name, None)?;
        }
    }
    let eta_k = match (eta, k) {
        (None, None) => None,
        // Mitsuba's defaults for a conductor given by eta/k: eta 0, k 1.
        (eta, k) => Some((
            eta.unwrap_or(ColorParam::Float(0.0)),
            k.unwrap_or(ColorParam::Float(1.0)),
        )),
    };
    let specular_reflectance = reflectance(props, "specular_reflectance", 1.0)?;
    props.ignore(&["sample_visible"]);
    Ok(RoughConductorParams {
        distribution,
        alpha,
        eta_k,
        specular_reflectance,
    })
}
