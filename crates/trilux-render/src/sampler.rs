//! Low-discrepancy samples: Owen-scrambled Sobol (Burley 2020, via the
//! `sobol_burley` crate).
//!
//! Each pixel gets its own scramble, a hash of (render seed, pixel x, pixel
//! y), so its error is decorrelated from its neighbours' (noise rather than
//! structured artifacts), and each camera sample of a pixel is one point of
//! that pixel's sequence. Every dimension an estimator uses has a fixed index
//! (see [`dims`]), so a render is a pure function of (scene, settings, seed).
//! `sobol_burley` allows 2^16 samples per pixel and 256 dimensions.

use glam::DVec2;

/// Fixed dimension indices of one camera sample.
pub mod dims {
    /// Film position within the pixel (2 dimensions).
    pub const FILM: u32 = 0;
    /// First dimension of the gather at the primary hit; each gather level
    /// uses [`PER_LEVEL`] dimensions from here.
    pub const GATHER: u32 = 2;
    /// Dimensions one gather level uses: light pick (1), point on the light
    /// (2), BSDF direction (2).
    pub const PER_LEVEL: u32 = 5;
    /// The cosine-sampled direction of the link gather's glossy-sender term
    /// (2 dimensions per level, three levels, after three gather levels).
    pub const GLOSSY_SENDERS: u32 = GATHER + GATHER_LEVELS * PER_LEVEL;
    /// Gather levels laid out from [`GATHER`], before the link gather's
    /// dimensions.
    pub const GATHER_LEVELS: u32 = 3;
    /// Dimensions of gather level L ≥ [`GATHER_LEVELS`] (paths continued
    /// through near-specular hits) start at DEEP_GATHER + L · PER_LEVEL,
    /// past every dimension the link gather uses.
    pub const DEEP_GATHER: u32 = 256;
    /// First dimension of the shadow rays of partly visible gather links.
    pub const LINKS: u32 = GLOSSY_SENDERS + 6;
    /// The control variate's lookup rays 1.. (2 dimensions each, up to
    /// `control::MAX_LOOKUPS`; lookup 0 uses the first gather level's).
    pub const CONTROL_LOOKUPS: u32 = 32;
    /// The control variate's residual path: vertex v ≥ 2 uses
    /// [`PER_PATH_VERTEX`] dimensions from PATH + (v − 2) · PER_PATH_VERTEX
    /// (past the table's 256 they are folded into the scramble).
    pub const PATH: u32 = 96;
    /// Dimensions one path vertex uses: light pick (1), point on the light
    /// (2), BSDF direction (2), Russian roulette (1).
    pub const PER_PATH_VERTEX: u32 = 6;
    /// The link gather's sky sample for the Lambertian part at gather
    /// level L: 2 dimensions from SKY + 2 (L mod 16) (deeper levels share
    /// them; past the control variate's first 21 path vertices).
    pub const SKY: u32 = 224;

    /// The first of the two dimensions of the link gather's sky sample at
    /// gather `level` ([`SKY`]).
    pub const fn sky(level: u32) -> u32 {
        SKY + 2 * (level % 16)
    }
}

/// Largest number of samples per pixel the sequence supports (the limit
/// scene files are checked against too).
pub const MAX_SAMPLES: u32 = trilux_files::film::MAX_SAMPLES_PER_PIXEL;

/// The sample sequence of one pixel.
#[derive(Clone, Copy, Debug)]
pub struct PixelSampler {
    scramble: u32,
    index: u32,
}

/// A 32-bit integer hash (lowbias32, Wellons) for seeding.
fn hash(mut x: u32) -> u32 {
    x ^= x >> 16;
    x = x.wrapping_mul(0x7feb_352d);
    x ^= x >> 15;
    x = x.wrapping_mul(0x846c_a68b);
    x ^= x >> 16;
    x
}

impl PixelSampler {
    /// The sequence of pixel (`x`, `y`) for render seed `seed`.
    pub fn new(seed: u32, x: u32, y: u32) -> Self {
        let scramble = hash(hash(hash(seed) ^ x.wrapping_mul(0x9e37_79b9)) ^ y);
        Self { scramble, index: 0 }
    }

    /// Moves to camera sample `index` (< [`MAX_SAMPLES`]) of this pixel.
    pub fn start_sample(&mut self, index: u32) {
        self.index = index;
    }

    /// One value in [0, 1) of dimension `dim` of the current sample.
    pub fn get1(&self, dim: u32) -> f64 {
        // Beyond the table, fold the dimension into the scramble.
        let (d, s) = if dim < sobol_burley::NUM_DIMENSIONS {
            (dim, self.scramble)
        } else {
            (
                dim % sobol_burley::NUM_DIMENSIONS,
                hash(self.scramble ^ dim),
            )
        };
        sobol_burley::sample(self.index, d, s) as f64
    }

    /// Two values in [0, 1)² of dimensions `dim`, `dim + 1`.
    pub fn get2(&self, dim: u32) -> DVec2 {
        DVec2::new(self.get1(dim), self.get1(dim + 1))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn samples_are_in_the_unit_interval_and_stratified() {
        let mut s = PixelSampler::new(7, 3, 4);
        // 64 points of a (0,2)-sequence: each of the 8x8 strata of a 2D
        // projection of dims (0, 1) holds exactly one point.
        let mut seen = [false; 64];
        for i in 0..64 {
            s.start_sample(i);
            let p = s.get2(0);
            assert!((0.0..1.0).contains(&p.x) && (0.0..1.0).contains(&p.y));
            let cell = (p.x * 8.0) as usize + 8 * (p.y * 8.0) as usize;
            seen[cell] = true;
        }
        assert!(seen.iter().all(|&b| b), "Sobol (0,2) property broken");
    }

    #[test]
    fn different_pixels_and_seeds_differ() {
        let a = PixelSampler::new(1, 0, 0).get1(0);
        let b = PixelSampler::new(1, 1, 0).get1(0);
        let c = PixelSampler::new(2, 0, 0).get1(0);
        assert!(a != b && a != c);
    }
}
