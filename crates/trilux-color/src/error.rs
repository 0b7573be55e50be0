//! Errors of this crate: bad colour values (never a panic).

use thiserror::Error;

/// What is wrong with a colour value.
#[derive(Clone, Debug, Error, PartialEq)]
#[non_exhaustive]
pub enum ColorError {
    /// A sampled spectrum needs at least two wavelength:value pairs.
    #[error("a sampled spectrum needs at least two wavelength:value pairs, got {0}")]
    TooFewSamples(usize),
    /// Wavelengths must be strictly ascending.
    #[error("wavelengths must be strictly ascending (at {0} nm)")]
    NotAscending(f64),
    /// A value or wavelength is NaN or infinite.
    #[error("colour values must be finite")]
    NotFinite,
    /// A value is negative.
    #[error("colour values must not be negative (got {0})")]
    Negative(f64),
    /// `--mode` must be `rgb` or `spectral`.
    #[error("unknown colour mode `{0}` (expected `rgb` or `spectral`)")]
    UnknownMode(String),
}
