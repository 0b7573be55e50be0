//! `plastic` and `roughplastic` in the XML loader: Mitsuba 3's parameters,
//! defaults (ior.h's named indices) and the located refusals.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test may panic

use std::path::PathBuf;

use trilux_brdf::{BsdfParams, Distribution, PlasticParams};
use trilux_color::ColorParam;
use trilux_scene::{Scene, SceneError, load_str};

fn try_load(body: &str) -> Result<Scene, SceneError> {
    load_str(
        &format!("<scene version=\"3.0.0\">\n<shape type=\"rectangle\">{body}</shape></scene>"),
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/inline.xml"),
    )
}

fn plastic(body: &str) -> PlasticParams {
    match &try_load(body).unwrap_or_else(|e| panic!("{e}")).shapes[0].bsdf {
        BsdfParams::Plastic(p) => p.clone(),
        other => panic!("{other:?}"),
    }
}

fn err(body: &str) -> String {
    match try_load(body) {
        Ok(_) => panic!("{body} should be refused"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn defaults_are_mitsubas() {
    assert_eq!(
        plastic(r#"<bsdf type="plastic"/>"#),
        PlasticParams::smooth()
    );
    let r = plastic(r#"<bsdf type="roughplastic"/>"#);
    assert_eq!(r, PlasticParams::rough());
    assert_eq!((r.int_ior, r.ext_ior), (1.49, 1.000277));
    assert_eq!(r.coat, Some((Distribution::Beckmann, 0.1)));
    assert_eq!(r.diffuse_reflectance, ColorParam::Float(0.5));
}

#[test]
fn parameters_and_named_iors() {
    let p = plastic(
        r#"<bsdf type="roughplastic"><string name="distribution" value="ggx"/>
        <float name="alpha" value="0.3"/><string name="int_ior" value="BK7"/>
        <string name="ext_ior" value="water"/><boolean name="nonlinear" value="true"/>
        <rgb name="diffuse_reflectance" value="0.1, 0.2, 0.3"/>
        <float name="specular_reflectance" value="0.8"/></bsdf>"#,
    );
    assert_eq!(p.coat, Some((Distribution::Ggx, 0.3)));
    assert_eq!((p.int_ior, p.ext_ior), (1.5046, 1.333));
    assert!(p.nonlinear);
    assert_eq!(p.diffuse_reflectance, ColorParam::Rgb([0.1, 0.2, 0.3]));
    assert_eq!(p.specular_reflectance, ColorParam::Float(0.8));
    let q = plastic(r#"<bsdf type="plastic"><float name="int_ior" value="1.7"/></bsdf>"#);
    assert_eq!((q.int_ior, q.coat), (1.7, None));
}

#[test]
fn bad_values_are_located_errors() {
    for (body, says) in [
        (
            r#"<bsdf type="plastic"><float name="int_ior" value="-1.5"/></bsdf>"#,
            "int_ior must be positive",
        ),
        (
            r#"<bsdf type="plastic"><float name="ext_ior" value="0"/></bsdf>"#,
            "ext_ior must be positive",
        ),
        (
            r#"<bsdf type="roughplastic"><string name="int_ior" value="unobtainium"/></bsdf>"#,
            "unknown index of refraction \"unobtainium\"",
        ),
        (
            r#"<bsdf type="roughplastic"><float name="int_ior" value="1.2"/><float name="ext_ior" value="1.2"/></bsdf>"#,
            "must differ",
        ),
        (
            r#"<bsdf type="roughplastic"><float name="alpha" value="0"/></bsdf>"#,
            "alpha must be positive",
        ),
        (
            r#"<bsdf type="roughplastic"><float name="alpha" value="-0.2"/></bsdf>"#,
            "alpha must be positive",
        ),
        (
            r#"<bsdf type="plastic"><float name="diffuse_reflectance" value="-0.1"/></bsdf>"#,
            "must not be negative",
        ),
        (
            r#"<bsdf type="plastic"><rgb name="specular_reflectance" value="0.5, 1.5, 0.5"/></bsdf>"#,
            "must not exceed 1",
        ),
        (
            r#"<bsdf type="plastic"><float name="diffuse_reflectance" value="nan"/></bsdf>"#,
            "NaN is not allowed",
        ),
        (
            r#"<bsdf type="plastic"><float name="eta" value="1.5"/></bsdf>"#,
            "eta",
        ),
    ] {
        let e = err(body);
        assert!(e.contains(says), "{body}: {e}");
        assert!(e.contains("inline.xml:2:"), "not located: {e}");
    }
}
