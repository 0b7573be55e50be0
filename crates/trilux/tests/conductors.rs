//! Smooth and named conductors through the binary against Mitsuba 3.9.1:
//! `scenes/conductors/metal-box.xml` (a closed diffuse box with a copper
//! mirror floor, a rough gold block and an aluminium mirror sphere under
//! an area light), its reference by `scenes/conductors/make_references.py`
//! (4096 spp in 16 passes; the image mean's relative standard error is in
//! its JSON, at most 0.1 %).
//!
//! Tolerance on the mean of all pixels and channels: 2 %, the gate
//! for a scene against Mitsuba (1–2 %), for the path gather (the default),
//! which continues paths through the mirrors (docs/rendering.md,
//! "Near-specular surfaces"). Not the 1 % of the lights' scenes: the
//! mirrors' light is 1.7 % short here (docs/results.md, "Smooth and named
//! conductors in a scene", which also gives the link gather's figure).
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test, bench or example may panic

mod common;
use common::{folder, mean_rgb_sum as mean, reference_rgb, render, scene, solve};

#[test]
fn the_metal_box_matches_mitsuba() {
    let dir = folder("conductors");
    let file = scene("conductors/metal-box.xml");
    let r: f64 = reference_rgb("conductors/metal-box.json").iter().sum();
    let sol = dir.join("metal-box.sol");
    solve(&file, &sol);
    // The default path gather (2 %: the bound of the daylight rooms' scene
    // comparisons; this scene is 1.7 % dark, a deficit not yet located,
    // docs/results.md "Smooth and named conductors in a scene").
    let tol = 0.02;
    let out = dir.join("metal-box-paths.exr");
    let image = render(
        &file,
        &[
            "--solution",
            sol.to_str().unwrap(),
            "--spp",
            "16",
            "--gather",
            "paths",
        ],
        &out,
    );
    let rel = mean(&image) / r - 1.0;
    let report = format!(
        "metal-box paths: {:+.2} % (tolerance {} %)",
        100.0 * rel,
        100.0 * tol
    );
    eprintln!("{report}");
    assert!(rel.abs() <= tol, "{report}"); // false for NaN
}
