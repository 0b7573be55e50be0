//! Mitsuba 3's own Cornell box (scenes/mitsuba-cbox: mitsuba-data's
//! `scenes/cbox` at the commit Mitsuba 3.9.1 pins, unedited) renders
//! through the binary and matches Mitsuba's image: the image mean (all
//! pixels and channels) within 1 %.
//!
//! Both files Mitsuba ships are rendered: `cbox.xml` (spectral, Gaussian
//! filter, `focus_distance`) and `cbox-rgb.xml` (its `fragments/`
//! included, the light a top-level `<emitter>` named by a `<ref>`, box
//! filter), each twice: as written (the path integrator's `max_depth` 6,
//! which trilux honours with the control-variate estimator) against
//! Mitsuba's mean at that depth (NAME.json, `mean_rgb_file_max_depth`), and
//! with `-D max_depth=-1` (the default path gather reading the solution)
//! against `scenes/mitsuba-cbox/NAME.exr`, Mitsuba at -1. References made
//! by `scenes/mitsuba-cbox/make_references.py` (1024 spp in 16 passes at
//! -1, 256 at 6) and, for the integrator's other parameters,
//! `make_integrator_references.py` (integrator.json, 512 spp each).
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test, bench or example may panic

use std::path::{Path, PathBuf};

use serde_json::Value;
use trilux_render::Image;

mod common;
use common::{folder, scene, trilux};

fn mean(image: &Image) -> [f64; 3] {
    let mut sum = [0.0; 3];
    for p in image.pixels() {
        for c in 0..3 {
            sum[c] += f64::from(p[c]);
        }
    }
    let n = image.pixels().len() as f64;
    sum.map(|s| s / n)
}

/// A JSON file of scenes/mitsuba-cbox.
fn json(name: &str) -> Value {
    let text = std::fs::read_to_string(scene(&format!("mitsuba-cbox/{name}"))).unwrap();
    serde_json::from_str(&text).unwrap()
}

fn rgb(v: &Value) -> [f64; 3] {
    [0, 1, 2].map(|c| v[c].as_f64().unwrap())
}

/// Renders `file` at 16 spp with `extra` arguments into `out` and returns
/// the image mean and stderr's warning lines.
fn render_mean(file: &str, extra: &[&str], out: &Path) -> ([f64; 3], Vec<String>) {
    let mut args = vec!["render", file, "--spp", "16", "-o", out.to_str().unwrap()];
    args.extend_from_slice(extra);
    let run = trilux(&args);
    let stderr = String::from_utf8_lossy(&run.stderr).into_owned();
    assert!(run.status.success(), "{file} {extra:?}: {stderr}");
    let warnings = stderr
        .lines()
        .filter(|l| l.starts_with("warning:"))
        .map(String::from)
        .collect();
    (mean(&Image::read_exr(out).unwrap()), warnings)
}

/// "CASE: image mean +0.12 % against Mitsuba (channels …)", and whether
/// the mean of all channels is within 1 %.
fn compare(case: &str, m: [f64; 3], r: [f64; 3]) -> (String, bool) {
    let ratio = m.iter().sum::<f64>() / r.iter().sum::<f64>();
    let per_channel: Vec<String> = (0..3)
        .map(|c| format!("{:+.2} %", 100.0 * (m[c] / r[c] - 1.0)))
        .collect();
    let line = format!(
        "{case}: image mean {:+.2} % against Mitsuba (channels {})",
        100.0 * (ratio - 1.0),
        per_channel.join(", ")
    );
    (line, (ratio - 1.0).abs() <= 0.01) // false for NaN
}

#[test]
fn mitsubas_cornell_box_renders_unedited_and_matches_mitsuba() {
    let dir = folder("mitsuba-cbox");
    let mut report = Vec::new();
    let mut failed = false;
    for name in ["cbox", "cbox-rgb"] {
        let file = scene(&format!("mitsuba-cbox/{name}.xml"));
        let out = dir.join(format!("{name}.exr"));
        // As written: max_depth 6, honoured, so nothing to warn about.
        let (m, warnings) = render_mean(&file, &[], &out);
        assert!(warnings.is_empty(), "{name}: {warnings:?}");
        let r = rgb(&json(&format!("{name}.json"))["mean_rgb_file_max_depth"]);
        let (line, ok) = compare(&format!("{name}, max_depth 6"), m, r);
        report.push(line);
        failed |= !ok;
        // Unlimited: the solution read by the path gather.
        let (m, warnings) = render_mean(&file, &["-D", "max_depth=-1"], &out);
        assert!(warnings.is_empty(), "{name}: {warnings:?}");
        let reference =
            Image::read_exr(Path::new(&scene(&format!("mitsuba-cbox/{name}.exr")))).unwrap();
        let image = Image::read_exr(&out).unwrap();
        assert_eq!(
            (image.width(), image.height()),
            (reference.width(), reference.height())
        );
        let (line, ok) = compare(&format!("{name}, max_depth -1"), m, mean(&reference));
        report.push(line);
        failed |= !ok;
    }
    println!("{}", report.join("\n"));
    assert!(!failed, "{}", report.join("\n"));
}

/// Copies scenes/mitsuba-cbox's `file`, its `fragments/` and `meshes/`
/// into `to`, with `edit` applied to the text of `edited` (a path in the
/// folder); returns the copy of `file`.
fn edited_copy(to: &Path, file: &str, edited: &str, edit: impl Fn(&str) -> String) -> PathBuf {
    let from = PathBuf::from(scene("mitsuba-cbox"));
    for sub in ["fragments", "meshes"] {
        std::fs::create_dir_all(to.join(sub)).unwrap();
        for entry in std::fs::read_dir(from.join(sub)).unwrap() {
            let path = entry.unwrap().path();
            std::fs::copy(&path, to.join(sub).join(path.file_name().unwrap())).unwrap();
        }
    }
    std::fs::copy(from.join(file), to.join(file)).unwrap();
    let text = std::fs::read_to_string(to.join(edited)).unwrap();
    let changed = edit(&text);
    assert_ne!(changed, text, "{edited} unchanged");
    std::fs::write(to.join(edited), changed).unwrap();
    to.join(file)
}

/// cbox-rgb.xml with `hide_emitters` set in its path integrator.
fn with_hidden_emitters(to: &Path) -> PathBuf {
    let depth = r#"<integer name="max_depth" value="$max_depth"/>"#;
    let hidden = format!(r#"{depth}<boolean name="hide_emitters" value="true"/>"#);
    edited_copy(to, "cbox-rgb.xml", "fragments/base.xml", |t| {
        t.replace(depth, &hidden)
    })
}

/// The path integrator's `max_depth` 1, 2 and 3 (emitters alone, direct
/// light, one bounce) and `hide_emitters` give Mitsuba's image means
/// (integrator.json): each case differs from the next by 10 % or more, so
/// the 1 % bound tells them apart.
#[test]
fn the_integrators_max_depth_and_hide_emitters_mean_what_they_mean_in_mitsuba() {
    let dir = folder("mitsuba-cbox-integrator");
    let cases = json("integrator.json")["cases"].clone();
    let file = scene("mitsuba-cbox/cbox-rgb.xml");
    let out = dir.join("image.exr");
    let mut report = Vec::new();
    let mut failed = false;
    for depth in 1..=3 {
        let define = format!("max_depth={depth}");
        let (m, warnings) = render_mean(&file, &["-D", &define], &out);
        assert!(warnings.is_empty(), "{define}: {warnings:?}");
        let r = rgb(&cases[format!("max_depth_{depth}")]["mean_rgb"]);
        let (line, ok) = compare(&format!("max_depth {depth}"), m, r);
        report.push(line);
        failed |= !ok;
    }
    let hidden = with_hidden_emitters(&dir.join("hidden"));
    let (m, warnings) = render_mean(hidden.to_str().unwrap(), &[], &out);
    assert!(warnings.is_empty(), "hide_emitters: {warnings:?}");
    let r = rgb(&cases["hide_emitters_max_depth_6"]["mean_rgb"]);
    let (line, ok) = compare("hide_emitters, max_depth 6", m, r);
    report.push(line);
    failed |= !ok;
    println!("{}", report.join("\n"));
    assert!(!failed, "{}", report.join("\n"));
}

/// An estimator that reads the solution cannot honour a finite
/// `max_depth`: chosen explicitly, it renders every bounce and says so in
/// one warning naming the place the file sets the limit.
#[test]
fn an_estimator_that_cannot_honour_max_depth_says_so() {
    let dir = folder("mitsuba-cbox-depth-warning");
    let file = scene("mitsuba-cbox/cbox-rgb.xml");
    let out = dir.join("image.exr");
    let run = trilux(&[
        "render",
        &file,
        "--spp",
        "1",
        "--gather",
        "paths",
        "-o",
        out.to_str().unwrap(),
    ]);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(run.status.success(), "{stderr}");
    let warnings: Vec<&str> = stderr
        .lines()
        .filter(|l| l.starts_with("warning:"))
        .collect();
    assert_eq!(warnings.len(), 1, "{stderr}");
    assert!(warnings[0].contains("base.xml:8:"), "{stderr}");
    assert!(warnings[0].contains("max_depth 6"), "{stderr}");
    assert!(warnings[0].contains("--gather control"), "{stderr}");
}

/// cbox.xml with `<spectrum name="srf" value="SRF"/>` first in its sensor.
fn with_response(to: &Path, srf: &str) -> PathBuf {
    edited_copy(to, "cbox.xml", "cbox.xml", |text| {
        let sensor = text.find("<sensor").unwrap();
        let at = sensor + text[sensor..].find('>').unwrap() + 1;
        format!(
            "{}\n<spectrum name=\"srf\" value=\"{srf}\"/>{}",
            &text[..at],
            &text[at..]
        )
    })
}

/// A sensor's spectral response (`srf`) multiplies the light before the
/// CIE observer sees it, as in Mitsuba 3.9.1's spectral variants: a box
/// over 600–700 nm (the image nearly all red, green and blue slightly
/// negative) and a ramp from 0.5 at 400 nm to 1.5 at 700 nm, against
/// srf.json (`make_srf_references.py`, 256 spp). Bound 2 % on the mean of
/// the channels: trilux's bands average the response, the light and the
/// reflectances separately, and all three change within the band holding
/// 700 nm, where the box ends (and the file's light and reflectances
/// with it). Ignoring the response would be 120 % too bright on the box
/// and 10 % too dark on the ramp (Mitsuba's mean without it, cbox.json).
#[test]
fn a_sensor_response_weighs_the_light_as_in_mitsuba() {
    let dir = folder("mitsuba-cbox-srf");
    let cases = json("srf.json")["cases"].clone();
    let mut report = Vec::new();
    let mut failed = false;
    for name in ["red_box", "ramp"] {
        let srf = cases[name]["srf"].as_str().unwrap();
        let file = with_response(&dir.join(name), srf);
        let out = dir.join(format!("{name}.exr"));
        let (m, warnings) = render_mean(file.to_str().unwrap(), &[], &out);
        assert!(warnings.is_empty(), "{name}: {warnings:?}");
        let r = rgb(&cases[name]["mean_rgb"]);
        let (line, _) = compare(&format!("srf {srf}"), m, r);
        let ratio = m.iter().sum::<f64>() / r.iter().sum::<f64>();
        let within = (ratio - 1.0).abs() <= 0.02; // false for NaN
        failed |= !within;
        report.push(line);
    }
    println!("{}", report.join("\n"));
    assert!(!failed, "{}", report.join("\n"));
}
