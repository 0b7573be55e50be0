//! # trilux-brdf — reflectance
//!
//! Layer: depends on `trilux-color` (spectra) and `trilux-geometry`
//! (elements, for area reflectance). Nothing here parses files.
//!
//! Contents:
//! - [`params`]: material parameters as plain data ([`BsdfParams`]), exactly
//!   the Mitsuba 3 BSDF subset that trilux supports.
#![forbid(unsafe_code)]

pub mod params;

pub use params::{BsdfParams, Distribution, RoughConductorParams};
