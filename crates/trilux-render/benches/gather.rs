//! Final-gather throughput on the analytic furnace (no geometry crate):
//! the cost of the estimator, sampler, filter and tiling themselves.
//!
//! Run: `cargo bench -p trilux-render --bench gather -- --warm-up-time 1 --measurement-time 3`
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test, bench or example may panic

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use glam::DVec3;
use trilux_render::analytic::Furnace;
use trilux_render::camera::look_at;
use trilux_render::{Camera, FovAxis, RenderSettings, render_image};

fn bench(c: &mut Criterion) {
    let scene = Furnace {
        le: 1.0,
        rho: 0.5,
        reflected: 1.0,
        element: 0.5,
    };
    let cam = Camera::new(
        look_at(DVec3::ZERO, DVec3::Z, DVec3::Y).unwrap(),
        90.0,
        FovAxis::X,
        64,
        64,
    )
    .unwrap();
    let settings = RenderSettings {
        spp: 16,
        ..Default::default()
    };
    let mut g = c.benchmark_group("final_gather");
    g.throughput(Throughput::Elements(64 * 64 * 16));
    g.bench_function("furnace_64x64_16spp", |b| {
        b.iter(|| render_image::<_, 3>(&scene, &cam, &settings, |l| l.0, |_, _| {}).unwrap())
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
