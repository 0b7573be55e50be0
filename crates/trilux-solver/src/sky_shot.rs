//! The sky's deposits (docs/solver.md, "The sky"): an environment map is a
//! distant source shot as the lights without area are (`light_shot`),
//! once, into every leaf element of every face. A leaf receives
//! ∫ E dA, E(y) = ∫ L(ω) V(y, ω) cos θ dω, estimated at the light shot's
//! 16 stratified points with [`DIRECTIONS`] directions each, drawn from
//! the sky's importance distribution (`crate::sky`): E ≈ (1/M) Σ L cos V / p.
//! The directions are a fixed Hammersley set, rotated per leaf by a hash
//! of its id (Cranley–Patterson), so the solve is reproducible and
//! neighbouring leaves do not share one pattern of shadows.

use glam::{DVec2, DVec3};
use trilux_color::Spectrum;
use trilux_geometry::FaceId;

use crate::light_shot::{Deposit, POINTS_PER_SIDE};
use crate::solver::Solver;

/// Sky directions per point of a leaf (16 points: 128 shadow rays a leaf).
pub(crate) const DIRECTIONS: u32 = 8;

/// A hash of `k` to [0, 1)² (SplitMix64's finaliser).
fn rotation(k: u32) -> DVec2 {
    let mut h = u64::from(k).wrapping_add(0x9E37_79B9_7F4A_7C15);
    h = (h ^ (h >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    h = (h ^ (h >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    h ^= h >> 31;
    DVec2::new(
        (h >> 40) as f64 / 16_777_216.0,
        ((h >> 8) & 0xFF_FFFF) as f64 / 16_777_216.0,
    )
}

impl<const N: usize> Solver<N> {
    /// What the sky brings to each leaf of face `f` (leaves it does not
    /// reach are left out).
    pub(crate) fn sky_deposits(&self, f: FaceId) -> Vec<Deposit<N>> {
        let Some(sky) = self.setup.scene.sky() else {
            return Vec::new();
        };
        let forest = self.setup.forest();
        let geometry = forest.geometry();
        let sign = f.side().sign();
        let n = POINTS_PER_SIDE;
        let total = n * n * DIRECTIONS;
        let mut out = Vec::new();
        for leaf in self.lit_leaves(f) {
            let shift = rotation(leaf.0 ^ (u32::from(sign > 0.0) << 31));
            let mut arrived = Spectrum::<N>::zero();
            let mut towards = DVec3::ZERO;
            for (s, y) in self.leaf_points(f, leaf) {
                let normal = sign * y.normal;
                let mut e = Spectrum::<N>::zero();
                for m in 0..DIRECTIONS {
                    // Point s takes every n²-th point of the set.
                    let t = m * n * n + s;
                    let h = trilux_geometry::sampling::hammersley(t, total);
                    let h = (h + shift).fract();
                    let Some(smp) = sky.sample(h) else {
                        continue;
                    };
                    let cos = normal.dot(smp.wi);
                    if cos <= 0.0 || smp.radiance.is_black() {
                        continue;
                    }
                    // The fraction the way out lets through (panes of
                    // glass, as for the lights), 0 when blocked.
                    let end = self.setup.scene.sky_end(y.point, smp.wi);
                    let tau = geometry.transmittance(y.point, end);
                    if tau <= 0.0 {
                        continue;
                    }
                    let c = smp.radiance * (tau * cos / smp.pdf);
                    towards += smp.wi * c.average();
                    e += c;
                }
                arrived += e * (1.0 / (f64::from(DIRECTIONS) * y.pdf_area));
            }
            if arrived.max_value() > 0.0 {
                let mean = forest.element(leaf).normal * sign;
                out.push(Deposit {
                    face: f,
                    leaf,
                    arrived: arrived * (1.0 / f64::from(n * n)),
                    wi: towards.try_normalize().unwrap_or(mean),
                });
            }
        }
        out
    }
}
