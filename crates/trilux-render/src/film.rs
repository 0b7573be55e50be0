//! The film: samples splatted through the reconstruction filter.
//!
//! Mitsuba 3's `ImageBlock::put`: a sample at film position p (pixels, the
//! centre of pixel (i, j) at (i + ½, j + ½)) adds value · w and w to every
//! pixel within the filter radius, w = w_x · w_y separable; the developed
//! pixel is Σ value·w / Σ w. Samples are drawn only inside the film
//! (Mitsuba's `sample_border` = false), so edge pixels are normalised by the
//! weights of the samples that reached them.
//!
//! A [`Film`] can be a whole image or one tile with a border of the filter's
//! radius; tiles are merged into the image with [`Film::merge`] in a fixed
//! order, which keeps renders bit-for-bit deterministic however rayon
//! schedules the tiles.

use crate::error::RenderError;
use crate::filter::ReconstructionFilter;
use crate::image::Image;

/// An accumulation buffer of filtered, weighted samples (linear RGB).
#[derive(Clone, Debug)]
pub struct Film {
    /// Pixel column of this buffer's first column (may be negative for a
    /// tile's border).
    x0: i64,
    /// Pixel row of this buffer's first row.
    y0: i64,
    width: usize,
    height: usize,
    filter: ReconstructionFilter,
    /// Σ value · w per pixel.
    sums: Vec<[f64; 3]>,
    /// Σ w per pixel.
    weights: Vec<f64>,
}

impl Film {
    /// A buffer covering pixels [x0, x0 + width) × [y0, y0 + height); an
    /// error, not an abort, when the memory cannot be had.
    pub fn new(
        x0: i64,
        y0: i64,
        width: usize,
        height: usize,
        filter: ReconstructionFilter,
    ) -> Result<Self, RenderError> {
        let no_memory = || {
            RenderError::Settings(format!(
                "not enough memory for a {width} × {height} film (docs/limits.md)"
            ))
        };
        let n = width.checked_mul(height).ok_or_else(no_memory)?;
        let mut sums = Vec::new();
        sums.try_reserve_exact(n).map_err(|_| no_memory())?;
        sums.resize(n, [0.0; 3]);
        let mut weights = Vec::new();
        weights.try_reserve_exact(n).map_err(|_| no_memory())?;
        weights.resize(n, 0.0);
        Ok(Self {
            x0,
            y0,
            width,
            height,
            filter,
            sums,
            weights,
        })
    }

    /// Splats one sample of linear RGB `value` taken at film position
    /// (`px`, `py`) in pixels. Pixels outside this buffer are skipped.
    pub fn splat(&mut self, px: f64, py: f64, value: [f64; 3]) {
        self.splat_weighted(px, py, value, 1.0);
    }

    /// [`Film::splat`] with the filter weights scaled by `weight`: adaptive
    /// sampling gives each sample of a pixel that took n samples weight 1/n,
    /// so a pixel's neighbours see its samples as one unit of weight however
    /// many it took (an unevenly sampled neighbour would otherwise pull a
    /// pixel toward its own value).
    pub fn splat_weighted(&mut self, px: f64, py: f64, value: [f64; 3], weight: f64) {
        let r = self.filter.radius();
        // Continuous position relative to pixel centres at integer indices.
        let cx = px - 0.5;
        let cy = py - 0.5;
        let lo_x = ((cx - r).ceil() as i64).max(self.x0);
        let hi_x = ((cx + r).floor() as i64).min(self.x0 + self.width as i64 - 1);
        let lo_y = ((cy - r).ceil() as i64).max(self.y0);
        let hi_y = ((cy + r).floor() as i64).min(self.y0 + self.height as i64 - 1);
        if lo_x > hi_x || lo_y > hi_y {
            return;
        }
        // At most 5 taps per axis for the default filter: keep them on the
        // stack (wider filters fall back to the heap).
        let taps = (hi_x - lo_x + 1) as usize;
        let mut stack = [0.0f64; 8];
        let mut heap = Vec::new();
        let wx: &mut [f64] = if taps <= stack.len() {
            &mut stack[..taps]
        } else {
            heap.resize(taps, 0.0);
            &mut heap
        };
        for (k, w) in wx.iter_mut().enumerate() {
            *w = self.filter.eval_discretized((lo_x + k as i64) as f64 - cx);
        }
        for j in lo_y..=hi_y {
            let wy = self.filter.eval_discretized(j as f64 - cy) * weight;
            if wy == 0.0 {
                continue;
            }
            let row = (j - self.y0) as usize * self.width;
            for (k, i) in (lo_x..=hi_x).enumerate() {
                let w = wx[k] * wy;
                if w == 0.0 {
                    continue;
                }
                let idx = row + (i - self.x0) as usize;
                let s = &mut self.sums[idx];
                s[0] += value[0] * w;
                s[1] += value[1] * w;
                s[2] += value[2] * w;
                self.weights[idx] += w;
            }
        }
    }

    /// Adds another buffer (a tile) into this one where they overlap.
    pub fn merge(&mut self, tile: &Film) {
        for ty in 0..tile.height {
            let y = tile.y0 + ty as i64;
            if y < self.y0 || y >= self.y0 + self.height as i64 {
                continue;
            }
            for tx in 0..tile.width {
                let x = tile.x0 + tx as i64;
                if x < self.x0 || x >= self.x0 + self.width as i64 {
                    continue;
                }
                let src = ty * tile.width + tx;
                let dst = (y - self.y0) as usize * self.width + (x - self.x0) as usize;
                for c in 0..3 {
                    self.sums[dst][c] += tile.sums[src][c];
                }
                self.weights[dst] += tile.weights[src];
            }
        }
    }

    /// The developed image: Σ value·w / Σ w per pixel (0 where no sample
    /// reached a pixel).
    pub fn develop(&self) -> Image {
        let pixels = self
            .sums
            .iter()
            .zip(&self.weights)
            .map(|(s, &w)| {
                if w > 0.0 {
                    [(s[0] / w) as f32, (s[1] / w) as f32, (s[2] / w) as f32]
                } else {
                    [0.0; 3]
                }
            })
            .collect();
        Image::from_pixels(self.width as u32, self.height as u32, pixels)
            .unwrap_or_else(|_| Image::black(1, 1))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_constant_develops_to_itself_with_any_filter() {
        for f in [
            ReconstructionFilter::default(),
            ReconstructionFilter::Box,
            ReconstructionFilter::Tent { radius: 1.3 },
            ReconstructionFilter::Mitchell {
                b: 1.0 / 3.0,
                c: 1.0 / 3.0,
            },
            ReconstructionFilter::Lanczos { lobes: 3 },
        ] {
            let mut film = Film::new(0, 0, 7, 5, f).unwrap();
            let mut k = 0u32;
            for j in 0..5 {
                for i in 0..7 {
                    for s in 0..4 {
                        k = k.wrapping_mul(747796405).wrapping_add(2891336453);
                        let dx = (s % 2) as f64 * 0.5 + 0.1 + (k >> 28) as f64 / 64.0;
                        let dy = (s / 2) as f64 * 0.5 + 0.2;
                        film.splat(i as f64 + dx, j as f64 + dy, [0.25, 1.0, 3.0]);
                    }
                }
            }
            let img = film.develop();
            for p in img.pixels() {
                for (c, e) in p.iter().zip([0.25f32, 1.0, 3.0]) {
                    assert!((c - e).abs() < 1e-6 * e);
                }
            }
        }
    }

    #[test]
    fn one_sample_spreads_with_mitsubas_weights() {
        // A single sample at the centre of pixel (3,3): pixels within 2 px
        // get the same value; its weight pattern is w(dx)·w(dy).
        let f = ReconstructionFilter::default();
        let mut film = Film::new(0, 0, 8, 8, f).unwrap();
        film.splat(3.5, 3.5, [1.0, 1.0, 1.0]);
        let w = |d| f.eval_discretized(d);
        assert!((film.weights[3 * 8 + 3] - w(0.0).powi(2)).abs() < 1e-15);
        assert!((film.weights[3 * 8 + 4] - w(0.0) * w(1.0)).abs() < 1e-15);
        assert_eq!(film.weights[3 * 8 + 5], 0.0); // d = 2: weight exactly zero
    }

    #[test]
    fn weighted_samples_count_as_units() {
        let f = ReconstructionFilter::default();
        let mut film = Film::new(0, 0, 8, 8, f).unwrap();
        film.splat_weighted(3.5, 3.5, [1.0; 3], 0.25);
        assert!((film.weights[3 * 8 + 3] - 0.25 * f.eval_discretized(0.0).powi(2)).abs() < 1e-15);
        // Pixel 0 took one sample of 1, pixel 2 four of 3, each weighted
        // 1/n: pixel 1, as far from both, sees two equal units, mean 2.
        let mut row = Film::new(0, 0, 3, 1, f).unwrap();
        row.splat_weighted(0.5, 0.5, [1.0; 3], 1.0);
        for _ in 0..4 {
            row.splat_weighted(2.5, 0.5, [3.0; 3], 0.25);
        }
        assert!((row.develop().pixels()[1][0] - 2.0).abs() < 1e-6);
    }

    #[test]
    fn tiles_merge_to_the_whole() {
        let f = ReconstructionFilter::default();
        let mut whole = Film::new(0, 0, 6, 6, f).unwrap();
        let mut a = Film::new(-2, -2, 7, 10, f).unwrap(); // columns 0..3 plus border
        let mut b = Film::new(1, -2, 7, 10, f).unwrap(); // columns 3..6 plus border
        let samples = [
            (0.3, 0.7, 1.0),
            (2.9, 4.1, 2.0),
            (3.1, 1.5, 3.0),
            (5.9, 5.9, 4.0),
        ];
        for &(x, y, v) in &samples {
            whole.splat(x, y, [v; 3]);
            if x < 3.0 {
                a.splat(x, y, [v; 3])
            } else {
                b.splat(x, y, [v; 3])
            }
        }
        let mut merged = Film::new(0, 0, 6, 6, f).unwrap();
        merged.merge(&a);
        merged.merge(&b);
        for (m, w) in merged.weights.iter().zip(&whole.weights) {
            assert!((m - w).abs() < 1e-12);
        }
    }
}
