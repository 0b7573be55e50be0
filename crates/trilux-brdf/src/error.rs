//! Errors of this crate (never a panic on bad parameters).

use thiserror::Error;

/// What is wrong with a material.
#[derive(Clone, Debug, Error, PartialEq)]
#[non_exhaustive]
pub enum BrdfError {
    /// A colour parameter could not be converted.
    #[error("{what}: {source}")]
    Color {
        /// Which parameter.
        what: &'static str,
        /// Why.
        source: trilux_color::ColorError,
    },
    /// Roughness must be finite and positive.
    #[error("roughness alpha must be finite and > 0, got {0}")]
    BadAlpha(f64),
    /// Indices of refraction must be finite and positive (and differ for a
    /// rough coat, as Mitsuba requires).
    #[error(
        "plastic int_ior and ext_ior must be finite, > 0 (and differ for roughplastic), got {0}"
    )]
    BadIor(f64),
    /// The blend weight must lie in [0, 1].
    #[error("blendbsdf weight must lie in [0, 1], got {0}")]
    BadWeight(f64),
    /// `twosided` may only appear at the top of a material, as in Mitsuba.
    #[error("twosided may not be nested inside another BSDF")]
    NestedTwoSided,
    /// A texture's texel count does not match its size.
    #[error("a texture of {width} × {height} texels cannot hold {texels}")]
    TextureSize {
        /// Width.
        width: u32,
        /// Height.
        height: u32,
        /// Texels given.
        texels: usize,
    },
    /// A texel is negative or not finite.
    #[error("a texture has a texel that is negative or not a finite number")]
    TextureValue,
    /// Textures are RGB: a solve in spectral bands would upsample every
    /// lookup.
    #[error("textured materials need RGB mode (--mode rgb): textures are RGB images")]
    TexturedSpectral,
    /// More textures on one material than it takes.
    #[error("a material takes at most 4 textures (MAX_SLOTS), found {0}")]
    TooManyTextures(usize),
    /// A texture stands for no parameter of its material.
    #[error("a texture stands for no parameter of its material ({0})")]
    TextureSlot(String),
    /// A textured side with more than one roughconductor.
    #[error(
        "a textured material may have at most one roughconductor on each side (its glossy part must be one lobe whose weight varies)"
    )]
    TexturedConductors,
}
