//! Property tests of the renderer's building blocks (proptest).
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test, bench or example may panic

use glam::{DMat4, DVec2, DVec3};
use proptest::prelude::*;
use trilux_render::camera::look_at;
use trilux_render::{Camera, Film, FovAxis, ReconstructionFilter, power_heuristic};

fn axis() -> impl Strategy<Value = FovAxis> {
    prop_oneof![
        Just(FovAxis::X),
        Just(FovAxis::Y),
        Just(FovAxis::Smaller),
        Just(FovAxis::Larger),
        Just(FovAxis::Diagonal)
    ]
}

proptest! {
    /// Every film position gives a finite unit direction in front of the
    /// camera, for any fov, axis, film shape and orientation.
    #[test]
    fn camera_rays_are_unit_and_forward(
        fov in 0.5f64..170.0,
        a in axis(),
        w in 1u32..400,
        h in 1u32..400,
        o in prop::array::uniform3(-10.0f64..10.0),
        t in prop::array::uniform3(-10.0f64..10.0),
        s in prop::array::uniform2(0.0f64..=1.0),
    ) {
        let (o, t) = (DVec3::from_array(o), DVec3::from_array(t));
        prop_assume!((t - o).length() > 1e-3);
        let up = if (t - o).normalize().dot(DVec3::Y).abs() > 0.99 { DVec3::X } else { DVec3::Y };
        let m = look_at(o, t, up).unwrap();
        // Some (fov, axis, aspect) combinations mean a horizontal fov of
        // 180° or more: those are errors, never NaN rays.
        let Ok(cam) = Camera::new(m, fov, a, w, h) else { return Ok(()); };
        let r = cam.ray_unit(DVec2::from_array(s));
        prop_assert!(r.dir.is_finite() && (r.dir.length() - 1.0).abs() < 1e-12);
        prop_assert!(r.dir.dot((t - o).normalize()) > 0.0);
    }

    /// Any set of samples of one constant value develops to that value in
    /// every pixel it reaches, whatever the filter (per-pixel normalisation).
    #[test]
    fn film_normalisation_is_exact(
        samples in prop::collection::vec((0.0f64..8.0, 0.0f64..6.0), 1..60),
        v in 0.0f64..100.0,
        gaussian in any::<bool>(),
    ) {
        let f = if gaussian { ReconstructionFilter::default() } else { ReconstructionFilter::Box };
        let mut film = Film::new(0, 0, 8, 6, f).unwrap();
        for &(x, y) in &samples {
            film.splat(x, y, [v, 2.0 * v, 0.5]);
        }
        for p in film.develop().pixels() {
            prop_assert!(p.iter().all(|c| c.is_finite() && *c >= 0.0));
            if p != &[0.0, 0.0, 0.0] {
                prop_assert!((p[0] as f64 - v).abs() <= 1e-5 * (1.0 + v));
                prop_assert!((p[2] - 0.5).abs() <= 1e-6);
            }
        }
    }

    /// MIS weights of two strategies add to one and stay in [0, 1].
    #[test]
    fn power_heuristic_partitions_unity(a in 0.0f64..1e6, b in 0.0f64..1e6) {
        prop_assume!(a + b > 0.0);
        let (wa, wb) = (power_heuristic(a, b), power_heuristic(b, a));
        prop_assert!((0.0..=1.0).contains(&wa) && (0.0..=1.0).contains(&wb));
        prop_assert!((wa + wb - 1.0).abs() < 1e-12);
    }
}

#[test]
fn singular_transforms_are_errors_not_nan() {
    assert!(
        Camera::new(
            DMat4::from_scale(DVec3::new(1.0, 0.0, 1.0)),
            40.0,
            FovAxis::X,
            4,
            4
        )
        .is_err()
    );
}
