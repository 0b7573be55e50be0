//! RGB or spectral: how one solve carries light, and [`WithBands`], the one
//! place that turns a [`Mode`] into a band count for code generic over it.

use serde::{Deserialize, Serialize};

/// Bands of spectral mode: 20 of 15 nm over 400–700 nm (the outer ones
/// reaching 360 and 830 nm). The paper used 10;
/// against Mitsuba 3's continuous spectral rendering of the Cornell box,
/// band averaging alone costs 0.73 % of the image mean with 10 bands and
/// 0.33 % with 20, at no measurable solve cost (docs/results.md).
pub const SPECTRAL_BANDS: usize = 20;

/// Code to run with a band count chosen at run time ([`Mode::with_bands`]);
/// closures cannot be generic over a const, so the code is a type.
pub trait WithBands {
    /// What the code returns.
    type Output;
    /// Runs with `N` bands.
    fn run<const N: usize>(self) -> Self::Output;
}

/// How a solve carries light.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Mode {
    /// Three bands of linear sRGB, as Mitsuba 3's `*_rgb` variants.
    Rgb,
    /// Spectral bands ([`SPECTRAL_BANDS`] by default; the paper used 10),
    /// as Mitsuba 3's `*_spectral` variants.
    Spectral,
}

impl Mode {
    /// The default band count of this mode: 3 for RGB,
    /// [`SPECTRAL_BANDS`] for spectral.
    pub const fn default_bands(self) -> usize {
        match self {
            Mode::Rgb => 3,
            Mode::Spectral => SPECTRAL_BANDS,
        }
    }

    /// Runs code generic over the band count with this mode's band count
    /// (3 or [`SPECTRAL_BANDS`]): the one `match` from a runtime mode to a
    /// compile-time `N`.
    pub fn with_bands<F: WithBands>(self, f: F) -> F::Output {
        match self {
            Mode::Rgb => f.run::<3>(),
            Mode::Spectral => f.run::<SPECTRAL_BANDS>(),
        }
    }

    /// The lower-case name used on the command line and in stats (`rgb`,
    /// `spectral`).
    pub const fn name(self) -> &'static str {
        match self {
            Mode::Rgb => "rgb",
            Mode::Spectral => "spectral",
        }
    }
}

impl std::str::FromStr for Mode {
    type Err = crate::ColorError;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "rgb" => Ok(Mode::Rgb),
            "spectral" => Ok(Mode::Spectral),
            other => Err(crate::ColorError::UnknownMode(other.to_string())),
        }
    }
}

impl std::fmt::Display for Mode {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}
