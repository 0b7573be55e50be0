//! RGB or spectral: how one solve carries light (design.md §2).

use serde::{Deserialize, Serialize};

use crate::param::ColorParam;

/// How a solve carries light.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Mode {
    /// Three bands of linear sRGB, as Mitsuba 3's `*_rgb` variants.
    Rgb,
    /// Spectral bands (10 by default, as in the paper), as Mitsuba 3's
    /// `*_spectral` variants.
    Spectral,
}

impl Mode {
    /// The default band count of this mode: 3 for RGB, 10 for spectral.
    pub const fn default_bands(self) -> usize {
        match self {
            Mode::Rgb => 3,
            Mode::Spectral => 10,
        }
    }

    /// The mode a scene is solved in (design.md §2): spectral when some
    /// value is a sampled `<spectrum>` (wavelength:value pairs), RGB
    /// otherwise. A single-value `<spectrum>` does not make a scene spectral.
    pub fn for_values<'a>(values: impl IntoIterator<Item = &'a ColorParam>) -> Mode {
        if values.into_iter().any(ColorParam::is_sampled) {
            Mode::Spectral
        } else {
            Mode::Rgb
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
