//! Next-event estimation to lights without area against closed forms: on
//! an open Lambertian floor (nothing else to reflect light back), a camera
//! ray looking straight down sees exactly ρ/π · I falloff cos θ / r² (ρ/π
//! · E cos θ under a directional light), with no noise: a delta light is
//! evaluated, not sampled, and the gather ray meets nothing. Checked for
//! the path gather and the control variate, with a blocker that shadows
//! one point.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test, bench or example may panic

use std::f64::consts::PI;
use std::sync::Arc;

use glam::{DMat3, DMat4, DVec3};
use trilux_brdf::BsdfParams;
use trilux_color::ColorParam;
use trilux_geometry::{Punctual, Shape, ShapeKind, SpotFalloff};
use trilux_render::control::ControlVariate;
use trilux_render::gather::FinalGather;
use trilux_render::solution::DirectOnly;
use trilux_render::{ExtraBounce, GatherStats, PixelSampler, SolvedScene};
use trilux_solver::{PreparedScene, SceneDescription};

const RHO: f64 = 0.5;

fn square(centre: DVec3, size: f64, down: bool) -> Shape {
    let rot = if down {
        DMat4::from_rotation_x(PI)
    } else {
        DMat4::IDENTITY
    };
    Shape {
        kind: ShapeKind::Rectangle,
        world_from_object: DMat4::from_translation(centre)
            * rot
            * DMat4::from_scale(DVec3::splat(0.5 * size)),
        flip_normals: false,
    }
}

/// A 4 × 4 floor of reflectance ρ at z = 0 and a small black blocker
/// over (1, 0, 0) on the way to a light at (0, 0, 1), lit by `light`.
fn scene(light: Punctual, i: f64) -> Arc<PreparedScene<3>> {
    let shapes = vec![
        square(DVec3::ZERO, 4.0, false),
        square(DVec3::new(0.5, 0.0, 0.5), 0.1, true),
    ];
    let bsdfs = vec![
        BsdfParams::Diffuse {
            reflectance: ColorParam::Float(RHO),
        },
        BsdfParams::Diffuse {
            reflectance: ColorParam::Float(0.0),
        },
    ];
    let desc = SceneDescription {
        shapes: &shapes,
        bsdfs: &bsdfs,
        emission: &[None, None],
    };
    let s = PreparedScene::new(&desc)
        .unwrap()
        .with_lights(&[(light, ColorParam::Float(i))])
        .unwrap();
    Arc::new(s)
}

/// The radiance the path gather and the control variate see at floor
/// point `x` from straight above.
fn seen(scene: &Arc<PreparedScene<3>>, x: DVec3) -> [f64; 2] {
    let solution = DirectOnly::new(Arc::clone(scene));
    let solved = SolvedScene::new(&solution);
    let mut stats = GatherStats::default();
    let sampler = PixelSampler::new(0, 0, 0);
    let (origin, dir) = (x + DVec3::new(0.0, 0.0, 3.0), -DVec3::Z);
    let paths = FinalGather {
        scene: &solved,
        extra: ExtraBounce::Always,
        hide_emitters: false,
    }
    .camera_sample::<3>(origin, dir, &sampler, &mut stats);
    let control = ControlVariate {
        scene: &solved,
        lookups: 4,
        max_depth: None,
        hide_emitters: false,
    }
    .camera_sample::<3>(origin, dir, &sampler, &mut stats);
    [paths[0], control[0]]
}

fn assert_close(got: [f64; 2], want: f64, what: &str) {
    for g in got {
        assert!(
            (g - want).abs() <= 1e-12 * want.max(1e-300),
            "{what}: {g} against {want}"
        );
    }
}

#[test]
fn a_point_light_gives_i_cos_over_r2() {
    let (p, i) = (DVec3::new(0.0, 0.0, 1.0), 3.0);
    let s = scene(Punctual::Point { position: p }, i);
    for x in [DVec3::new(0.0, 0.7, 0.0), DVec3::new(-1.2, 0.4, 0.0)] {
        let d = p - x;
        let want = RHO / PI * i * (d.z / d.length()) / d.length_squared();
        assert_close(seen(&s, x), want, "point");
    }
    // In the blocker's shadow.
    assert_close(seen(&s, DVec3::new(1.0, 0.0, 0.0)), 0.0, "shadowed");
}

/// A spot aimed straight down (cutoff 40°, beam 20°): at 30° off the axis
/// its falloff is (40 − 30)/(40 − 20) = ½.
#[test]
fn a_spot_falls_off_as_mitsubas() {
    let (p, i) = (DVec3::new(0.0, 0.0, 1.0), 2.0);
    let light = Punctual::Spot {
        position: p,
        light_from_world: DMat3::from_diagonal(DVec3::new(1.0, -1.0, -1.0)),
        falloff: SpotFalloff::Mitsuba {
            cutoff_angle: 40f64.to_radians(),
            beam_width: 20f64.to_radians(),
        },
    };
    let s = scene(light, i);
    let t = 30f64.to_radians();
    let x = DVec3::new(0.0, t.tan(), 0.0);
    let want = RHO / PI * i * 0.5 * t.cos().powi(3);
    assert_close(seen(&s, x), want, "spot at 30°");
    // Beyond the cutoff.
    assert_close(seen(&s, DVec3::new(0.0, 1.5, 0.0)), 0.0, "outside the cone");
}

/// The sun at 60° from the zenith: ρ/π · E cos 60° everywhere it is not
/// blocked.
#[test]
fn a_directional_light_gives_e_cos() {
    let e = 1.5;
    let t = 60f64.to_radians();
    let d = DVec3::new(0.0, t.sin(), -t.cos());
    let s = scene(Punctual::Directional { direction: d }, e);
    assert_close(
        seen(&s, DVec3::new(-1.0, 0.3, 0.0)),
        RHO / PI * e * t.cos(),
        "sun",
    );
}

/// The directional bake's estimator (`LinkGather::glossy_directions`)
/// takes a point light's glossy reflection too: on an open glossy floor
/// (no area light, nothing for a gather ray to meet) it is exactly, in
/// every outgoing direction, the light's one term glossy_cos · I / r² —
/// the same term `punctual_direct` adds for a single direction.
#[test]
fn the_bakes_glossy_estimate_reflects_a_point_light_in_every_direction() {
    use trilux_brdf::{Distribution, RoughConductorParams};
    use trilux_render::link_gather::{Caches, IncidentSamples, LinkGather};
    use trilux_render::{GatherScene, SolutionGather};
    let (p, i) = (DVec3::new(0.3, -0.2, 1.0), 2.0);
    let shapes = vec![square(DVec3::ZERO, 4.0, false)];
    let bsdfs = vec![BsdfParams::RoughConductor(RoughConductorParams {
        distribution: Distribution::Ggx,
        alpha: 0.3,
        eta_k: None,
        specular_reflectance: ColorParam::Float(0.8),
    })];
    let desc = SceneDescription {
        shapes: &shapes,
        bsdfs: &bsdfs,
        emission: &[None],
    };
    let scene = Arc::new(
        PreparedScene::<3>::new(&desc)
            .unwrap()
            .with_lights(&[(Punctual::Point { position: p }, ColorParam::Float(i))])
            .unwrap(),
    );
    let solution = DirectOnly::new(Arc::clone(&scene));
    let solved = SolvedScene::new(&solution);
    let gather = LinkGather {
        scene: &solved,
        fallback: FinalGather {
            scene: &solved,
            extra: ExtraBounce::Never,
            hide_emitters: false,
        },
        glossy_scene: true,
    };
    let x = solved
        .intersect(DVec3::new(-0.2, 0.1, 2.0), -DVec3::Z)
        .unwrap();
    let wos: Vec<DVec3> = [(0.0, 0.0), (0.5, 0.2), (-0.6, 0.3), (0.1, -0.8)]
        .iter()
        .map(|&(a, b): &(f64, f64)| DVec3::new(a, b, (1.0 - a * a - b * b).sqrt()))
        .collect();
    let counts = IncidentSamples {
        gather: 4,
        light: 4,
        links: false,
    };
    let mut sampler = PixelSampler::new(0, 0, 0);
    let (mut caches, mut stats) = (Caches::<3>::default(), GatherStats::default());
    let got = gather.glossy_directions(&x, &wos, counts, &mut sampler, &mut caches, &mut stats);
    let d = p - x.point;
    let wi = d.normalize();
    let mut brightest = 0.0f64;
    for (wo, g) in wos.iter().zip(&got) {
        let want = solved.glossy_cos(&x, wi, *wo).0[0] * i / d.length_squared();
        brightest = brightest.max(want);
        assert!(
            (g.0[0] - want).abs() <= 1e-12 * want.max(1e-300),
            "towards {wo}: {} against {want}",
            g.0[0]
        );
    }
    assert!(
        brightest > 0.01,
        "the lobe must face some direction: {brightest}"
    );
}
