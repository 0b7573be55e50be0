//! Quadrature rules: Gauss–Legendre on intervals and squares, and a
//! symmetric degree-5 rule on triangles.
//!
//! These integrate the form-factor kernels of [`crate::form_factor`] and the
//! areas of curved pieces.

use glam::DVec3;

/// Gauss–Legendre nodes and weights on [-1, 1], computed by Newton's method
/// on the Legendre polynomial (accurate to about 1e-15 for n ≤ 64).
pub(crate) fn gauss_legendre(n: usize) -> (Vec<f64>, Vec<f64>) {
    let mut x = vec![0.0; n];
    let mut w = vec![0.0; n];
    let m = n.div_ceil(2);
    for i in 0..m {
        let mut z = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut pp = 0.0;
        for _ in 0..100 {
            let mut p1 = 1.0;
            let mut p2 = 0.0;
            for j in 0..n {
                let p3 = p2;
                p2 = p1;
                p1 = ((2.0 * j as f64 + 1.0) * z * p2 - j as f64 * p3) / (j as f64 + 1.0);
            }
            pp = n as f64 * (z * p1 - p2) / (z * z - 1.0);
            let z1 = z;
            z = z1 - p1 / pp;
            if (z - z1).abs() < 1e-16 {
                break;
            }
        }
        x[i] = -z;
        x[n - 1 - i] = z;
        w[i] = 2.0 / ((1.0 - z * z) * pp * pp);
        w[n - 1 - i] = w[i];
    }
    (x, w)
}

/// The 3-point Gauss–Legendre rule on [0, 1] (exact for degree 5).
pub(crate) const GL3_X: [f64; 3] = [
    0.5 - 0.387_298_334_620_741_7,
    0.5,
    0.5 + 0.387_298_334_620_741_7,
];
/// Weights of [`GL3_X`] (sum 1).
pub(crate) const GL3_W: [f64; 3] = [5.0 / 18.0, 8.0 / 18.0, 5.0 / 18.0];

/// The 2-point Gauss–Legendre rule on [0, 1] (exact for degree 3), weights
/// ½ each: the cubature's error check for [`GL3_X`].
pub(crate) const GL2_X: [f64; 2] = [0.5 - 0.288_675_134_594_812_9, 0.5 + 0.288_675_134_594_812_9];

/// Strang and Fix's 3-point rule on a triangle (exact for degree 2),
/// weights ⅓ each: the cubature's error check for [`TRI7`].
pub(crate) const TRI3: [[f64; 3]; 3] = [
    [2.0 / 3.0, 1.0 / 6.0, 1.0 / 6.0],
    [1.0 / 6.0, 2.0 / 3.0, 1.0 / 6.0],
    [1.0 / 6.0, 1.0 / 6.0, 2.0 / 3.0],
];

/// Dunavant's 7-point rule on a triangle (exact for degree 5): barycentric
/// coordinates and weights (sum 1).
pub(crate) const TRI7: [([f64; 3], f64); 7] = [
    ([1.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0], 0.225),
    (
        [
            0.059_715_871_789_770,
            0.470_142_064_105_115,
            0.470_142_064_105_115,
        ],
        0.132_394_152_788_506,
    ),
    (
        [
            0.470_142_064_105_115,
            0.059_715_871_789_770,
            0.470_142_064_105_115,
        ],
        0.132_394_152_788_506,
    ),
    (
        [
            0.470_142_064_105_115,
            0.470_142_064_105_115,
            0.059_715_871_789_770,
        ],
        0.132_394_152_788_506,
    ),
    (
        [
            0.797_426_985_353_087,
            0.101_286_507_323_456,
            0.101_286_507_323_456,
        ],
        0.125_939_180_544_827,
    ),
    (
        [
            0.101_286_507_323_456,
            0.797_426_985_353_087,
            0.101_286_507_323_456,
        ],
        0.125_939_180_544_827,
    ),
    (
        [
            0.101_286_507_323_456,
            0.101_286_507_323_456,
            0.797_426_985_353_087,
        ],
        0.125_939_180_544_827,
    ),
];

/// Adaptive 2-D Gauss–Legendre integration of `f` over [u0,u1]×[v0,v1]:
/// compares an 8×8 with a 16×16 rule and bisects until they agree to
/// `rel_tol` (used for the exact areas of curved pieces).
pub(crate) fn integrate_rect(
    f: &dyn Fn(f64, f64) -> f64,
    u: [f64; 2],
    v: [f64; 2],
    rel_tol: f64,
    depth: u32,
) -> f64 {
    let rule = |n: usize| -> f64 {
        let (x, w) = gauss_legendre(n);
        let (hu, hv) = (0.5 * (u[1] - u[0]), 0.5 * (v[1] - v[0]));
        let (cu, cv) = (0.5 * (u[1] + u[0]), 0.5 * (v[1] + v[0]));
        let mut s = 0.0;
        for i in 0..n {
            for j in 0..n {
                s += w[i] * w[j] * f(cu + hu * x[i], cv + hv * x[j]);
            }
        }
        s * hu * hv
    };
    let coarse = rule(8);
    let fine = rule(16);
    if (fine - coarse).abs() <= rel_tol * fine.abs() || depth == 0 {
        return fine;
    }
    let um = 0.5 * (u[0] + u[1]);
    let vm = 0.5 * (v[0] + v[1]);
    let mut s = 0.0;
    for (ua, ub) in [(u[0], um), (um, u[1])] {
        for (va, vb) in [(v[0], vm), (vm, v[1])] {
            s += integrate_rect(f, [ua, ub], [va, vb], rel_tol, depth - 1);
        }
    }
    s
}

/// Area of the triangle (a, b, c).
#[inline]
pub(crate) fn triangle_area(a: DVec3, b: DVec3, c: DVec3) -> f64 {
    0.5 * (b - a).cross(c - a).length()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gauss_legendre_integrates_polynomials_exactly() {
        for n in [2usize, 3, 5, 8, 16] {
            let (x, w) = gauss_legendre(n);
            for deg in 0..(2 * n) {
                let exact = if deg % 2 == 1 {
                    0.0
                } else {
                    2.0 / (deg as f64 + 1.0)
                };
                let q: f64 = x.iter().zip(&w).map(|(x, w)| w * x.powi(deg as i32)).sum();
                assert!(
                    (q - exact).abs() < 1e-13,
                    "n={n} deg={deg} q={q} exact={exact}"
                );
            }
        }
    }

    #[test]
    fn triangle_rule_is_degree_five() {
        // ∫ over the unit right triangle of x^a y^b = a! b! / (a+b+2)!, area 1/2.
        let fact = |n: u32| (1..=n).map(|k| k as f64).product::<f64>();
        for a in 0..=5u32 {
            for b in 0..=(5 - a) {
                let exact = fact(a) * fact(b) / fact(a + b + 2);
                let q: f64 = TRI7
                    .iter()
                    .map(|(l, w)| 0.5 * w * l[1].powi(a as i32) * l[2].powi(b as i32))
                    .sum();
                assert!((q - exact).abs() < 1e-12, "a={a} b={b}");
            }
        }
    }
}
