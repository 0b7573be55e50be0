//! Colour values exactly as a scene file states them.
//!
//! The scene layer records *what was written* (an `<rgb>`, a `<float>`, a
//! single-value or a sampled `<spectrum>`); conversion into the spectra of a
//! particular solve (3 RGB bands or N spectral bands) happens later, because
//! Mitsuba 3 converts the same written value differently for a reflectance
//! and for an emitter (docs/architecture.md, "Colour").

use serde::{Deserialize, Serialize};

/// A colour-valued parameter as written in a scene file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum ColorParam {
    /// `<float value="v">`: the value `v` in every channel.
    Float(f64),
    /// `<rgb value="r, g, b">`: linear sRGB.
    Rgb([f64; 3]),
    /// `<spectrum value="v">`: a constant spectrum. On an emitter Mitsuba 3
    /// reads this as the equal-energy spectrum scaled by `v`; on a
    /// reflectance, as `v` in every channel.
    Constant(f64),
    /// `<spectrum value="λ:v, λ:v, ...">`: samples (wavelength in nm, value),
    /// ascending in wavelength, linear in between and zero outside.
    Sampled(Vec<(f64, f64)>),
    /// A measured spectrum named by a preset rather than written (a
    /// conductor's `material="Cu"`: Mitsuba's `data/ior` tables), samples
    /// as in [`ColorParam::Sampled`]. RGB mode converts it as Mitsuba's
    /// `ior_from_file` does (no illuminant, negative channels to 0);
    /// spectral mode as a sampled spectrum. It does not make a scene
    /// spectral: Mitsuba's RGB variants take such a preset as RGB.
    Measured(Vec<(f64, f64)>),
}

impl ColorParam {
    /// True when this value makes a scene spectral (docs/architecture.md, "Colour": a
    /// `<spectrum>` with wavelength:value pairs).
    pub fn is_sampled(&self) -> bool {
        matches!(self, ColorParam::Sampled(_))
    }

    /// Every number in the value, for validation (finite, non-negative).
    pub fn values(&self) -> Vec<f64> {
        match self {
            ColorParam::Float(v) | ColorParam::Constant(v) => vec![*v],
            ColorParam::Rgb(c) => c.to_vec(),
            ColorParam::Sampled(s) | ColorParam::Measured(s) => s.iter().map(|&(_, v)| v).collect(),
        }
    }
}
