//! Errors of this crate (never a panic on bad parameters).

use thiserror::Error;

/// What is wrong with a material.
#[derive(Clone, Debug, Error, PartialEq)]
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
    #[error("roughconductor alpha must be finite and > 0, got {0}")]
    BadAlpha(f64),
    /// The blend weight must lie in [0, 1].
    #[error("blendbsdf weight must lie in [0, 1], got {0}")]
    BadWeight(f64),
    /// `twosided` may only appear at the top of a material, as in Mitsuba.
    #[error("twosided may not be nested inside another BSDF")]
    NestedTwoSided,
}
