//! Material parameters as plain data, in Mitsuba 3's terms.
//!
//! The scene loader fills these from `<bsdf>` elements; the models in this
//! crate give them behaviour once the solve's spectral mode is known.

use serde::{Deserialize, Serialize};
use trilux_color::ColorParam;

/// Microfacet normal distribution of `roughconductor` and `roughplastic`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[non_exhaustive]
pub enum Distribution {
    /// Beckmann (Mitsuba's default).
    Beckmann,
    /// GGX / Trowbridge–Reitz.
    Ggx,
}

/// The roughness that stands for a perfectly smooth surface (Mitsuba's
/// `conductor`, a mirror with a Dirac lobe): a Beckmann lobe of this α.
/// Its values differ from the Dirac lobe's only within about 3α = 3e-4 rad
/// of the mirror direction (Beckmann's D falls as exp(−tan²θ/α²)), where
/// it keeps the Dirac lobe's energy (Beckmann's G1 is exactly 1 unless
/// tan θ > 1/(1.6 α), within 0.01° of grazing); the solver samples it as a narrow lobe and the
/// render continues paths through it (docs/solver.md, "Narrow lobes";
/// docs/rendering.md, "Near-specular surfaces"), as for the α = 1e-4
/// mirrors measured in docs/results.md.
pub const MIRROR_ALPHA: f64 = 1e-5;

/// Parameters of Mitsuba 3's `roughconductor` (isotropic only), and of
/// its smooth `conductor` as a Beckmann lobe of α = [`MIRROR_ALPHA`].
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

/// Parameters of Mitsuba 3's `plastic` (`coat` = `None`) and `roughplastic`:
/// a diffuse base under a dielectric coat (see [`crate::plastic`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PlasticParams {
    /// Reflectance of the diffuse base. Default 0.5.
    pub diffuse_reflectance: ColorParam,
    /// Multiplies the coat's reflection. Default 1.
    pub specular_reflectance: ColorParam,
    /// Index of refraction inside the coat. Default 1.49 (polypropylene).
    pub int_ior: f64,
    /// Index of refraction outside. Default 1.000277 (air).
    pub ext_ior: f64,
    /// Internal scattering tints the base (ρ/(1 − ρ F_dr) instead of
    /// ρ/(1 − F_dr)). Default false.
    pub nonlinear: bool,
    /// The rough coat's distribution and roughness α (`roughplastic`;
    /// Mitsuba's defaults Beckmann, 0.1); `None` for the smooth `plastic`.
    pub coat: Option<(Distribution, f64)>,
}

impl PlasticParams {
    /// Mitsuba's defaults: white-ish polypropylene in air, smooth coat.
    pub fn smooth() -> Self {
        PlasticParams {
            diffuse_reflectance: ColorParam::Float(0.5),
            specular_reflectance: ColorParam::Float(1.0),
            int_ior: 1.49,
            ext_ior: 1.000277,
            nonlinear: false,
            coat: None,
        }
    }

    /// Mitsuba's `roughplastic` defaults (Beckmann, α = 0.1).
    pub fn rough() -> Self {
        PlasticParams {
            coat: Some((Distribution::Beckmann, 0.1)),
            ..Self::smooth()
        }
    }
}

/// Mitsuba 3's named indices of refraction (`include/mitsuba/render/ior.h`,
/// after Hecht, "Optics"; 0–20 °C at ≈ 589 nm), for `int_ior`/`ext_ior`
/// given by name.
pub const NAMED_IORS: [(&str, f64); 23] = [
    ("vacuum", 1.0),
    ("helium", 1.000036),
    ("hydrogen", 1.000132),
    ("air", 1.000277),
    ("carbon dioxide", 1.00045),
    ("water", 1.3330),
    ("acetone", 1.36),
    ("ethanol", 1.361),
    ("carbon tetrachloride", 1.461),
    ("glycerol", 1.4729),
    ("benzene", 1.501),
    ("silicone oil", 1.52045),
    ("bromine", 1.661),
    ("water ice", 1.31),
    ("fused quartz", 1.458),
    ("pyrex", 1.470),
    ("acrylic glass", 1.49),
    ("polypropylene", 1.49),
    ("bk7", 1.5046),
    ("sodium chloride", 1.544),
    ("amber", 1.55),
    ("pet", 1.5750),
    ("diamond", 2.419),
];

/// The index of refraction Mitsuba names `name` (case-insensitive).
pub fn named_ior(name: &str) -> Option<f64> {
    let lower = name.to_lowercase();
    NAMED_IORS
        .iter()
        .find(|(n, _)| *n == lower)
        .map(|&(_, v)| v)
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
    /// `plastic` and `roughplastic`: a diffuse base under a dielectric coat,
    /// black on the back.
    Plastic(PlasticParams),
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
