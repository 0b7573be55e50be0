//! The audit of Mitsuba 3.9.1's parameters on the plugins trilux reads
//! (their `props.get` calls in Mitsuba's sources, `src/{render,films,
//! samplers,integrators,shapes,emitters,bsdfs,textures}/`): each one that
//! does not change the light loads and leaves the scene as it is without
//! it; each one that changes the light and is not supported is refused
//! with its name. The README's "Scene format" table lists the outcome.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test, bench or example may panic

use std::path::PathBuf;

use trilux_brdf::BsdfParams;
use trilux_color::ColorParam;
use trilux_scene::{Scene, SceneError, load_str};

fn try_load(body: &str) -> Result<Scene, SceneError> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data");
    load_str(
        &format!("<scene version=\"3.0.0\">{body}</scene>"),
        dir.join("inline.xml"),
    )
}

fn load(body: &str) -> Scene {
    try_load(body).unwrap_or_else(|e| panic!("{body}: {e}"))
}

fn refused(body: &str) -> String {
    match try_load(body) {
        Ok(_) => panic!("{body} should be refused"),
        Err(e) => e.to_string(),
    }
}

/// What a scene is, for comparing one with an ignored parameter to one
/// without: its shapes' geometry, BSDFs and emitters, and its camera's
/// film, filter and samples.
fn summary(s: &Scene) -> String {
    let shapes: Vec<String> = s
        .shapes
        .iter()
        .map(|x| {
            format!(
                "{:?} {:?} {:?}",
                x.shape,
                x.bsdf,
                x.emitter.as_ref().map(|e| &e.radiance)
            )
        })
        .collect();
    let camera = s.camera.as_ref().map(|c| {
        format!(
            "{}x{} {:?} {}",
            c.width, c.height, c.rfilter, c.sample_count
        )
    });
    format!("{shapes:?} {camera:?} {:?}", s.max_depth)
}

/// Each (with, without) pair loads to the same scene.
#[test]
fn parameters_that_do_not_change_the_light_are_ignored() {
    let sensor = |film: &str, sampler: &str| {
        format!(
            r#"<sensor type="perspective"><film type="hdrfilm">{film}</film><sampler type="stratified">{sampler}</sampler></sensor>"#
        )
    };
    let pairs = [
        (
            sensor(
                r#"<boolean name="compensate" value="true"/><boolean name="banner" value="false"/><boolean name="sample_border" value="false"/>"#,
                r#"<boolean name="jitter" value="false"/><integer name="seed" value="3"/>"#,
            ),
            sensor("", ""),
        ),
        (
            r#"<shape type="rectangle"><float name="silhouette_sampling_weight" value="2"/><boolean name="face_normals" value="true"/></shape>"#.into(),
            r#"<shape type="rectangle"/>"#.into(),
        ),
        (
            r#"<shape type="cube"><boolean name="face_normals" value="true"/></shape>"#.into(),
            r#"<shape type="cube"/>"#.into(),
        ),
        (
            r#"<shape type="sphere"><emitter type="area"><float name="sampling_weight" value="0.25"/></emitter></shape>"#.into(),
            r#"<shape type="sphere"><emitter type="area"/></shape>"#.into(),
        ),
        (
            r#"<shape type="rectangle"><bsdf type="twosided"><boolean name="allow_transmission" value="true"/><bsdf type="diffuse"/></bsdf></shape>"#.into(),
            r#"<shape type="rectangle"><bsdf type="twosided"><bsdf type="diffuse"/></bsdf></shape>"#.into(),
        ),
        (
            r#"<integrator type="volpathmis"><integer name="rr_depth" value="2"/><integer name="samples_per_pass" value="4"/><integer name="block_size" value="16"/><float name="timeout" value="60"/><boolean name="use_spectral_mis" value="false"/><boolean name="hide_emitters" value="false"/></integrator>"#.into(),
            r#"<integrator type="ptracer"/>"#.into(),
        ),
    ];
    for (with, without) in &pairs {
        assert_eq!(summary(&load(with)), summary(&load(without)), "{with}");
    }
}

/// A bitmap's storage format and texture acceleration are read (their
/// values checked) and do not change the texture.
#[test]
fn bitmap_storage_parameters_are_ignored() {
    let bitmap = |extra: &str| {
        format!(
            r#"<shape type="rectangle"><bsdf type="diffuse"><texture type="bitmap" name="reflectance"><string name="filename" value="ramp.png"/>{extra}</texture></bsdf></shape>"#
        )
    };
    let e = refused(&bitmap(r#"<string name="format" value="float64"/>"#));
    assert!(e.contains("unknown format \"float64\""), "{e}");
    let plain = format!("{:?}", load(&bitmap("")).shapes[0].textures);
    for extra in [
        r#"<string name="format" value="uint8"/><boolean name="accel" value="false"/>"#,
        r#"<string name="format" value="fp16"/>"#,
    ] {
        let with = format!("{:?}", load(&bitmap(extra)).shapes[0].textures);
        assert_eq!(with, plain, "{extra}");
    }
}

/// Parameters and plugins that change the light and that trilux does not
/// implement are refused, naming what is refused.
#[test]
fn parameters_that_change_the_light_are_refused() {
    for (body, want) in [
        (
            r#"<integrator type="direct"/>"#,
            "\"direct\" does not compute global illumination",
        ),
        (
            r#"<integrator type="aov"/>"#,
            "\"aov\" does not compute global illumination",
        ),
        (
            r#"<integrator type="path"><boolean name="use_spectral_mis" value="true"/></integrator>"#,
            "unknown parameter \"use_spectral_mis\"",
        ),
        (
            r#"<sensor type="perspective"><rgb name="srf" value="1, 0, 0"/></sensor>"#,
            "srf: give the sensor's spectral response as a <spectrum>",
        ),
        (
            r#"<shape type="sphere"><boolean name="face_normals" value="true"/></shape>"#,
            "unknown parameter \"face_normals\"",
        ),
    ] {
        let e = refused(body);
        assert!(e.contains(want), "{body}: {e}");
    }
}

/// Mitsuba 3.9.1 gives a shape with an emitter and no BSDF a black diffuse
/// BSDF (its Shape constructor; `mitsuba.load_string` prints
/// `reflectance = UniformSpectrum[value=0.000000]`), and any other shape
/// without a BSDF diffuse 0.5.
#[test]
fn an_emitter_without_a_bsdf_reflects_nothing() {
    let s = load(r#"<shape type="rectangle"><emitter type="area"/></shape><shape type="cube"/>"#);
    let reflectance = |i: usize| match &s.shapes[i].bsdf {
        BsdfParams::Diffuse { reflectance } => reflectance.clone(),
        other => panic!("{other:?}"),
    };
    assert_eq!(reflectance(0), ColorParam::Float(0.0));
    assert_eq!(reflectance(1), ColorParam::Float(0.5));
}

/// `max_depth` and `hide_emitters` are kept for the renderer, which
/// honours them (crates/trilux/tests/mitsuba_cbox.rs checks the images
/// against Mitsuba's), with the place `max_depth` is written for its
/// warnings; loading warns about neither.
#[test]
fn max_depth_and_hide_emitters_are_kept_with_their_place() {
    let s = load(
        "<integrator type=\"path\">\n<integer name=\"max_depth\" value=\"6\"/><boolean name=\"hide_emitters\" value=\"true\"/></integrator>",
    );
    assert!(s.warnings.is_empty(), "{:?}", s.warnings);
    assert_eq!(s.max_depth, Some(6));
    assert!(s.hide_emitters);
    let at = s.max_depth_location.expect("the place of max_depth");
    assert_eq!(at.line, 2, "{at}");
    let s = load(r#"<integrator type="path"/>"#);
    assert_eq!((s.max_depth, s.hide_emitters), (None, false));
    assert!(s.max_depth_location.is_none());
}

/// `sample_border` is kept for the renderer, which samples the filter's
/// border beyond the film (crates/trilux/tests/sample_border.rs checks the
/// image against Mitsuba's).
#[test]
fn sample_border_is_kept() {
    let film = |value: &str| {
        format!(
            r#"<sensor type="perspective"><film type="hdrfilm"><boolean name="sample_border" value="{value}"/></film></sensor>"#
        )
    };
    let camera = |value| load(&film(value)).camera.expect("a camera");
    assert!(camera("true").sample_border);
    assert!(!camera("false").sample_border);
}

/// A sensor's `srf` is kept (crates/trilux/tests/mitsuba_cbox.rs checks
/// the image against Mitsuba's) and, sampled, makes the scene spectral as
/// Mitsuba reads it in spectral variants only.
#[test]
fn a_sensor_response_is_kept_and_makes_the_scene_spectral() {
    let s =
        load(r#"<sensor type="perspective"><spectrum name="srf" value="400:1, 700:1"/></sensor>"#);
    let camera = s.camera.as_ref().expect("a camera");
    assert_eq!(
        camera.response,
        Some(ColorParam::Sampled(vec![(400.0, 1.0), (700.0, 1.0)]))
    );
    assert!(s.spectral);
    let s = load(r#"<sensor type="perspective"/>"#);
    assert!(s.camera.expect("a camera").response.is_none());
}
