//! The bundled scenes in scenes/ load, with the structure their files state
//! (areas from Mitsuba 3's `surface_area` of the same shapes: see
//! scenes/check_mitsuba.py, whose output lists them).
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test, bench or example may panic

use std::path::PathBuf;

use trilux_brdf::BsdfParams;
use trilux_color::{ColorParam, Mode};
use trilux_geometry::ShapeKind;
use trilux_scene::{FovAxis, load, surface_area};

fn scenes() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenes")
}

#[test]
fn every_bundled_scene_loads() {
    let mut n = 0;
    for entry in std::fs::read_dir(scenes()).expect("scenes/") {
        let path = entry.expect("entry").path();
        if path.extension().is_some_and(|e| e == "xml") {
            let scene = load(&path).unwrap_or_else(|e| panic!("{e}"));
            assert!(!scene.shapes.is_empty(), "{}", path.display());
            assert!(scene.emitters().count() > 0, "{}", path.display());
            n += 1;
        }
    }
    assert!(n >= 2);
}

#[test]
fn cornell_box() {
    let s = load(scenes().join("cornell-box.xml")).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(s.shapes.len(), 8);
    assert_eq!(s.mode(), Mode::Spectral);
    assert_eq!(s.max_depth, Some(-1));
    let ids: Vec<&str> = s.shapes.iter().filter_map(|x| x.id.as_deref()).collect();
    assert_eq!(
        ids,
        [
            "light",
            "floor",
            "ceiling",
            "back",
            "green-wall",
            "red-wall",
            "small-box",
            "large-box"
        ]
    );
    // Mitsuba 3: light 0.1748, green and red walls 4 each, the white shapes
    // together 17.808 (Mitsuba merges them into one mesh).
    let area = |id: &str| {
        surface_area(
            &s.shapes
                .iter()
                .find(|x| x.id.as_deref() == Some(id))
                .expect(id)
                .shape,
        )
    };
    assert!((area("light") - 0.1748).abs() < 1e-9);
    assert!((area("green-wall") - 4.0).abs() < 1e-9);
    assert!((area("red-wall") - 4.0).abs() < 1e-9);
    let white: f64 = ["floor", "ceiling", "back", "small-box", "large-box"]
        .iter()
        .map(|id| area(id))
        .sum();
    assert!((white - 17.808).abs() < 1e-6, "{white}");
    // The light faces down (-y), 0.01 below the ceiling.
    let light = &s.shapes[0];
    let n = light
        .shape
        .world_from_object
        .transform_vector3(glam::DVec3::Z)
        .normalize();
    assert!(n.distance(-glam::DVec3::Y) < 1e-12, "{n}");
    assert!(
        (light
            .shape
            .world_from_object
            .transform_point3(glam::DVec3::ZERO)
            .y
            - 0.99)
            .abs()
            < 1e-12
    );
    assert_eq!(
        light.emitter.as_ref().map(|e| e.radiance.clone()),
        Some(ColorParam::Sampled(vec![
            (400.0, 0.0),
            (500.0, 8.0),
            (600.0, 15.6),
            (700.0, 18.4)
        ]))
    );
    // The classic measured white: 76 samples from 400 to 700 nm every 4 nm.
    let BsdfParams::Diffuse {
        reflectance: ColorParam::Sampled(white),
    } = &s.shapes[1].bsdf
    else {
        panic!("white is a sampled diffuse reflectance");
    };
    assert_eq!(white.len(), 76);
    assert_eq!(white[0], (400.0, 0.343));
    assert_eq!(white[75], (700.0, 0.737));
    assert!(matches!(s.shapes[6].shape.kind, ShapeKind::Cube));
    let c = s.camera.expect("camera");
    assert_eq!(
        (c.fov, c.fov_axis, c.width, c.height, c.sample_count),
        (39.3077, FovAxis::Smaller, 256, 256, 64)
    );
    assert_eq!(s.bsdf_counts.get("diffuse"), Some(&3));
}

#[test]
fn furnace() {
    let s = load(scenes().join("furnace.xml")).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(s.shapes.len(), 1);
    assert_eq!(s.mode(), Mode::Rgb);
    let cube = &s.shapes[0];
    assert!(matches!(cube.shape.kind, ShapeKind::Cube));
    assert!(cube.shape.flip_normals);
    assert_eq!(
        cube.bsdf,
        BsdfParams::Diffuse {
            reflectance: ColorParam::Float(0.5)
        }
    );
    assert_eq!(
        cube.emitter.as_ref().map(|e| e.radiance.clone()),
        Some(ColorParam::Float(1.0))
    );
    // The camera is inside the cube [-1, 1]^3.
    let c = s.camera.expect("camera");
    assert!(c.origin.abs().max_element() < 1.0);
}

/// `$spp` can be overridden like Mitsuba's `load_file(path, spp=...)`.
#[test]
fn scene_parameters_override_defaults() {
    let s =
        trilux_scene::load_with_params(scenes().join("furnace.xml"), &[("spp".into(), "7".into())])
            .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(s.camera.map(|c| c.sample_count), Some(7));
}
