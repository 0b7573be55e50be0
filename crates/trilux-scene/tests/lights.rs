//! Mitsuba 3's emitters without area (`point`, `spot`, `directional`):
//! their parameters with Mitsuba 3.9.1's defaults and conventions, and
//! every bad value refused as one located line.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test, bench or example may panic

use std::path::PathBuf;

use glam::{DMat3, DVec3};
use trilux_color::ColorParam;
use trilux_geometry::{Punctual, SpotFalloff};
use trilux_scene::{Scene, SceneError, load_str};

fn try_load(body: &str) -> Result<Scene, SceneError> {
    load_str(
        &format!("<scene version=\"3.0.0\">\n{body}</scene>"),
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/inline.xml"),
    )
}

fn light(body: &str) -> (Punctual, ColorParam) {
    let s = try_load(body).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(s.lights.len(), 1);
    (s.lights[0].punctual, s.lights[0].intensity.clone())
}

/// The error of `body`, checked to be one line at `line` of the file.
fn err(body: &str, line: usize) -> String {
    let e = try_load(body).map(|_| ()).unwrap_err().to_string();
    assert_eq!(e.lines().count(), 1, "{e}");
    assert!(e.contains(&format!("inline.xml:{line}:")), "{e}");
    e
}

#[test]
fn point_defaults_position_and_to_world() {
    let (p, i) = light(r#"<emitter type="point"/>"#);
    assert_eq!(
        p,
        Punctual::Point {
            position: DVec3::ZERO
        }
    );
    assert_eq!(i, ColorParam::Float(1.0));
    let (p, i) = light(
        r#"<emitter type="point"><point name="position" x="1" y="2" z="3"/><rgb name="intensity" value="1, 2, 3"/></emitter>"#,
    );
    assert_eq!(
        p,
        Punctual::Point {
            position: DVec3::new(1.0, 2.0, 3.0)
        }
    );
    assert_eq!(i, ColorParam::Rgb([1.0, 2.0, 3.0]));
    let (p, _) = light(
        r#"<emitter type="point"><transform name="to_world"><translate x="4" y="5" z="6"/></transform></emitter>"#,
    );
    assert_eq!(
        p,
        Punctual::Point {
            position: DVec3::new(4.0, 5.0, 6.0)
        }
    );
}

/// Mitsuba's spot defaults: cutoff 20°, beam width ¾ of the cutoff,
/// pointing along +z of `to_world` (identity: +z).
#[test]
fn spot_defaults_and_falloff() {
    let (p, _) = light(r#"<emitter type="spot"/>"#);
    match p {
        Punctual::Spot {
            position,
            light_from_world,
            falloff,
        } => {
            assert_eq!(position, DVec3::ZERO);
            assert_eq!(light_from_world, DMat3::IDENTITY);
            assert_eq!(
                falloff,
                SpotFalloff::Mitsuba {
                    cutoff_angle: 20f64.to_radians(),
                    beam_width: 15f64.to_radians()
                }
            );
        }
        other => panic!("{other:?}"),
    }
    // Aimed by a look-at down −y: a point straight below is on the axis.
    let (p, _) = light(
        r#"<emitter type="spot"><transform name="to_world"><lookat origin="0, 1, 0" target="0, 0, 0" up="0, 0, 1"/></transform><float name="cutoff_angle" value="30"/></emitter>"#,
    );
    let a = p.arrival(DVec3::new(0.0, -1.0, 0.0)).unwrap();
    assert!((a.factor - 0.25).abs() < 1e-12, "{a:?}");
    assert!(p.arrival(DVec3::new(0.0, 2.0, 0.0)).is_none());
}

#[test]
fn directional_direction_and_to_world() {
    let (p, i) = light(
        r#"<emitter type="directional"><vector name="direction" x="0" y="0" z="-2"/><float name="irradiance" value="3"/></emitter>"#,
    );
    assert_eq!(
        p,
        Punctual::Directional {
            direction: -DVec3::Z
        }
    );
    assert_eq!(i, ColorParam::Float(3.0));
    let (p, _) = light(
        r#"<emitter type="directional"><transform name="to_world"><rotate x="1" angle="90"/></transform></emitter>"#,
    );
    match p {
        Punctual::Directional { direction } => {
            assert!(
                (direction - DVec3::new(0.0, -1.0, 0.0)).length() < 1e-12,
                "{direction}"
            )
        }
        other => panic!("{other:?}"),
    }
}

/// Each bad value: one line at its place (line 2, where the emitter is
/// written), naming the problem.
#[test]
fn bad_lights_are_located() {
    let cases = [
        (
            r#"<emitter type="point"><float name="intensity" value="-1"/></emitter>"#,
            "intensity must not be negative",
        ),
        (
            r#"<emitter type="point"><float name="intensity" value="nan"/></emitter>"#,
            "NaN",
        ),
        (
            r#"<emitter type="spot"><rgb name="intensity" value="1, -2, 1"/></emitter>"#,
            "intensity must not be negative",
        ),
        (
            r#"<emitter type="directional"><float name="irradiance" value="-3"/></emitter>"#,
            "irradiance must not be negative",
        ),
        (
            r#"<emitter type="directional"><vector name="direction" x="0" y="0" z="0"/></emitter>"#,
            "direction must not be zero",
        ),
        (
            r#"<emitter type="spot"><float name="cutoff_angle" value="0"/></emitter>"#,
            "cutoff_angle must be in (0, 180)",
        ),
        (
            r#"<emitter type="spot"><float name="cutoff_angle" value="180"/></emitter>"#,
            "cutoff_angle must be in (0, 180)",
        ),
        (
            r#"<emitter type="spot"><float name="beam_width" value="-1"/></emitter>"#,
            "beam_width must be in [0, 180)",
        ),
        (
            r#"<emitter type="point"><float name="radius" value="1"/></emitter>"#,
            "unknown parameter \"radius\"",
        ),
        (
            r#"<emitter type="spot"><point name="position" x="1" y="0" z="0"/></emitter>"#,
            "unknown parameter \"position\"",
        ),
        (
            r#"<emitter type="point"><point name="position" x="1" y="0" z="0"/><transform name="to_world"><translate x="1"/></transform></emitter>"#,
            "only one of \"position\" and \"to_world\"",
        ),
        (
            r#"<emitter type="spot"><texture type="bitmap" name="texture"><string name="filename" value="a.png"/></texture></emitter>"#,
            "projected image) is not supported",
        ),
        (
            r#"<emitter type="projector"/>"#,
            "unknown emitter plugin \"projector\"",
        ),
        (
            r#"<shape type="rectangle"><emitter type="point"/></shape>"#,
            "a shape's emitter must be \"area\"",
        ),
    ];
    for (body, what) in cases {
        let e = err(&format!("{body}\n"), 2);
        assert!(e.contains(what), "{body}: {e}");
    }
}
