//! Load a scene and print a summary.
//!
//! ```sh
//! cargo run -p trilux-scene --example summary -- scenes/cornell-box.xml
//! ```
//! Without an argument it loads the bundled Cornell box.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test, bench or example may panic

use std::path::PathBuf;
use std::process::ExitCode;

use trilux_geometry::ShapeKind;
use trilux_scene::surface_area;

fn main() -> ExitCode {
    let path = std::env::args_os().nth(1).map_or_else(
        || PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenes/cornell-box.xml"),
        PathBuf::from,
    );
    let scene = match trilux_scene::load(&path) {
        Ok(s) => s,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::FAILURE;
        }
    };
    println!(
        "{}: {} shapes, mode {}",
        path.display(),
        scene.shapes.len(),
        scene.mode().name()
    );
    for s in &scene.shapes {
        let kind = match &s.shape.kind {
            ShapeKind::Rectangle => "rectangle",
            ShapeKind::Cube => "cube",
            ShapeKind::Disk => "disk",
            ShapeKind::Sphere { .. } => "sphere",
            ShapeKind::Cylinder { .. } => "cylinder",
            ShapeKind::Mesh(_) => "mesh",
        };
        println!(
            "  line {:4}  {:10} {:12} area {:8.4}{}",
            s.location.line,
            kind,
            s.id.as_deref().unwrap_or("-"),
            surface_area(&s.shape),
            match &s.emitter {
                Some(e) => format!("  emits {:?}", e.radiance),
                None => String::new(),
            }
        );
    }
    if let Some(c) = &scene.camera {
        println!(
            "camera at {} looking at {}, fov {}° ({}), {}x{}, {} spp",
            c.origin,
            c.target,
            c.fov,
            c.fov_axis.name(),
            c.width,
            c.height,
            c.sample_count
        );
    }
    ExitCode::SUCCESS
}
