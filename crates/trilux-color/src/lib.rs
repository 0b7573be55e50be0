//! # trilux-color — the lowest layer: light as spectra
//!
//! Layer: depends on nothing else in trilux (only `serde` and `thiserror`).
//! Everything above carries light with the types defined here.
//!
//! Contents, in reading order:
//! - [`spectrum`]: [`Spectrum<N>`](Spectrum), light in `N` bands (3: RGB
//!   mode, 20 in spectral mode, any N in general), per-band arithmetic, XYZ and
//!   luminance.
//! - [`mode`]: [`Mode`] (RGB or spectral) and the rule that picks it.
//! - [`param`]: colour values as a scene file states them ([`ColorParam`]).
//! - [`convert`]: [`ColorParam`] → [`Spectrum<N>`](Spectrum) as a
//!   reflectance, an emission or an unbounded quantity ([`Role`]), exactly as
//!   Mitsuba 3 converts them.
//! - [`cie`]: the CIE 1931 2° observer (1 nm), D65, sampled spectra and their
//!   exact XYZ; Mitsuba 3's own quadrature for RGB mode.
//! - [`bands`]: the spectral bands (400–700 nm split evenly, outer bands to
//!   360 and 830 nm) and their band-integrated colour-matching functions.
//! - [`upsample`]: RGB → smooth band spectrum for RGB values in a spectral
//!   scene, with its measured round-trip error.
//! - [`srgb`]: XYZ → linear sRGB → sRGB-encoded 8-bit values, and RGB
//!   luminance ([`luminance`], the one definition).
#![forbid(unsafe_code)]
// Band and channel loops index several arrays in step; iterators would hide that.
#![allow(clippy::needless_range_loop)]

pub mod bands;
pub mod cie;
mod cie_data;
pub mod convert;
pub mod error;
pub mod mode;
pub mod param;
pub mod spectrum;
pub mod srgb;
pub mod upsample;

pub use bands::Bands;
pub use cie::SampledSpectrum;
pub use convert::Role;
pub use error::ColorError;

/// Largest emitted radiance a scene may state, in any band (1e20; see
/// docs/limits.md): light is summed over bounces, bands and areas and kept
/// in 32-bit floats (largest 3.4e38) in solution and image files, so 1e20
/// leaves eighteen orders of magnitude for the sums (the sun's radiance is
/// about 2e7 W/(sr m²)).
pub const MAX_RADIANCE: f64 = 1e20;
pub use mode::{Mode, SPECTRAL_BANDS, WithBands};
pub use param::ColorParam;
pub use spectrum::{Rgb, Spectrum};
pub use srgb::luminance;
