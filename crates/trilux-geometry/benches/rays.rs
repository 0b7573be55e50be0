//! Closest-hit and occlusion rays per second, on 1 and 2 threads, on a
//! ≥100k-triangle scene (a tessellated sphere in a box) and on a
//! Cornell-box-sized scene.
//!
//! Run: `cargo bench -p trilux-geometry --bench rays -- --warm-up-time 1 --measurement-time 3`
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test, bench or example may panic

mod scenes;

use std::hint::black_box;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use glam::DVec3;
use scenes::*;
use trilux_geometry::{ElementForest, Geometry, Ray};

const RAYS: usize = 200_000;

fn bench_scene(
    c: &mut Criterion,
    name: &str,
    geom: &Geometry,
    rays: &[Ray],
    segs: &[(DVec3, DVec3)],
) {
    let mut group = c.benchmark_group(name);
    group.sample_size(10);
    group.throughput(Throughput::Elements(rays.len() as u64));
    for threads in [1usize, 2] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("thread pool");
        group.bench_function(format!("closest_hit/{threads}t"), |b| {
            b.iter(|| pool.install(|| black_box(geom.intersect_batch(rays, f64::INFINITY))))
        });
        group.bench_function(format!("occluded/{threads}t"), |b| {
            b.iter(|| pool.install(|| black_box(geom.occluded_batch(segs))))
        });
    }
    group.finish();
}

fn rays(c: &mut Criterion) {
    let t0 = std::time::Instant::now();
    let geom = Geometry::build(&sphere_in_box(160)).expect("valid scene");
    eprintln!(
        "sphere in a box: {} primitives, {} input surfaces, built in {:.2} s",
        geom.primitive_count(),
        geom.surfaces().len(),
        t0.elapsed().as_secs_f64()
    );
    let (r, s) = workload(&geom, RAYS, 1);
    let hits = r
        .iter()
        .filter(|ray| geom.intersect(ray, f64::INFINITY).is_some())
        .count();
    eprintln!("  {hits} of {} closest-hit rays hit", r.len());
    bench_scene(c, "sphere_in_box_102k", &geom, &r, &s);

    let forest = ElementForest::new(Geometry::build_shared(&cornell_box()).expect("valid scene"));
    let geom = forest.geometry();
    eprintln!(
        "cornell box: {} primitives, {} input surfaces",
        geom.primitive_count(),
        geom.surfaces().len()
    );
    let (r, s) = surface_workload(&forest, RAYS, 2);
    bench_scene(c, "cornell_box", geom, &r, &s);
}

criterion_group!(benches, rays);
criterion_main!(benches);
