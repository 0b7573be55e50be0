//! Energy: directional albedo against docs/validation.md's table (separable
//! Smith, F = 1) and against an independent Monte Carlo estimate.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test, bench or example may panic

mod common;

use common::{Rng, conductor, dir_deg, gold};
use glam::DVec3;
use trilux_brdf::{Bsdf, Distribution};

/// docs/validation.md, "Microfacet directional albedo", separable Smith column
/// (computed there with the exact Smith G1; Mitsuba's rational Beckmann G1
/// differs by < 0.35%, inside this test's 0.005 tolerance).
const TABLE: [(Distribution, f64, [f64; 4]); 8] = [
    (Distribution::Beckmann, 0.1, [1.000, 1.000, 1.000, 0.938]),
    (Distribution::Beckmann, 0.3, [1.000, 0.967, 0.923, 0.913]),
    (Distribution::Beckmann, 0.5, [0.943, 0.875, 0.869, 0.918]),
    (Distribution::Beckmann, 1.0, [0.462, 0.649, 0.756, 0.880]),
    (Distribution::Ggx, 0.1, [0.988, 0.982, 0.969, 0.892]),
    (Distribution::Ggx, 0.3, [0.877, 0.844, 0.818, 0.821]),
    (Distribution::Ggx, 0.5, [0.688, 0.678, 0.686, 0.747]),
    (Distribution::Ggx, 1.0, [0.307, 0.360, 0.409, 0.523]),
];
const ANGLES: [f64; 4] = [0.0, 45.0, 60.0, 80.0];

#[test]
fn albedo_matches_validation_table() {
    let mut worst: f64 = 0.0;
    for (d, alpha, row) in TABLE {
        let b = Bsdf::<3>::new(&conductor(d, alpha)).unwrap();
        for (k, &theta) in ANGLES.iter().enumerate() {
            let a = b.albedo(dir_deg(theta));
            let err = (a[0] - row[k]).abs();
            worst = worst.max(err);
            eprintln!(
                "{d:?} α={alpha} θ={theta}: trilux {:.4} table {:.3} (Δ {:+.4})",
                a[0],
                row[k],
                a[0] - row[k]
            );
            assert!(
                err <= 0.005,
                "{d:?} α={alpha} θ={theta}: {} vs {}",
                a[0],
                row[k]
            );
        }
    }
    eprintln!("worst |Δ| = {worst:.4}");
}

/// The quadrature albedo against the mean sample weight (an independent
/// estimator: sampling, pdf and eval together), within 4 standard errors.
#[test]
fn albedo_agrees_with_sampling() {
    let mut rng = Rng(7);
    let mats = [
        conductor(Distribution::Ggx, 0.05),
        conductor(Distribution::Ggx, 0.7),
        conductor(Distribution::Beckmann, 0.2),
        conductor(Distribution::Beckmann, 0.8),
        gold(Distribution::Ggx, 0.3),
        gold(Distribution::Beckmann, 0.5),
        common::diffuse(0.7),
    ];
    for p in &mats {
        let b = Bsdf::<3>::new(p).unwrap();
        for theta in [5.0, 40.0, 70.0, 85.0] {
            let wo = dir_deg(theta);
            let n = 200_000;
            let (mut s, mut s2) = (DVec3::ZERO, DVec3::ZERO);
            for _ in 0..n {
                if let Some(x) = b.sample(wo, rng.vec2()) {
                    let w = DVec3::new(x.weight[0], x.weight[1], x.weight[2]);
                    s += w;
                    s2 += w * w;
                }
            }
            let mean = s / n as f64;
            let var = s2 / n as f64 - mean * mean;
            let a = b.albedo(wo);
            for c in 0..3 {
                let se = (var[c] / n as f64).sqrt();
                let err = (a[c] - mean[c]).abs();
                assert!(
                    err <= 4.0 * se + 2e-4,
                    "{p:?} θ={theta} ch{c}: quadrature {} sampling {} ± {se}",
                    a[c],
                    mean[c]
                );
            }
        }
    }
}
