//! The final gather on analytic mock scenes (trilux_render::analytic).
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test, bench or example may panic

use glam::DVec3;
use trilux_color::Spectrum;
use trilux_render::analytic::{Furnace, LitFloor};
use trilux_render::camera::look_at;
use trilux_render::{
    Camera, ExtraBounce, FovAxis, Image, ReconstructionFilter, RenderSettings, render_image,
};

fn rgb3(l: &Spectrum<3>) -> [f64; 3] {
    l.0
}

fn furnace_camera(w: u32, h: u32) -> Camera {
    let m = look_at(
        DVec3::new(0.1, -0.2, 0.0),
        DVec3::new(0.5, 0.3, 1.0),
        DVec3::Y,
    )
    .unwrap();
    Camera::new(m, 100.0, FovAxis::X, w, h).unwrap()
}

/// Share of pixels (all channels) within `tol` relative of `value`.
fn share_within(img: &Image, value: f32, tol: f32) -> f64 {
    let ok = img
        .pixels()
        .iter()
        .filter(|p| p.iter().all(|c| (c - value).abs() <= tol * value))
        .count();
    ok as f64 / img.pixels().len() as f64
}

#[test]
fn gather_of_a_constant_solution_is_exact() {
    // No emission; the solution says 2.0 everywhere; diffuse albedo 0.5 with
    // cosine sampling: every gather sample weighs fr·cos/pdf = ρ = 0.5, so
    // every pixel is exactly 1.0 (f32 rounding of the filter normalisation).
    let scene = Furnace {
        le: 0.0,
        rho: 0.5,
        reflected: 2.0,
        element: 0.5,
    };
    let settings = RenderSettings {
        spp: 4,
        extra_bounce: ExtraBounce::Never,
        ..Default::default()
    };
    let (img, stats) =
        render_image::<_, 3>(&scene, &furnace_camera(24, 16), &settings, rgb3, |_, _| {}).unwrap();
    for p in img.pixels() {
        for c in p {
            assert!((c - 1.0).abs() < 1e-6, "{c}");
        }
    }
    assert_eq!(stats.gather.camera_rays, 24 * 16 * 4);
    assert_eq!(stats.gather.dropped, 0);
}

#[test]
fn furnace_renders_two_at_64_spp() {
    // The furnace: emission 1, albedo 0.5, solution (reflected) 1 → L = 2.
    // Mean within 0.5 %, 99 % of pixels within 2 %, for every extra-bounce
    // rule (the extra bounce changes the estimator, not its expectation).
    for extra in [
        ExtraBounce::Never,
        ExtraBounce::Auto { close_factor: 1.0 },
        ExtraBounce::Always,
    ] {
        let scene = Furnace {
            le: 1.0,
            rho: 0.5,
            reflected: 1.0,
            element: 0.5,
        };
        let settings = RenderSettings {
            spp: 64,
            seed: 3,
            extra_bounce: extra,
            ..Default::default()
        };
        let (img, stats) =
            render_image::<_, 3>(&scene, &furnace_camera(64, 48), &settings, rgb3, |_, _| {})
                .unwrap();
        let mean = img.mean();
        for m in mean {
            assert!((m - 2.0).abs() < 0.005 * 2.0, "{extra:?}: mean {m}");
        }
        let share = share_within(&img, 2.0, 0.02);
        assert!(
            share >= 0.99,
            "{extra:?}: only {share} of pixels within 2 %"
        );
        match extra {
            ExtraBounce::Never => assert_eq!(stats.gather.extra_bounces, 0),
            ExtraBounce::Always => assert_eq!(stats.gather.extra_bounces, stats.gather.camera_rays),
            ExtraBounce::Auto { .. } => {
                assert!(
                    stats.gather.extra_bounces > 0
                        && stats.gather.extra_bounces < stats.gather.camera_rays
                )
            }
            other => panic!("no expectation for {other:?}"),
        }
    }
}

#[test]
fn a_biased_solution_shows_in_the_furnace() {
    // Sanity of the test above: a solution that is off by 10 % shows.
    let scene = Furnace {
        le: 1.0,
        rho: 0.5,
        reflected: 1.1,
        element: 0.5,
    };
    let settings = RenderSettings {
        spp: 64,
        extra_bounce: ExtraBounce::Never,
        ..Default::default()
    };
    let (img, _) =
        render_image::<_, 3>(&scene, &furnace_camera(32, 24), &settings, rgb3, |_, _| {}).unwrap();
    assert!((img.mean()[0] - 2.05).abs() < 0.01);
}

#[test]
fn direct_light_on_a_floor_matches_lamberts_formula() {
    // A 0.5°-wide view of a floor point under a square light: the pixel
    // footprint is a few mm, the closed form varies by < 0.1 % across it.
    // MIS of light samples and gather rays must reproduce ρ·Le·F within 1 %
    // (noise at 4096 spp × 9 pixels ≈ 0.2 %).
    let scene = LitFloor {
        rho: 0.8,
        s: 0.5,
        h: 1.0,
        le: 5.0,
    };
    let target = DVec3::new(0.7, 0.2, 0.0);
    let eye = DVec3::new(-0.3, -0.8, 0.6);
    let m = look_at(eye, target, DVec3::Z).unwrap();
    let cam = Camera::new(m, 0.5, FovAxis::X, 3, 3).unwrap();
    let settings = RenderSettings {
        spp: 4096,
        filter: ReconstructionFilter::Box,
        extra_bounce: ExtraBounce::Never,
        ..Default::default()
    };
    let (img, stats) = render_image::<_, 3>(&scene, &cam, &settings, rgb3, |_, _| {}).unwrap();
    let expected = scene.expected(target);
    let got = img.mean()[0];
    assert!(expected > 0.1);
    assert!(
        (got - expected).abs() < 0.01 * expected,
        "got {got}, closed form {expected}"
    );
    assert!(stats.gather.shadow_rays > 0 && stats.gather.gather_rays > 0);
}

#[test]
fn renders_are_deterministic_for_a_seed_whatever_the_threads() {
    let scene = Furnace {
        le: 1.0,
        rho: 0.5,
        reflected: 1.0,
        element: 0.5,
    };
    let settings = RenderSettings {
        spp: 8,
        seed: 11,
        tile_size: 8,
        ..Default::default()
    };
    let cam = furnace_camera(40, 30);
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            render_image::<_, 3>(&scene, &cam, &settings, rgb3, |_, _| {})
                .unwrap()
                .0
        })
    };
    let a = run(1);
    let b = run(2);
    assert_eq!(a, b);
    let other = RenderSettings {
        seed: 12,
        ..settings
    };
    let (c, _) = render_image::<_, 3>(&scene, &cam, &other, rgb3, |_, _| {}).unwrap();
    assert_ne!(a, c);
}

#[test]
fn bad_settings_are_errors() {
    let scene = Furnace {
        le: 1.0,
        rho: 0.5,
        reflected: 1.0,
        element: 0.5,
    };
    let cam = furnace_camera(4, 4);
    for s in [
        RenderSettings {
            spp: 0,
            ..Default::default()
        },
        RenderSettings {
            spp: 70_000,
            ..Default::default()
        },
        RenderSettings {
            tile_size: 0,
            ..Default::default()
        },
        RenderSettings {
            extra_bounce: ExtraBounce::Auto {
                close_factor: f64::NAN,
            },
            ..Default::default()
        },
    ] {
        assert!(render_image::<_, 3>(&scene, &cam, &s, rgb3, |_, _| {}).is_err());
    }
}

#[test]
fn non_finite_samples_are_counted_and_left_out() {
    // Every 7th sample's colour is NaN: the render counts each one in
    // `dropped` (which the command reports as a warning) and no pixel is
    // anything but the finite value of the others.
    use std::sync::atomic::{AtomicU64, Ordering};
    let scene = Furnace {
        le: 0.0,
        rho: 0.5,
        reflected: 2.0,
        element: 0.5,
    };
    let settings = RenderSettings {
        spp: 8,
        extra_bounce: ExtraBounce::Never,
        ..Default::default()
    };
    let k = AtomicU64::new(0);
    let poison = |l: &Spectrum<3>| {
        if k.fetch_add(1, Ordering::Relaxed).is_multiple_of(7) {
            [f64::NAN; 3]
        } else {
            l.0
        }
    };
    let (img, stats) = render_image::<_, 3>(
        &scene,
        &furnace_camera(16, 16),
        &settings,
        poison,
        |_, _| {},
    )
    .unwrap();
    let total = 16 * 16 * 8;
    assert_eq!(stats.gather.dropped, k.load(Ordering::Relaxed).div_ceil(7));
    assert!(stats.gather.dropped > 0 && stats.gather.dropped < total);
    assert!(img.first_non_finite().is_none());
    for c in img.pixels().iter().flatten() {
        assert!((c - 1.0).abs() < 1e-6, "{c}");
    }
}
