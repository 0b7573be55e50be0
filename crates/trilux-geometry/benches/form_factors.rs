//! Element-to-element form factors per second (default accuracy), and
//! visibility estimates per second.
//!
//! Run: `cargo bench -p trilux-geometry --bench form_factors -- --warm-up-time 1 --measurement-time 3`
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test, bench or example may panic

mod scenes;

use std::hint::black_box;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use glam::{DMat4, DVec3};
use scenes::*;
use trilux_geometry::{
    ElementForest, ElementId, FaceElement, FormFactorOptions, Geometry, Shape, ShapeKind,
    SurfaceId, Visibility, form_factor_batch, form_factor_front,
};

/// All ordered pairs of elements at depth `depth` of different surfaces
/// whose centres face each other.
fn facing_pairs(geom: &mut ElementForest, depth: u32, limit: usize) -> Vec<(ElementId, ElementId)> {
    let mut elems = Vec::new();
    for s in 0..geom.geometry().surfaces().len() {
        let mut f = vec![geom.root(SurfaceId(s as u32))];
        for _ in 0..depth {
            f = f.into_iter().flat_map(|e| geom.subdivide(e)).collect();
        }
        elems.extend(f);
    }
    let mut pairs = Vec::new();
    for &a in &elems {
        for &b in &elems {
            let (ea, eb) = (geom.element(a), geom.element(b));
            let d = eb.centre - ea.centre;
            if ea.surface != eb.surface && ea.normal.dot(d) > 0.0 && eb.normal.dot(d) < 0.0 {
                pairs.push((a, b));
            }
        }
    }
    let step = (pairs.len() / limit).max(1);
    pairs.into_iter().step_by(step).take(limit).collect()
}

fn bench_pairs(
    c: &mut Criterion,
    name: &str,
    geom: &ElementForest,
    pairs: &[(ElementId, ElementId)],
) {
    let mut group = c.benchmark_group(name);
    group.sample_size(10);
    group.throughput(Throughput::Elements(pairs.len() as u64));
    let opts = FormFactorOptions::default();
    let faces: Vec<(FaceElement, FaceElement)> = pairs
        .iter()
        .map(|&(a, b)| (FaceElement::front(a), FaceElement::front(b)))
        .collect();
    group.bench_function("form_factor/1t", |b| {
        b.iter(|| {
            black_box(
                pairs
                    .iter()
                    .map(|&(x, y)| form_factor_front(geom, x, y).value)
                    .sum::<f64>(),
            )
        })
    });
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .expect("thread pool");
    group.bench_function("form_factor/2t", |b| {
        b.iter(|| pool.install(|| black_box(form_factor_batch(geom, &faces, &opts))))
    });
    group.bench_function("visibility16/1t", |b| {
        b.iter(|| {
            black_box(
                pairs
                    .iter()
                    .map(|&(x, y)| {
                        Visibility::new(geom, None).fraction(
                            FaceElement::front(x),
                            FaceElement::front(y),
                            16,
                        )
                    })
                    .sum::<f64>(),
            )
        })
    });
    group.finish();
}

fn form_factors(c: &mut Criterion) {
    let mut geom = ElementForest::new(Geometry::build_shared(&cornell_box()).expect("valid scene"));
    let pairs = facing_pairs(&mut geom, 2, 2000);
    eprintln!(
        "cornell box: {} planar element pairs at depth 2",
        pairs.len()
    );
    bench_pairs(c, "ff_planar_cornell", &geom, &pairs);

    let curved = vec![
        Shape {
            kind: ShapeKind::Sphere {
                center: DVec3::new(0.0, 0.0, 1.5),
                radius: 1.0,
            },
            world_from_object: DMat4::IDENTITY,
            flip_normals: false,
        },
        Shape {
            kind: ShapeKind::Cylinder {
                p0: DVec3::new(3.0, -1.0, 0.0),
                p1: DVec3::new(3.0, 1.0, 0.0),
                radius: 0.7,
            },
            world_from_object: DMat4::IDENTITY,
            flip_normals: false,
        },
        Shape {
            kind: ShapeKind::Disk,
            world_from_object: DMat4::from_scale(DVec3::splat(3.0)),
            flip_normals: false,
        },
    ];
    let mut geom = ElementForest::new(Geometry::build_shared(&curved).expect("valid scene"));
    let pairs = facing_pairs(&mut geom, 1, 2000);
    eprintln!(
        "sphere, cylinder, disk: {} curved element pairs at depth 1",
        pairs.len()
    );
    bench_pairs(c, "ff_curved", &geom, &pairs);

    let mut geom =
        ElementForest::new(Geometry::build_shared(&sphere_in_box(32)).expect("valid scene"));
    let pairs = facing_pairs(&mut geom, 2, 2000);
    eprintln!(
        "tessellated sphere (charts) in a box: {} pairs at depth 2",
        pairs.len()
    );
    bench_pairs(c, "ff_charts", &geom, &pairs);
}

criterion_group!(benches, form_factors);
criterion_main!(benches);
