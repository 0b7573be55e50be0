//! Deterministic low-discrepancy points: Owen-scrambled Sobol samples
//! (sobol_burley) with seeds derived from element ids, so that every
//! sampled estimate (visibility, sampled form factors) is reproducible and
//! the same for (a, b) and (b, a).

use glam::DVec2;

use crate::ids::ElementId;

/// A 32-bit mix of two integers (SplitMix-style finaliser).
fn hash2(a: u32, b: u32) -> u32 {
    let mut h = (a as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15)
        ^ (b as u64).wrapping_mul(0xC2B2_AE3D_27D4_EB4F);
    h ^= h >> 31;
    h = h.wrapping_mul(0xBF58_476D_1CE4_E5B9);
    (h ^ (h >> 29)) as u32
}

/// Stratified 2-D sample `k` (Owen-scrambled Sobol), dimensions `dim`, `dim+1`.
pub(crate) fn sobol2(k: u32, dim: u32, seed: u32) -> DVec2 {
    DVec2::new(
        sobol_burley::sample(k, dim, seed) as f64,
        sobol_burley::sample(k, dim + 1, seed) as f64,
    )
}

/// The scrambling seed of an ordered element pair.
pub(crate) fn seed_of(a: ElementId, b: ElementId) -> u32 {
    hash2(a.0, b.0)
}
