//! The bake as a library: a closed box solved through the solver's API,
//! baked, and the file read back by hand (and by the `gltf` crate).
//!
//! The box is six unit-reflectance-0.5 Lambertian squares facing inwards,
//! the ceiling emitting Le = 1. What the file must show is derived without
//! the bake's code:
//! - the GLB container as the glTF 2.0 specification (§4.4) lays it out;
//! - per input surface and side, the flux the viewer shows (linear
//!   interpolation of `_RADIANCE` over each triangle: area × mean of the
//!   three vertices) equals the flux of the solution's leaves (radiance ×
//!   area), the bake's conservation rule;
//! - summed over the box, ∫ L dA = Le·A_emitter / (1 − ρ): in a closed box
//!   every ray leaving a surface lands on one, so the outgoing flux is the
//!   emitted flux plus ρ times itself;
//! - the back sides (outside the box, a one-sided material) are black.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test, bench or example may panic

use std::f64::consts::FRAC_PI_2;

use glam::{DMat4, DVec3};
use serde_json::Value;
use trilux_bake::{BakeInput, BakeOptions, bake};
use trilux_brdf::BsdfParams;
use trilux_color::ColorParam;
use trilux_geometry::{FaceId, Shape, ShapeKind, Side, SurfaceId};
use trilux_solver::{Quality, SceneDescription, Solution, Solver, SolverSettings};

const RHO: f64 = 0.5;
const LE: f64 = 1.0;
/// Each face of the box [-1, 1]³: Mitsuba's rectangle is [-1, 1]².
const FACE_AREA: f64 = 4.0;

/// The box's six faces, normals inwards; the first is the ceiling.
fn box_shapes() -> Vec<Shape> {
    let face = |translate: DVec3, rotate: DMat4| Shape {
        kind: ShapeKind::Rectangle,
        world_from_object: DMat4::from_translation(translate) * rotate,
        flip_normals: false,
    };
    vec![
        face(DVec3::Z, DMat4::from_rotation_x(2.0 * FRAC_PI_2)),
        face(-DVec3::Z, DMat4::IDENTITY),
        face(-DVec3::X, DMat4::from_rotation_y(FRAC_PI_2)),
        face(DVec3::X, DMat4::from_rotation_y(-FRAC_PI_2)),
        face(-DVec3::Y, DMat4::from_rotation_x(-FRAC_PI_2)),
        face(DVec3::Y, DMat4::from_rotation_x(FRAC_PI_2)),
    ]
}

fn solve() -> (Solution<3>, Vec<BsdfParams>) {
    let shapes = box_shapes();
    let bsdfs = vec![
        BsdfParams::Diffuse {
            reflectance: ColorParam::Float(RHO),
        };
        6
    ];
    let mut emission = vec![None; 6];
    emission[0] = Some(ColorParam::Float(LE));
    let input = SceneDescription {
        shapes: &shapes,
        bsdfs: &bsdfs,
        emission: &emission,
    };
    let mut settings = SolverSettings::preset(Quality::Default);
    settings.convergence = 0.999;
    settings.max_depth = 3;
    let solution = Solver::<3>::from_description(&input, settings)
        .expect("the box builds")
        .solve(|_| {});
    (solution, bsdfs)
}

/// The GLB's JSON and BIN chunks, checking the container (glTF 2.0 §4.4).
fn chunks(glb: &[u8]) -> (Value, &[u8]) {
    let u32_at = |at: usize| u32::from_le_bytes(glb[at..at + 4].try_into().unwrap()) as usize;
    assert_eq!(&glb[0..4], b"glTF", "magic");
    assert_eq!(u32_at(4), 2, "version");
    assert_eq!(u32_at(8), glb.len(), "the header's length is the file's");
    let json_len = u32_at(12);
    assert_eq!(&glb[16..20], b"JSON");
    assert_eq!(json_len % 4, 0, "the JSON chunk is padded to 4 bytes");
    let json: Value = serde_json::from_slice(&glb[20..20 + json_len]).expect("valid JSON");
    let bin_at = 20 + json_len;
    let bin_len = u32_at(bin_at);
    assert_eq!(&glb[bin_at + 4..bin_at + 8], b"BIN\0");
    assert_eq!(bin_len % 4, 0, "the BIN chunk is padded to 4 bytes");
    assert_eq!(
        bin_at + 8 + bin_len,
        glb.len(),
        "nothing after the BIN chunk"
    );
    (json, &glb[bin_at + 8..])
}

/// An accessor's data as little-endian 4-byte words, `width` per element.
fn accessor(json: &Value, bin: &[u8], index: &Value, width: usize) -> Vec<[u8; 4]> {
    let a = &json["accessors"][index.as_u64().unwrap() as usize];
    let view = &json["bufferViews"][a["bufferView"].as_u64().unwrap() as usize];
    let offset = view["byteOffset"].as_u64().unwrap() as usize;
    let count = a["count"].as_u64().unwrap() as usize;
    assert_eq!(offset % 4, 0);
    assert_eq!(
        view["byteLength"].as_u64().unwrap() as usize,
        4 * width * count
    );
    bin[offset..offset + 4 * width * count]
        .chunks_exact(4)
        .map(|w| w.try_into().unwrap())
        .collect()
}

fn vec3s(json: &Value, bin: &[u8], index: &Value) -> Vec<DVec3> {
    let words = accessor(json, bin, index, 3);
    words
        .chunks_exact(3)
        .map(|c| DVec3::from_array(std::array::from_fn(|k| f64::from(f32::from_le_bytes(c[k])))))
        .collect()
}

/// ∫ L dA over the primitive's triangles, per channel, as a viewer
/// interpolating `_RADIANCE` linearly shows it.
fn primitive_flux(json: &Value, bin: &[u8], primitive: &Value) -> DVec3 {
    let positions = vec3s(json, bin, &primitive["attributes"]["POSITION"]);
    let radiance = vec3s(json, bin, &primitive["attributes"]["_RADIANCE"]);
    let indices: Vec<usize> = accessor(json, bin, &primitive["indices"], 1)
        .into_iter()
        .map(|w| u32::from_le_bytes(w) as usize)
        .collect();
    let mut flux = DVec3::ZERO;
    for t in indices.chunks_exact(3) {
        let [a, b, c] = [t[0], t[1], t[2]].map(|i| positions[i]);
        let area = 0.5 * (b - a).cross(c - a).length();
        flux += area * (radiance[t[0]] + radiance[t[1]] + radiance[t[2]]) / 3.0;
    }
    flux
}

/// Σ over the surface's leaves of radiance × exposed area on `side`
/// (buried parts send nothing), from the solution itself.
fn solution_flux(solution: &Solution<3>, surface: SurfaceId, side: Side) -> DVec3 {
    let forest = solution.forest();
    let face = FaceId::new(surface, side);
    forest
        .leaves(forest.root(surface))
        .into_iter()
        .map(|leaf| {
            DVec3::from_array(solution.face_radiance(face, leaf).0)
                * solution.exposed_area(face, leaf)
        })
        .sum()
}

#[test]
fn a_baked_closed_box_keeps_its_flux_and_is_valid_gltf() {
    let (solution, bsdfs) = solve();
    let names: Vec<Option<String>> = (0..6).map(|i| Some(format!("face {i}"))).collect();
    let input = BakeInput {
        solution: &solution,
        materials: &bsdfs,
        names: &names,
        camera: None,
        glossy: None,
        gathered: None,
    };
    let baked = bake(&input, &BakeOptions::default()).expect("the box bakes");
    assert_eq!(baked.stats.bytes, baked.glb.len());

    // The container, then the glTF crate's own reading of the file.
    let (json, bin) = chunks(&baked.glb);
    assert_eq!(json["asset"]["version"], "2.0");
    let declared = json["buffers"][0]["byteLength"].as_u64().unwrap() as usize;
    assert!(
        declared <= bin.len() && bin.len() < declared + 4,
        "buffer length"
    );
    gltf::Gltf::from_slice(&baked.glb).expect("the gltf crate reads and validates the file");

    // One mesh per shape, one primitive per input surface and side.
    let meshes = json["meshes"].as_array().unwrap();
    assert_eq!(meshes.len(), 6);
    let mut total_front = DVec3::ZERO;
    let mut sides_seen = 0;
    for mesh in meshes {
        for primitive in mesh["primitives"].as_array().unwrap() {
            let trilux = &primitive["extras"]["trilux"];
            let surface = SurfaceId(trilux["surface"].as_u64().unwrap() as u32);
            let side = match trilux["side"].as_str().unwrap() {
                "front" => Side::Front,
                "back" => Side::Back,
                other => panic!("side {other}"),
            };
            sides_seen += 1;
            let shown = primitive_flux(&json, bin, primitive);
            let solved = solution_flux(&solution, surface, side);
            // Conservation per surface and side, to the f32 rounding of
            // the file's positions and radiance.
            for c in 0..3 {
                assert!(
                    (shown[c] - solved[c]).abs() <= 1e-5 * solved[c].max(1e-3),
                    "surface {surface:?} {side:?}: the file shows {shown}, the solution has {solved}"
                );
            }
            match side {
                Side::Front => {
                    // Every inner face is lit.
                    assert!(
                        shown.min_element() > 0.05 * FACE_AREA,
                        "{surface:?}: {shown}"
                    );
                    total_front += shown;
                }
                Side::Back => assert_eq!(shown, DVec3::ZERO, "{surface:?}: a back side is black"),
            }
        }
    }
    assert_eq!(sides_seen, 12);
    // The closed box's balance: ∫ L dA = Le A_e / (1 − ρ) = 8. Stopped at
    // CR 0.999, the solve still holds 0.1 % of the emitted flux unshot,
    // whose later reflections are missing: (1 − CR)·ρ = 0.05 % of the
    // total. Tolerance 0.1 %, twice that (measured 0.054 %).
    let expected = LE * FACE_AREA / (1.0 - RHO);
    eprintln!("closed box: ∫ L dA over the file = {total_front} (expected {expected})");
    for c in 0..3 {
        assert!(
            (total_front[c] - expected).abs() < 1e-3 * expected,
            "∫ L dA = {total_front}, expected {expected}"
        );
    }
    // The bake's own check agrees.
    assert!(baked.stats.max_flux_error < 1e-9, "{:?}", baked.stats);
}

/// A stand-in for the renderer's glossy light, a quadratic polynomial of
/// the direction scaled by the position: order-2 spherical harmonics hold
/// it exactly, so the file must give it back at every vertex.
struct Quadratic;

fn quadratic(p: DVec3, w: DVec3) -> [f64; 3] {
    let s = 2.0 + p.x + 0.5 * p.y;
    [
        s * (1.0 + 0.3 * w.x - 0.2 * w.z),
        s * (0.5 + w.x * w.y),
        s * (0.2 + 0.4 * w.z * w.z - 0.1 * w.y),
    ]
}

impl trilux_bake::GlossyLight for Quadratic {
    fn outgoing(
        &self,
        points: &[trilux_bake::GlossyPoint],
        directions: &[DVec3],
        _samples: trilux_bake::GlossySamples,
    ) -> Vec<[f64; 3]> {
        let per = directions.len() / points.len();
        directions
            .iter()
            .enumerate()
            .map(|(k, &w)| quadratic(points[k / per].point, w))
            .collect()
    }
}

/// The real spherical harmonics of order 2 from their closed forms
/// (Sloan, "Stupid spherical harmonics tricks", appendix A2).
fn sh(w: DVec3) -> [f64; 9] {
    use std::f64::consts::PI;
    let (x, y, z) = (w.x, w.y, w.z);
    let (c1, c2) = ((3.0 / (4.0 * PI)).sqrt(), 0.5 * (15.0 / PI).sqrt());
    [
        0.5 / PI.sqrt(),
        c1 * y,
        c1 * z,
        c1 * x,
        c2 * x * y,
        c2 * y * z,
        0.25 * (5.0 / PI).sqrt() * (3.0 * z * z - 1.0),
        c2 * x * z,
        0.25 * (15.0 / PI).sqrt() * (x * x - y * y),
    ]
}

#[test]
fn a_glossy_floor_carries_its_glossy_light_as_harmonics_and_a_lobe() {
    let shapes = box_shapes();
    let mut bsdfs = vec![
        BsdfParams::Diffuse {
            reflectance: ColorParam::Float(RHO),
        };
        6
    ];
    bsdfs[1] = BsdfParams::RoughConductor(trilux_brdf::RoughConductorParams {
        distribution: trilux_brdf::Distribution::Ggx,
        alpha: 0.3,
        eta_k: None,
        specular_reflectance: ColorParam::Float(0.8),
    });
    let mut emission = vec![None; 6];
    emission[0] = Some(ColorParam::Float(LE));
    let input = SceneDescription {
        shapes: &shapes,
        bsdfs: &bsdfs,
        emission: &emission,
    };
    let mut settings = SolverSettings::preset(Quality::Draft);
    settings.max_depth = 2;
    let solution = Solver::<3>::from_description(&input, settings)
        .expect("the box builds")
        .solve(|_| {});
    let names: Vec<Option<String>> = vec![None; 6];
    let input = BakeInput {
        solution: &solution,
        materials: &bsdfs,
        names: &names,
        camera: None,
        glossy: Some(&Quadratic),
        gathered: None,
    };
    // Without: the glossy light is left out and the floor marked.
    let mut without = BakeOptions::default();
    without.glossy = false;
    let plain = bake(&input, &without).expect("the box bakes");
    let (json, _) = chunks(&plain.glb);
    assert!(!String::from_utf8_lossy(&plain.glb).contains("_TRILUX_SH0"));
    let left_out = json["materials"]
        .as_array()
        .expect("materials")
        .iter()
        .filter(|m| m["extras"]["trilux"]["glossy_left_out"] == true)
        .count();
    assert_eq!(left_out, 1, "the floor's front is marked");
    assert_eq!(plain.stats.glossy_vertices, 0);
    // On by default.
    let baked = bake(&input, &BakeOptions::default()).expect("the box bakes");
    let (json, bin) = chunks(&baked.glb);
    gltf::Gltf::from_slice(&baked.glb).expect("the gltf crate reads the file");
    let mut glossy_primitives = 0;
    for mesh in json["meshes"].as_array().unwrap() {
        let shape = mesh["extras"]["trilux"]["shape"].as_u64().unwrap();
        for p in mesh["primitives"].as_array().unwrap() {
            let material = &json["materials"][p["material"].as_u64().unwrap() as usize];
            let front = p["extras"]["trilux"]["side"] == "front";
            let glossy = shape == 1 && front;
            let attrs = &p["attributes"];
            assert_eq!(attrs.get("_TRILUX_SH0").is_some(), glossy, "shape {shape}");
            assert_eq!(material["extras"]["trilux"]["glossy_left_out"], false);
            if !glossy {
                continue;
            }
            glossy_primitives += 1;
            assert_eq!(material["extras"]["trilux"]["glossy"], "sh2+lobe");
            let lobe = vec3s(&json, bin, &attrs["_TRILUX_LOBE"]);
            let amplitude = vec3s(&json, bin, &attrs["_TRILUX_LOBE_RGB"]);
            let positions = vec3s(&json, bin, &attrs["POSITION"]);
            let normals = vec3s(&json, bin, &attrs["NORMAL"]);
            let c: Vec<Vec<DVec3>> = (0..9)
                .map(|j| vec3s(&json, bin, &attrs[format!("_TRILUX_SH{j}")]))
                .collect();
            for (v, (&p, &n)) in positions.iter().zip(&normals).enumerate() {
                // Directions over the front hemisphere, grazing ones too.
                for w in [
                    n,
                    (n + DVec3::X).normalize(),
                    (n - 0.9 * DVec3::Y).normalize(),
                ] {
                    let y = sh(w);
                    // The lobe adds nothing the harmonics span.
                    let g = (lobe[v].dot(w) - lobe[v].length()).exp();
                    let got: DVec3 =
                        (0..9).map(|j| c[j][v] * y[j]).sum::<DVec3>() + amplitude[v] * g;
                    let want = DVec3::from_array(quadratic(p, w));
                    assert!(
                        (got - want).abs().max_element() < 1e-4,
                        "{p} {w}: {got} vs {want}"
                    );
                }
            }
        }
    }
    assert_eq!(glossy_primitives, 1);
    assert!(baked.stats.glossy_vertices > 0);
}

/// A renderer that has no links to read (a solution without gather
/// links) answers `None`.
struct NoLinks;

impl trilux_bake::GatheredLight for NoLinks {
    fn irradiance(&self, _points: &[trilux_bake::GlossyPoint]) -> Option<Vec<[f64; 3]>> {
        None
    }
}

/// Asked for the gathered light where there is none, the bake keeps the
/// leaves' values: the same file as the default bake, not black sides.
#[test]
fn gathered_light_without_links_keeps_the_leaves() {
    let (solution, bsdfs) = solve();
    let names: Vec<Option<String>> = vec![None; 6];
    let input = |gathered: Option<&'static dyn trilux_bake::GatheredLight>| BakeInput {
        solution: &solution,
        materials: &bsdfs,
        names: &names,
        camera: None,
        glossy: None,
        gathered,
    };
    let leaves = bake(&input(None), &BakeOptions::default()).expect("the box bakes");
    let mut asked = BakeOptions::default();
    asked.diffuse = trilux_bake::DiffuseLight::Gathered;
    let fallback = bake(&input(Some(&NoLinks)), &asked).expect("the box bakes");
    assert_eq!(leaves.glb, fallback.glb);
    assert!(fallback.stats.max_flux_error < 1e-9, "{:?}", fallback.stats);
}
