//! BRDF evaluations, samples and area-reflectance estimates per second.
//!
//! Run: `cargo bench -p trilux-brdf --bench brdf -- --warm-up-time 1 --measurement-time 3`
//! Each iteration processes a batch of 1024 direction pairs (throughput is
//! reported per element).
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test, bench or example may panic

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use glam::{DVec2, DVec3};
use std::hint::black_box;
use trilux_brdf::{
    Bsdf, BsdfParams, Distribution, ElementPoints, RoughConductorParams, area_reflectance,
    brdf_variation,
};
use trilux_color::ColorParam;

const BATCH: usize = 1024;

fn models() -> Vec<(&'static str, BsdfParams)> {
    let rc = |distribution, alpha, gold: bool| {
        BsdfParams::RoughConductor(RoughConductorParams {
            distribution,
            alpha,
            eta_k: gold.then_some((
                ColorParam::Rgb([0.143, 0.374, 1.442]),
                ColorParam::Rgb([3.983, 2.385, 1.603]),
            )),
            specular_reflectance: ColorParam::Float(1.0),
        })
    };
    vec![
        (
            "diffuse",
            BsdfParams::Diffuse {
                reflectance: ColorParam::Float(0.5),
            },
        ),
        ("ggx_none", rc(Distribution::Ggx, 0.2, false)),
        ("beckmann_none", rc(Distribution::Beckmann, 0.2, false)),
        ("ggx_gold", rc(Distribution::Ggx, 0.2, true)),
        (
            "blend_diffuse_ggx",
            BsdfParams::Blend {
                weight: 0.3,
                first: Box::new(BsdfParams::Diffuse {
                    reflectance: ColorParam::Float(0.5),
                }),
                second: Box::new(rc(Distribution::Ggx, 0.2, true)),
            },
        ),
    ]
}

fn dirs() -> Vec<(DVec3, DVec3, DVec2)> {
    let mut s = 0x1234_5678_u64;
    let mut r = move || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut h = || {
        let z = r().max(0.01);
        let p = r() * std::f64::consts::TAU;
        let q = (1.0 - z * z).sqrt();
        DVec3::new(q * p.cos(), q * p.sin(), z)
    };
    (0..BATCH)
        .map(|_| (h(), h(), DVec2::new(0.3, 0.7)))
        .collect()
}

fn bench<const N: usize>(c: &mut Criterion, tag: &str) {
    let d = dirs();
    let mut g = c.benchmark_group(format!("brdf_{tag}"));
    g.throughput(Throughput::Elements(BATCH as u64));
    for (name, p) in models() {
        let b = Bsdf::<N>::new(&p).unwrap();
        g.bench_function(format!("eval/{name}"), |bch| {
            bch.iter(|| {
                let mut acc = 0.0;
                for &(wi, wo, _) in &d {
                    acc += b.eval(black_box(wi), black_box(wo))[0];
                }
                acc
            })
        });
        g.bench_function(format!("sample/{name}"), |bch| {
            bch.iter(|| {
                let mut acc = 0.0;
                for (k, &(_, wo, _)) in d.iter().enumerate() {
                    let u = DVec2::new(
                        (k as f64 + 0.5) / BATCH as f64,
                        ((k * 7) % BATCH) as f64 / BATCH as f64,
                    );
                    if let Some(s) = b.sample(black_box(wo), u) {
                        acc += s.weight[0];
                    }
                }
                acc
            })
        });
    }
    g.finish();
}

fn bench_area(c: &mut Criterion) {
    let models = models();
    let b = Bsdf::<3>::new(&models[4].1).unwrap();
    let sq = |c: DVec3| {
        [
            c + DVec3::X * 0.1,
            c - DVec3::X * 0.1,
            c + DVec3::Y * 0.1,
            c - DVec3::Y * 0.1,
        ]
    };
    let (i, j, k) = (
        DVec3::new(-1.0, 0.0, 1.0),
        DVec3::ZERO,
        DVec3::new(1.0, 0.2, 1.0),
    );
    let (pi, pj, pk) = (sq(i), sq(j), sq(k));
    let ie = ElementPoints {
        centre: i,
        normal: DVec3::new(1.0, 0.0, -1.0).normalize(),
        points: &pi,
    };
    let je = ElementPoints {
        centre: j,
        normal: DVec3::Z,
        points: &pj,
    };
    let ke = ElementPoints {
        centre: k,
        normal: DVec3::new(-1.0, 0.0, -1.0).normalize(),
        points: &pk,
    };
    let mut g = c.benchmark_group("area");
    g.throughput(Throughput::Elements(1));
    g.bench_function("area_reflectance/blend", |bch| {
        bch.iter(|| area_reflectance(&b, black_box(0.05), black_box(i), j, DVec3::Z, black_box(k)))
    });
    g.bench_function("brdf_variation/blend", |bch| {
        bch.iter(|| brdf_variation(&b, black_box(&ie), black_box(&je), black_box(&ke)))
    });
    g.bench_function("albedo/blend", |bch| {
        bch.iter(|| b.albedo(black_box(DVec3::new(0.5, 0.0, 0.866))))
    });
    g.finish();
}

fn benches(c: &mut Criterion) {
    bench::<3>(c, "rgb");
    bench::<10>(c, "spectral10");
    bench_area(c);
}

criterion_group!(group, benches);
criterion_main!(group);
