//! The control variate (`trilux_render::control`) on the analytic furnace:
//! its expectation is the true radiance whatever the solution says.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test, bench or example may panic

use glam::DVec3;
use trilux_color::Spectrum;
use trilux_render::analytic::Furnace;
use trilux_render::camera::look_at;
use trilux_render::{Camera, Estimator, ExtraBounce, FovAxis, RenderSettings, render_image};

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

/// The furnace's image mean (channel 0) with a solution answering
/// `reflected` everywhere (the exact answer is 1: emission 1, albedo 0.5,
/// L = 2).
fn furnace_mean(reflected: f64, estimator: Estimator, lookups: u32) -> f64 {
    furnace_mean_with(
        reflected,
        RenderSettings {
            estimator,
            lookups,
            ..Default::default()
        },
    )
}

/// [`furnace_mean`] with more of the settings given (64 spp, seed 5 and
/// no extra bounce always).
fn furnace_mean_with(reflected: f64, settings: RenderSettings) -> f64 {
    let scene = Furnace {
        le: 1.0,
        rho: 0.5,
        reflected,
        element: 0.5,
    };
    let settings = RenderSettings {
        spp: 64,
        seed: 5,
        extra_bounce: ExtraBounce::Never,
        ..settings
    };
    let (img, stats) =
        render_image::<_, 3>(&scene, &furnace_camera(48, 32), &settings, rgb3, |_, _| {}).unwrap();
    assert_eq!(stats.gather.dropped, 0);
    img.mean()[0]
}

#[test]
fn the_control_variate_is_unbiased_whatever_the_solution() {
    // L = Le / (1 − ρ) = 2. A solution that is exact (1), half (0.5), zero
    // or three times too bright (3) must give the same mean within the
    // noise of 98 304 paths (measured ≤ 0.1 %; bound 0.5 %), with one
    // lookup (a path tracer) or eight.
    for reflected in [1.0, 0.5, 0.0, 3.0] {
        for lookups in [1, 8] {
            let m = furnace_mean(reflected, Estimator::Control, lookups);
            assert!(
                (m - 2.0).abs() <= 0.005 * 2.0,
                "solution {reflected}, {lookups} lookups: mean {m}, not 2"
            );
        }
    }
}

#[test]
fn the_path_gather_with_a_wrong_solution_is_biased() {
    // The test above can fail: the path gather, which reads the solution
    // instead of correcting it, gives Le + ρ (Le + 0.5) = 1.75 with the
    // solution at half, 12.5 % below 2 (direct light from the emitting
    // walls, the solution for the rest).
    let m = furnace_mean(0.5, Estimator::Paths, 1);
    assert!((m - 1.75).abs() < 0.005, "mean {m}");
}

#[test]
fn a_path_length_limit_counts_exactly_the_paths_mitsuba_counts() {
    // Paths of at most D segments from the eye carry Le Σ_{k<D} ρ^k =
    // 2 (1 − 0.5^D): 0, 1, 1.5, 1.75 for D = 0..3 (Mitsuba's `max_depth`,
    // emission seen directly being the path of one segment), whatever the
    // solution says (here 3× too bright), with one lookup or eight. Bound
    // 0.5 % as above (D = 0 and 1 are exact).
    for depth in 0..=3u32 {
        let expected = 2.0 * (1.0 - 0.5f64.powi(depth as i32));
        for lookups in [1, 8] {
            let settings = RenderSettings {
                estimator: Estimator::Control,
                lookups,
                max_depth: Some(depth),
                ..Default::default()
            };
            let m = furnace_mean_with(3.0, settings);
            assert!(
                (m - expected).abs() <= 0.005 * expected,
                "max_depth {depth}, {lookups} lookups: mean {m}, not {expected}"
            );
        }
    }
}

#[test]
fn only_the_control_variate_takes_a_path_length_limit() {
    // The other estimators read a solution that carries every bounce.
    for estimator in [Estimator::Paths, Estimator::Links, Estimator::Preview] {
        let settings = RenderSettings {
            estimator,
            max_depth: Some(4),
            ..Default::default()
        };
        let e = settings.validate().unwrap_err().to_string();
        assert!(e.contains("max_depth 4"), "{e}");
    }
    let control = RenderSettings {
        estimator: Estimator::Control,
        max_depth: Some(4),
        ..Default::default()
    };
    assert!(control.validate().is_ok());
}

#[test]
fn hidden_emitters_leave_a_furnace_black() {
    // Every wall of the furnace emits, so with `hide_emitters` every camera
    // ray meets an emitter and counts as a miss (Mitsuba's meaning), for
    // every estimator; without it the image is not black (the tests above).
    for estimator in [
        Estimator::Paths,
        Estimator::Links,
        Estimator::Preview,
        Estimator::Control,
    ] {
        let settings = RenderSettings {
            estimator,
            hide_emitters: true,
            ..Default::default()
        };
        assert_eq!(furnace_mean_with(1.0, settings), 0.0, "{estimator:?}");
    }
}
