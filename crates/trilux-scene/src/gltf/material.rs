//! glTF materials → trilux BSDFs: the mapping of `pbrMetallicRoughness`
//! (docs/gltf.md gives it with its reasons; `scripts/gltf_to_mitsuba.py`
//! writes the same Mitsuba BSDFs).
//!
//! With base colour B = baseColorFactor ⊙ baseColorTexture (sRGB-decoded),
//! metallic m, roughness r, and the dielectric's reflectance at normal
//! incidence F0 = min(0.04 · specularColorFactor, 1) · specularFactor
//! (`KHR_materials_specular`; 0.04 without it), F = max(F0):
//!
//! ```text
//! diffuse part   D = (1 − m)(1 − F) · B          (Lambertian, ρ_d)
//! specular part  S = (1 − m) · F0 + m · B        (GGX, α = max(r², 0.01),
//!                                                 Fresnel 1 × S)
//! ```
//!
//! D + S ≤ 1 in every channel. With D̂ and Ŝ the largest channel of each
//! over the factors (textures are at most 1), the material is
//! `blendbsdf(weight w = Ŝ/(D̂ + Ŝ), diffuse(D/(1 − w)), roughconductor(S/w))`,
//! or `diffuse(D)` alone when Ŝ = 0 (`specularFactor` 0 on a dielectric,
//! the way to write Mitsuba's `diffuse` in glTF), or the `roughconductor`
//! alone when D̂ = 0 (a metal). `doubleSided` wraps it in `twosided`.
//! Emission: `emissiveFactor × KHR_materials_emissive_strength` is the
//! radiance of an area emitter on the front side; an emissive material that
//! is also `doubleSided` is refused (glTF would have it emit on both sides,
//! and trilux's area emitters emit on the front only).
//!
//! `metallicRoughnessTexture` (linear: metalness m = metallicFactor × blue,
//! roughness r = roughnessFactor × green) makes the mapping hold at each
//! point: D and S are slots affine in the base colour lookup t and the
//! metalness lookup M, value = offset + scale ⊙ t + M · (offset′ + scale′ ⊙ t)
//! (`trilux_brdf::SlotFactor`, exact); with M textured, D̂ is D at m = 0
//! and Ŝ the larger of S at m = 0 and m = metallicFactor, so D̂ + Ŝ may
//! pass 1 and the blend's inner values are bounded by 1/(1 − w) and 1/w
//! (`TextureSlot::max`). r is a `SlotKind::Roughness` slot: the render
//! takes each hit's α, the solve the material's α at the mean roughness
//! (a warning line; docs/gltf.md, "Metalness and roughness textures").
//!
//! Refused (one error naming the material):
//! `emissiveTexture`, the textures of `KHR_materials_specular`,
//! texture coordinates other than `TEXCOORD_0`,
//! and `alphaMode` `BLEND` (a semi-transparent surface composited over what
//! is behind it, which a physically based renderer has no meaning for). `normalTexture` turns the
//! shading normal in the render (`trilux_brdf::normal_map`: n =
//! normalize((2·rgb − 1) ⊙ (scale, scale, 1)) in the frame of ∂p/∂u and
//! n × ∂p/∂u, green up; the mesh's `TANGENT` attribute is not read), not
//! in the solve; with `KHR_texture_transform` or another `texCoord` it is
//! refused.
//!
//! `alphaMode` `MASK` cuts the surface out: with a = baseColorFactor.a ×
//! baseColorTexture.a, a point where a < `alphaCutoff` (0.5) is not there
//! (light passes it), any other is opaque ([`crate::cutout`]). Without a
//! base colour texture the whole primitive is opaque, or, when
//! baseColorFactor.a < `alphaCutoff`, left out of the scene (a warning
//! line). `alphaCutoff` must be a number ≥ 0 (glTF's schema); a vertex
//! colour's alpha (`COLOR_0`) is not read, as no vertex colour is.
//! `KHR_texture_transform` on the base colour texture maps TEXCOORD_0 (as
//! Mitsuba's `to_uv` does). `occlusionTexture` is ignored: it approximates, for real-time engines,
//! the shadowing that a global illumination solve computes.

use std::path::Path;
use std::sync::Arc;

use trilux_brdf::{
    Branch, BsdfParams, Distribution, Filter, NormalPerturbation, RoughConductorParams, SlotKind,
    UvTransform, Wrap, gltf_alpha,
};
use trilux_color::ColorParam;

use crate::error::{Result, SceneError, SourceLocation};
use crate::image::Sampling;

/// A texture of a mapped material, its image not read yet.
#[derive(Clone, Debug)]
pub(crate) struct TextureUse {
    /// Where it enters the BSDF.
    pub path: Vec<Branch>,
    /// Which parameter.
    pub kind: SlotKind,
    /// The glTF image.
    pub image: usize,
    /// Its sampler.
    pub sampling: Sampling,
    /// value = offset + scale ⊙ texture.
    pub scale: [f64; 3],
    /// See `scale`.
    pub offset: [f64; 3],
    /// `KHR_texture_transform`.
    pub to_uv: UvTransform,
    /// `/materials/i/pbrMetallicRoughness/baseColorTexture`.
    pub location: SourceLocation,
    /// For the alpha of `alphaMode` `MASK`: its `alphaCutoff` (the use is
    /// then a cut-out, not a slot).
    pub cutoff: Option<f64>,
    /// Set for the `normalTexture`: how it turns the shading normal.
    pub normal: Option<NormalPerturbation>,
    /// The metalness texture multiplying part of the value
    /// (`trilux_brdf::SlotFactor`: value += m · (its offset + its scale ⊙
    /// texture)).
    pub factor: Option<Box<TextureUse>>,
    /// The largest value at a point (`trilux_brdf::TextureSlot::max`).
    pub max: f64,
}

/// A glTF material as trilux takes it.
#[derive(Clone, Debug)]
pub(crate) struct Mapped {
    pub bsdf: BsdfParams,
    pub textures: Vec<TextureUse>,
    /// Emitted radiance (front side), if the material emits.
    pub emission: Option<ColorParam>,
    /// The BSDF types used, for `bsdf_counts`.
    pub types: Vec<&'static str>,
    /// `alphaMode` `MASK` (module docs).
    pub alpha: Alpha,
    /// Warning lines (without the file): approximations of the solve.
    pub warnings: Vec<String>,
}

impl Mapped {
    /// Every texture use: the slots', then the cut-out's.
    pub fn uses(&self) -> impl Iterator<Item = &TextureUse> {
        let cutout = match &self.alpha {
            Alpha::Cutout(t) => Some(&**t),
            _ => None,
        };
        self.textures.iter().chain(cutout)
    }
}

/// What `alphaMode` `MASK` makes of a material (module docs).
#[derive(Clone, Debug)]
pub(crate) enum Alpha {
    /// Opaque everywhere (`OPAQUE`, or `MASK` with a ≥ cutoff).
    Opaque,
    /// Transparent everywhere: the primitive is left out.
    Transparent,
    /// Cut out where the texture's alpha times `scale` is below the use's
    /// `cutoff` (its `kind` and `path` are not used).
    Cutout(Box<TextureUse>),
}

/// Maps one material (`None`: glTF's default material, white, metallic 1,
/// roughness 1).
pub(crate) fn map(file: &Arc<Path>, m: &gltf::Material<'_>) -> Result<Mapped> {
    let base = match m.index() {
        Some(i) => format!("/materials/{i}"),
        None => "/materials (the default material)".into(),
    };
    let at = |suffix: &str, msg: String| {
        let name = m
            .name()
            .map(|n| format!("material \"{n}\": "))
            .unwrap_or_default();
        SceneError::at(
            &SourceLocation::json(file, format!("{base}{suffix}")),
            format!("{name}{msg}"),
        )
    };
    refuse_unsupported(m, &at)?;
    let factors = factors(m, &at)?;
    let pbr = m.pbr_metallic_roughness();
    // A texture of `pbrMetallicRoughness` named by its JSON key.
    let pbr_texture = |t: Option<gltf::texture::Info<'_>>, key: &str| {
        t.map(|t| {
            let suffix = format!("/pbrMetallicRoughness/{key}");
            let location = SourceLocation::json(file, format!("{base}{suffix}"));
            texture_info(&t, &at, &suffix, location)
        })
        .transpose()
    };
    let base_texture = pbr_texture(pbr.base_color_texture(), "baseColorTexture")?;
    let mr = pbr_texture(pbr.metallic_roughness_texture(), "metallicRoughnessTexture")?;
    let alpha = alpha(m, &at, base_texture.as_ref())?;
    let textures = Textures::new(base_texture, mr, &factors);
    let lobes = Lobes::of(&factors, textures.metal.is_some());
    let (bsdf, mut types, mut textures, warnings) = lobe_bsdf(&lobes, &textures);
    let bsdf = if m.double_sided() {
        types.push("twosided");
        for t in &mut textures {
            t.path.insert(0, Branch::Front);
        }
        BsdfParams::TwoSided {
            front: Box::new(bsdf),
            back: None,
        }
    } else {
        bsdf
    };
    if let Some(t) = m.normal_texture() {
        textures.push(normal_texture(
            &t,
            &at,
            SourceLocation::json(file, format!("{base}/normalTexture")),
        )?);
    }
    Ok(Mapped {
        bsdf,
        textures,
        emission: emission(m, &at)?,
        types,
        alpha,
        warnings,
    })
}

/// `alphaMode` `MASK` with `alphaCutoff` (module docs); `BLEND` is refused
/// before.
fn alpha(m: &gltf::Material<'_>, at: &At<'_>, base: Option<&BaseTexture>) -> Result<Alpha> {
    if m.alpha_mode() != gltf::material::AlphaMode::Mask {
        return Ok(Alpha::Opaque);
    }
    let cutoff = f64::from(m.alpha_cutoff().unwrap_or(0.5));
    if !(cutoff.is_finite() && cutoff >= 0.0) {
        return Err(at(
            "/alphaCutoff",
            format!("alphaCutoff must be a number of at least 0, found {cutoff}"),
        ));
    }
    let a = f64::from(m.pbr_metallic_roughness().base_color_factor()[3]);
    if !a.is_finite() {
        return Err(at(
            "/pbrMetallicRoughness/baseColorFactor",
            "the base colour's alpha is not a finite number".into(),
        ));
    }
    let a = a.clamp(0.0, 1.0);
    Ok(match base {
        None if a >= cutoff => Alpha::Opaque,
        None => Alpha::Transparent,
        Some((image, sampling, to_uv, location)) => Alpha::Cutout(Box::new(TextureUse {
            path: Vec::new(),
            kind: SlotKind::Weight,
            image: *image,
            sampling: Sampling {
                alpha: true,
                ..*sampling
            },
            scale: [a; 3],
            offset: [0.0; 3],
            to_uv: *to_uv,
            location: location.clone(),
            cutoff: Some(cutoff),
            normal: None,
            factor: None,
            max: 1.0,
        })),
    })
}

/// One lobe's reflectance as an affine function of the base colour
/// texture's value t and the metalness texture's value M (each 1 where
/// there is none): offset + scale ⊙ t + M · (m_offset + m_scale ⊙ t).
#[derive(Clone, Copy, Debug, Default)]
struct Affine {
    offset: [f64; 3],
    scale: [f64; 3],
    m_offset: [f64; 3],
    m_scale: [f64; 3],
}

impl Affine {
    fn map(&self, f: impl Fn(f64) -> f64) -> Affine {
        Affine {
            offset: self.offset.map(&f),
            scale: self.scale.map(&f),
            m_offset: self.m_offset.map(&f),
            m_scale: self.m_scale.map(&f),
        }
    }

    /// The value with both textures at 1: the lobe's value when neither
    /// texture enters it.
    fn constant(&self) -> [f64; 3] {
        std::array::from_fn(|c| self.offset[c] + self.scale[c] + self.m_offset[c] + self.m_scale[c])
    }
}

/// The material's two lobes as the module's header derives them: the
/// diffuse part D and the specular part S ([`Affine`] in the textures),
/// with D̂ and Ŝ, the largest channel of each over every texel value.
struct Lobes {
    rough: f64,
    metal_textured: bool,
    diffuse: Affine,
    specular: Affine,
    d_hat: f64,
    s_hat: f64,
}

/// A material's factors: base colour b, metallic, roughness and the
/// dielectric's F0.
struct Factors {
    b: [f64; 3],
    metal: f64,
    rough: f64,
    f0: [f64; 3],
}

/// The [`Factors`] of `m` (clamped to [0, 1]; refused unless finite).
fn factors(m: &gltf::Material<'_>, at: &At<'_>) -> Result<Factors> {
    let pbr = m.pbr_metallic_roughness();
    let f = pbr.base_color_factor();
    let b = [f[0], f[1], f[2]].map(|v| f64::from(v).clamp(0.0, 1.0));
    let metal = f64::from(pbr.metallic_factor()).clamp(0.0, 1.0);
    let rough = f64::from(pbr.roughness_factor()).clamp(0.0, 1.0);
    let (sf, sc) = match m.specular() {
        Some(s) => (
            f64::from(s.specular_factor()),
            s.specular_color_factor().map(f64::from),
        ),
        None => (1.0, [1.0; 3]),
    };
    if !(b.iter().all(|v| v.is_finite())
        && metal.is_finite()
        && rough.is_finite()
        && sf.is_finite()
        && sc.iter().all(|v| v.is_finite()))
    {
        return Err(at("", "a factor is not a finite number".into()));
    }
    let f0 = sc.map(|c| (0.04 * c).clamp(0.0, 1.0) * sf.clamp(0.0, 1.0));
    Ok(Factors {
        b,
        metal,
        rough,
        f0,
    })
}

impl Lobes {
    /// The lobes of the factors, the metallic factor times the metalness
    /// texture M when `metal_textured`. With m = metal · M and
    /// F = max(F0):
    ///
    /// ```text
    /// D = (1 − m)(1 − F) · b ⊙ t   = (1 − F) b ⊙ t − M · metal (1 − F) b ⊙ t
    /// S = (1 − m) F0 + m · b ⊙ t   = F0 + M · (metal b ⊙ t − metal F0)
    /// ```
    ///
    /// D̂ is D's largest value (m = 0 where M = 0), Ŝ S's: S is affine in m,
    /// largest at m = 0 or m = metal.
    fn of(factors: &Factors, metal_textured: bool) -> Lobes {
        let Factors {
            b,
            metal,
            rough,
            f0,
        } = *factors;
        let fmax = f0.iter().copied().fold(0.0, f64::max);
        let bmax = b.iter().copied().fold(0.0, f64::max);
        let max = |v: [f64; 3]| v.iter().copied().fold(0.0, f64::max);
        let at_metal = |m: f64| std::array::from_fn(|c| (1.0 - m) * f0[c] + m * b[c]);
        if metal_textured {
            Lobes {
                rough,
                metal_textured,
                diffuse: Affine {
                    scale: b.map(|c| (1.0 - fmax) * c),
                    m_scale: b.map(|c| -metal * (1.0 - fmax) * c),
                    ..Affine::default()
                },
                specular: Affine {
                    offset: f0,
                    m_offset: f0.map(|c| -metal * c),
                    m_scale: b.map(|c| metal * c),
                    ..Affine::default()
                },
                d_hat: (1.0 - fmax) * bmax,
                s_hat: max(f0).max(max(at_metal(metal))),
            }
        } else {
            let specular = Affine {
                offset: f0.map(|c| (1.0 - metal) * c),
                scale: b.map(|c| metal * c),
                ..Affine::default()
            };
            Lobes {
                rough,
                metal_textured,
                diffuse: Affine {
                    scale: b.map(|c| (1.0 - metal) * (1.0 - fmax) * c),
                    ..Affine::default()
                },
                specular,
                d_hat: (1.0 - metal) * (1.0 - fmax) * bmax,
                s_hat: max(at_metal(metal)),
            }
        }
    }
}

/// The base colour texture as [`texture_info`] reads it.
type BaseTexture = (usize, Sampling, UvTransform, SourceLocation);

/// The textures of a material: base colour (sRGB), and the
/// metallicRoughnessTexture's metalness (blue) and roughness (green),
/// linear; each only where its factor is not 0.
struct Textures {
    base: Option<BaseTexture>,
    metal: Option<BaseTexture>,
    rough: Option<BaseTexture>,
}

impl Textures {
    fn new(base: Option<BaseTexture>, mr: Option<BaseTexture>, factors: &Factors) -> Textures {
        let channel = |k: u8, factor: f64| {
            mr.as_ref()
                .filter(|_| factor > 0.0)
                .map(|(image, sampling, to_uv, location)| {
                    let sampling = Sampling {
                        raw: true,
                        channel: Some(k),
                        ..*sampling
                    };
                    (*image, sampling, *to_uv, location.clone())
                })
        };
        Textures {
            metal: channel(2, factors.metal),
            rough: channel(1, factors.rough),
            base,
        }
    }

    /// The use of lobe `a` at `path` (`None` when no texture enters it).
    fn lobe_use(
        &self,
        a: &Affine,
        path: Vec<Branch>,
        kind: SlotKind,
        max: f64,
    ) -> Option<TextureUse> {
        let nonzero = |v: &[f64; 3]| v.iter().any(|&c| c != 0.0);
        let add = |x: &[f64; 3], y: &[f64; 3]| std::array::from_fn(|c| x[c] + y[c]);
        let make = |t: &BaseTexture, scale: [f64; 3], offset: [f64; 3]| TextureUse {
            path: path.clone(),
            kind,
            image: t.0,
            sampling: t.1,
            scale,
            offset,
            to_uv: t.2,
            location: t.3.clone(),
            cutoff: None,
            normal: None,
            factor: None,
            max,
        };
        match (&self.base, &self.metal) {
            (Some(b), Some(m)) => (nonzero(&a.scale)
                || nonzero(&a.m_offset)
                || nonzero(&a.m_scale))
            .then(|| TextureUse {
                factor: Some(Box::new(make(m, a.m_scale, a.m_offset))),
                ..make(b, a.scale, a.offset)
            }),
            (Some(b), None) => {
                let scale = add(&a.scale, &a.m_scale);
                nonzero(&scale).then(|| make(b, scale, add(&a.offset, &a.m_offset)))
            }
            (None, Some(m)) => {
                let scale = add(&a.m_offset, &a.m_scale);
                nonzero(&scale).then(|| make(m, scale, add(&a.offset, &a.scale)))
            }
            (None, None) => None,
        }
    }

    /// The roughness texture's use on the conductor at `path`, and the
    /// warning that the solve takes one α for the material.
    fn rough_use(&self, rough: f64, path: Vec<Branch>) -> Option<(TextureUse, String)> {
        let (image, sampling, to_uv, location) = self.rough.as_ref()?;
        let warning = format!(
            "{location}: the solve takes one GGX roughness for the material, α = max(r², 0.01) at the texture's mean r = roughnessFactor × mean green (the render takes each point's; docs/gltf.md)"
        );
        let t = TextureUse {
            path,
            kind: SlotKind::Roughness,
            image: *image,
            sampling: *sampling,
            scale: [rough; 3],
            offset: [0.0; 3],
            to_uv: *to_uv,
            location: location.clone(),
            cutoff: None,
            normal: None,
            factor: None,
            max: 1.0,
        };
        Some((t, warning))
    }
}

/// The BSDF of the lobes (diffuse alone, conductor alone, or their blend),
/// its BSDF type names, the texture uses (one per slot) and the warnings.
fn lobe_bsdf(
    lobes: &Lobes,
    textures: &Textures,
) -> (BsdfParams, Vec<&'static str>, Vec<TextureUse>, Vec<String>) {
    let Lobes {
        rough,
        metal_textured,
        diffuse,
        specular,
        d_hat,
        s_hat,
        ..
    } = *lobes;
    let conductor = |spec: [f64; 3]| {
        BsdfParams::RoughConductor(RoughConductorParams {
            distribution: Distribution::Ggx,
            alpha: gltf_alpha(rough),
            eta_k: None,
            specular_reflectance: ColorParam::Rgb(spec.map(|c| c.clamp(0.0, 1.0))),
        })
    };
    let diffuse_of = |a: &Affine| BsdfParams::Diffuse {
        reflectance: ColorParam::Rgb(a.constant().map(|c| c.clamp(0.0, 1.0))),
    };
    let mut uses = Vec::new();
    let mut warnings = Vec::new();
    let mut rough_at = |path: Vec<Branch>, uses: &mut Vec<TextureUse>| {
        if let Some((t, w)) = textures.rough_use(rough, path) {
            uses.push(t);
            warnings.push(w);
        }
    };
    let (bsdf, types) = if s_hat <= 0.0 {
        uses.extend(textures.lobe_use(&diffuse, vec![], SlotKind::Reflectance, 1.0));
        (diffuse_of(&diffuse), vec!["diffuse"])
    } else if d_hat <= 0.0 {
        let kind = SlotKind::SpecularReflectance;
        uses.extend(textures.lobe_use(&specular, vec![], kind, 1.0));
        rough_at(vec![], &mut uses);
        (conductor(specular.constant()), vec!["roughconductor"])
    } else {
        // blendbsdf(w, diffuse(D/(1 − w)), roughconductor(S/w)): with a
        // metalness texture, D̂ + Ŝ may pass 1 (D̂ where m = 0, Ŝ where
        // m = metal), so the inner values may pass 1 where (1 − w)·D ≤ 1
        // and w·S ≤ 1 still hold: their bounds.
        let w = s_hat / (d_hat + s_hat);
        let (d, sp) = (diffuse.map(|c| c / (1.0 - w)), specular.map(|c| c / w));
        let (d_max, s_max) = if metal_textured {
            (1.0 / (1.0 - w), 1.0 / w)
        } else {
            (1.0, 1.0)
        };
        let kind = SlotKind::Reflectance;
        uses.extend(textures.lobe_use(&d, vec![Branch::First], kind, d_max));
        let kind = SlotKind::SpecularReflectance;
        uses.extend(textures.lobe_use(&sp, vec![Branch::Second], kind, s_max));
        rough_at(vec![Branch::Second], &mut uses);
        let blend = BsdfParams::Blend {
            weight: w,
            first: Box::new(diffuse_of(&d)),
            second: Box::new(conductor(sp.constant())),
        };
        (blend, vec!["blendbsdf", "diffuse", "roughconductor"])
    };
    (bsdf, types, uses, warnings)
}

type At<'a> = dyn Fn(&str, String) -> SceneError + 'a;

fn refuse_unsupported(m: &gltf::Material<'_>, at: &At<'_>) -> Result<()> {
    let refused = [
        (
            m.emissive_texture().is_some(),
            "/emissiveTexture",
            "emissiveTexture is not supported (trilux's area emitters have one radiance per shape)",
        ),
        (
            m.specular().is_some_and(|s| {
                s.specular_texture().is_some() || s.specular_color_texture().is_some()
            }),
            "/extensions/KHR_materials_specular",
            "the textures of KHR_materials_specular are not supported (only its factors)",
        ),
        (
            m.alpha_mode() == gltf::material::AlphaMode::Blend,
            "/alphaMode",
            "alphaMode BLEND is not supported (a surface composited over what is behind it has no physical meaning; a cut-out is MASK)",
        ),
    ];
    for (is, suffix, message) in refused {
        if is {
            return Err(at(suffix, message.into()));
        }
    }
    let changes_light = |name: &str, value: &gltf::json::Value| {
        let default_ior = name == "KHR_materials_ior"
            && value.get("ior").is_none_or(|ior| ior.as_f64() == Some(1.5));
        !default_ior && !super::IGNORED_EXTENSIONS.contains(&name)
    };
    match m
        .extensions()
        .and_then(|e| e.iter().find(|(k, v)| changes_light(k, v)))
    {
        Some((name, _)) => Err(at(&format!("/extensions/{name}"), super::refusal(name))),
        None => Ok(()),
    }
}

fn emission(m: &gltf::Material<'_>, at: &At<'_>) -> Result<Option<ColorParam>> {
    let strength = f64::from(m.emissive_strength().unwrap_or(1.0));
    let e = m.emissive_factor().map(|v| f64::from(v) * strength);
    if !e.iter().all(|v| v.is_finite() && *v >= 0.0) {
        return Err(at(
            "/emissiveFactor",
            "emitted radiance must be finite and non-negative".into(),
        ));
    }
    if let Some(v) = e.iter().find(|v| **v > crate::limits::MAX_RADIANCE) {
        return Err(at(
            "/emissiveFactor",
            format!(
                "radiance {v:e} is beyond the limit {:e} (docs/limits.md)",
                crate::limits::MAX_RADIANCE
            ),
        ));
    }
    let emits = e.iter().any(|&v| v > 0.0);
    if emits && m.double_sided() {
        return Err(at(
            "/doubleSided",
            "a double-sided emissive material is not supported: trilux's area emitters emit on their front side only (make the material single-sided, or give each side its own primitive)".into(),
        ));
    }
    Ok(emits.then_some(ColorParam::Rgb(e)))
}

/// The image, sampling, coordinate transform and place of a texture
/// reference.
fn texture_info(
    t: &gltf::texture::Info<'_>,
    at: &At<'_>,
    suffix: &str,
    location: SourceLocation,
) -> Result<(usize, Sampling, UvTransform, SourceLocation)> {
    if t.tex_coord() != 0 {
        return Err(at(
            suffix,
            format!(
                "texCoord {} is not supported (only TEXCOORD_0)",
                t.tex_coord()
            ),
        ));
    }
    let to_uv = match t.texture_transform() {
        Some(tt) => texture_transform(&tt, at, suffix)?,
        None => UvTransform::IDENTITY,
    };
    let texture = t.texture();
    let sampling = sampling(&texture, at, suffix)?;
    Ok((texture.source().index(), sampling, to_uv, location))
}

/// The `normalTexture` (linear values; `scale` multiplies the normal's x
/// and y: `trilux_brdf::normal_map`).
fn normal_texture(
    t: &gltf::material::NormalTexture<'_>,
    at: &At<'_>,
    location: SourceLocation,
) -> Result<TextureUse> {
    let suffix = "/normalTexture";
    if t.tex_coord() != 0 {
        return Err(at(
            suffix,
            format!(
                "texCoord {} is not supported (only TEXCOORD_0)",
                t.tex_coord()
            ),
        ));
    }
    if t.extension_value("KHR_texture_transform").is_some() {
        return Err(at(
            suffix,
            "KHR_texture_transform on a normalTexture is not supported".into(),
        ));
    }
    let scale = f64::from(t.scale());
    if !scale.is_finite() {
        return Err(at(suffix, format!("scale must be finite, found {scale}")));
    }
    let texture = t.texture();
    let sampling = Sampling {
        raw: true,
        ..sampling(&texture, at, suffix)?
    };
    Ok(TextureUse {
        path: Vec::new(),
        kind: SlotKind::Reflectance,
        image: texture.source().index(),
        sampling,
        scale: [1.0; 3],
        offset: [0.0; 3],
        to_uv: UvTransform::IDENTITY,
        location,
        cutoff: None,
        normal: Some(NormalPerturbation::Normal { scale, flip: false }),
        factor: None,
        max: 1.0,
    })
}

/// A texture's sampler as a [`Sampling`] (sRGB-decoded).
fn sampling(texture: &gltf::texture::Texture<'_>, at: &At<'_>, suffix: &str) -> Result<Sampling> {
    let sampler = texture.sampler();
    let wrap = |w: gltf::texture::WrappingMode| match w {
        gltf::texture::WrappingMode::Repeat => Wrap::Repeat,
        gltf::texture::WrappingMode::MirroredRepeat => Wrap::Mirror,
        gltf::texture::WrappingMode::ClampToEdge => Wrap::Clamp,
    };
    let (ws, wt) = (wrap(sampler.wrap_s()), wrap(sampler.wrap_t()));
    if ws != wt {
        return Err(at(suffix, "a sampler with different wrapS and wrapT is not supported (Mitsuba's bitmap has one wrap_mode)".into()));
    }
    let filter = match sampler.mag_filter() {
        Some(gltf::texture::MagFilter::Nearest) => Filter::Nearest,
        _ => Filter::Bilinear,
    };
    Ok(Sampling {
        wrap: [ws, wt],
        filter,
        raw: false,
        alpha: false,
        channel: None,
    })
}

/// `KHR_texture_transform` as the map from TEXCOORD_0 to the image's
/// coordinates: T · R · S (the extension's order), with R the rotation that
/// implementations and the extension's sample model agree on, (u, v) ↦
/// (c·u + s·v, −s·u + c·v), counter-clockwise in glTF's v-down coordinates
/// (the extension's GLSL listing has the opposite sign; KhronosGroup/glTF
/// issue 1563).
fn texture_transform(
    tt: &gltf::texture::TextureTransform<'_>,
    at: &At<'_>,
    suffix: &str,
) -> Result<UvTransform> {
    if let Some(tc) = tt.tex_coord()
        && tc != 0
    {
        return Err(at(
            suffix,
            format!("KHR_texture_transform's texCoord {tc} is not supported (only TEXCOORD_0)"),
        ));
    }
    let [ox, oy] = tt.offset().map(f64::from);
    let [sx, sy] = tt.scale().map(f64::from);
    let (s, c) = f64::from(tt.rotation()).sin_cos();
    let m = UvTransform([c * sx, s * sy, ox, -s * sx, c * sy, oy]);
    if !m.0.iter().all(|v| v.is_finite()) {
        return Err(at(
            suffix,
            "KHR_texture_transform has a value that is not finite".into(),
        ));
    }
    Ok(m)
}
