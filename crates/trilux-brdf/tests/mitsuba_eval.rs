//! fr at fixed directions and parameters against Mitsuba 3's `bsdf.eval`.
//!
//! The reference values were made once by
//! `crates/trilux-brdf/tools/gen_mitsuba_eval.py` (Mitsuba 3, scalar_rgb) and
//! are stored in `tests/data/mitsuba_eval.json`: Mitsuba's eval divided by
//! |cosθ| of the light direction. Tolerance: 1e-4 relative or 1e-6
//! absolute per channel; Mitsuba computes in f32, so agreement to ~1e-6
//! relative is what exact formulas give.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test, bench or example may panic

use glam::DVec3;
use serde::Deserialize;
use trilux_brdf::{Bsdf, BsdfParams};

#[derive(Deserialize)]
struct Sample {
    wi: [f64; 3],
    wo: [f64; 3],
    fr: [f64; 3],
}

#[derive(Deserialize)]
struct Case {
    name: String,
    params: BsdfParams,
    samples: Vec<Sample>,
}

#[derive(Deserialize)]
struct File {
    cases: Vec<Case>,
}

#[test]
fn brdf_values_match_mitsuba3() {
    let text = include_str!("data/mitsuba_eval.json");
    let file: File = serde_json::from_str(text).expect("valid reference file");
    assert!(file.cases.len() >= 10);
    let mut checked = 0;
    let mut worst_rel: f64 = 0.0;
    let mut failures = Vec::new();
    for case in &file.cases {
        let bsdf = Bsdf::<3>::new(&case.params).expect("valid params");
        for s in &case.samples {
            let wi = DVec3::from_array(s.wi);
            let wo = DVec3::from_array(s.wo);
            let got = bsdf.eval(wi, wo);
            let back = bsdf.eval(wo, wi); // reciprocity against the same value
            for c in 0..3 {
                let want = s.fr[c];
                for (what, g) in [("eval(wi, wo)", got[c]), ("eval(wo, wi)", back[c])] {
                    let err = (g - want).abs();
                    if want.abs() > 1e-6 {
                        worst_rel = worst_rel.max(err / want.abs());
                    }
                    if !(err <= 1e-6 || err <= 1e-4 * want.abs()) {
                        failures.push(format!(
                            "{} {what} wi={:?} wo={:?} channel {c}: trilux {g} Mitsuba {want}",
                            case.name, s.wi, s.wo
                        ));
                    }
                }
                checked += 1;
            }
        }
    }
    eprintln!("checked {checked} channel values; worst relative error {worst_rel:.3e}");
    assert!(
        failures.is_empty(),
        "{} mismatches:\n{}",
        failures.len(),
        failures.join("\n")
    );
}
