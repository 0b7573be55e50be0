//! Adaptive cubature over integration domains: the outer integral of every
//! deterministic form factor (the module docs of [`super`] give the method).
//!
//! A domain is a uv rectangle of a parametric patch or a triangle. Its
//! degree-5 rule (3×3 Gauss–Legendre, or Dunavant's 7 points) is compared
//! with a lower-order rule (2×2 Gauss–Legendre, degree 3, or Strang and
//! Fix's 3 points, degree 2), or with the same rule on its four children,
//! and refined where they differ by more than the domain's share of the
//! tolerance. [`integrate_pairs`] does the same over pairs of domains, for
//! the kernel itself when neither element is polygonal.

use glam::{DVec2, DVec3};

use crate::patch::Patch;
use crate::quadrature::{GL2_X, GL3_W, GL3_X, TRI3, TRI7, triangle_area};

use super::kernel;

/// A domain of integration.
#[derive(Clone, Copy, Debug)]
pub(crate) enum QDom<'a> {
    Rect {
        patch: &'a Patch,
        min: DVec2,
        max: DVec2,
        /// ±1: which side's normal the rules report.
        s: f64,
    },
    Tri {
        v: [DVec3; 3],
        n: DVec3,
    },
}

impl QDom<'_> {
    fn split(&self) -> [Self; 4] {
        match *self {
            QDom::Rect { patch, min, max, s } => {
                let mid = 0.5 * (min + max);
                [
                    QDom::Rect {
                        patch,
                        min,
                        max: mid,
                        s,
                    },
                    QDom::Rect {
                        patch,
                        min: DVec2::new(mid.x, min.y),
                        max: DVec2::new(max.x, mid.y),
                        s,
                    },
                    QDom::Rect {
                        patch,
                        min: DVec2::new(min.x, mid.y),
                        max: DVec2::new(mid.x, max.y),
                        s,
                    },
                    QDom::Rect {
                        patch,
                        min: mid,
                        max,
                        s,
                    },
                ]
            }
            QDom::Tri { v: [a, b, c], n } => {
                let (ab, bc, ca) = (0.5 * (a + b), 0.5 * (b + c), 0.5 * (c + a));
                [
                    QDom::Tri { v: [a, ab, ca], n },
                    QDom::Tri { v: [ab, b, bc], n },
                    QDom::Tri { v: [ca, bc, c], n },
                    QDom::Tri { v: [bc, ca, ab], n },
                ]
            }
        }
    }

    /// The one-point rule: the top-level check of [`integrate`].
    fn centre_rule(&self, f: &mut dyn FnMut(DVec3, DVec3) -> (f64, f64)) -> f64 {
        match *self {
            QDom::Rect { patch, min, max, s } => {
                let d = max - min;
                let pp = patch.eval(min + 0.5 * d);
                pp.jacobian() * d.x * d.y * f(pp.p, s * pp.n).0
            }
            QDom::Tri { v: [a, b, c], n } => triangle_area(a, b, c) * f((a + b + c) / 3.0, n).0,
        }
    }

    /// The lower-order rule that checks [`QDom::rule`] inside the
    /// refinement: 2×2 Gauss–Legendre on a rectangle, Strang and Fix's 3
    /// points on a triangle. Their difference estimates the lower rule's
    /// error, h⁴ or h³ in the domain's size against the degree-5 rule's
    /// h⁶; the one-point rule (h²) refined nearly every child near a
    /// shared edge although its degree-5 value was already accurate. Not
    /// at the top: on a domain as large as its distance to the polygon the
    /// two rules' errors are correlated (2 × 2 parallel squares at
    /// distance 1 were accepted 0.28 % low at a 0.1 % tolerance).
    fn check_rule(&self, f: &mut dyn FnMut(DVec3, DVec3) -> (f64, f64)) -> f64 {
        match *self {
            QDom::Rect { patch, min, max, s } => {
                let d = max - min;
                let mut sum = 0.0;
                for x in GL2_X {
                    for y in GL2_X {
                        let pp = patch.eval(min + d * DVec2::new(x, y));
                        sum += 0.25 * pp.jacobian() * f(pp.p, s * pp.n).0;
                    }
                }
                sum * d.x * d.y
            }
            QDom::Tri { v: [a, b, c], n } => {
                let sum: f64 = TRI3
                    .iter()
                    .map(|l| f(l[0] * a + l[1] * b + l[2] * c, n).0)
                    .sum();
                triangle_area(a, b, c) * sum / 3.0
            }
        }
    }

    fn centre_point(&self) -> (DVec3, DVec3, f64) {
        match *self {
            QDom::Rect { patch, min, max, s } => {
                let d = max - min;
                let pp = patch.eval(min + 0.5 * d);
                (pp.p, s * pp.n, pp.jacobian() * d.x * d.y)
            }
            QDom::Tri { v: [a, b, c], n } => ((a + b + c) / 3.0, n, triangle_area(a, b, c)),
        }
    }

    /// The rule's points (position, normal, weight).
    pub(crate) fn points(&self) -> Vec<(DVec3, DVec3, f64)> {
        let mut out = Vec::with_capacity(9);
        match *self {
            QDom::Rect { patch, min, max, s } => {
                let d = max - min;
                for i in 0..3 {
                    for j in 0..3 {
                        let pp = patch.eval(min + d * DVec2::new(GL3_X[i], GL3_X[j]));
                        out.push((
                            pp.p,
                            s * pp.n,
                            GL3_W[i] * GL3_W[j] * pp.jacobian() * d.x * d.y,
                        ));
                    }
                }
            }
            QDom::Tri { v: [a, b, c], n } => {
                let area = triangle_area(a, b, c);
                for (l, w) in TRI7 {
                    out.push((l[0] * a + l[1] * b + l[2] * c, n, w * area));
                }
            }
        }
        out
    }

    /// A size measure: the diagonal of the box of a 3×3 grid of the domain
    /// (corners alone miss the extent of disk sectors and annuli).
    fn size(&self) -> f64 {
        match *self {
            QDom::Rect {
                patch, min, max, ..
            } => {
                let d = max - min;
                let b = crate::bounds::Bounds::from_points((0..9).map(|k| {
                    patch
                        .eval(min + d * DVec2::new((k % 3) as f64 * 0.5, (k / 3) as f64 * 0.5))
                        .p
                }));
                b.diagonal().length()
            }
            QDom::Tri { v: [a, b, c], .. } => {
                (a - b).length().max((b - c).length()).max((c - a).length())
            }
        }
    }

    /// Applies the degree-5 rule: Σ w f(x, n), and Σ w · (inner error).
    fn rule(&self, f: &mut dyn FnMut(DVec3, DVec3) -> (f64, f64)) -> (f64, f64) {
        let mut sum = 0.0;
        let mut e = 0.0;
        match *self {
            QDom::Rect { patch, min, max, s } => {
                let d = max - min;
                for i in 0..3 {
                    for j in 0..3 {
                        let uv = min + d * DVec2::new(GL3_X[i], GL3_X[j]);
                        let pp = patch.eval(uv);
                        let w = GL3_W[i] * GL3_W[j] * pp.jacobian() * d.x * d.y;
                        let (v, ve) = f(pp.p, s * pp.n);
                        sum += w * v;
                        e += w * ve;
                    }
                }
            }
            QDom::Tri { v: [a, b, c], n } => {
                let area = triangle_area(a, b, c);
                for (l, w) in TRI7 {
                    let p = l[0] * a + l[1] * b + l[2] * c;
                    let (v, ve) = f(p, n);
                    sum += w * area * v;
                    e += w * area * ve;
                }
            }
        }
        (sum, e)
    }
}

/// Adaptive cubature of `f` over `dom`, whose coarse estimate is `q0`.
fn adaptive(
    dom: &QDom<'_>,
    f: &mut dyn FnMut(DVec3, DVec3) -> (f64, f64),
    q0: (f64, f64),
    tol: f64,
    depth: u32,
) -> (f64, f64) {
    let children = dom.split();
    let qs = children.map(|c| c.rule(f));
    let q1: f64 = qs.iter().map(|q| q.0).sum();
    let err = (q1 - q0.0).abs();
    if err <= tol || depth == 0 {
        return (q1, err + qs.iter().map(|q| q.1).sum::<f64>());
    }
    // Only the children whose own check fails are refined further (near
    // a shared edge, where the integrand is singular, one or two of four).
    let mut v = 0.0;
    let mut e = 0.0;
    for (c, q) in children.iter().zip(qs) {
        let (cv, ce) = accept_or_refine(c, f, q, (0.5 * tol, depth - 1), |d, f| d.check_rule(f));
        v += cv;
        e += ce;
    }
    (v, e)
}

/// A domain's degree-5 estimate `q` when `check` (a lower-order rule)
/// agrees within `tol` (error: their difference), else [`adaptive`].
fn accept_or_refine<'a>(
    dom: &QDom<'a>,
    f: &mut dyn FnMut(DVec3, DVec3) -> (f64, f64),
    q: (f64, f64),
    (tol, depth): (f64, u32),
    check: impl Fn(&QDom<'a>, &mut dyn FnMut(DVec3, DVec3) -> (f64, f64)) -> f64,
) -> (f64, f64) {
    let c = check(dom, f);
    if (c - q.0).abs() <= tol {
        return (q.0, (c - q.0).abs() + q.1);
    }
    adaptive(dom, f, q, tol, depth)
}

/// Integrates `f` over a list of domains to a relative tolerance. A domain
/// whose degree-5 estimate agrees with its lower-order check within the
/// tolerance is accepted at once (error: their difference, a conservative
/// bound for smooth integrands); the others are refined adaptively.
pub(crate) fn integrate(
    doms: &[QDom<'_>],
    f: &mut dyn FnMut(DVec3, DVec3) -> (f64, f64),
    rel_tol: f64,
    depth: u32,
) -> (f64, f64) {
    let q0: Vec<(f64, f64)> = doms.iter().map(|d| d.rule(f)).collect();
    let total: f64 = q0.iter().map(|q| q.0.abs()).sum();
    // Each domain's share of the tolerance: half by its share of the
    // estimate, half evenly (the shares sum to rel_tol · total).
    let even = total / doms.len().max(1) as f64;
    let mut v = 0.0;
    let mut e = 0.0;
    for (d, q) in doms.iter().zip(q0) {
        let tol = (0.5 * rel_tol * (q.0.abs() + even)).max(1e-300);
        // The one-point check at the top: see `QDom::check_rule` for why
        // not the lower-order rule there.
        let (dv, de) = accept_or_refine(d, f, q, (tol, depth), |d, f| d.centre_rule(f));
        v += dv;
        e += de;
    }
    (v, e)
}

/// Rule points of a domain: (point, normal, weight).
type RulePoints = Vec<(DVec3, DVec3, f64)>;

/// The product rule over two domains' rule points:
/// Σ_i Σ_j w_i w_j K(x_i, y_j).
fn pair_rule(pa: &[(DVec3, DVec3, f64)], pb: &[(DVec3, DVec3, f64)]) -> f64 {
    pa.iter()
        .map(|&(x, nx, wx)| {
            wx * pb
                .iter()
                .map(|&(y, ny, wy)| wy * kernel(x, nx, y, ny))
                .sum::<f64>()
        })
        .sum()
}

/// Adaptive cubature of the kernel over a pair of domains (with their rule
/// points `pa`, `pb`, evaluated once per domain). Both one-sided
/// refinements (split `a`, split `b`) are compared with the parent
/// estimate: the error is the larger difference (refining one side alone
/// cannot see the other side's rule error), and the side whose refinement
/// changed the estimate most is refined further (as hierarchical radiosity
/// refines the link's worse end).
fn pair_adaptive(
    a: &QDom<'_>,
    pa: &[(DVec3, DVec3, f64)],
    b: &QDom<'_>,
    pb: &[(DVec3, DVec3, f64)],
    q0: f64,
    tol: f64,
    depth: u32,
) -> (f64, f64) {
    let ca = a.split();
    let cb = b.split();
    let pca: [RulePoints; 4] = ca.map(|c| c.points());
    let pcb: [RulePoints; 4] = cb.map(|c| c.points());
    let qa: [f64; 4] = std::array::from_fn(|k| pair_rule(&pca[k], pb));
    let qb: [f64; 4] = std::array::from_fn(|k| pair_rule(pa, &pcb[k]));
    let (sa, sb): (f64, f64) = (qa.iter().sum(), qb.iter().sum());
    let (ea, eb) = ((sa - q0).abs(), (sb - q0).abs());
    let split_a = ea > eb || (ea == eb && a.size() >= b.size());
    let q1 = if split_a { sa } else { sb };
    if ea.max(eb) <= tol || depth == 0 {
        return (q1, ea.max(eb));
    }
    let mut v = 0.0;
    let mut e = 0.0;
    for k in 0..4 {
        let (cv, ce) = if split_a {
            pair_adaptive(&ca[k], &pca[k], b, pb, qa[k], 0.5 * tol, depth - 1)
        } else {
            pair_adaptive(a, pa, &cb[k], &pcb[k], qb[k], 0.5 * tol, depth - 1)
        };
        v += cv;
        e += ce;
    }
    (v, e)
}

/// ∫∫ K over all pairs of domains to a relative tolerance; also the min and
/// max of the point-to-element estimates at the sender's rule points.
pub(crate) fn integrate_pairs(
    from: &[QDom<'_>],
    to: &[QDom<'_>],
    rel_tol: f64,
    depth: u32,
) -> (f64, f64, f64, f64) {
    let from_points: Vec<RulePoints> = from.iter().map(QDom::points).collect();
    let to_points: Vec<RulePoints> = to.iter().map(QDom::points).collect();
    let mut q0 = Vec::with_capacity(from.len() * to.len());
    for pa in &from_points {
        for pb in &to_points {
            q0.push(pair_rule(pa, pb));
        }
    }
    let total: f64 = q0.iter().sum();
    let even = total / q0.len().max(1) as f64;
    let mut v = 0.0;
    let mut e = 0.0;
    let mut k = 0;
    for (a, pa) in from.iter().zip(&from_points) {
        for (b, pb) in to.iter().zip(&to_points) {
            let tol = (0.5 * rel_tol * (q0[k].abs() + even)).max(1e-300);
            // Accept at once when the one-point pair rule agrees with the
            // product rule (error: their difference, conservative for
            // smooth kernels).
            let ((x, nx, wx), (y, ny, wy)) = (a.centre_point(), b.centre_point());
            let c = wx * wy * kernel(x, nx, y, ny);
            let (dv, de) = if (c - q0[k]).abs() <= tol {
                (q0[k], (c - q0[k]).abs())
            } else {
                pair_adaptive(a, pa, b, pb, q0[k], tol, depth)
            };
            v += dv;
            e += de;
            k += 1;
        }
    }
    let all_to: RulePoints = to_points.into_iter().flatten().collect();
    let mut lo = f64::INFINITY;
    let mut hi = f64::NEG_INFINITY;
    for pa in &from_points {
        for &(x, nx, _) in pa {
            let g: f64 = all_to
                .iter()
                .map(|&(y, ny, wy)| wy * kernel(x, nx, y, ny))
                .sum::<f64>()
                .min(1.0);
            lo = lo.min(g);
            hi = hi.max(g);
        }
    }
    (v, e, lo, hi)
}
