//! Spectrum arithmetic and colour conversions per second.
//!
//! Run: `cargo bench -p trilux-color --bench color -- --warm-up-time 1 --measurement-time 3`
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test, bench or example may panic

use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;
use trilux_color::{ColorParam, Spectrum};

fn benches(c: &mut Criterion) {
    let a = Spectrum::<10>::splat(0.3);
    let b = Spectrum::<10>::splat(0.7);
    c.bench_function("spectrum10/mul_add", |bch| {
        bch.iter(|| black_box(a) * black_box(b) + black_box(a))
    });
    c.bench_function("spectrum10/luminance", |bch| {
        bch.iter(|| black_box(a).luminance())
    });
    let light = ColorParam::Sampled(vec![
        (400.0, 0.0),
        (500.0, 8.0),
        (600.0, 15.6),
        (700.0, 18.4),
    ]);
    c.bench_function("convert/sampled_to_rgb_mitsuba", |bch| {
        bch.iter(|| black_box(&light).emission::<3>())
    });
    c.bench_function("convert/sampled_to_10_bands", |bch| {
        bch.iter(|| black_box(&light).emission::<10>())
    });
    c.bench_function("convert/rgb_to_smooth_10_bands", |bch| {
        bch.iter(|| ColorParam::Rgb(black_box([0.2, 0.5, 0.7])).reflectance::<10>())
    });
}

criterion_group!(group, benches);
criterion_main!(group);
