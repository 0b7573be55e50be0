//! One test (at least) per element of the supported subset (README, "Scene format"),
//! with expected values from Mitsuba 3's documented defaults and semantics.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test, bench or example may panic

use std::path::PathBuf;

use glam::{DMat4, DVec3};
use trilux_brdf::{BsdfParams, Distribution};
use trilux_color::ColorParam;
use trilux_geometry::ShapeKind;
use trilux_scene::{
    FovAxis, ReconstructionFilter, Scene, SceneError, load_str, load_str_with_params,
};

fn data_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data")
}

fn try_load(body: &str) -> Result<Scene, SceneError> {
    load_str(
        &format!("<scene version=\"3.0.0\">{body}</scene>"),
        data_dir().join("inline.xml"),
    )
}

fn load(body: &str) -> Scene {
    try_load(body).unwrap_or_else(|e| panic!("{e}"))
}

/// The first shape's BSDF with `bsdf` as its only child.
fn bsdf(bsdf: &str) -> BsdfParams {
    load(&format!("<shape type=\"rectangle\">{bsdf}</shape>")).shapes[0]
        .bsdf
        .clone()
}

fn diffuse_reflectance(value: &str) -> ColorParam {
    match bsdf(&format!("<bsdf type=\"diffuse\">{value}</bsdf>")) {
        BsdfParams::Diffuse { reflectance } => reflectance,
        other => panic!("{other:?}"),
    }
}

fn err(body: &str) -> String {
    match try_load(body) {
        Ok(_) => panic!("{body} should be refused"),
        Err(e) => e.to_string(),
    }
}

// ---- values -------------------------------------------------------------

#[test]
fn float_rgb_and_spectrum_values() {
    let r = diffuse_reflectance;
    assert_eq!(
        r(r#"<float name="reflectance" value="0.25"/>"#),
        ColorParam::Float(0.25)
    );
    assert_eq!(
        r(r#"<rgb name="reflectance" value="0.1, 0.2, 0.3"/>"#),
        ColorParam::Rgb([0.1, 0.2, 0.3])
    );
    assert_eq!(
        r(r#"<rgb name="reflectance" value="0.4"/>"#),
        ColorParam::Rgb([0.4; 3])
    );
    assert_eq!(
        r(r#"<spectrum name="reflectance" value="0.3"/>"#),
        ColorParam::Constant(0.3)
    );
    assert_eq!(
        r(r#"<spectrum name="reflectance" value="400:0.1, 500:0.2,600:0.3"/>"#),
        ColorParam::Sampled(vec![(400.0, 0.1), (500.0, 0.2), (600.0, 0.3)])
    );
}

#[test]
fn integer_and_boolean_and_string_values() {
    let s = load(
        r#"<integrator type="path"><integer name="max_depth" value="5"/></integrator>
           <shape type="rectangle"><boolean name="flip_normals" value="true"/>
             <bsdf type="roughconductor"><string name="distribution" value="ggx"/></bsdf></shape>"#,
    );
    assert_eq!(s.max_depth, Some(5));
    assert!(s.shapes[0].shape.flip_normals);
    let BsdfParams::RoughConductor(rc) = &s.shapes[0].bsdf else {
        panic!()
    };
    assert_eq!(rc.distribution, Distribution::Ggx);
}

#[test]
fn point_and_vector_values() {
    let s = load(
        r#"<shape type="sphere"><point name="center" value="1, 2, 3"/></shape>
           <shape type="sphere"><point name="center" x="1" z="-3"/></shape>
           <shape type="cylinder"><vector name="p1" value="0 0 2"/></shape>"#,
    );
    let center = |i: usize| match s.shapes[i].shape.kind {
        ShapeKind::Sphere { center, .. } => center,
        _ => panic!(),
    };
    assert_eq!(center(0), DVec3::new(1.0, 2.0, 3.0));
    assert_eq!(center(1), DVec3::new(1.0, 0.0, -3.0));
    assert!(
        matches!(s.shapes[2].shape.kind, ShapeKind::Cylinder { p1, .. } if p1 == DVec3::new(0.0, 0.0, 2.0))
    );
}

#[test]
fn wrong_value_types_are_refused() {
    let e = err(
        r#"<shape type="rectangle"><bsdf type="diffuse"><string name="reflectance" value="red"/></bsdf></shape>"#,
    );
    assert!(
        e.contains("must be a <rgb, spectrum or float>, found <string>"),
        "{e}"
    );
    let e = err(r#"<shape type="rectangle"><float name="flip_normals" value="1"/></shape>"#);
    assert!(e.contains("must be a <boolean>"), "{e}");
    let e = err(r#"<shape type="sphere"><float name="radius" value="abc"/></shape>"#);
    assert!(e.contains("\"abc\" is not a number"), "{e}");
    let e = err(r#"<shape type="rectangle"><boolean name="flip_normals" value="yes"/></shape>"#);
    assert!(e.contains("not a boolean"), "{e}");
    let e = err(
        r#"<sensor type="perspective"><sampler type="independent"><integer name="sample_count" value="1.5"/></sampler></sensor>"#,
    );
    assert!(e.contains("not an integer"), "{e}");
}

#[test]
fn spectra_must_be_well_formed() {
    let sp = |v: &str| {
        err(&format!(
            r#"<shape type="rectangle"><bsdf type="diffuse"><spectrum name="reflectance" value="{v}"/></bsdf></shape>"#
        ))
    };
    assert!(sp("500:0.1, 400:0.2").contains("wavelengths must increase"));
    assert!(sp("500:0.1").contains("at least two"));
    assert!(sp("0.1, 0.2").contains("one number or wavelength:value pairs"));
    assert!(sp("400:0.1, 500:nan").contains("NaN"));
}

// ---- <default>, $name, <ref>, top-level <bsdf id> ---------------------

#[test]
fn defaults_and_substitution() {
    let body = r#"<default name="r" value="0.125"/><default name="kind" value="diffuse"/>
        <shape type="rectangle"><bsdf type="$kind"><float name="reflectance" value="$r"/></bsdf></shape>"#;
    let BsdfParams::Diffuse { reflectance } = &load(body).shapes[0].bsdf else {
        panic!()
    };
    assert_eq!(*reflectance, ColorParam::Float(0.125));
    // A caller's value overrides the <default> (Mitsuba's load_file(path, r=...)).
    let s = load_str_with_params(
        &format!("<scene version=\"3.0.0\">{body}</scene>"),
        "inline.xml",
        &[("r".into(), "0.75".into())],
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let BsdfParams::Diffuse { reflectance } = &s.shapes[0].bsdf else {
        panic!()
    };
    assert_eq!(*reflectance, ColorParam::Float(0.75));
    // Substitution inside a longer value.
    let s = load(
        r#"<default name="y" value="2"/><shape type="sphere"><point name="center" value="1, $y, 3"/></shape>"#,
    );
    assert!(matches!(s.shapes[0].shape.kind, ShapeKind::Sphere { center, .. } if center.y == 2.0));
    let e = err(r#"<shape type="sphere"><float name="radius" value="$nope"/></shape>"#);
    assert!(e.contains("undefined parameter $nope"), "{e}");
}

#[test]
fn references_to_top_level_bsdfs() {
    let s = load(
        r#"<bsdf type="diffuse" id="grey"><float name="reflectance" value="0.3"/></bsdf>
           <shape type="rectangle"><ref id="grey"/></shape>
           <shape type="cube"><ref name="bsdf" id="grey"/></shape>"#,
    );
    for shape in &s.shapes {
        assert_eq!(
            shape.bsdf,
            BsdfParams::Diffuse {
                reflectance: ColorParam::Float(0.3)
            }
        );
    }
    // The definition counts once, however often it is referenced.
    assert_eq!(s.bsdf_counts.get("diffuse"), Some(&1));
    assert!(
        err(r#"<shape type="rectangle"><ref id="missing"/></shape>"#)
            .contains("unknown id \"missing\"")
    );
    assert!(
        err(r#"<shape type="rectangle" id="a"/><shape type="cube"><ref id="a"/></shape>"#)
            .contains("only <bsdf>, <texture>, <emitter>, <film>, <sampler> and <rfilter> elements can be referenced")
    );
    assert!(
        err(r#"<bsdf type="diffuse" id="a"/><bsdf type="diffuse" id="a"/>"#)
            .contains("already used")
    );
    // A texture's <ref> gives the parameter's name; without one the copy
    // has none, and a definition needs an id.
    let e = err(
        r#"<texture type="checkerboard" id="t"/><shape type="rectangle"><bsdf type="diffuse"><ref id="t"/></bsdf></shape>"#,
    );
    assert!(e.contains("name"), "{e}");
    assert!(err(r#"<texture type="checkerboard"/>"#).contains("unsupported element <texture>"));
}

// ---- sensor, film, sampler, integrator ---------------------------------

#[test]
fn sensor_defaults_follow_mitsuba() {
    let c = load(r#"<sensor type="perspective"/>"#)
        .camera
        .expect("camera");
    assert_eq!((c.width, c.height), (768, 576));
    assert_eq!(c.rfilter, ReconstructionFilter::Gaussian { stddev: 0.5 });
    assert_eq!(c.sample_count, 4);
    assert_eq!(c.fov_axis, FovAxis::Diagonal);
    // 50 mm lens on 36 x 24 mm: 2 atan(43.2666 / 100) = 46.7930° (the
    // x_fov Mitsuba derives from it is checked in tests/mitsuba.rs).
    assert!((c.fov - 46.7930).abs() < 1e-4, "{}", c.fov);
    assert_eq!(c.world_from_camera, DMat4::IDENTITY);
    assert_eq!(c.origin, DVec3::ZERO);
    assert_eq!(c.target, DVec3::Z);
    assert_eq!(c.up, DVec3::Y);
    assert!(load("").camera.is_none());
}

#[test]
fn sensor_parameters() {
    let c = load(
        r#"<sensor type="perspective">
             <float name="fov" value="30"/><string name="fov_axis" value="larger"/>
             <transform name="to_world"><lookat origin="1, 2, 3" target="1, 2, 0" up="0, 1, 0"/></transform>
             <sampler type="stratified"><integer name="sample_count" value="16"/><integer name="seed" value="7"/></sampler>
             <film type="hdrfilm"><integer name="width" value="320"/><integer name="height" value="240"/>
               <rfilter type="box"/><string name="pixel_format" value="rgba"/>
               <string name="component_format" value="float16"/><string name="file_format" value="openexr"/></film>
           </sensor>"#,
    )
    .camera
    .expect("camera");
    assert_eq!(c.fov, 30.0);
    assert_eq!(c.fov_axis, FovAxis::Larger);
    assert_eq!((c.width, c.height, c.sample_count), (320, 240, 16));
    assert_eq!(c.rfilter, ReconstructionFilter::Box);
    assert_eq!(c.origin, DVec3::new(1.0, 2.0, 3.0));
    assert_eq!(c.target, DVec3::new(1.0, 2.0, 0.0));
    assert_eq!(c.up, DVec3::Y);
    // fov without fov_axis: Mitsuba's default axis is x.
    let x = load(r#"<sensor type="perspective"><float name="fov" value="40"/></sensor>"#)
        .camera
        .expect("camera");
    assert_eq!((x.fov, x.fov_axis), (40.0, FovAxis::X));
    assert_eq!(x.x_fov(), 40.0);
    for (name, axis) in [
        ("x", FovAxis::X),
        ("y", FovAxis::Y),
        ("smaller", FovAxis::Smaller),
        ("larger", FovAxis::Larger),
        ("diagonal", FovAxis::Diagonal),
    ] {
        let c = load(&format!(r#"<sensor type="perspective"><float name="fov" value="40"/><string name="fov_axis" value="{name}"/></sensor>"#)).camera.expect("camera");
        assert_eq!(c.fov_axis, axis);
    }
    for sampler in ["independent", "multijitter", "ldsampler", "orthogonal"] {
        let c = load(&format!(r#"<sensor type="perspective"><sampler type="{sampler}"><integer name="sample_count" value="8"/></sampler></sensor>"#)).camera.expect("camera");
        assert_eq!(c.sample_count, 8);
    }
}

#[test]
fn sensor_to_world_may_be_any_transform() {
    let c = load(
        r#"<sensor type="perspective"><transform name="to_world">
             <rotate y="1" angle="90"/><translate x="1" y="2" z="3"/></transform></sensor>"#,
    )
    .camera
    .expect("camera");
    assert!(c.origin.distance(DVec3::new(1.0, 2.0, 3.0)) < 1e-12);
    // Camera +z (forward) rotated 90° about +y is world +x.
    assert!(
        c.target.distance(DVec3::new(2.0, 2.0, 3.0)) < 1e-12,
        "{}",
        c.target
    );
    assert!(c.up.distance(DVec3::Y) < 1e-12);
}

#[test]
fn sensor_errors() {
    assert!(
        err(r#"<sensor type="perspective"><float name="fov" value="180"/></sensor>"#)
            .contains("fov must lie")
    );
    assert!(err(r#"<sensor type="perspective"><float name="fov" value="40"/><string name="fov_axis" value="z"/></sensor>"#).contains("unknown fov_axis"));
    assert!(err(r#"<sensor type="perspective"><transform name="to_world"><scale value="2"/></transform></sensor>"#).contains("must not scale"));
    assert!(err(r#"<sensor type="thinlens"/>"#).contains("unknown sensor plugin"));
    assert!(
        err(r#"<sensor type="perspective"><string name="fov_axis" value="y"/></sensor>"#)
            .contains("fov_axis needs a fov")
    );
    assert!(
        err(r#"<sensor type="perspective"><float name="aperture_radius" value="0.1"/></sensor>"#)
            .contains("unknown parameter \"aperture_radius\"")
    );
    assert!(err(r#"<sensor type="perspective"><film type="hdrfilm"><integer name="width" value="0"/></film></sensor>"#).contains("width must be a positive integer"));
    assert!(err(r#"<sensor type="perspective"><film type="hdrfilm"><rfilter type="sinc"/></film></sensor>"#).contains("unknown rfilter plugin"));
    assert!(
        err(r#"<sensor type="perspective"><film type="specfilm"/></sensor>"#)
            .contains("unknown film plugin")
    );
    assert!(
        err(r#"<sensor type="perspective"/><sensor type="perspective"/>"#)
            .contains("only one <sensor>")
    );
    assert!(err(r#"<sensor type="perspective"><transform name="to_world"><lookat origin="0,0,0" target="0,1,0" up="0,1,0"/></transform></sensor>"#).contains("parallel"));
}

/// Mitsuba 3.9.1's integrator parameters that change only its noise are
/// read and ignored; `max_depth` and `hide_emitters` are kept; integrators
/// that compute something else are refused (crates/trilux-scene/tests/plugin_params.rs
/// has the rest of the audit).
#[test]
fn integrator_keeps_max_depth_and_refuses_what_changes_the_image() {
    let s = load(
        r#"<integrator type="volpath"><integer name="max_depth" value="-1"/><boolean name="hide_emitters" value="false"/><integer name="rr_depth" value="3"/></integrator>"#,
    );
    assert_eq!(s.max_depth, Some(-1));
    assert!(s.warnings.is_empty(), "{:?}", s.warnings);
    assert!(err(r#"<integrator type="direct"/>"#).contains("does not compute global illumination"));
    assert!(
        load(
            r#"<integrator type="path"><boolean name="hide_emitters" value="true"/></integrator>"#
        )
        .hide_emitters
    );
}

// ---- BSDFs -------------------------------------------------------------

#[test]
fn shape_without_bsdf_is_diffuse_half() {
    let s = load(r#"<shape type="rectangle"/>"#);
    assert_eq!(
        s.shapes[0].bsdf,
        BsdfParams::Diffuse {
            reflectance: ColorParam::Float(0.5)
        }
    );
    assert!(s.bsdf_counts.is_empty());
}

#[test]
fn diffuse() {
    assert_eq!(
        bsdf(r#"<bsdf type="diffuse"/>"#),
        BsdfParams::Diffuse {
            reflectance: ColorParam::Float(0.5)
        }
    );
    let e = err(
        r#"<shape type="rectangle"><bsdf type="diffuse"><rgb name="reflectance" value="0.5, -0.1, 0.5"/></bsdf></shape>"#,
    );
    assert!(e.contains("reflectance must not be negative"), "{e}");
    let e = err(
        r#"<shape type="rectangle"><bsdf type="diffuse"><float name="reflectance" value="1.5"/></bsdf></shape>"#,
    );
    assert!(e.contains("must not exceed 1"), "{e}");
}

#[test]
fn roughconductor_defaults_and_parameters() {
    let rc = |body: &str| match bsdf(&format!(r#"<bsdf type="roughconductor">{body}</bsdf>"#)) {
        BsdfParams::RoughConductor(rc) => rc,
        other => panic!("{other:?}"),
    };
    let d = rc("");
    assert_eq!(d.distribution, Distribution::Beckmann);
    assert_eq!(d.alpha, 0.1);
    assert_eq!(d.eta_k, None);
    assert_eq!(d.specular_reflectance, ColorParam::Float(1.0));
    let g = rc(
        r#"<string name="distribution" value="ggx"/><float name="alpha" value="0.3"/>
                <string name="material" value="none"/><boolean name="sample_visible" value="false"/>
                <rgb name="specular_reflectance" value="0.9, 0.8, 0.7"/>"#,
    );
    assert_eq!((g.distribution, g.alpha), (Distribution::Ggx, 0.3));
    assert_eq!(g.specular_reflectance, ColorParam::Rgb([0.9, 0.8, 0.7]));
    assert_eq!(
        rc(r#"<float name="alpha_u" value="0.2"/><float name="alpha_v" value="0.2"/>"#).alpha,
        0.2
    );
    let m = rc(r#"<rgb name="eta" value="0.2, 0.9, 1.1"/><float name="k" value="3"/>"#);
    assert_eq!(
        m.eta_k,
        Some((ColorParam::Rgb([0.2, 0.9, 1.1]), ColorParam::Float(3.0)))
    );
    // Mitsuba's defaults for the missing half: eta 0, k 1.
    assert_eq!(
        rc(r#"<float name="k" value="2"/>"#).eta_k,
        Some((ColorParam::Float(0.0), ColorParam::Float(2.0)))
    );
}

#[test]
fn roughconductor_refusals() {
    let e = |body: &str| {
        err(&format!(
            r#"<shape type="rectangle"><bsdf type="roughconductor">{body}</bsdf></shape>"#
        ))
    };
    assert!(
        e(r#"<float name="alpha_u" value="0.1"/><float name="alpha_v" value="0.2"/>"#)
            .contains("anisotropic")
    );
    assert!(e(r#"<float name="alpha_u" value="0.1"/>"#).contains("both alpha_u and alpha_v"));
    assert!(e(r#"<float name="alpha" value="0"/>"#).contains("alpha must be positive"));
    assert!(e(r#"<float name="alpha" value="-0.1"/>"#).contains("alpha must be positive"));
    // Mitsuba's named conductors load (`Au`); a name it does not ship, or a
    // name beside eta, is refused.
    assert!(e(r#"<string name="material" value="Gold"/>"#).contains("unknown conductor material"));
    assert!(
        e(r#"<string name="material" value="Au"/><float name="eta" value="0.2"/>"#)
            .contains("not both")
    );
    assert!(
        e(r#"<string name="distribution" value="phong"/>"#)
            .contains("unknown microfacet distribution")
    );
}

#[test]
fn blendbsdf_and_twosided() {
    let b = bsdf(
        r#"<bsdf type="blendbsdf"><float name="weight" value="0.25"/>
                     <bsdf type="diffuse"/><bsdf type="roughconductor"/></bsdf>"#,
    );
    let BsdfParams::Blend {
        weight,
        first,
        second,
    } = b
    else {
        panic!()
    };
    assert_eq!(weight, 0.25);
    assert!(matches!(*first, BsdfParams::Diffuse { .. }));
    assert!(matches!(*second, BsdfParams::RoughConductor(_)));

    let one = bsdf(r#"<bsdf type="twosided"><bsdf type="diffuse"/></bsdf>"#);
    assert!(matches!(one, BsdfParams::TwoSided { back: None, .. }));
    let two =
        bsdf(r#"<bsdf type="twosided"><bsdf type="diffuse"/><bsdf type="roughconductor"/></bsdf>"#);
    let BsdfParams::TwoSided {
        front,
        back: Some(back),
    } = two
    else {
        panic!()
    };
    assert!(matches!(*front, BsdfParams::Diffuse { .. }));
    assert!(matches!(*back, BsdfParams::RoughConductor(_)));

    let e = |b: &str| err(&format!(r#"<shape type="rectangle">{b}</shape>"#));
    assert!(
        e(r#"<bsdf type="blendbsdf"><bsdf type="diffuse"/><bsdf type="diffuse"/></bsdf>"#)
            .contains("weight")
    );
    assert!(e(r#"<bsdf type="blendbsdf"><float name="weight" value="1.5"/><bsdf type="diffuse"/><bsdf type="diffuse"/></bsdf>"#).contains("[0, 1]"));
    assert!(e(r#"<bsdf type="blendbsdf"><float name="weight" value="0.5"/><bsdf type="diffuse"/></bsdf>"#).contains("exactly two"));
    assert!(e(r#"<bsdf type="twosided"/>"#).contains("one or two"));
    assert!(e(r#"<bsdf type="hair"/>"#).contains("unknown bsdf plugin \"hair\""));
    assert!(e(r#"<bsdf type="dielectric"/>"#).contains("refracts light through a thick object"));
}

#[test]
fn bsdf_counts_include_nested_ones() {
    let s = load(
        r#"<bsdf type="diffuse" id="w"/>
           <shape type="rectangle"><bsdf type="twosided"><bsdf type="blendbsdf"><float name="weight" value="0.5"/>
             <bsdf type="diffuse"/><bsdf type="roughconductor"/></bsdf></bsdf></shape>
           <shape type="rectangle"><ref id="w"/></shape>"#,
    );
    let counts: Vec<(&str, usize)> = s
        .bsdf_counts
        .iter()
        .map(|(k, v)| (k.as_str(), *v))
        .collect();
    assert_eq!(
        counts,
        [
            ("blendbsdf", 1),
            ("diffuse", 2),
            ("roughconductor", 1),
            ("twosided", 1)
        ]
    );
}

// ---- emitters -----------------------------------------------------------

#[test]
fn area_emitters() {
    let s = load(
        r#"<shape type="rectangle"><emitter type="area"><rgb name="radiance" value="1, 2, 3"/></emitter></shape>
           <shape type="rectangle"><emitter type="area"/></shape>
           <shape type="rectangle"/>"#,
    );
    assert_eq!(s.emitters().count(), 2);
    assert_eq!(
        s.shapes[0].emitter.as_ref().map(|e| e.radiance.clone()),
        Some(ColorParam::Rgb([1.0, 2.0, 3.0]))
    );
    // Mitsuba's default radiance is 1.
    assert_eq!(
        s.shapes[1].emitter.as_ref().map(|e| e.radiance.clone()),
        Some(ColorParam::Float(1.0))
    );
    assert!(err(r#"<emitter type="projector"/>"#).contains("unknown emitter plugin \"projector\""));
    assert!(err(r#"<emitter type="area"/>"#).contains("inside a <shape>"));
    assert!(
        err(r#"<shape type="rectangle"><emitter type="spot"/></shape>"#)
            .contains("a shape's emitter must be \"area\"")
    );
    assert!(err(r#"<shape type="rectangle"><emitter type="area"><float name="radiance" value="-1"/></emitter></shape>"#).contains("radiance must not be negative"));
}

#[test]
fn spectral_decision() {
    assert!(!load(r#"<shape type="rectangle"><emitter type="area"><spectrum name="radiance" value="2"/></emitter></shape>"#).spectral);
    assert!(load(r#"<shape type="rectangle"><emitter type="area"><spectrum name="radiance" value="400:1, 700:2"/></emitter></shape>"#).spectral);
    assert!(load(r#"<shape type="rectangle"><bsdf type="twosided"><bsdf type="diffuse"><spectrum name="reflectance" value="400:0.1, 700:0.2"/></bsdf></bsdf></shape>"#).spectral);
}

// ---- shapes and transforms ----------------------------------------------

#[test]
fn every_shape_kind() {
    let s = load(
        r#"<shape type="rectangle"/><shape type="cube"/><shape type="disk"/>
           <shape type="sphere"><float name="radius" value="2"/></shape>
           <shape type="cylinder"><point name="p0" value="0,0,-1"/><point name="p1" value="0,0,1"/><float name="radius" value="0.5"/></shape>
           <shape type="obj"><string name="filename" value="quad.obj"/></shape>"#,
    );
    assert!(matches!(s.shapes[0].shape.kind, ShapeKind::Rectangle));
    assert!(matches!(s.shapes[1].shape.kind, ShapeKind::Cube));
    assert!(matches!(s.shapes[2].shape.kind, ShapeKind::Disk));
    assert!(
        matches!(s.shapes[3].shape.kind, ShapeKind::Sphere { radius, center } if radius == 2.0 && center == DVec3::ZERO)
    );
    assert!(matches!(s.shapes[4].shape.kind, ShapeKind::Cylinder { radius, .. } if radius == 0.5));
    assert!(matches!(s.shapes[5].shape.kind, ShapeKind::Mesh(_)));
    // Mitsuba's cylinder defaults: p0 = 0, p1 = (0, 0, 1), radius 1.
    let c = load(r#"<shape type="cylinder"/>"#);
    assert!(
        matches!(c.shapes[0].shape.kind, ShapeKind::Cylinder { p0, p1, radius } if p0 == DVec3::ZERO && p1 == DVec3::Z && radius == 1.0)
    );
}

#[test]
fn shape_ids_locations_and_flip_normals() {
    let s = load(
        "<shape type=\"rectangle\" id=\"floor\">\n<boolean name=\"flip_normals\" value=\"true\"/></shape>\n  <shape type=\"disk\"/>",
    );
    assert_eq!(s.shapes[0].id.as_deref(), Some("floor"));
    assert_eq!(s.shapes[1].id, None);
    assert!(s.shapes[0].shape.flip_normals);
    assert!(!s.shapes[1].shape.flip_normals);
    assert_eq!(
        (s.shapes[1].location.line, s.shapes[1].location.col),
        (3, 3)
    );
}

#[test]
fn obj_meshes() {
    let s = load(
        r#"<shape type="obj"><string name="filename" value="quad.obj"/></shape>
                    <shape type="obj"><string name="filename" value="quad.obj"/><boolean name="face_normals" value="true"/></shape>"#,
    );
    let mesh = |i: usize| match &s.shapes[i].shape.kind {
        ShapeKind::Mesh(m) => m.clone(),
        _ => panic!(),
    };
    let with_vn = mesh(0);
    assert_eq!(with_vn.triangles.len(), 2);
    assert!(!with_vn.face_normals);
    // The file's vn, not the face normal.
    for n in with_vn.normals.as_ref().expect("vn") {
        assert!(n.distance(DVec3::new(0.0, 0.6, 0.8)) < 1e-6);
    }
    // Counter-clockwise seen from +z: the face normal is +z.
    let t = with_vn.triangles[0].map(|i| with_vn.positions[i as usize]);
    assert!((t[1] - t[0]).cross(t[2] - t[0]).z > 0.0);
    let flat = mesh(1);
    assert!(flat.face_normals);
    assert!(flat.normals.is_none());
    // Relative file names resolve against the scene file's folder, not the
    // working directory.
    let e = load_str(
        r#"<scene version="3.0.0"><shape type="obj"><string name="filename" value="quad.obj"/></shape></scene>"#,
        "/nonexistent/scene.xml",
    )
    .expect_err("no quad.obj there");
    assert!(e.to_string().contains("/nonexistent/quad.obj"), "{e}");
    let e = err(r#"<shape type="obj"><string name="filename" value="broken.obj"/></shape>"#);
    assert!(e.contains("malformed OBJ file"), "{e}");
    let e = err(r#"<shape type="obj"><string name="filename" value="missing.obj"/></shape>"#);
    assert!(e.contains("cannot read OBJ file"), "{e}");
    let e = err(r#"<shape type="obj"/>"#);
    assert!(e.contains("needs <string name=\"filename\">"), "{e}");
}

#[test]
fn transform_operations_compose_first_listed_first() {
    let m = |t: &str| {
        load(&format!(
            r#"<shape type="rectangle"><transform name="to_world">{t}</transform></shape>"#
        ))
        .shapes[0]
            .shape
            .world_from_object
    };
    let p = DVec3::new(1.0, 0.0, 0.0);
    // Scale, then translate: (1,0,0) → (2,0,0) → (2,5,0).
    assert!(
        m(r#"<scale value="2"/><translate y="5"/>"#)
            .transform_point3(p)
            .distance(DVec3::new(2.0, 5.0, 0.0))
            < 1e-12
    );
    // Translate, then scale: (1,0,0) → (1,5,0) → (2,10,0).
    assert!(
        m(r#"<translate y="5"/><scale value="2"/>"#)
            .transform_point3(p)
            .distance(DVec3::new(2.0, 10.0, 0.0))
            < 1e-12
    );
    // Rotate +90° about z maps x to y (right-handed).
    assert!(
        m(r#"<rotate z="1" angle="90"/>"#)
            .transform_point3(p)
            .distance(DVec3::Y)
            < 1e-12
    );
    assert_eq!(
        m(r#"<scale x="2" y="3" z="4"/>"#),
        DMat4::from_scale(DVec3::new(2.0, 3.0, 4.0))
    );
    assert_eq!(
        m(r#"<scale value="2, 3, 4"/>"#),
        DMat4::from_scale(DVec3::new(2.0, 3.0, 4.0))
    );
    assert_eq!(
        m(r#"<translate value="1 2 3"/>"#),
        DMat4::from_translation(DVec3::new(1.0, 2.0, 3.0))
    );
    // matrix is written row by row.
    let mm = m(r#"<matrix value="1 0 0 7  0 1 0 8  0 0 1 9  0 0 0 1"/>"#);
    assert_eq!(mm.transform_point3(DVec3::ZERO), DVec3::new(7.0, 8.0, 9.0));
    // A lookat in a shape's to_world places +z towards the target.
    let l = m(r#"<lookat origin="0, 0, 5" target="0, 0, 0" up="0, 1, 0"/>"#);
    assert!(l.transform_vector3(DVec3::Z).distance(-DVec3::Z) < 1e-12);
    assert!(
        l.transform_point3(DVec3::ZERO)
            .distance(DVec3::new(0.0, 0.0, 5.0))
            < 1e-12
    );
}

#[test]
fn transform_refusals() {
    let e = |t: &str| {
        err(&format!(
            r#"<shape type="rectangle"><transform name="to_world">{t}</transform></shape>"#
        ))
    };
    assert!(e(r#"<rotate value="1, 1, 0" angle="30"/>"#).contains("unit vector"));
    assert!(e(r#"<rotate x="1"/>"#).contains("needs the attribute \"angle\""));
    assert!(e(r#"<rotate axis="1, 0, 0" angle="30"/>"#).contains("unexpected attribute \"axis\""));
    assert!(e(r#"<matrix value="1 0 0 0"/>"#).contains("expected 16 numbers"));
    assert!(e(r#"<shear value="1"/>"#).contains("unknown transform operation <shear>"));
    assert!(e(r#"<scale value="0"/>"#).contains("singular"));
    assert!(e(r#"<scale x="1" y="0"/>"#).contains("singular"));
    assert!(e(r#"<translate x="inf"/>"#).contains("not a finite number"));
}

#[test]
fn zero_and_degenerate_shapes_are_refused() {
    assert!(
        err(r#"<shape type="sphere"><float name="radius" value="0"/></shape>"#)
            .contains("radius must be positive")
    );
    assert!(
        err(r#"<shape type="cylinder"><float name="radius" value="-1"/></shape>"#)
            .contains("radius must be positive")
    );
    assert!(
        err(r#"<shape type="cylinder"><point name="p1" value="0, 0, 0"/></shape>"#)
            .contains("zero length")
    );
    assert!(
        err(
            r#"<shape type="sphere"><transform name="to_world"><scale x="2"/></transform></shape>"#
        )
        .contains("uniformly")
    );
    assert!(err(r#"<shape type="cylinder"><transform name="to_world"><scale x="2"/></transform></shape>"#).contains("circular"));
    assert!(err(r#"<shape type="rectangle"><transform name="to_world"><matrix value="1 1 0 0  1 1 0 0  0 0 1 0  0 0 0 1"/></transform></shape>"#).contains("singular"));
}

/// Every `<rfilter>` Mitsuba 3 has, with its parameters and defaults
/// (Mitsuba's documentation: tent radius 1, Mitchell B = C = 1/3,
/// Catmull–Rom B = 0 and C = 1/2, Lanczos 3 lobes, Gaussian stddev 0.5).
#[test]
fn reconstruction_filters_and_their_parameters() {
    let filter = |body: &str| {
        load(&format!(
            r#"<sensor type="perspective"><film type="hdrfilm">{body}</film></sensor>"#
        ))
        .camera
        .expect("camera")
        .rfilter
    };
    use ReconstructionFilter as F;
    assert_eq!(filter(""), F::Gaussian { stddev: 0.5 });
    assert_eq!(
        filter(r#"<rfilter type="gaussian"><float name="stddev" value="0.3"/></rfilter>"#),
        F::Gaussian { stddev: 0.3 }
    );
    assert_eq!(filter(r#"<rfilter type="tent"/>"#), F::Tent { radius: 1.0 });
    assert_eq!(
        filter(r#"<rfilter type="tent"><float name="radius" value="1.5"/></rfilter>"#),
        F::Tent { radius: 1.5 }
    );
    assert_eq!(
        filter(r#"<rfilter type="mitchell"/>"#),
        F::Mitchell {
            b: 1.0 / 3.0,
            c: 1.0 / 3.0
        }
    );
    assert_eq!(
        filter(
            r#"<rfilter type="mitchell"><float name="B" value="0.5"/><float name="C" value="0.25"/></rfilter>"#
        ),
        F::Mitchell { b: 0.5, c: 0.25 }
    );
    assert_eq!(
        filter(r#"<rfilter type="catmullrom"/>"#),
        F::Mitchell { b: 0.0, c: 0.5 }
    );
    assert_eq!(
        filter(r#"<rfilter type="lanczos"/>"#),
        F::Lanczos { lobes: 3 }
    );
    let sensor = |body: &str| {
        format!(r#"<sensor type="perspective"><film type="hdrfilm">{body}</film></sensor>"#)
    };
    for (body, what) in [
        (
            r#"<rfilter type="tent"><float name="radius" value="-1"/></rfilter>"#,
            "radius must be positive",
        ),
        (
            r#"<rfilter type="gaussian"><float name="stddev" value="5"/></rfilter>"#,
            "at most 16 px, found 5",
        ),
        (
            r#"<rfilter type="lanczos"><integer name="lobes" value="40"/></rfilter>"#,
            "lobes must be between 1 and 16",
        ),
        (
            r#"<rfilter type="mitchell"><float name="b" value="0.5"/></rfilter>"#,
            "unknown parameter \"b\"",
        ),
    ] {
        let e = err(&sensor(body));
        assert!(e.contains(what), "{body}: {e}");
    }
}

/// `<spectrum type="blackbody">`: Mitsuba 3.9.1's own values
/// (`mi.load_dict({'type': 'blackbody', 'temperature': 3000}).eval`,
/// scalar_spectral, W m⁻² sr⁻¹ nm⁻¹) at its samples, zero outside
/// 360–830 nm; 1e-5 relative (Mitsuba's single precision).
#[test]
fn blackbody_spectra_are_mitsubas() {
    let scene = load(
        r#"<shape type="rectangle"><emitter type="area"><spectrum name="radiance" type="blackbody">
             <float name="temperature" value="3000"/></spectrum></emitter></shape>"#,
    );
    assert!(scene.spectral, "a blackbody makes the scene spectral");
    let radiance = &scene.shapes[0]
        .emitter
        .as_ref()
        .expect("an emitter")
        .radiance;
    let trilux_color::ColorParam::Sampled(samples) = radiance else {
        panic!("{radiance:?}");
    };
    let at = |nm: f64| {
        samples
            .iter()
            .find(|(l, _)| *l == nm)
            .map(|(_, v)| *v)
            .expect("a sample there")
    };
    for (nm, mitsuba) in [
        (360.0, 32.265_571_594_238_28),
        (400.0, 72.197_395_324_707_03),
        (500.0, 260.267_669_677_734_4),
        (550.0, 386.542_327_880_859_4),
        (600.0, 517.502_075_195_312_5),
        (700.0, 750.596_374_511_718_8),
        (830.0, 938.497_070_312_5),
    ] {
        assert!(
            (at(nm) / mitsuba - 1.0).abs() < 1e-5,
            "{nm} nm: {} vs {mitsuba}",
            at(nm)
        );
    }
    assert_eq!(samples.first().map(|s| s.0), Some(360.0));
    assert_eq!(samples.last().map(|s| s.0), Some(830.0));
    let emitter = |spectrum: &str| {
        err(&format!(
            r#"<shape type="rectangle"><emitter type="area">{spectrum}</emitter></shape>"#
        ))
    };
    for (spectrum, what) in [
        (
            r#"<spectrum name="radiance" type="blackbody"/>"#,
            "needs <float name=\"temperature\"",
        ),
        (
            r#"<spectrum name="radiance" type="d65"/>"#,
            "unknown spectrum plugin \"d65\"",
        ),
        (
            r#"<spectrum name="radiance" type="blackbody"><float name="temperature" value="-5"/></spectrum>"#,
            "temperature must be between 1 and 1000000 K, found -5",
        ),
        (
            r#"<spectrum name="radiance" type="blackbody"><float name="scale" value="2"/></spectrum>"#,
            "takes one <float name=\"temperature\">",
        ),
    ] {
        let e = emitter(spectrum);
        assert!(e.contains(what), "{spectrum}: {e}");
    }
}

/// Mitsuba's crop window: `crop_offset_*` default 0, `crop_width` and
/// `crop_height` the rest of the film; it must fit in the film.
#[test]
fn crop_windows() {
    let film = |params: &str| {
        let body = format!(
            r#"<sensor type="perspective"><film type="hdrfilm"><integer name="width" value="80"/><integer name="height" value="64"/>{params}</film></sensor>"#
        );
        try_load(&body).map(|s| s.camera.expect("camera").crop)
    };
    assert_eq!(film("").unwrap(), None);
    let c = film(
        r#"<integer name="crop_offset_x" value="20"/><integer name="crop_height" value="30"/>"#,
    )
    .unwrap()
    .expect("a crop");
    assert_eq!((c.offset, c.size), ([20, 0], [60, 30]));
    let e = film(
        r#"<integer name="crop_offset_x" value="50"/><integer name="crop_width" value="40"/>"#,
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("the crop window 40 × 64 at (50, 0) must lie within the 80 × 64 film"),
        "{e}"
    );
}

/// `near_clip` and `far_clip` as written; none when unwritten (not
/// Mitsuba's 0.01 and 10⁴, which would cut scenes within trilux's range).
#[test]
fn clip_planes() {
    let camera = |params: &str| {
        load(&format!(
            r#"<sensor type="perspective"><float name="fov" value="40"/>{params}</sensor>"#
        ))
        .camera
        .expect("camera")
    };
    let c = camera("");
    assert_eq!((c.near_clip, c.far_clip), (0.0, f64::INFINITY));
    let c = camera(r#"<float name="near_clip" value="0.1"/><float name="far_clip" value="100"/>"#);
    assert_eq!((c.near_clip, c.far_clip), (0.1, 100.0));
    assert_eq!(c.principal_point_offset, [0.0; 2]);
    let c = camera(
        r#"<float name="principal_point_offset_x" value="0.1"/><float name="principal_point_offset_y" value="-0.2"/>"#,
    );
    assert_eq!(c.principal_point_offset, [0.1, -0.2]);
    let e = err(
        r#"<sensor type="perspective"><float name="principal_point_offset_x" value="3"/></sensor>"#,
    );
    assert!(
        e.contains("principal_point_offset_x must be within [-1, 1]"),
        "{e}"
    );
    let e = err(r#"<sensor type="perspective"><float name="near_clip" value="0"/></sensor>"#);
    assert!(
        e.contains("near_clip must be a positive number, found 0"),
        "{e}"
    );
    let e = err(
        r#"<sensor type="perspective"><float name="near_clip" value="2"/><float name="far_clip" value="1"/></sensor>"#,
    );
    assert!(
        e.contains("far_clip 1 must be larger than near_clip 2"),
        "{e}"
    );
}

#[test]
fn unknown_things_are_refused() {
    assert!(err(r#"<shape type="heightfield"/>"#).contains("unknown shape plugin \"heightfield\""));
    assert!(
        err(r#"<shape type="rectangle"><float name="size" value="2"/></shape>"#)
            .contains("unknown parameter \"size\" for <shape type=\"rectangle\">")
    );
    assert!(err(r#"<texture type="bitmap"/>"#).contains("unsupported element <texture>"));
    assert!(
        err(r#"<shape type="rectangle"><bsdf type="diffuse"/><bsdf type="diffuse"/></shape>"#)
            .contains("at most one <bsdf>")
    );
    assert!(err(r#"<shape type="rectangle"><float name="x" value="1"/><float name="x" value="2"/></shape>"#).contains("given twice"));
    assert!(err(r#"<shape type="rectangle" foo="1"/>"#).contains("unexpected attribute \"foo\""));
    assert!(err(r#"<shape type="rectangle">hello</shape>"#).contains("unexpected text"));
}

#[test]
fn scene_root_and_version() {
    let e =
        load_str("<scene><shape type=\"rectangle\"/></scene>", "a.xml").expect_err("no version");
    assert!(e.to_string().starts_with("a.xml:1:1: "), "{e}");
    let e = load_str("<scene version=\"0.6.0\"/>", "a.xml").expect_err("old version");
    assert!(e.to_string().contains("unsupported scene version"), "{e}");
    let e = load_str("<shape type=\"rectangle\"/>", "a.xml").expect_err("no scene root");
    assert!(
        e.to_string().contains("the root element must be <scene>"),
        "{e}"
    );
    assert!(load_str("<scene version=\"2.1.0\"/>", "a.xml").is_ok());
}

/// `<include>`: the included file's elements take its place; `$name`s are
/// shared as Mitsuba 3.9.1 shares them (checked with `mi.load_file` on the
/// same files: a `<default>` before the include wins over the included
/// file's, 0.7; one defined only in the included file applies after it,
/// 0.3); mesh files are named relative to the scene file's folder, as in
/// Mitsuba; errors name the file they are in.
#[test]
fn includes_share_parameters_as_mitsuba_does() {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("scene-include");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(dir.join("sub")).unwrap();
    let write = |name: &str, text: &str| std::fs::write(dir.join(name), text).unwrap();
    write(
        "sub/part.xml",
        r#"<scene version="3.0.0">
  <default name="r" value="0.3"/>
  <bsdf type="diffuse" id="grey"><float name="reflectance" value="$r"/></bsdf>
  <shape type="rectangle"><ref id="grey"/></shape>
</scene>"#,
    );
    write(
        "first.xml",
        r#"<scene version="3.0.0">
  <default name="r" value="0.7"/>
  <include filename="sub/part.xml"/>
  <shape type="sphere"><ref id="grey"/></shape>
</scene>"#,
    );
    write(
        "after.xml",
        r#"<scene version="3.0.0">
  <include filename="sub/part.xml"/>
  <shape type="sphere"><bsdf type="diffuse"><float name="reflectance" value="$r"/></bsdf></shape>
</scene>"#,
    );
    let reflectances = |file: &str| -> Vec<ColorParam> {
        let scene = trilux_scene::load(dir.join(file)).unwrap();
        scene
            .shapes
            .iter()
            .map(|s| match &s.bsdf {
                BsdfParams::Diffuse { reflectance } => reflectance.clone(),
                other => panic!("{other:?}"),
            })
            .collect()
    };
    assert_eq!(reflectances("first.xml"), vec![ColorParam::Float(0.7); 2]);
    assert_eq!(reflectances("after.xml"), vec![ColorParam::Float(0.3); 2]);

    let err = |file: &str| trilux_scene::load(dir.join(file)).unwrap_err().to_string();
    write(
        "a.xml",
        r#"<scene version="3.0.0"><include filename="b.xml"/></scene>"#,
    );
    write(
        "b.xml",
        r#"<scene version="3.0.0"><include filename="a.xml"/></scene>"#,
    );
    let e = err("a.xml");
    assert!(
        e.contains("b.xml:1:") && e.contains("include cycle: "),
        "{e}"
    );
    write(
        "missing.xml",
        r#"<scene version="3.0.0"><include filename="nope.xml"/></scene>"#,
    );
    let e = err("missing.xml");
    assert!(
        e.contains("missing.xml:1:") && e.contains("cannot read the included file"),
        "{e}"
    );
    write(
        "nested.xml",
        r#"<scene version="3.0.0"><shape type="cube"><include filename="sub/part.xml"/></shape></scene>"#,
    );
    assert!(err("nested.xml").contains("<include> belongs directly in <scene>"));
    write(
        "bad-part.xml",
        r#"<scene version="3.0.0">
<shape type="teapot"/></scene>"#,
    );
    write(
        "uses-bad.xml",
        r#"<scene version="3.0.0"><include filename="bad-part.xml"/></scene>"#,
    );
    let e = err("uses-bad.xml");
    assert!(
        e.contains("bad-part.xml:2:") && e.contains("unknown shape plugin \"teapot\""),
        "{e}"
    );
}
