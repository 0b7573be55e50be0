//! Extents and units through the binary: scenes beyond the
//! float pipeline's range are refused with their location, and within the
//! documented range (docs/limits.md) the image does not depend on the
//! scene's unit.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test may panic

use std::path::Path;
use std::process::Output;

mod common;
use common::hostile::{assert_refused, s};
use common::{folder, trilux};

/// A closed box (reflectance 0.5, emitting 1) holding a smaller box, seen
/// from inside; every length is multiplied by `scale` and the whole is
/// moved by `offset` along x.
fn scene(scale: f64, offset: f64) -> String {
    let p = |v: f64| format!("{:e}", v * scale);
    let x = |v: f64| format!("{:e}", v * scale + offset);
    format!(
        r#"<scene version="3.0.0">
  <sensor type="perspective">
    <float name="fov" value="70"/>
    <transform name="to_world"><lookat origin="{},{},{}" target="{},{},{}" up="0,1,0"/></transform>
    <sampler type="independent"><integer name="sample_count" value="4"/></sampler>
    <film type="hdrfilm"><integer name="width" value="16"/><integer name="height" value="16"/></film>
  </sensor>
  <shape type="cube"><boolean name="flip_normals" value="true"/>
    <transform name="to_world"><scale value="{}"/><translate x="{}"/></transform>
    <bsdf type="diffuse"><float name="reflectance" value="0.5"/></bsdf>
    <emitter type="area"><float name="radiance" value="1.0"/></emitter>
  </shape>
  <shape type="cube">
    <transform name="to_world"><scale value="{}"/><translate x="{}" y="{}"/></transform>
    <bsdf type="diffuse"><float name="reflectance" value="0.8"/></bsdf>
  </shape>
</scene>
"#,
        x(0.0),
        p(0.2),
        p(0.8),
        x(0.1),
        p(-0.1),
        p(-1.0),
        p(1.0),
        x(0.0),
        p(0.3),
        x(0.2),
        p(-0.5),
    )
}

fn render(dir: &Path, name: &str, text: &str) -> (Output, std::path::PathBuf) {
    let path = dir.join(format!("{name}.xml"));
    std::fs::write(&path, text).unwrap();
    let exr = dir.join(format!("{name}.exr"));
    let out = trilux(&["render", s(&path), "-o", s(&exr), "--quality", "draft"]);
    (out, exr)
}

#[test]
fn unit_range() {
    let dir = folder("unit-range");
    let image = |name: &str, scale: f64, offset: f64| {
        let (out, exr) = render(&dir, name, &scene(scale, offset));
        assert!(
            out.status.success(),
            "{name}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        trilux_render::Image::read_exr(&exr).unwrap()
    };
    let unit = image("unit", 1.0, 0.0);
    // The ends of the documented range: the scene's diagonal (about 3.5 ×
    // scale) down to 1e-6, its coordinates up to 1e15, its offset up to
    // 1e5 times its size.
    for (name, scale, offset) in [
        ("small", 3e-7, 0.0),
        ("large", 5e14, 0.0),
        ("far", 1.0, 3e5),
    ] {
        let img = image(name, scale, offset);
        let c = trilux_render::compare(&img, &unit, None).unwrap();
        assert!(
            c.rel_rmse < 0.01 && (c.mean_ratio - 1.0).abs() < 1e-3,
            "{name}: {c:?}"
        );
    }
}

#[test]
fn scenes_beyond_the_range_are_refused_at_their_place() {
    let dir = folder("unit-refused");
    let (out, _) = render(&dir, "tiny", &scene(1e-7, 0.0));
    assert_refused(
        &out,
        &format!("{}:8:3: ", s(&dir.join("tiny.xml"))),
        "the whole scene is 3.464e-7 across",
    );
    let (out, _) = render(&dir, "huge", &scene(1e16, 0.0));
    let huge = s(&dir.join("huge.xml")).to_owned();
    // Three independent errors, each reported at its place in one run: the
    // sensor's origin and the two shapes' transforms.
    assert_eq!(out.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&out.stderr);
    let lines: Vec<&str> = stderr.lines().collect();
    assert_eq!(lines.len(), 3, "three errors: {stderr}");
    for (line, (place, what)) in lines.iter().zip([
        (
            4,
            "<lookat> origin: coordinate 8e15 is beyond the coordinate limit ±1e15",
        ),
        (
            9,
            "to_world scales or moves by 1e16, beyond the coordinate limit ±1e15",
        ),
        (
            14,
            "to_world scales or moves by 5e15, beyond the coordinate limit ±1e15",
        ),
    ]) {
        assert!(
            line.starts_with(&format!("error: {huge}:{place}:")),
            "{line}"
        );
        assert!(line.contains(what), "{line} should say {what}");
    }
    let text = "<scene version=\"3.0.0\">\n  <shape type=\"rectangle\"><transform name=\"to_world\"><scale value=\"1e19\"/></transform></shape>\n</scene>\n";
    std::fs::write(&huge, text).unwrap();
    let out = trilux(&["info", &huge]);
    assert_refused(
        &out,
        &format!("{huge}:2:"),
        "to_world scales or moves by 1e19, beyond the coordinate limit ±1e15",
    );
    // 1e6 from the origin is 2.9e5 times the scene's size.
    let (out, _) = render(&dir, "offset", &scene(1.0, 1e6));
    assert_refused(
        &out,
        &format!("{}:8:3: ", s(&dir.join("offset.xml"))),
        "move the scene nearer the origin",
    );
    // The BVH crash of 1e19 and of OBJ coordinates of 1e30.
    let obj = dir.join("huge.obj");
    std::fs::write(
        &obj,
        "v 0 0 0\nv 1e30 0 0\nv 0 1e30 0\nv 0 0 1e30\nf 1 2 3\nf 1 2 4\nf 1 3 4\n",
    )
    .unwrap();
    let text = "<scene version=\"3.0.0\">\n  <shape type=\"obj\"><string name=\"filename\" value=\"huge.obj\"/></shape>\n</scene>\n";
    let path = dir.join("obj.xml");
    std::fs::write(&path, text).unwrap();
    for cmd in ["info", "solve"] {
        let mut args = vec![cmd, s(&path)];
        let sol = dir.join("x.sol");
        if cmd == "solve" {
            args.extend(["-o", s(&sol)]);
        }
        let out = trilux(&args);
        assert_refused(
            &out,
            &format!("{}:2:3: ", s(&path)),
            "the shape reaches coordinate 1.000e30",
        );
    }
    let text = "<scene version=\"3.0.0\">\n  <shape type=\"sphere\"><float name=\"radius\" value=\"1e19\"/></shape>\n</scene>\n";
    std::fs::write(&path, text).unwrap();
    let out = trilux(&["info", s(&path)]);
    assert_refused(
        &out,
        &format!("{}:2:3: ", s(&path)),
        "beyond the coordinate limit",
    );
}
