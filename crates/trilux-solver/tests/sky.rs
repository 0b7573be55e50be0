//! An environment map in the solve (docs/solver.md, "The sky"), against
//! closed forms: a floor under a sky whose upper hemisphere is exactly L
//! receives E = π L and holds ρ L; the sky's flux is π R² ∫ L dω; the
//! ledger books nothing created. Only the sky shoots (a shot budget of 1).
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test, bench or example may panic

use std::f64::consts::{FRAC_PI_2, PI};
use std::sync::Arc;

use glam::{DMat3, DMat4, DVec3};
use trilux_brdf::BsdfParams;
use trilux_color::{ColorParam, Spectrum};
use trilux_geometry::{FaceId, Shape, ShapeKind, Side, SurfaceId, Transmittance};
use trilux_solver::{
    PreparedScene, PreparedSky, Quality, SceneDescription, Solution, Solver, SolverSettings,
};

const RHO: f64 = 0.5;
const L: f64 = 2.0;

/// The first bounce of a sky of 8 × 3 texels, rows 0 and 1 (the zenith
/// and the horizon, in Mitsuba's layout) at L and row 2 (the nadir) at
/// 0, turned so that its up is +z, on a 2 × 2 floor facing +z; with
/// `pane`, under a black 100 × 100 m pane 1 m up that lets that through.
fn first_bounce(pane: Option<Transmittance>) -> Solution<3> {
    let mut shapes = vec![Shape {
        kind: ShapeKind::Rectangle,
        world_from_object: DMat4::IDENTITY,
        flip_normals: false,
    }];
    let mut bsdfs = vec![BsdfParams::Diffuse {
        reflectance: ColorParam::Float(RHO),
    }];
    let mut emission = vec![None];
    if pane.is_some() {
        shapes.push(Shape {
            kind: ShapeKind::Rectangle,
            world_from_object: DMat4::from_translation(DVec3::Z)
                * DMat4::from_scale(DVec3::new(50.0, 50.0, 1.0)),
            flip_normals: false,
        });
        bsdfs.push(BsdfParams::Diffuse {
            reflectance: ColorParam::Float(0.0),
        });
        emission.push(None);
    }
    let desc = SceneDescription {
        shapes: &shapes,
        bsdfs: &bsdfs,
        emission: &emission,
    };
    let texels = (0..24)
        .map(|k| Spectrum::splat(if k < 16 { L } else { 0.0 }))
        .collect();
    let sky = PreparedSky::new(8, 3, texels, DMat3::from_rotation_x(FRAC_PI_2)).unwrap();
    let scene = PreparedScene::<3>::new(&desc)
        .unwrap()
        .with_sky(Some(sky))
        .with_transmission(&[None, pane]);
    let mut settings = SolverSettings::preset(Quality::Default);
    settings.max_shots = 1;
    settings.max_depth = 4;
    settings.min_area_fraction = 1e-12;
    let mut s = Solver::new(Arc::new(scene), settings)
        .unwrap()
        .solve(|_| {});
    s.set_ambient(false);
    s
}

#[test]
fn a_floor_under_a_sky_of_radiance_l_above_holds_rho_l() {
    let s = first_bounce(None);
    let forest = s.forest();
    let face = FaceId::new(SurfaceId(0), Side::Front);
    let leaves = forest.leaves(forest.root(SurfaceId(0)));
    assert!(leaves.len() >= 64, "{} leaves", leaves.len());
    let (mut worst, mut sum): (f64, f64) = (0.0, 0.0);
    for &leaf in &leaves {
        let got = s.face_radiance(face, leaf)[0] / (RHO * L);
        worst = worst.max((got - 1.0).abs());
        sum += got;
    }
    let mean = sum / leaves.len() as f64;
    eprintln!(
        "sky on a floor: mean {:+.3} %, worst element {:.3} %",
        100.0 * (mean - 1.0),
        100.0 * worst
    );
    // 128 importance-sampled directions a leaf: each element within 3 %,
    // their mean within 0.5 % (the set is rotated per leaf).
    assert!((mean - 1.0).abs() < 5e-3, "mean {mean}");
    assert!(worst < 0.03, "worst element off by {:.3} %", 100.0 * worst);
    // Φ = π R² ∫ L dω, R = √2 (half the floor's diagonal); ∫ L dω =
    // 2π L above and 4 L below (L falling linearly in θ to the nadir).
    let st = s.stats();
    let phi = PI * 2.0 * (2.0 * PI * L + 4.0 * L);
    assert!(
        (st.emitted_flux[0] / phi - 1.0).abs() < 1e-12,
        "{}",
        st.emitted_flux[0]
    );
    // Nothing created: what arrived (absorbed, escaped or still unshot)
    // is the flux shot.
    let total = st.absorbed_flux[0] + st.escaped_flux[0] + st.residual_flux[0];
    assert!(st.escaped_flux[0] >= 0.0 && st.absorbed_flux[0] >= 0.0);
    assert!((total / phi - 1.0).abs() < 1e-9, "{total} of {phi}");
}

#[test]
fn a_floor_under_a_pane_holds_what_the_pane_lets_through() {
    // The same floor under a pane letting half through at every angle: the
    // sky's deposits take the pane's fraction, E = π L / 2 (the pane covers
    // every direction but those within 1.2° of the horizon, under 1e-3 of
    // E), so each element holds ρ L / 2. A pane taken as opaque gives 0,
    // one ignored ρ L.
    let s = first_bounce(Some(Transmittance::Constant(0.5)));
    let forest = s.forest();
    let face = FaceId::new(SurfaceId(0), Side::Front);
    let leaves = forest.leaves(forest.root(SurfaceId(0)));
    let sum: f64 = leaves
        .iter()
        .map(|&leaf| s.face_radiance(face, leaf)[0] / (0.5 * RHO * L))
        .sum();
    let mean = sum / leaves.len() as f64;
    eprintln!(
        "sky through a pane of ½: floor mean {:+.3} %",
        100.0 * (mean - 1.0)
    );
    // 0.5 %: the unglazed floor's bound above.
    assert!((mean - 1.0).abs() < 5e-3, "mean {mean}");
}
