//! Sampling: chi-square goodness of fit of sampled directions against the
//! pdf (as Mitsuba's and pbrt's own tests do), and the pdf's integral.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test, bench or example may panic

mod common;

use std::f64::consts::{PI, TAU};

use common::{Rng, chi2_sf, conductor, diffuse, dir_deg, gold};
use glam::DVec3;
use trilux_brdf::{Bsdf, BsdfParams, Distribution};

const NZ: usize = 40;
const NPHI: usize = 80;
const SUB: usize = 12;

fn dir(z: f64, phi: f64) -> DVec3 {
    let r = (1.0 - z * z).max(0.0).sqrt();
    DVec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// ∫ pdf over each (|z|, φ) bin of the hemisphere on wo's side (dω = dz dφ),
/// by a SUB × SUB midpoint rule inside each bin.
fn expected(b: &Bsdf<3>, wo: DVec3) -> Vec<f64> {
    let sign = wo.z.signum();
    let mut e = vec![0.0; NZ * NPHI];
    for iz in 0..NZ {
        for ip in 0..NPHI {
            let mut acc = 0.0;
            for sz in 0..SUB {
                for sp in 0..SUB {
                    let z = (iz as f64 + (sz as f64 + 0.5) / SUB as f64) / NZ as f64;
                    let phi = (ip as f64 + (sp as f64 + 0.5) / SUB as f64) / NPHI as f64 * TAU;
                    acc += b.pdf(wo, dir(z * sign, phi));
                }
            }
            e[iz * NPHI + ip] = acc / (SUB * SUB) as f64 * (1.0 / NZ as f64) * (TAU / NPHI as f64);
        }
    }
    e
}

/// Returns the p-value of Pearson's χ² test (bins with expected count < 5
/// pooled).
fn chi2_test(p: &BsdfParams, wo: DVec3, n: usize, seed: u64) -> (f64, f64) {
    let b = Bsdf::<3>::new(p).unwrap();
    let e = expected(&b, wo);
    let mut obs = vec![0.0; NZ * NPHI];
    let mut rng = Rng(seed);
    for _ in 0..n {
        if let Some(s) = b.sample(wo, rng.vec2()) {
            let z = s.wi.z.abs().min(1.0 - 1e-15);
            let phi = s.wi.y.atan2(s.wi.x).rem_euclid(TAU);
            let iz = (z * NZ as f64) as usize;
            let ip = ((phi / TAU * NPHI as f64) as usize).min(NPHI - 1);
            obs[iz * NPHI + ip] += 1.0;
        }
    }
    let mut pairs: Vec<(f64, f64)> = e.iter().map(|&x| x * n as f64).zip(obs).collect();
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
    let (mut chi2, mut dof) = (0.0, 0usize);
    let (mut pool_e, mut pool_o) = (0.0, 0.0);
    for (ex, ob) in pairs {
        if ex < 5.0 {
            pool_e += ex;
            pool_o += ob;
            continue;
        }
        chi2 += (ob - ex) * (ob - ex) / ex;
        dof += 1;
    }
    if pool_e > 0.0 {
        chi2 += (pool_o - pool_e) * (pool_o - pool_e) / pool_e.max(1.0);
        dof += 1;
    }
    let k = (dof.max(2) - 1) as f64;
    (chi2_sf(chi2, k), e.iter().sum())
}

#[test]
fn sampling_matches_pdf_chi_square() {
    let mut cases: Vec<(String, BsdfParams, DVec3)> = Vec::new();
    for d in [Distribution::Beckmann, Distribution::Ggx] {
        for alpha in [0.1, 0.3, 0.6, 1.0] {
            for theta in [0.0, 30.0, 60.0, 80.0] {
                cases.push((
                    format!("{d:?} α={alpha} θ={theta}"),
                    conductor(d, alpha),
                    dir_deg(theta),
                ));
            }
        }
    }
    for theta in [0.0, 45.0, 85.0] {
        cases.push((format!("diffuse θ={theta}"), diffuse(0.5), dir_deg(theta)));
    }
    let blend = BsdfParams::Blend {
        weight: 0.4,
        first: Box::new(diffuse(0.8)),
        second: Box::new(gold(Distribution::Ggx, 0.2)),
    };
    let two = BsdfParams::TwoSided {
        front: Box::new(diffuse(0.3)),
        back: Some(Box::new(conductor(Distribution::Beckmann, 0.3))),
    };
    for theta in [10.0, 50.0, 75.0] {
        cases.push((format!("blend θ={theta}"), blend.clone(), dir_deg(theta)));
        let mut w = dir_deg(theta);
        w.z = -w.z;
        cases.push((format!("twosided back θ={theta}"), two.clone(), w));
    }
    // Šidák-style correction: the whole family at significance 1%.
    let alpha_sig = 0.01 / cases.len() as f64;
    let mut failures = Vec::new();
    for (i, (name, p, wo)) in cases.iter().enumerate() {
        let (pval, mass) = chi2_test(p, *wo, 500_000, 1000 + i as u64);
        eprintln!("{name}: p = {pval:.3e}, ∫pdf = {mass:.4}");
        if pval < alpha_sig {
            failures.push(format!("{name}: p = {pval:.3e}"));
        }
    }
    assert!(failures.is_empty(), "χ² rejects:\n{}", failures.join("\n"));
}

/// ∫ pdf dω over the hemisphere = 1 for diffuse sampling; for microfacet
/// sampling it equals the probability that a sample is valid (the rest lands
/// below the horizon and is returned as `None`), which the sampler itself
/// measures.
#[test]
fn pdf_integrates_to_one_where_it_should() {
    let integral = |b: &Bsdf<3>, wo: DVec3| -> f64 {
        // Fine (z, φ) quadrature with a z grid dense near the top.
        let (nz, nphi) = (2000, 400);
        let mut acc = 0.0;
        for iz in 0..nz {
            let z = (iz as f64 + 0.5) / nz as f64;
            for ip in 0..nphi {
                let phi = (ip as f64 + 0.5) / nphi as f64 * TAU;
                acc += b.pdf(wo, dir(z, phi));
            }
        }
        acc / (nz * nphi) as f64 * TAU
    };
    let d = Bsdf::<3>::new(&diffuse(0.5)).unwrap();
    for theta in [0.0, 50.0, 89.0] {
        let i = integral(&d, dir_deg(theta));
        assert!((i - 1.0).abs() < 1e-6, "diffuse: {i}");
    }
    let mut rng = Rng(99);
    for (dist, alpha) in [
        (Distribution::Ggx, 0.3),
        (Distribution::Ggx, 1.0),
        (Distribution::Beckmann, 0.3),
        (Distribution::Beckmann, 1.0),
    ] {
        let b = Bsdf::<3>::new(&conductor(dist, alpha)).unwrap();
        for theta in [0.0, 45.0, 80.0] {
            let wo = dir_deg(theta);
            let i = integral(&b, wo);
            let n = 400_000;
            let ok = (0..n)
                .filter(|_| b.sample(wo, rng.vec2()).is_some())
                .count() as f64
                / n as f64;
            let se = (ok * (1.0 - ok) / n as f64).sqrt();
            eprintln!("{dist:?} α={alpha} θ={theta}: ∫pdf = {i:.5}, valid fraction = {ok:.5}");
            assert!(i <= 1.0 + 1e-3);
            assert!(
                (i - ok).abs() <= 4.0 * se + 2e-3,
                "{dist:?} {alpha} {theta}: {i} vs {ok}"
            );
        }
    }
    let _ = PI;
}
