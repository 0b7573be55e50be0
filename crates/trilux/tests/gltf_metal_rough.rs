//! glTF's metallicRoughnessTexture through the binary against Mitsuba
//! 3.9.1: scenes/metal-rough/metal-rough-box.gltf (a closed box whose
//! floor has a base colour texture times a metalness texture and a
//! roughness texture, and whose back wall has a metalness and roughness
//! texture without a base colour texture; 16 × 16 texels, NEAREST), its
//! reference made through `scripts/gltf_to_mitsuba.py`, which evaluates
//! glTF's formulas per texel on its own (per-texel images of the blend
//! weight, D, S and α), by scenes/metal-rough/make_references.py, 4096
//! spp in 16 passes, whose image means have a relative standard error of
//! at most 0.05 %.
//!
//! Tolerances, per channel on the mean of all pixels: 1 % for the path
//! gather and the control variate, 2 % for the link gather and the
//! preview, as for the lights' scenes (tests/lights.rs gives the
//! reasons: trilux's noise at 16 spp is about 0.2 % of the mean, the
//! links' and preview's bias from piecewise-constant senders 0.5–2 %).
//! The solve takes one GGX α per material (the texture's mean roughness)
//! where the render takes each point's: that reaches the image only
//! through the gather rays' indirect light. Measured (R, G, B): paths
//! −0.20, +0.23, +0.32 %; control +0.41, +0.27, +0.29 %; links −0.21,
//! +0.12, +0.17 %; preview −0.58, −0.13, +0.10 %.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test may panic

mod common;
use common::{folder, gather_args, mean_rgb, reference_rgb, render, scene, solve};

#[test]
fn a_metal_rough_textured_box_matches_mitsuba_in_every_estimator() {
    let dir = folder("metal-rough");
    let file = scene("metal-rough/metal-rough-box.gltf");
    let r = reference_rgb("metal-rough/metal-rough-box.json");
    let sol = dir.join("box.sol");
    solve(&file, &sol);
    let mut report = Vec::new();
    let mut ok = true;
    for (gather, tol) in [
        ("paths", 0.01),
        ("control", 0.01),
        ("links", 0.02),
        ("preview", 0.02),
    ] {
        let out = dir.join(format!("{gather}.exr"));
        let mut args = vec!["--solution", sol.to_str().unwrap()];
        args.extend(["--spp", "16", "--width", "64", "--height", "64"]);
        args.extend(gather_args(gather));
        let m = mean_rgb(&render(&file, &args, &out));
        let rel: Vec<f64> = (0..3).map(|c| m[c] / r[c] - 1.0).collect();
        ok &= rel.iter().all(|e| e.abs() <= tol); // false for NaN
        report.push(format!(
            "{gather}: trilux {m:.5?} Mitsuba {r:.5?}, {:+.2?} % (tolerance {} %)",
            rel.iter().map(|e| 100.0 * e).collect::<Vec<_>>(),
            100.0 * tol
        ));
    }
    eprintln!("{}", report.join("\n"));
    assert!(ok, "{}", report.join("\n"));
}
