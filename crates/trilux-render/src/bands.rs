//! Per-band radiance as plain `[f64; N]` arrays.
//!
//! The integrator is generic over the number of bands `N` (3 in RGB mode,
//! 20 in spectral mode). It only needs addition and products, so
//! it works on arrays; the adapter to the solver converts its spectra.

/// All bands zero.
pub fn zero<const N: usize>() -> [f64; N] {
    [0.0; N]
}

/// Every band set to `v`.
pub fn splat<const N: usize>(v: f64) -> [f64; N] {
    [v; N]
}

/// `a + b` per band.
pub fn add<const N: usize>(a: [f64; N], b: [f64; N]) -> [f64; N] {
    std::array::from_fn(|i| a[i] + b[i])
}

/// `a · b` per band.
pub fn mul<const N: usize>(a: [f64; N], b: [f64; N]) -> [f64; N] {
    std::array::from_fn(|i| a[i] * b[i])
}

/// `a · s`.
pub fn scale<const N: usize>(a: [f64; N], s: f64) -> [f64; N] {
    std::array::from_fn(|i| a[i] * s)
}

/// True when every band is exactly zero.
pub fn is_black<const N: usize>(a: &[f64; N]) -> bool {
    a.iter().all(|&v| v == 0.0)
}

/// True when every band is finite.
pub fn is_finite<const N: usize>(a: &[f64; N]) -> bool {
    a.iter().all(|v| v.is_finite())
}
