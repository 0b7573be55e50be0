//! Real spherical harmonics of order 2 and their least-squares fit over
//! directions: the part of a glossy record both forms share (the
//! harmonics alone, and with the lobe of module `lobe`).

use glam::DVec3;

/// Coefficients of order-2 real spherical harmonics.
pub const SH_COEFFICIENTS: usize = 9;

/// RGB slots of a vertex's glossy record: the order-2 harmonics, then
/// (the lobe form, module `lobe`) the lobe's axis × sharpness and amplitude.
pub const SLOTS: usize = SH_COEFFICIENTS + 2;

/// A vertex's glossy light in its form's slots.
pub type GlossyRecord = [[f64; 3]; SLOTS];

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
pub fn sh_part(c: &GlossyRecord) -> [[f64; 3]; SH_COEFFICIENTS] {
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

/// Solves A x = b (A symmetric positive definite) by Cholesky, three
/// right-hand sides at once.
pub(crate) fn cholesky_solve<const M: usize>(
    a: [[f64; M]; M],
    b: [[f64; 3]; M],
) -> Option<[[f64; 3]; M]> {
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
