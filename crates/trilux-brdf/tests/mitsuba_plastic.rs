//! `plastic` and `roughplastic` against Mitsuba 3's `eval`, `pdf` and
//! `sample`, and their albedo against their own sampling.
//!
//! The reference values were made once by
//! `crates/trilux-brdf/tools/gen_mitsuba_plastic.py` (Mitsuba 3.9.1,
//! scalar_rgb) and are stored in `tests/data/mitsuba_plastic.json`.
//! Tolerance 1e-4 relative or 1e-6 absolute, except one stated case: for a
//! Beckmann coat Mitsuba's `pdf` uses its rational Smith G1 while trilux's
//! uses the exact G1 its sampler draws (crate::microfacet), ≤ 0.35 % apart
//! in the coat's share of the density.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test may panic

use glam::{DVec2, DVec3};
use serde::Deserialize;
use trilux_brdf::{Bsdf, BsdfParams, Distribution, PlasticParams};
use trilux_color::ColorParam;

#[derive(Deserialize)]
struct Eval {
    wi: [f64; 3],
    wo: [f64; 3],
    fr: [f64; 3],
    pdf: f64,
}

#[derive(Deserialize)]
struct Sample {
    wo: [f64; 3],
    wi: [f64; 3],
    pdf: f64,
    weight: [f64; 3],
    delta: bool,
}

#[derive(Deserialize)]
struct Case {
    name: String,
    params: BsdfParams,
    evals: Vec<Eval>,
    samples: Vec<Sample>,
}

#[derive(Deserialize)]
struct File {
    cases: Vec<Case>,
}

fn cases() -> Vec<Case> {
    let text = include_str!("data/mitsuba_plastic.json");
    let file: File = serde_json::from_str(text).expect("valid reference file");
    assert!(file.cases.len() >= 10);
    file.cases
}

fn plastic(p: &BsdfParams) -> &PlasticParams {
    match p {
        BsdfParams::Plastic(pp) => pp,
        BsdfParams::TwoSided { front, .. } => plastic(front),
        _ => panic!("not a plastic"),
    }
}

fn close(got: f64, want: f64, rel: f64) -> bool {
    let err = (got - want).abs();
    err <= 1e-6 || err <= rel * want.abs()
}

fn mean(c: &ColorParam) -> f64 {
    match c {
        ColorParam::Float(v) => *v,
        ColorParam::Rgb(v) => v.iter().sum::<f64>() / 3.0,
        _ => panic!("float or rgb only"),
    }
}

/// The tolerance of a pdf (module docs).
fn pdf_tolerance(pp: &PlasticParams) -> f64 {
    match pp.coat {
        Some((Distribution::Beckmann, _)) => 4e-3,
        _ => 1e-4,
    }
}

/// Mitsuba's probability of sampling a smooth coat for viewer cosθ = `f`'s
/// angle, from F (trilux's delta weight over specular_reflectance).
fn prob_specular(pp: &PlasticParams, f: f64) -> f64 {
    let (d, s) = (
        mean(&pp.diffuse_reflectance),
        mean(&pp.specular_reflectance),
    );
    let w = s / (d + s);
    f * w / (f * w + (1.0 - f) * (1.0 - w))
}

#[test]
fn eval_and_pdf_match_mitsuba3() {
    let mut failures = Vec::new();
    let mut worst: f64 = 0.0;
    for case in cases() {
        let pp = plastic(&case.params);
        let bsdf = Bsdf::<3>::new(&case.params).expect("valid params");
        for s in &case.evals {
            let (wi, wo) = (DVec3::from_array(s.wi), DVec3::from_array(s.wo));
            let (got, back) = (bsdf.eval(wi, wo), bsdf.eval(wo, wi));
            for c in 0..3 {
                if s.fr[c].abs() > 1e-6 {
                    worst = worst.max((got[c] - s.fr[c]).abs() / s.fr[c].abs());
                }
                for (what, g) in [("eval", got[c]), ("eval reversed", back[c])] {
                    if !close(g, s.fr[c], 1e-4) {
                        failures.push(format!(
                            "{} {what} wi={wi} wo={wo} channel {c}: trilux {g} Mitsuba {}",
                            case.name, s.fr[c]
                        ));
                    }
                }
            }
            let mut pdf = bsdf.pdf(wo, wi);
            if pp.coat.is_none() && wo.z * wi.z > 0.0 {
                // Mitsuba's pdf counts the probability of the delta lobe out.
                let (_, w) = bsdf.delta_reflection(wo).expect("a smooth coat");
                let f = w[0] / mean(&pp.specular_reflectance);
                pdf *= 1.0 - prob_specular(pp, f);
            }
            if !close(pdf, s.pdf, pdf_tolerance(pp)) {
                failures.push(format!(
                    "{} pdf wi={wi} wo={wo}: trilux {pdf} Mitsuba {}",
                    case.name, s.pdf
                ));
            }
        }
    }
    eprintln!("worst relative error of fr: {worst:.2e}");
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn samples_match_mitsuba3() {
    let mut failures = Vec::new();
    for case in cases() {
        let pp = plastic(&case.params);
        let bsdf = Bsdf::<3>::new(&case.params).expect("valid params");
        for s in &case.samples {
            let (wi, wo) = (DVec3::from_array(s.wi), DVec3::from_array(s.wo));
            if s.delta {
                // The mirror direction, weight F·spec / prob, pdf = prob.
                let (dir, w) = bsdf.delta_reflection(wo).expect("a smooth coat");
                let f = w[0] / mean(&pp.specular_reflectance);
                let prob = prob_specular(pp, f);
                let ok = (dir - wi).length() < 1e-5
                    && close(prob, s.pdf, 1e-4)
                    && (0..3).all(|c| close(w[c], s.weight[c] * s.pdf, 1e-4));
                if !ok {
                    failures.push(format!(
                        "{} delta wo={wo}: trilux {dir} {w:?} prob {prob}; Mitsuba {wi} {:?} pdf {}",
                        case.name, s.weight, s.pdf
                    ));
                }
                continue;
            }
            // A continuous sample: Mitsuba's weight is its eval·cos over its
            // pdf; trilux's density at the same direction must agree.
            let fr = bsdf.eval(wi, wo);
            for c in 0..3 {
                let w = fr[c] * wi.z.abs() / s.pdf;
                if !close(w, s.weight[c], 1e-4) {
                    failures.push(format!(
                        "{} sample weight wo={wo} wi={wi} channel {c}: trilux {w} Mitsuba {}",
                        case.name, s.weight[c]
                    ));
                }
            }
            let mut pdf = bsdf.pdf(wo, wi);
            if pp.coat.is_none() {
                let (_, w) = bsdf.delta_reflection(wo).expect("a smooth coat");
                pdf *= 1.0 - prob_specular(pp, w[0] / mean(&pp.specular_reflectance));
            }
            if !close(pdf, s.pdf, pdf_tolerance(pp)) {
                failures.push(format!(
                    "{} sample pdf wo={wo} wi={wi}: trilux {pdf} Mitsuba {}",
                    case.name, s.pdf
                ));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// The albedo (quadrature, delta included) against the mean weight of
/// trilux's own sampler on a stratified 128² grid plus the delta weight.
#[test]
fn albedo_matches_sampling() {
    for case in cases() {
        let bsdf = Bsdf::<3>::new(&case.params).expect("valid params");
        for th in [0.0f64, 30.0, 60.0, 80.0] {
            let th = th.to_radians();
            let wo = DVec3::new(th.sin(), 0.0, th.cos());
            let n = 128;
            let mut sum = 0.0;
            for a in 0..n {
                for b in 0..n {
                    let u = DVec2::new((a as f64 + 0.5) / n as f64, (b as f64 + 0.5) / n as f64);
                    if let Some(s) = bsdf.sample(wo, u) {
                        sum += s.weight[1];
                    }
                }
            }
            let mut est = sum / (n * n) as f64;
            if let Some((_, w)) = bsdf.delta_reflection(wo) {
                est += w[1];
            }
            let a = bsdf.albedo(wo)[1];
            assert!(
                (a - est).abs() < 5e-3,
                "{} θ {:.0}°: albedo {a} sampled {est}",
                case.name,
                th.to_degrees()
            );
        }
    }
}
