//! The glossy (view-dependent) light of a bake: per vertex of a glossy
//! side, the outgoing glossy radiance L_g(x, ω_o) as real spherical
//! harmonics of order 2 (nine coefficients per colour channel) in world
//! coordinates.
//!
//! The bake asks a [`GlossyLight`] (the renderer's own estimate of the
//! glossy part, supplied by the `trilux` crate) for L_g at every vertex
//! towards [`BakeOptions::glossy_directions`](crate::BakeOptions)
//! directions (fewer in a bake larger than its `glossy_budget`) spread uniformly in solid angle over the side's hemisphere
//! (a spherical Fibonacci set), and fits the nine coefficients by least
//! squares over them. The constant Y₀₀ is in the basis, so the residuals
//! sum to zero: the fit's mean over the hemisphere is the estimate's mean
//! (what a viewer's image mean depends on), and its flux Σ c_j ∫ Y_j cos is
//! the estimate's to the fit's error in the cosine moment. What the fit
//! loses is the shape of narrow lobes (a highlight of GGX α ≲ 0.2 is
//! blurred and its peak lowered; docs/bake.md measures it by roughness).
//!
//! A viewer evaluates c · Y(ω_o) for ω_o from the point to the eye,
//! clamped at zero, and adds it to the diffuse vertex colour.

use glam::DVec3;
use rayon::prelude::*;
use trilux_geometry::{Side, SurfaceCoord, SurfaceId};

/// Coefficients of order-2 real spherical harmonics.
pub const SH_COEFFICIENTS: usize = 9;

/// RGB slots of a vertex's glossy record: the order-2 harmonics, then
/// (form [`GlossyForm::Lobe`]) the lobe's axis × sharpness and amplitude.
pub const SLOTS: usize = SH_COEFFICIENTS + 2;

/// A vertex's glossy light in its form's slots.
pub type GlossyRecord = [[f64; 3]; SLOTS];

/// Where the bake asks for glossy light: a vertex of a glossy side.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GlossyPoint {
    /// The scene shape.
    pub shape: u32,
    /// The input surface the vertex belongs to.
    pub surface: SurfaceId,
    /// Its coordinates on that surface.
    pub coord: SurfaceCoord,
    /// The side whose light is asked for.
    pub side: Side,
    /// World-space position.
    pub point: DVec3,
    /// Unit normal of the front side.
    pub normal: DVec3,
    /// A number no other point of the bake has (seeds its samples).
    pub key: u64,
}

/// Incident samples a [`GlossyLight`] draws per point, shared by all of
/// the point's directions.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct GlossySamples {
    /// BSDF-sampled gather rays.
    pub gather: u32,
    /// Light samples.
    pub light: u32,
    /// Gather hits read through their links, as the full render reads
    /// them; without, the solution's radiance there (much cheaper).
    pub links: bool,
}

/// The glossy part of the radiance leaving surface points.
pub trait GlossyLight: Sync {
    /// The glossy radiance, linear Rec. 709, leaving each of `points`
    /// towards each of its directions, estimated from `samples` incident
    /// samples per point: `directions` holds `directions.len() /
    /// points.len()` unit vectors per point, point after point, and the
    /// answer is laid out the same way.
    fn outgoing(
        &self,
        points: &[GlossyPoint],
        directions: &[DVec3],
        samples: GlossySamples,
    ) -> Vec<[f64; 3]>;
}

/// The order-2 real spherical harmonics at unit direction `d` (the usual
/// normalisation: ∫ Y_j Y_k dω = δ_jk).
pub fn sh_basis(d: DVec3) -> [f64; SH_COEFFICIENTS] {
    let (x, y, z) = (d.x, d.y, d.z);
    [
        0.282_094_791_773_878_1,
        0.488_602_511_902_919_9 * y,
        0.488_602_511_902_919_9 * z,
        0.488_602_511_902_919_9 * x,
        1.092_548_430_592_079_2 * x * y,
        1.092_548_430_592_079_2 * y * z,
        0.315_391_565_252_52 * (3.0 * z * z - 1.0),
        1.092_548_430_592_079_2 * x * z,
        0.546_274_215_296_039_6 * (x * x - y * y),
    ]
}

/// The order-2 harmonics of a record.
fn sh_part(c: &GlossyRecord) -> [[f64; 3]; SH_COEFFICIENTS] {
    std::array::from_fn(|j| c[j])
}

/// The SH expansion `c` evaluated towards `d`, per channel.
pub fn sh_eval(c: &[[f64; 3]; SH_COEFFICIENTS], d: DVec3) -> [f64; 3] {
    let y = sh_basis(d);
    std::array::from_fn(|ch| (0..SH_COEFFICIENTS).map(|j| c[j][ch] * y[j]).sum())
}

/// `n` directions uniform in solid angle over the hemisphere about the
/// unit vector `normal` (a spherical Fibonacci set: equal-area bands in
/// cos θ, golden-angle steps in φ).
pub fn hemisphere_directions(normal: DVec3, n: usize) -> Vec<DVec3> {
    let (t, b) = normal.any_orthonormal_pair();
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    (0..n)
        .map(|k| {
            let z = 1.0 - (k as f64 + 0.5) / n as f64;
            let r = (1.0 - z * z).max(0.0).sqrt();
            let phi = golden * k as f64;
            (t * (r * phi.cos()) + b * (r * phi.sin()) + normal * z).normalize()
        })
        .collect()
}

/// The least-squares SH coefficients of the `values` measured towards
/// `directions` (module docs). A tiny ridge keeps the 9 × 9 system
/// definite with few directions; `None` for fewer directions than
/// coefficients.
pub fn fit_sh(directions: &[DVec3], values: &[[f64; 3]]) -> Option<[[f64; 3]; SH_COEFFICIENTS]> {
    const M: usize = SH_COEFFICIENTS;
    if directions.len() < M || directions.len() != values.len() {
        return None;
    }
    let mut a = [[0.0; M]; M];
    let mut rhs = [[0.0; 3]; M];
    for (d, v) in directions.iter().zip(values) {
        let y = sh_basis(*d);
        for j in 0..M {
            for k in 0..M {
                a[j][k] += y[j] * y[k];
            }
            for c in 0..3 {
                rhs[j][c] += y[j] * v[c];
            }
        }
    }
    let ridge = 1e-9 * (0..M).map(|j| a[j][j]).sum::<f64>();
    for (j, row) in a.iter_mut().enumerate() {
        row[j] += ridge;
    }
    cholesky_solve(a, rhs)
}

/// How a vertex's glossy light is written ([`SLOTS`] RGB slots).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum GlossyForm {
    /// Order-2 real spherical harmonics alone, slots 0..9 (`_TRILUX_SH0..8`).
    Sh2,
    /// Order-2 harmonics plus one spherical Gaussian (module `lobe`):
    /// slots 0..9 (`_TRILUX_SH0..8`), the lobe's axis × sharpness
    /// (`_TRILUX_LOBE`) and its RGB amplitude (`_TRILUX_LOBE_RGB`).
    #[default]
    Lobe,
}

impl GlossyForm {
    /// The form's value towards unit `d`, per channel.
    pub fn eval(self, c: &GlossyRecord, d: DVec3) -> [f64; 3] {
        match self {
            GlossyForm::Sh2 => sh_eval(&sh_part(c), d),
            GlossyForm::Lobe => crate::lobe::lobe_eval(c, d),
        }
    }

    /// The least-squares fit to `values` towards `directions`.
    pub fn fit(self, directions: &[DVec3], values: &[[f64; 3]]) -> Option<GlossyRecord> {
        match self {
            GlossyForm::Sh2 => fit_sh(directions, values).map(|c| {
                let mut r = [[0.0; 3]; SLOTS];
                r[..SH_COEFFICIENTS].copy_from_slice(&c);
                r
            }),
            GlossyForm::Lobe => crate::lobe::fit_lobe(directions, values),
        }
    }

    /// The glTF attribute of each slot used.
    pub fn attributes(self) -> &'static [&'static str] {
        match self {
            GlossyForm::Sh2 => &[
                "_TRILUX_SH0", "_TRILUX_SH1", "_TRILUX_SH2", "_TRILUX_SH3", "_TRILUX_SH4",
                "_TRILUX_SH5", "_TRILUX_SH6", "_TRILUX_SH7", "_TRILUX_SH8",
            ],
            GlossyForm::Lobe => &[
                "_TRILUX_SH0", "_TRILUX_SH1", "_TRILUX_SH2", "_TRILUX_SH3", "_TRILUX_SH4",
                "_TRILUX_SH5", "_TRILUX_SH6", "_TRILUX_SH7", "_TRILUX_SH8", "_TRILUX_LOBE",
                "_TRILUX_LOBE_RGB",
            ],
        }
    }

    /// The name the materials' `extras.trilux.glossy` gives it.
    pub fn name(self) -> &'static str {
        match self {
            GlossyForm::Sh2 => "sh2",
            GlossyForm::Lobe => "sh2+lobe",
        }
    }
}

/// Solves A x = b (A symmetric positive definite) by Cholesky, three
/// right-hand sides at once.
pub(crate) fn cholesky_solve<const M: usize>(a: [[f64; M]; M], b: [[f64; 3]; M]) -> Option<[[f64; 3]; M]> {
    let mut l = [[0.0; M]; M];
    for j in 0..M {
        let d = a[j][j] - (0..j).map(|k| l[j][k] * l[j][k]).sum::<f64>();
        if d.is_nan() || d <= 0.0 {
            return None;
        }
        l[j][j] = d.sqrt();
        for i in j + 1..M {
            let s = a[i][j] - (0..j).map(|k| l[i][k] * l[j][k]).sum::<f64>();
            l[i][j] = s / l[j][j];
        }
    }
    let mut y = [[0.0; 3]; M];
    for i in 0..M {
        for c in 0..3 {
            let s = b[i][c] - (0..i).map(|k| l[i][k] * y[k][c]).sum::<f64>();
            y[i][c] = s / l[i][i];
        }
    }
    let mut x = [[0.0; 3]; M];
    for i in (0..M).rev() {
        for c in 0..3 {
            let s = y[i][c] - (i + 1..M).map(|k| l[k][i] * x[k][c]).sum::<f64>();
            x[i][c] = s / l[i][i];
        }
    }
    Some(x)
}

/// The fitted `form` of every vertex of `points`' side (zero for
/// vertices not in `points`): asks `light` in
/// batches of [`BATCH_POINTS`] points, `n_dir` directions each.
pub(crate) fn fit_vertices(
    light: &dyn GlossyLight,
    points: &[(usize, GlossyPoint)],
    vertices: usize,
    (form, n_dir, samples): (GlossyForm, usize, GlossySamples),
) -> Vec<GlossyRecord> {
    let mut out = vec![[[0.0; 3]; SLOTS]; vertices];
    for batch in points.chunks(BATCH_POINTS) {
        let dirs: Vec<Vec<DVec3>> = batch
            .iter()
            .map(|(_, p)| hemisphere_directions(p.normal * p.side.sign(), n_dir))
            .collect();
        let flat: Vec<DVec3> = dirs.iter().flatten().copied().collect();
        let only: Vec<GlossyPoint> = batch.iter().map(|(_, p)| *p).collect();
        let values = light.outgoing(&only, &flat, samples);
        let fits: Vec<Option<GlossyRecord>> = (0..batch.len())
            .into_par_iter()
            .map(|k| {
                let measured = values.get(k * n_dir..(k + 1) * n_dir).unwrap_or(&[]);
                form.fit(&dirs[k], measured)
            })
            .collect();
        for ((v, _), fit) in batch.iter().zip(fits) {
            if let Some(c) = fit {
                out[*v] = c;
            }
        }
    }
    out
}

/// Points per request to a [`GlossyLight`] (bounds the directions held).
const BATCH_POINTS: usize = 2048;

#[cfg(test)]
mod tests {
    use super::*;

    /// The basis is orthonormal over the sphere: a brute-force quadrature
    /// (midpoint rule in cos θ and φ, 400 × 800 cells) of Y_j Y_k.
    #[test]
    fn basis_is_orthonormal() {
        let (nz, nphi) = (400, 800);
        let mut gram = [[0.0; 9]; 9];
        let cell = (2.0 / nz as f64) * (2.0 * std::f64::consts::PI / nphi as f64);
        for i in 0..nz {
            let z = -1.0 + (i as f64 + 0.5) * 2.0 / nz as f64;
            let r = (1.0 - z * z).sqrt();
            for k in 0..nphi {
                let phi = (k as f64 + 0.5) * 2.0 * std::f64::consts::PI / nphi as f64;
                let y = sh_basis(DVec3::new(r * phi.cos(), r * phi.sin(), z));
                for (row, ya) in gram.iter_mut().zip(y) {
                    for (g, yb) in row.iter_mut().zip(y) {
                        *g += ya * yb * cell;
                    }
                }
            }
        }
        for (a, row) in gram.iter().enumerate() {
            for (b, g) in row.iter().enumerate() {
                let expect = if a == b { 1.0 } else { 0.0 };
                assert!((g - expect).abs() < 1e-4, "{a} {b}: {g}");
            }
        }
    }

    /// A function in the span (any quadratic polynomial of the direction)
    /// is fitted exactly from hemisphere samples, whatever the normal.
    #[test]
    fn quadratics_are_fitted_exactly() {
        let f = |d: DVec3| {
            [
                1.0 + 0.5 * d.x - d.y * d.z,
                2.0 * d.z * d.z,
                0.3 - d.x * d.y,
            ]
        };
        for n in [
            DVec3::Z,
            DVec3::new(0.3, -0.8, 0.2).normalize(),
            DVec3::NEG_Y,
        ] {
            let dirs = hemisphere_directions(n, 48);
            assert!(dirs.iter().all(|d| d.dot(n) > 0.0));
            let vals: Vec<[f64; 3]> = dirs.iter().map(|&d| f(d)).collect();
            let c = fit_sh(&dirs, &vals).unwrap();
            for d in hemisphere_directions(n, 200) {
                let (g, e) = (sh_eval(&c, d), f(d));
                for ch in 0..3 {
                    assert!((g[ch] - e[ch]).abs() < 1e-6, "{n} {d}: {g:?} vs {e:?}");
                }
            }
        }
    }

    /// Least squares with the constant in the basis: the fit's mean over
    /// the sample directions equals the data's, even for a lobe the basis
    /// cannot follow (a narrow cosine power lobe).
    #[test]
    fn the_fit_keeps_the_mean() {
        let n = DVec3::new(0.0, 1.0, 0.0);
        let axis = DVec3::new(0.6, 0.8, 0.0);
        let dirs = hemisphere_directions(n, 64);
        let vals: Vec<[f64; 3]> = dirs
            .iter()
            .map(|d| [d.dot(axis).max(0.0).powi(40); 3])
            .collect();
        let c = fit_sh(&dirs, &vals).unwrap();
        let mean = |v: &dyn Fn(DVec3) -> f64| dirs.iter().map(|&d| v(d)).sum::<f64>() / 64.0;
        let data = mean(&|d| d.dot(axis).max(0.0).powi(40));
        let fit = mean(&|d| sh_eval(&c, d)[0]);
        assert!(data > 0.0);
        assert!((fit - data).abs() < 1e-9 * data.max(1.0), "{fit} vs {data}");
    }
}
