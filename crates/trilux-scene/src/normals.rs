//! Mitsuba 3's `normalmap` and `bumpmap` BSDFs: a nested BSDF whose
//! shading normal a texture turns (`trilux_brdf::normal_map`).
//!
//! | plugin | parameters (default) |
//! |---|---|
//! | `normalmap` | `<texture name="normalmap">` (RGB: n = 2·rgb − 1 in the tangent frame), one nested BSDF, `flip_invalid_normals` (true), `use_shadowing_function` (true: read, not applied) |
//! | `bumpmap` | one nested `<texture>` (its luminance a height field), `scale` (1), one nested BSDF, `flip_invalid_normals` (true), `use_shadowing_function` (true: read, not applied) |
//!
//! The material is its nested BSDF (the solve keeps the geometric normal);
//! the texture is kept with the shape and turns the shading normal in the
//! render only. Mitsuba's `use_shadowing_function` (Estevez et al.'s
//! attenuation of light arriving at grazing angles to the perturbed
//! normal) is not applied: docs/rendering.md, "Normal and bump maps".
//!
//! Refused (one located line): a second normal or bump map in one
//! material; one inside a `blendbsdf`, a `mask` or the back of a
//! two-sided BSDF with two sides (it turns the normal of the whole
//! material); a `scale` that is not finite; a texture that is not a
//! `bitmap`; a shape other than a mesh (`obj`, `ply`: Mitsuba 3.9.1's
//! `rectangle` has a shading frame of length 2, not a unit one); and, when the images are read, a normal
//! map whose image is not RGB.

use trilux_brdf::{BsdfParams, NormalPerturbation, SlotKind};

use crate::error::{Result, SceneError};
use crate::material::{TextureCollector, bitmap, nested};
use crate::props::Props;
use crate::xml::Element;

/// A `normalmap` or `bumpmap` BSDF (`kind`): its nested BSDF, with its
/// texture recorded in `tex` as the material's normal map.
pub(crate) fn normal_mapped(
    e: &Element,
    kind: &str,
    props: &Props<'_>,
    tex: &mut TextureCollector<'_>,
) -> Result<BsdfParams> {
    if tex.normal_request().is_some() {
        return Err(SceneError::at(
            &e.loc,
            "a material takes one normalmap or bumpmap",
        ));
    }
    if !tex.at_top() {
        return Err(SceneError::at(
            &e.loc,
            format!(
                "a {kind} turns the normal of the whole material: it cannot be inside a blendbsdf, a mask or the back of a twosided"
            ),
        ));
    }
    let flip = props.boolean("flip_invalid_normals")?.unwrap_or(true);
    // Read (Mitsuba's default true), not applied: module docs.
    props.boolean("use_shadowing_function")?;
    let textures: Vec<&Element> = props
        .objects
        .iter()
        .copied()
        .filter(|o| o.tag == "texture")
        .collect();
    let texture = match (kind, textures.as_slice()) {
        ("normalmap", [t]) if t.attr("name").map(|a| a.value.as_str()) == Some("normalmap") => *t,
        ("bumpmap", [t]) => *t,
        _ => {
            let what = if kind == "normalmap" {
                "one <texture name=\"normalmap\">"
            } else {
                "one nested <texture>"
            };
            return Err(SceneError::at(
                &e.loc,
                format!(
                    "<bsdf type=\"{kind}\"> needs {what}, found {}",
                    textures.len()
                ),
            ));
        }
    };
    if texture.plugin_type()? != "bitmap" {
        return Err(SceneError::at(
            &texture.loc,
            format!("the texture of a {kind} must be a bitmap"),
        ));
    }
    let perturbation = if kind == "normalmap" {
        NormalPerturbation::Normal { scale: 1.0, flip }
    } else {
        let scale = props.float("scale")?.unwrap_or(1.0);
        if !scale.is_finite() {
            return Err(SceneError::at(
                &props.loc("scale"),
                format!("bumpmap scale must be finite, found {scale}"),
            ));
        }
        NormalPerturbation::Bump { scale, flip }
    };
    let mut request = bitmap(texture, SlotKind::Reflectance, tex)?;
    request.normal = Some(perturbation);
    let [inner] = nested::<1>(props, "one nested BSDF")?;
    let inner = tex.nest(inner)?;
    tex.set_normal_request(request);
    Ok(inner)
}
