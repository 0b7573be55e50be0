//! # trilux-brdf — reflectance
//!
//! Layer: depends on `trilux-color` (spectra), `trilux-frame` (the side of
//! a surface, [`Side`], and the tangent frame), `glam`, `serde` and
//! `thiserror`, not on the geometry; nothing here parses files or
//! knows about elements beyond points and normals (so it can be used
//! without the solver). Every model is defined exactly as Mitsuba 3 defines it.
//!
//! Contents, in reading order:
//! - [`params`]: material parameters as plain data ([`BsdfParams`]), the
//!   Mitsuba 3 BSDF subset that trilux supports.
//! - [`bsdf`]: [`Bsdf<N>`](Bsdf), a material ready to evaluate: `eval`
//!   (fr), `sample` (fr·cos importance sampling), `pdf`, `albedo`, and the
//!   Lambertian / glossy split the solver uses.
//! - [`frame`]: local frames (z = front normal; `wi` to the light, `wo` to the
//!   viewer).
//! - [`lobe`]: one side of a material: `diffuse`, `roughconductor`,
//!   `plastic`/`roughplastic`, `blendbsdf`.
//! - [`plastic`]: Mitsuba's `plastic` and `roughplastic` (a diffuse base
//!   under a dielectric coat) and how the solver splits them.
//! - [`microfacet`]: Mitsuba's Beckmann and GGX D, separable Smith G (its
//!   rational G1 for Beckmann), and their sampling.
//! - [`conductors`]: Mitsuba's named conductors (`material="Cu"`), their
//!   measured η and k.
//! - `special` (private): erf and its inverse (Beckmann visible-normal
//!   sampling).
//! - `fresnel` (private): conductor Fresnel from η and k, dielectric
//!   Fresnel and its diffuse reflectance F_dr.
//! - [`albedo`]: [`AlbedoTable`], the directional albedo tabulated per
//!   degree for frequent use.
//! - [`texture`]: bitmap textures ([`Texture`]) with Mitsuba 3's
//!   bilinear and nearest lookups and wrap modes.
//! - [`textured`]: materials whose Lambertian reflectance and glossy weight
//!   vary over a surface ([`TexturedBsdf`], [`TextureSlot`]) and the
//!   material at one point ([`Shading`]).
//! - [`slot`]: the parameter a texture stands for ([`TextureSlot`]) and
//!   its value, a product of two textures included ([`SlotFactor`]).
//! - [`area`]: area reflectance R(I→J→K) = π F_JI fr (paper Eq. 5) and the
//!   BRDF variation estimate over three elements (docs/solver.md,
//!   "Refinement").
#![forbid(unsafe_code)]
// Band loops index several arrays in step; iterators would hide that.
#![allow(clippy::needless_range_loop)]

pub mod albedo;
pub mod area;
pub mod bsdf;
pub mod conductors;
pub mod error;
pub mod frame;
mod fresnel;
pub mod lobe;
pub mod microfacet;
pub mod normal_map;
pub mod params;
pub mod plastic;
pub mod slot;
mod special;
pub mod texture;
pub mod textured;

pub use albedo::AlbedoTable;
pub use area::{
    AreaReflectance, BrdfVariation, ElementPoints, LobeSample, area_reflectance, brdf_variation,
    is_narrow, lobe_width, sample_glossy_lobe,
};
pub use bsdf::{Bsdf, BsdfSample};
pub use conductors::{conductor_names, named_conductor};
pub use error::BrdfError;
pub use frame::Frame;
pub use normal_map::{NormalMap, NormalPerturbation, TangentFrame};
pub use params::{
    BsdfParams, Distribution, MIRROR_ALPHA, NAMED_IORS, PlasticParams, RoughConductorParams,
    named_ior,
};
pub use plastic::Plastic;
pub use texture::{Filter, Texture, UvTransform, Wrap};
pub use textured::{
    Branch, MIN_GLTF_ALPHA, PointParts, Shading, SlotFactor, SlotKind, SlotValues, TextureSlot,
    TexturedBsdf, gltf_alpha,
};
pub use trilux_frame::Side;
