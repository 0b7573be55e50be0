//! `cargo xtask color`: trilux's spectrum → XYZ → sRGB against colour-science.
//!
//! For a set of spectra (the classic Cornell box's measured reflectances and
//! light, a blackbody, narrow bands, the equal-energy spectrum), trilux's
//! CIE 1931 XYZ at 1 nm (`SampledSpectrum::to_xyz`) is compared with
//! colour-science's
//! `sd_to_XYZ` (via `xtask/color_check.py`); the equal-energy spectrum is
//! normalised to Y = 1. The check fails above 1e-3 absolute in any of X, Y, Z.
//! The reduction to `SPECTRAL_BANDS` bands that spectral solves use is reported
//! beside it (its error is the band discretisation's, not a bug, and is not
//! gated), as is sRGB (trilux uses Mitsuba's 6-decimal XYZ→sRGB matrix,
//! colour-science IEC 61966-2-1's).

use std::process::Command;

use anyhow::{Context, Result, bail};
use trilux_color::{ColorParam, SPECTRAL_BANDS, SampledSpectrum, Spectrum, srgb};

const TOLERANCE: f64 = 1e-3;

const CORNELL_WHITE: &str = "400:0.343, 404:0.445, 408:0.551, 412:0.624, 416:0.665, 420:0.687, 424:0.708, 428:0.723, 432:0.715, 436:0.71, 440:0.745, 444:0.758, 448:0.739, 452:0.767, 456:0.777, 460:0.765, 464:0.751, 468:0.745, 472:0.748, 476:0.729, 480:0.745, 484:0.757, 488:0.753, 492:0.75, 496:0.746, 500:0.747, 504:0.735, 508:0.732, 512:0.739, 516:0.734, 520:0.725, 524:0.721, 528:0.733, 532:0.725, 536:0.732, 540:0.743, 544:0.744, 548:0.748, 552:0.728, 556:0.716, 560:0.733, 564:0.726, 568:0.713, 572:0.74, 576:0.754, 580:0.764, 584:0.752, 588:0.736, 592:0.734, 596:0.741, 600:0.74, 604:0.732, 608:0.745, 612:0.755, 616:0.751, 620:0.744, 624:0.731, 628:0.733, 632:0.744, 636:0.731, 640:0.712, 644:0.708, 648:0.729, 652:0.73, 656:0.727, 660:0.707, 664:0.703, 668:0.729, 672:0.75, 676:0.76, 680:0.751, 684:0.739, 688:0.724, 692:0.73, 696:0.74, 700:0.737";
const CORNELL_RED: &str = "400:0.04, 404:0.046, 408:0.048, 412:0.053, 416:0.049, 420:0.05, 424:0.053, 428:0.055, 432:0.057, 436:0.056, 440:0.059, 444:0.057, 448:0.061, 452:0.061, 456:0.06, 460:0.062, 464:0.062, 468:0.062, 472:0.061, 476:0.062, 480:0.06, 484:0.059, 488:0.057, 492:0.058, 496:0.058, 500:0.058, 504:0.056, 508:0.055, 512:0.056, 516:0.059, 520:0.057, 524:0.055, 528:0.059, 532:0.059, 536:0.058, 540:0.059, 544:0.061, 548:0.061, 552:0.063, 556:0.063, 560:0.067, 564:0.068, 568:0.072, 572:0.08, 576:0.09, 580:0.099, 584:0.124, 588:0.154, 592:0.192, 596:0.255, 600:0.287, 604:0.349, 608:0.402, 612:0.443, 616:0.487, 620:0.513, 624:0.558, 628:0.584, 632:0.62, 636:0.606, 640:0.609, 644:0.651, 648:0.612, 652:0.61, 656:0.65, 660:0.638, 664:0.627, 668:0.62, 672:0.63, 676:0.628, 680:0.642, 684:0.639, 688:0.657, 692:0.639, 696:0.635, 700:0.642";
const CORNELL_GREEN: &str = "400:0.092, 404:0.096, 408:0.098, 412:0.097, 416:0.098, 420:0.095, 424:0.095, 428:0.097, 432:0.095, 436:0.094, 440:0.097, 444:0.098, 448:0.096, 452:0.101, 456:0.103, 460:0.104, 464:0.107, 468:0.109, 472:0.112, 476:0.115, 480:0.125, 484:0.14, 488:0.16, 492:0.187, 496:0.229, 500:0.285, 504:0.343, 508:0.39, 512:0.435, 516:0.464, 520:0.472, 524:0.476, 528:0.481, 532:0.462, 536:0.447, 540:0.441, 544:0.426, 548:0.406, 552:0.373, 556:0.347, 560:0.337, 564:0.314, 568:0.285, 572:0.277, 576:0.266, 580:0.25, 584:0.23, 588:0.207, 592:0.186, 596:0.171, 600:0.16, 604:0.148, 608:0.141, 612:0.136, 616:0.13, 620:0.126, 624:0.123, 628:0.121, 632:0.122, 636:0.119, 640:0.114, 644:0.115, 648:0.117, 652:0.117, 656:0.118, 660:0.12, 664:0.122, 668:0.128, 672:0.132, 676:0.139, 680:0.144, 684:0.146, 688:0.15, 692:0.152, 696:0.157, 700:0.159";
const CORNELL_LIGHT: &str = "400:0, 500:8, 600:15.6, 700:18.4";

fn parse(s: &str) -> Result<Vec<(f64, f64)>> {
    s.split(',')
        .map(|p| {
            let (l, v) = p.trim().split_once(':').context("wavelength:value")?;
            Ok((l.trim().parse()?, v.trim().parse()?))
        })
        .collect()
}

/// Planck's law (relative), sampled every 5 nm over 360–830, normalised to 1
/// at 560 nm.
fn blackbody(t: f64) -> Vec<(f64, f64)> {
    const C2: f64 = 1.438_776_877e-2; // m·K
    let b = |nm: f64| {
        let l = nm * 1e-9;
        1.0 / (l.powi(5) * ((C2 / (l * t)).exp() - 1.0))
    };
    let norm = b(560.0);
    (0..=94)
        .map(|i| {
            let nm = 360.0 + 5.0 * i as f64;
            (nm, b(nm) / norm)
        })
        .collect()
}

/// A named sampled spectrum.
type Named = (String, Vec<(f64, f64)>);

fn spectra() -> Result<Vec<Named>> {
    Ok(vec![
        ("equal-energy".into(), vec![(360.0, 1.0), (830.0, 1.0)]),
        ("cornell-white".into(), parse(CORNELL_WHITE)?),
        ("cornell-red".into(), parse(CORNELL_RED)?),
        ("cornell-green".into(), parse(CORNELL_GREEN)?),
        ("cornell-light".into(), parse(CORNELL_LIGHT)?),
        ("blackbody-2856K".into(), blackbody(2856.0)),
        ("blackbody-6504K".into(), blackbody(6504.0)),
        (
            "narrow-450nm".into(),
            vec![(444.0, 0.0), (445.0, 1.0), (455.0, 1.0), (456.0, 0.0)],
        ),
        (
            "narrow-550nm".into(),
            vec![(544.0, 0.0), (545.0, 1.0), (555.0, 1.0), (556.0, 0.0)],
        ),
        (
            "narrow-650nm".into(),
            vec![(644.0, 0.0), (645.0, 1.0), (655.0, 1.0), (656.0, 0.0)],
        ),
        (
            "line-590nm".into(),
            vec![(585.0, 0.0), (590.0, 1.0), (595.0, 0.0)],
        ),
    ])
}

fn ensure_colour_science() -> Result<()> {
    let ok = |args: &[&str]| {
        Command::new("python3")
            .args(args)
            .output()
            .map(|o| o.status.success())
            .unwrap_or(false)
    };
    if ok(&["-c", "import colour"]) {
        return Ok(());
    }
    eprintln!("xtask: colour-science missing; python3 -m pip install --quiet colour-science");
    if ok(&["-m", "pip", "install", "--quiet", "colour-science"]) && ok(&["-c", "import colour"]) {
        return Ok(());
    }
    bail!(
        "colour-science is not installed and could not be installed; install it with \
         `python3 -m pip install colour-science` (needs python3 and pip)"
    )
}

/// Runs the comparison; `Err` when it cannot run or a spectrum is off by more
/// than the tolerance.
pub fn color() -> Result<()> {
    ensure_colour_science()?;
    let spectra = spectra()?;
    let json: Vec<serde_json::Value> = spectra
        .iter()
        .map(|(n, s)| serde_json::json!({"name": n, "samples": s}))
        .collect();
    let dir = std::env::temp_dir().join(format!("trilux-xtask-color-{}", std::process::id()));
    std::fs::create_dir_all(&dir)?;
    let input = dir.join("spectra.json");
    std::fs::write(&input, serde_json::to_string(&json)?)?;
    let script = concat!(env!("CARGO_MANIFEST_DIR"), "/color_check.py");
    let out = Command::new("python3")
        .arg(script)
        .arg(&input)
        .output()
        .context("could not run python3")?;
    let _ = std::fs::remove_dir_all(&dir);
    if !out.status.success() {
        bail!(
            "color_check.py failed: {}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    let reference: serde_json::Value = serde_json::from_slice(&out.stdout)?;
    let version = reference["colour_version"].as_str().unwrap_or("?");
    let results = reference["results"].as_array().context("results array")?;
    println!(
        "cargo xtask color: trilux vs colour-science {version} (XYZ with equal-energy Y = 1; gate {TOLERANCE:e} absolute)"
    );
    println!(
        "{:<16} {:>30} {:>10} {:>10} {:>12} {:>8}",
        "spectrum", "trilux XYZ (1 nm)", "|ΔXYZ|", "|Δbands|", "|ΔsRGBlin|", "Δ8bit"
    );
    let mut worst: f64 = 0.0;
    let mut failures = Vec::new();
    for ((name, samples), r) in spectra.iter().zip(results) {
        let s = SampledSpectrum::new(samples)?;
        let xyz = s.to_xyz();
        let band: Spectrum<SPECTRAL_BANDS> = ColorParam::Sampled(samples.clone()).emission()?;
        let xyz_bands = band.to_xyz();
        let want: Vec<f64> = r["xyz"]
            .as_array()
            .context("xyz")?
            .iter()
            .filter_map(|v| v.as_f64())
            .collect();
        let want_lin: Vec<f64> = r["srgb_linear"]
            .as_array()
            .context("srgb")?
            .iter()
            .filter_map(|v| v.as_f64())
            .collect();
        let want_enc: Vec<f64> = r["srgb_encoded"]
            .as_array()
            .context("srgb")?
            .iter()
            .filter_map(|v| v.as_f64())
            .collect();
        if want.len() != 3 || want_lin.len() != 3 || want_enc.len() != 3 {
            bail!("malformed reference for {name}");
        }
        let d = (0..3).map(|k| (xyz[k] - want[k]).abs()).fold(0.0, f64::max);
        let d_bands = (0..3)
            .map(|k| (xyz_bands[k] - want[k]).abs())
            .fold(0.0, f64::max);
        let lin = srgb::xyz_to_linear_srgb(xyz);
        let dlin = (0..3)
            .map(|k| (lin[k] - want_lin[k]).abs())
            .fold(0.0, f64::max);
        let bytes = srgb::linear_srgb_to_u8(lin);
        let want_bytes = want_enc
            .iter()
            .map(|&e| (e.clamp(0.0, 1.0) * 255.0).round() as i32);
        let d8 = bytes
            .iter()
            .zip(want_bytes)
            .map(|(&a, b)| (a as i32 - b).abs())
            .max()
            .unwrap_or(0);
        worst = worst.max(d);
        println!(
            "{name:<16} ({:>8.5}, {:>8.5}, {:>8.5}) {d:>10.2e} {d_bands:>10.2e} {dlin:>12.2e} {d8:>8}",
            xyz[0], xyz[1], xyz[2]
        );
        if d.is_nan() || d > TOLERANCE {
            failures.push(format!("{name}: |ΔXYZ| = {d:e}"));
        }
    }
    println!("worst |ΔXYZ| = {worst:.2e} (gate {TOLERANCE:e})");
    if !failures.is_empty() {
        bail!("colour check failed:\n{}", failures.join("\n"));
    }
    Ok(())
}
