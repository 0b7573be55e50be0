//! The furnace (docs/validation.md, "Whole-system checks"): inside a closed box
//! whose every face is Lambertian with ρ = 0.5 and emits Le = 1, the radiance
//! is Le / (1 − ρ) everywhere (2 for Le = 1), for any discretisation, because every
//! element's form factors sum to 1.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test, bench or example may panic

use glam::{DMat4, DVec2};
use trilux_brdf::BsdfParams;
use trilux_color::ColorParam;
use trilux_geometry::{Shape, ShapeKind, Side, SurfaceCoord, SurfaceId};
use trilux_solver::{
    Quality, SceneDescription, Solution, Solver, SolverSettings, SurfaceSite, Transport,
};

fn furnace_input() -> (Vec<Shape>, Vec<BsdfParams>, Vec<Option<ColorParam>>) {
    let shapes = vec![Shape {
        kind: ShapeKind::Cube,
        world_from_object: DMat4::IDENTITY,
        flip_normals: true,
    }];
    let bsdfs = vec![BsdfParams::Diffuse {
        reflectance: ColorParam::Float(0.5),
    }];
    let emission = vec![Some(ColorParam::Float(1.0))];
    (shapes, bsdfs, emission)
}

fn solve<const N: usize>(transport: Transport) -> Solution<N> {
    let (shapes, bsdfs, emission) = furnace_input();
    let input = SceneDescription {
        shapes: &shapes,
        bsdfs: &bsdfs,
        emission: &emission,
    };
    let mut settings = SolverSettings::preset(Quality::Default);
    settings.convergence = 0.999;
    settings.max_depth = 3;
    settings.transport = transport;
    Solver::<N>::from_description(&input, settings)
        .expect("furnace builds")
        .solve(|_| {})
}

/// Every face, on a 7×7 grid of points, towards the centre of the opposite
/// face: reflected radiance + Le must be 2 within 0.5%.
fn check<const N: usize>(solution: &Solution<N>) {
    // Le and ρ per band as this mode converts them (in spectral mode a
    // `<float>` emitter is the smooth RGB spectrum times D65, not flat).
    let le = ColorParam::Float(1.0).emission::<N>().expect("emission");
    let rho = ColorParam::Float(0.5)
        .reflectance::<N>()
        .expect("reflectance");
    let stats = solution.stats();
    assert!(
        stats.convergence_ratio >= 0.999,
        "CR {}",
        stats.convergence_ratio
    );
    let faces = solution.forest().geometry().surfaces().len();
    assert_eq!(faces, 6);
    let mut worst: f64 = 0.0;
    for f in 0..faces as u32 {
        // The opposite face of a cube: pairs (0,1), (2,3), (4,5) in some
        // order; use any other face, the Lambertian answer is the same.
        let other = (f + 1) % faces as u32;
        for a in 0..7 {
            for b in 0..7 {
                let uv = DVec2::new((a as f64 + 0.5) / 7.0, (b as f64 + 0.5) / 7.0);
                let from = SurfaceSite::new(SurfaceId(f), Side::Front, SurfaceCoord::Uv(uv));
                let to = SurfaceSite::new(
                    SurfaceId(other),
                    Side::Front,
                    SurfaceCoord::Uv(DVec2::splat(0.5)),
                );
                let l = solution.radiance(&from, &to);
                for band in 0..N {
                    let expected = le[band] / (1.0 - rho[band]);
                    let total = l[band] + le[band];
                    worst = worst.max((total - expected).abs() / expected);
                }
            }
        }
    }
    eprintln!(
        "furnace N={N}: worst relative error {worst:.5}, escaped {:.5} of emitted, CR {:.5}, shots {}",
        stats.escaped_flux[0] / stats.emitted_flux[0],
        stats.convergence_ratio,
        stats.shots
    );
    assert!(worst <= 0.005, "worst relative error {worst}");
    // The ledger: emitted = absorbed + escaped + residual, escaped small.
    for band in 0..N {
        let e = stats.emitted_flux[band];
        let sum = stats.absorbed_flux[band] + stats.escaped_flux[band] + stats.residual_flux[band];
        assert!((e - sum).abs() <= 1e-6 * e, "band {band}: {e} vs {sum}");
        assert!(stats.escaped_flux[band] >= -1e-9 * e);
        assert!(
            stats.escaped_flux[band] <= 0.005 * e,
            "escaped {} of {e}",
            stats.escaped_flux[band]
        );
    }
}

#[test]
fn furnace_rgb_two_point() {
    check(&solve::<3>(Transport::TwoPoint));
}

#[test]
fn furnace_spectral_two_point() {
    check(&solve::<10>(Transport::TwoPoint));
}

#[test]
fn furnace_rgb_uniform() {
    check(&solve::<3>(Transport::Uniform));
}
