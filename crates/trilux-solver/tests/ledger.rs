//! The energy ledger on random scenes (docs/solver.md, "Energy ledger"): emitted = absorbed +
//! escaped + residual, no shot and no receiving element creates energy, the
//! residual never grows from one shot to the next, and no radiance is
//! negative or not finite.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test, bench or example may panic

use std::f64::consts::PI;

use glam::{DMat4, DVec3};
use proptest::prelude::*;
use trilux_brdf::{BsdfParams, Distribution, RoughConductorParams};
use trilux_color::ColorParam;
use trilux_geometry::{Shape, ShapeKind};
use trilux_solver::{Quality, SceneDescription, Solution, Solver, SolverSettings, Transport};

fn material() -> impl Strategy<Value = BsdfParams> {
    let diffuse = (0.0..0.95f64).prop_map(|r| BsdfParams::Diffuse {
        reflectance: ColorParam::Float(r),
    });
    // α log-uniform from 1e-4 (near mirrors, sampled lobes) to 1.
    let conductor =
        (-4.0..0.0f64, any::<bool>(), 0.3..1.0f64).prop_map(|(log_alpha, ggx, spec)| {
            let alpha = 10f64.powf(log_alpha);
            BsdfParams::RoughConductor(RoughConductorParams {
                distribution: if ggx {
                    Distribution::Ggx
                } else {
                    Distribution::Beckmann
                },
                alpha,
                eta_k: None,
                specular_reflectance: ColorParam::Float(spec),
            })
        });
    prop_oneof![
        diffuse.clone(),
        conductor.clone(),
        (0.0..1.0f64, diffuse, conductor).prop_map(|(w, a, b)| BsdfParams::Blend {
            weight: w,
            first: Box::new(a),
            second: Box::new(b),
        }),
    ]
}

#[derive(Clone, Debug)]
struct Plate {
    centre: DVec3,
    angles: (f64, f64),
    size: f64,
    material: BsdfParams,
}

fn plate() -> impl Strategy<Value = Plate> {
    (
        (-0.6..0.6f64, -0.6..0.6f64, -0.6..0.4f64),
        (0.0..PI, 0.0..2.0 * PI),
        0.15..0.5f64,
        material(),
    )
        .prop_map(|((x, y, z), angles, size, material)| Plate {
            centre: DVec3::new(x, y, z),
            angles,
            size,
            material,
        })
}

fn scene(
    closed: bool,
    box_material: BsdfParams,
    plates: &[Plate],
    tube: Option<BsdfParams>,
    le: f64,
) -> (Vec<Shape>, Vec<BsdfParams>, Vec<Option<ColorParam>>) {
    let mut shapes = Vec::new();
    let mut bsdfs = Vec::new();
    let mut emission = Vec::new();
    // The light: a small square under the ceiling, facing down.
    shapes.push(Shape {
        kind: ShapeKind::Rectangle,
        world_from_object: DMat4::from_translation(DVec3::new(0.0, 0.0, 0.95))
            * DMat4::from_rotation_x(PI)
            * DMat4::from_scale(DVec3::splat(0.25)),
        flip_normals: false,
    });
    bsdfs.push(BsdfParams::Diffuse {
        reflectance: ColorParam::Float(0.3),
    });
    emission.push(Some(ColorParam::Float(le)));
    if closed {
        shapes.push(Shape {
            kind: ShapeKind::Cube,
            world_from_object: DMat4::IDENTITY,
            flip_normals: true,
        });
        bsdfs.push(box_material);
        emission.push(None);
    }
    // An open tube seen from inside (flipped normals): a concave surface
    // whose pieces light themselves (secondary interactions, glossy or
    // not).
    if let Some(material) = tube {
        shapes.push(Shape {
            kind: ShapeKind::Cylinder {
                p0: DVec3::new(-0.2, 0.0, -0.5),
                p1: DVec3::new(0.2, 0.1, 0.3),
                radius: 0.35,
            },
            world_from_object: DMat4::IDENTITY,
            flip_normals: true,
        });
        bsdfs.push(material);
        emission.push(None);
    }
    for p in plates {
        shapes.push(Shape {
            kind: ShapeKind::Rectangle,
            world_from_object: DMat4::from_translation(p.centre)
                * DMat4::from_rotation_z(p.angles.1)
                * DMat4::from_rotation_x(p.angles.0)
                * DMat4::from_scale(DVec3::splat(p.size)),
            flip_normals: false,
        });
        bsdfs.push(p.material.clone());
        emission.push(None);
    }
    (shapes, bsdfs, emission)
}

/// The ledger's checks on a solution.
fn check_ledger(solution: &Solution<3>) -> Result<(), TestCaseError> {
    let stats = solution.stats();
    for b in 0..3 {
        let e = stats.emitted_flux[b];
        let sum = stats.absorbed_flux[b] + stats.escaped_flux[b] + stats.residual_flux[b];
        prop_assert!(
            (e - sum).abs() <= 1e-6 * e,
            "band {}: emitted {} vs {}",
            b,
            e,
            sum
        );
        prop_assert!(stats.escaped_flux[b] >= -1e-9 * e);
        prop_assert!(stats.absorbed_flux[b] >= -1e-9 * e);
    }
    prop_assert!(
        stats.min_shot_escaped >= -1e-9,
        "a shot created energy: {}",
        stats.min_shot_escaped
    );
    prop_assert!(
        stats.min_element_absorbed >= -1e-9,
        "an element created energy: {}",
        stats.min_element_absorbed
    );
    let min = solution.min_radiance();
    prop_assert!(min.is_finite() && min >= 0.0, "radiance minimum {}", min);
    // The remainder's account: what is still to be reflected is what the
    // residual brings back at the measured return fraction, and CR is the
    // share already reflected.
    let amb = &stats.ambient;
    let (mut reflected, mut future) = (0.0, 0.0);
    for b in 0..3 {
        let a = amb.return_fraction[b];
        prop_assert!((0.0..=1.0).contains(&a), "return fraction {}", a);
        prop_assert!(amb.reflected_flux[b] >= 0.0 && amb.radiance[b] >= 0.0);
        let expect = stats.residual_flux[b] * a / (1.0 - a).max(1e-9);
        prop_assert!((amb.future_reflected_flux[b] - expect).abs() <= 1e-9 * expect.max(1e-12));
        reflected += amb.reflected_flux[b];
        future += amb.future_reflected_flux[b];
    }
    if reflected + future > 0.0 {
        let cr = reflected / (reflected + future);
        prop_assert!(
            (stats.convergence_ratio - cr).abs() <= 1e-9,
            "CR {} vs {}",
            stats.convergence_ratio,
            cr
        );
    }
    Ok(())
}

/// A long room (a flipped cube 6 × 1 × 6) with a light under its ceiling
/// and `boxes` small cubes (position on the floor in [−1, 1]², size, height
/// above the floor, material), so that clustering finds far clusters.
fn clustered_scene(
    boxes: &[((f64, f64), f64, f64, BsdfParams)],
    room: BsdfParams,
) -> (Vec<Shape>, Vec<BsdfParams>, Vec<Option<ColorParam>>) {
    let mut shapes = vec![
        Shape {
            kind: ShapeKind::Rectangle,
            world_from_object: DMat4::from_translation(DVec3::new(0.0, 0.0, 0.95))
                * DMat4::from_rotation_x(PI)
                * DMat4::from_scale(DVec3::splat(0.2)),
            flip_normals: false,
        },
        Shape {
            kind: ShapeKind::Cube,
            world_from_object: DMat4::from_scale(DVec3::new(6.0, 6.0, 1.0)),
            flip_normals: true,
        },
    ];
    let mut bsdfs = vec![
        BsdfParams::Diffuse {
            reflectance: ColorParam::Float(0.3),
        },
        room,
    ];
    let mut emission = vec![Some(ColorParam::Float(10.0)), None];
    for ((x, y), size, lift, material) in boxes {
        shapes.push(Shape {
            kind: ShapeKind::Cube,
            world_from_object: DMat4::from_translation(DVec3::new(
                5.5 * x,
                5.5 * y,
                -1.0 + size + lift,
            )) * DMat4::from_scale(DVec3::splat(*size)),
            flip_normals: false,
        });
        bsdfs.push(material.clone());
        emission.push(None);
    }
    (shapes, bsdfs, emission)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 12, ..ProptestConfig::default() })]
    /// The ledger with clustering on, on scenes large enough to have far
    /// clusters (checked: the solve must have made far blocks), diffuse and
    /// glossy boxes mixed, some resting on the floor, some in the air.
    #[test]
    fn ledger_balances_on_clustered_scenes(
        boxes in proptest::collection::vec(
            ((-1.0..1.0f64, -1.0..1.0f64), 0.05..0.2f64, prop_oneof![Just(0.0), 0.0..0.5f64], material()),
            8..24,
        ),
        room in material(),
    ) {
        let (shapes, bsdfs, emission) = clustered_scene(&boxes, room);
        let input = SceneDescription { shapes: &shapes, bsdfs: &bsdfs, emission: &emission };
        let mut settings = SolverSettings::preset(Quality::Draft);
        settings.max_depth = 3;
        settings.max_shots = 60;
        settings.visibility_samples = 4;
        prop_assert!(settings.clustering);
        let mut last_cr = 0.0f64;
        let mut monotone = true;
        let solution = Solver::<3>::from_description(&input, settings).expect("builds").solve(|p| {
            monotone &= p.paper_convergence_ratio >= last_cr - 1e-12;
            last_cr = p.paper_convergence_ratio;
        });
        prop_assert!(monotone, "the residual grew between shots");
        prop_assert!(solution.stats().far_blocks > 0, "no far clusters: the scene does not test clustering");
        check_ledger(&solution)?;
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]
    #[test]
    fn ledger_balances_on_random_scenes(
        closed in any::<bool>(),
        box_material in material(),
        plates in proptest::collection::vec(plate(), 0..3),
        tube in proptest::option::of(material()),
        le in 0.5..20.0f64,
        uniform in any::<bool>(),
    ) {
        let (shapes, bsdfs, emission) = scene(closed, box_material, &plates, tube, le);
        let input = SceneDescription { shapes: &shapes, bsdfs: &bsdfs, emission: &emission };
        let mut settings = SolverSettings::preset(Quality::Draft);
        settings.max_depth = 3;
        settings.max_shots = 25;
        settings.visibility_samples = 4;
        settings.transport = if uniform { Transport::Uniform } else { Transport::TwoPoint };
        let mut last_cr = 0.0f64;
        let mut monotone = true;
        let solution = Solver::<3>::from_description(&input, settings).expect("builds").solve(|p| {
            monotone &= p.paper_convergence_ratio >= last_cr - 1e-12;
            last_cr = p.paper_convergence_ratio;
        });
        prop_assert!(monotone, "the residual grew between shots");
        check_ledger(&solution)?;
    }
}
