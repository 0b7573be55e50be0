//! The `trilux` binary: scene errors give exactly one line
//! `error: FILE:LINE:COL: ...` on stderr and exit status 1; usage errors exit
//! with clap's status 2; `info --json` has exactly the documented keys (README, "Using it").
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test, bench or example may panic

use std::path::{Path, PathBuf};
use std::process::Command;

mod common;
use common::{folder, trilux};

fn write(dir: &Path, file: &str, text: &str) -> PathBuf {
    let path = dir.join(file);
    std::fs::write(&path, text).expect("write test file");
    path
}

/// Runs `trilux info` on `text` and checks the one-line error: it must start
/// with `error: FILE:LINE:COL: ` and contain `what`, where LINE is `line` and
/// COL is where `marker` starts on that line (1-based, in characters).
fn assert_scene_error(name: &str, text: &str, line: u32, marker: &str, what: &str) {
    let in_line = text.lines().nth(line as usize - 1).expect("line exists");
    let byte = in_line.find(marker).expect("marker on the line");
    let col = in_line[..byte].chars().count() + 1;
    let dir = folder(name);
    let path = write(&dir, "scene.xml", text);
    let path_str = path.to_str().expect("utf-8 path");
    for extra in [&[][..], &["--json"][..]] {
        let mut args = vec!["info", path_str];
        args.extend_from_slice(extra);
        let out = trilux(&args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(
            out.status.code(),
            Some(1),
            "{name}: status; stderr: {stderr}"
        );
        assert!(out.stdout.is_empty(), "{name}: no output on error");
        assert_eq!(
            stderr.lines().count(),
            1,
            "{name}: exactly one line: {stderr}"
        );
        let prefix = format!("error: {path_str}:{line}:{col}: ");
        assert!(
            stderr.starts_with(&prefix),
            "{name}: {stderr:?} should start with {prefix:?}"
        );
        assert!(
            stderr.contains(what),
            "{name}: {stderr:?} should say {what:?}"
        );
    }
}

const HEAD: &str = "<scene version=\"3.0.0\">\n";

#[test]
fn malformed_xml() {
    assert_scene_error(
        "malformed",
        &format!("{HEAD}  <shape type=\"rectangle\">\n</scene>\n"),
        3,
        "</scene>",
        "malformed XML",
    );
    assert_scene_error("garbage", "not xml at all", 1, "not", "malformed XML");
}

#[test]
fn unknown_plugin() {
    assert_scene_error(
        "plugin",
        &format!("{HEAD}  <shape type=\"heightfield\"/>\n</scene>\n"),
        2,
        "heightfield",
        "unknown shape plugin \"heightfield\"",
    );
    assert_scene_error(
        "bsdf-plugin",
        &format!(
            "{HEAD}  <shape type=\"cube\">\n    <bsdf type=\"hair\"/>\n  </shape>\n</scene>\n"
        ),
        3,
        "hair",
        "unknown bsdf plugin \"hair\"",
    );
}

#[test]
fn unknown_parameter() {
    assert_scene_error(
        "parameter",
        &format!(
            "{HEAD}  <shape type=\"cube\">\n    <float name=\"size\" value=\"2\"/>\n  </shape>\n</scene>\n"
        ),
        3,
        "<float",
        "unknown parameter \"size\"",
    );
}

#[test]
fn missing_obj_file() {
    assert_scene_error(
        "obj",
        &format!(
            "{HEAD}  <shape type=\"obj\">\n    <string name=\"filename\" value=\"meshes/none.obj\"/>\n  </shape>\n</scene>\n"
        ),
        3,
        "<string",
        "cannot read OBJ file",
    );
}

#[test]
fn nan_value() {
    assert_scene_error(
        "nan",
        &format!(
            "{HEAD}  <shape type=\"sphere\"><float name=\"radius\" value=\"NaN\"/></shape>\n</scene>\n"
        ),
        2,
        "NaN",
        "NaN",
    );
}

#[test]
fn negative_values() {
    assert_scene_error(
        "negative-reflectance",
        &format!(
            "{HEAD}  <shape type=\"cube\">\n    <bsdf type=\"diffuse\"><rgb name=\"reflectance\" value=\"0.5, -0.2, 0.5\"/></bsdf>\n  </shape>\n</scene>\n"
        ),
        3,
        "<rgb",
        "reflectance must not be negative",
    );
    assert_scene_error(
        "negative-radiance",
        &format!(
            "{HEAD}  <shape type=\"rectangle\">\n    <emitter type=\"area\">\n      <float name=\"radiance\" value=\"-1\"/>\n    </emitter>\n  </shape>\n</scene>\n"
        ),
        4,
        "<float",
        "radiance must not be negative",
    );
}

#[test]
fn zero_area_shapes() {
    assert_scene_error(
        "zero-scale",
        &format!(
            "{HEAD}  <shape type=\"rectangle\">\n    <transform name=\"to_world\"><scale x=\"0\"/></transform>\n  </shape>\n</scene>\n"
        ),
        3,
        "<transform",
        "singular",
    );
    assert_scene_error(
        "zero-radius",
        &format!(
            "{HEAD}  <shape type=\"sphere\">\n    <float name=\"radius\" value=\"0\"/>\n  </shape>\n</scene>\n"
        ),
        3,
        "<float",
        "radius must be positive",
    );
    // A mesh whose triangles are all degenerate loads, as in Mitsuba, left
    // out with one warning line at its place (tests/loading_cli.rs).
    let dir = folder("zero-mesh");
    write(&dir, "line.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n");
    let path = write(
        &dir,
        "scene.xml",
        &format!(
            "{HEAD}  <shape type=\"obj\">\n    <string name=\"filename\" value=\"line.obj\"/>\n  </shape>\n</scene>\n"
        ),
    );
    let out = trilux(&["info", path.to_str().expect("utf-8")]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{stderr}");
    assert_eq!(stderr.lines().count(), 1);
    assert!(
        stderr.starts_with(&format!("warning: {}:2:3: ", path.display())),
        "{stderr}"
    );
    assert!(stderr.contains("zero area"), "{stderr}");
}

#[test]
fn missing_scene_file_is_one_line_status_1() {
    let out = trilux(&["info", "/nonexistent/scene.xml"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1));
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(
        stderr.starts_with("error: /nonexistent/scene.xml: "),
        "{stderr}"
    );
}

#[test]
fn usage_errors_exit_2() {
    for args in [
        &["info"][..],
        &["--bogus"][..],
        &["info", "x.xml", "--mode", "grey"][..],
    ] {
        let out = trilux(args);
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        assert!(String::from_utf8_lossy(&out.stderr).contains("error: "));
    }
    let out = trilux(&["info"]);
    assert!(String::from_utf8_lossy(&out.stderr).contains("Usage: trilux info"));
}

fn scenes_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes")
}

fn info_json(scene: &Path, extra: &[&str]) -> serde_json::Value {
    let mut args = vec!["info", scene.to_str().expect("utf-8"), "--json"];
    args.extend_from_slice(extra);
    let out = trilux(&args);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("JSON on stdout")
}

#[test]
fn info_json_has_exactly_the_design_keys() {
    let v = info_json(&scenes_dir().join("cornell-box.xml"), &[]);
    let mut keys: Vec<&str> = v
        .as_object()
        .expect("object")
        .keys()
        .map(String::as_str)
        .collect();
    keys.sort();
    assert_eq!(
        keys,
        [
            "bsdfs",
            "camera",
            "cameras",
            "emitted_power",
            "emitters",
            "input_surfaces",
            "lights",
            "mode",
            "shape_list",
            "shapes"
        ]
    );
    let mut camera: Vec<&str> = v["camera"]
        .as_object()
        .expect("camera")
        .keys()
        .map(String::as_str)
        .collect();
    camera.sort();
    assert_eq!(
        camera,
        [
            "fov", "fov_axis", "height", "origin", "target", "up", "width"
        ]
    );
    assert!(v["shapes"].is_u64() && v["input_surfaces"].is_u64() && v["emitters"].is_u64());
    assert_eq!(v["mode"], "spectral");
    assert_eq!(
        v["emitted_power"].as_array().map(Vec::len),
        Some(trilux_color::SPECTRAL_BANDS)
    );
}

/// `-D NAME=VALUE` sets a `$name` as Mitsuba's `-D` does: the Cornell box
/// writes its film as `$res` × `$res` with `<default name="res" value="256"/>`.
#[test]
fn defines_override_the_scenes_defaults() {
    let box_ = scenes_dir().join("cornell-box.xml");
    assert_eq!(info_json(&box_, &[])["camera"]["width"], 256);
    let v = info_json(&box_, &["-D", "res=96", "--define", "spp=4"]);
    assert_eq!(
        (&v["camera"]["width"], &v["camera"]["height"]),
        (&96.into(), &96.into())
    );
    for bad in ["res", "=96", "r-s=96"] {
        let out = trilux(&["info", box_.to_str().expect("utf-8"), "-D", bad]);
        assert_eq!(out.status.code(), Some(2), "-D {bad}");
    }
    let gltf = scenes_dir().join("product-shot.glb");
    let out = trilux(&["info", gltf.to_str().expect("utf-8"), "-D", "res=96"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("$name parameters are for Mitsuba XML scenes"),
        "{stderr}"
    );
}

#[test]
fn info_json_for_the_cornell_box() {
    let v = info_json(&scenes_dir().join("cornell-box.xml"), &["--mode", "rgb"]);
    assert_eq!(v["shapes"], 8);
    // One input surface per rectangle, one per cube face (docs/architecture.md, "Meshes").
    assert_eq!(v["input_surfaces"], 6 + 2 * 6);
    assert_eq!(v["emitters"], 1);
    assert_eq!(v["bsdfs"], serde_json::json!({ "diffuse": 3 }));
    assert_eq!(v["mode"], "rgb");
    assert_eq!(v["camera"]["origin"], serde_json::json!([0.0, 0.0, 3.9]));
    assert_eq!(v["camera"]["target"], serde_json::json!([0.0, 0.0, 0.0]));
    assert_eq!(v["camera"]["up"], serde_json::json!([0.0, 1.0, 0.0]));
    assert_eq!(v["camera"]["fov"], 39.3077);
    assert_eq!(v["camera"]["fov_axis"], "smaller");
    assert_eq!(
        (
            v["camera"]["width"].as_u64(),
            v["camera"]["height"].as_u64()
        ),
        (Some(256), Some(256))
    );
    // π · A · L: the light is 0.46 × 0.38 (Mitsuba's area 0.1748) and the
    // classic light spectrum is linear sRGB (20.7108, 10.8546, 2.77115)
    // (Mitsuba 3.9's value). 1e-4 relative: the check value's digits.
    let power = v["emitted_power"].as_array().expect("array");
    for (p, l) in power.iter().zip([20.7108, 10.8546, 2.77115]) {
        let want = std::f64::consts::PI * 0.1748 * l;
        let got = p.as_f64().expect("number");
        assert!((got - want).abs() <= 1e-4 * want, "{got} vs {want}");
    }
}

#[test]
fn info_json_for_the_furnace() {
    let v = info_json(&scenes_dir().join("furnace.xml"), &[]);
    assert_eq!(v["shapes"], 1);
    assert_eq!(v["input_surfaces"], 6);
    assert_eq!(v["emitters"], 1);
    assert_eq!(v["mode"], "rgb");
    // Six inner faces of 2 × 2, radiance 1: π · 24 W per band.
    for p in v["emitted_power"].as_array().expect("array") {
        assert!((p.as_f64().expect("number") - std::f64::consts::PI * 24.0).abs() < 1e-9);
    }
    let s = info_json(&scenes_dir().join("furnace.xml"), &["--mode", "spectral"]);
    assert_eq!(s["mode"], "spectral");
    assert_eq!(
        s["emitted_power"].as_array().map(Vec::len),
        Some(trilux_color::SPECTRAL_BANDS)
    );
}

#[test]
fn no_arguments_renders_the_default_scene_into_out() {
    let dir = folder("no-arguments");
    let out = Command::new(env!("CARGO_BIN_EXE_trilux"))
        .current_dir(&dir)
        .output()
        .expect("runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    for file in ["cornell-box.exr", "cornell-box.png", "cornell-box.json"] {
        assert!(dir.join("out").join(file).exists(), "out/{file} written");
    }
    assert!(String::from_utf8_lossy(&out.stdout).contains("out/cornell-box.exr"));
}

/// The README's main command is a plain `cargo run --release`: in a
/// workspace with two binaries (trilux, xtask) that only works when the
/// `trilux` crate is the workspace's default member.
#[test]
fn cargo_run_means_the_trilux_command() {
    let manifest =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("../../Cargo.toml"))
            .expect("workspace manifest");
    assert!(
        manifest.contains("default-members = [\"crates/trilux\"]"),
        "the workspace must name crates/trilux as its default member"
    );
}
