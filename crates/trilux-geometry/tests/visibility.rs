//! Visibility fractions against an independent brute-force estimate.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test, bench or example may panic

mod common;

use common::*;
use glam::DVec3;
use trilux_geometry::{FaceElement, SurfaceId, Visibility};

/// Exact visible fraction of segments between uniform points of the unit
/// squares at z = 0 and z = 1 (centred on the z axis) past the blocker
/// square [cx ± h] × [cy ± h] at z = 0.5. A segment crosses z = 0.5 at the
/// midpoint m = (x0 + x1)/2 of its ends, whose density is triangular on
/// [−½, ½] with CDF 2(m + ½)² (m ≤ 0), 1 − 2(½ − m)² (m ≥ 0); the x and y
/// coordinates are independent. No ray tracing involved.
fn exact(cx: f64, cy: f64, h: f64) -> f64 {
    let cdf = |m: f64| {
        let m = m.clamp(-0.5, 0.5);
        if m <= 0.0 {
            2.0 * (m + 0.5) * (m + 0.5)
        } else {
            1.0 - 2.0 * (0.5 - m) * (0.5 - m)
        }
    };
    let px = cdf(cx + h) - cdf(cx - h);
    let py = cdf(cy + h) - cdf(cy - h);
    1.0 - px * py
}

/// The same by brute force: the x and y crossings are independent, so count
/// the pairs (x0, x1) of an n × n grid whose midpoint falls in [c − h, c + h]
/// for each axis (the grid error is O(1/n)).
fn brute_force(n: usize, cx: f64, cy: f64, h: f64) -> f64 {
    let g: Vec<f64> = (0..n).map(|i| (i as f64 + 0.5) / n as f64 - 0.5).collect();
    let frac = |c: f64| {
        let mut inside = 0u64;
        for &a in &g {
            for &b in &g {
                if (0.5 * (a + b) - c).abs() <= h {
                    inside += 1;
                }
            }
        }
        inside as f64 / (n * n) as f64
    };
    1.0 - frac(cx) * frac(cy)
}

#[test]
fn blocker_plate_halfway_matches_brute_force() {
    for (cx, cy, h) in [(0.0, 0.0, 0.25), (0.1, -0.05, 0.2), (0.3, 0.3, 0.35)] {
        let shapes = [
            rect(DVec3::ZERO, 0.5 * DVec3::X, 0.5 * DVec3::Y, false),
            rect(DVec3::Z, 0.5 * DVec3::X, 0.5 * DVec3::Y, true),
            rect(DVec3::new(cx, cy, 0.5), h * DVec3::X, h * DVec3::Y, false),
        ];
        let g = common::forest(&shapes).expect("valid shapes");
        let (a, b) = (g.root(SurfaceId(0)), g.root(SurfaceId(1)));
        let reference = exact(cx, cy, h);
        let brute = brute_force(3001, cx, cy, h);
        assert!(
            (brute - reference).abs() < 2e-3,
            "brute force {brute} vs exact {reference}"
        );
        let samples = 4096;
        let v = Visibility::new(&g, None).fraction(
            FaceElement::front(a),
            FaceElement::front(b),
            samples,
        );
        // 3σ of a binomial estimate with independent samples (stratified
        // samples do better): 3 √(1/4 / 4096) ≈ 0.023.
        assert!(
            (v - reference).abs() < 0.025,
            "blocker ({cx}, {cy}, {h}): {v} vs {reference}"
        );
        // Symmetric in its arguments up to sampling noise, and the batch
        // form agrees with the single form exactly.
        // (a, b) and (b, a) trace the same segments: exactly symmetric.
        assert_eq!(
            Visibility::new(&g, None).fraction(
                FaceElement::front(b),
                FaceElement::front(a),
                samples
            ),
            v
        );
        assert_eq!(
            Visibility::new(&g, None)
                .fraction_batch(&[(FaceElement::front(a), FaceElement::front(b))], samples)[0],
            v
        );
        println!(
            "blocker ({cx}, {cy}, {h}): visibility {v:.4} (exact {reference:.4}, brute force {brute:.4})"
        );
    }
}

#[test]
fn unblocked_and_fully_blocked() {
    let open = common::forest(&[
        rect(DVec3::ZERO, 0.5 * DVec3::X, 0.5 * DVec3::Y, false),
        rect(DVec3::Z, 0.5 * DVec3::X, 0.5 * DVec3::Y, true),
    ])
    .expect("valid");
    assert_eq!(
        Visibility::new(&open, None).fraction(
            FaceElement::front(open.root(SurfaceId(0))),
            FaceElement::front(open.root(SurfaceId(1))),
            256
        ),
        1.0
    );
    let closed = common::forest(&[
        rect(DVec3::ZERO, 0.5 * DVec3::X, 0.5 * DVec3::Y, false),
        rect(DVec3::Z, 0.5 * DVec3::X, 0.5 * DVec3::Y, true),
        rect(0.5 * DVec3::Z, 0.6 * DVec3::X, 0.6 * DVec3::Y, false),
    ])
    .expect("valid");
    assert_eq!(
        Visibility::new(&closed, None).fraction(
            FaceElement::front(closed.root(SurfaceId(0))),
            FaceElement::front(closed.root(SurfaceId(1))),
            256
        ),
        0.0
    );
}

#[test]
fn concave_surfaces_see_their_own_pieces() {
    use glam::DMat4;
    use trilux_geometry::Side;
    // Inside a sphere (flipped) and inside a tube (back sides), every pair
    // of pieces, including a piece with itself, is fully visible: the
    // chords touch the surface only at their ends.
    let g = common::forest(&[
        sphere(DVec3::new(0.1, 0.2, 0.3), 1.3, DMat4::IDENTITY, true),
        cylinder(
            DVec3::new(5.0, 0.0, 0.0),
            DVec3::new(5.0, 0.0, 3.0),
            0.8,
            DMat4::IDENTITY,
            false,
        ),
    ])
    .expect("valid");
    for i in 0..8 {
        for j in 0..8 {
            let v = Visibility::new(&g, None).fraction(
                FaceElement::front(g.root(SurfaceId(i as u32))),
                FaceElement::front(g.root(SurfaceId(j as u32))),
                256,
            );
            assert_eq!(v, 1.0, "sphere pieces {i} {j}");
        }
    }
    for i in 8..12 {
        for j in 8..12 {
            let v = Visibility::new(&g, None).fraction(
                FaceElement::new(g.root(SurfaceId(i as u32)), Side::Back),
                FaceElement::new(g.root(SurfaceId(j as u32)), Side::Back),
                256,
            );
            assert_eq!(v, 1.0, "tube pieces {i} {j}");
        }
    }
}

/// Kernel-weighted visible fraction between the unit squares at z = 0 and
/// z = 1 past the blocker, by brute force over an n⁴ grid of point pairs
/// (no ray tracing): Σ K vis / Σ K with K = 1/r⁴ (both cosines are the
/// height 1 over r).
fn weighted_brute_force(n: usize, cx: f64, cy: f64, h: f64) -> f64 {
    let g: Vec<f64> = (0..n).map(|i| (i as f64 + 0.5) / n as f64 - 0.5).collect();
    let (mut seen, mut total) = (0.0, 0.0);
    for &x0 in &g {
        for &y0 in &g {
            for &x1 in &g {
                for &y1 in &g {
                    let r2 = (x1 - x0).powi(2) + (y1 - y0).powi(2) + 1.0;
                    let k = 1.0 / (r2 * r2);
                    total += k;
                    let (mx, my) = (0.5 * (x0 + x1), 0.5 * (y0 + y1));
                    if (mx - cx).abs() > h || (my - cy).abs() > h {
                        seen += k;
                    }
                }
            }
        }
    }
    seen / total
}

#[test]
fn kernel_weighted_visibility_matches_brute_force() {
    use trilux_geometry::Side;
    for (cx, cy, h) in [(0.0, 0.0, 0.25), (0.3, 0.3, 0.35)] {
        let g = common::forest(&[
            rect(DVec3::ZERO, 0.5 * DVec3::X, 0.5 * DVec3::Y, false),
            rect(DVec3::Z, 0.5 * DVec3::X, 0.5 * DVec3::Y, true),
            rect(DVec3::new(cx, cy, 0.5), h * DVec3::X, h * DVec3::Y, false),
        ])
        .expect("valid");
        let (a, b) = (g.root(SurfaceId(0)), g.root(SurfaceId(1)));
        let v = Visibility::new(&g, None).weighted(
            FaceElement::new(a, Side::Front),
            FaceElement::new(b, Side::Front),
            4096,
        );
        // An odd grid keeps pair midpoints off the blocker's edges (an even
        // one puts many exactly on them and biases the count by ~0.02).
        let reference = weighted_brute_force(37, cx, cy, h);
        // 3σ of 4096 independent samples (0.023), plus the grid's error.
        assert!(
            (v - reference).abs() < 0.025,
            "({cx}, {cy}, {h}): {v} vs {reference}"
        );
        println!(
            "weighted visibility ({cx}, {cy}, {h}): {v:.4} (brute force {reference:.4}, unweighted {:.4})",
            Visibility::new(&g, None).fraction(FaceElement::front(a), FaceElement::front(b), 4096)
        );
    }
}
