//! An environment map (Mitsuba 3's `envmap`): radiance arriving from
//! infinitely far away, read from an equirectangular image, as the solver
//! and the renderer take it. It is a true distant light: no surface stands
//! for it; a ray that leaves the scene brings its radiance, and both the
//! solve and the render sample it by direction (docs/architecture.md,
//! "Environment").
//!
//! **Lookup, as Mitsuba 3.9.1's.** A world direction ω goes to the map's
//! frame, d = M⁻¹ ω (M its `to_world`, a rotation), and to image
//! coordinates u = atan2(d_x, −d_z) / 2π (wrapped into [0, 1)) and
//! v = acos(d_y) / π (+y is up, v = 0 at the zenith). The radiance is the
//! bilinear interpolation of the texels at x = u W − ½ (texel centres,
//! wrapping in u) and y = v (H − 1) (the first and last rows at the poles),
//! times `scale`: what Mitsuba 3.9.1's `envmap` returns, measured on a
//! probe image (docs/results.md).
//!
//! **Sampling.** The bilinear radiance is positive in a *cell* (between
//! two neighbouring columns and rows of texels) iff one of its four
//! corners is, so the sampling density is piecewise constant over the
//! W × (H − 1) cells in (u, v), each cell's probability its exact
//! ∫ L dω (luminance; band mean in spectral mode), and
//! p(ω) = p_uv(u, v) / (2π² sin θ) (the Jacobian of (u, v) → ω):
//! positive wherever L is, so every estimate that divides by it is
//! unbiased (pbrt-v4 §12.5.2, with bilinear cells).

use std::f64::consts::PI;

use glam::{DMat3, DVec2, DVec3};
use trilux_color::Spectrum;

/// A direction sampled on the sky.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SkySample<const N: usize> {
    /// Unit world direction towards the sky.
    pub wi: DVec3,
    /// Radiance arriving from it.
    pub radiance: Spectrum<N>,
    /// Solid-angle density of `wi`.
    pub pdf: f64,
}

/// Why a sky cannot be prepared.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum SkyError {
    /// Too few texels.
    #[error("an environment map needs at least 1 × 2 texels, this one has {width} × {height}")]
    TooSmall {
        /// Width.
        width: usize,
        /// Height.
        height: usize,
    },
    /// The texel list does not match the size.
    #[error("{texels} texels for a {width} × {height} image")]
    Size {
        /// Width.
        width: usize,
        /// Height.
        height: usize,
        /// Texels given.
        texels: usize,
    },
    /// A texel that is negative, not finite or too large.
    #[error("texel ({x}, {y}) is negative, not finite or above 1e30 after scaling")]
    Texel {
        /// Column.
        x: usize,
        /// Row (0 at the top).
        y: usize,
    },
    /// `to_world` is not a rotation.
    #[error("to_world must be a rotation (no scale, shear or mirror) for an environment map")]
    NotRotation,
}

/// The sky in `N` bands with its sampling distribution.
#[derive(Clone, Debug, PartialEq)]
pub struct PreparedSky<const N: usize> {
    width: usize,
    height: usize,
    /// Radiance per texel (scaled), row-major from the top row.
    texels: Vec<Spectrum<N>>,
    world_from_sky: DMat3,
    sky_from_world: DMat3,
    /// Cumulative row probabilities (H − 1 cell rows; H entries).
    row_cdf: Vec<f64>,
    /// Per cell row, cumulative column probabilities (W + 1 entries each).
    col_cdf: Vec<f64>,
    /// ∫ L dω over the sphere.
    integral: Spectrum<N>,
}

impl<const N: usize> PreparedSky<N> {
    /// The sky of `texels` (`width` × `height`, row-major from the top,
    /// already in bands and scaled) turned by `world_from_sky`.
    pub fn new(
        width: usize,
        height: usize,
        texels: Vec<Spectrum<N>>,
        world_from_sky: DMat3,
    ) -> Result<Self, SkyError> {
        if width < 1 || height < 2 {
            return Err(SkyError::TooSmall { width, height });
        }
        if texels.len() != width * height {
            return Err(SkyError::Size {
                width,
                height,
                texels: texels.len(),
            });
        }
        if let Some(k) = texels
            .iter()
            .position(|t| !(t.is_finite() && t.is_non_negative() && t.max_value() <= 1e30))
        {
            return Err(SkyError::Texel {
                x: k % width,
                y: k / width,
            });
        }
        let m = world_from_sky;
        let orthonormal = (m.transpose() * m - DMat3::IDENTITY)
            .to_cols_array()
            .iter()
            .all(|e| e.abs() < 1e-6);
        if !(orthonormal && m.determinant() > 0.0) {
            return Err(SkyError::NotRotation);
        }
        let mut sky = PreparedSky {
            width,
            height,
            texels,
            world_from_sky: m,
            sky_from_world: m.transpose(),
            row_cdf: Vec::new(),
            col_cdf: Vec::new(),
            integral: Spectrum::zero(),
        };
        sky.build_distribution();
        Ok(sky)
    }

    /// The cells' exact ∫ L dω, their cumulative probabilities and the
    /// sky's integral (module docs).
    fn build_distribution(&mut self) {
        let (w, rows) = (self.width, self.height - 1);
        let mut row_mass = Vec::with_capacity(rows);
        let mut col_cdf = Vec::with_capacity(rows * (w + 1));
        let mut integral = Spectrum::<N>::zero();
        for r in 0..rows {
            let (a, b) = self.cell_row_weights(r);
            let mut acc = 0.0;
            col_cdf.push(0.0);
            for c in 0..w {
                let c1 = (c + 1) % w;
                let top = (self.texel(c, r) + self.texel(c1, r)) * 0.5;
                let bottom = (self.texel(c, r + 1) + self.texel(c1, r + 1)) * 0.5;
                let cell = top * a + bottom * b;
                integral += cell;
                acc += cell.average();
                col_cdf.push(acc);
            }
            row_mass.push(acc);
        }
        let total: f64 = row_mass.iter().sum();
        let mut row_cdf = vec![0.0];
        let mut acc = 0.0;
        for (r, m) in row_mass.iter().enumerate() {
            acc += m;
            row_cdf.push(acc);
            let row = &mut col_cdf[r * (w + 1)..(r + 1) * (w + 1)];
            if *m > 0.0 {
                row.iter_mut().for_each(|x| *x /= m);
            }
        }
        if total > 0.0 {
            row_cdf.iter_mut().for_each(|x| *x /= total);
        }
        self.row_cdf = row_cdf;
        self.col_cdf = col_cdf;
        self.integral = integral;
    }

    /// The solid-angle weights of a cell row r's upper and lower texel
    /// rows in ∫ L dω over one cell: L is linear in θ between them, so
    /// (2π / W) ∫ [(1 − t) a + t b] sin θ dθ, t = (θ − θ₀)/Δ.
    fn cell_row_weights(&self, r: usize) -> (f64, f64) {
        let rows = (self.height - 1) as f64;
        let (t0, t1) = (PI * r as f64 / rows, PI * (r + 1) as f64 / rows);
        let d = t1 - t0;
        let whole = t0.cos() - t1.cos();
        let lower = (-d * t1.cos() + t1.sin() - t0.sin()) / d;
        let dphi = 2.0 * PI / self.width as f64;
        (dphi * (whole - lower), dphi * lower)
    }

    fn texel(&self, x: usize, y: usize) -> Spectrum<N> {
        self.texels[y * self.width + x]
    }

    /// Feeds the texels and the orientation to a content hash.
    pub(crate) fn hash_into(&self, h: &mut impl std::io::Write) {
        let mut put = |x: f64| {
            // A hash sink never fails.
            let _ = h.write_all(&x.to_bits().to_le_bytes());
        };
        put(self.width as f64);
        put(self.height as f64);
        self.world_from_sky
            .to_cols_array()
            .into_iter()
            .for_each(&mut put);
        for t in &self.texels {
            t.as_slice().iter().copied().for_each(&mut put);
        }
    }

    /// ∫ L dω over the whole sphere.
    pub fn integral(&self) -> Spectrum<N> {
        self.integral
    }

    /// The flux it sends into a scene whose bounding sphere has radius
    /// `scene_radius`: π R² ∫ L dω (each direction's light crossing the
    /// sphere's disc, as a directional light's E π R²).
    pub fn flux(&self, scene_radius: f64) -> Spectrum<N> {
        self.integral * (PI * scene_radius * scene_radius)
    }

    /// The image coordinates (u, v) of world direction `wi` and sin θ.
    fn uv(&self, wi: DVec3) -> (DVec2, f64) {
        let d = (self.sky_from_world * wi).normalize_or_zero();
        let u = d.x.atan2(-d.z) / (2.0 * PI);
        let u = u - u.floor();
        let y = d.y.clamp(-1.0, 1.0);
        (DVec2::new(u, y.acos() / PI), (1.0 - y * y).max(0.0).sqrt())
    }

    /// The radiance arriving from world direction `wi` (module docs).
    pub fn radiance(&self, wi: DVec3) -> Spectrum<N> {
        let (uv, _) = self.uv(wi);
        let (w, h) = (self.width, self.height);
        let x = uv.x * w as f64 - 0.5;
        let x0 = x.floor();
        let fx = x - x0;
        let x0 = (x0 as i64).rem_euclid(w as i64) as usize;
        let x1 = (x0 + 1) % w;
        let y = (uv.y * (h - 1) as f64).clamp(0.0, (h - 1) as f64);
        let y0 = (y.floor() as usize).min(h - 2);
        let fy = y - y0 as f64;
        let row = |r: usize| self.texel(x0, r) * (1.0 - fx) + self.texel(x1, r) * fx;
        row(y0) * (1.0 - fy) + row(y0 + 1) * fy
    }

    /// The cell (column, row) holding (u, v) and its probability density
    /// in (u, v).
    fn cell_density(&self, uv: DVec2) -> f64 {
        let (w, rows) = (self.width, self.height - 1);
        let x = uv.x * w as f64 - 0.5;
        let c = (x.floor() as i64).rem_euclid(w as i64) as usize;
        let r = ((uv.y * rows as f64).floor().max(0.0) as usize).min(rows - 1);
        let p_row = self.row_cdf[r + 1] - self.row_cdf[r];
        let cols = &self.col_cdf[r * (w + 1)..];
        let p = p_row * (cols[c + 1] - cols[c]);
        p * (w * rows) as f64
    }

    /// The solid-angle density [`PreparedSky::sample`] has for `wi`.
    pub fn pdf(&self, wi: DVec3) -> f64 {
        let (uv, sin) = self.uv(wi);
        if sin <= 0.0 {
            return 0.0;
        }
        self.cell_density(uv) / (2.0 * PI * PI * sin)
    }

    /// A direction drawn with density ∝ the cells' ∫ L dω from `u` in
    /// [0, 1)²; `None` for a black sky or a pole.
    pub fn sample(&self, u: DVec2) -> Option<SkySample<N>> {
        let (w, rows) = (self.width, self.height - 1);
        let (r, fy) = pick(&self.row_cdf, u.y)?;
        let (c, fx) = pick(&self.col_cdf[r * (w + 1)..(r + 1) * (w + 1)], u.x)?;
        let uu = (c as f64 + 0.5 + fx) / w as f64;
        let uv = DVec2::new(uu - uu.floor(), (r as f64 + fy) / rows as f64);
        let (phi, theta) = (2.0 * PI * uv.x, PI * uv.y);
        let sin = theta.sin();
        if sin <= 0.0 {
            return None;
        }
        let local = DVec3::new(phi.sin() * sin, theta.cos(), -phi.cos() * sin);
        let wi = (self.world_from_sky * local).normalize_or_zero();
        let pdf = self.cell_density(uv) / (2.0 * PI * PI * sin);
        (pdf > 0.0 && pdf.is_finite()).then(|| SkySample {
            wi,
            radiance: self.radiance(wi),
            pdf,
        })
    }
}

/// The interval of cumulative list `cdf` (ascending from 0 to 1) that
/// holds `u`, and where in it `u` lies (in [0, 1)); `None` when every
/// interval is empty.
fn pick(cdf: &[f64], u: f64) -> Option<(usize, f64)> {
    let n = cdf.len() - 1;
    if cdf[n].is_nan() || cdf[n] <= 0.0 {
        return None;
    }
    let u = u.clamp(0.0, 1.0) * cdf[n];
    let k = cdf.partition_point(|&c| c <= u).clamp(1, n) - 1;
    // Skip empty intervals at the end (u = 1).
    let k = (0..=k).rev().find(|&k| cdf[k + 1] > cdf[k])?;
    let f = ((u - cdf[k]) / (cdf[k + 1] - cdf[k])).clamp(0.0, 1.0 - 1e-12);
    Some((k, f))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sky(w: usize, h: usize, f: impl Fn(usize, usize) -> f64) -> PreparedSky<3> {
        let texels = (0..h)
            .flat_map(|y| (0..w).map(move |x| (x, y)))
            .map(|(x, y)| Spectrum::splat(f(x, y)))
            .collect();
        PreparedSky::new(w, h, texels, DMat3::IDENTITY).unwrap()
    }

    #[test]
    fn a_uniform_sky_integrates_to_four_pi_and_its_samples_carry_its_radiance() {
        let s = sky(8, 4, |_, _| 2.0);
        assert!((s.integral()[0] - 8.0 * PI).abs() < 1e-12);
        for k in 0..64 {
            let u = DVec2::new(
                (f64::from(k) + 0.5) / 64.0,
                (f64::from(k * 37 % 64) + 0.5) / 64.0,
            );
            let smp = s.sample(u).unwrap();
            assert!((smp.radiance[1] - 2.0).abs() < 1e-12);
            assert!(smp.pdf > 0.0 && smp.pdf.is_finite(), "{}", smp.pdf);
            assert!((s.pdf(smp.wi) - smp.pdf).abs() < 1e-9 * smp.pdf);
        }
    }

    #[test]
    fn the_lookup_matches_mitsubas_probe() {
        // Texel (i, j) holds i + 1 (Mitsuba 3.9.1's `envmap` returned these
        // values for an 8 × 4 probe image, docs/results.md).
        let s = sky(8, 4, |x, _| (x + 1) as f64);
        let dir = |u: f64, v: f64| {
            let (p, t) = (2.0 * PI * u, PI * v);
            DVec3::new(p.sin() * t.sin(), t.cos(), -p.cos() * t.sin())
        };
        let t = sky(8, 4, |_, y| (y + 1) as f64);
        assert!((s.radiance(dir(0.01, 0.5))[0] - 3.94).abs() < 1e-9);
        assert!((s.radiance(dir(0.999, 0.5))[0] - 4.556).abs() < 1e-9);
        assert!((t.radiance(dir(0.0625, 0.125))[0] - 1.375).abs() < 1e-9);
        assert!((t.radiance(dir(0.3125, 0.385))[0] - 2.155).abs() < 1e-9);
    }

    #[test]
    fn the_density_integrates_to_one_and_sampling_is_unbiased() {
        // A bright texel on a dim sky: E[L / p] = ∫ L dω by quadrature,
        // on a grid whose points split evenly among the 16 × 7 cells.
        let s = sky(16, 8, |x, y| if (x, y) == (5, 3) { 500.0 } else { 0.1 });
        let (nu, nv) = (512u32, 448u32);
        let cells = f64::from(nu * nv);
        let (mut mass, mut est) = (0.0, 0.0);
        for i in 0..nu {
            for j in 0..nv {
                let u = DVec2::new(
                    (f64::from(i) + 0.5) / f64::from(nu),
                    (f64::from(j) + 0.5) / f64::from(nv),
                );
                let (p, t) = (2.0 * PI * u.x, PI * u.y);
                let d = DVec3::new(p.sin() * t.sin(), t.cos(), -p.cos() * t.sin());
                mass += s.pdf(d) * t.sin() * 2.0 * PI * PI / cells;
                if let Some(smp) = s.sample(u) {
                    est += smp.radiance[0] / smp.pdf / cells;
                }
            }
        }
        assert!((mass - 1.0).abs() < 1e-9, "{mass}");
        assert!((est / s.integral()[0] - 1.0).abs() < 1e-3, "{est}");
    }

    #[test]
    fn bad_maps_are_refused() {
        let one = vec![Spectrum::<3>::splat(1.0); 4];
        assert!(PreparedSky::new(4, 1, one.clone(), DMat3::IDENTITY).is_err());
        assert!(
            PreparedSky::new(2, 2, one.clone(), DMat3::from_diagonal(DVec3::splat(2.0))).is_err()
        );
        let mut nan = one;
        nan[3] = Spectrum::splat(f64::NAN);
        assert_eq!(
            PreparedSky::new(2, 2, nan, DMat3::IDENTITY),
            Err(SkyError::Texel { x: 1, y: 1 })
        );
    }
}
