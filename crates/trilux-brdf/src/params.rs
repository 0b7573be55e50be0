//! Material parameters as plain data, in Mitsuba 3's terms.
//!
//! The scene loader fills these from `<bsdf>` elements; the models in this
//! crate give them behaviour once the solve's spectral mode is known.

use serde::{Deserialize, Serialize};
use trilux_color::ColorParam;

/// Microfacet normal distribution of `roughconductor`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[non_exhaustive]
pub enum Distribution {
    /// Beckmann (Mitsuba's default).
    Beckmann,
    /// GGX / Trowbridge–Reitz.
    Ggx,
}

/// Parameters of Mitsuba 3's `roughconductor` (isotropic only).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RoughConductorParams {
    /// Normal distribution.
    pub distribution: Distribution,
    /// Roughness α, used as given (no remapping). Mitsuba's default is 0.1.
    pub alpha: f64,
    /// Complex index of refraction (η, k); `None` for `material="none"`,
    /// which means Fresnel = 1.
    pub eta_k: Option<(ColorParam, ColorParam)>,
    /// Multiplies the Fresnel term. Default 1.
    pub specular_reflectance: ColorParam,
}

/// A BSDF of the supported Mitsuba 3 subset.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum BsdfParams {
    /// `diffuse`: fr = ρ/π on the front side, black on the back.
    Diffuse {
        /// Reflectance ρ (Mitsuba's default 0.5).
        reflectance: ColorParam,
    },
    /// `roughconductor`: a microfacet conductor, black on the back.
    RoughConductor(RoughConductorParams),
    /// `blendbsdf`: (1 − weight) · first + weight · second.
    Blend {
        /// Blend weight in [0, 1].
        weight: f64,
        /// The first nested BSDF.
        first: Box<BsdfParams>,
        /// The second nested BSDF.
        second: Box<BsdfParams>,
    },
    /// `twosided`: `front` on the front side; on the back side `back`, or
    /// `front` again when only one BSDF is nested.
    TwoSided {
        /// BSDF of the front side.
        front: Box<BsdfParams>,
        /// BSDF of the back side, if a second one is nested.
        back: Option<Box<BsdfParams>>,
    },
}

impl Default for BsdfParams {
    /// Mitsuba's BSDF for a shape that names none: `diffuse` with 0.5.
    fn default() -> Self {
        BsdfParams::Diffuse {
            reflectance: ColorParam::Float(0.5),
        }
    }
}
