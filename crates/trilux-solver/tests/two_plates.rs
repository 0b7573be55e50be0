//! Single-bounce checks between plates (docs/validation.md, "Whole-system
//! checks"): only the emitter shoots (a shot budget of 1), so what the
//! receivers hold is exactly the first bounce.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test, bench or example may panic

use std::f64::consts::PI;

use glam::{DMat4, DVec2, DVec3};
use trilux_brdf::{Bsdf, BsdfParams, Distribution, Frame, RoughConductorParams};
use trilux_color::{ColorParam, Spectrum};
use trilux_geometry::{FaceId, Shape, ShapeKind, Side, SurfaceCoord, SurfaceId};
use trilux_solver::{Quality, SceneDescription, Solver, SolverSettings, SurfaceSite};

/// A unit square centred at `centre`, facing down (−z) or up (+z).
fn square(centre: DVec3, down: bool) -> Shape {
    let rot = if down {
        DMat4::from_rotation_x(PI)
    } else {
        DMat4::IDENTITY
    };
    Shape {
        kind: ShapeKind::Rectangle,
        world_from_object: DMat4::from_translation(centre)
            * rot
            * DMat4::from_scale(DVec3::splat(0.5)),
        flip_normals: false,
    }
}

fn black() -> BsdfParams {
    BsdfParams::Diffuse {
        reflectance: ColorParam::Float(0.0),
    }
}

fn one_bounce_settings() -> SolverSettings {
    let mut s = SolverSettings::preset(Quality::High);
    s.max_shots = 1;
    s.max_depth = 5;
    s
}

/// Closed form (a) of docs/validation.md: parallel, directly opposed unit
/// squares at distance 1 have F = 0.199825. The receiver's mean radiance
/// after one bounce is ρ Le F; at its centre the point form factor (c) is
/// 0.239456 and the solution may differ by at most its refinement bound
/// ρ Le FFErr (the oracle stops when the point form factor varies less than
/// FFErr over an element).
#[test]
fn diffuse_receiver_one_bounce() {
    let shapes = vec![
        square(DVec3::new(0.0, 0.0, 1.0), true),
        square(DVec3::ZERO, false),
    ];
    let bsdfs = vec![
        black(),
        BsdfParams::Diffuse {
            reflectance: ColorParam::Float(0.5),
        },
    ];
    let emission = vec![Some(ColorParam::Float(1.0)), None];
    let input = SceneDescription {
        shapes: &shapes,
        bsdfs: &bsdfs,
        emission: &emission,
    };
    let settings = one_bounce_settings();
    let ff_eps = settings.ff_eps;
    let mut solution = Solver::<3>::from_description(&input, settings)
        .expect("builds")
        .solve(|_| {});
    // One bounce as shot, without the estimate of the bounces to come.
    solution.set_ambient(false);
    let rho_le = 0.5;
    // Area-weighted mean over a fine grid of the receiver (uv is uniform in
    // area on a rectangle).
    let g = 64;
    let mut sum = 0.0;
    for a in 0..g {
        for b in 0..g {
            let uv = DVec2::new((a as f64 + 0.5) / g as f64, (b as f64 + 0.5) / g as f64);
            let site = SurfaceSite::new(SurfaceId(1), Side::Front, SurfaceCoord::Uv(uv));
            sum += solution.lambertian_radiance(&site)[1];
        }
    }
    let mean = sum / (g * g) as f64;
    let expected = rho_le * 0.199825;
    eprintln!("diffuse plate: mean {mean:.6} vs closed form {expected:.6}");
    assert!(
        (mean - expected).abs() <= 0.01 * expected,
        "mean {mean} vs {expected}"
    );
    let centre = SurfaceSite::new(
        SurfaceId(1),
        Side::Front,
        SurfaceCoord::Uv(DVec2::splat(0.5)),
    );
    let l = solution.lambertian_radiance(&centre)[1];
    let expected = rho_le * 0.239456;
    assert!(
        (l - expected).abs() <= rho_le * ff_eps,
        "centre {l} vs {expected}"
    );
}

/// A tiny deterministic generator for the reference integral.
struct XorShift(u64);
impl XorShift {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// A glossy receiver R between an emitter E and a third plate K placed in
/// the mirror direction: the flux R sends towards K after one bounce must
/// match a brute-force Monte Carlo estimate of the 6-D integral
/// Φ = ∫_E ∫_R ∫_K Le fr(e→r→k) G(e, r) G(r, k) within 1%.
#[test]
fn glossy_receiver_one_bounce() {
    let e_centre = DVec3::new(-1.0, 0.0, 1.0);
    let k_centre = DVec3::new(1.0, 0.0, 1.0);
    let shapes = vec![
        square(e_centre, true),
        square(DVec3::ZERO, false),
        square(k_centre, true),
    ];
    let glossy = BsdfParams::RoughConductor(RoughConductorParams {
        distribution: Distribution::Ggx,
        alpha: 0.3,
        eta_k: None,
        specular_reflectance: ColorParam::Float(1.0),
    });
    let bsdfs = vec![
        black(),
        glossy.clone(),
        BsdfParams::Diffuse {
            reflectance: ColorParam::Float(0.5),
        },
    ];
    let emission = vec![Some(ColorParam::Float(1.0)), None, None];
    let input = SceneDescription {
        shapes: &shapes,
        bsdfs: &bsdfs,
        emission: &emission,
    };
    let mut settings = one_bounce_settings();
    settings.fr_eps = 0.05;
    settings.max_depth = 4;
    let solution = Solver::<3>::from_description(&input, settings)
        .expect("builds")
        .solve(|_| {});
    let flux = solution
        .interaction_flux(
            FaceId::new(SurfaceId(1), Side::Front),
            FaceId::new(SurfaceId(2), Side::Front),
        )
        .expect("the glossy plate stores an interaction towards K");

    // Brute force.
    let bsdf = Bsdf::<3>::new(&glossy).expect("bsdf");
    let frame = Frame::from_normal(DVec3::Z);
    let mut rng = XorShift(0x9E37_79B9_7F4A_7C15);
    let samples = 2_000_000;
    let mut sum = 0.0;
    let on = |c: DVec3, rng: &mut XorShift| c + DVec3::new(rng.next() - 0.5, rng.next() - 0.5, 0.0);
    for _ in 0..samples {
        let e = on(e_centre, &mut rng);
        let r = on(DVec3::ZERO, &mut rng);
        let k = on(k_centre, &mut rng);
        let (de, dk) = (e - r, k - r);
        let (le2, lk2) = (de.length_squared(), dk.length_squared());
        let (we, wk) = (de / le2.sqrt(), dk / lk2.sqrt());
        // Cosines: at R with +z, at E and K with −z.
        let g_er = we.z * we.z / le2;
        let g_rk = wk.z * wk.z / lk2;
        let fr: Spectrum<3> = bsdf.eval(frame.to_local(we), frame.to_local(wk));
        sum += fr[0] * g_er * g_rk;
    }
    let reference = sum / samples as f64; // areas are 1, Le = 1
    let got = flux[0];
    eprintln!("glossy plate: flux towards K {got:.6} vs brute force {reference:.6}");
    assert!(
        (got - reference).abs() <= 0.01 * reference,
        "solver flux {got} vs brute force {reference}"
    );
}

/// The diffuse receiver of [`diffuse_receiver_one_bounce`] with a texture
/// that varies across it: reflectance 0.2 on one half and 0.8 on the other
/// (a 2 × 1 bitmap, nearest, clamped). The configuration is symmetric about
/// the line between the halves, so each half's mean point form factor is
/// the whole square's, F = 0.199825 (closed form (a)): after one bounce the
/// two halves' mean radiances are 0.2 Le F and 0.8 Le F, and the halves
/// across the other axis both 0.5 Le F. A solve that took the texture's
/// mean for every element would give 0.5 Le F everywhere.
#[test]
fn textured_receiver_one_bounce_resolves_the_texture() {
    use std::sync::Arc;
    use trilux_brdf::{Filter, SlotKind, Texture, TextureSlot, Wrap};
    use trilux_solver::PreparedScene;

    let shapes = vec![
        square(DVec3::new(0.0, 0.0, 1.0), true),
        square(DVec3::ZERO, false),
    ];
    let bsdfs = vec![
        black(),
        BsdfParams::Diffuse {
            reflectance: ColorParam::Float(0.5),
        },
    ];
    let emission = vec![Some(ColorParam::Float(1.0)), None];
    let input = SceneDescription {
        shapes: &shapes,
        bsdfs: &bsdfs,
        emission: &emission,
    };
    let texture = Texture::new(
        2,
        1,
        vec![[0.2; 3], [0.8; 3]],
        [Wrap::Clamp; 2],
        Filter::Nearest,
    )
    .unwrap();
    let slot = TextureSlot {
        path: vec![],
        kind: SlotKind::Reflectance,
        texture: Arc::new(texture),
        scale: [1.0; 3],
        offset: [0.0; 3],
        to_uv: trilux_brdf::UvTransform::IDENTITY,
        factor: None,
        max: 1.0,
    };
    let prepared = PreparedScene::<3>::new_textured(&input, &[vec![], vec![slot]]).unwrap();
    let mut solution = Solver::new(Arc::new(prepared), one_bounce_settings())
        .expect("builds")
        .solve(|_| {});
    solution.set_ambient(false);
    // Means over the halves u < ½, u > ½, v < ½, v > ½ of a fine grid.
    let g = 64;
    let mut halves = [0.0; 4];
    for a in 0..g {
        for b in 0..g {
            let uv = DVec2::new((a as f64 + 0.5) / g as f64, (b as f64 + 0.5) / g as f64);
            let site = SurfaceSite::new(SurfaceId(1), Side::Front, SurfaceCoord::Uv(uv));
            let l = solution.lambertian_radiance(&site)[1];
            halves[usize::from(uv.x > 0.5)] += l;
            halves[2 + usize::from(uv.y > 0.5)] += l;
        }
    }
    let halves = halves.map(|s| s / (g * g / 2) as f64);
    eprintln!(
        "textured plate: halves u {:?}, v {:?}",
        &halves[..2],
        &halves[2..]
    );
    let f = 0.199825;
    // The texture varies along one of the square's axes (which one, and in
    // which direction, is the rectangle's uv convention): that axis's
    // halves hold 0.2 F and 0.8 F, the other's 0.5 F each.
    let (across, along) = if (halves[0] - halves[1]).abs() > (halves[2] - halves[3]).abs() {
        ([halves[0], halves[1]], [halves[2], halves[3]])
    } else {
        ([halves[2], halves[3]], [halves[0], halves[1]])
    };
    let (lo, hi) = (across[0].min(across[1]), across[0].max(across[1]));
    for (got, rho) in [(lo, 0.2), (hi, 0.8), (along[0], 0.5), (along[1], 0.5)] {
        let expected = rho * f;
        assert!(
            (got - expected).abs() <= 0.01 * expected,
            "half mean {got} vs {expected} (halves {halves:?})"
        );
    }
}
