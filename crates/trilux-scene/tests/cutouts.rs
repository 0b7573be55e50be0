//! Cut-outs in the loaders: a Mitsuba `mask` whose `opacity` is a bitmap
//! (given in place or by a `<ref>`) and glTF's `alphaMode` `MASK` with
//! `alphaCutoff`, read into the shape's `Transmittance::Cutout` (the
//! fraction 1 − α(u, v) let through) and, for the mask, the textured
//! weight of its `blendbsdf`. Expected values from the images' texels and
//! the two specifications.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test may panic

use std::path::{Path, PathBuf};

use glam::DVec2;
use serde_json::{Value, json};
use trilux_brdf::{Branch, BsdfParams, SlotKind};
use trilux_geometry::Transmittance;
use trilux_scene::Scene;

fn folder(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("cutouts-{name}"));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A `width` × 1 PNG of 8-bit `channels` (1: grey, 4: RGBA) per texel.
fn png(path: &Path, channels: u8, texels: &[u8]) {
    let width = texels.len() as u32 / u32::from(channels);
    let file = std::fs::File::create(path).unwrap();
    let mut e = png::Encoder::new(std::io::BufWriter::new(file), width, 1);
    e.set_color(if channels == 1 {
        png::ColorType::Grayscale
    } else {
        png::ColorType::Rgba
    });
    e.set_depth(png::BitDepth::Eight);
    e.write_header().unwrap().write_image_data(texels).unwrap();
}

/// The fraction let through at (u, ½) by shape `i`'s cut-out.
fn through(scene: &Scene, i: usize, u: f64) -> f64 {
    match &scene.shapes[i].transmission {
        Some(Transmittance::Cutout(c)) => c.fraction(DVec2::new(u, 0.5)),
        other => panic!("not a cut-out: {other:?}"),
    }
}

fn xml_scene(dir: &Path, top: &str, bsdf: &str) -> Result<Scene, trilux_scene::SceneError> {
    let xml =
        format!(r#"<scene version="3.0.0">{top}<shape type="rectangle">{bsdf}</shape></scene>"#);
    let path = dir.join("scene.xml");
    std::fs::write(&path, xml).unwrap();
    trilux_scene::load(&path)
}

#[test]
fn a_bitmap_opacity_lets_one_minus_its_texel_through() {
    // Four raw texels 0, 85, 170, 255, looked up at their centres (nearest):
    // α = v/255 (a grey image's value is its luminance).
    let dir = folder("bitmap");
    png(&dir.join("alpha.png"), 1, &[0, 85, 170, 255]);
    let texture = r#"<texture type="bitmap" name="opacity" id="alpha"><string name="filename" value="alpha.png"/><boolean name="raw" value="true"/><string name="filter_type" value="nearest"/></texture>"#;
    let bsdf = format!(r#"<bsdf type="mask">{texture}<bsdf type="diffuse"/></bsdf>"#);
    let scene = xml_scene(&dir, "", &bsdf).unwrap();
    for (k, v) in [0.0, 85.0, 170.0, 255.0].into_iter().enumerate() {
        let u = (k as f64 + 0.5) / 4.0;
        let want = 1.0 - v / 255.0;
        assert!((through(&scene, 0, u) - want).abs() < 1e-6, "texel {k}");
    }
    // The reflection: a blend of black and the nested BSDF, its weight the
    // same texture.
    let slots = &scene.shapes[0].textures;
    assert_eq!(slots.len(), 1);
    assert_eq!(
        (slots[0].kind, slots[0].path.as_slice()),
        (SlotKind::Weight, &[][..])
    );
    assert!(matches!(scene.shapes[0].bsdf, BsdfParams::Blend { .. }));
    // The same texture by a <ref>, sRGB-decoded this time (no raw).
    let top = r#"<texture type="bitmap" id="leaf"><string name="filename" value="alpha.png"/><string name="filter_type" value="nearest"/></texture>"#;
    let bsdf = r#"<bsdf type="mask"><ref name="opacity" id="leaf"/><bsdf type="diffuse"/></bsdf>"#;
    let scene = xml_scene(&dir, top, bsdf).unwrap();
    let srgb = |v: f64| ((v + 0.055) / 1.055).powf(2.4);
    let want = 1.0 - srgb(170.0 / 255.0);
    assert!((through(&scene, 0, 0.625) - want).abs() < 1e-6);
}

#[test]
fn a_masks_nested_textures_follow_it_to_each_side() {
    // A twosided nested BSDF with one textured diffuse: the mask's blend
    // goes inside the twosided, on both sides, and so do the textures.
    let dir = folder("nested");
    png(&dir.join("alpha.png"), 1, &[0, 255]);
    let bsdf = r#"<bsdf type="mask">
        <texture type="bitmap" name="opacity"><string name="filename" value="alpha.png"/></texture>
        <bsdf type="twosided"><bsdf type="diffuse">
            <texture type="bitmap" name="reflectance"><string name="filename" value="alpha.png"/></texture>
        </bsdf></bsdf></bsdf>"#;
    let scene = xml_scene(&dir, "", bsdf).unwrap();
    let mut paths: Vec<(SlotKind, Vec<Branch>)> = scene.shapes[0]
        .textures
        .iter()
        .map(|s| (s.kind, s.path.clone()))
        .collect();
    paths.sort_by_key(|(k, p)| format!("{k:?}{p:?}"));
    let want = vec![
        (SlotKind::Reflectance, vec![Branch::Back, Branch::Second]),
        (SlotKind::Reflectance, vec![Branch::Front, Branch::Second]),
        (SlotKind::Weight, vec![Branch::Back]),
        (SlotKind::Weight, vec![Branch::Front]),
    ];
    assert_eq!(paths, want);
}

#[test]
fn a_missing_opacity_image_is_one_located_line() {
    let dir = folder("missing");
    let bsdf = r#"<bsdf type="mask"><texture type="bitmap" name="opacity"><string name="filename" value="nowhere.png"/></texture><bsdf type="diffuse"/></bsdf>"#;
    let e = xml_scene(&dir, "", bsdf).unwrap_err().to_string();
    assert!(
        e.contains("scene.xml:1:") && e.contains("nowhere.png"),
        "{e}"
    );
    assert_eq!(e.lines().count(), 1, "{e}");
}

/// A glTF quad (two triangles, u across it) with `material`, an RGBA
/// image `alpha.png` (nearest) beside it.
fn gltf_quad(dir: &Path, material: Value) -> Result<Scene, trilux_scene::SceneError> {
    let mut bin = Vec::new();
    let positions: [f32; 12] = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 1.0, 0.0];
    let uvs: [f32; 8] = [0.0, 0.5, 1.0, 0.5, 1.0, 0.5, 0.0, 0.5];
    let indices: [u32; 6] = [0, 1, 2, 0, 2, 3];
    positions
        .iter()
        .for_each(|f| bin.extend_from_slice(&f.to_le_bytes()));
    uvs.iter()
        .for_each(|f| bin.extend_from_slice(&f.to_le_bytes()));
    indices
        .iter()
        .for_each(|i| bin.extend_from_slice(&i.to_le_bytes()));
    let uri = format!("data:application/octet-stream;base64,{}", base64(&bin));
    let j = json!({
        "asset": {"version": "2.0"},
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "indices": 2, "material": 0}]}],
        "materials": [material],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0.0, 0.0, 0.0], "max": [1.0, 1.0, 0.0]},
            {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC2"},
            {"bufferView": 2, "componentType": 5125, "count": 6, "type": "SCALAR"}
        ],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 48},
            {"buffer": 0, "byteOffset": 48, "byteLength": 32},
            {"buffer": 0, "byteOffset": 80, "byteLength": 24}
        ],
        "buffers": [{"byteLength": 104, "uri": uri}],
        "images": [{"uri": "alpha.png"}],
        "samplers": [{"magFilter": 9728, "wrapS": 33071, "wrapT": 33071}],
        "textures": [{"source": 0, "sampler": 0}]
    });
    let path = dir.join("quad.gltf");
    std::fs::write(&path, serde_json::to_vec(&j).unwrap()).unwrap();
    trilux_scene::load(&path)
}

fn base64(bytes: &[u8]) -> String {
    const A: &[u8] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::new();
    for chunk in bytes.chunks(3) {
        let b = [
            chunk[0],
            *chunk.get(1).unwrap_or(&0),
            *chunk.get(2).unwrap_or(&0),
        ];
        let n = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        for k in 0..4 {
            out.push(if k <= chunk.len() {
                A[((n >> (18 - 6 * k)) & 63) as usize] as char
            } else {
                '='
            });
        }
    }
    out
}

#[test]
fn gltf_mask_cuts_out_where_alpha_is_below_the_cutoff() {
    // Alphas 0, 100, 140, 255 (linear: the colour is sRGB, the alpha
    // not): with the default cutoff 0.5, the first two texels are clear
    // (100/255 = 0.39) and the last two opaque (140/255 = 0.55); with
    // baseColorFactor.a = 0.6, only the last (a = 0.6 ≥ 0.5; 0.6 · 0.55 =
    // 0.33 is not); with alphaCutoff 0.3, all but the first.
    let dir = folder("gltf-mask");
    let rgba: Vec<u8> = [0u8, 100, 140, 255]
        .iter()
        .flat_map(|&a| [200, 200, 200, a])
        .collect();
    png(&dir.join("alpha.png"), 4, &rgba);
    let cases = [
        (json!({"alphaMode": "MASK"}), [1.0, 1.0, 0.0, 0.0]),
        (
            json!({"alphaMode": "MASK", "pbrMetallicRoughness": {"baseColorFactor": [1.0, 1.0, 1.0, 0.6]}}),
            [1.0, 1.0, 1.0, 0.0],
        ),
        (
            json!({"alphaMode": "MASK", "alphaCutoff": 0.3}),
            [1.0, 0.0, 0.0, 0.0],
        ),
    ];
    for (mut m, want) in cases {
        m["pbrMetallicRoughness"]["baseColorTexture"] = json!({"index": 0});
        let scene = gltf_quad(&dir, m.clone()).unwrap();
        for (k, w) in want.into_iter().enumerate() {
            let u = (k as f64 + 0.5) / 4.0;
            assert_eq!(through(&scene, 0, u), w, "{m} texel {k}");
        }
    }
    // OPAQUE (the default) ignores the alpha.
    let m = json!({"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}});
    assert_eq!(gltf_quad(&dir, m).unwrap().shapes[0].transmission, None);
}

#[test]
fn gltf_mask_without_a_texture_is_opaque_or_left_out() {
    let dir = folder("gltf-flat");
    png(&dir.join("alpha.png"), 4, &[0, 0, 0, 0]);
    let opaque = json!({"alphaMode": "MASK", "pbrMetallicRoughness": {"baseColorFactor": [1.0, 1.0, 1.0, 0.5]}});
    let scene = gltf_quad(&dir, opaque).unwrap();
    assert_eq!(scene.shapes.len(), 1);
    assert_eq!(scene.shapes[0].transmission, None);
    let clear = json!({"alphaMode": "MASK", "pbrMetallicRoughness": {"baseColorFactor": [1.0, 1.0, 1.0, 0.4]}});
    let scene = gltf_quad(&dir, clear).unwrap();
    assert!(scene.shapes.is_empty());
    assert!(
        scene.warnings.iter().any(|w| w.contains("left out")),
        "{:?}",
        scene.warnings
    );
}

#[test]
fn bad_gltf_alpha_is_one_located_line() {
    let dir = folder("gltf-bad");
    png(&dir.join("alpha.png"), 4, &[0, 0, 0, 0]);
    for (m, pointer, what) in [
        (
            json!({"alphaMode": "MASK", "alphaCutoff": -0.1}),
            "/materials/0/alphaCutoff",
            "at least 0",
        ),
        (
            json!({"alphaMode": "BLEND"}),
            "/materials/0/alphaMode",
            "alphaMode BLEND is not supported",
        ),
    ] {
        let e = gltf_quad(&dir, m).unwrap_err().to_string();
        assert!(e.contains(&format!("quad.gltf:{pointer}: ")), "{e}");
        assert!(e.contains(what), "{e}");
        assert_eq!(e.lines().count(), 1, "{e}");
    }
}
