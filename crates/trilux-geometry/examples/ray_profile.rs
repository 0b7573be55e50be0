//! Times closest-hit and occlusion queries on one thread, on the ray
//! benchmark's scenes and workloads (for profiling with `perf record`; the
//! record is `cargo xtask rays`).
//!
//! Run: `cargo run -p trilux-geometry --release --example ray_profile [-- RAYS [sphere[N]|cornell] [closest|shadow]]`
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
    let only = args.get(2).map_or("both", String::as_str);
    let t0 = Instant::now();
    let (geom, (rays, segs)) = if which == "cornell" {
        let forest = ElementForest::new(Geometry::build_shared(&scenes::cornell_box())?);
        let w = scenes::surface_workload(&forest, count, 2);
        (forest.shared_geometry().clone(), w)
    } else {
        let n = which
            .strip_prefix("sphere")
            .and_then(|n| n.parse().ok())
            .unwrap_or(160);
        let geom = Geometry::build_shared(&scenes::sphere_in_box(n))?;
        let w = scenes::workload(&geom, count, 1);
        (geom, w)
    };
    println!(
        "{which}: {} primitives, built with the workload in {:.2} s; BVH {:?}",
        geom.primitive_count(),
        t0.elapsed().as_secs_f64(),
        geom.bvh_stats()
    );
    #[cfg(feature = "trace-stats")]
    stats(&geom, &rays, &segs);
    for _ in 0..3 {
        let t0 = Instant::now();
        let hits = rays
            .iter()
            .take(if only == "shadow" { 0 } else { count })
            .filter(|r| black_box(geom.intersect(r, f64::INFINITY)).is_some())
            .count();
        let closest = t0.elapsed().as_nanos() as f64 / count as f64;
        let t0 = Instant::now();
        let occ = segs
            .iter()
            .take(if only == "closest" { 0 } else { count })
            .filter(|&&(p, q)| black_box(geom.occluded(p, q)))
            .count();
        let shadow = t0.elapsed().as_nanos() as f64 / count as f64;
        println!(
            "closest hit {closest:.0} ns/ray ({hits} hits), occlusion {shadow:.0} ns/segment ({occ} occluded)"
        );
    }
    // The batch calls (several rays in flight), on one thread.
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    for _ in 0..3 {
        let t0 = Instant::now();
        let hits: usize = pool.install(|| {
            rays.chunks(1 << 16)
                .take(if only == "shadow" { 0 } else { usize::MAX })
                .map(|c| {
                    geom.intersect_batch(c, f64::INFINITY)
                        .iter()
                        .flatten()
                        .count()
                })
                .sum()
        });
        let closest = t0.elapsed().as_nanos() as f64 / count as f64;
        let t0 = Instant::now();
        let occ: usize = pool.install(|| {
            segs.chunks(1 << 16)
                .take(if only == "closest" { 0 } else { usize::MAX })
                .map(|c| geom.occluded_batch(c).iter().filter(|&&o| o).count())
                .sum()
        });
        let shadow = t0.elapsed().as_nanos() as f64 / count as f64;
        println!(
            "batch: closest hit {closest:.0} ns/ray ({hits} hits), occlusion {shadow:.0} ns/segment ({occ} occluded)"
        );
    }
    Ok(())
}

/// Traversal work per query (`--features trace-stats`).
#[cfg(feature = "trace-stats")]
fn stats(geom: &Geometry, rays: &[trilux_geometry::Ray], segs: &[(glam::DVec3, glam::DVec3)]) {
    use trilux_geometry::trace_stats::take;
    let per = |n: usize| take().map(|x| x as f64 / n as f64);
    take();
    rays.iter().for_each(|r| {
        black_box(geom.intersect(r, f64::INFINITY));
    });
    let s = per(rays.len());
    println!(
        "closest: nodes {:.2} leaves {:.2} f64 hits {:.2} misses {:.2}",
        s[0], s[1], s[2], s[3]
    );
    segs.iter().for_each(|&(p, q)| {
        black_box(geom.occluded(p, q));
    });
    let s = per(segs.len());
    println!(
        "occluded: nodes {:.2} leaves {:.2} f64 hits {:.2} misses {:.2}",
        s[0], s[1], s[2], s[3]
    );
}
