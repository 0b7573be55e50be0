//! The solution surface by surface against an independent renderer: for
//! every non-emitting shape of the Cornell box (RGB mode, default quality),
//! the area mean of the reflected radiance leaving its front face against
//! Mitsuba 3's irradiance meters (ρ Ē / π, path tracing with unbounded depth:
//! tests/golden/surfaces/cornell-box.json, made by
//! tests/golden/surface_irradiance.py, which says how).
//!
//! Tolerance: 2 % per face (band sum) and 1.5 % for the area-weighted
//! total. The reference's own noise is ≤ 0.12 % (its `relative_stderr`);
//! the rest is the solver's discretisation at the default quality (flux
//! threshold 1e-5 of the emitted flux, piecewise-constant radiance near
//! the boxes' contact with the floor), measured at 0.3–1.4 % per face and
//! 0.86 % in total (docs/results.md, "The solution surface by surface").
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test, bench or example may panic

use std::path::PathBuf;

mod common;

use trilux_geometry::Side;
use trilux_solver::{Quality, Solver, SolverSettings};

#[test]
fn cornell_box_faces_match_mitsuba_irradiance_meters() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
    let text = std::fs::read_to_string(root.join("tests/golden/surfaces/cornell-box.json"))
        .expect("reference present");
    let reference: serde_json::Value = serde_json::from_str(&text).expect("valid JSON");
    let scene = common::prepare(&root.join("scenes/cornell-box.xml").display().to_string());
    let solution = Solver::<3>::new(scene, SolverSettings::preset(Quality::Default))
        .expect("builds")
        .solve(|_| {});
    let geom = solution.forest().geometry();
    let (mut total_ref, mut total_got) = (0.0, 0.0);
    let shapes = reference["shapes"].as_array().expect("shapes");
    assert!(shapes.len() >= 7);
    for entry in shapes {
        let shape = entry["shape"].as_u64().expect("shape") as u32;
        let want: f64 = entry["radiance"]
            .as_array()
            .expect("radiance")
            .iter()
            .map(|v| v.as_f64().expect("number"))
            .sum();
        let area: f64 = geom
            .surfaces_of_shape(shape)
            .into_iter()
            .map(|s| geom.surface(s).area())
            .sum();
        let got = solution.shape_mean_radiance(shape, Side::Front).sum();
        let ratio = got / want;
        eprintln!("shape {shape}: trilux {got:.5} Mitsuba {want:.5} ratio {ratio:.4}");
        assert!((ratio - 1.0).abs() <= 0.02, "shape {shape}: ratio {ratio}");
        total_ref += want * area;
        total_got += got * area;
    }
    let ratio = total_got / total_ref;
    eprintln!("area-weighted total ratio {ratio:.4}");
    assert!((ratio - 1.0).abs() <= 0.015, "total ratio {ratio}");
}
