//! The furnace criterion (mean within 0.5 %, 99 % of pixels within 2 %)
//! through the whole pipeline: scenes/furnace.xml
//! (a closed cube, every inner face emitting 1 and reflecting 0.5 diffusely)
//! is solved by trilux-solver at the default quality (CR ≥ 0.99) and
//! rendered by each estimator (the path gather and the link gather at 64
//! spp, the preview at 1): the radiance is 2.0 everywhere, so the image
//! mean must be within 0.5 % of 2.0 and 99 % of the pixels within 2 %.
//! (The 1 % of flux left unshot at CR 0.99 lowers the reflected half of the
//! radiance by well under 1 %.) Adaptive sampling must keep the answer and
//! stop early: every pixel is alike, so after its minimum of samples.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test, bench or example may panic

use std::path::PathBuf;

use trilux::{Observer, Plan, RenderPlan, SolutionSource, ViewOverrides};
use trilux_render::driver::MIN_ADAPTIVE_SPP;
use trilux_render::{Estimator, RenderSettings};
use trilux_solver::{Quality, SolverSettings};

#[test]
fn solved_furnace_renders_two_with_every_estimator() {
    for (estimator, spp) in [
        (Estimator::Paths, 64),
        (Estimator::Links, 64),
        (Estimator::Preview, 1),
    ] {
        let (mean, within, samples) = furnace(estimator, spp, None);
        println!(
            "{estimator:?}: mean {mean:?}, {within:.4} of pixels within 2 %, {samples} samples"
        );
        for m in mean {
            assert!(
                (m - 2.0).abs() <= 0.005 * 2.0,
                "{estimator:?}: mean {mean:?}"
            );
        }
        assert!(
            within >= 0.99,
            "{estimator:?}: only {within} of pixels within 2 %"
        );
    }
}

#[test]
fn adaptive_sampling_keeps_the_furnace_and_stops_early() {
    // The link gather is exact in the furnace (every link fully visible,
    // every sender at 2.0): each pixel takes the minimum, its pilot's
    // samples, kept (not taken again). The path gather has per-sample noise
    // of about 10 % here: at a 1 % target a pixel needs about 100 samples,
    // well under the cap of 256.
    let pixels = 64 * 64;
    for (estimator, most) in [
        (Estimator::Links, MIN_ADAPTIVE_SPP as u64 * pixels),
        (Estimator::Paths, 160 * pixels),
    ] {
        let (mean, within, samples) = furnace(estimator, 256, Some(0.01));
        println!(
            "adaptive {estimator:?}: mean {mean:?}, {within:.4} within 2 %, {samples} samples"
        );
        for m in mean {
            assert!((m - 2.0).abs() <= 0.005 * 2.0, "mean {mean:?}");
        }
        assert!(within >= 0.99);
        assert!(samples <= most, "{estimator:?}: {samples} samples spent");
    }
}

/// The furnace rendered at 64 × 64: the image mean, the share of pixels
/// within 2 % of 2.0, and the camera samples spent.
fn furnace(estimator: Estimator, spp: u32, target_error: Option<f64>) -> ([f64; 3], f64, u64) {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenes/furnace.xml");
    let scene = trilux_scene::load(&path).unwrap();
    let settings = RenderSettings {
        spp,
        estimator,
        target_error,
        ..trilux::render_settings(scene.camera.as_ref().unwrap())
    };
    let view = ViewOverrides {
        width: Some(64),
        height: Some(64),
        ..Default::default()
    };
    let plan = Plan {
        mode: scene.mode(),
        solver: SolverSettings::preset(Quality::Default),
        source: SolutionSource::Solve,
        save: None,
        solution_file: false,
        bake: None,
        render: Some(RenderPlan { view, settings }),
    };
    let outcome = Observer::quiet(|o| trilux::pipeline::run(&scene, &plan, o)).unwrap();
    assert!(outcome.solve.convergence_ratio >= 0.99);
    let img = outcome.image.unwrap();
    let within = img
        .pixels()
        .iter()
        .filter(|p| p.iter().all(|&c| (c - 2.0).abs() <= 0.02 * 2.0))
        .count() as f64
        / img.pixels().len() as f64;
    let samples = outcome.render.unwrap().gather.camera_rays;
    (img.mean(), within, samples)
}
