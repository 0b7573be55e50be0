//! Mitsuba 3's `thindielectric` and `mask` in the XML loader: the fraction
//! of light a pane lets through (trilux-geometry's `Transmittance`) and the
//! one it reflects, at Mitsuba 3.9.1's defaults and named indices, against
//! Mitsuba's own `sample` (scalar_rgb), and a mask's BRDF (`eval`) and the
//! fraction it lets through, stored in `data/thindielectric.json` by
//! `data/thindielectric.py`: tolerance 1e-4 relative or 1e-6 absolute
//! (Mitsuba computes in f32). And the refusals: one located line each.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test may panic

use std::path::PathBuf;

use serde::Deserialize;
use trilux_brdf::{Bsdf, BsdfParams};
use trilux_color::ColorParam;
use trilux_geometry::Transmittance;
use trilux_geometry::transmission::slab_reflectance;
use trilux_scene::{Scene, SceneError, load_str};

#[derive(Deserialize)]
struct Row {
    cos: f64,
    r: f64,
    t: f64,
    straight: bool,
}

#[derive(Deserialize)]
struct Case {
    name: String,
    body: String,
    rows: Vec<Row>,
}

#[derive(Deserialize)]
struct Eval {
    wi: [f64; 3],
    wo: [f64; 3],
    fr: [f64; 3],
}

#[derive(Deserialize)]
struct Mask {
    name: String,
    body: String,
    evals: Vec<Eval>,
    t: f64,
    straight: bool,
}

#[derive(Deserialize)]
struct File {
    cases: Vec<Case>,
    masks: Vec<Mask>,
}

fn try_load(body: &str) -> Result<Scene, SceneError> {
    load_str(
        &format!(
            "<scene version=\"3.0.0\">\n<shape type=\"rectangle\">\n{body}\n</shape>\n</scene>"
        ),
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/inline.xml"),
    )
}

fn close(got: f64, want: f64) -> bool {
    let err = (got - want).abs();
    err <= 1e-6 || err <= 1e-4 * want.abs()
}

#[test]
fn a_pane_lets_through_and_reflects_what_mitsuba_samples() {
    let file: File = serde_json::from_str(include_str!("data/thindielectric.json")).unwrap();
    assert!(file.cases.len() >= 7);
    let (mut checked, mut failures) = (0, Vec::new());
    for case in &file.cases {
        let xml = format!("<bsdf type=\"thindielectric\">{}</bsdf>", case.body);
        let scene = try_load(&xml).unwrap_or_else(|e| panic!("{}: {e}", case.name));
        let shape = &scene.shapes[0];
        let t = shape.transmission.expect("a pane lets light through");
        // The pane reflects nothing trilux carries: its BSDF is black.
        assert_eq!(
            shape.bsdf,
            BsdfParams::Diffuse {
                reflectance: ColorParam::Float(0.0)
            }
        );
        let eta = match t {
            Transmittance::ThinSlab { eta, .. } => eta,
            other => panic!("{}: {other:?}", case.name),
        };
        let spec_r = if case.name == "scaled" { 0.6 } else { 1.0 };
        for row in &case.rows {
            assert!(row.straight, "{}: Mitsuba transmits straight on", case.name);
            let (tau, r) = (t.at(row.cos), spec_r * slab_reflectance(row.cos, eta));
            checked += 2;
            if !close(tau, row.t) {
                failures.push(format!(
                    "{} cos {}: T {tau} against {}",
                    case.name, row.cos, row.t
                ));
            }
            if !close(r, row.r) {
                failures.push(format!(
                    "{} cos {}: R {r} against {}",
                    case.name, row.cos, row.r
                ));
            }
        }
    }
    assert!(checked >= 280, "{checked}");
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn a_mask_reflects_and_lets_through_what_mitsuba_does() {
    let file: File = serde_json::from_str(include_str!("data/thindielectric.json")).unwrap();
    assert!(file.masks.len() >= 3);
    for m in &file.masks {
        let xml = format!("<bsdf type=\"mask\">{}</bsdf>", m.body);
        let scene = try_load(&xml).unwrap_or_else(|e| panic!("{}: {e}", m.name));
        let shape = &scene.shapes[0];
        let t = shape.transmission.expect("a mask lets light through");
        assert!(
            m.straight,
            "{}: Mitsuba lets it through straight on",
            m.name
        );
        // Whatever the angle.
        for cos in [1.0, 0.5, 0.05] {
            assert!(
                close(t.at(cos), m.t),
                "{}: {} against {}",
                m.name,
                t.at(cos),
                m.t
            );
        }
        let bsdf = Bsdf::<3>::new(&shape.bsdf).unwrap();
        for e in &m.evals {
            let got = bsdf.eval(glam::DVec3::from_array(e.wi), glam::DVec3::from_array(e.wo));
            for c in 0..3 {
                assert!(
                    close(got[c], e.fr[c]),
                    "{} {:?} {:?} channel {c}: {} against {}",
                    m.name,
                    e.wi,
                    e.wo,
                    got[c],
                    e.fr[c]
                );
            }
        }
    }
}

fn err(body: &str) -> String {
    match try_load(body) {
        Ok(_) => panic!("{body} should be refused"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn bad_panes_are_one_located_line_each() {
    for (body, words) in [
        (
            r#"<bsdf type="thindielectric"><float name="int_ior" value="-1.5"/></bsdf>"#,
            &["int_ior", "positive"][..],
        ),
        (
            r#"<bsdf type="thindielectric"><string name="ext_ior" value="unobtainium"/></bsdf>"#,
            &["unknown index of refraction", "bk7"],
        ),
        (
            r#"<bsdf type="thindielectric"><float name="specular_transmittance" value="1.5"/></bsdf>"#,
            &["specular_transmittance", "[0, 1]"],
        ),
        (
            r#"<bsdf type="thindielectric"><rgb name="specular_transmittance" value="0.9, 0.5, 0.5"/></bsdf>"#,
            &["specular_transmittance", "grey"],
        ),
        (
            r#"<bsdf type="thindielectric"><float name="roughness" value="0.1"/></bsdf>"#,
            &["roughness"],
        ),
        (
            r#"<bsdf type="dielectric"/>"#,
            &["dielectric", "refracts", "thindielectric"],
        ),
        (
            r#"<bsdf type="roughdielectric"/>"#,
            &["roughdielectric", "refracts"],
        ),
        (
            r#"<bsdf type="twosided"><bsdf type="thindielectric"/></bsdf>"#,
            &["cannot be nested", "thindielectric"],
        ),
        (
            r#"<bsdf type="blendbsdf"><float name="weight" value="0.5"/><bsdf type="thindielectric"/><bsdf type="diffuse"/></bsdf>"#,
            &["cannot be nested"],
        ),
        (
            r#"<bsdf type="mask"><float name="opacity" value="1.5"/><bsdf type="diffuse"/></bsdf>"#,
            &["opacity", "[0, 1]"],
        ),
        (
            r#"<bsdf type="mask"><float name="opacity" value="-0.1"/><bsdf type="diffuse"/></bsdf>"#,
            &["opacity", "[0, 1]"],
        ),
        (
            r#"<bsdf type="mask"><texture type="bitmap" name="opacity"><string name="filename" value="leaf.png"/></texture><bsdf type="diffuse"/></bsdf>"#,
            &["opacity", "texture"],
        ),
        (
            r#"<bsdf type="mask"><float name="opacity" value="0.5"/></bsdf>"#,
            &["one nested BSDF"],
        ),
        (
            r#"<bsdf type="mask"><bsdf type="mask"><bsdf type="diffuse"/></bsdf></bsdf>"#,
            &["cannot be nested", "mask"],
        ),
    ] {
        let e = err(body);
        assert!(
            e.contains("inline.xml:3:") && !e.contains('\n'),
            "{body}: {e}"
        );
        for w in words {
            assert!(e.contains(w), "{body}: {e} (wanted {w})");
        }
    }
}

#[test]
fn a_pane_is_black_to_the_brdf_layer() {
    let scene = try_load(r#"<bsdf type="thindielectric"/>"#).unwrap();
    let bsdf = Bsdf::<3>::new(&scene.shapes[0].bsdf).unwrap();
    let up = glam::DVec3::Z;
    assert_eq!(bsdf.eval(up, up).max_value(), 0.0);
}
