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

/// A sensor's `<film>` and `<sampler>`, and a film's `<rfilter>`, defined
/// at the top level with an id and named by a `<ref>`: Mitsuba 3.9.1 loads
/// this (checked with `mitsuba.load_string` on this machine), and the
/// camera is the one written inline.
#[test]
fn sensor_children_can_be_referenced() {
    let inline = try_load(
        r#"<sensor type="perspective"><sampler type="independent"><integer name="sample_count" value="7"/></sampler><film type="hdrfilm"><integer name="width" value="40"/><integer name="height" value="30"/><rfilter type="tent"><float name="radius" value="1.5"/></rfilter></film></sensor>"#,
    )
    .unwrap_or_else(|e| panic!("{e}"))
    .camera
    .unwrap();
    let referenced = try_load(
        r#"<rfilter type="tent" id="r"><float name="radius" value="1.5"/></rfilter>
           <film type="hdrfilm" id="f"><integer name="width" value="40"/><integer name="height" value="30"/><ref id="r"/></film>
           <sampler type="independent" id="s"><integer name="sample_count" value="7"/></sampler>
           <sensor type="perspective"><ref id="s"/><ref id="f"/></sensor>"#,
    )
    .unwrap_or_else(|e| panic!("{e}"))
    .camera
    .unwrap();
    assert_eq!(
        (referenced.width, referenced.height, referenced.sample_count),
        (40, 30, 7)
    );
    assert_eq!(referenced.rfilter, inline.rfilter);
    assert_ne!(referenced.rfilter, Default::default());
}

/// An unused film, sampler or filter definition is still checked; one
/// without an id (nothing could name it) is refused, and so is a `<ref>`
/// to an object trilux does not read by reference (a shape).
#[test]
fn sensor_child_definitions_are_checked() {
    for (body, want) in [
        (
            r#"<film type="hdrfilm" id="f"><integer name="width" value="-4"/></film>"#,
            "width",
        ),
        (
            r#"<sampler type="halton" id="s"/>"#,
            "unknown sampler plugin",
        ),
        (
            r#"<rfilter type="tent" id="r"><float name="radius" value="0"/></rfilter>"#,
            "radius",
        ),
        (r#"<film type="hdrfilm"/>"#, "unsupported element <film>"),
        (
            r#"<shape type="rectangle" id="a"/><shape type="cube"><ref id="a"/></shape>"#,
            "names a <shape type=\"rectangle\">",
        ),
    ] {
        let e = try_load(body).map(|_| ()).unwrap_err().to_string();
        assert!(e.contains(want), "{body}: {e}");
    }
}

/// A BSDF or a texture defined inside another object can be named from
/// elsewhere, as in Mitsuba (any object with an id).
#[test]
fn nested_definitions_can_be_referenced() {
    let s = try_load(
        r#"<shape type="rectangle"><bsdf type="twosided"><bsdf type="diffuse" id="inner"><rgb name="reflectance" value="0.2, 0.3, 0.4"/></bsdf></bsdf></shape>
           <shape type="cube"><ref id="inner"/></shape>"#,
    )
    .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(
        s.shapes[1].bsdf,
        trilux_brdf::BsdfParams::Diffuse {
            reflectance: ColorParam::Rgb([0.2, 0.3, 0.4])
        }
    );
}
