//! Lights without area in the solve (docs/solver.md, "Lights without
//! area"), against closed forms: a light's shot puts into each element of
//! a Lambertian plane ρ/π times the element's mean irradiance, I Ω / A for
//! a point light (Ω the solid angle the element subtends from the light:
//! ∫ I cos θ / r² dA = I Ω); the energy ledger books what arrives and what
//! escapes. Only the light shoots (a shot budget of 1), so the plane holds
//! exactly that first bounce.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test, bench or example may panic

use std::f64::consts::PI;
use std::sync::Arc;

use glam::{DMat3, DMat4, DVec3};
use trilux_brdf::BsdfParams;
use trilux_color::ColorParam;
use trilux_geometry::{FaceId, Punctual, Shape, ShapeKind, Side, SpotFalloff, SurfaceId};
use trilux_solver::{PreparedScene, Quality, SceneDescription, Solution, Solver, SolverSettings};

const RHO: f64 = 0.5;

/// A square floor of side `size` centred at the origin, facing up.
fn floor(size: f64) -> Shape {
    Shape {
        kind: ShapeKind::Rectangle,
        world_from_object: DMat4::from_scale(DVec3::splat(0.5 * size)),
        flip_normals: false,
    }
}

/// The first bounce of `light` (intensity `i`) on a Lambertian floor of
/// side `size` and reflectance [`RHO`].
fn first_bounce(size: f64, light: Punctual, i: f64) -> Solution<3> {
    let shapes = vec![floor(size)];
    let bsdfs = vec![BsdfParams::Diffuse {
        reflectance: ColorParam::Float(RHO),
    }];
    let emission = vec![None];
    let desc = SceneDescription {
        shapes: &shapes,
        bsdfs: &bsdfs,
        emission: &emission,
    };
    let scene = PreparedScene::<3>::new(&desc)
        .unwrap()
        .with_lights(&[(light, ColorParam::Float(i))])
        .unwrap();
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

/// Solid angle of the rectangle [x0, x1] × [y0, y1] in the plane z = 0
/// seen from height h above the origin (sum of corner terms
/// atan(x y / (h √(x² + y² + h²)))).
fn solid_angle(x: [f64; 2], y: [f64; 2], h: f64) -> f64 {
    let f = |x: f64, y: f64| (x * y / (h * (x * x + y * y + h * h).sqrt())).atan();
    f(x[1], y[1]) - f(x[0], y[1]) - f(x[1], y[0]) + f(x[0], y[0])
}

/// Every element of the floor holds ρ/π × I Ω / A to 0.5 % (16 midpoint
/// points per element integrate the smooth irradiance), and the ledger
/// books I Ω_floor arriving, (1 − ρ) of it absorbed, 4π I − I Ω_floor
/// escaped.
#[test]
fn point_light_irradiance_on_a_plane_is_i_cos_over_r2() {
    let (p, i) = (DVec3::new(0.3, -0.2, 0.8), 2.0);
    let s = first_bounce(2.0, Punctual::Point { position: p }, i);
    let forest = s.forest();
    let face = FaceId::new(SurfaceId(0), Side::Front);
    let leaves = forest.leaves(forest.root(SurfaceId(0)));
    assert!(leaves.len() >= 64, "{} leaves", leaves.len());
    let mut worst: f64 = 0.0;
    for leaf in leaves {
        let pts = forest.element_points(leaf);
        let xs = pts[..4].iter().map(|q| q.x - p.x);
        let ys = pts[..4].iter().map(|q| q.y - p.y);
        let x = [
            xs.clone().fold(f64::MAX, f64::min),
            xs.fold(f64::MIN, f64::max),
        ];
        let y = [
            ys.clone().fold(f64::MAX, f64::min),
            ys.fold(f64::MIN, f64::max),
        ];
        let area = (x[1] - x[0]) * (y[1] - y[0]);
        let want = RHO / PI * i * solid_angle(x, y, p.z) / area;
        let got = s.face_radiance(face, leaf)[0];
        worst = worst.max((got / want - 1.0).abs());
    }
    eprintln!("point light: worst element off by {:.3} %", 100.0 * worst);
    assert!(worst < 5e-3, "worst element off by {:.3} %", 100.0 * worst);
    let arrived = i * solid_angle([-1.0 - p.x, 1.0 - p.x], [-1.0 - p.y, 1.0 - p.y], p.z);
    let st = s.stats();
    assert!((st.emitted_flux[0] / (4.0 * PI * i) - 1.0).abs() < 1e-12);
    let absorbed = st.absorbed_flux[0] / ((1.0 - RHO) * arrived) - 1.0;
    assert!(absorbed.abs() < 2e-3, "absorbed off by {absorbed:e}");
    let escaped = st.escaped_flux[0] / (4.0 * PI * i - arrived) - 1.0;
    assert!(escaped.abs() < 2e-3, "escaped off by {escaped:e}");
}

/// A Mitsuba spot (cutoff c, beam b) aimed straight down at a floor that
/// catches its whole cone: all its flux I · 2π[(1 − cos b) + ((c − b) cos b
/// + sin b − sin c)/(c − b)] arrives (∫ falloff dω in closed form).
#[test]
fn a_spots_whole_cone_arrives() {
    let (c, b, i) = (30f64.to_radians(), 15f64.to_radians(), 3.0);
    let light = Punctual::Spot {
        position: DVec3::new(0.0, 0.0, 1.0),
        // Its +z axis pointing down.
        light_from_world: DMat3::from_diagonal(DVec3::new(1.0, -1.0, -1.0)),
        falloff: SpotFalloff::Mitsuba {
            cutoff_angle: c,
            beam_width: b,
        },
    };
    let s = first_bounce(4.0, light, i);
    let omega = 2.0 * PI * ((1.0 - b.cos()) + ((c - b) * b.cos() + b.sin() - c.sin()) / (c - b));
    let st = s.stats();
    assert!((st.emitted_flux[0] / (i * omega) - 1.0).abs() < 1e-5);
    let absorbed = st.absorbed_flux[0] / ((1.0 - RHO) * i * omega) - 1.0;
    eprintln!("spot: absorbed off by {:.3} %", 100.0 * absorbed);
    assert!(absorbed.abs() < 1e-2, "absorbed off by {absorbed:e}");
}

/// A directional light of irradiance E at 60° from the normal of a 2 × 2
/// floor: E cos 60° · 4 arrives; its flux is E π R² over the scene's
/// bounding sphere (R = √2, the floor's half diagonal), as Mitsuba counts
/// a directional emitter's power.
#[test]
fn a_directional_light_brings_e_cos_theta() {
    let e = 1.5;
    let d = DVec3::new(60f64.to_radians().sin(), 0.0, -(60f64.to_radians().cos()));
    let s = first_bounce(2.0, Punctual::Directional { direction: d }, e);
    let st = s.stats();
    assert!((st.emitted_flux[0] / (e * PI * 2.0) - 1.0).abs() < 1e-12);
    let arrived = e * 0.5 * 4.0;
    let absorbed = st.absorbed_flux[0] / ((1.0 - RHO) * arrived) - 1.0;
    assert!(absorbed.abs() < 1e-9, "absorbed off by {absorbed:e}");
    let face = FaceId::new(SurfaceId(0), Side::Front);
    let mean = s.surface_mean_radiance(face)[0];
    assert!((mean / (RHO / PI * e * 0.5) - 1.0).abs() < 1e-9, "{mean}");
}

/// A light's intensity must be finite and non-negative in every band.
#[test]
fn a_negative_intensity_is_refused() {
    let shapes = vec![floor(1.0)];
    let bsdfs = vec![BsdfParams::default()];
    let desc = SceneDescription {
        shapes: &shapes,
        bsdfs: &bsdfs,
        emission: &[None],
    };
    let light = Punctual::Point { position: DVec3::Z };
    let e = PreparedScene::<3>::new(&desc)
        .unwrap()
        .with_lights(&[(light, ColorParam::Rgb([1.0, -1.0, 1.0]))])
        .unwrap_err();
    assert_eq!(e.index, 0);
    assert!(e.problem.contains("negative"), "{e}");
}

mod common;

/// The ledger closes on whole solves of the bundled light scenes
/// (`scenes/lights/`, point, spot, sun and a glossy floor): emitted =
/// absorbed + escaped + residual per band, no shot creates energy and no
/// element reflects more than arrived; the lights' flux is the emitted
/// flux (none of these scenes has an area emitter).
#[test]
fn the_ledger_closes_with_lights() {
    for name in ["point-box", "spot-box", "sun-room", "point-glossy"] {
        let path = format!(
            "{}/../../scenes/lights/{name}.xml",
            env!("CARGO_MANIFEST_DIR")
        );
        let scene = common::prepare::<3>(&path);
        assert_eq!(scene.lights().len(), 1);
        let radius = trilux_solver::lights::scene_radius(scene.geometry());
        let flux = scene.lights()[0].flux(radius);
        let mut settings = SolverSettings::preset(Quality::Draft);
        settings.max_shots = 200;
        let s = Solver::new(scene, settings).unwrap().solve(|_| {});
        let st = s.stats();
        for b in 0..3 {
            let e = st.emitted_flux[b];
            assert!((e / flux[b] - 1.0).abs() < 1e-12, "{name}");
            let sum = st.absorbed_flux[b] + st.escaped_flux[b] + st.residual_flux[b];
            assert!(
                (sum / e - 1.0).abs() < 1e-9,
                "{name} band {b}: {sum} of {e}"
            );
        }
        assert!(
            st.min_shot_escaped >= -1e-9,
            "{name}: {}",
            st.min_shot_escaped
        );
        assert!(
            st.min_element_absorbed >= -1e-9,
            "{name}: {}",
            st.min_element_absorbed
        );
    }
}
