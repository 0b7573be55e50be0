//! Lights without area through the binary against Mitsuba 3.9.1
//! (scenes/lights: a closed diffuse box under a point light, the same box
//! under a spot, a room lit by the sun through an opening in its ceiling,
//! the point-lit box with a glossy floor, and the glTF Cornell box with its
//! ceiling light replaced by a `KHR_lights_punctual` point light (its
//! reference made through `scripts/gltf_to_mitsuba.py`);
//! references by `scenes/lights/make_references.py`, 4096 spp in 16
//! passes, whose image means have a relative standard error of at most
//! 0.03 %).
//!
//! Tolerances, on the mean of all pixels and channels: 1 % for the path
//! gather and the control variate (the gate for lights; trilux's
//! own noise at 16 spp is about 0.2 % of the mean, and the solution's
//! bias reaches the image only through the gather rays, measured at
//! 0.1–0.4 %); 2 % for the link gather and the preview, whose bias from
//! the gather links' piecewise-constant senders is 0.5–2 % on any scene
//! (docs/rendering.md). The preview is not checked on the glossy floor: it
//! reads a glossy part's indirect light in the mirror direction only, and
//! is -7.3 % there (-5.4 % with a small sphere light of the same
//! intensity instead of the point: docs/results.md, "Lights without
//! area").
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test, bench or example may panic

mod common;
use common::{
    folder, gather_args, mean_rgb_sum as mean, reference_rgb, render, scene, solve, trilux,
};

fn reference(name: &str) -> f64 {
    reference_rgb(&format!("lights/{name}.json")).iter().sum()
}

/// Every estimator's image mean against Mitsuba's, one solve per scene.
#[test]
fn lights_without_area_match_mitsuba_in_every_estimator() {
    let dir = folder("lights");
    let mut report = Vec::new();
    let mut ok = true;
    let names = [
        "point-box",
        "spot-box",
        "sun-room",
        "point-glossy",
        "cornell-point",
    ];
    for name in names {
        // The glTF Cornell box's film is 768 wide; its reference is at 64.
        let gltf = name == "cornell-point";
        let file = scene(&format!(
            "lights/{name}.{}",
            if gltf { "gltf" } else { "xml" }
        ));
        let sol = dir.join(format!("{name}.sol"));
        solve(&file, &sol);
        let r = reference(name);
        for (gather, tol) in [
            ("paths", 0.01),
            ("control", 0.01),
            ("links", 0.02),
            ("preview", 0.02),
        ] {
            if name == "point-glossy" && gather == "preview" {
                continue;
            }
            let out = dir.join(format!("{name}-{gather}.exr"));
            let mut args = vec!["--solution", sol.to_str().unwrap(), "--spp", "16"];
            if gltf {
                args.extend(["--width", "64", "--height", "64"]);
            }
            args.extend(gather_args(gather));
            let m = mean(&render(&file, &args, &out));
            let rel = m / r - 1.0;
            ok &= rel.abs() <= tol; // false for NaN
            report.push(format!(
                "{name} {gather}: {:+.2} % (tolerance {} %)",
                100.0 * rel,
                100.0 * tol
            ));
        }
    }
    eprintln!("{}", report.join("\n"));
    assert!(ok, "{}", report.join("\n"));
}

/// A bad light in a scene file: one line naming file, line and problem,
/// exit 1.
#[test]
fn a_bad_light_is_one_located_line_and_exit_1() {
    let dir = folder("bad-light");
    let path = dir.join("bad.xml");
    std::fs::write(
        &path,
        "<scene version=\"3.0.0\">\n  <emitter type=\"spot\">\n    <float name=\"cutoff_angle\" value=\"200\"/>\n  </emitter>\n</scene>\n",
    )
    .unwrap();
    let p = path.to_str().unwrap();
    let out = trilux(&["solve", p]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    let lines: Vec<&str> = stderr.lines().collect();
    assert_eq!(lines.len(), 1, "{stderr}");
    assert!(lines[0].starts_with(&format!("error: {p}:3:")), "{stderr}");
    assert!(
        lines[0].contains("cutoff_angle must be in (0, 180) degrees"),
        "{stderr}"
    );
}
