//! Mitsuba 3's own Cornell box (scenes/mitsuba-cbox: mitsuba-data's
//! `scenes/cbox` at the commit Mitsuba 3.9.1 pins, unedited) renders
//! through the binary and matches Mitsuba's image: the image mean (all
//! pixels and channels) within 1 %.
//!
//! Both files Mitsuba ships are rendered: `cbox.xml` (spectral, Gaussian
//! filter, `focus_distance`) and `cbox-rgb.xml` (its `fragments/`
//! included, the light a top-level `<emitter>` named by a `<ref>`, box
//! filter). References: `scenes/mitsuba-cbox/NAME.exr`, Mitsuba 3.9.1 with
//! the file's own `$max_depth` set to -1 (trilux's solution has every
//! bounce; at the file's 6 Mitsuba's mean is 1.3 % lower, recorded in
//! NAME.json), 1024 spp in 16 passes, made by
//! `python3 scenes/mitsuba-cbox/make_references.py`.
//!
//! Why 1 % covers the noise: the reference mean's relative standard error
//! is at most 0.05 % per channel (NAME.json, from its 16 passes), and
//! trilux's at 16 spp over 65 536 pixels moved by at most 0.06 % between
//! seeds (docs/results.md); what remains is trilux's own bias (measured
//! -0.8 % and -0.5 %, docs/results.md), which this bounds.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test, bench or example may panic

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

#[test]
fn mitsubas_cornell_box_renders_unedited_and_matches_mitsuba() {
    let dir = folder("mitsuba-cbox");
    let mut report = Vec::new();
    let mut failed = false;
    for name in ["cbox", "cbox-rgb"] {
        let out = dir.join(format!("{name}.exr"));
        let run = trilux(&[
            "render",
            &scene(&format!("mitsuba-cbox/{name}.xml")),
            "--spp",
            "16",
            "-o",
            out.to_str().unwrap(),
        ]);
        let stderr = String::from_utf8_lossy(&run.stderr);
        assert!(run.status.success(), "{name}: {stderr}");
        let warnings: Vec<&str> = stderr
            .lines()
            .filter(|l| l.starts_with("warning:"))
            .collect();
        assert_eq!(warnings.len(), 1, "{name}: {stderr}");
        assert!(warnings[0].contains("max_depth 6"), "{name}: {stderr}");
        let image = Image::read_exr(&out).unwrap();
        let reference = Image::read_exr(std::path::Path::new(&scene(&format!(
            "mitsuba-cbox/{name}.exr"
        ))))
        .unwrap();
        assert_eq!(
            (image.width(), image.height()),
            (reference.width(), reference.height())
        );
        let (m, r) = (mean(&image), mean(&reference));
        let ratio = m.iter().sum::<f64>() / r.iter().sum::<f64>();
        let per_channel: Vec<String> = (0..3)
            .map(|c| format!("{:+.2} %", 100.0 * (m[c] / r[c] - 1.0)))
            .collect();
        report.push(format!(
            "{name}: image mean {:+.2} % against Mitsuba (channels {})",
            100.0 * (ratio - 1.0),
            per_channel.join(", ")
        ));
        let within = (ratio - 1.0).abs() <= 0.01; // false for NaN
        failed |= !within;
    }
    println!("{}", report.join("\n"));
    assert!(!failed, "{}", report.join("\n"));
}
