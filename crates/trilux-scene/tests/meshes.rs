//! A large OBJ through the loader: the 8 192-triangle sheet of the
//! foundation issue's chart test (64 × 64 quads, each split in two).
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test, bench or example may panic

use std::fmt::Write as _;
use std::path::Path;

use trilux_geometry::ShapeKind;

#[test]
fn sheet_of_8192_triangles_loads_as_a_few_input_surfaces() {
    let n = 64;
    let mut obj = String::from("# 64 x 64 quads in z = 0, slightly waved in z\n");
    for j in 0..=n {
        for i in 0..=n {
            let (x, y) = (i as f64 / n as f64, j as f64 / n as f64);
            let z = 0.05 * (6.0 * x).sin() * (4.0 * y).cos();
            let _ = writeln!(obj, "v {x} {y} {z}");
        }
    }
    let id = |i: usize, j: usize| j * (n + 1) + i + 1;
    for j in 0..n {
        for i in 0..n {
            let _ = writeln!(
                obj,
                "f {} {} {} {}",
                id(i, j),
                id(i + 1, j),
                id(i + 1, j + 1),
                id(i, j + 1)
            );
        }
    }
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("scene-sheet");
    std::fs::create_dir_all(&dir).expect("temp folder");
    std::fs::write(dir.join("sheet.obj"), obj).expect("write OBJ");
    let scene = trilux_scene::load_str(
        r#"<scene version="3.0.0"><shape type="obj"><string name="filename" value="sheet.obj"/></shape></scene>"#,
        dir.join("sheet.xml"),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let ShapeKind::Mesh(mesh) = &scene.shapes[0].shape.kind else {
        panic!("a mesh");
    };
    // Quads triangulate as fans: 2 triangles each; vertices are shared.
    assert_eq!(mesh.triangles.len(), 8192);
    assert_eq!(mesh.positions.len(), 65 * 65);
    // No vn in the file: smooth normals, all facing +z more or less.
    assert!(
        mesh.normals
            .as_ref()
            .expect("normals")
            .iter()
            .all(|n| n.z > 0.5)
    );
    let geometry = scene.build_geometry().unwrap_or_else(|e| panic!("{e}"));
    let surfaces = geometry.surfaces().len();
    // Charts, not triangles: a handful of input surfaces (docs/architecture.md, "Meshes").
    assert!((1..=64).contains(&surfaces), "{surfaces} input surfaces");
}
