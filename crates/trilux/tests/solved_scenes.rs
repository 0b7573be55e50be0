//! The final gather on trilux's real layers (scene loader, geometry, BRDFs,
//! colour) with stand-in solutions, on the scene files in scenes/.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test, bench or example may panic

use std::path::PathBuf;

use trilux::{ViewOverrides, prepare, scene_camera};
use trilux_color::Spectrum;
use trilux_render::{DirectOnly, RenderSettings, render};

fn scene(name: &str) -> trilux_scene::Scene {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../scenes")
        .join(name);
    trilux_scene::load(&p).unwrap()
}

fn small(w: u32) -> ViewOverrides {
    ViewOverrides {
        width: Some(w),
        height: Some(w),
        ..Default::default()
    }
}

#[test]
fn furnace_file_renders_two_with_a_solution_that_knows_the_answer() {
    // scenes/furnace.xml: Le = 1, ρ = 0.5. A stand-in solution answering the
    // exact reflected radiance 1 everywhere: image 2.0 (the furnace
    // criterion: mean within 0.5 %, 99 % of pixels within 2 %, 64 spp).
    let s = scene("furnace.xml");
    let sol = DirectOnly::<3>::constant(prepare(&s).unwrap(), Spectrum::splat(1.0));
    let settings = RenderSettings {
        spp: 64,
        ..trilux::render_settings(s.camera.as_ref().unwrap())
    };
    let camera = scene_camera(&s, &small(64)).unwrap();
    let (img, stats) = render(&sol, &camera, &settings, |_, _| {}).unwrap();
    for m in img.mean() {
        assert!((m - 2.0).abs() < 0.01, "mean {m}");
    }
    let ok = img
        .pixels()
        .iter()
        .filter(|p| p.iter().all(|c| (c - 2.0).abs() < 0.04))
        .count();
    assert!(
        ok as f64 >= 0.99 * img.pixels().len() as f64,
        "{ok} pixels within 2 %"
    );
    assert_eq!(stats.gather.dropped, 0);
}

#[test]
fn every_scene_renders_direct_light_without_nan_in_both_modes() {
    for name in [
        "cornell-box.xml",
        "paper-scene1.xml",
        "paper-scene2.xml",
        "paper-scene3.xml",
        "furnace.xml",
    ] {
        let s = scene(name);
        let settings = RenderSettings {
            spp: 4,
            ..trilux::render_settings(s.camera.as_ref().unwrap())
        };
        let camera = scene_camera(&s, &small(24)).unwrap();
        let rgb = DirectOnly::<3>::new(prepare(&s).unwrap());
        let (img, stats) = render(&rgb, &camera, &settings, |_, _| {}).unwrap();
        assert_eq!(stats.gather.dropped, 0, "{name}");
        let mean = img.mean();
        assert!(
            mean.iter().all(|m| m.is_finite() && *m > 0.0),
            "{name}: mean {mean:?}"
        );
        let spectral = DirectOnly::<10>::new(prepare(&s).unwrap());
        let (img, stats) = render(&spectral, &camera, &settings, |_, _| {}).unwrap();
        assert_eq!(stats.gather.dropped, 0, "{name} spectral");
        assert!(
            img.pixels().iter().flatten().all(|v| v.is_finite()),
            "{name} spectral"
        );
    }
}
