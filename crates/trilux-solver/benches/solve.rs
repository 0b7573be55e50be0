//! Solve time per bundled scene (geometry, materials and the solve): `cargo bench -p
//! trilux-solver --bench solve`. Draft quality keeps a full sweep short;
//! `TRILUX_BENCH_QUALITY=default` measures the default preset.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test, bench or example may panic

use std::path::PathBuf;

use criterion::{Criterion, criterion_group, criterion_main};
use trilux_color::Mode;
use trilux_solver::{Quality, SceneDescription, Solver, SolverSettings};

fn scenes() -> Vec<PathBuf> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    let mut out: Vec<PathBuf> = std::fs::read_dir(&dir)
        .map(|d| d.filter_map(|e| e.ok().map(|e| e.path())).collect())
        .unwrap_or_default();
    out.retain(|p| p.extension().is_some_and(|x| x == "xml"));
    out.sort();
    out
}

fn bench(c: &mut Criterion) {
    let quality: Quality = std::env::var("TRILUX_BENCH_QUALITY")
        .ok()
        .and_then(|q| q.parse().ok())
        .unwrap_or(Quality::Draft);
    let mut group = c.benchmark_group("solve");
    group.sample_size(10);
    for path in scenes() {
        let Ok(scene) = trilux_scene::load(&path) else {
            continue;
        };
        let (shapes, bsdfs, emission) = (
            scene.geometry_shapes(),
            scene.bsdf_params(),
            scene.emitter_radiance(),
        );
        let input = SceneDescription {
            shapes: &shapes,
            bsdfs: &bsdfs,
            emission: &emission,
        };
        let settings = SolverSettings::preset(quality);
        let name = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        match scene.mode() {
            Mode::Rgb => group.bench_function(&name, |b| {
                b.iter(|| {
                    Solver::<3>::from_description(&input, settings.clone())
                        .map(|s| s.solve(|_| {}))
                        .is_ok()
                })
            }),
            Mode::Spectral => group.bench_function(&name, |b| {
                b.iter(|| {
                    Solver::<{ trilux_color::SPECTRAL_BANDS }>::from_description(
                        &input,
                        settings.clone(),
                    )
                    .map(|s| s.solve(|_| {}))
                    .is_ok()
                })
            }),
        };
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
