//! The glTF loader, element by element: node hierarchies with TRS and
//! matrix transforms, indexed and non-indexed triangles, normals and
//! texture coordinates, the material mapping of docs/gltf.md
//! (`pbrMetallicRoughness`, `KHR_materials_specular`, `doubleSided`),
//! emissive materials with `KHR_materials_emissive_strength`, perspective
//! cameras (the first or one by name), base colour textures, and
//! `KHR_lights_punctual` refused by name. Expected values are worked out by
//! hand from the glTF specification and the mapping.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test may panic

use std::path::{Path, PathBuf};

use glam::DVec3;
use serde_json::{Value, json};
use trilux_brdf::{BsdfParams, Distribution, SlotKind};
use trilux_color::ColorParam;
use trilux_geometry::ShapeKind;
use trilux_scene::{FovAxis, Scene, SceneError};

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
            if k <= chunk.len() {
                out.push(A[((n >> (18 - 6 * k)) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

/// A glTF document under construction: one buffer of f32 / u32 data.
#[derive(Default)]
struct Doc {
    bin: Vec<u8>,
    accessors: Vec<Value>,
    views: Vec<Value>,
}

impl Doc {
    fn accessor(&mut self, floats: &[f32], ints: &[u32], kind: &str) -> usize {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        let start = self.bin.len();
        let (count, component) = if ints.is_empty() {
            for f in floats {
                self.bin.extend_from_slice(&f.to_le_bytes());
            }
            let width = match kind {
                "VEC2" => 2,
                "VEC3" => 3,
                _ => 1,
            };
            (floats.len() / width, 5126)
        } else {
            for i in ints {
                self.bin.extend_from_slice(&i.to_le_bytes());
            }
            (ints.len(), 5125)
        };
        self.views
            .push(json!({"buffer": 0, "byteOffset": start, "byteLength": self.bin.len() - start}));
        let mut a = json!({"bufferView": self.views.len() - 1, "componentType": component,
                           "count": count, "type": kind});
        if kind == "VEC3" {
            let mut lo = [f32::MAX; 3];
            let mut hi = [f32::MIN; 3];
            for v in floats.chunks(3) {
                for c in 0..3 {
                    lo[c] = lo[c].min(v[c]);
                    hi[c] = hi[c].max(v[c]);
                }
            }
            a["min"] = json!(lo);
            a["max"] = json!(hi);
        }
        self.accessors.push(a);
        self.accessors.len() - 1
    }

    /// The JSON with `rest` merged in (meshes, nodes, scenes, materials...).
    fn json(self, mut rest: Value) -> Value {
        rest["asset"] = json!({"version": "2.0"});
        rest["accessors"] = Value::Array(self.accessors);
        rest["bufferViews"] = Value::Array(self.views);
        rest["buffers"] = json!([{"byteLength": self.bin.len(),
            "uri": format!("data:application/octet-stream;base64,{}", base64(&self.bin))}]);
        rest
    }
}

/// One triangle (0,0,0), (1,0,0), (0,1,0), indexed, with a normal +z and
/// texture coordinates; returns (positions, normals, uvs, indices).
fn triangle(doc: &mut Doc) -> Value {
    let p = doc.accessor(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0], &[], "VEC3");
    let n = doc.accessor(&[0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0], &[], "VEC3");
    let t = doc.accessor(&[0.0, 0.0, 1.0, 0.0, 0.0, 1.0], &[], "VEC2");
    let i = doc.accessor(&[], &[0, 1, 2], "SCALAR");
    json!({"attributes": {"POSITION": p, "NORMAL": n, "TEXCOORD_0": t}, "indices": i})
}

fn folder(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("gltf-{name}"));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn load_in(dir: &Path, json: &Value) -> Result<Scene, SceneError> {
    let path = dir.join("scene.gltf");
    std::fs::write(&path, serde_json::to_vec(json).unwrap()).unwrap();
    trilux_scene::load(&path)
}

fn load(name: &str, json: &Value) -> Result<Scene, SceneError> {
    load_in(&folder(name), json)
}

fn mesh(scene: &Scene, i: usize) -> &trilux_geometry::TriangleMesh {
    match &scene.shapes[i].shape.kind {
        ShapeKind::Mesh(m) => m,
        other => panic!("shape {i} is {other:?}"),
    }
}

fn close(a: DVec3, b: DVec3) -> bool {
    (a - b).abs().max_element() < 1e-6
}

fn rgb(c: &ColorParam) -> [f64; 3] {
    match c {
        ColorParam::Rgb(v) => *v,
        ColorParam::Float(v) => [*v; 3],
        other => panic!("{other:?}"),
    }
}

fn near3(a: [f64; 3], b: [f64; 3]) -> bool {
    (0..3).all(|c| (a[c] - b[c]).abs() < 1e-6)
}

#[test]
fn trs_and_matrix_transforms_compose_parent_times_child() {
    let mut doc = Doc::default();
    let prim = triangle(&mut doc);
    let h = std::f64::consts::FRAC_1_SQRT_2 as f32;
    let j = doc.json(json!({
        "scene": 0,
        "scenes": [{"nodes": [0, 2]}],
        "meshes": [{"primitives": [prim]}],
        "nodes": [
            // Parent: translation (1, 2, 3); child: a quarter turn about z
            // and scale 2: x ↦ T · R · S · x.
            {"translation": [1.0, 2.0, 3.0], "children": [1]},
            {"mesh": 0, "rotation": [0.0, 0.0, h, h], "scale": [2.0, 2.0, 2.0]},
            // A column-major matrix: x scaled by 2, then translated by (5, 0, 0).
            {"mesh": 0, "matrix": [2.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0,
                                   0.0, 0.0, 1.0, 0.0, 5.0, 0.0, 0.0, 1.0]}
        ]
    }));
    let scene = load("trs", &j).unwrap();
    assert_eq!(scene.shapes.len(), 2);
    let a = mesh(&scene, 0);
    // (1,0,0) → scaled (2,0,0) → turned (0,2,0) → moved (1,4,3).
    let expected = [
        DVec3::new(1.0, 2.0, 3.0),
        DVec3::new(1.0, 4.0, 3.0),
        DVec3::new(-1.0, 2.0, 3.0),
    ];
    for (p, e) in a.positions.iter().zip(expected) {
        assert!(close(*p, e), "{p} vs {e}");
    }
    let b = mesh(&scene, 1);
    let expected = [
        DVec3::new(5.0, 0.0, 0.0),
        DVec3::new(7.0, 0.0, 0.0),
        DVec3::new(5.0, 1.0, 0.0),
    ];
    for (p, e) in b.positions.iter().zip(expected) {
        assert!(close(*p, e), "{p} vs {e}");
    }
    // Normals +z stay +z under both (rotation about z; scale along x).
    for m in [a, b] {
        for n in m.normals.as_ref().unwrap() {
            assert!(close(*n, DVec3::Z), "{n}");
        }
        assert!(!m.face_normals);
        assert_eq!(m.triangles, vec![[0, 1, 2]]);
    }
}

#[test]
fn normals_follow_the_inverse_transpose() {
    let mut doc = Doc::default();
    let p = doc.accessor(&[0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0], &[], "VEC3");
    let s = std::f32::consts::FRAC_1_SQRT_2;
    let n = doc.accessor(&[s, s, 0.0, s, s, 0.0, s, s, 0.0], &[], "VEC3");
    let j = doc.json(json!({
        "scenes": [{"nodes": [0]}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": p, "NORMAL": n}}]}],
        "nodes": [{"mesh": 0, "scale": [2.0, 1.0, 1.0]}]
    }));
    let scene = load("normals", &j).unwrap();
    // diag(2,1,1)^-T (1,1,0)/√2 ∝ (1/2, 1, 0), normalised: (1, 2, 0)/√5.
    let e = DVec3::new(1.0, 2.0, 0.0) / 5f64.sqrt();
    for n in mesh(&scene, 0).normals.as_ref().unwrap() {
        assert!(close(*n, e), "{n} vs {e}");
    }
}

#[test]
fn non_indexed_triangles_without_normals_are_flat_and_keep_their_uvs() {
    let mut doc = Doc::default();
    #[rustfmt::skip]
    let p = doc.accessor(&[
        0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 1.0, 0.0,
        0.0, 0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 1.0, 0.0,
    ], &[], "VEC3");
    let t = doc.accessor(
        &[0.0, 1.0, 1.0, 1.0, 1.0, 0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 0.0],
        &[],
        "VEC2",
    );
    let j = doc.json(json!({
        "scenes": [{"nodes": [0]}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": p, "TEXCOORD_0": t}, "mode": 4}]}],
        "nodes": [{"mesh": 0}]
    }));
    let scene = load("flat", &j).unwrap();
    let m = mesh(&scene, 0);
    assert_eq!(m.triangles, vec![[0, 1, 2], [3, 4, 5]]);
    assert!(m.face_normals && m.normals.is_none());
    let uv = m.texcoords.as_ref().unwrap();
    assert_eq!(uv.len(), 6);
    assert!((uv[2].x - 1.0).abs() < 1e-12 && uv[2].y.abs() < 1e-12);
}

/// A one-triangle scene whose primitive has material `material` (or none).
fn with_material(material: Option<Value>) -> Value {
    let mut doc = Doc::default();
    let mut prim = triangle(&mut doc);
    let mut rest = json!({
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "extensionsUsed": ["KHR_materials_specular", "KHR_materials_emissive_strength"]
    });
    if let Some(m) = material {
        prim["material"] = 0.into();
        rest["materials"] = json!([m]);
    }
    rest["meshes"] = json!([{"primitives": [prim]}]);
    doc.json(rest)
}

fn conductor(b: &BsdfParams) -> (f64, [f64; 3]) {
    match b {
        BsdfParams::RoughConductor(c) => {
            assert_eq!(c.distribution, Distribution::Ggx);
            assert!(c.eta_k.is_none(), "material none: Fresnel 1");
            (c.alpha, rgb(&c.specular_reflectance))
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn the_default_material_is_a_white_rough_metal() {
    // glTF's default: base colour 1, metallic 1, roughness 1: S = B = 1,
    // D = 0, α = 1.
    let scene = load("default-material", &with_material(None)).unwrap();
    let (alpha, s) = conductor(&scene.shapes[0].bsdf);
    assert!((alpha - 1.0).abs() < 1e-12);
    assert!(near3(s, [1.0; 3]), "{s:?}");
}

#[test]
fn a_dielectric_is_a_blend_of_diffuse_and_a_rough_conductor() {
    let m = json!({"pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.25, 0.1, 1.0],
                   "metallicFactor": 0.0, "roughnessFactor": 0.5}});
    let scene = load("dielectric", &with_material(Some(m))).unwrap();
    // F0 = 0.04: D = 0.96 B = (0.48, 0.24, 0.096), S = 0.04; D̂ = 0.48,
    // Ŝ = 0.04, w = 0.04 / 0.52; inner diffuse D / (1 − w) = D · 0.52/0.48,
    // inner conductor S / w = 0.52; α = 0.5² = 0.25.
    let BsdfParams::Blend {
        weight,
        first,
        second,
    } = &scene.shapes[0].bsdf
    else {
        panic!("{:?}", scene.shapes[0].bsdf)
    };
    assert!((weight - 0.04 / 0.52).abs() < 1e-9, "{weight}");
    let BsdfParams::Diffuse { reflectance } = first.as_ref() else {
        panic!("{first:?}")
    };
    assert!(
        near3(rgb(reflectance), [0.52, 0.26, 0.104]),
        "{reflectance:?}"
    );
    let (alpha, s) = conductor(second);
    assert!((alpha - 0.25).abs() < 1e-9);
    assert!(near3(s, [0.52; 3]), "{s:?}");
    // The blend's total reflectance at normal incidence is D + S.
    let total: Vec<f64> = (0..3)
        .map(|c| (1.0 - weight) * rgb(reflectance)[c] + weight * s[c])
        .collect();
    assert!(
        near3([total[0], total[1], total[2]], [0.52, 0.28, 0.136]),
        "{total:?}"
    );
}

#[test]
fn specular_factor_zero_is_lambertian_and_double_sided_is_twosided() {
    let m = json!({"pbrMetallicRoughness": {"baseColorFactor": [0.7, 0.6, 0.5, 1.0], "metallicFactor": 0.0},
                   "doubleSided": true,
                   "extensions": {"KHR_materials_specular": {"specularFactor": 0.0}}});
    let scene = load("lambert", &with_material(Some(m))).unwrap();
    let BsdfParams::TwoSided { front, back: None } = &scene.shapes[0].bsdf else {
        panic!("{:?}", scene.shapes[0].bsdf)
    };
    let BsdfParams::Diffuse { reflectance } = front.as_ref() else {
        panic!("{front:?}")
    };
    assert!(near3(rgb(reflectance), [0.7, 0.6, 0.5]), "{reflectance:?}");
    assert_eq!(scene.bsdf_counts.get("twosided"), Some(&1));
}

#[test]
fn a_metal_is_a_rough_conductor_with_its_base_colour_and_smallest_alpha() {
    let m = json!({"pbrMetallicRoughness": {"baseColorFactor": [0.9, 0.6, 0.3, 1.0],
                   "metallicFactor": 1.0, "roughnessFactor": 0.05}});
    let scene = load("metal", &with_material(Some(m))).unwrap();
    let (alpha, s) = conductor(&scene.shapes[0].bsdf);
    // 0.05² = 0.0025 is below the smallest α taken, 0.01.
    assert!((alpha - 0.01).abs() < 1e-12, "{alpha}");
    assert!(near3(s, [0.9, 0.6, 0.3]), "{s:?}");
}

#[test]
fn emission_is_factor_times_strength_on_the_front() {
    let m = json!({"pbrMetallicRoughness": {"baseColorFactor": [0.0, 0.0, 0.0, 1.0], "metallicFactor": 0.0},
                   "emissiveFactor": [1.0, 0.5, 0.25],
                   "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 4.0},
                                  "KHR_materials_specular": {"specularFactor": 0.0}}});
    let scene = load("emissive", &with_material(Some(m))).unwrap();
    let e = scene.shapes[0].emitter.as_ref().expect("an emitter");
    assert!(near3(rgb(&e.radiance), [4.0, 2.0, 1.0]), "{:?}", e.radiance);
    // A material that does not emit makes no emitter.
    let scene = load("not-emissive", &with_material(Some(json!({})))).unwrap();
    assert!(scene.shapes[0].emitter.is_none());
}

fn with_cameras() -> Value {
    let mut doc = Doc::default();
    let prim = triangle(&mut doc);
    let h = std::f64::consts::FRAC_1_SQRT_2 as f32;
    doc.json(json!({
        "scenes": [{"nodes": [0, 1, 2]}],
        "meshes": [{"primitives": [prim]}],
        "cameras": [
            {"name": "wide", "type": "perspective", "perspective": {"yfov": 0.5, "aspectRatio": 2.0, "znear": 0.1}},
            {"type": "perspective", "perspective": {"yfov": 1.0, "znear": 0.1}}
        ],
        "nodes": [
            {"mesh": 0},
            {"camera": 0, "translation": [0.0, 1.0, 5.0]},
            // A quarter turn about y: glTF's −z view direction becomes −x.
            {"name": "side", "camera": 1, "translation": [3.0, 0.0, 0.0], "rotation": [0.0, h, 0.0, h]}
        ]
    }))
}

#[test]
fn the_first_perspective_camera_or_one_by_name() {
    let scene = load("cameras", &with_cameras()).unwrap();
    let c = scene.camera.as_ref().unwrap();
    assert!(close(c.origin, DVec3::new(0.0, 1.0, 5.0)));
    assert!(close((c.target - c.origin).normalize(), DVec3::NEG_Z));
    assert!(close(c.up, DVec3::Y));
    assert!((c.fov - 0.5f64.to_degrees()).abs() < 1e-4, "{}", c.fov);
    assert_eq!(c.fov_axis, FovAxis::Y);
    assert_eq!((c.width, c.height), (768, 384));

    let dir = folder("cameras-named");
    let path = dir.join("scene.gltf");
    std::fs::write(&path, serde_json::to_vec(&with_cameras()).unwrap()).unwrap();
    for name in ["side", "wide"] {
        let scene = trilux_scene::open_with_camera(&path, Some(name), &[])
            .unwrap()
            .finish()
            .unwrap();
        let c = scene.camera.unwrap();
        if name == "side" {
            // By its node's name; no aspect ratio: 768 × 576.
            assert!(close(c.origin, DVec3::new(3.0, 0.0, 0.0)));
            assert!(
                close((c.target - c.origin).normalize(), DVec3::NEG_X),
                "{}",
                c.target
            );
            assert_eq!((c.width, c.height), (768, 576));
        } else {
            assert!(close(c.origin, DVec3::new(0.0, 1.0, 5.0)));
        }
    }
    let err = trilux_scene::open_with_camera(&path, Some("top"), &[])
        .unwrap_err()
        .to_string();
    assert!(err.contains("no camera named \"top\""), "{err}");
}

#[test]
fn a_base_colour_texture_is_decoded_from_srgb() {
    let dir = folder("texture");
    let ramp = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/textures/ramp.png");
    std::fs::copy(ramp, dir.join("ramp.png")).unwrap();
    let m = json!({"pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1.0], "metallicFactor": 0.0,
                   "baseColorTexture": {"index": 0}},
                   "extensions": {"KHR_materials_specular": {"specularFactor": 0.0}}});
    let mut j = with_material(Some(m));
    j["images"] = json!([{"uri": "ramp.png"}]);
    j["samplers"] = json!([{"wrapS": 33071, "wrapT": 33071}]);
    j["textures"] = json!([{"source": 0, "sampler": 0}]);
    let scene = load_in(&dir, &j).unwrap();
    let slots = &scene.shapes[0].textures;
    assert_eq!(slots.len(), 1);
    let slot = &slots[0];
    assert_eq!(slot.kind, SlotKind::Reflectance);
    assert!(near3(slot.scale, [0.5; 3]) && near3(slot.offset, [0.0; 3]));
    // ramp.png (scripts/make_gltf_scenes.py): 32 columns of grey
    // round(255 k / 31); the mean of their sRGB decodings (IEC 61966-2-1).
    let decode = |v: f64| {
        if v <= 0.04045 {
            v / 12.92
        } else {
            ((v + 0.055) / 1.055).powf(2.4)
        }
    };
    let mean = (0..32)
        .map(|k| decode((255.0 * k as f64 / 31.0).round() / 255.0))
        .sum::<f64>()
        / 32.0;
    let got = slot.texture.mean();
    assert!(
        (got[0] - mean).abs() < 1e-5 && (got[2] - mean).abs() < 1e-5,
        "{got:?} vs {mean}"
    );
}

/// `KHR_texture_transform` maps TEXCOORD_0 by T · R · S. The extension's
/// examples: an offset (0.5, 0) moves the lookup half an image right; a
/// scale of 2 tiles the image twice; a rotation of +90° turns (1, 0) into
/// (0, −1), a clockwise turn in y-up terms, counter-clockwise in glTF's
/// v-down coordinates (what implementations do, KhronosGroup/glTF #1563).
#[test]
fn texture_transforms_map_the_texture_coordinates() {
    let dir = folder("texture-transform");
    let ramp = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/textures/ramp.png");
    std::fs::copy(ramp, dir.join("ramp.png")).unwrap();
    let to_uv = |transform: serde_json::Value| {
        let m = json!({"pbrMetallicRoughness": {"metallicFactor": 0.0,
                       "baseColorTexture": {"index": 0, "extensions": {"KHR_texture_transform": transform}}},
                       "extensions": {"KHR_materials_specular": {"specularFactor": 0.0}}});
        let mut j = with_material(Some(m));
        j["extensionsUsed"] = json!(["KHR_materials_specular", "KHR_texture_transform"]);
        j["extensionsRequired"] = json!(["KHR_texture_transform"]);
        j["images"] = json!([{"uri": "ramp.png"}]);
        j["textures"] = json!([{"source": 0}]);
        let scene = load_in(&dir, &j).unwrap();
        scene.shapes[0].textures[0].to_uv
    };
    let p = glam::DVec2::new(1.0, 0.0);
    let q = glam::DVec2::new(0.25, 0.5);
    let close = |a: glam::DVec2, b: glam::DVec2| (a - b).length() < 1e-6;
    assert!(close(
        to_uv(json!({"offset": [0.5, 0.0]})).apply(q),
        glam::DVec2::new(0.75, 0.5)
    ));
    assert!(close(
        to_uv(json!({"scale": [2.0, 3.0]})).apply(q),
        glam::DVec2::new(0.5, 1.5)
    ));
    let quarter = std::f64::consts::FRAC_PI_2;
    assert!(close(
        to_uv(json!({"rotation": quarter})).apply(p),
        glam::DVec2::new(0.0, -1.0)
    ));
    // All three: scale, then rotate, then offset.
    let all = to_uv(json!({"offset": [0.1, 0.2], "rotation": quarter, "scale": [2.0, 1.0]}));
    assert!(close(all.apply(p), glam::DVec2::new(0.1, 0.2 - 2.0)));
    let err = |transform: serde_json::Value| {
        let m = json!({"pbrMetallicRoughness": {"baseColorTexture": {"index": 0,
                       "extensions": {"KHR_texture_transform": transform}}}});
        let mut j = with_material(Some(m));
        j["images"] = json!([{"uri": "ramp.png"}]);
        j["textures"] = json!([{"source": 0}]);
        load_in(&dir, &j).unwrap_err().to_string()
    };
    let e = err(json!({"texCoord": 1}));
    assert!(e.contains("texCoord 1 is not supported"), "{e}");
    assert!(
        e.contains("/materials/0/pbrMetallicRoughness/baseColorTexture"),
        "{e}"
    );
}

/// A scene of `lights` placed by nodes 1.. (node k + 1 carries light k,
/// with the node's own fields from `nodes`).
fn with_lights(lights: Value, nodes: Value) -> Value {
    let mut j = with_material(None);
    j["extensionsUsed"] = json!(["KHR_lights_punctual"]);
    j["extensions"] = json!({"KHR_lights_punctual": {"lights": lights}});
    let mut all = vec![json!({"mesh": 0})];
    for (k, n) in nodes.as_array().unwrap().iter().enumerate() {
        let mut n = n.clone();
        n["extensions"] = json!({"KHR_lights_punctual": {"light": k}});
        all.push(n);
    }
    j["scenes"] = json!([{"nodes": (0..all.len()).collect::<Vec<_>>()}]);
    j["nodes"] = Value::Array(all);
    j
}

/// glTF's units as trilux reads glTF's emission (one for one): candela →
/// W sr⁻¹ for point and spot, lux → W m⁻² for directional, times
/// `color`; a light shines along its node's −z; a spot keeps glTF's
/// falloff; `range` is ignored with a warning naming the light.
#[test]
fn punctual_lights_load_with_their_units_and_directions() {
    use trilux_geometry::{Punctual, SpotFalloff};
    let j = with_lights(
        json!([
            {"type": "point", "color": [1.0, 0.5, 0.25], "intensity": 8.0, "range": 3.0},
            {"type": "directional", "intensity": 2.0},
            {"name": "Sun", "type": "spot", "spot": {"innerConeAngle": 0.2, "outerConeAngle": 0.5}}
        ]),
        // The directional light's node turned +90° about x: its −z
        // points along +y.
        json!([
            {"translation": [1.0, 2.0, 3.0]},
            {"rotation": [std::f64::consts::FRAC_1_SQRT_2, 0.0, 0.0, std::f64::consts::FRAC_1_SQRT_2]},
            {"translation": [0.0, 1.0, 0.0]}
        ]),
    );
    let s = load("lights", &j).unwrap();
    assert_eq!(s.lights.len(), 3);
    assert_eq!(
        s.lights[0].punctual,
        Punctual::Point {
            position: DVec3::new(1.0, 2.0, 3.0)
        }
    );
    assert!(near3(rgb(&s.lights[0].intensity), [8.0, 4.0, 2.0]));
    match s.lights[1].punctual {
        Punctual::Directional { direction } => {
            assert!(close(direction, DVec3::new(0.0, 1.0, 0.0)), "{direction}")
        }
        other => panic!("{other:?}"),
    }
    assert!(near3(rgb(&s.lights[1].intensity), [2.0, 2.0, 2.0]));
    match s.lights[2].punctual {
        Punctual::Spot {
            position,
            light_from_world,
            falloff,
        } => {
            assert!(close(position, DVec3::Y));
            // The node's −z (world −z here) is the spot's axis.
            assert!(close(light_from_world * -DVec3::Z, DVec3::Z));
            assert_eq!(
                falloff,
                SpotFalloff::Gltf {
                    inner_cone_angle: f64::from(0.2f32),
                    outer_cone_angle: f64::from(0.5f32)
                }
            );
        }
        other => panic!("{other:?}"),
    }
    assert_eq!(s.warnings.len(), 1, "{:?}", s.warnings);
    assert!(
        s.warnings[0].contains("/nodes/1/extensions/KHR_lights_punctual")
            && s.warnings[0].contains("range 3 is ignored"),
        "{}",
        s.warnings[0]
    );
}

/// Bad values of a punctual light: one line at the node's light, naming
/// the light and the problem.
#[test]
fn bad_punctual_lights_are_located() {
    let cases = [
        (
            json!({"type": "point", "intensity": -1.0}),
            "intensity must be finite and not negative",
        ),
        (
            json!({"type": "point", "color": [1.0, -0.5, 1.0]}),
            "color must be finite and not negative",
        ),
        (
            json!({"type": "spot", "spot": {"innerConeAngle": 0.5, "outerConeAngle": 0.5}}),
            "0 ≤ innerConeAngle < outerConeAngle ≤ π/2",
        ),
        (
            json!({"type": "spot", "spot": {"outerConeAngle": 2.0}}),
            "0 ≤ innerConeAngle < outerConeAngle ≤ π/2",
        ),
    ];
    for (k, (light, what)) in cases.into_iter().enumerate() {
        let j = with_lights(json!([light]), json!([{}]));
        let err = load(&format!("bad-light-{k}"), &j).unwrap_err().to_string();
        assert!(
            err.contains("/nodes/1/extensions/KHR_lights_punctual"),
            "{err}"
        );
        assert!(err.contains(what), "{err}");
        assert_eq!(err.lines().count(), 1, "{err}");
    }
    // A directional light on a node scaled to nothing has no direction.
    let j = with_lights(
        json!([{"type": "directional"}]),
        json!([{"scale": [0.0, 0.0, 0.0]}]),
    );
    let err = load("bad-light-scale", &j).unwrap_err().to_string();
    assert!(err.contains("has no direction"), "{err}");
}

/// The `gltf` crate's validation indexes a primitive's POSITION accessor
/// before checking that it exists: an out-of-range one must be a located
/// error, not a panic (found by tests/fuzz_gltf.rs).
#[test]
fn an_attribute_naming_a_missing_accessor_is_located() {
    let mut j = with_material(None);
    j["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = 99.into();
    let err = load("missing-accessor", &j).unwrap_err().to_string();
    assert!(err.contains("/meshes/0/primitives/0/attributes"), "{err}");
    assert!(err.contains("accessor 99"), "{err}");
}

/// An image in a buffer view without a mimeType (the crate unwraps it).
#[test]
fn an_image_without_its_mime_type_is_located() {
    let mut j = with_material(Some(json!({
        "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}
    })));
    j["textures"] = json!([{"source": 0}]);
    j["images"] = json!([{"bufferView": 0}]);
    let err = load("image-mime", &j).unwrap_err().to_string();
    assert!(err.contains("/images/0"), "{err}");
}

/// A one-component (grayscale) JPEG is read as Mitsuba reads it: one
/// channel standing for R = G = B. `tests/data/grey192.jpg` is 8 × 8 pixels
/// of 192 (its README); a flat JPEG decodes to its value within 1/255, so
/// every texel lies between the sRGB decodings of 191/255 and 193/255.
#[test]
fn a_grayscale_jpeg_texture_is_read_through_gltf_and_xml() {
    let dir = folder("texture-grey-jpeg");
    let jpeg = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/grey192.jpg");
    std::fs::copy(jpeg, dir.join("grey.jpg")).unwrap();
    let decode = |v: f64| ((v / 255.0 + 0.055) / 1.055).powf(2.4);
    let (lo, hi) = (decode(191.0), decode(193.0));
    let check = |texture: &trilux_brdf::Texture, how: &str| {
        assert_eq!((texture.width(), texture.height()), (8, 8), "{how}");
        let m = texture.mean();
        assert!(m.iter().all(|&c| lo <= c && c <= hi), "{how}: {m:?}");
        assert!(m[0] == m[1] && m[1] == m[2], "{how}: R = G = B: {m:?}");
    };
    // glTF: a base colour texture.
    let m = json!({"pbrMetallicRoughness": {"baseColorFactor": [1.0, 1.0, 1.0, 1.0], "metallicFactor": 0.0,
                   "baseColorTexture": {"index": 0}},
                   "extensions": {"KHR_materials_specular": {"specularFactor": 0.0}}});
    let mut j = with_material(Some(m));
    j["images"] = json!([{"uri": "grey.jpg"}]);
    j["textures"] = json!([{"source": 0}]);
    let scene = load_in(&dir, &j).unwrap();
    check(&scene.shapes[0].textures[0].texture, "glTF");
    // Mitsuba XML: a bitmap reflectance.
    let xml = dir.join("grey.xml");
    std::fs::write(
        &xml,
        r#"<scene version="3.0.0">
  <shape type="rectangle">
    <bsdf type="diffuse">
      <texture type="bitmap" name="reflectance"><string name="filename" value="grey.jpg"/></texture>
    </bsdf>
  </shape>
</scene>
"#,
    )
    .unwrap();
    let scene = trilux_scene::load(&xml).unwrap();
    let slot = &scene.shapes[0].textures[0];
    assert_eq!(slot.kind, SlotKind::Reflectance);
    check(&slot.texture, "XML");
}

/// The error for a material carrying `ext` (with `body`), and listing it
/// in `extensionsUsed` as the specification asks.
fn material_extension_error(ext: &str, body: Value) -> String {
    let m = json!({"name": "glass", "extensions": {ext: body}});
    let mut j = with_material(Some(m));
    j["extensionsUsed"] = json!([ext]);
    // A folder per call: two tests may ask for the same extension at once.
    static CALLS: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let call = CALLS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let err = load(&format!("{ext}-{call}"), &j).unwrap_err().to_string();
    assert_eq!(err.lines().count(), 1, "{err}");
    err
}

/// A material extension that changes the light and that trilux does not
/// implement is refused at the material, naming it and the extension.
fn assert_refused_on_material(ext: &str, body: Value) {
    let err = material_extension_error(ext, body);
    assert!(
        err.contains(&format!("scene.gltf:/materials/0/extensions/{ext}")),
        "{err}"
    );
    assert!(
        err.contains("material \"glass\"") && err.contains("refused"),
        "{err}"
    );
}

macro_rules! refused_on_material {
    ($($test:ident: $ext:literal $body:tt;)*) => {$(
        #[test]
        fn $test() {
            assert_refused_on_material($ext, json!($body));
        }
    )*};
}

refused_on_material! {
    transmission_is_refused: "KHR_materials_transmission" {"transmissionFactor": 1.0};
    volume_is_refused: "KHR_materials_volume" {"thicknessFactor": 0.1};
    ior_other_than_the_default_is_refused: "KHR_materials_ior" {"ior": 1.33};
    clearcoat_is_refused: "KHR_materials_clearcoat" {"clearcoatFactor": 1.0};
    sheen_is_refused: "KHR_materials_sheen" {"sheenColorFactor": [1.0, 1.0, 1.0]};
    iridescence_is_refused: "KHR_materials_iridescence" {"iridescenceFactor": 1.0};
    anisotropy_is_refused: "KHR_materials_anisotropy" {"anisotropyStrength": 0.5};
    dispersion_is_refused: "KHR_materials_dispersion" {"dispersion": 0.1};
    diffuse_transmission_is_refused: "KHR_materials_diffuse_transmission" {"diffuseTransmissionFactor": 0.5};
    unlit_is_refused: "KHR_materials_unlit" {};
    specular_glossiness_is_refused: "KHR_materials_pbrSpecularGlossiness" {"diffuseFactor": [1.0, 1.0, 1.0, 1.0]};
    an_unknown_material_extension_is_refused: "VENDOR_materials_magic" {};
}

/// Transmission's refusal says why: ignored, glass would be opaque.
#[test]
fn transmission_is_refused_saying_that_glass_would_be_opaque() {
    let err = material_extension_error("KHR_materials_transmission", json!({}));
    assert!(err.contains("opaque"), "{err}");
}

/// glTF's default index of refraction (1.5, written or implied) is what
/// trilux's dielectrics use, so it loads.
#[test]
fn the_default_index_of_refraction_loads() {
    for body in [json!({"ior": 1.5}), json!({})] {
        let m = json!({"extensions": {"KHR_materials_ior": body}});
        let mut j = with_material(Some(m));
        j["extensionsUsed"] = json!(["KHR_materials_ior"]);
        assert!(load("ior-default", &j).is_ok());
    }
}

/// An extension listed as used but found on no material or node of the
/// scene (here: on a material no primitive uses) is refused at its entry
/// in `extensionsUsed`, unless it does not change the light.
#[test]
fn an_unimplemented_extension_listed_as_used_is_refused_there() {
    let mut j = with_material(None);
    j["materials"] = json!([{"extensions": {"KHR_materials_sheen": {}}}]);
    j["extensionsUsed"] = json!(["KHR_materials_specular", "KHR_materials_sheen"]);
    let err = load("used", &j).unwrap_err().to_string();
    assert!(err.contains("scene.gltf:/extensionsUsed/1"), "{err}");
    assert!(err.contains("KHR_materials_sheen"), "{err}");
    for harmless in [
        "KHR_materials_variants",
        "KHR_xmp_json_ld",
        "KHR_mesh_quantization",
    ] {
        let mut j = with_material(None);
        j["extensionsUsed"] = json!([harmless]);
        assert!(load("harmless", &j).is_ok(), "{harmless}");
    }
}

/// A node extension trilux does not implement (GPU instancing places
/// more copies of the mesh) is refused at the node, naming it.
#[test]
fn an_unimplemented_node_extension_is_refused_at_the_node() {
    let mut j = with_material(None);
    j["extensionsUsed"] = json!(["EXT_mesh_gpu_instancing"]);
    j["nodes"] = json!([{"mesh": 0, "name": "rows",
        "extensions": {"EXT_mesh_gpu_instancing": {"attributes": {}}}}]);
    let err = load("instancing", &j).unwrap_err().to_string();
    assert!(
        err.contains("scene.gltf:/nodes/0/extensions/EXT_mesh_gpu_instancing"),
        "{err}"
    );
    assert!(err.contains("node \"rows\""), "{err}");
}
