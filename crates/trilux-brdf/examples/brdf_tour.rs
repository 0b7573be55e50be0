//! Evaluate, sample and integrate a material; one area reflectance.
//!
//! Run: `cargo run -p trilux-brdf --example brdf_tour`
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test, bench or example may panic

use glam::{DVec2, DVec3};
use trilux_brdf::{
    Bsdf, BsdfParams, Distribution, ElementPoints, RoughConductorParams, Side, area_reflectance,
    brdf_variation,
};
use trilux_color::ColorParam;

fn main() -> Result<(), trilux_brdf::BrdfError> {
    // 30% rough gold over 70% white paint, both sides.
    let params = BsdfParams::TwoSided {
        front: Box::new(BsdfParams::Blend {
            weight: 0.3,
            first: Box::new(BsdfParams::Diffuse {
                reflectance: ColorParam::Float(0.7),
            }),
            second: Box::new(BsdfParams::RoughConductor(RoughConductorParams {
                distribution: Distribution::Ggx,
                alpha: 0.2,
                eta_k: Some((
                    ColorParam::Rgb([0.143, 0.374, 1.442]),
                    ColorParam::Rgb([3.983, 2.385, 1.603]),
                )),
                specular_reflectance: ColorParam::Float(1.0),
            })),
        }),
        back: None,
    };
    let bsdf: Bsdf<3> = Bsdf::new(&params)?;

    // Local frame: z is the normal; wi towards the light, wo towards the viewer.
    let wo = DVec3::new(0.5, 0.0, 0.866);
    let mirror = DVec3::new(-0.5, 0.0, 0.866);
    println!("fr(mirror, wo)        = {:?}", bsdf.eval(mirror, wo).0);
    println!(
        "glossy part           = {:?}",
        bsdf.eval_glossy(mirror, wo).0
    );
    println!(
        "Lambertian fr_d       = {:?}",
        bsdf.diffuse_reflectance(Side::Front).0
    );
    println!("directional albedo    = {:?}", bsdf.albedo(wo).0);
    if let Some(s) = bsdf.sample(wo, DVec2::new(0.8, 0.3)) {
        println!(
            "sample: wi {:?} pdf {:.4} weight {:?}",
            s.wi, s.pdf, s.weight.0
        );
    }

    // Area reflectance of light from element I reflecting on J towards K.
    let (i, j, k) = (
        DVec3::new(-1.0, 0.0, 1.0),
        DVec3::ZERO,
        DVec3::new(1.0, 0.0, 1.0),
    );
    let r = area_reflectance(&bsdf, 0.05, i, j, DVec3::Z, k);
    println!(
        "R(I→J→K): diffuse {:?} glossy {:?}",
        r.diffuse.0, r.glossy.0
    );
    let pts = |c: DVec3| {
        [
            c + DVec3::X * 0.1,
            c - DVec3::X * 0.1,
            c + DVec3::Y * 0.1,
            c - DVec3::Y * 0.1,
        ]
    };
    let (pi, pj, pk) = (pts(i), pts(j), pts(k));
    let v = brdf_variation(
        &bsdf,
        &ElementPoints {
            centre: i,
            normal: DVec3::new(1.0, 0.0, -1.0).normalize(),
            points: &pi,
        },
        &ElementPoints {
            centre: j,
            normal: DVec3::Z,
            points: &pj,
        },
        &ElementPoints {
            centre: k,
            normal: DVec3::new(-1.0, 0.0, -1.0).normalize(),
            points: &pk,
        },
    );
    println!(
        "variation: ΔR = {:.4} (F_JI = 0.05), split {:?}, mirror in K: {}",
        v.delta_r(0.05),
        v.driver(),
        v.mirror_in_k
    );
    Ok(())
}
