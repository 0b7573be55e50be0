//! glTF's `metallicRoughnessTexture` (glTF 2.0, "Metallic-Roughness
//! Material"): linear, metalness in the blue channel and roughness in the
//! green one, each times its factor, looked up as the base colour texture
//! is. Expected values are worked out by hand from the specification and
//! the mapping of docs/gltf.md (D = (1 − m)(1 − F)·B Lambertian,
//! S = (1 − m)·F0 + m·B on a GGX lobe of α = max(r², 0.01)), on the texels
//! that scenes/metal-rough/make_references.py writes (its docstring;
//! numpy's `round` rounds halves to even).
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test may panic

use std::path::{Path, PathBuf};

use glam::{DVec2, DVec3};
use serde_json::Value;
use trilux_brdf::{
    Bsdf, BsdfParams, Distribution, RoughConductorParams, Side, SlotKind, TexturedBsdf,
};
use trilux_color::ColorParam;

const SCENE: &str = "../../scenes/metal-rough";

fn scene_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(SCENE)
}

/// IEC 61966-2-1: an sRGB-encoded 8-bit value, decoded.
fn srgb(v: u8) -> f64 {
    let x = f64::from(v) / 255.0;
    if x <= 0.04045 {
        x / 12.92
    } else {
        ((x + 0.055) / 1.055).powf(2.4)
    }
}

/// glTF's lobes at one point: base colour `b`, metalness `m`, F0 = 0.04:
/// (D, S).
fn lobes(b: [f64; 3], m: f64) -> ([f64; 3], [f64; 3]) {
    let d = b.map(|c| (1.0 - m) * (1.0 - 0.04) * c);
    let s = b.map(|c| (1.0 - m) * 0.04 + m * c);
    (d, s)
}

/// Texels are stored as 32-bit floats: values agree within 1e-6.
///
/// fr(wi, wo) of glTF's material at a point, from its own formulas:
/// D/π + S × the GGX lobe of α (Fresnel 1).
fn expected_fr(d: [f64; 3], s: [f64; 3], alpha: f64, wi: DVec3, wo: DVec3) -> [f64; 3] {
    let unit: Bsdf<3> = Bsdf::new(&BsdfParams::RoughConductor(RoughConductorParams {
        distribution: Distribution::Ggx,
        alpha,
        eta_k: None,
        specular_reflectance: ColorParam::Float(1.0),
    }))
    .unwrap();
    let g = unit.eval(wi, wo).0[0];
    std::array::from_fn(|c| d[c] / std::f64::consts::PI + s[c] * g)
}

fn material(shape: usize) -> TexturedBsdf<3> {
    let scene = trilux_scene::open(scene_dir().join("metal-rough-box.gltf"))
        .unwrap()
        .finish()
        .unwrap();
    let s = &scene.shapes[shape];
    TexturedBsdf::new(&s.bsdf, s.textures.clone()).unwrap()
}

/// The centre of texel (column x, row y) of a 16 × 16 image.
fn texel(x: u32, y: u32) -> DVec2 {
    DVec2::new((f64::from(x) + 0.5) / 16.0, (f64::from(y) + 0.5) / 16.0)
}

fn check(t: &TexturedBsdf<3>, uv: DVec2, d: [f64; 3], s: [f64; 3], alpha: f64, what: &str) {
    let at = t.at(uv);
    let rho = at.diffuse_albedo(Side::Front).0;
    for c in 0..3 {
        assert!((rho[c] - d[c]).abs() < 1e-6, "{what}: ρ_d {rho:?}, D {d:?}");
    }
    assert!(
        (at.min_alpha(Side::Front).unwrap() - alpha).abs() < 1e-6,
        "{what}: α"
    );
    for (wi, wo) in [
        (DVec3::new(0.3, 0.1, 0.9), DVec3::new(-0.2, 0.0, 1.0)),
        (DVec3::new(0.6, -0.2, 0.5), DVec3::new(-0.5, 0.3, 0.7)),
    ] {
        let (wi, wo) = (wi.normalize(), wo.normalize());
        let got = at.eval(wi, wo).0;
        let want = expected_fr(d, s, alpha, wi, wo);
        for c in 0..3 {
            assert!(
                (got[c] - want[c]).abs() <= 1e-5 * want[c].max(1.0),
                "{what}: fr {got:?}, glTF {want:?}"
            );
        }
    }
}

/// The floor: base colour texture × metalness texture (a product of two
/// lookups), metallicFactor 0.9, roughnessFactor 1. Texel (x, y): base
/// (230, 180, 90) sRGB where (x/4 + y/4) is even, metalness
/// [0, 255, 128, 64][x/4] / 255, roughness round(255 (0.15 + 0.85 y/15)) / 255.
#[test]
fn floor_texels_with_metalness_0_1_and_between() {
    let t = material(0);
    let kinds: Vec<SlotKind> = t.slots().iter().map(|s| s.kind).collect();
    assert_eq!(
        kinds,
        [
            SlotKind::Reflectance,
            SlotKind::SpecularReflectance,
            SlotKind::Roughness
        ]
    );
    let orange = [230, 180, 90].map(srgb);
    let blue = [90, 140, 220].map(srgb);
    let rough = |y: u32| (255.0 * (0.15 + 0.85 * f64::from(y) / 15.0)).round_ties_even() / 255.0;
    let alpha = |y: u32| (rough(y) * rough(y)).max(0.01);
    // m = 0: a dielectric, D = 0.96 B, S = 0.04.
    let (d, s) = lobes(orange, 0.0);
    check(&t, texel(1, 2), d, s, alpha(2), "m = 0");
    // m = 0.9 × 1: D = 0.1 × 0.96 B, S = 0.1 × 0.04 + 0.9 B.
    let (d, s) = lobes(blue, 0.9);
    check(&t, texel(5, 2), d, s, alpha(2), "m = 0.9");
    // m = 0.9 × 128/255, rough r = 1 × green of row 13 (blue: 2 + 3 odd).
    let (d, s) = lobes(blue, 0.9 * 128.0 / 255.0);
    check(&t, texel(9, 13), d, s, alpha(13), "m between");
    // The solve's one α per material: r at the texture's mean green.
    let mean: f64 = (0..16).map(rough).sum::<f64>() / 16.0;
    let nominal = t.bsdf().min_alpha(Side::Front).unwrap();
    assert!((nominal - mean * mean).abs() < 1e-6, "{nominal} {mean}");
}

/// The back wall: no base colour texture (B = (0.9, 0.7, 0.4)), metalness
/// 1 in rows 0–3 and 8–11 and 0 elsewhere (metallicFactor 1), roughness
/// 0.8 × round(255 (0.3 + 0.6 x/15)) / 255 across the columns.
#[test]
fn a_metalness_texture_without_a_base_colour_texture() {
    let t = material(1);
    let b = [0.9f32, 0.7, 0.4].map(f64::from);
    let rough =
        |x: u32| 0.8 * (255.0 * (0.3 + 0.6 * f64::from(x) / 15.0)).round_ties_even() / 255.0;
    let (d, s) = lobes(b, 1.0);
    check(&t, texel(3, 1), d, s, rough(3) * rough(3), "metal");
    let (d, s) = lobes(b, 0.0);
    check(&t, texel(12, 5), d, s, rough(12) * rough(12), "dielectric");
}

/// A copy of the test scene with its floor material's
/// metallicRoughnessTexture changed by `edit`, loaded; the error's text.
fn error_with(name: &str, edit: impl Fn(&mut Value)) -> String {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("metal-rough-{name}"));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    for f in std::fs::read_dir(scene_dir()).unwrap() {
        let f = f.unwrap().path();
        std::fs::copy(&f, dir.join(f.file_name().unwrap())).unwrap();
    }
    let path = dir.join("metal-rough-box.gltf");
    let mut j: Value = serde_json::from_slice(&std::fs::read(&path).unwrap()).unwrap();
    edit(&mut j);
    std::fs::write(&path, serde_json::to_vec(&j).unwrap()).unwrap();
    let err = trilux_scene::load(&path).unwrap_err().to_string();
    assert_eq!(err.lines().count(), 1, "{err}");
    err
}

const AT: &str = "/materials/0/pbrMetallicRoughness/metallicRoughnessTexture";

#[test]
fn a_texture_index_out_of_range_is_located() {
    let err = error_with("index", |j| {
        j["materials"][0]["pbrMetallicRoughness"]["metallicRoughnessTexture"]["index"] = 7.into();
    });
    assert!(err.contains(AT), "{err}");
}

#[test]
fn an_image_that_does_not_decode_is_located() {
    let err = error_with("decode", |j| {
        j["images"][1]["uri"] = "metal-rough-box.bin".into();
    });
    assert!(err.contains(AT), "{err}");
    assert!(err.contains("not a PNG or JPEG image"), "{err}");
}

#[test]
fn another_texture_coordinate_set_is_located() {
    let err = error_with("texcoord", |j| {
        j["materials"][0]["pbrMetallicRoughness"]["metallicRoughnessTexture"]["texCoord"] =
            1.into();
    });
    assert!(err.contains(AT), "{err}");
    assert!(err.contains("texCoord 1 is not supported"), "{err}");
}
