//! `<bsdf>` elements → [`BsdfParams`], with Mitsuba 3's parameters and
//! defaults:
//!
//! | plugin | parameters (default) |
//! |---|---|
//! | `diffuse` | `reflectance` (0.5) |
//! | `conductor` | `material` (`none`: Fresnel = 1; or one of Mitsuba's measured conductors, `Cu`, `Au`, `Ag`, `Al`, `Cr`, …: `trilux_brdf::conductors`), `eta` (0) / `k` (1), `specular_reflectance` (1); a mirror, as a Beckmann lobe of α = `MIRROR_ALPHA` (1e-5) |
//! | `roughconductor` | `distribution` (`beckmann` \| `ggx`), `alpha` (0.1) or `alpha_u` = `alpha_v`, `material`, `eta` / `k` and `specular_reflectance` as `conductor`; `sample_visible` ignored |
//! | `plastic` | `diffuse_reflectance` (0.5), `specular_reflectance` (1), `int_ior` (`polypropylene`: 1.49) / `ext_ior` (`air`: 1.000277), as a float or one of Mitsuba's named indices (`bk7`, `water`, …), `nonlinear` (false) |
//! | `roughplastic` | as `plastic`, with `distribution` (`beckmann` \| `ggx`) and `alpha` (0.1) or `alpha_u` = `alpha_v`; `sample_visible` ignored |
//! | `blendbsdf` | `weight` (required, in \[0, 1\]), two nested BSDFs |
//! | `twosided` | one nested BSDF (both sides) or two (front, back) |
//! | `thindielectric` | black here; the light it lets through is its shape's ([`crate::glass`]) |
//! | `mask` | `opacity` (0.5: a float, or a texture) × one nested BSDF; the rest is let through by its shape ([`crate::glass`], [`crate::cutout`]) |
//! | `normalmap`, `bumpmap` | one nested BSDF whose shading normal a texture turns in the render ([`normal_mapped`]) |
//!
//! Textures: `<texture type="bitmap" name="...">` (Mitsuba's `bitmap`:
//! `filename`, `filter_type` `bilinear` | `nearest`, `wrap_mode` `repeat` |
//! `mirror` | `clamp`, `raw`) as the `reflectance` of `diffuse`, the
//! `specular_reflectance` of `conductor` and `roughconductor`, the `diffuse_reflectance`
//! of `plastic` and `roughplastic`, the `weight` of
//! `blendbsdf` and the `opacity` of `mask`; the image is read when the scene is finished
//! ([`crate::textures`]).
//!
//! Refused: other plugins, anisotropic roughness (`alpha_u` ≠ `alpha_v`),
//! a conductor `material` Mitsuba does not name, or given with `eta` or
//! `k`, other textures, `alpha` ≤ 0, indices of
//! refraction ≤ 0 (or equal inside and out for `roughplastic`, as in
//! Mitsuba), negative (but for a conductor's `eta` and `k`, as in Mitsuba)
//! or NaN values, and reflectances above 1 (they would create energy and keep the
//! solver from converging; Mitsuba renders them, trilux refuses them).

use std::path::Path;

use trilux_brdf::{
    Branch, BsdfParams, Distribution, Filter, MIRROR_ALPHA, NormalPerturbation, PlasticParams,
    RoughConductorParams, SlotKind, UvTransform, Wrap, conductor_names, named_conductor,
};
use trilux_color::ColorParam;

use crate::cutout::{AlphaRule, CutoutRequest};
use crate::error::{Result, SceneError, SourceLocation};
use crate::image::Sampling;
use crate::ior::ior;
use crate::props::Props;
use crate::textures::{ImageSource, TextureRequest};
use crate::xml::Element;

/// The textures found while building one material, with the path to the
/// BSDF being built.
pub(crate) struct TextureCollector<'f> {
    folder: &'f Path,
    path: Vec<Branch>,
    /// The textures found.
    pub requests: Vec<TextureRequest>,
    /// A `mask`'s textured opacity ([`crate::cutout`]).
    pub cutout: Option<CutoutRequest>,
    /// The material's normal or bump map, if it has one
    /// ([`normal_mapped`]).
    normal: Option<TextureRequest>,
}

impl<'f> TextureCollector<'f> {
    /// A collector for one material; image names resolve against `folder`.
    pub fn new(folder: &'f Path) -> Self {
        TextureCollector {
            folder,
            path: Vec::new(),
            requests: Vec::new(),
            cutout: None,
            normal: None,
        }
    }

    /// Every texture found, the normal or bump map last.
    pub fn into_requests(self) -> Vec<TextureRequest> {
        let mut r = self.requests;
        r.extend(self.normal);
        r
    }

    /// The normal or bump map found so far.
    pub fn normal_request(&self) -> Option<&TextureRequest> {
        self.normal.as_ref()
    }

    /// Records the material's normal or bump map.
    pub fn set_normal_request(&mut self, request: TextureRequest) {
        self.normal = Some(request);
    }

    /// True at the top of the material or in the front of a `twosided`
    /// (where a normal map turns the normal of the whole material).
    pub fn at_top(&self) -> bool {
        matches!(self.path.as_slice(), [] | [Branch::Front])
    }

    /// The BSDF nested in a `normalmap` or `bumpmap` (no branch: it is the
    /// material).
    pub fn nest(&mut self, e: &Element) -> Result<BsdfParams> {
        build_nested(e, self)
    }

    fn nested(&mut self, branch: Branch, e: &Element) -> Result<BsdfParams> {
        self.path.push(branch);
        let b = build_nested(e, self);
        self.path.pop();
        b
    }
}

/// Builds the BSDF of a `<bsdf>` element (references already resolved).
pub(crate) fn build_bsdf(e: &Element, tex: &mut TextureCollector<'_>) -> Result<BsdfParams> {
    e.check_attrs(&["type", "id", "name"])?;
    let props = Props::new(e)?;
    let bsdf = match e.plugin_type()? {
        "diffuse" => {
            let textured = texture(&props, "reflectance", SlotKind::Reflectance, tex)?;
            no_other_objects(&props)?;
            let reflectance = if textured {
                ColorParam::Float(0.5)
            } else {
                reflectance(&props, "reflectance", 0.5)?
            };
            BsdfParams::Diffuse { reflectance }
        }
        kind @ ("roughconductor" | "conductor") => {
            let textured = texture(
                &props,
                "specular_reflectance",
                SlotKind::SpecularReflectance,
                tex,
            )?;
            no_other_objects(&props)?;
            BsdfParams::RoughConductor(rough_conductor(&props, textured, kind == "conductor")?)
        }
        kind @ ("plastic" | "roughplastic") => {
            let textured = texture(&props, "diffuse_reflectance", SlotKind::Reflectance, tex)?;
            no_other_objects(&props)?;
            BsdfParams::Plastic(plastic(&props, kind == "roughplastic", textured)?)
        }
        "blendbsdf" => {
            let textured = texture(&props, "weight", SlotKind::Weight, tex)?;
            let [first, second] = nested::<2>(&props, "exactly two nested BSDFs")?;
            let weight = match props.float("weight")? {
                _ if textured => 0.5,
                Some(w) => w,
                None => {
                    return Err(SceneError::at(
                        &e.loc,
                        "<bsdf type=\"blendbsdf\"> needs a <float name=\"weight\"> or a <texture name=\"weight\">",
                    ));
                }
            };
            if !(0.0..=1.0).contains(&weight) {
                return Err(SceneError::at(
                    &props.loc("weight"),
                    format!("blendbsdf weight must lie in [0, 1], found {weight}"),
                ));
            }
            BsdfParams::Blend {
                weight,
                first: Box::new(tex.nested(Branch::First, first)?),
                second: Box::new(tex.nested(Branch::Second, second)?),
            }
        }
        "twosided" => {
            // Mitsuba's check that nested BSDFs do not transmit, relaxed:
            // trilux's BSDFs never do, so it changes nothing.
            props.boolean("allow_transmission")?;
            twosided(e, &props, tex)?
        }
        // A pane: black here, its transmission the shape's (crate::glass).
        "thindielectric" => {
            crate::glass::thin_dielectric(&props)?;
            BsdfParams::Diffuse {
                reflectance: ColorParam::Float(0.0),
            }
        }
        // Mitsuba's opacity: the nested BSDF times opacity, the rest let
        // through (crate::glass).
        "mask" => mask(&props, tex)?,
        kind @ ("normalmap" | "bumpmap") => normal_mapped(e, kind, &props, tex)?,
        kind if crate::glass::REFRACTING.contains(&kind) => {
            return Err(crate::glass::refused(e, kind)?);
        }
        other => {
            return Err(SceneError::at(
                &e.required("type")?.loc,
                format!(
                    "unknown bsdf plugin \"{other}\" (supported: diffuse, conductor, roughconductor, plastic, roughplastic, blendbsdf, twosided, thindielectric, mask, normalmap, bumpmap)"
                ),
            ));
        }
    };
    props.finish()?;
    Ok(bsdf)
}

/// A `mask`: its nested BSDF times its opacity, a float or a texture
/// (which is also its shape's cut-out, [`crate::cutout`]).
fn mask(props: &Props<'_>, tex: &mut TextureCollector<'_>) -> Result<BsdfParams> {
    let textured = texture(props, "opacity", SlotKind::Weight, tex)?;
    let opacity = if textured { tex.requests.pop() } else { None };
    let constant = match opacity {
        Some(_) => 0.5,
        None => crate::glass::opacity(props)?,
    };
    let [inner] = nested::<1>(props, "one nested BSDF")?;
    let before = tex.requests.len();
    let inner = tex.nested(Branch::Second, inner)?;
    crate::glass::move_into_mask(&mut tex.requests, before, &inner);
    let masked = crate::glass::masked(constant, inner);
    if let Some(request) = opacity {
        tex.requests
            .extend(crate::glass::opacity_slots(&request, &masked));
        tex.cutout = Some(CutoutRequest {
            texture: request,
            rule: AlphaRule::Opacity,
        });
    }
    Ok(masked)
}

/// A `twosided` BSDF: one nested BSDF (both sides) or two (front, back).
fn twosided(e: &Element, props: &Props<'_>, tex: &mut TextureCollector<'_>) -> Result<BsdfParams> {
    Ok(match props.objects.as_slice() {
        [front] => BsdfParams::TwoSided {
            front: Box::new(tex.nested(Branch::Front, front)?),
            back: None,
        },
        [front, back] => {
            let front = tex.nested(Branch::Front, front)?;
            if tex.normal_request().is_some() {
                return Err(SceneError::at(
                    &e.loc,
                    "a normalmap or bumpmap turns the normal of the whole material: it cannot be the front of a twosided with two sides",
                ));
            }
            BsdfParams::TwoSided {
                front: Box::new(front),
                back: Some(Box::new(tex.nested(Branch::Back, back)?)),
            }
        }
        _ => {
            return Err(SceneError::at(
                &e.loc,
                "<bsdf type=\"twosided\"> needs one or two nested BSDFs",
            ));
        }
    })
}

fn build_nested(e: &Element, tex: &mut TextureCollector<'_>) -> Result<BsdfParams> {
    if e.tag != "bsdf" {
        return Err(SceneError::at(
            &e.loc,
            format!("expected a nested <bsdf>, found {}", e.describe()),
        ));
    }
    let kind = e.plugin_type()?;
    if crate::glass::TRANSMITTING.contains(&kind) {
        return Err(crate::glass::nested(e, kind)?);
    }
    build_bsdf(e, tex)
}

/// Exactly `N` nested `<bsdf>` elements (a `<texture>` is the caller's).
pub(crate) fn nested<'a, const N: usize>(
    props: &Props<'a>,
    what: &str,
) -> Result<[&'a Element; N]> {
    let owner = props.owner();
    let bsdfs: Vec<&Element> = props
        .objects
        .iter()
        .copied()
        .filter(|o| o.tag != "texture")
        .collect();
    for o in &bsdfs {
        if o.tag != "bsdf" {
            return Err(SceneError::at(
                &o.loc,
                format!("{} cannot contain {}", owner.describe(), o.describe()),
            ));
        }
    }
    <[&Element; N]>::try_from(bsdfs.as_slice()).map_err(|_| {
        SceneError::at(
            &owner.loc,
            format!("{} needs {what}, found {}", owner.describe(), bsdfs.len()),
        )
    })
}

/// Refuses nested objects other than `<texture>`s (which [`texture`] has
/// checked).
fn no_other_objects(props: &Props<'_>) -> Result<()> {
    match props.objects.iter().find(|o| o.tag != "texture") {
        Some(o) => Err(SceneError::at(
            &o.loc,
            format!(
                "{} cannot contain {}",
                props.owner().describe(),
                o.describe()
            ),
        )),
        None => Ok(()),
    }
}

/// The `<texture name="{name}">` of the BSDF, if it has one, recorded in
/// `tex`; any other `<texture>` is an error.
fn texture(
    props: &Props<'_>,
    name: &str,
    kind: SlotKind,
    tex: &mut TextureCollector<'_>,
) -> Result<bool> {
    let mut found = false;
    for o in props.objects.iter().filter(|o| o.tag == "texture") {
        let named = o.attr("name").map(|a| a.value.as_str());
        if named != Some(name) || found {
            return Err(SceneError::at(
                &o.loc,
                format!(
                    "{} takes one texture, as \"{name}\" (found {})",
                    props.owner().describe(),
                    named.map_or("one without a name".to_string(), |n| format!("\"{n}\""))
                ),
            ));
        }
        if props.has(name) {
            return Err(SceneError::at(
                &o.loc,
                format!("\"{name}\" is given both as a value and as a texture"),
            ));
        }
        tex.requests.push(bitmap(o, kind, tex)?);
        found = true;
    }
    Ok(found)
}

/// A `<texture>`: `bitmap` (Mitsuba's defaults: bilinear, repeat, sRGB) or
/// `checkerboard`, either with a `to_uv` transform.
pub(crate) fn bitmap(
    e: &Element,
    kind: SlotKind,
    tex: &TextureCollector<'_>,
) -> Result<TextureRequest> {
    e.check_attrs(&["type", "id", "name"])?;
    let t = e.plugin_type()?;
    if t == "checkerboard" {
        return checkerboard(e, kind, tex);
    }
    if t != "bitmap" {
        return Err(SceneError::at(
            &e.required("type")?.loc,
            format!("unknown texture plugin \"{t}\" (bitmap or checkerboard)"),
        ));
    }
    let props = Props::new(e)?;
    props.no_objects()?;
    let filename = props.string("filename")?.ok_or_else(|| {
        SceneError::at(
            &e.loc,
            "<texture type=\"bitmap\"> needs <string name=\"filename\">",
        )
    })?;
    let choice = |name: &str, options: &[&str]| -> Result<Option<String>> {
        match props.string(name)? {
            Some(v) if !options.contains(&v.as_str()) => Err(SceneError::at(
                &props.loc(name),
                format!("unknown {name} \"{v}\" ({})", options.join(", ")),
            )),
            v => Ok(v),
        }
    };
    let filter = match choice("filter_type", &["bilinear", "nearest"])?.as_deref() {
        Some("nearest") => Filter::Nearest,
        _ => Filter::Bilinear,
    };
    let wrap = match choice("wrap_mode", &["repeat", "mirror", "clamp"])?.as_deref() {
        Some("mirror") => Wrap::Mirror,
        Some("clamp") => Wrap::Clamp,
        _ => Wrap::Repeat,
    };
    let raw = props.boolean("raw")?.unwrap_or(false);
    // How Mitsuba stores the image (its precision: PNG and JPEG hold 8-bit
    // values, which every format keeps, float16 within 0.05 %) and whether
    // it uses the GPU's texture units: not the light.
    choice("format", &["auto", "variant", "float16", "fp16", "uint8"])?;
    props.boolean("accel")?;
    let to_uv = to_uv(&props)?;
    let location = props.loc("filename");
    props.finish()?;
    Ok(TextureRequest {
        path: tex.path.clone(),
        kind,
        source: ImageSource::File(tex.folder.join(filename)),
        sampling: Sampling {
            wrap: [wrap; 2],
            filter,
            raw,
            alpha: false,
            channel: None,
        },
        scale: [1.0; 3],
        offset: [0.0; 3],
        to_uv,
        location,
        normal: None,
        factor: None,
        max: 1.0,
    })
}

/// A texture's `to_uv`: Mitsuba keeps the 2D affine part of the 4 × 4
/// matrix (rows and columns x, y and the translation).
fn to_uv(props: &Props<'_>) -> Result<UvTransform> {
    let Some(t) = props.transform("to_uv")? else {
        return Ok(UvTransform::IDENTITY);
    };
    let m = t.matrix;
    let uv = UvTransform([
        m.x_axis.x, m.y_axis.x, m.w_axis.x, m.x_axis.y, m.y_axis.y, m.w_axis.y,
    ]);
    if !uv.0.iter().all(|v| v.is_finite()) {
        return Err(SceneError::at(&props.loc("to_uv"), "to_uv must be finite"));
    }
    Ok(uv)
}

/// Mitsuba's `checkerboard`: `color0` where ⌊2u⌋ + ⌊2v⌋ is even (the
/// [0, ½)² quarter of every unit tile), `color1` elsewhere; defaults 0.4
/// and 0.2. It is a 2 × 2 image looked up at its nearest texel, repeated:
/// value = color1 + (color0 − color1) · t with t = 1 on the diagonal
/// texels, so either colour comes out exactly.
fn checkerboard(e: &Element, kind: SlotKind, tex: &TextureCollector<'_>) -> Result<TextureRequest> {
    let props = Props::new(e)?;
    props.no_objects()?;
    let color = |name: &str, default: f64| -> Result<[f64; 3]> {
        let c = reflectance(&props, name, default)?;
        match c {
            ColorParam::Float(v) => Ok([v; 3]),
            ColorParam::Rgb(rgb) => Ok(rgb),
            _ => Err(SceneError::at(
                &props.loc(name),
                format!(
                    "{name} of a checkerboard must be a float or an rgb value (textures are RGB)"
                ),
            )),
        }
    };
    let (c0, c1) = (color("color0", 0.4)?, color("color1", 0.2)?);
    let to_uv = to_uv(&props)?;
    props.finish()?;
    Ok(TextureRequest {
        path: tex.path.clone(),
        kind,
        source: ImageSource::Checkerboard,
        sampling: Sampling {
            wrap: [Wrap::Repeat; 2],
            filter: Filter::Nearest,
            raw: true,
            alpha: false,
            channel: None,
        },
        scale: std::array::from_fn(|c| c0[c] - c1[c]),
        offset: c1,
        to_uv,
        location: e.loc.clone(),
        normal: None,
        factor: None,
        max: 1.0,
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

/// `roughconductor`, or the smooth `conductor` (`smooth`) as a Beckmann
/// lobe of α = [`MIRROR_ALPHA`] (trilux_brdf::params).
fn rough_conductor(
    props: &Props<'_>,
    textured: bool,
    smooth: bool,
) -> Result<RoughConductorParams> {
    let (distribution, alpha) = if smooth {
        (Distribution::Beckmann, MIRROR_ALPHA)
    } else {
        roughness(props)?
    };
    let eta_k = conductor_ior(props)?;
    let specular_reflectance = if textured {
        ColorParam::Float(1.0)
    } else {
        reflectance(props, "specular_reflectance", 1.0)?
    };
    Ok(RoughConductorParams {
        distribution,
        alpha,
        eta_k,
        specular_reflectance,
    })
}

/// A conductor's complex index of refraction, as Mitsuba 3.9.1 reads it:
/// `eta` / `k` (defaults 0 and 1), or `material` naming one of its
/// measured conductors (`Cu`, `Au`, …; `trilux_brdf::conductors`), not
/// both; `None` for `material="none"` without `eta` and `k` (Fresnel = 1).
fn conductor_ior(props: &Props<'_>) -> Result<Option<(ColorParam, ColorParam)>> {
    let material = props.string("material")?;
    match material.as_deref() {
        None | Some("none") => {}
        Some(name) => {
            if let Some(given) = ["eta", "k"].into_iter().find(|n| props.has(n)) {
                return Err(SceneError::at(
                    &props.loc(given),
                    format!("give either material (\"{name}\") or eta and k, not both"),
                ));
            }
            return match named_conductor(name) {
                Some(eta_k) => Ok(Some(eta_k)),
                None => Err(SceneError::at(
                    &props.loc("material"),
                    format!(
                        "unknown conductor material \"{name}\" (Mitsuba's names, case as written: {}, or none)",
                        conductor_names().collect::<Vec<_>>().join(", ")
                    ),
                )),
            };
        }
    }
    // Negative values are Mitsuba's too (published data have them): its
    // Fresnel term sees only their squares (`trilux_color::Role::Unbounded`).
    let eta = props.color("eta")?;
    let k = props.color("k")?;
    Ok(match (eta, k) {
        (None, None) => None,
        // Mitsuba's defaults for a conductor given by eta/k: eta 0, k 1.
        (eta, k) => Some((
            eta.unwrap_or(ColorParam::Float(0.0)),
            k.unwrap_or(ColorParam::Float(1.0)),
        )),
    })
}

/// A microfacet `distribution` and isotropic `alpha` (Mitsuba's defaults:
/// Beckmann, 0.1).
fn roughness(props: &Props<'_>) -> Result<(Distribution, f64)> {
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
    if !(alpha > 0.0 && alpha.is_finite()) {
        return Err(SceneError::at(
            &alpha_loc,
            format!("roughness alpha must be positive and finite, found {alpha}"),
        ));
    }
    props.ignore(&["sample_visible"]);
    Ok((distribution, alpha))
}

/// `plastic` (`rough` false) or `roughplastic`, Mitsuba's parameters and
/// defaults.
fn plastic(props: &Props<'_>, rough: bool, textured: bool) -> Result<PlasticParams> {
    let coat = if rough { Some(roughness(props)?) } else { None };
    let int_ior = ior(props, "int_ior", "polypropylene")?;
    let ext_ior = ior(props, "ext_ior", "air")?;
    if rough && int_ior == ext_ior {
        return Err(SceneError::at(
            &props.loc("int_ior"),
            format!("int_ior and ext_ior must differ (both {int_ior}), as Mitsuba requires"),
        ));
    }
    let nonlinear = props.boolean("nonlinear")?.unwrap_or(false);
    let diffuse_reflectance = if textured {
        ColorParam::Float(0.5)
    } else {
        reflectance(props, "diffuse_reflectance", 0.5)?
    };
    Ok(PlasticParams {
        diffuse_reflectance,
        specular_reflectance: reflectance(props, "specular_reflectance", 1.0)?,
        int_ior,
        ext_ior,
        nonlinear,
        coat,
    })
}

/// An emitter's strength `name` (`radiance`, a light's `intensity` or
/// `irradiance`; Mitsuba's default 1), checked as a material's colours are
/// (finite, not negative) and within the limit.
pub(crate) fn emitted_strength(props: &Props<'_>, name: &str) -> Result<ColorParam> {
    let value = props.color(name)?.unwrap_or(ColorParam::Float(1.0));
    let loc = props.loc(name);
    check_color(&value, &loc, name, None)?;
    if let Some(v) = value
        .values()
        .into_iter()
        .find(|v| *v > crate::limits::MAX_RADIANCE)
    {
        return Err(SceneError::at(
            &loc,
            format!(
                "{name} {v:e} is beyond the limit {:e} (docs/limits.md)",
                crate::limits::MAX_RADIANCE
            ),
        ));
    }
    Ok(value)
}
// Mitsuba 3's `normalmap` and `bumpmap` BSDFs: a nested BSDF whose
// shading normal a texture turns (`trilux_brdf::normal_map`).
//
// | plugin | parameters (default) |
// |---|---|
// | `normalmap` | `<texture name="normalmap">` (RGB: n = 2·rgb − 1 in the tangent frame), one nested BSDF, `flip_invalid_normals` (true), `use_shadowing_function` (true: read, not applied) |
// | `bumpmap` | one nested `<texture>` (its luminance a height field), `scale` (1), one nested BSDF, `flip_invalid_normals` (true), `use_shadowing_function` (true: read, not applied) |
//
// The material is its nested BSDF (the solve keeps the geometric normal);
// the texture is kept with the shape and turns the shading normal in the
// render only. Mitsuba's `use_shadowing_function` (Estevez et al.'s
// attenuation of light arriving at grazing angles to the perturbed
// normal) is not applied: docs/rendering.md, "Normal and bump maps".
//
// Refused (one located line): a second normal or bump map in one
// material; one inside a `blendbsdf`, a `mask` or the back of a
// two-sided BSDF with two sides (it turns the normal of the whole
// material); a `scale` that is not finite; a texture that is not a
// `bitmap`; a shape other than a mesh (`obj`, `ply`: Mitsuba 3.9.1's
// `rectangle` has a shading frame of length 2, not a unit one); and, when the images are read, a normal
// map whose image is not RGB.

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
