//! Times closest-hit and occlusion queries on a ~100k-triangle scene (for
//! profiling; the criterion bench `rays` is the record).
//!
//! Run: `cargo run -p trilux-geometry --release --example ray_profile`
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test, bench or example may panic

use glam::{DMat4, DVec3};
use trilux_geometry::{Geometry, Ray, Shape, ShapeKind, TriangleMesh};

fn main() -> Result<(), trilux_geometry::GeometryError> {
    let n = 160u32;
    let mut p = Vec::new();
    for i in 0..=n {
        let th = std::f64::consts::PI * i as f64 / n as f64;
        for j in 0..=2 * n {
            let ph = std::f64::consts::PI * j as f64 / n as f64;
            p.push(DVec3::new(
                th.sin() * ph.cos(),
                th.sin() * ph.sin(),
                th.cos(),
            ));
        }
    }
    let w = 2 * n + 1;
    let mut t = Vec::new();
    for i in 0..n {
        for j in 0..2 * n {
            let a = i * w + j;
            t.push([a, a + w, a + w + 1]);
            t.push([a, a + w + 1, a + 1]);
        }
    }
    let shapes = [
        Shape {
            kind: ShapeKind::Mesh(TriangleMesh {
                positions: p,
                normals: None,
                triangles: t,
                face_normals: true,
                texcoords: None,
            }),
            world_from_object: DMat4::IDENTITY,
            flip_normals: false,
        },
        Shape {
            kind: ShapeKind::Cube,
            world_from_object: DMat4::from_scale(DVec3::splat(2.0)),
            flip_normals: true,
        },
    ];
    let t0 = std::time::Instant::now();
    let g = Geometry::build(&shapes)?;
    println!(
        "build: {:.2} s, {} primitives, {} input surfaces",
        t0.elapsed().as_secs_f64(),
        g.primitive_count(),
        g.surfaces().len()
    );
    let mut st = 7u64;
    let mut rnd = || {
        st ^= st << 13;
        st ^= st >> 7;
        st ^= st << 17;
        (st >> 11) as f64 / (1u64 << 53) as f64
    };
    let count = 1_000_000;
    let rays: Vec<Ray> = (0..count)
        .map(|_| Ray {
            origin: DVec3::new(3.6 * rnd() - 1.8, 3.6 * rnd() - 1.8, 3.6 * rnd() - 1.8),
            dir: DVec3::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5),
        })
        .collect();
    let t0 = std::time::Instant::now();
    let hits = rays
        .iter()
        .filter(|r| g.intersect(r, f64::INFINITY).is_some())
        .count();
    println!(
        "closest hit: {:.0} ns/ray ({hits} hits)",
        t0.elapsed().as_nanos() as f64 / count as f64
    );
    let t0 = std::time::Instant::now();
    let occ = rays.iter().filter(|r| g.ray_occluded(r, 1.0)).count();
    println!(
        "occlusion:   {:.0} ns/ray ({occ} occluded)",
        t0.elapsed().as_nanos() as f64 / count as f64
    );
    Ok(())
}
