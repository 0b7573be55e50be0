//! The parameter a texture stands for ([`TextureSlot`]) and its value at a
//! point: `offset + scale ⊙ t`, with t the texture's RGB, plus, when the
//! slot has a [`SlotFactor`], `f · (offset' + scale' ⊙ t)` with f a second
//! texture's value. The second term is what a product of two textures
//! needs: glTF's diffuse part (1 − m)(1 − F)·B is linear in the base colour
//! B and in the metalness m separately, not jointly, so it is evaluated as
//! the product at each lookup (exact, whatever the two textures' mappings;
//! an element's average of it is the average of the product).

use std::sync::Arc;

use glam::DVec2;
use serde::Serialize;
use trilux_color::luminance;

use crate::texture::{Texture, UvTransform};

/// The smallest GGX α of a glTF roughness (roughness 0.1): smoother
/// surfaces are mirrors that no element-based solve can resolve
/// (docs/gltf.md).
pub const MIN_GLTF_ALPHA: f64 = 0.01;

/// The GGX α of glTF roughness `r`: α = max(r², [`MIN_GLTF_ALPHA`]) (glTF
/// 2.0, Appendix B: α = roughness²).
pub fn gltf_alpha(r: f64) -> f64 {
    let r = if r.is_finite() {
        r.clamp(0.0, 1.0)
    } else {
        1.0
    };
    (r * r).max(MIN_GLTF_ALPHA)
}

/// One step from a BSDF to a BSDF nested in it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum Branch {
    /// The front BSDF of a `twosided` (both sides when it has one only).
    Front,
    /// The back BSDF of a `twosided` with two.
    Back,
    /// The first BSDF of a `blendbsdf`.
    First,
    /// The second BSDF of a `blendbsdf`.
    Second,
}

/// Which parameter a texture stands for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum SlotKind {
    /// `reflectance` of a `diffuse`, `diffuse_reflectance` of a `plastic`
    /// or `roughplastic`.
    Reflectance,
    /// `specular_reflectance` of a `roughconductor`.
    SpecularReflectance,
    /// `weight` of a `blendbsdf` (the texture's luminance).
    Weight,
    /// The glTF roughness r of a `roughconductor` (the first channel):
    /// α = [`gltf_alpha`]\(r). Not linear in the BRDF: the render takes
    /// each point's α, the solve the material's nominal one
    /// (`crate::textured`).
    Roughness,
}

/// A second texture multiplying part of a slot's value (module docs).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SlotFactor {
    /// The image; its first channel is the factor f.
    #[serde(serialize_with = "texture_summary")]
    pub texture: Arc<Texture>,
    /// The map from the surface's texture coordinates to the image's.
    pub to_uv: UvTransform,
    /// The term f multiplies is offset + scale ⊙ t.
    pub scale: [f64; 3],
    /// See `scale`.
    pub offset: [f64; 3],
}

/// A texture standing for one parameter of a material (module docs).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TextureSlot {
    /// The path from the top of the material to the BSDF that has the
    /// parameter.
    pub path: Vec<Branch>,
    /// The parameter.
    pub kind: SlotKind,
    /// The image.
    #[serde(serialize_with = "texture_summary")]
    pub texture: Arc<Texture>,
    /// value = offset + scale ⊙ texture (per RGB channel).
    pub scale: [f64; 3],
    /// See `scale`.
    pub offset: [f64; 3],
    /// The map from the surface's texture coordinates to the image's.
    pub to_uv: UvTransform,
    /// A second texture multiplying part of the value (module docs).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub factor: Option<SlotFactor>,
    /// The largest value a point takes (a reflectance's 1, unless the
    /// parameter is one of a blend's, where (1 − w)·ρ ≤ 1 is the bound
    /// that conserves energy: glTF's blend with a metalness texture). The
    /// nominal value stays within [0, 1].
    #[serde(skip_serializing_if = "is_one")]
    pub max: f64,
}

fn is_one(v: &f64) -> bool {
    *v == 1.0
}

fn texture_summary<S: serde::Serializer>(t: &Arc<Texture>, s: S) -> Result<S::Ok, S::Error> {
    t.as_ref().serialize(s)
}

impl TextureSlot {
    /// The linear part offset + scale ⊙ `rgb` for the texture value `rgb`.
    pub fn value(&self, rgb: [f64; 3]) -> [f64; 3] {
        std::array::from_fn(|c| self.offset[c] + self.scale[c] * rgb[c])
    }

    /// The value for texture value `rgb` and factor `f` (module docs),
    /// before clamping.
    fn combined(&self, rgb: [f64; 3], f: f64) -> [f64; 3] {
        let v = self.value(rgb);
        match &self.factor {
            None => v,
            Some(k) => std::array::from_fn(|c| v[c] + f * (k.offset[c] + k.scale[c] * rgb[c])),
        }
    }

    /// The value at texture coordinates `uv`, within the parameter's range.
    pub fn at(&self, uv: DVec2) -> [f64; 3] {
        let rgb = self.texture.eval(self.to_uv.apply(uv));
        let f = self
            .factor
            .as_ref()
            .map_or(0.0, |k| k.texture.eval(k.to_uv.apply(uv))[0]);
        self.clamped(self.combined(rgb, f), self.max)
    }

    /// The value at the textures' means, within [0, 1]: the nominal value
    /// (for a factor, the product of the means).
    pub fn nominal(&self) -> [f64; 3] {
        let f = self.factor.as_ref().map_or(0.0, |k| k.texture.mean()[0]);
        self.clamped(self.combined(self.texture.mean(), f), 1.0)
    }

    /// `v` within the parameter's range: [0, `max`] for reflectances, a
    /// weight's luminance within [0, 1], a roughness's first channel
    /// within [0, 1]. Non-finite values (never from valid textures) are 0.
    fn clamped(&self, v: [f64; 3], max: f64) -> [f64; 3] {
        let v = v.map(|c| if c.is_finite() { c.max(0.0) } else { 0.0 });
        match self.kind {
            SlotKind::Weight => [luminance(v).clamp(0.0, 1.0); 3],
            SlotKind::Roughness => [v[0].min(1.0); 3],
            SlotKind::Reflectance | SlotKind::SpecularReflectance => v.map(|c| c.min(max)),
        }
    }
}
