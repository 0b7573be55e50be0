//! glTF through the binary: every refused input is one line `error:
//! FILE:/json/path: ...` with exit status 1 and no output; `info --json`
//! has the XML case's keys; `--camera` chooses a camera.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test, bench or example may panic

use std::path::{Path, PathBuf};

mod common;
use common::{folder, trilux};

fn scenes() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes")
}

/// A one-triangle glTF: positions (3 × VEC3 float) then indices (3 × u16)
/// in one base64 buffer; `edit` changes the JSON before it is written.
fn triangle(edit: impl FnOnce(&mut serde_json::Value)) -> serde_json::Value {
    let mut bin = Vec::new();
    for v in [[0.0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]] {
        for c in v {
            bin.extend_from_slice(&c.to_le_bytes());
        }
    }
    for i in [0u16, 1, 2] {
        bin.extend_from_slice(&i.to_le_bytes());
    }
    bin.extend_from_slice(&[0, 0]);
    let mut j = serde_json::json!({
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0, 1]}],
        "nodes": [{"name": "tri", "mesh": 0}, {"name": "eye", "camera": 0, "translation": [0.2, 0.2, 2.0]}],
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.01}}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "mode": 4}]}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
             "min": [0.0, 0.0, 0.0], "max": [1.0, 1.0, 0.0]},
            {"bufferView": 1, "componentType": 5123, "count": 3, "type": "SCALAR"}
        ],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 36},
            {"buffer": 0, "byteOffset": 36, "byteLength": 6}
        ],
        "buffers": [{"byteLength": 44, "uri": format!("data:application/octet-stream;base64,{}", base64(&bin))}]
    });
    edit(&mut j);
    j
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
            if k <= chunk.len() {
                out.push(A[((n >> (18 - 6 * k)) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

/// `info` on `json` written as `name.gltf` must fail with one line naming
/// the file and `pointer`, saying `what`.
fn assert_refused(name: &str, json: &serde_json::Value, pointer: &str, what: &str) {
    let dir = folder(&format!("gltf-{name}"));
    let path = dir.join(format!("{name}.gltf"));
    std::fs::write(&path, serde_json::to_vec(json).unwrap()).unwrap();
    assert_refused_file(name, &path, pointer, what);
}

fn assert_refused_file(name: &str, path: &Path, pointer: &str, what: &str) {
    let p = path.to_str().unwrap();
    let image = path.with_extension("exr");
    let o = image.to_str().unwrap();
    for args in [vec!["info", p], vec!["render", p, "-o", o]] {
        let out = trilux(&args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(
            out.status.code(),
            Some(1),
            "{name}: status; stderr {stderr}"
        );
        assert!(out.stdout.is_empty(), "{name}: no output");
        assert_eq!(stderr.lines().count(), 1, "{name}: one line: {stderr}");
        let prefix = format!("error: {p}:{pointer}");
        assert!(
            stderr.starts_with(&prefix),
            "{name}: {stderr:?} should start with {prefix:?}"
        );
        assert!(
            stderr.contains(what),
            "{name}: {stderr:?} should say {what:?}"
        );
        assert!(!image.exists(), "{name}: no image is written");
    }
}

#[test]
fn a_valid_triangle_loads() {
    let dir = folder("gltf-valid");
    let path = dir.join("tri.gltf");
    std::fs::write(&path, serde_json::to_vec(&triangle(|_| {})).unwrap()).unwrap();
    let out = trilux(&["info", path.to_str().unwrap(), "--json"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["shapes"], 1);
    // glTF's default material: white, metallic 1: a rough conductor.
    assert_eq!(v["bsdfs"]["roughconductor"], 1);
}

#[test]
fn unknown_required_extension() {
    let j =
        triangle(|j| j["extensionsRequired"] = serde_json::json!(["KHR_draco_mesh_compression"]));
    assert_refused(
        "required",
        &j,
        "/extensionsRequired",
        "KHR_draco_mesh_compression",
    );
}

#[test]
fn missing_buffer_file() {
    let j = triangle(|j| j["buffers"][0]["uri"] = "missing.bin".into());
    assert_refused("missing-buffer", &j, "/buffers/0", "missing.bin");
}

#[test]
fn short_buffer() {
    let j = triangle(|j| j["buffers"][0]["byteLength"] = 4000.into());
    assert_refused(
        "short-buffer",
        &j,
        "/buffers/0",
        "fewer than its byteLength",
    );
}

#[test]
fn out_of_range_index() {
    // An accessor index past the end: the gltf crate's validation.
    let j = triangle(|j| j["meshes"][0]["primitives"][0]["indices"] = 7.into());
    assert_refused(
        "index",
        &j,
        "/meshes/0/primitives/0/indices",
        "invalid glTF",
    );
    // A vertex index past the vertex count: ours.
    let dir = folder("gltf-vertex-index");
    let mut j = triangle(|_| {});
    let uri = j["buffers"][0]["uri"].as_str().unwrap().to_string();
    let payload = uri.split(',').nth(1).unwrap();
    let mut bin = decode64(payload);
    bin[40..42].copy_from_slice(&9u16.to_le_bytes());
    j["buffers"][0]["uri"] =
        format!("data:application/octet-stream;base64,{}", base64(&bin)).into();
    let path = dir.join("vertex-index.gltf");
    std::fs::write(&path, serde_json::to_vec(&j).unwrap()).unwrap();
    assert_refused_file(
        "vertex-index",
        &path,
        "/accessors/1",
        "index 9 is out of range for 3 vertices",
    );
}

fn decode64(s: &str) -> Vec<u8> {
    const A: &[u8] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = Vec::new();
    let (mut acc, mut bits) = (0u32, 0);
    for c in s.bytes().filter(|&c| c != b'=') {
        acc = (acc << 6) | A.iter().position(|&a| a == c).unwrap() as u32;
        bits += 6;
        if bits >= 8 {
            bits -= 8;
            out.push((acc >> bits) as u8);
        }
    }
    out
}

#[test]
fn nan_in_an_accessor() {
    let mut j = triangle(|_| {});
    let uri = j["buffers"][0]["uri"].as_str().unwrap().to_string();
    let mut bin = decode64(uri.split(',').nth(1).unwrap());
    bin[12..16].copy_from_slice(&f32::NAN.to_le_bytes());
    j["buffers"][0]["uri"] =
        format!("data:application/octet-stream;base64,{}", base64(&bin)).into();
    assert_refused("nan", &j, "/accessors/0", "not a finite number");
}

#[test]
fn wrong_accessor_type() {
    let j = triangle(|j| {
        j["accessors"][0]["type"] = "VEC2".into();
    });
    assert_refused("type", &j, "/accessors/0", "must be VEC3 of FLOAT");
}

#[test]
fn unsupported_primitive_mode() {
    let j = triangle(|j| j["meshes"][0]["primitives"][0]["mode"] = 1.into());
    assert_refused("mode", &j, "/meshes/0/primitives/0/mode", "only TRIANGLES");
}

#[test]
fn a_punctual_light_with_a_negative_intensity_is_refused_by_name() {
    let j = triangle(|j| {
        j["extensionsUsed"] = serde_json::json!(["KHR_lights_punctual"]);
        j["extensions"] = serde_json::json!({"KHR_lights_punctual": {"lights": [
            {"name": "Desk lamp", "type": "point", "color": [1.0, 1.0, 1.0], "intensity": -10.0}
        ]}});
        j["nodes"] = serde_json::json!([
            {"name": "tri", "mesh": 0, "children": [2]},
            {"name": "eye", "camera": 0, "translation": [0.2, 0.2, 2.0]},
            {"name": "lamp", "extensions": {"KHR_lights_punctual": {"light": 0}}}
        ]);
    });
    assert_refused(
        "light",
        &j,
        "/nodes/2/extensions/KHR_lights_punctual",
        "light \"Desk lamp\": intensity must be finite and not negative",
    );
}

/// A point light of 10 cd with colour (1, 0.5, 0.25) and a spot: `info`
/// counts them, and the point's power is 4π · 10 · colour W (candela read
/// as W sr⁻¹, docs/gltf.md); its `range` is a warning, and the scene
/// solves and renders lit by the light alone.
#[test]
fn punctual_lights_load_solve_and_render() {
    let j = triangle(|j| {
        j["extensionsUsed"] = serde_json::json!(["KHR_lights_punctual"]);
        j["extensions"] = serde_json::json!({"KHR_lights_punctual": {"lights": [
            {"name": "lamp", "type": "point", "color": [1.0, 0.5, 0.25], "intensity": 10.0, "range": 5.0}
        ]}});
        j["nodes"] = serde_json::json!([
            {"name": "tri", "mesh": 0, "children": [2]},
            {"name": "eye", "camera": 0, "translation": [0.2, 0.2, 2.0]},
            {"name": "lamp", "translation": [0.3, 0.3, 1.0], "extensions": {"KHR_lights_punctual": {"light": 0}}}
        ]);
    });
    let dir = folder("gltf-lights");
    let path = dir.join("lit.gltf");
    std::fs::write(&path, serde_json::to_vec(&j).unwrap()).unwrap();
    let v = info_json(&path, &[]);
    assert_eq!(v["lights"], 1);
    assert_eq!(v["emitters"], 0);
    let four_pi_i = 4.0 * std::f64::consts::PI * 10.0;
    for (c, want) in [1.0, 0.5, 0.25].into_iter().enumerate() {
        let got = v["emitted_power"][c].as_f64().unwrap();
        assert!((got / (four_pi_i * want) - 1.0).abs() < 1e-9, "{v}");
    }
    let exr = dir.join("lit.exr");
    let out = trilux(&[
        "render",
        path.to_str().unwrap(),
        "--spp",
        "4",
        "-o",
        exr.to_str().unwrap(),
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(
        stderr.contains(
            "/nodes/2/extensions/KHR_lights_punctual: light \"lamp\": range 5 is ignored"
        ),
        "{stderr}"
    );
    assert!(!stderr.contains("no emitter"), "{stderr}");
    let image = trilux_render::Image::read_exr(&exr).unwrap();
    assert!(
        image.pixels().iter().any(|p| p[0] > 0.0),
        "the light lights the triangle"
    );
}

#[test]
fn refused_material_features() {
    let j = triangle(|j| {
        j["materials"] = serde_json::json!([{"alphaMode": "BLEND"}]);
        j["meshes"][0]["primitives"][0]["material"] = 0.into();
    });
    assert_refused("alpha", &j, "/materials/0/alphaMode", "not supported");
}

/// Three meshes placed by three nodes, each with its own bad material
/// (alpha blending, an extension that changes the light, a double-sided
/// emitter), and a fourth node with a spot whose inner cone is wider than
/// its outer one: all four reported in
/// one run, one line each at its JSON path, exit 1.
#[test]
fn several_bad_materials_are_reported_in_one_run() {
    let j = triangle(|j| {
        let primitive = j["meshes"][0]["primitives"][0].clone();
        let mesh = |m: usize| {
            let mut p = primitive.clone();
            p["material"] = m.into();
            serde_json::json!({"primitives": [p]})
        };
        j["meshes"] = serde_json::json!([mesh(0), mesh(1), mesh(2)]);
        j["materials"] = serde_json::json!([
            {"alphaMode": "BLEND"},
            {"extensions": {"KHR_materials_clearcoat": {"clearcoatFactor": 1.0}}},
            {"emissiveFactor": [1.0, 1.0, 1.0], "doubleSided": true}
        ]);
        j["extensions"] = serde_json::json!({"KHR_lights_punctual": {"lights": [{"type": "spot",
                "spot": {"innerConeAngle": 0.6, "outerConeAngle": 0.5}}]}});
        j["nodes"] = serde_json::json!([
            {"mesh": 0},
            {"mesh": 1, "translation": [2.0, 0.0, 0.0]},
            {"mesh": 2, "translation": [4.0, 0.0, 0.0]},
            {"name": "eye", "camera": 0, "translation": [0.2, 0.2, 2.0]},
            {"extensions": {"KHR_lights_punctual": {"light": 0}}}
        ]);
        j["scenes"] = serde_json::json!([{"nodes": [0, 1, 2, 3, 4]}]);
    });
    let dir = folder("gltf-several");
    let path = dir.join("several.gltf");
    std::fs::write(&path, serde_json::to_vec(&j).unwrap()).unwrap();
    let p = path.to_str().unwrap();
    let out = trilux(&["info", p]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    let lines: Vec<&str> = stderr.lines().collect();
    assert_eq!(lines.len(), 4, "{stderr}");
    let expected = [
        ("/materials/0/alphaMode", "alphaMode BLEND"),
        (
            "/materials/1/extensions/KHR_materials_clearcoat",
            "extension KHR_materials_clearcoat is refused",
        ),
        ("/materials/2/doubleSided", "double-sided emissive"),
        ("/nodes/4/extensions/KHR_lights_punctual", "spot light #0"),
    ];
    for (line, (pointer, what)) in lines.iter().zip(expected) {
        assert!(
            line.starts_with(&format!("error: {p}:{pointer}: ")),
            "{line}"
        );
        assert!(line.contains(what), "{line}");
    }
}

#[test]
fn malformed_json_and_truncated_glb() {
    let dir = folder("gltf-malformed");
    let path = dir.join("bad.gltf");
    std::fs::write(&path, b"{\"asset\": {\"version\": \"2.0\"}, ").unwrap();
    let out = trilux(&["info", path.to_str().unwrap()]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1));
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(
        stderr.contains("bad.gltf") && stderr.contains("malformed glTF JSON"),
        "{stderr}"
    );
    let glb = std::fs::read(scenes().join("product-shot.glb")).unwrap();
    let cut = dir.join("cut.glb");
    std::fs::write(&cut, &glb[..glb.len() / 2]).unwrap();
    let out = trilux(&["info", cut.to_str().unwrap()]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(
        stderr.starts_with(&format!("error: {}:", cut.display())),
        "{stderr}"
    );
}

fn info_json(path: &Path, extra: &[&str]) -> serde_json::Value {
    let mut args = vec!["info", path.to_str().unwrap(), "--json"];
    args.extend_from_slice(extra);
    let out = trilux(&args);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap()
}

fn keys(v: &serde_json::Value) -> Vec<String> {
    let mut k: Vec<String> = v.as_object().unwrap().keys().cloned().collect();
    k.sort();
    k
}

#[test]
fn info_json_of_a_glb_has_the_xml_keys() {
    let glb = info_json(&scenes().join("product-shot.glb"), &[]);
    let xml = info_json(&scenes().join("cornell-box.xml"), &[]);
    assert_eq!(keys(&glb), keys(&xml));
    assert_eq!(keys(&glb["camera"]), keys(&xml["camera"]));
    // floor, studio, softbox, ball; one emitter.
    assert_eq!(glb["shapes"], 4);
    assert_eq!(glb["emitters"], 1);
    assert_eq!(glb["mode"], "rgb");
    // The first camera, "front": at (0, 1.6, 3.5), 45° vertically.
    assert_eq!(
        glb["camera"]["origin"],
        serde_json::json!([0.0, 1.600000023841858, 3.5])
    );
    assert!((glb["camera"]["fov"].as_f64().unwrap() - 45.0).abs() < 1e-4);
    assert_eq!(glb["camera"]["fov_axis"], "y");
    // The softbox: radiance 10 over 2 m × 2 m, one-sided: π · 4 · 10 W.
    let power = glb["emitted_power"].as_array().unwrap();
    for p in power {
        let expected = std::f64::consts::PI * 4.0 * 10.0;
        assert!(
            (p.as_f64().unwrap() - expected).abs() < 1e-4 * expected,
            "{power:?}"
        );
    }
}

#[test]
fn camera_by_name() {
    let top = info_json(&scenes().join("product-shot.glb"), &["--camera", "top"]);
    let o = top["camera"]["origin"].as_array().unwrap();
    assert!((o[1].as_f64().unwrap() - 4.5).abs() < 1e-6, "{o:?}");
    let p = scenes().join("product-shot.glb");
    let out = trilux(&["info", p.to_str().unwrap(), "--camera", "side"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        stderr.contains("no camera named \"side\"") && stderr.contains("front, top"),
        "{stderr}"
    );
}

/// `info` names every camera: by the camera's name, else its node's, else
/// `null` (JSON) or `(unnamed)` (text), in the order of the nodes.
#[test]
fn info_names_every_camera() {
    let json = triangle(|j| {
        j["scenes"][0]["nodes"] = serde_json::json!([0, 1, 2, 3]);
        j["cameras"][0]["name"] = "wide".into();
        let lens = serde_json::json!({"yfov": 0.5, "znear": 0.01});
        let nodes = j["nodes"].as_array_mut().unwrap();
        nodes
            .push(serde_json::json!({"name": "side", "camera": 1, "translation": [2.0, 0.2, 0.2]}));
        nodes.push(serde_json::json!({"camera": 2, "translation": [0.2, 2.0, 0.2]}));
        let cameras = j["cameras"].as_array_mut().unwrap();
        for _ in 0..2 {
            cameras.push(serde_json::json!({"type": "perspective", "perspective": lens}));
        }
    });
    let dir = folder("gltf-camera-names");
    let path = dir.join("cameras.gltf");
    std::fs::write(&path, serde_json::to_vec(&json).unwrap()).unwrap();
    let v = info_json(&path, &[]);
    assert_eq!(v["cameras"], serde_json::json!(["wide", "side", null]));
    let out = trilux(&["info", path.to_str().unwrap()]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.lines()
            .any(|l| l == "cameras        wide, side, (unnamed)"),
        "{text}"
    );
}
