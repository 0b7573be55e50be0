//! Times closest-hit and occlusion queries on one thread, on the ray
//! benchmark's scenes and workloads (for profiling with `perf record`; the
//! record is `cargo xtask rays`).
//!
//! Run: `cargo run -p trilux-geometry --release --example ray_profile [-- RAYS [sphere|cornell]]`
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test, bench or example may panic

#[path = "../benches/scenes/mod.rs"]
mod scenes;

use std::hint::black_box;
use std::time::Instant;

use trilux_geometry::{ElementForest, Geometry};

fn main() -> Result<(), trilux_geometry::GeometryError> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let count: usize = args
        .first()
        .and_then(|a| a.parse().ok())
        .unwrap_or(1_000_000);
    let which = args.get(1).map_or("sphere", String::as_str);
    let t0 = Instant::now();
    let (geom, (rays, segs)) = if which == "cornell" {
        let forest = ElementForest::new(Geometry::build_shared(&scenes::cornell_box())?);
        let w = scenes::surface_workload(&forest, count, 2);
        (forest.shared_geometry().clone(), w)
    } else {
        let geom = Geometry::build_shared(&scenes::sphere_in_box(160))?;
        let w = scenes::workload(&geom, count, 1);
        (geom, w)
    };
    println!(
        "{which}: {} primitives, built with the workload in {:.2} s",
        geom.primitive_count(),
        t0.elapsed().as_secs_f64()
    );
    for _ in 0..3 {
        let t0 = Instant::now();
        let hits = rays
            .iter()
            .filter(|r| black_box(geom.intersect(r, f64::INFINITY)).is_some())
            .count();
        let closest = t0.elapsed().as_nanos() as f64 / count as f64;
        let t0 = Instant::now();
        let occ = segs
            .iter()
            .filter(|&&(p, q)| black_box(geom.occluded(p, q)))
            .count();
        let shadow = t0.elapsed().as_nanos() as f64 / count as f64;
        println!(
            "closest hit {closest:.0} ns/ray ({hits} hits), occlusion {shadow:.0} ns/segment ({occ} occluded)"
        );
    }
    Ok(())
}
