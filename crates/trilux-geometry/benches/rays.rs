//! Closest-hit and occlusion rays per second, on 1 and 2 threads, on a
//! ≥100k-triangle scene (a tessellated sphere in a box) and on a
//! Cornell-box-sized scene.
//!
//! Run: `cargo bench -p trilux-geometry --bench rays -- --warm-up-time 1 --measurement-time 3`
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test, bench or example may panic

mod scenes;

use std::hint::black_box;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use glam::{DVec2, DVec3};
use scenes::*;
use trilux_geometry::{ElementForest, Geometry, Ray, SurfaceId};

const RAYS: usize = 200_000;

/// Incoherent rays from random points inside the box in random directions,
/// and segments between random pairs of such points.
fn workload(geom: &Geometry, seed: u64) -> (Vec<Ray>, Vec<(DVec3, DVec3)>) {
    let mut rng = Rng(seed);
    let b = geom.bounds();
    let (lo, hi) = (b.min + 0.05 * b.diagonal(), b.max - 0.05 * b.diagonal());
    let rays = (0..RAYS)
        .map(|_| Ray {
            origin: rng.in_box(lo, hi),
            dir: rng.direction(),
        })
        .collect();
    let segs = (0..RAYS)
        .map(|_| (rng.in_box(lo, hi), rng.in_box(lo, hi)))
        .collect();
    (rays, segs)
}

/// Gather-like rays: from points sampled on the surfaces, into their front
/// hemisphere; shadow segments between points on two random surfaces.
fn surface_workload(forest: &ElementForest, seed: u64) -> (Vec<Ray>, Vec<(DVec3, DVec3)>) {
    let mut rng = Rng(seed);
    let n = forest.geometry().surfaces().len();
    let point = |rng: &mut Rng| {
        let s = SurfaceId(((rng.next_f64() * n as f64) as usize).min(n - 1) as u32);
        forest.sample_surface(s, DVec2::new(rng.next_f64(), rng.next_f64()))
    };
    let rays = (0..RAYS)
        .map(|_| {
            let s = point(&mut rng);
            let d = rng.direction();
            Ray {
                origin: s.point,
                dir: if d.dot(s.normal) < 0.0 { -d } else { d },
            }
        })
        .collect();
    let segs = (0..RAYS)
        .map(|_| (point(&mut rng).point, point(&mut rng).point))
        .collect();
    (rays, segs)
}

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
    let (r, s) = workload(&geom, 1);
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
    let (r, s) = surface_workload(&forest, 2);
    bench_scene(c, "cornell_box", geom, &r, &s);
}

criterion_group!(benches, rays);
criterion_main!(benches);
