//! Small files whose loading once grew faster than their size, through
//! the binary: a scene of 10 000 emitters (each element's line counted
//! from the start of the file), 200 000 copies of one triangle (chart
//! building and the BVH's passes quadratic, 8 GiB asked for), a polygon
//! of 250 000 vertices (fanned into slivers: the BVH's passes quadratic;
//! now cut in halves), and a glTF file placing one mesh 100 001 times and
//! an XML scene of 100 001 shapes (refused at the node or shape that
//! passes the shape limit). That the work is linear is tested where it is
//! done, by counting it: `xml::tests` (bytes scanned), `chart::tests`
//! (neighbours visited), `bvh::ploc::tests` (nodes visited) and
//! `obj::tests` (the triangles' summed extents); here each case must
//! finish, or be refused with one located line, well inside a generous
//! guard against a hang.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test may panic

use std::fmt::Write as _;
use std::time::Duration;

mod common;
use common::hostile::{assert_ok, assert_refused, s, trilux_or_hang, write};
use common::{folder, trilux};

/// A guard against a hang, not a speed figure: each case takes well under
/// a second in release (docs/results.md, "Hostile inputs").
const GUARD: Duration = Duration::from_secs(60);

const SENSOR: &str = r#"<sensor type="perspective"><transform name="to_world"><lookat origin="0.3,0.3,5" target="0.3,0.3,0" up="0,1,0"/></transform><film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/></film><sampler type="independent"><integer name="sample_count" value="1"/></sampler></sensor>"#;

#[test]
fn a_ceiling_of_ten_thousand_emitters_loads() {
    let dir = folder("growth-emitters");
    let mut text = format!("<scene version=\"3.0.0\">\n{SENSOR}\n");
    for i in 0..10_000 {
        writeln!(
            text,
            r#"<shape type="rectangle"><transform name="to_world"><translate value="{},{},3"/></transform><emitter type="area"><rgb name="radiance" value="1"/></emitter></shape>"#,
            i % 100,
            i / 100
        )
        .unwrap();
    }
    text += "</scene>\n";
    assert!(text.len() > 1_500_000);
    let scene = write(&dir, "ceiling.xml", text);
    // `info` prints a line a shape, more than a pipe holds: read as it
    // comes (`trilux_or_hang` reads once the command ends).
    let out = trilux(&["info", s(&scene)]);
    assert_ok(&out);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("emitters       10000"), "{stdout}");
}

/// An OBJ scene of `obj` with an emitting mesh, rendered on 8 × 8 pixels.
fn render_obj(name: &str, obj: Vec<u8>) {
    let dir = folder(name);
    write(&dir, "mesh.obj", obj);
    let scene = write(
        &dir,
        "scene.xml",
        format!(
            "<scene version=\"3.0.0\">\n{SENSOR}\n<shape type=\"obj\"><string name=\"filename\" value=\"mesh.obj\"/><emitter type=\"area\"><rgb name=\"radiance\" value=\"1\"/></emitter></shape>\n</scene>\n"
        ),
    );
    let exr = dir.join("out.exr");
    let out = trilux_or_hang(
        &["render", s(&scene), "-o", s(&exr), "--quality", "draft"],
        GUARD,
    );
    assert_ok(&out);
    assert!(exr.exists());
}

#[test]
fn two_hundred_thousand_copies_of_a_triangle_render() {
    let mut obj = b"v 0 0 0\nv 1 0 0\nv 0 1 0\n".to_vec();
    obj.extend(b"f 1 2 3\n".repeat(200_000));
    assert_eq!(obj.len(), 1_600_024);
    render_obj("growth-copies", obj);
}

#[test]
fn a_polygon_of_a_quarter_million_vertices_loads() {
    let dir = folder("growth-polygon");
    let n = 250_000;
    let mut obj = String::new();
    for i in 0..n {
        let a = std::f64::consts::TAU * f64::from(i) / f64::from(n);
        writeln!(obj, "v {:.9} {:.9} 0", a.cos(), a.sin()).unwrap();
    }
    obj += "f";
    for i in 1..=n {
        write!(obj, " {i}").unwrap();
    }
    obj += "\n";
    write(&dir, "polygon.obj", obj);
    let scene = write(
        &dir,
        "scene.xml",
        format!(
            "<scene version=\"3.0.0\">\n{SENSOR}\n<shape type=\"obj\"><string name=\"filename\" value=\"polygon.obj\"/></shape>\n</scene>\n"
        ),
    );
    let out = trilux_or_hang(&["info", s(&scene)], GUARD);
    assert_ok(&out);
    let stdout = String::from_utf8_lossy(&out.stdout);
    // n − 2 triangles, less those of zero area (the slivers halving makes
    // near the circle), which the warning counts.
    let stderr = String::from_utf8_lossy(&out.stderr);
    let dropped: usize = stderr
        .strip_prefix("warning: ")
        .and_then(|w| w.split(": ").nth(1))
        .and_then(|w| w.split(' ').next())
        .and_then(|c| c.parse().ok())
        .unwrap_or(0);
    if dropped > 0 {
        assert!(stderr.contains("of the 249998 triangles"), "{stderr}");
    }
    let kept = 249_998 - dropped;
    assert!(
        stdout.contains(&format!("({kept} triangles)")),
        "{stdout}\n{stderr}"
    );
}

#[test]
fn a_mesh_placed_by_too_many_nodes_is_refused_at_the_node() {
    let dir = folder("growth-nodes");
    // One triangle (positions, then u16 indices) as a data URI.
    let mut buf = Vec::new();
    for v in [0f32, 0., 0., 1., 0., 0., 0., 1., 0.] {
        buf.extend(v.to_le_bytes());
    }
    for i in [0u16, 1, 2, 0] {
        buf.extend(i.to_le_bytes());
    }
    let uri = format!("data:application/octet-stream;base64,{}", base64(&buf));
    let n = 100_001;
    let mut nodes = String::new();
    for i in 0..n {
        if i > 0 {
            nodes.push(',');
        }
        write!(
            nodes,
            r#"{{"mesh":0,"translation":[{},{},0]}}"#,
            2 * (i % 1000),
            2 * (i / 1000)
        )
        .unwrap();
    }
    let roots: Vec<String> = (0..n).map(|i| i.to_string()).collect();
    let gltf = format!(
        r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[{}]}}],"nodes":[{nodes}],"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"indices":1}}]}}],"accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}},{{"bufferView":1,"componentType":5123,"count":3,"type":"SCALAR"}}],"bufferViews":[{{"buffer":0,"byteOffset":0,"byteLength":36}},{{"buffer":0,"byteOffset":36,"byteLength":6}}],"buffers":[{{"byteLength":{},"uri":"{uri}"}}]}}"#,
        roots.join(","),
        buf.len()
    );
    let file = write(&dir, "nodes.gltf", gltf);
    let out = trilux_or_hang(&["info", s(&file)], GUARD);
    assert_refused(
        &out,
        &format!("{}:/nodes/100000:", s(&file)),
        "more than 100000 mesh primitives (shapes), the limit",
    );
}

#[test]
fn a_scene_of_too_many_shapes_is_refused_at_the_shape() {
    let dir = folder("growth-shapes");
    let mut text = String::from("<scene version=\"3.0.0\">\n");
    text += &"<shape type=\"rectangle\"/>\n".repeat(100_001);
    text += "</scene>\n";
    let scene = write(&dir, "shapes.xml", text);
    let out = trilux_or_hang(&["info", s(&scene)], GUARD);
    assert_refused(
        &out,
        &format!("{}:100002:1:", s(&scene)),
        "more than 100000 shapes, the limit",
    );
}

/// Standard base64 with padding.
fn base64(bytes: &[u8]) -> String {
    const A: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::new();
    for c in bytes.chunks(3) {
        let b = [c[0], *c.get(1).unwrap_or(&0), *c.get(2).unwrap_or(&0)];
        let v = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        for k in 0..4 {
            if k <= c.len() {
                out.push(A[(v >> (18 - 6 * k)) as usize & 63] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}
