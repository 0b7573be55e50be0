//! Render time per bundled scene: one draft solve per scene outside the
//! timing, then the final gather of its camera at 128×128, 16 spp (camera,
//! shadow and gather rays through trilux-geometry: the renderer's ray cost).
//!
//! Run: `cargo bench -p trilux --bench render`
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test, bench or example may panic

use std::path::PathBuf;

use criterion::{Criterion, criterion_group, criterion_main};
use trilux::{ViewOverrides, prepare, scene_camera};
use trilux_color::WithBands;
use trilux_render::{RenderSettings, render};
use trilux_scene::Scene;
use trilux_solver::{Quality, Solver, SolverSettings};

fn scenes() -> Vec<PathBuf> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    let mut out: Vec<PathBuf> = std::fs::read_dir(&dir)
        .map(|d| d.filter_map(|e| e.ok().map(|e| e.path())).collect())
        .unwrap_or_default();
    out.retain(|p| p.extension().is_some_and(|x| x == "xml"));
    out.sort();
    out
}

/// Solves `scene` at draft quality, then benches its render.
struct Bench<'a, 'c> {
    scene: &'a Scene,
    name: &'a str,
    c: &'c mut Criterion,
}

impl WithBands for Bench<'_, '_> {
    type Output = ();

    fn run<const N: usize>(self) {
        let prepared = prepare::<N>(self.scene).expect("valid scene");
        let solution = Solver::new(prepared, SolverSettings::preset(Quality::Draft))
            .expect("valid settings")
            .solve(|_| {});
        let view = ViewOverrides {
            width: Some(128),
            height: Some(128),
            ..Default::default()
        };
        let camera = scene_camera(self.scene, &view).expect("camera");
        let settings = RenderSettings {
            spp: 16,
            ..trilux::render_settings(self.scene.camera.as_ref().expect("camera"))
        };
        let mut group = self.c.benchmark_group("render");
        group.sample_size(10);
        group.bench_function(self.name, |b| {
            b.iter(|| render(&solution, &camera, &settings, |_, _| {}).expect("render"))
        });
        group.finish();
    }
}

fn bench(c: &mut Criterion) {
    for path in scenes() {
        let Ok(scene) = trilux_scene::load(&path) else {
            continue;
        };
        let name = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        scene.mode().with_bands(Bench {
            scene: &scene,
            name: &name,
            c,
        });
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
