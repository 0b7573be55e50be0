//! The facing test of `faces::eligible_pairs`, with a fast path.
//!
//! The joint test — some probe q of face b with (q − p)·n_p > ε and some
//! probe p of face a with (p − q)·n_q > ε, for the same pair (p, q) —
//! costs 7⁴ = 2 401 pair tests. It separates for (near-)planar faces:
//! with a reference normal n̄_a and ν_a = max_p |n_p − n̄_a|,
//!
//!   (q − p)·n_p = q·n̄_a − p·n̄_a + (q − p)·(n_p − n̄_a),
//!
//! whose last term is at most D ν_a in size (D bounds |q − p|), and the
//! floating-point values of both forms differ by less than τ (a bound of
//! their rounding errors). So the first condition holds for q* = argmax
//! q·n̄_a and every p when max_q q·n̄_a − max_p p·n̄_a − D ν_a − τ > ε, and
//! for no pair when max_q q·n̄_a − min_p p·n̄_a + D ν_a + τ ≤ ε; likewise
//! the second with n̄_b and p* = argmax p·n̄_b. When both hold for every
//! partner the pair (p*, q*) satisfies both; when either holds for none,
//! no pair does. Only the remaining cases (curved faces, faces nearly
//! touching ε) run the joint test, so the answer is the joint test's,
//! bit for bit, at 49 + 49 dot products for most pairs.

use glam::DVec3;

/// Probe points and normals of one face with what the fast path needs.
pub(crate) struct FaceProbes {
    /// Points and face-oriented normals (`faces::probe_points`).
    pub points: Vec<(DVec3, DVec3)>,
    /// The reference normal n̄ (the first probe's).
    normal: DVec3,
    /// ν: an upper bound of |n_p − n̄| over the probes.
    nu: f64,
    /// min and max of p·n̄ over the probes.
    lo: f64,
    hi: f64,
    /// A ball holding every probe (centre, radius).
    centre: DVec3,
    radius: f64,
    /// Every coordinate finite (else only the joint test is used).
    finite: bool,
}

impl FaceProbes {
    pub fn new(points: Vec<(DVec3, DVec3)>) -> Self {
        let finite =
            !points.is_empty() && points.iter().all(|(p, n)| p.is_finite() && n.is_finite());
        let normal = points.first().map_or(DVec3::ZERO, |&(_, n)| n);
        let nu = points
            .iter()
            .map(|&(_, n)| (n - normal).length())
            .fold(0.0, f64::max)
            * (1.0 + 1e-9)
            + 1e-15;
        let (lo, hi) = points
            .iter()
            .fold((f64::MAX, f64::MIN), |(lo, hi), &(p, _)| {
                let s = p.dot(normal);
                (lo.min(s), hi.max(s))
            });
        let centre = points.iter().map(|&(p, _)| p).sum::<DVec3>() / points.len().max(1) as f64;
        let radius = points
            .iter()
            .map(|&(p, _)| (p - centre).length())
            .fold(0.0, f64::max);
        FaceProbes {
            points,
            normal,
            nu,
            lo,
            hi,
            centre,
            radius,
            finite,
        }
    }

    /// The largest |coordinate| of the probes (for the rounding bound).
    pub fn extent(&self) -> f64 {
        self.points
            .iter()
            .map(|&(p, _)| p.abs().max_element())
            .fold(0.0, f64::max)
    }
}

/// The rounding bound τ for probes whose coordinates are at most `extent`
/// in size: both forms' errors are below 40 u·extent (u = 2⁻⁵³); τ is 200
/// times that.
pub(crate) fn rounding_bound(extent: f64) -> f64 {
    1e-12 * extent
}

/// The joint test (module docs): some pair (p, q) of probes of `a` and `b`
/// with q in front of p and p in front of q, both by more than `eps`.
pub(crate) fn facing_joint(a: &[(DVec3, DVec3)], b: &[(DVec3, DVec3)], eps: f64) -> bool {
    a.iter().any(|&(p, np)| {
        b.iter().any(|&(q, nq)| {
            let d = q - p;
            d.dot(np) > eps && -d.dot(nq) > eps
        })
    })
}

/// The same answer as [`facing_joint`], by the separated bounds when they
/// decide (module docs); `tau` from [`rounding_bound`] of every probe.
pub(crate) fn facing(a: &FaceProbes, b: &FaceProbes, eps: f64, tau: f64) -> bool {
    if !(a.finite && b.finite && tau.is_finite()) {
        return facing_joint(&a.points, &b.points, eps);
    }
    let d = ((a.centre - b.centre).length() + a.radius + b.radius) * (1.0 + 1e-9);
    // First condition: (q − p)·n_p > ε, with n̄_a.
    let q_max = max_dot(&b.points, a.normal);
    let slack_a = d * a.nu + tau;
    if q_max - a.lo + slack_a <= eps {
        return false;
    }
    // Second condition: (p − q)·n_q > ε, with n̄_b.
    let p_max = max_dot(&a.points, b.normal);
    let slack_b = d * b.nu + tau;
    if p_max - b.lo + slack_b <= eps {
        return false;
    }
    if q_max - a.hi - slack_a > eps && p_max - b.hi - slack_b > eps {
        return true;
    }
    facing_joint(&a.points, &b.points, eps)
}

fn max_dot(points: &[(DVec3, DVec3)], n: DVec3) -> f64 {
    points
        .iter()
        .map(|&(p, _)| p.dot(n))
        .fold(f64::MIN, f64::max)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A small deterministic generator (xorshift).
    struct Rng(u64);
    impl Rng {
        fn next(&mut self) -> f64 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            (self.0 >> 11) as f64 / (1u64 << 53) as f64
        }
        fn vec(&mut self) -> DVec3 {
            DVec3::new(self.next(), self.next(), self.next()) * 2.0 - 1.0
        }
    }

    /// 7×7 probes of a random planar quad (parallelogram) with origin
    /// `o`, edges `u`, `v` and normal ±(u × v).
    fn quad(o: DVec3, u: DVec3, v: DVec3, flip: bool) -> Vec<(DVec3, DVec3)> {
        let n = u.cross(v).normalize() * if flip { -1.0 } else { 1.0 };
        (0..49)
            .map(|k| {
                (
                    o + u * ((k / 7) as f64 / 6.0) + v * ((k % 7) as f64 / 6.0),
                    n,
                )
            })
            .collect()
    }

    /// Random planar pairs, many of them touching, coplanar or parallel
    /// (where ε decides): the fast path gives the brute-force answer.
    #[test]
    fn fast_path_agrees_with_the_joint_test_on_planar_pairs() {
        let mut rng = Rng(0x9E37_79B9_7F4A_7C15);
        let (mut yes, mut no) = (0, 0);
        for case in 0..20_000 {
            let scale = [1e-3, 1.0, 1e3][case % 3];
            let (o, u, v) = (rng.vec() * scale, rng.vec() * scale, rng.vec() * scale);
            let (o2, u2, v2) = match case % 5 {
                // Coplanar, sharing a corner or apart.
                0 => (o + u * rng.next(), u * rng.next(), v * rng.next()),
                // Parallel at a distance near ε.
                1 => {
                    let off = u.cross(v).normalize() * scale * 1e-9 * 4.0 * rng.next();
                    (o + off + v, u, v)
                }
                // Sharing an edge, at a random angle.
                2 => (o, u, rng.vec() * scale),
                _ => (rng.vec() * scale, rng.vec() * scale, rng.vec() * scale),
            };
            let a = quad(o, u, v, rng.next() < 0.5);
            let b = quad(o2, u2, v2, rng.next() < 0.5);
            let extent = (a.iter().chain(&b))
                .map(|(p, _)| p.abs().max_element())
                .fold(0.0, f64::max);
            let eps = 1e-9 * scale;
            let brute = facing_joint(&a, &b, eps);
            let fast = facing(
                &FaceProbes::new(a),
                &FaceProbes::new(b),
                eps,
                rounding_bound(extent),
            );
            assert_eq!(fast, brute, "case {case}");
            if brute { yes += 1 } else { no += 1 }
        }
        // Both answers occur often enough for the comparison to mean something.
        assert!(yes > 2_000 && no > 2_000, "{yes} facing, {no} not");
    }

    /// Curved faces (normals spread over a hemisphere) take the joint test.
    #[test]
    fn curved_faces_agree_with_the_joint_test() {
        let mut rng = Rng(12345);
        for case in 0..2_000 {
            let probe = |rng: &mut Rng, c: DVec3| -> Vec<(DVec3, DVec3)> {
                (0..49)
                    .map(|_| {
                        let n = rng.vec().normalize();
                        (c + n * 0.5, n)
                    })
                    .collect()
            };
            let (ca, cb) = (rng.vec(), rng.vec());
            let (a, b) = (probe(&mut rng, ca), probe(&mut rng, cb));
            let brute = facing_joint(&a, &b, 1e-9);
            let fast = facing(&FaceProbes::new(a), &FaceProbes::new(b), 1e-9, 1e-12);
            assert_eq!(fast, brute, "case {case}");
        }
    }
}
