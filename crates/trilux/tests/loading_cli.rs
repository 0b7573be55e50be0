//! Scenes as Mitsuba loads them, through the binary: `serialized` meshes
//! (areas against the analytic ones, bad files refused in one located
//! line), and meshes with zero-area parts or of zero area (loaded with a
//! warning line, the parts left out: a closed furnace keeps its analytic
//! radiance Le / (1 − ρ)).
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test may panic

use std::f64::consts::PI;
use std::path::Path;
use std::process::Output;

mod common;
use common::hostile::{assert_ok, assert_refused, furnace, s, write};
use common::serialized::{Mesh, file, mesh_data, zlib_stored};
use common::{folder, trilux};

const TRIANGLE: Mesh<'static> = Mesh {
    positions: &[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
    triangles: &[[0, 1, 2]],
    texcoords: None,
    double: false,
};

/// A 2 × 3 rectangle, in doubles, with texture coordinates.
const QUAD: Mesh<'static> = Mesh {
    positions: &[
        [0.0, 0.0, 0.0],
        [2.0, 0.0, 0.0],
        [2.0, 3.0, 0.0],
        [0.0, 3.0, 0.0],
    ],
    triangles: &[[0, 1, 2], [0, 2, 3]],
    texcoords: Some(&[[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]),
    double: true,
};

/// A scene of one `serialized` shape with `params` (line 3 onwards), lit
/// by radiance 1.
fn scene(params: &str) -> String {
    format!(
        "<scene version=\"3.0.0\">\n  <shape type=\"serialized\">\n{params}\n    <emitter type=\"area\"><float name=\"radiance\" value=\"1\"/></emitter>\n  </shape>\n</scene>\n"
    )
}

fn filename(name: &str) -> String {
    format!("    <string name=\"filename\" value=\"{name}\"/>")
}

/// The emitted power `trilux info --json` reports (equal in every band).
fn power(out: &Output) -> f64 {
    assert_ok(out);
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    json["emitted_power"][0].as_f64().unwrap()
}

/// A Lambertian emitter of radiance 1 and area A emits πA.
#[test]
fn serialized_meshes_emit_from_their_analytic_areas() {
    let dir = folder("serialized-areas");
    let two = file(&[mesh_data(&TRIANGLE), mesh_data(&QUAD)]);
    write(&dir, "two.serialized", two);
    let cases = [
        (filename("two.serialized"), 0.5),
        (
            format!(
                "{}\n    <integer name=\"shape_index\" value=\"1\"/>",
                filename("two.serialized")
            ),
            6.0,
        ),
        // Scaled by 2: four times the area; the checkerboard needs the
        // file's texture coordinates.
        (
            format!(
                "{}\n    <integer name=\"shape_index\" value=\"1\"/>\n    <transform name=\"to_world\"><scale value=\"2\"/></transform>\n    <bsdf type=\"diffuse\"><texture type=\"checkerboard\" name=\"reflectance\"/></bsdf>",
                filename("two.serialized")
            ),
            24.0,
        ),
    ];
    for (params, area) in cases {
        let path = write(&dir, "scene.xml", scene(&params));
        let got = power(&trilux(&["info", "--json", s(&path)]));
        assert!((got / (PI * area) - 1.0).abs() < 1e-6, "{params}: {got}");
    }
}

/// Every malformed file is one line `error: FILE:LINE:COL: ...`, status 1,
/// at the `<string name="filename">` (line 3) or the `shape_index` (line 4).
#[test]
fn bad_serialized_files_are_refused_in_one_located_line() {
    let dir = folder("serialized-bad");
    let good = file(&[mesh_data(&TRIANGLE), mesh_data(&QUAD)]);
    let mut magic = good.clone();
    magic[0] = 0x1D;
    let mut version = good.clone();
    version[2] = 5;
    let truncated = good[..30].to_vec();
    // Counts of 2^40 vertices, the stream then running on (a bomb): refused
    // at the counts, before any allocation for them.
    let mut bomb = 0x1000u32.to_le_bytes().to_vec();
    bomb.extend(b"\0");
    bomb.extend((1u64 << 40).to_le_bytes());
    bomb.extend(1u64.to_le_bytes());
    bomb.extend(vec![0; 1 << 20]);
    let bomb = file(&[bomb]);
    let index = file(&[mesh_data(&Mesh {
        triangles: &[[0, 1, 3]],
        ..TRIANGLE
    })]);
    let mut corrupt = file(&[mesh_data(&TRIANGLE)]);
    corrupt[4] = 0x00; // the zlib header
    let cases: [(&str, Vec<u8>, &str, u32, &str); 8] = [
        ("magic", magic, "", 3, "not a serialized mesh"),
        ("version", version, "", 3, "version 5"),
        ("truncated", truncated, "", 3, "the data ends early"),
        ("bomb", bomb, "", 3, "the limits are 4000000 triangles"),
        (
            "index",
            index,
            "",
            3,
            "refers to vertex 3, but the mesh has 3 vertices",
        ),
        ("corrupt", corrupt, "", 3, "corrupt"),
        (
            "range",
            good.clone(),
            "2",
            3,
            "shape_index 2 is out of range: the file holds 2 meshes",
        ),
        (
            "negative",
            good,
            "-1",
            4,
            "shape_index must be a mesh index",
        ),
    ];
    for (name, bytes, index, line, what) in cases {
        let mesh = write(&dir, &format!("{name}.serialized"), bytes);
        let mut params = filename(s(&mesh));
        if !index.is_empty() {
            params += &format!("\n    <integer name=\"shape_index\" value=\"{index}\"/>");
        }
        let path = write(&dir, &format!("{name}.xml"), scene(&params));
        let out = trilux(&["info", s(&path)]);
        assert_refused(&out, &format!("{}:{line}:5: ", s(&path)), what);
    }
    let path = write(&dir, "missing.xml", scene(&filename("none.serialized")));
    let out = trilux(&["info", s(&path)]);
    assert_refused(
        &out,
        &format!("{}:3:5: ", s(&path)),
        "cannot read serialized file",
    );
}

/// A mesh with a triangle of zero area and a mesh of zero area: the scene
/// loads, one warning line for each, the flat mesh is left out, the area
/// of the other is that of its one real triangle (power π · 0.5).
#[test]
fn zero_area_parts_load_with_a_warning_line() {
    let dir = folder("zero-area");
    write(
        &dir,
        "part.obj",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 0 0\nf 1 2 3\nf 1 2 4\n",
    );
    let flat = Mesh {
        positions: &[[0.0, 0.0, 0.0], [1.0, 1.0, 1.0], [3.0, 3.0, 3.0]],
        ..TRIANGLE
    };
    write(&dir, "flat.serialized", file(&[mesh_data(&flat)]));
    let text = "<scene version=\"3.0.0\">\n  <shape type=\"obj\">\n    <string name=\"filename\" value=\"part.obj\"/>\n    <emitter type=\"area\"><float name=\"radiance\" value=\"1\"/></emitter>\n  </shape>\n  <shape type=\"serialized\">\n    <string name=\"filename\" value=\"flat.serialized\"/>\n  </shape>\n</scene>\n";
    let path = write(&dir, "scene.xml", text);
    let out = trilux(&["info", "--json", s(&path)]);
    assert!((power(&out) / (PI * 0.5) - 1.0).abs() < 1e-9);
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(json["shapes"], 1);
    let stderr = String::from_utf8_lossy(&out.stderr);
    let lines: Vec<&str> = stderr.lines().collect();
    assert_eq!(lines.len(), 2, "{stderr}");
    assert!(lines[0].starts_with(&format!("warning: {}:2:3: 1 of the 2 triangles", s(&path))));
    assert!(lines[1].starts_with(&format!("warning: {}:6:3: every triangle", s(&path))));
    // An emitter on the flat mesh has nothing to emit from: refused, as
    // Mitsuba refuses it.
    let lit = text.replace(
        "flat.serialized\"/>\n",
        "flat.serialized\"/>\n    <emitter type=\"area\"/>\n",
    );
    let path = write(&dir, "lit.xml", lit);
    let out = trilux(&["info", s(&path)]);
    assert_refused(
        &out,
        &format!("{}:8:5: ", s(&path)),
        "no surface to emit from",
    );
}

/// The furnace (a closed box of ρ = 0.5 emitting Le = 1: L = 2 everywhere)
/// made of an OBJ cube with one flat triangle more, and a zero-area mesh
/// inside: the image is the one of the same cube without them (the parts
/// are left out before anything is built, so the solve and the render are
/// the same, to 1e-6 for summation order), and near 2. (Face normals:
/// smooth ones, recomputed across the cube's edges, would tilt the shading
/// and lose energy.)
#[test]
fn zero_area_parts_leave_a_furnace_unchanged() {
    let dir = folder("zero-area-furnace");
    let flat = Mesh {
        positions: &[[0.0, 0.0, 0.0], [0.1, 0.1, 0.1], [0.3, 0.3, 0.3]],
        ..TRIANGLE
    };
    write(&dir, "flat.serialized", file(&[mesh_data(&flat)]));
    // Mitsuba's cube [-1, 1]³, faces wound outward, and a triangle along
    // the edge from vertex 1 to vertex 2.
    let corners = "v -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\nv -1 -1 1\nv 1 -1 1\nv 1 1 1\nv -1 1 1\nv 0 -1 -1\n";
    let faces = "f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 4 8 7 3\nf 1 5 8 4\nf 2 3 7 6\n";
    write(&dir, "box.obj", format!("{corners}{faces}f 1 2 9\n"));
    write(&dir, "plain.obj", format!("{corners}{faces}"));
    let scene = |obj: &str, inside: &str| {
        furnace("0.5", "1", 1.0)
            .replace(
                "<shape type=\"cube\">",
                &format!("<shape type=\"obj\"><string name=\"filename\" value=\"{obj}\"/><boolean name=\"face_normals\" value=\"true\"/>"),
            )
            .replace("</scene>", &format!("{inside}</scene>"))
    };
    let inside = "  <shape type=\"serialized\"><string name=\"filename\" value=\"flat.serialized\"/></shape>\n";
    let render = |name: &str, text: String| {
        let path = write(&dir, &format!("{name}.xml"), text);
        let exr = dir.join(format!("{name}.exr"));
        let out = trilux(&["render", s(&path), "-o", s(&exr), "--quality", "draft"]);
        assert_ok(&out);
        (
            String::from_utf8_lossy(&out.stderr).into_owned(),
            image_mean(&exr),
        )
    };
    let (stderr, mean) = render("furnace", scene("box.obj", inside));
    assert!(stderr.contains("1 of the 13 triangles"), "{stderr}");
    assert_eq!(stderr.matches("warning: ").count(), 2, "{stderr}");
    let (_, plain) = render("plain", scene("plain.obj", ""));
    for (m, p) in mean.iter().zip(plain) {
        assert!((m / p - 1.0).abs() < 1e-6, "{mean:?} against {plain:?}");
    }
    // Draft quality's furnace is 0.44 % low (its convergence stop and
    // coarse elements): within 1 % of L = 2.
    assert!(
        mean.iter().all(|m| (m / 2.0 - 1.0).abs() < 0.01),
        "{mean:?}"
    );
}

fn image_mean(exr: &Path) -> [f64; 3] {
    trilux_render::Image::read_exr(exr).unwrap().mean()
}

/// The hand-written zlib is zlib: a stored stream of the empty input is
/// RFC 1950's fixed 11 bytes.
#[test]
fn the_test_writer_makes_rfc_1950_streams() {
    assert_eq!(
        zlib_stored(&[]),
        [
            0x78, 0x01, 0x01, 0x00, 0x00, 0xFF, 0xFF, 0x00, 0x00, 0x00, 0x01
        ]
    );
}
