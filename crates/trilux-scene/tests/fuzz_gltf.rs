//! Mutated glTF JSON and truncated or corrupted GLB files never panic:
//! each either loads (meshes, buffers and textures read) or is refused
//! with one error line. The seeds are the bundled glTF scenes, loaded as if
//! they lay in scenes/ (so their relative buffer and image URIs resolve).
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test may panic

use std::path::{Path, PathBuf};

use proptest::prelude::*;
use proptest::sample::Index;
use serde_json::Value;

fn scenes() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes")
}

const GLB: &[u8] = include_bytes!("../../../scenes/product-shot.glb");
const ROOM: &str = include_str!("../../../scenes/textured-room.gltf");
const CORNELL: &str = include_str!("../../../scenes/cornell-box-gltf.gltf");

/// Loads `bytes` as scenes/NAME; true when it loaded. Panics (failing the
/// property) only on an error of several lines, or on more than 20 errors
/// and a count — a panic inside is the failure this test looks for.
fn load(bytes: &[u8], name: &str) -> bool {
    let path = scenes().join(name);
    match trilux_scene::open_gltf_bytes(bytes, &path).and_then(|p| p.finish()) {
        Ok(_) => true,
        Err(e) => {
            for one in e.errors() {
                let text = one.to_string();
                assert!(!text.contains('\n'), "a multi-line error: {text}");
                assert!(!text.is_empty());
            }
            assert!(e.lines().len() <= 21, "{e}");
            false
        }
    }
}

/// Every JSON pointer of `v` (objects' keys and arrays' elements).
fn pointers(v: &Value, here: String, out: &mut Vec<String>) {
    match v {
        Value::Object(m) => {
            for (k, x) in m {
                let p = format!("{here}/{}", k.replace('~', "~0").replace('/', "~1"));
                out.push(p.clone());
                pointers(x, p, out);
            }
        }
        Value::Array(a) => {
            for (i, x) in a.iter().enumerate() {
                let p = format!("{here}/{i}");
                out.push(p.clone());
                pointers(x, p, out);
            }
        }
        _ => {}
    }
}

/// Values a mutation writes: out of range, of the wrong type, extreme.
fn replacement(k: usize) -> Value {
    let all = [
        serde_json::json!(-1),
        serde_json::json!(0),
        serde_json::json!(1),
        serde_json::json!(7),
        serde_json::json!(4_294_967_296u64),
        serde_json::json!(1e300),
        serde_json::json!(-1e-300),
        serde_json::json!("x"),
        serde_json::json!("data:application/octet-stream;base64,AAAA"),
        serde_json::json!("../../../../etc/passwd"),
        Value::Null,
        serde_json::json!([]),
        serde_json::json!({}),
        serde_json::json!([0, 0, 0]),
        serde_json::json!(["KHR_draco_mesh_compression"]),
        serde_json::json!(true),
    ];
    all[k % all.len()].clone()
}

/// `json` with `edits` applied: each replaces (or, for odd `how`,
/// deletes) the value at one pointer.
fn mutate(json: &str, edits: &[(Index, usize)]) -> Vec<u8> {
    let mut v: Value = serde_json::from_str(json).unwrap();
    for (at, how) in edits {
        let mut ps = Vec::new();
        pointers(&v, String::new(), &mut ps);
        if ps.is_empty() {
            break;
        }
        let p = ps[at.index(ps.len())].clone();
        if how % 5 == 4 {
            // Delete: from its parent object or array.
            let (parent, last) = p.rsplit_once('/').unwrap();
            match v.pointer_mut(parent) {
                Some(Value::Object(m)) => {
                    m.remove(&last.replace("~1", "/").replace("~0", "~"));
                }
                Some(Value::Array(a)) => {
                    if let Ok(i) = last.parse::<usize>()
                        && i < a.len()
                    {
                        a.remove(i);
                    }
                }
                _ => {}
            }
        } else if let Some(slot) = v.pointer_mut(&p) {
            *slot = replacement(*how / 5);
        }
    }
    serde_json::to_vec(&v).unwrap()
}

#[test]
fn the_seeds_load() {
    assert!(load(GLB, "product-shot.glb"));
    assert!(load(ROOM.as_bytes(), "textured-room.gltf"));
    assert!(load(CORNELL.as_bytes(), "cornell-box-gltf.gltf"));
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 4000, failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn mutated_gltf_json_never_panics(
        seed in 0usize..3,
        edits in prop::collection::vec((any::<Index>(), 0usize..80), 1..4),
    ) {
        let (json, name) = match seed {
            0 => (ROOM, "textured-room.gltf"),
            1 => (CORNELL, "cornell-box-gltf.gltf"),
            _ => {
                // The GLB's JSON chunk, loaded as a .gltf beside nothing:
                // its binary-chunk buffer is then missing.
                let len = u32::from_le_bytes(GLB[12..16].try_into().unwrap()) as usize;
                (std::str::from_utf8(&GLB[20..20 + len]).unwrap(), "product-shot-json.gltf")
            }
        };
        load(&mutate(json.trim_end(), &edits), name);
    }

    #[test]
    fn truncated_glb_never_panics(cut in 0usize..GLB.len()) {
        prop_assert!(!load(&GLB[..cut], "product-shot.glb"));
    }

    #[test]
    fn corrupted_glb_never_panics(
        flips in prop::collection::vec((any::<Index>(), any::<u8>()), 1..8),
    ) {
        let mut bytes = GLB.to_vec();
        for (at, b) in &flips {
            let i = at.index(bytes.len());
            bytes[i] = *b;
        }
        load(&bytes, "product-shot.glb");
    }
}
