//! Light that would overflow or never settle, through the binary (against
//! "silent garbage"): radiance beyond the limit is refused where it is
//! written; radiance at the limit renders with finite pixels; a closed
//! scene that reflects everything is refused before the solve; a solve
//! that stops at its shot cap says so; a directly seen emitter is never
//! brighter than its radiance.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test may panic

use std::path::Path;
use std::process::Output;

mod common;
use common::hostile::{assert_refused, furnace, s, write};
use common::{folder, trilux};

fn render(scene: &Path, exr: &Path, extra: &[&str]) -> Output {
    let mut args = vec!["render", s(scene), "-o", s(exr), "--quality", "draft"];
    args.extend(extra);
    trilux(&args)
}

#[test]
fn radiance_beyond_the_limit_is_refused_where_it_is_written() {
    let dir = folder("light-overflow");
    for (le, scale) in [
        ("3.4e38", 1.0),
        ("1e308", 1e12),
        ("inf", 1.0),
        ("1.0001e20", 1.0),
    ] {
        let scene = write(&dir, "over.xml", furnace("0.5", le, scale));
        let exr = dir.join("over.exr");
        for out in [
            trilux(&["info", s(&scene)]),
            trilux(&["solve", s(&scene), "-o", s(&dir.join("over.sol"))]),
            render(&scene, &exr, &[]),
        ] {
            let what = if le == "inf" {
                "not a finite number"
            } else {
                "beyond the limit 1e20"
            };
            assert_refused(&out, &format!("{}:9:", s(&scene)), what);
        }
        assert!(!exr.exists() && !dir.join("over.sol").exists());
    }
}

#[test]
fn radiance_at_the_limit_renders_finite_pixels() {
    let dir = folder("light-limit");
    for mode in ["rgb", "spectral"] {
        let scene = write(&dir, "limit.xml", furnace("0.5", "1e20", 1e6));
        let exr = dir.join(format!("limit-{mode}.exr"));
        let out = render(&scene, &exr, &["--mode", mode]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert!(
            out.stderr.is_empty(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let img = trilux_render::Image::read_exr(&exr).unwrap();
        assert!(img.pixels().iter().flatten().all(|c| c.is_finite()));
        // L = Le / (1 − ρ) = 2e20 (draft: within a few per cent).
        let mean = img.mean();
        assert!(
            mean.iter().all(|m| (m / 2e20 - 1.0).abs() < 0.03),
            "{mode}: {mean:?}"
        );
    }
}

#[test]
fn a_closed_scene_reflecting_everything_is_refused_before_the_solve() {
    let dir = folder("light-trapped");
    let scene = write(&dir, "trapped.xml", furnace("1", "1", 1.0));
    let exr = dir.join("trapped.exr");
    let sol = dir.join("trapped.sol");
    // One line and no progress: refused by the check before the solve.
    for out in [
        trilux(&["solve", s(&scene), "-o", s(&sol), "--quality", "draft"]),
        render(&scene, &exr, &[]),
    ] {
        // At the <emitter> whose light is trapped.
        assert_refused(
            &out,
            &format!("{}:9:5: ", s(&scene)),
            "the scene has no finite solution",
        );
    }
    assert!(!exr.exists() && !sol.exists());
    // Open it (one face black on its inside: it absorbs) and it solves.
    let open = furnace("1", "1", 1.0).replace(
        "</shape>\n</scene>",
        "</shape>\n  <shape type=\"rectangle\"><transform name=\"to_world\"><scale value=\"0.5\"/><translate z=\"-0.999\"/></transform><bsdf type=\"diffuse\"><float name=\"reflectance\" value=\"0\"/></bsdf></shape>\n</scene>",
    );
    let scene = write(&dir, "open.xml", &open);
    let out = trilux(&["solve", s(&scene), "-o", s(&sol), "--quality", "draft"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn a_solve_that_stops_at_its_cap_says_so() {
    let dir = folder("light-cap");
    // Reflectance 0.9999 converges, but far beyond draft's 20 000 shots.
    let scene = write(&dir, "slow.xml", furnace("0.9999", "1", 1.0));
    let sol = dir.join("slow.sol");
    let out = trilux(&["solve", s(&scene), "-o", s(&sol), "--quality", "draft"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    // Progress lines ("solve: CR ...") appear off a terminal on a long solve.
    let said: Vec<&str> = stderr
        .lines()
        .filter(|l| !l.starts_with("solve: "))
        .collect();
    assert_eq!(said.len(), 1, "{stderr}");
    assert!(
        said[0].starts_with(
            "warning: the solve stopped at its cap of 20000 shots with convergence ratio"
        ),
        "{stderr}"
    );
    assert!(stderr.contains("short of its target 0.95"), "{stderr}");
}

#[test]
fn a_directly_seen_emitter_is_never_brighter_than_its_radiance() {
    let dir = folder("light-filter");
    // A black room, a black emitter of radiance 10 filling the middle of
    // the view: every sample is 10 or 0, so with the Gaussian filter's
    // normalised weights (Mitsuba's) no pixel exceeds 10.
    let text = r#"<scene version="3.0.0">
  <sensor type="perspective">
    <float name="fov" value="40"/>
    <transform name="to_world"><lookat origin="0,0,0.9" target="0,0,-1" up="0,1,0"/></transform>
    <sampler type="independent"><integer name="sample_count" value="16"/></sampler>
    <film type="hdrfilm"><integer name="width" value="24"/><integer name="height" value="24"/></film>
  </sensor>
  <shape type="cube"><boolean name="flip_normals" value="true"/>
    <bsdf type="diffuse"><float name="reflectance" value="0"/></bsdf>
  </shape>
  <shape type="rectangle"><transform name="to_world"><scale value="0.4"/><translate z="-0.99"/></transform>
    <bsdf type="diffuse"><float name="reflectance" value="0"/></bsdf>
    <emitter type="area"><float name="radiance" value="10"/></emitter>
  </shape>
</scene>
"#;
    let scene = write(&dir, "emitter.xml", text);
    for mode in ["rgb", "spectral"] {
        let exr = dir.join(format!("emitter-{mode}.exr"));
        let out = render(&scene, &exr, &["--mode", mode]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let img = trilux_render::Image::read_exr(&exr).unwrap();
        let max = img.pixels().iter().flatten().fold(0f32, |m, &c| m.max(c));
        let centre = img.get(12, 12);
        assert!(max <= 10.0, "{mode}: max {max}");
        assert_eq!(
            centre, [10.0; 3],
            "{mode}: the emitter's middle is exactly 10"
        );
    }
}
