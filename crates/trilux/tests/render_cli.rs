//! `trilux solve` and `trilux render` through the binary: a render from a
//! saved solution does no solving, a solution made for another scene is
//! refused, bad outputs and bad options fail cleanly.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test, bench or example may panic

use std::path::Path;
use std::process::Output;

mod common;
use common::{folder, scene, trilux};

fn s(p: &Path) -> &str {
    p.to_str().expect("utf-8 path")
}

const SMALL: [&str; 8] = [
    "--width",
    "24",
    "--height",
    "24",
    "--spp",
    "2",
    "--quality",
    "draft",
];

fn assert_one_error_line(out: &Output, what: &str) {
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(
        out.status.code(),
        Some(1),
        "{what}: status; stderr {stderr}"
    );
    assert_eq!(stderr.lines().count(), 1, "{what}: one line: {stderr}");
    assert!(stderr.starts_with("error: "), "{what}: {stderr}");
}

/// Saves a draft solve of the furnace to `sol`.
fn solve_furnace(sol: &Path) {
    let out = trilux(&[
        "solve",
        &scene("furnace.xml"),
        "-o",
        s(sol),
        "--quality",
        "draft",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn render_from_a_saved_solution_does_not_solve() {
    let dir = folder("saved");
    let sol = dir.join("furnace.sol");
    solve_furnace(&sol);
    let exr = dir.join("a.exr");
    let stats = dir.join("a.json");
    let furnace = scene("furnace.xml");
    let mut args = vec!["render", &furnace[..]];
    let (sol_s, exr_s, stats_s) = (s(&sol).to_owned(), s(&exr).to_owned(), s(&stats).to_owned());
    args.extend(["--solution", &sol_s, "-o", &exr_s, "--stats", &stats_s]);
    args.extend(SMALL);
    let out = trilux(&args);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&stats).expect("stats written"))
            .expect("stats are JSON");
    assert_eq!(json["solve_seconds"], serde_json::json!(0.0));
    assert!(json["render_seconds"].as_f64().is_some_and(|t| t > 0.0));
    assert!(exr.exists());
    // Another view of the same solution, with a hyphenated --lookat.
    let exr2 = dir.join("b.exr");
    let exr2_s = s(&exr2).to_owned();
    let mut args = vec!["render", &furnace[..], "--solution", &sol_s, "-o", &exr2_s];
    args.extend(["--lookat", "-0.5,0.2,0.3,0,0,-1", "--fov", "60"]);
    args.extend(SMALL);
    let out = trilux(&args);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(exr2.exists());
}

#[test]
fn a_solution_for_another_scene_is_refused() {
    let dir = folder("other");
    let sol = dir.join("furnace.sol");
    solve_furnace(&sol);
    let exr = dir.join("x.exr");
    let cornell = scene("cornell-box.xml");
    let mut args = vec!["render", &cornell[..], "--solution", s(&sol), "-o", s(&exr)];
    args.extend(SMALL);
    let out = trilux(&args);
    assert_one_error_line(&out, "foreign solution");
    assert!(!exr.exists(), "no output left behind");
}

#[test]
fn unwritable_output_and_missing_scene_fail_cleanly() {
    let dir = folder("bad");
    let exr = dir.join("no-such-folder").join("x.exr");
    let furnace = scene("furnace.xml");
    let mut args = vec!["render", &furnace[..], "-o", s(&exr)];
    args.extend(SMALL);
    let out = trilux(&args);
    assert_one_error_line(&out, "unwritable output");
    assert!(!exr.exists());
    let out = trilux(&["render", s(&dir.join("missing.xml"))]);
    assert_one_error_line(&out, "missing scene");
    let out = trilux(&[
        "solve",
        s(&dir.join("missing.xml")),
        "-o",
        s(&dir.join("m.sol")),
    ]);
    assert_one_error_line(&out, "missing scene (solve)");
    // Adaptive sampling's pilot takes 4 samples a pixel: fewer is refused
    // before any work, with what to change.
    let out = trilux(&[
        "render",
        &furnace[..],
        "-o",
        s(&dir.join("a.exr")),
        "--spp",
        "2",
        "--target-error",
        "0.1",
    ]);
    assert_one_error_line(&out, "adaptive with 2 spp");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("--spp") && stderr.contains("at least 4"),
        "{stderr}"
    );
}

#[test]
fn unknown_option_is_a_usage_error() {
    let out = trilux(&["render", &scene("furnace.xml"), "--no-such-option"]);
    assert_eq!(out.status.code(), Some(2));
    // Malformed values are usage errors too, found before the scene is read
    // (the scene named here does not even exist).
    for bad in [
        &["--lookat", "1,2"][..],
        &["--lookat", "1,2,3,4,5,x"][..],
        &["--fov", "200"][..],
        &["--width", "0"][..],
        &["--spp", "0"][..],
        &["--threads", "0"][..],
        &["--convergence", "2"][..],
        &["--target-error", "0"][..],
        &["--target-error", "1.5"][..],
        &["--exposure", "nan"][..],
        &["--exposure", "100"][..],
        &["--gather", "rays"][..],
    ] {
        let mut args = vec!["render", "/no/such/scene.xml"];
        args.extend(bad);
        let out = trilux(&args);
        assert_eq!(out.status.code(), Some(2), "{bad:?}");
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!stderr.contains("/no/such/scene.xml:"), "{bad:?}: {stderr}");
    }
}

/// `--exposure` scales the PNG by 2^stops before the sRGB curve: the
/// furnace's radiance 2.0 at −2 stops is 0.5, sRGB-encoded
/// 1.055 · 0.5^(1/2.4) − 0.055 = 0.7354, code 188 (the preview is within
/// 2 % of 2.0 on every pixel, ±2.4 codes at that slope; at 0 stops every
/// pixel clips to 255, which is what −2 stops avoids).
#[test]
fn exposure_scales_the_png() {
    let dir = folder("exposure");
    let furnace = scene("furnace.xml");
    let codes = |stops: &str| {
        let png = dir.join(format!("f{stops}.png"));
        let mut args = vec!["render", furnace.as_str()];
        let exr = dir.join("f.exr");
        args.extend(["-o", s(&exr), "--png", s(&png), "--preview"]);
        args.extend(&SMALL[..4]);
        args.extend(["--quality", "draft", "--exposure", stops]);
        let out = trilux(&args);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let decoder =
            png::Decoder::new(std::io::BufReader::new(std::fs::File::open(&png).unwrap()));
        let mut reader = decoder.read_info().unwrap();
        let mut buf = vec![0; reader.output_buffer_size().unwrap()];
        let info = reader.next_frame(&mut buf).unwrap();
        buf.truncate(info.buffer_size());
        buf
    };
    let expected = (1.055 * 0.5f64.powf(1.0 / 2.4) - 0.055) * 255.0;
    let dark = codes("-2");
    assert!(
        dark.iter().all(|&c| (f64::from(c) - expected).abs() <= 3.0),
        "{dark:?}"
    );
    assert!(codes("0").iter().all(|&c| c == 255));
}
