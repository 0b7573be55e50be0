//! The solver's own guards, for callers that bypass the scene loader:
//! emission whose flux overflows is refused when the scene is prepared,
//! and a closed scene that reflects everything is refused before a solve.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test may panic

use glam::{DMat4, DVec3};
use trilux_brdf::BsdfParams;
use trilux_color::ColorParam;
use trilux_geometry::{Shape, ShapeKind};
use trilux_solver::{
    PrepareError, PreparedScene, Quality, SceneDescription, Solver, SolverError, SolverSettings,
};

fn cube(flip: bool, scale: f64) -> Shape {
    Shape {
        kind: ShapeKind::Cube,
        world_from_object: DMat4::from_scale(DVec3::splat(scale)),
        flip_normals: flip,
    }
}

fn diffuse(rho: f64) -> BsdfParams {
    BsdfParams::Diffuse {
        reflectance: ColorParam::Float(rho),
    }
}

fn prepare(
    shapes: &[Shape],
    bsdfs: &[BsdfParams],
    le: &[Option<ColorParam>],
) -> Result<PreparedScene<3>, PrepareError> {
    PreparedScene::new(&SceneDescription {
        shapes,
        bsdfs,
        emission: le,
    })
}

#[test]
fn emission_whose_flux_overflows_is_refused() {
    for (le, scale) in [(1e308, 1e12), (1e31, 1.0), (f64::MAX, 1.0)] {
        let e = prepare(
            &[cube(true, scale)],
            &[diffuse(0.5)],
            &[Some(ColorParam::Float(le))],
        )
        .unwrap_err();
        assert!(
            matches!(e, PrepareError::FluxOverflow { shape: 0 }),
            "{le}: {e}"
        );
        assert!(e.is_emitter());
    }
    assert!(
        prepare(
            &[cube(true, 1e12)],
            &[diffuse(0.5)],
            &[Some(ColorParam::Float(1e20))]
        )
        .is_ok()
    );
}

#[test]
fn a_closed_scene_reflecting_everything_has_no_finite_solution() {
    let settings = SolverSettings::preset(Quality::Draft);
    let le = [Some(ColorParam::Float(1.0))];
    let closed = prepare(&[cube(true, 1.0)], &[diffuse(1.0)], &le).unwrap();
    match Solver::new(closed.into(), settings.clone()) {
        Err(SolverError::NoFiniteSolution {
            shape: 0,
            band: 0,
            bands: 3,
        }) => {}
        Err(e) => panic!("{e}"),
        Ok(_) => panic!("a closed furnace of reflectance 1 was accepted"),
    }
    // Reflectance 1 in green only: trapped in green (band 1).
    let green = BsdfParams::Diffuse {
        reflectance: ColorParam::Rgb([0.5, 1.0, 0.5]),
    };
    let closed = prepare(&[cube(true, 1.0)], &[green], &le).unwrap();
    assert!(matches!(
        Solver::new(closed.into(), settings.clone()),
        Err(SolverError::NoFiniteSolution { band: 1, .. })
    ));
    // Open (the cube's inside is its back: the light leaves through the
    // one-sided faces) or absorbing anywhere: accepted.
    let open = prepare(&[cube(false, 1.0)], &[diffuse(1.0)], &le).unwrap();
    assert!(Solver::new(open.into(), settings.clone()).is_ok());
    let absorbing = prepare(&[cube(true, 1.0)], &[diffuse(0.999)], &le).unwrap();
    assert!(Solver::new(absorbing.into(), settings).is_ok());
}
