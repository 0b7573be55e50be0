//! The loader against Mitsuba 3 itself: transforms, sensors, areas, ray
//! hits, OBJ and PLY normals and texture coordinates, and texture lookups
//! built by Mitsuba 3 from the same XML text
//! (`data/mitsuba_expected.py` made `data/mitsuba_expected.json`).
//!
//! Tolerance: Mitsuba's scalar_rgb variant computes in single precision, so
//! values agree to a few float32 ulps: 2e-6 absolute plus 2e-6 relative.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test, bench or example may panic

use std::path::PathBuf;

use glam::DMat4;
use serde_json::Value;
use trilux_scene::{Scene, load_str, surface_area};

fn data_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data")
}

fn expected() -> Value {
    let text = std::fs::read_to_string(data_dir().join("mitsuba_expected.json"))
        .expect("tests/data/mitsuba_expected.json is committed");
    serde_json::from_str(&text).expect("valid JSON")
}

fn load(body: &str) -> Scene {
    let text = format!("<scene version=\"3.0.0\">{body}</scene>");
    match load_str(&text, data_dir().join("inline.xml")) {
        Ok(s) => s,
        Err(e) => panic!("{body}: {e}"),
    }
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 2e-6 + 2e-6 * b.abs()
}

fn assert_matrix(got: &DMat4, want: &Value, what: &str) {
    for i in 0..4 {
        for j in 0..4 {
            let w = want[i][j].as_f64().expect("number");
            // glam is column-major: row i, column j.
            let g = got.col(j)[i];
            assert!(close(g, w), "{what}: [{i}][{j}] = {g}, Mitsuba {w}\n{got}");
        }
    }
}

#[test]
fn transforms_match_mitsuba() {
    let exp = expected();
    let cases = exp["transforms"].as_array().expect("transforms");
    assert!(cases.len() >= 10);
    for case in cases {
        let xml = case["xml"].as_str().expect("xml");
        let scene = load(&format!(
            "<shape type=\"rectangle\"><transform name=\"to_world\">{xml}</transform></shape>"
        ));
        assert_matrix(
            &scene.shapes[0].shape.world_from_object,
            &case["matrix"],
            xml,
        );
    }
}

#[test]
fn sensors_match_mitsuba() {
    let exp = expected();
    for case in exp["sensors"].as_array().expect("sensors") {
        let xml = case["xml"].as_str().expect("xml");
        let scene = load(&format!("<sensor type=\"perspective\">{xml}</sensor>"));
        let camera = scene.camera.expect("a sensor");
        assert_matrix(&camera.world_from_camera, &case["to_world"], xml);
        let want = case["x_fov"].as_f64().expect("x_fov");
        // x_fov goes through tan/atan in float32: 1e-4 degrees.
        assert!(
            (camera.x_fov() - want).abs() < 1e-4,
            "{xml}: x_fov {} vs Mitsuba {want}",
            camera.x_fov()
        );
    }
}

#[test]
fn areas_match_mitsuba() {
    let exp = expected();
    for case in exp["areas"].as_array().expect("areas") {
        let xml = case["xml"].as_str().expect("xml");
        let scene = load(xml);
        let want = case["area"].as_f64().expect("area");
        let got = surface_area(&scene.shapes[0].shape);
        assert!(
            (got - want).abs() <= 1e-6 * want.max(1.0),
            "{xml}: area {got} vs Mitsuba {want}"
        );
    }
}

/// Vertex normals (recomputed without the file's, or the file's) and
/// texture coordinates of OBJ and PLY meshes.
#[test]
fn mesh_normals_and_texture_coordinates_match_mitsuba() {
    let exp = expected();
    for case in exp["meshes"].as_array().expect("meshes") {
        let xml = case["xml"].as_str().expect("xml");
        let scene = load(xml);
        let trilux_geometry::ShapeKind::Mesh(mesh) = &scene.shapes[0].shape.kind else {
            panic!("a mesh");
        };
        let normals = mesh.normals.as_ref().expect("recomputed normals");
        let positions = case["positions"].as_array().expect("positions");
        assert_eq!(positions.len(), mesh.positions.len(), "vertex count");
        let texcoords = case["texcoords"].as_array().expect("texcoords");
        assert_eq!(
            mesh.texcoords.is_some(),
            !texcoords.is_empty(),
            "{xml}: texture coordinates"
        );
        for (j, (p, n)) in positions
            .iter()
            .zip(case["normals"].as_array().expect("normals"))
            .enumerate()
        {
            let p = glam::DVec3::new(
                p[0].as_f64().unwrap_or(f64::NAN),
                p[1].as_f64().unwrap_or(f64::NAN),
                p[2].as_f64().unwrap_or(f64::NAN),
            );
            let i = mesh
                .positions
                .iter()
                .position(|q| q.distance(p) < 1e-9)
                .expect("same vertices as Mitsuba");
            for k in 0..3 {
                let w = n[k].as_f64().expect("number");
                assert!(
                    (normals[i][k] - w).abs() < 1e-6,
                    "vertex {p}: normal {} vs Mitsuba {n}",
                    normals[i]
                );
            }
            if let Some(uv) = &mesh.texcoords {
                let w = &texcoords[j];
                for k in 0..2 {
                    let w = w[k].as_f64().expect("number");
                    assert!(
                        (uv[i][k] - w).abs() < 1e-6,
                        "{xml}: vertex {p}: uv {}",
                        uv[i]
                    );
                }
            }
        }
    }
}

/// The geometry layer's input surfaces of each shape cover exactly the
/// shape: their areas sum to Mitsuba's area (an independent implementation:
/// trilux-geometry's patches and charts), and `build_geometry` accepts every
/// case.
#[test]
fn input_surfaces_cover_mitsubas_area() {
    let exp = expected();
    for case in exp["areas"].as_array().expect("areas") {
        let xml = case["xml"].as_str().expect("xml");
        let scene = load(xml);
        let geometry = scene.build_geometry().unwrap_or_else(|e| panic!("{e}"));
        let total: f64 = geometry.surfaces().iter().map(|s| s.area()).sum();
        let want = case["area"].as_f64().expect("area");
        // Curved pieces integrate their area numerically: 1e-6 relative.
        assert!(
            (total - want).abs() <= 1e-6 * want.max(1.0),
            "{xml}: surfaces cover {total}, Mitsuba {want}"
        );
    }
}

/// Rays against each shape, in trilux's geometry built from the loaded scene
/// and in Mitsuba 3 from the same XML: same hit or miss, same distance and
/// same geometric normal (after `flip_normals`). This checks that the scene
/// layer hands the geometry layer Mitsuba's object-space conventions (sphere
/// centre and radius, cylinder frame, disk and rectangle orientation, mesh
/// winding). Tolerance 1e-4 relative on t and 1e-4 on normals: Mitsuba
/// intersects in float32.
#[test]
fn rays_hit_what_mitsuba_hits() {
    let exp = expected();
    let num = |v: &Value| v.as_f64().expect("number");
    let vec3 = |v: &Value| glam::DVec3::new(num(&v[0]), num(&v[1]), num(&v[2]));
    let mut hits = 0;
    for case in exp["rays"].as_array().expect("rays") {
        let xml = case["xml"].as_str().expect("xml");
        let geometry = load(xml).build_geometry().unwrap_or_else(|e| panic!("{e}"));
        for ray in case["rays"].as_array().expect("rays") {
            let r = trilux_geometry::Ray {
                origin: vec3(&ray["origin"]),
                dir: vec3(&ray["dir"]),
            };
            let hit = geometry.intersect(&r, 1e30);
            match (hit, ray["t"].as_f64()) {
                (None, None) => {}
                (Some(h), Some(t)) => {
                    hits += 1;
                    assert!(
                        (h.t - t).abs() <= 1e-4 * t,
                        "{xml}: t {} vs Mitsuba {t}",
                        h.t
                    );
                    let n = vec3(&ray["n"]);
                    assert!(
                        h.geometric_normal.distance(n) < 1e-4,
                        "{xml}: normal {} vs Mitsuba {n}",
                        h.geometric_normal
                    );
                }
                (h, t) => panic!("{xml}: trilux {:?} vs Mitsuba t = {t:?}", h.map(|h| h.t)),
            }
        }
    }
    assert!(hits > 200, "{hits} hits");
}

/// Textures with `to_uv` (scale, translation, rotation, their composition)
/// and `checkerboard`: the diffuse reflectance at fixed texture
/// coordinates, against Mitsuba's `eval_diffuse_reflectance`. Tolerance
/// 1e-5: Mitsuba interpolates and decodes sRGB in single precision. Each
/// texture is given inside its BSDF and, as a top-level definition, by a
/// `<ref>` that names its parameter.
#[test]
fn texture_lookups_match_mitsuba() {
    let exp = expected();
    let cases = exp["textures"].as_array().expect("textures");
    for (case, by_ref) in cases.iter().flat_map(|c| [(c, false), (c, true)]) {
        let xml = case["xml"].as_str().expect("xml");
        let scene = load(&if by_ref {
            let definition = xml.replacen("name=\"reflectance\"", "id=\"t\"", 1);
            format!(
                "{definition}<shape type=\"rectangle\"><bsdf type=\"diffuse\"><ref name=\"reflectance\" id=\"t\"/></bsdf></shape>"
            )
        } else {
            format!("<shape type=\"rectangle\"><bsdf type=\"diffuse\">{xml}</bsdf></shape>")
        });
        let slot = scene.shapes[0].textures.first().expect("a texture slot");
        for v in case["values"].as_array().expect("values") {
            let uv = glam::DVec2::new(
                v["uv"][0].as_f64().expect("u"),
                v["uv"][1].as_f64().expect("v"),
            );
            let got = slot.value(slot.texture.eval(slot.to_uv.apply(uv)));
            for c in 0..3 {
                let want = v["rgb"][c].as_f64().expect("number");
                assert!(
                    (got[c] - want).abs() < 1e-5,
                    "{xml} at {uv}: {got:?}, Mitsuba {}",
                    v["rgb"]
                );
            }
        }
    }
}
