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
use trilux_geometry::{FaceId, Shape, ShapeKind, Side, SurfaceId};
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
        // The residual's emitted part E is reflected first at a₀, then
        // returns as reflected light does; the rest returns a of itself.
        let e = amb.unshot_emission_flux[b].clamp(0.0, stats.residual_flux[b].max(0.0));
        let a0 = amb.first_reflectance[b];
        prop_assert!((0.0..=1.0).contains(&a0), "first reflectance {}", a0);
        let expect = ((stats.residual_flux[b] - e) * a + e * a0) / (1.0 - a).max(1e-9);
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

/// Deferred glossy reception (docs/solver.md, "Deferred glossy
/// reception") sums the glossy shares of small links per pair before
/// refining them, which is exact by linearity except where the sums are
/// then refined differently (more finely: each carries more flux). So on
/// a room of glossy and diffuse boxes solved to CR 0.999 both ways, the
/// ledger closes both ways, the light absorbed agrees within 0.2 % (twice
/// the residual), every face's mean Lambertian radiance within 1 %
/// (measured 0.06 %) and the glossy light below.
#[test]
fn deferred_glossy_light_is_the_same_light() {
    let glossy = |alpha: f64| {
        BsdfParams::RoughConductor(RoughConductorParams {
            distribution: Distribution::Ggx,
            alpha,
            eta_k: None,
            specular_reflectance: ColorParam::Float(0.8),
        })
    };
    let boxes: Vec<_> = (0..12)
        .map(|k| {
            let (x, y) = (
                -0.8 + 0.3 * f64::from(k % 6),
                if k < 6 { -0.4 } else { 0.4 },
            );
            let material = if k % 2 == 0 {
                glossy(0.1 + 0.05 * f64::from(k))
            } else {
                BsdfParams::Diffuse {
                    reflectance: ColorParam::Float(0.6),
                }
            };
            ((x, y), 0.12, 0.0, material)
        })
        .collect();
    let room = BsdfParams::Diffuse {
        reflectance: ColorParam::Float(0.7),
    };
    let (shapes, bsdfs, emission) = clustered_scene(&boxes, room);
    let input = SceneDescription {
        shapes: &shapes,
        bsdfs: &bsdfs,
        emission: &emission,
    };
    let solve = |defer: bool| {
        let mut settings = SolverSettings::preset(Quality::Draft);
        settings.convergence = 0.999;
        settings.defer_glossy = defer;
        Solver::<3>::from_description(&input, settings)
            .expect("builds")
            .solve(|_| {})
    };
    let (on, off) = (solve(true), solve(false));
    assert!(on.stats().deferred_links > 0 && on.stats().deferred_releases > 0);
    assert_eq!(off.stats().deferred_links, 0);
    for s in [&on, &off] {
        check_ledger(s).expect("the ledger closes");
    }
    let absorbed = |s: &Solution<3>| s.stats().absorbed_flux.iter().sum::<f64>();
    let rel = absorbed(&on) / absorbed(&off) - 1.0;
    assert!(rel.abs() < 2e-3, "absorbed flux differs by {rel}");
    let geometry = on.forest().geometry();
    let mut worst = 0.0f64;
    for k in 0..geometry.surfaces().len() {
        let face = FaceId::new(SurfaceId(k as u32), Side::Front);
        let (a, b) = (
            on.surface_mean_radiance(face).sum(),
            off.surface_mean_radiance(face).sum(),
        );
        if b > 0.0 {
            worst = worst.max((a / b - 1.0).abs());
        }
        assert!(
            (a - b).abs() <= 1e-2 * b,
            "surface {k}: {a} deferred against {b}"
        );
    }
    // The glossy light each glossy face sends to the others (the light
    // that waited, after the last release), within 2 %: a released sum is
    // refined as one link carrying more flux than each of its parts, so
    // it may be refined more finely (measured 0.5 %; losing half of the
    // released light moves it by 44 %).
    let faces: Vec<_> = (0..geometry.surfaces().len() as u32)
        .map(|k| FaceId::new(SurfaceId(k), Side::Front))
        .collect();
    let sent = |s: &Solution<3>, f| {
        faces
            .iter()
            .filter_map(|&k| s.interaction_flux(f, k))
            .map(|x| x.sum())
            .sum::<f64>()
    };
    let mut worst_glossy = 0.0f64;
    for &f in &faces {
        let (a, b) = (sent(&on, f), sent(&off, f));
        if b > 0.0 {
            worst_glossy = worst_glossy.max((a / b - 1.0).abs());
        }
    }
    assert!(
        worst_glossy < 2e-2,
        "glossy light differs by {worst_glossy}"
    );
    eprintln!(
        "deferred: {} links, {} releases; absorbed {rel:+.2e}; worst face {worst:.2e}, \
         glossy {worst_glossy:.2e}",
        on.stats().deferred_links,
        on.stats().deferred_releases
    );
}
