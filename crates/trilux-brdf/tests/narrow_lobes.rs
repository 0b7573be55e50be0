//! The sampled area reflectance of narrow lobes (docs/solver.md, "Narrow
//! lobes"): `sample_glossy_lobe` shares are non-negative, sum to the glossy
//! albedo and so never to more over receivers that do not overlap, and the
//! flux they carry between two receivers is reciprocal.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test, bench or example may panic

mod common;

use std::f64::consts::PI;

use glam::DVec3;
use proptest::prelude::*;
use trilux_brdf::{
    AlbedoTable, Bsdf, BsdfParams, Distribution, Frame, Side, is_narrow, lobe_width,
    sample_glossy_lobe,
};

fn material() -> impl Strategy<Value = BsdfParams> {
    // α drawn log-uniformly down to 1e-4 (near mirrors), half of them
    // blended with a diffuse part.
    (-4.0..0.0f64, 0.0..=1.0f64, any::<bool>(), any::<bool>()).prop_map(|(la, w, ggx, blend)| {
        let d = if ggx {
            Distribution::Ggx
        } else {
            Distribution::Beckmann
        };
        let g = common::gold(d, 10f64.powf(la));
        if blend {
            BsdfParams::Blend {
                weight: w,
                first: Box::new(common::diffuse(0.5)),
                second: Box::new(g),
            }
        } else {
            g
        }
    })
}

/// A direction from its polar angle's cosine and its azimuth.
fn direction(z: f64, phi: f64) -> DVec3 {
    let r = (1.0 - z * z).max(0.0).sqrt();
    DVec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// The glossy albedo the solver uses: the table less the Lambertian part.
fn glossy_albedo(b: &Bsdf<3>, table: &AlbedoTable<3>, wi: DVec3) -> trilux_color::Spectrum<3> {
    let side = if wi.z > 0.0 { Side::Front } else { Side::Back };
    (table.albedo(wi) - b.diffuse_albedo(side)).max(trilux_color::Spectrum::zero())
}

/// The lobe grid of [`cone_transfer`] (per axis) for lobes at least as
/// wide as the sending rule's radial spacing: fine enough that its error
/// is far below the reciprocity bound (see that test).
const LOBE_GRID: u32 = 32;

/// The sending rule (per axis) and the lobe grid for a lobe of angular
/// width `width` sent from a cone of angular radius `radius`.
///
/// The transfer integrates the product of a smooth cone rule and the lobe's
/// spread. A lobe wider than the 16 × 16 rule's radial spacing (radius/16)
/// smooths the receiving cone's edge, and 16 × 16 points with a 32 × 32
/// lobe grid suffice. A narrower lobe (a near mirror) sees the receiving
/// cone as a sharp indicator: the error is then the sending rule's on a
/// lens-shaped domain, which with 256 points reached 0.66 % (α = 2e-4,
/// cones of 0.08 rad, a CI draw). There the rule is 64 × 64 (the boundary
/// error falls about as n^-1.5, 8× lower) and the lobe grid 8 × 8: only
/// the points whose lobe straddles the edge, under 1/8 of them, see the
/// lobe grid's error, so the product costs no more than before.
fn rule_sizes(width: f64, radius: f64) -> (u32, u32) {
    if width < radius / 16.0 {
        (64, 8)
    } else {
        (16, LOBE_GRID)
    }
}

/// The flux that a cone of directions `from` (axis, angular radius) sends
/// through the reflector into the cone `to`, per unit radiance:
/// (1/π) ∫_{Ω_from} cos θ_i ∫_{Ω_to} fr cos θ_o, the incident directions
/// on a stratified grid over the cone, each lobe sampled ([`rule_sizes`]).
fn cone_transfer(b: &Bsdf<3>, table: &AlbedoTable<3>, from: (DVec3, f64), to: (DVec3, f64)) -> f64 {
    let (axis, radius) = from;
    let width = lobe_width(b, Side::Front).unwrap_or(f64::INFINITY);
    let (n, grid) = rule_sizes(width, radius);
    let frame = Frame::from_normal(axis);
    let cos_r = radius.cos();
    let mut sum = 0.0;
    let mut samples = Vec::new();
    for a in 0..n {
        for c in 0..n {
            // Uniform in solid angle over the cone.
            let z = 1.0 - (f64::from(a) + 0.5) / f64::from(n) * (1.0 - cos_r);
            let phi = (f64::from(c) + 0.5) / f64::from(n) * 2.0 * PI;
            let wi = frame.to_world(direction(z, phi));
            if wi.z <= 0.0 {
                continue;
            }
            let dw = 2.0 * PI * (1.0 - cos_r) / f64::from(n * n);
            samples.clear();
            sample_glossy_lobe(b, wi, glossy_albedo(b, table, wi), grid, 1.0, &mut samples);
            let into: f64 = samples
                .iter()
                .filter(|s| s.wo.dot(to.0) >= to.1.cos())
                .map(|s| s.share[1])
                .sum();
            sum += wi.z * dw / PI * into;
        }
    }
    sum
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    /// Over receivers that tile the sphere of directions (a latitude ×
    /// longitude grid of any size), the shares are finite, non-negative and
    /// sum to exactly the glossy albedo: never more.
    #[test]
    fn shares_conserve_energy(p in material(), z in 0.02..1.0f64, phi in 0.0..6.3f64,
                              back in any::<bool>(), grid in 1u32..9,
                              rows in 1usize..12, cols in 1usize..12) {
        let b = Bsdf::<3>::new(&p).unwrap();
        let mut wi = direction(z, phi);
        if back {
            wi.z = -wi.z;
        }
        let albedo = glossy_albedo(&b, &b.albedo_table(), wi);
        let mut samples = Vec::new();
        sample_glossy_lobe(&b, wi, albedo, grid, 1.0, &mut samples);
        let mut cells = vec![[0.0f64; 3]; rows * cols];
        for s in &samples {
            prop_assert!(s.share.is_finite() && s.share.is_non_negative());
            prop_assert!(s.wo.z * wi.z > 0.0, "a sample left on the other side");
            let row = (((s.wo.z + 1.0) * 0.5 * rows as f64) as usize).min(rows - 1);
            let col = (((s.wo.y.atan2(s.wo.x) + PI) / (2.0 * PI) * cols as f64) as usize).min(cols - 1);
            for (q, c) in cells[row * cols + col].iter_mut().enumerate() {
                *c += s.share[q];
            }
        }
        for q in 0..3 {
            let total: f64 = cells.iter().map(|c| c[q]).sum();
            prop_assert!(cells.iter().all(|c| c[q] >= 0.0));
            prop_assert!(total <= albedo[q] * (1.0 + 1e-12) + 1e-15,
                "Σ shares {} > glossy albedo {}", total, albedo[q]);
            if !samples.is_empty() && albedo[q] > 0.0 {
                prop_assert!((total - albedo[q]).abs() <= 1e-9 * albedo[q]);
            }
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(12))]

    /// Reciprocity of the sampled transfer for narrow lobes: the flux from
    /// a cone I into a cone K near I's mirror direction equals the flux
    /// from K into I (both are ∫∫ fr cos cos, symmetric by fr's
    /// reciprocity), to the sampling's accuracy.
    #[test]
    fn sampled_transfer_is_reciprocal(la in -4.0..-1.5f64, ggx in any::<bool>(),
                                      z in 0.3..0.95f64, phi in 0.0..6.3f64,
                                      radius in 0.08..0.2f64, off in 0.0..0.5f64,
                                      turn in 0.0..6.3f64) {
        let d = if ggx { Distribution::Ggx } else { Distribution::Beckmann };
        let b = Bsdf::<3>::new(&common::gold(d, 10f64.powf(la))).unwrap();
        let di = direction(z, phi);
        let mirror = DVec3::new(-di.x, -di.y, di.z);
        // K's axis: the mirror direction moved by up to half the radius.
        let f = Frame::from_normal(mirror);
        let dk = f.to_world(direction((off * radius).cos(), turn)).normalize();
        prop_assume!(dk.z > radius.sin() + 0.05);
        let table = b.albedo_table();
        let a = cone_transfer(&b, &table, (di, radius), (dk, radius));
        let c = cone_transfer(&b, &table, (dk, radius), (di, radius));
        prop_assert!(a > 0.0 && c > 0.0);
        // The two directions estimate one integral with two discretisations:
        // the rule over the sending cone and the lobe grid at each of its
        // points ([`rule_sizes`]). On the worst wide-lobe case found (the regression
        // file's: GGX α 0.029, cones of 0.12 rad) they differ by 9e-5 to
        // 2e-4 at these sizes, but by 0.6 % with an 8 × 8 lobe grid, whatever
        // the cone rule (24² to 192² points): the lobe grid's error, which an
        // earlier version of this test had taken for the rule's. 0.5 % stays
        // the bound (it was 5 %, which a wrong factor of a few per cent
        // would have passed).
        prop_assert!((a - c).abs() <= 0.005 * a.max(c), "I→K {a}, K→I {c}");
    }
}

/// The narrow/wide rule: a lobe is sampled exactly when it is narrower than
/// an eighth of the receiver's angular radius; a mirror-like lobe is
/// narrow against any element but the tiniest, a lobe of α ≥ 0.1 against
/// none.
#[test]
fn the_rule_compares_width_and_angular_radius() {
    let w = |a: f64| {
        lobe_width(
            &Bsdf::<3>::new(&common::conductor(Distribution::Ggx, a)).unwrap(),
            Side::Front,
        )
        .unwrap()
    };
    assert!(is_narrow(w(1e-4), 1e-2));
    assert!(!is_narrow(w(1.0), std::f64::consts::FRAC_PI_2));
    assert!(!is_narrow(w(0.1), std::f64::consts::FRAC_PI_2));
    assert!(is_narrow(w(0.01), 0.2) && !is_narrow(w(0.015), 0.2));
    assert!(lobe_width(&Bsdf::<3>::new(&common::diffuse(0.5)).unwrap(), Side::Front).is_none());
}
