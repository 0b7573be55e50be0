//! The parameters of Mitsuba 3.9.1's `perspective` sensor beyond `fov`:
//! `focal_length` with Mitsuba's meaning, and those that do not change a
//! pinhole camera's image of a static scene (`focus_distance`, the
//! shutter interval) accepted and ignored, as Mitsuba's own scenes write
//! them (its cbox.xml carries `focus_distance`).
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test, bench or example may panic

use std::path::PathBuf;

use trilux_scene::{Camera, FovAxis, SceneError, load_str};

fn try_camera(params: &str) -> Result<Camera, SceneError> {
    let body = format!(
        r#"<scene version="3.0.0"><sensor type="perspective">{params}<film type="hdrfilm"><integer name="width" value="64"/><integer name="height" value="48"/></film></sensor></scene>"#
    );
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data");
    load_str(&body, dir.join("inline.xml")).map(|s| s.camera.expect("camera"))
}

fn camera(params: &str) -> Camera {
    try_camera(params).unwrap_or_else(|e| panic!("{e}"))
}

fn refused(params: &str) -> String {
    match try_camera(params) {
        Ok(_) => panic!("{params} should be refused"),
        Err(e) => e.to_string(),
    }
}

/// A pinhole camera has no focal plane and a static scene no motion: the
/// camera with these parameters equals the one without.
#[test]
fn focus_distance_and_shutter_do_not_change_the_camera() {
    let plain = camera(r#"<float name="fov" value="40"/>"#);
    let with = camera(
        r#"<float name="fov" value="40"/><float name="focus_distance" value="1000"/><float name="shutter_open" value="0"/><float name="shutter_close" value="0.5"/>"#,
    );
    assert_eq!(
        serde_json::to_value(&plain).unwrap(),
        serde_json::to_value(&with).unwrap()
    );
    let e =
        refused(r#"<float name="shutter_open" value="2"/><float name="shutter_close" value="1"/>"#);
    assert!(
        e.contains("inline.xml:") && e.contains("shutter_open 2"),
        "{e}"
    );
    let e = refused(r#"<string name="focus_distance" value="far"/>"#);
    assert!(e.contains("focus_distance"), "{e}");
}

/// `focal_length` x mm on Mitsuba's 36 × 24 mm film: the diagonal field of
/// view 2 atan(√(36² + 24²) / 2x). Mitsuba 3.9.1 gives x_fov 52.62254°
/// for "35mm" on a 4:3 film (`mi.traverse(mi.load_dict({'type':
/// 'perspective', 'focal_length': '35mm'}))['x_fov']`).
#[test]
fn focal_length_is_a_diagonal_field_of_view() {
    let c = camera(r#"<string name="focal_length" value="35mm"/>"#);
    assert_eq!(c.fov_axis, FovAxis::Diagonal);
    let want = (2.0 * (36f64.hypot(24.0) / (2.0 * 35.0)).atan()).to_degrees();
    assert!((c.fov - want).abs() < 1e-12, "{} {want}", c.fov);
    assert!((c.x_fov() - 52.62254).abs() < 1e-4, "{}", c.x_fov());
    let bare = camera(r#"<string name="focal_length" value="35"/>"#);
    assert_eq!(bare.fov, c.fov);
    for bad in ["abc", "-10mm", "0mm"] {
        let e = refused(&format!(r#"<string name="focal_length" value="{bad}"/>"#));
        assert!(e.contains("focal_length must be a positive length"), "{e}");
    }
    let e = refused(r#"<string name="focal_length" value="35mm"/><float name="fov" value="40"/>"#);
    assert!(e.contains("either focal_length or fov"), "{e}");
}
