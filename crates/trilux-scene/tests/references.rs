//! `<ref>` to a top-level `<emitter id>`, as Mitsuba's own cbox.xml writes
//! its light: Mitsuba 3.9.1 attaches the emitter to the shape that names
//! it, refuses a second shape naming the same one ("an endpoint can only
//! be attached to a single shape"), and loads an unreferenced definition.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test, bench or example may panic

use std::path::PathBuf;

use trilux_color::ColorParam;
use trilux_scene::{Scene, SceneError, load_str};

fn try_load(body: &str) -> Result<Scene, SceneError> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data");
    load_str(
        &format!("<scene version=\"3.0.0\">{body}</scene>"),
        dir.join("inline.xml"),
    )
}

const LIGHT: &str =
    r#"<emitter type="area" id="light"><rgb name="radiance" value="18, 10, 2.5"/></emitter>"#;

/// The shape naming the emitter emits its radiance; the other does not.
#[test]
fn a_referenced_emitter_is_attached_to_its_shape() {
    let s = try_load(&format!(
        r#"{LIGHT}<shape type="rectangle"/><shape type="rectangle"><ref id="light"/></shape>"#
    ))
    .unwrap_or_else(|e| panic!("{e}"));
    assert!(s.shapes[0].emitter.is_none());
    let radiance = s.shapes[1].emitter.as_ref().map(|e| e.radiance.clone());
    assert_eq!(radiance, Some(ColorParam::Rgb([18.0, 10.0, 2.5])));
    assert_eq!(s.emitters().count(), 1);
}

/// Two shapes naming one emitter are refused at the second `<ref>`.
#[test]
fn an_emitter_belongs_to_one_shape() {
    let e = try_load(&format!(
        "{LIGHT}<shape type=\"rectangle\"><ref id=\"light\"/></shape>\n<shape type=\"cube\"><ref id=\"light\"/></shape>"
    ))
    .unwrap_err()
    .to_string();
    assert!(e.contains("inline.xml:2:"), "{e}");
    assert!(e.contains("already attached to the shape at line 1"), "{e}");
}

/// An unreferenced definition loads (without light, as in Mitsuba), but
/// its errors are still reported; one without an id is refused.
#[test]
fn emitter_definitions_are_checked() {
    let s = try_load(&format!(r#"{LIGHT}<shape type="rectangle"/>"#)).unwrap();
    assert_eq!(s.emitters().count(), 0);
    let e = try_load(r#"<emitter type="area" id="l"><float name="power" value="1"/></emitter>"#)
        .unwrap_err()
        .to_string();
    assert!(e.contains("power"), "{e}");
    let e = try_load(r#"<emitter type="area"/>"#)
        .unwrap_err()
        .to_string();
    assert!(e.contains("inside a <shape>"), "{e}");
}
