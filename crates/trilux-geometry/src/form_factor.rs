//! Unoccluded element-to-element form factors with an error estimate.
//!
//! F_{i→j} = (1/A_i) ∫_{A_i} ∫_{A_j} cos θ_x cos θ_y / (π r²) dA_y dA_x,
//! both cosines on the front sides (light leaves i's front towards j's
//! front); paper Eq. 5 uses F_{J→I} in the area reflectance.
//!
//! # Method
//!
//! - **Polygonal receiver** (a uv rectangle of a planar quad, or a cluster
//!   of at most [`MAX_POLYGON_PIECES`] triangle pieces): the inner integral
//!   is Lambert's closed form for a point and a polygon,
//!   F(dA_x → P) = (1/2π) |Σ_e β_e n_x · u_e| (notes/validation.md), after
//!   clipping P to x's tangent plane and dropping pieces whose front does not
//!   face x. The sender is first clipped to the receiver's front half-space
//!   (the integrand vanishes behind it, with a kink along the plane); for
//!   a non-planar cluster, to each piece's half-space in turn, integrating
//!   piece by piece (otherwise a sliver in front of one piece could hold no
//!   rule point and be missed). The outer integral over the sender is adaptive
//!   cubature: a degree-5 rule (3×3 Gauss–Legendre on uv rectangles,
//!   Dunavant's 7-point rule on triangles) on a domain is accepted at once
//!   if it agrees with the one-point rule within the domain's share of the
//!   tolerance; otherwise it is compared with the same rule on its four
//!   children, and where they differ by more than the tolerance the children
//!   are refined in turn (to `max_depth` levels). This resolves the
//!   logarithmic singularity along an edge shared with the receiver. Disk
//!   elements are integrated as quarter-turn sectors.
//! - **Polygonal sender, non-polygonal receiver**: the same, integrating
//!   over the receiver and using reciprocity A_i F_ij = A_j F_ji.
//! - **Neither polygonal** (disks, sphere and cylinder pieces): adaptive
//!   cubature of the kernel over the pair (the product of the two degree-5
//!   rules; each step compares splitting either element and refines the one
//!   that matters more, as hierarchical radiosity refines links, up to
//!   `max_depth + 2` splits): a deterministic point-sampled estimate.
//! - **Large clusters** (more than [`MAX_POLYGON_PIECES`] pieces on a side
//!   that must be integrated): a sampled estimate stratified by piece (at
//!   least one Owen-scrambled Sobol point in every piece, `samples` in all
//!   at least), with Lambert's form on the other side when it is polygonal
//!   and the kernel with a sampled point of the other element otherwise.
//!
//! `error` is the sum over the final subdomains of |fine − coarse| (a
//! conservative estimate of the error of the returned fine value; a domain
//! accepted at once contributes |degree-5 − one-point|), or, for sampled
//! estimates, the standard error from collapsing neighbouring strata in
//! pairs. `spread` is max − min of the point estimates of F_{from→to} seen
//! during the integration: how much the transfer varies over the integrated
//! element, the usual refinement oracle.

use std::f64::consts::PI;

use glam::{DVec2, DVec3};
use rayon::prelude::*;

use crate::element::ElementDomain;
use crate::ids::ElementId;
use crate::patch::Patch;
use crate::quadrature::{GL3_W, GL3_X, TRI7, triangle_area};
use crate::scene_geometry::SceneGeometry;
use crate::surface::SurfaceGeom;

/// Clusters with at most this many pieces are treated as polygon sets
/// (Lambert's formula, deterministic cubature); larger ones are sampled.
pub const MAX_POLYGON_PIECES: usize = 8;

/// Which side of an element light leaves or arrives on.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Side {
    /// The front (the side the normal points to, after `flip_normals`).
    Front,
    /// The back.
    Back,
}

impl Side {
    /// +1 for the front, −1 for the back.
    pub fn sign(self) -> f64 {
        match self {
            Side::Front => 1.0,
            Side::Back => -1.0,
        }
    }
}

/// A form factor estimate.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FormFactor {
    /// The estimate of F_{from→to} (unoccluded), ≥ 0.
    pub value: f64,
    /// Estimated absolute error of `value` (module docs).
    pub error: f64,
    /// max − min of the point estimates of F_{from→to} over the integrated
    /// element (module docs).
    pub spread: f64,
}

/// Accuracy settings for [`SceneGeometry::form_factor_with`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FormFactorOptions {
    /// Target relative accuracy of the adaptive cubature.
    pub rel_tol: f64,
    /// Maximum number of adaptive refinement levels.
    pub max_depth: u32,
    /// Number of sample pairs for sampled estimates (large clusters).
    pub samples: u32,
}

impl Default for FormFactorOptions {
    /// rel_tol 1e-3, 4 levels, 64 samples.
    fn default() -> Self {
        FormFactorOptions {
            rel_tol: 1e-3,
            max_depth: 4,
            samples: 64,
        }
    }
}

/// A planar polygon with its front unit normal.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Poly {
    v: [DVec3; 4],
    len: usize,
    n: DVec3,
}

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

    /// The one-point (centre) rule: a cheap first estimate.
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

    /// The one-point rule's point (position, normal, weight = area).
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
    fn points(&self) -> Vec<(DVec3, DVec3, f64)> {
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
    let mut v = 0.0;
    let mut e = 0.0;
    for (c, q) in children.iter().zip(qs) {
        let (cv, ce) = adaptive(c, f, q, 0.5 * tol, depth - 1);
        v += cv;
        e += ce;
    }
    (v, e)
}

/// Integrates `f` over a list of domains to a relative tolerance. A domain
/// whose degree-5 estimate agrees with its one-point estimate within the
/// tolerance is accepted at once (error: their difference, a conservative
/// bound for smooth integrands); the others are refined adaptively.
fn integrate(
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
        let c = d.centre_rule(f);
        if (c - q.0).abs() <= tol {
            v += q.0;
            e += (c - q.0).abs() + q.1;
            continue;
        }
        let (dv, de) = adaptive(d, f, q, tol, depth);
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
#[allow(clippy::too_many_arguments)]
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
fn integrate_pairs(
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

/// atan2(y, x) for y ≥ 0 (an angle in [0, π]), by Cephes' double-precision
/// arctangent (range reduction to |t| ≤ tan(π/8), then a 4/5 rational
/// approximation; error ≲ 2 ulp). About twice as fast as libm's general
/// atan2, which dominated the cost of Lambert's formula.
#[inline]
fn atan2_nonneg(y: f64, x: f64) -> f64 {
    const MOREBITS: f64 = 6.123_233_995_736_766e-17;
    const T3P8: f64 = 2.414_213_562_373_095;
    const P: [f64; 5] = [
        -8.750_608_600_031_904e-1,
        -1.615_753_718_733_365e1,
        -7.500_855_792_314_705e1,
        -1.228_866_684_490_136e2,
        -6.485_021_904_942_025e1,
    ];
    const Q: [f64; 5] = [
        2.485_846_490_142_306e1,
        1.650_270_098_316_988e2,
        4.328_810_604_912_903e2,
        4.853_903_996_359_137e2,
        1.945_506_571_482_614e2,
    ];
    let atan_pos = |t: f64| -> f64 {
        // atan(t) for t ≥ 0.
        let (base, more, t) = if t > T3P8 {
            (std::f64::consts::FRAC_PI_2, MOREBITS, -1.0 / t)
        } else if t > 0.66 {
            (
                std::f64::consts::FRAC_PI_4,
                0.5 * MOREBITS,
                (t - 1.0) / (t + 1.0),
            )
        } else {
            (0.0, 0.0, t)
        };
        let z = t * t;
        let p = (((P[0] * z + P[1]) * z + P[2]) * z + P[3]) * z + P[4];
        let q = ((((z + Q[0]) * z + Q[1]) * z + Q[2]) * z + Q[3]) * z + Q[4];
        base + (t * (z * p / q) + t + more)
    };
    if !(y.is_finite() && x.is_finite()) {
        return y.atan2(x);
    }
    if x > 0.0 {
        atan_pos(y / x)
    } else if x < 0.0 {
        std::f64::consts::PI - atan_pos(y / -x)
    } else if y > 0.0 {
        std::f64::consts::FRAC_PI_2
    } else {
        0.0
    }
}

/// Lambert's form factor from a differential area at `x` with unit normal
/// `n` to a planar polygon, clipped to the half-space in front of `x`. The
/// polygon's own orientation is not checked (see
/// [`point_to_polygon_front`]).
pub fn point_to_polygon(x: DVec3, n: DVec3, poly: &[DVec3]) -> f64 {
    let mut clipped = [DVec3::ZERO; 12];
    let mut len = 0usize;
    let k = poly.len();
    if !(3..=10).contains(&k) {
        return 0.0;
    }
    for i in 0..k {
        let a = poly[i];
        let b = poly[(i + 1) % k];
        let da = n.dot(a - x);
        let db = n.dot(b - x);
        if da >= 0.0 {
            clipped[len] = a;
            len += 1;
        }
        if (da >= 0.0) != (db >= 0.0) {
            clipped[len] = a + (b - a) * (da / (da - db));
            len += 1;
        }
    }
    if len < 3 {
        return 0.0;
    }
    let mut sum = 0.0;
    for i in 0..len {
        let r0 = clipped[i] - x;
        let r1 = clipped[(i + 1) % len] - x;
        let c = r0.cross(r1);
        let cl = c.length();
        if cl > 0.0 {
            let beta = atan2_nonneg(cl, r0.dot(r1));
            sum += beta * n.dot(c) / cl;
        }
    }
    (sum.abs() / (2.0 * PI)).min(1.0)
}

/// [`point_to_polygon`] for a one-sided polygon with front normal `front`:
/// zero unless `x` lies strictly in front of it.
pub fn point_to_polygon_front(x: DVec3, n: DVec3, poly: &[DVec3], front: DVec3) -> f64 {
    if front.dot(x - poly[0]) <= 0.0 {
        return 0.0;
    }
    point_to_polygon(x, n, poly)
}

fn lambert_sum(x: DVec3, n: DVec3, polys: &[Poly]) -> f64 {
    polys
        .iter()
        .map(|p| point_to_polygon_front(x, n, &p.v[..p.len], p.n))
        .sum::<f64>()
        .min(1.0)
}

/// The part of planar integration domains in front of the common plane of
/// `polys` (when they are coplanar): only there is Lambert's integrand
/// non-zero, and it has a kink along that plane that the cubature would
/// otherwise have to resolve. Domains entirely in front are kept as they
/// are, domains entirely behind are dropped, the others are clipped and
/// fanned into triangles. Curved domains are kept unchanged.
fn clip_to_plane<'a>(doms: &[QDom<'a>], polys: &[Poly]) -> Vec<QDom<'a>> {
    let Some(first) = polys.first() else {
        return Vec::new();
    };
    let (n, p0) = (first.n, first.v[0]);
    if !coplanar_polys(polys) {
        return doms.to_vec();
    }
    let mut out = Vec::with_capacity(doms.len());
    for d in doms {
        let Some((corners, normal)) = planar_corners(d) else {
            out.push(*d);
            continue;
        };
        let dist: Vec<f64> = corners.iter().map(|c| n.dot(*c - p0)).collect();
        if dist.iter().all(|&x| x >= 0.0) {
            out.push(*d);
            continue;
        }
        if dist.iter().all(|&x| x <= 0.0) {
            continue;
        }
        let k = corners.len();
        let mut poly = Vec::with_capacity(k + 1);
        for i in 0..k {
            let (a, b) = (corners[i], corners[(i + 1) % k]);
            let (da, db) = (dist[i], dist[(i + 1) % k]);
            if da >= 0.0 {
                poly.push(a);
            }
            if (da >= 0.0) != (db >= 0.0) {
                poly.push(a + (b - a) * (da / (da - db)));
            }
        }
        for i in 1..poly.len().saturating_sub(1) {
            let t = [poly[0], poly[i], poly[i + 1]];
            if triangle_area(t[0], t[1], t[2]) > 0.0 {
                out.push(QDom::Tri { v: t, n: normal });
            }
        }
    }
    out
}

/// The corners and normal of a planar polygonal domain (a uv rectangle of
/// a planar quad, or a triangle); `None` for curved domains.
fn planar_corners(d: &QDom<'_>) -> Option<(Vec<DVec3>, DVec3)> {
    match *d {
        QDom::Rect { patch, min, max, s }
            if patch.is_planar() && matches!(patch, Patch::Quad { .. }) =>
        {
            Some((
                [min, DVec2::new(max.x, min.y), max, DVec2::new(min.x, max.y)]
                    .iter()
                    .map(|&uv| patch.eval(uv).p)
                    .collect(),
                s * patch.eval(min).n,
            ))
        }
        QDom::Tri { v, n } => Some((v.to_vec(), n)),
        QDom::Rect { .. } => None,
    }
}

/// True when some planar domain has corners strictly on both sides of
/// some polygon's plane (then Lambert's integrand has a kink inside it).
fn any_domain_straddles(doms: &[QDom<'_>], polys: &[Poly]) -> bool {
    let corners: Vec<Vec<DVec3>> = doms
        .iter()
        .filter_map(|d| planar_corners(d).map(|(c, _)| c))
        .collect();
    polys.iter().any(|p| {
        let (n, p0) = (p.n, p.v[0]);
        corners.iter().any(|c| {
            let (mut front, mut back) = (false, false);
            for x in c {
                let d = n.dot(*x - p0);
                front |= d > 0.0;
                back |= d < 0.0;
            }
            front && back
        })
    })
}

/// True when all the polygons lie in one plane and face the same way.
fn coplanar_polys(polys: &[Poly]) -> bool {
    let Some(first) = polys.first() else {
        return true;
    };
    let (n, p0) = (first.n, first.v[0]);
    let scale = polys
        .iter()
        .flat_map(|p| p.v[..p.len].iter())
        .map(|v| (*v - p0).length())
        .fold(0.0, f64::max);
    polys.iter().all(|p| {
        p.n.dot(n) > 1.0 - 1e-12
            && p.v[..p.len]
                .iter()
                .all(|v| n.dot(*v - p0).abs() <= 1e-12 * scale.max(1e-300))
    })
}

/// ∫ over `doms` of Lambert's form factor to `polys` (paper notation:
/// A_x F(dA_x → polys)), with its error, and the min and max of the point
/// values F(x → polys) seen. Lambert's integrand vanishes behind each
/// polygon's plane, with a kink there: the domains are clipped to the
/// front half-space of each plane before integrating, one polygon at a
/// time when the polygons are not coplanar (a non-planar cluster), so that
/// a sliver of a domain in front of one piece is integrated rather than
/// missed by every rule point.
fn integrate_lambert(
    doms: &[QDom<'_>],
    polys: &[Poly],
    rel_tol: f64,
    depth: u32,
) -> (f64, f64, f64, f64) {
    let mut lo = f64::INFINITY;
    let mut hi = f64::NEG_INFINITY;
    // One integration of the whole set when no piece's plane cuts a
    // domain (the integrand is then smooth on every domain, or the pieces
    // are coplanar and the domains are clipped to their common plane).
    if coplanar_polys(polys) || !any_domain_straddles(doms, polys) {
        let mut f = |x: DVec3, n: DVec3| {
            let g = lambert_sum(x, n, polys);
            lo = lo.min(g);
            hi = hi.max(g);
            (g, 0.0)
        };
        let doms = clip_to_plane(doms, polys);
        if doms.is_empty() {
            return (0.0, 0.0, lo, hi);
        }
        let (v, e) = integrate(&doms, &mut f, rel_tol, depth);
        return (v, e, lo, hi);
    }
    // The spread of the whole cluster's point values, at the rule points
    // of the unclipped domains.
    for d in doms {
        for (x, n, _) in d.points() {
            let g = lambert_sum(x, n, polys);
            lo = lo.min(g);
            hi = hi.max(g);
        }
    }
    let (mut v, mut e) = (0.0, 0.0);
    for p in polys {
        let one = std::slice::from_ref(p);
        let clipped = clip_to_plane(doms, one);
        if clipped.is_empty() {
            continue;
        }
        let mut f = |x: DVec3, n: DVec3| (lambert_sum(x, n, one), 0.0);
        let (pv, pe) = integrate(&clipped, &mut f, rel_tol, depth);
        v += pv;
        e += pe;
    }
    (v, e, lo, hi)
}

/// The point-to-point kernel cos θ_x cos θ_y / (π r²), one-sided.
#[inline]
fn kernel(x: DVec3, nx: DVec3, y: DVec3, ny: DVec3) -> f64 {
    let d = y - x;
    let r2 = d.length_squared();
    let cx = nx.dot(d);
    let cy = -ny.dot(d);
    if cx <= 0.0 || cy <= 0.0 || r2 == 0.0 {
        return 0.0;
    }
    cx * cy / (PI * r2 * r2)
}

fn hash2(a: u32, b: u32) -> u32 {
    let mut h = (a as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15)
        ^ (b as u64).wrapping_mul(0xC2B2_AE3D_27D4_EB4F);
    h ^= h >> 31;
    h = h.wrapping_mul(0xBF58_476D_1CE4_E5B9);
    (h ^ (h >> 29)) as u32
}

/// Stratified 2-D sample `k` (Owen-scrambled Sobol), dimensions `dim`, `dim+1`.
pub(crate) fn sobol2(k: u32, dim: u32, seed: u32) -> DVec2 {
    DVec2::new(
        sobol_burley::sample(k, dim, seed) as f64,
        sobol_burley::sample(k, dim + 1, seed) as f64,
    )
}

pub(crate) fn seed_of(a: ElementId, b: ElementId) -> u32 {
    hash2(a.0, b.0)
}

impl SceneGeometry {
    /// True if both elements are planar and lie in the same plane (then no
    /// light passes between them, whatever the sides).
    pub(crate) fn coplanar(&self, a: ElementId, b: ElementId) -> bool {
        let (ea, eb) = (&self.elements[a.index()], &self.elements[b.index()]);
        if !(ea.planar && eb.planar) {
            return false;
        }
        if a == b {
            return true;
        }
        let scale = ea
            .bounds
            .diagonal()
            .length()
            .max(eb.bounds.diagonal().length())
            + ea.centre
                .abs()
                .max_element()
                .max(eb.centre.abs().max_element());
        // Symmetric in (a, b), so that F_ab and F_ba are both zero or both
        // computed (reciprocity): each centre lies in the other's plane.
        let d = eb.centre - ea.centre;
        ea.normal.dot(eb.normal).abs() > 1.0 - 1e-12
            && ea.normal.dot(d).abs() <= 1e-12 * scale
            && eb.normal.dot(d).abs() <= 1e-12 * scale
    }

    /// The element as polygons (fronts on side `s` = ±1), if it is polygonal.
    pub(crate) fn element_polygons(&self, id: ElementId, s: f64) -> Option<Vec<Poly>> {
        let e = &self.elements[id.index()];
        match (e.domain, &self.surfaces[e.surface.index()].geom) {
            (ElementDomain::Rect { min, max }, SurfaceGeom::Patch(patch))
                if matches!(patch.as_ref(), Patch::Quad { .. }) =>
            {
                let normal = patch.eval(DVec2::ZERO).n;
                let v = [min, DVec2::new(max.x, min.y), max, DVec2::new(min.x, max.y)]
                    .map(|uv| patch.eval(uv).p);
                Some(vec![Poly {
                    v,
                    len: 4,
                    n: s * normal,
                }])
            }
            (ElementDomain::Cluster { count, .. }, SurfaceGeom::Chart { mesh })
                if count as usize <= MAX_POLYGON_PIECES =>
            {
                let m = &self.meshes[*mesh as usize];
                Some(
                    self.element_pieces(id)
                        .iter()
                        .map(|p| {
                            let [a, b, c] = p.corners(m);
                            Poly {
                                v: [a, b, c, c],
                                len: 3,
                                n: s * m.tri_normal[p.triangle as usize],
                            }
                        })
                        .collect(),
                )
            }
            _ => None,
        }
    }

    /// The element as integration domains (normals on side `s` = ±1), unless
    /// it is a large cluster.
    pub(crate) fn element_domains(&self, id: ElementId, s: f64) -> Option<Vec<QDom<'_>>> {
        let e = &self.elements[id.index()];
        match (e.domain, &self.surfaces[e.surface.index()].geom) {
            (ElementDomain::Rect { min, max }, SurfaceGeom::Patch(patch)) => {
                // Disk elements spanning more than a quarter turn are
                // integrated as quarter-turn sectors: a 3-point rule over a
                // whole revolution is poor.
                let turns = if matches!(patch.as_ref(), Patch::Disk { .. }) {
                    ((max.y - min.y) / 0.25 - 1e-9).ceil().max(1.0) as usize
                } else {
                    1
                };
                let dv = (max.y - min.y) / turns as f64;
                Some(
                    (0..turns)
                        .map(|k| QDom::Rect {
                            patch,
                            min: DVec2::new(min.x, min.y + k as f64 * dv),
                            max: DVec2::new(
                                max.x,
                                if k + 1 == turns {
                                    max.y
                                } else {
                                    min.y + (k + 1) as f64 * dv
                                },
                            ),
                            s,
                        })
                        .collect(),
                )
            }
            (ElementDomain::Cluster { count, .. }, SurfaceGeom::Chart { mesh })
                if count as usize <= MAX_POLYGON_PIECES =>
            {
                let m = &self.meshes[*mesh as usize];
                Some(
                    self.element_pieces(id)
                        .iter()
                        .map(|p| QDom::Tri {
                            v: p.corners(m),
                            n: s * m.tri_normal[p.triangle as usize],
                        })
                        .collect(),
                )
            }
            _ => None,
        }
    }

    /// Unoccluded form factor F_{from→to} with default accuracy
    /// ([`FormFactorOptions::default`]).
    pub fn form_factor(&self, from: ElementId, to: ElementId) -> FormFactor {
        self.form_factor_with(from, to, &FormFactorOptions::default())
    }

    /// Many form factors at once, in parallel (rayon).
    pub fn form_factor_batch(
        &self,
        pairs: &[(ElementId, ElementId)],
        opts: &FormFactorOptions,
    ) -> Vec<FormFactor> {
        pairs
            .par_iter()
            .map(|&(a, b)| self.form_factor_with(a, b, opts))
            .collect()
    }

    /// Unoccluded form factor F_{from→to} to the given accuracy (module docs).
    pub fn form_factor_with(
        &self,
        from: ElementId,
        to: ElementId,
        opts: &FormFactorOptions,
    ) -> FormFactor {
        self.form_factor_sided(from, Side::Front, to, Side::Front, opts)
    }

    /// Unoccluded form factor from one side of `from` to one side of `to`
    /// (for two-sided materials: light leaving the back of an element, or
    /// arriving on its back), with the same method and accuracy as
    /// [`SceneGeometry::form_factor_with`].
    pub fn form_factor_sided(
        &self,
        from: ElementId,
        from_side: Side,
        to: ElementId,
        to_side: Side,
        opts: &FormFactorOptions,
    ) -> FormFactor {
        let (sf, st) = (from_side.sign(), to_side.sign());
        let a_from = self.elements[from.index()].area;
        let a_to = self.elements[to.index()].area;
        if self.coplanar(from, to) {
            return FormFactor::default();
        }
        let depth = opts.max_depth;
        let tol = opts.rel_tol.max(1e-14);
        let to_polys = self.element_polygons(to, st);
        let from_doms = self.element_domains(from, sf);
        let result = |v: f64, e: f64, lo: f64, hi: f64| FormFactor {
            value: v.max(0.0),
            error: e,
            spread: if hi >= lo { hi - lo } else { 0.0 },
        };
        if let (Some(polys), Some(doms)) = (&to_polys, &from_doms) {
            let (v, e, lo, hi) = integrate_lambert(doms, polys, tol, depth);
            return result(v / a_from, e / a_from, lo, hi);
        }
        let from_polys = self.element_polygons(from, sf);
        let to_doms = self.element_domains(to, st);
        let ratio = a_to / a_from;
        if let (Some(polys), Some(doms)) = (&from_polys, &to_doms) {
            let (v, e, lo, hi) = integrate_lambert(doms, polys, tol, depth);
            return result(v / a_from, e / a_from, lo * ratio, hi * ratio);
        }
        if let (Some(fd), Some(td)) = (&from_doms, &to_doms) {
            let (v, e, lo, hi) = integrate_pairs(fd, td, tol, depth + 2);
            return result(v / a_from, e / a_from, lo, hi);
        }
        let mut lo = f64::INFINITY;
        let mut hi = f64::NEG_INFINITY;
        // Sampled estimate (large clusters): stratified points on the
        // integrated side; one point per piece when the cluster has at least
        // `samples` pieces.
        let seed = seed_of(from, to);
        let (values, weights): (Vec<f64>, Vec<f64>) = if let Some(polys) = &to_polys {
            self.stratified_points(from, seed, 0, opts.samples, sf)
                .into_iter()
                .map(|(x, n, w)| (lambert_sum(x, n, polys), w))
                .unzip()
        } else if let Some(polys) = &from_polys {
            self.stratified_points(to, seed, 2, opts.samples, st)
                .into_iter()
                .map(|(y, m, w)| (lambert_sum(y, m, polys) * a_to / a_from, w * a_from / a_to))
                .unzip()
        } else {
            let xs = self.stratified_points(from, seed, 0, opts.samples, sf);
            let n = xs.len() as u32;
            xs.into_iter()
                .enumerate()
                .map(|(k, (x, nx, w))| {
                    let y = self.sample_element(to, sobol2(k as u32 % n, 2, seed));
                    let g = if y.pdf_area > 0.0 {
                        (kernel(x, nx, y.point, st * y.normal) / y.pdf_area).min(1.0)
                    } else {
                        0.0
                    };
                    (g, w)
                })
                .unzip()
        };
        // F = Σ w g / A_from; variance by collapsing neighbouring strata in
        // pairs (Morton or Sobol neighbours): Var ≈ Σ (y_a − y_b)², y = w g.
        let total: f64 = values.iter().zip(&weights).map(|(g, w)| g * w).sum();
        let var: f64 = values
            .chunks(2)
            .zip(weights.chunks(2))
            .map(|(g, w)| {
                if g.len() == 2 {
                    (g[0] * w[0] - g[1] * w[1]).powi(2)
                } else {
                    0.0
                }
            })
            .sum();
        for &g in &values {
            lo = lo.min(g);
            hi = hi.max(g);
        }
        result(total / a_from, var.sqrt() / a_from, lo, hi)
    }

    /// Stratified points of an element with weights summing (in
    /// expectation) to its area: for a cluster of at most 4096 pieces,
    /// ⌈samples / pieces⌉ (at least one) Sobol points in every piece, each
    /// weighted by its share of the piece's area; otherwise `samples` Sobol
    /// points mapped by `sample_element` with weight 1/(pdf · n).
    fn stratified_points(
        &self,
        id: ElementId,
        seed: u32,
        dim: u32,
        samples: u32,
        sign: f64,
    ) -> Vec<(DVec3, DVec3, f64)> {
        let samples = samples.clamp(4, 1 << 16);
        let e = &self.elements[id.index()];
        if let (ElementDomain::Cluster { count, .. }, SurfaceGeom::Chart { mesh }) =
            (e.domain, &self.surfaces[e.surface.index()].geom)
            && count <= 4096
        {
            let m = &self.meshes[*mesh as usize];
            let per_piece = samples.div_ceil(count).max(1);
            let mut out = Vec::with_capacity((count * per_piece) as usize);
            for (k, p) in self.element_pieces(id).iter().enumerate() {
                let a = m.tri_area[p.triangle as usize] * p.area_fraction() / per_piece as f64;
                let n = sign * m.tri_normal[p.triangle as usize];
                let piece_seed = seed ^ (k as u32).wrapping_mul(0x9E37_79B9);
                for j in 0..per_piece {
                    let u = if per_piece == 1 {
                        sobol2(k as u32, dim, seed)
                    } else {
                        sobol2(j, dim, piece_seed)
                    };
                    let l = crate::sampling::square_to_triangle(u);
                    let b = l[0] * p.bary[0] + l[1] * p.bary[1] + l[2] * p.bary[2];
                    out.push((m.point(p.triangle, b), n, a));
                }
            }
            return out;
        }
        (0..samples)
            .map(|k| {
                let s = self.sample_element(id, sobol2(k, dim, seed));
                let w = if s.pdf_area > 0.0 {
                    1.0 / (s.pdf_area * samples as f64)
                } else {
                    0.0
                };
                (s.point, sign * s.normal, w)
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::atan2_nonneg;

    #[test]
    fn fast_atan2_matches_libm() {
        let mut worst: f64 = 0.0;
        let mut state = 12345u64;
        let mut rnd = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        for k in 0..2_000_000i32 {
            let scale = 10f64.powi(k % 41 - 20);
            let y = rnd() * scale;
            let x = (2.0 * rnd() - 1.0) * 10f64.powi(k % 37 - 18);
            let (a, b) = (atan2_nonneg(y, x), y.atan2(x));
            worst = worst.max((a - b).abs());
        }
        for (y, x) in [
            (0.0, 1.0),
            (0.0, -1.0),
            (1.0, 0.0),
            (0.0, 0.0),
            (1e-300, 1.0),
            (1.0, 1e-300),
            (1.0, -1e-300),
            (f64::MAX, 1.0),
        ] {
            assert!(
                (atan2_nonneg(y, x) - y.atan2(x)).abs() <= 4.0 * f64::EPSILON,
                "{y} {x}"
            );
        }
        assert!(worst <= 4.0 * f64::EPSILON, "worst {worst:e}");
    }
}
