//! Four triangles at once in f32: the watertight test of Woop, Benthin and
//! Wald (JCGT 2013) on four SIMD lanes, used as a *conservative filter* for
//! the f64 test of [`super::triangle`]. It rules a lane out only when the
//! f64 test would certainly miss it too, and calls a lane hit only when the
//! f64 test would certainly hit it; every other lane is left to the f64
//! test, which alone gives t and the barycentric coordinates. Answers are
//! therefore exactly the f64 test's (same hits, same watertightness, same
//! self-intersection rule), while the f64 test runs only for the few
//! triangles near the ray's path, and an occlusion query usually needs none.
//!
//! # Error bounds
//!
//! Let u = 2⁻²⁴ (f32 unit roundoff) and R = |o|∞ + extent (the scene's
//! largest absolute coordinate bounds every vertex). Vertices V and origin O
//! are rounded to f32 (|ΔV| ≤ u|v|, |ΔO| ≤ u|o|), and so are the shear
//! constants s_x, s_y (|s| ≤ 1) and s_z = 1/d_z, computed in f64 as the f64
//! test does (|Δs| ≤ u|s|). To first order in u (the margins below cover
//! the higher-order terms and the rounding of the bounds themselves):
//!
//! - a translated coordinate A = V − O is off by at most u|v| + u|o| +
//!   u|A| ≤ 2uR; the filter uses e_z = 3uR;
//! - a sheared coordinate a_x = A_kx − s_x A_kz (|a_x| ≤ 2R) is off by at
//!   most 2uR + uR + 2uR + uR + 2uR = 8uR, and so is a_y; the filter uses
//!   e₁ = 10uR;
//! - an edge function U = c_x b_y − c_y b_x is off by at most
//!   e₁ (S_b + S_c) + 2e₁² + 2u S_b S_c, with S_p = |p_x| + |p_y|; all
//!   three by at most E = 2 (e₁ (S + e₁) + u S²)(1 + 16u), S = max S_p;
//! - det = U + V + W is off by at most Δdet = (3E + 2uΣ)(1 + 8u), with
//!   Σ = |U| + |V| + |W|; T = U a_z + V b_z + W c_z by at most
//!   ΔT = (Σ (e_z + 3uZ) + 3E (Z + e_z))(1 + 8u), Z = max |z|; and
//!   N = s_z T by at most ΔN = |s_z| (ΔT + 3u|T|)(1 + 8u).
//!
//! The f64 test's own error is below 10⁻¹³ R², under every bound here. A
//! lane is **ruled out** if one edge function is below −E and another above
//! +E (the exact and the f64 edge functions then have strictly mixed signs),
//! or if det's sign is certain (|det| > Δdet) and t = N / det certainly lies
//! outside (tmin, tmax), each end rounded outwards to f32 and each product
//! given 4u more. A lane is **certainly hit** if all three edge functions
//! exceed E in magnitude with one sign and t certainly lies inside.
//!
//! NaN or infinite lanes (analytic primitives are stored as NaN,
//! overflowing coordinates become infinite) are never decided, since every
//! comparison with NaN is false; products whose underflow would shrink a
//! bound get 10⁻³⁶ added. [`super::Bvh`] uses this filter only for scenes
//! whose extent lies in [10⁻⁶, 10¹⁵], where no bound underflows.

use glam::{DVec3, Vec4};

use super::triangle::RayPre;

/// f32 unit roundoff, 2⁻²⁴.
const U: f32 = f32::EPSILON / 2.0;
/// Above any product an underflow can lose (f32's smallest normal number
/// is 1.2·10⁻³⁸).
const TINY: f32 = 1e-36;

/// Four triangles in f32, structure of arrays: `v[i][axis]` holds the
/// `axis` coordinate of vertex `i` of the four lanes (NaN for a lane that
/// is not a triangle).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Tri4 {
    pub v: [[Vec4; 3]; 3],
}

impl Tri4 {
    /// Lanes from up to four triangles; `None` lanes become NaN (never
    /// ruled out: the f64 test decides them).
    pub(crate) fn new(lanes: [Option<[DVec3; 3]>; 4]) -> Tri4 {
        let mut v = [[Vec4::NAN; 3]; 3];
        for (lane, tri) in lanes.iter().enumerate() {
            if let Some(tri) = tri {
                for (i, p) in tri.iter().enumerate() {
                    for axis in 0..3 {
                        v[i][axis][lane] = p[axis] as f32;
                    }
                }
            }
        }
        Tri4 { v }
    }

    /// What the f32 test decides for the four lanes within the ray
    /// interval `span` (module docs); from the edge functions alone unless
    /// `WITH_T`.
    #[inline(always)]
    pub(crate) fn classify<const WITH_T: bool>(&self, r: &Ray4, span: &Span4) -> Lanes {
        let [kx, ky, kz] = r.k;
        let project = |v: &[Vec4; 3]| {
            let z = v[kz] - r.o[2];
            let x = (v[kx] - r.o[0]) - r.sx * z;
            let y = (v[ky] - r.o[1]) - r.sy * z;
            (x, y, z, x.abs() + y.abs())
        };
        let (ax, ay, az, sa) = project(&self.v[0]);
        let (bx, by, bz, sb) = project(&self.v[1]);
        let (cx, cy, cz, sc) = project(&self.v[2]);
        let u = cx * by - cy * bx;
        let v = ax * cy - ay * cx;
        let w = bx * ay - by * ax;
        let s = sa.max(sb).max(sc);
        let e = (r.e1 * (s + r.e1) + Vec4::splat(U) * s * s) * Vec4::splat(2.0 * (1.0 + 16.0 * U));
        let ne = -e;
        let neg = u.cmplt(ne) | v.cmplt(ne) | w.cmplt(ne);
        let pos = u.cmpgt(e) | v.cmpgt(e) | w.cmpgt(e);
        let open = !(neg & pos).bitmask() & 0xf;
        if open == 0 || !WITH_T {
            return Lanes {
                test: open,
                hits: 0,
            };
        }
        // t = s_z T / det, bounded (module docs).
        let grow = Vec4::splat(1.0 + 8.0 * U);
        let det = u + v + w;
        let sum = u.abs() + v.abs() + w.abs();
        let zmax = az.abs().max(bz.abs()).max(cz.abs());
        let t = u * az + v * bz + w * cz;
        let dt = (sum * (r.ez + Vec4::splat(3.0 * U) * zmax)
            + Vec4::splat(3.0) * e * (zmax + r.ez))
            * grow;
        let ddet = (Vec4::splat(3.0) * e + Vec4::splat(2.0 * U) * sum) * grow;
        let sign = det.signum();
        let n = r.sz * t * sign;
        let dn = r.sz.abs() * (dt + Vec4::splat(3.0 * U) * t.abs()) * grow;
        let d = det.abs();
        let (d_lo, d_hi) = (d - ddet, d + ddet);
        let (n_lo, n_hi) = (n - dn, n + dn);
        // Products that must not come out too small get TINY added: an
        // underflow is rounded towards zero.
        let (below, above) = (Vec4::splat(1.0 - 4.0 * U), Vec4::splat(1.0 + 4.0 * U));
        let tiny = Vec4::splat(TINY);
        let decided = d_lo.cmpgt(Vec4::ZERO);
        let outside = decided
            & (n_hi.cmplt(span.min_lo * d_lo * below)
                | n_lo.cmpgt(span.max_hi * d_hi * above + tiny));
        let within = decided
            & n_lo.cmpgt(span.min_hi * d_hi * above + tiny)
            & n_hi.cmplt(span.max_lo * d_lo * below);
        let inside =
            (u.cmpgt(e) & v.cmpgt(e) & w.cmpgt(e)) | (u.cmplt(ne) & v.cmplt(ne) & w.cmplt(ne));
        Lanes {
            test: open & !outside.bitmask(),
            hits: (inside & within).bitmask() & open,
        }
    }
}

/// The f32 test's verdict on four lanes.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Lanes {
    /// Lanes the f64 test must decide (all others are missed).
    pub test: u32,
    /// Lanes certainly hit within the interval (a subset of `test`).
    pub hits: u32,
}

/// A ray interval (tmin, tmax) in f32, each end rounded down and up.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Span4 {
    min_lo: Vec4,
    min_hi: Vec4,
    max_lo: Vec4,
    max_hi: Vec4,
}

impl Span4 {
    pub(crate) fn new(tmin: f64, tmax: f64) -> Span4 {
        let (min_lo, min_hi) = bracket(tmin);
        let (max_lo, max_hi) = bracket(tmax);
        Span4 {
            min_lo: Vec4::splat(min_lo),
            min_hi: Vec4::splat(min_hi),
            max_lo: Vec4::splat(max_lo),
            max_hi: Vec4::splat(max_hi),
        }
    }

    /// The same interval with a new upper end.
    pub(crate) fn with_max(self, tmax: f64) -> Span4 {
        let (max_lo, max_hi) = bracket(tmax);
        Span4 {
            max_lo: Vec4::splat(max_lo),
            max_hi: Vec4::splat(max_hi),
            ..self
        }
    }
}

/// The f32 values just below and just above `x`.
fn bracket(x: f64) -> (f32, f32) {
    let f = x as f32;
    if f64::from(f) > x {
        (f.next_down(), f)
    } else if f64::from(f) < x {
        (f, f.next_up())
    } else {
        (f, f)
    }
}

/// Per-ray constants of the f32 filter.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Ray4 {
    /// Origin, permuted (x, y, z = the ray's k_x, k_y, k_z), splatted.
    o: [Vec4; 3],
    sx: Vec4,
    sy: Vec4,
    k: [usize; 3],
    sz: Vec4,
    /// Bound on the error of a sheared coordinate, 10uR.
    e1: Vec4,
    /// Bound on the error of a translated z coordinate, 3uR.
    ez: Vec4,
}

impl Ray4 {
    /// The filter's constants for the f64 test's ray `pre`; `r` ≥ |o|∞ +
    /// the scene's largest absolute coordinate.
    #[inline(always)]
    pub(crate) fn new(pre: &RayPre, r: f64) -> Ray4 {
        // Outside this range f32 would round s_z with more than u relative
        // error: t is then never decided in f32 (NaN compares false).
        let sz = if (1e-30..=1e30).contains(&pre.s[2].abs()) {
            pre.s[2] as f32
        } else {
            f32::NAN
        };
        // 10.0001 and 3.0001: rounding to f32 cannot take the bounds below
        // 10uR and 3uR.
        let u = f64::from(U);
        Ray4 {
            o: pre.ok.map(|c| Vec4::splat(c as f32)),
            sx: Vec4::splat(pre.s[0] as f32),
            sy: Vec4::splat(pre.s[1] as f32),
            sz: Vec4::splat(sz),
            k: pre.k,
            e1: Vec4::splat((10.0001 * u * r) as f32),
            ez: Vec4::splat((3.0001 * u * r) as f32),
        }
    }
}

#[cfg(test)]
mod tests {
    //! The f32 test against the f64 test it filters for, on rays through
    //! the shared vertex and the shared edges of triangle fans (where a
    //! filter that is not conservative would open a crack), and the f64
    //! test's own watertightness there.

    use super::*;
    use crate::bvh::triangle::intersect_triangle;
    use proptest::prelude::*;

    /// A closed fan of `n` triangles around `c` (consistent winding).
    fn fan(c: DVec3, rim: &[DVec3]) -> Vec<[DVec3; 3]> {
        (0..rim.len())
            .map(|i| [c, rim[i], rim[(i + 1) % rim.len()]])
            .collect()
    }

    /// Checks one ray against a fan: the f64 test hits some triangle when
    /// `inside`, every triangle it hits is kept by the f32 test, and every
    /// lane the f32 test finds certainly hit is hit.
    fn check(tris: &[[DVec3; 3]], o: DVec3, d: DVec3, tmin: f64, tmax: f64, inside: bool) {
        let pre = RayPre::new(o, d);
        let extent = tris
            .iter()
            .flatten()
            .fold(0.0f64, |m, p| m.max(p.abs().max_element()));
        let r4 = Ray4::new(&pre, o.abs().max_element() + extent);
        let span = Span4::new(tmin, tmax);
        let mut any = false;
        for group in tris.chunks(4) {
            let mut lanes = [None; 4];
            for (l, t) in group.iter().enumerate() {
                lanes[l] = Some(*t);
            }
            let valid = (1u32 << group.len()) - 1;
            let f32_with_t = Tri4::new(lanes).classify::<true>(&r4, &span);
            let f32_edges = Tri4::new(lanes).classify::<false>(&r4, &span);
            for (l, t) in group.iter().enumerate() {
                let hit = intersect_triangle(&pre, t, tmin, tmax).is_some();
                any |= hit;
                let bit = 1 << l;
                assert!(
                    !hit || f32_with_t.test & bit != 0,
                    "f32 (with t) ruled out a hit: {t:?} {o} {d}"
                );
                assert!(
                    !hit || f32_edges.test & bit != 0,
                    "f32 (edges) ruled out a hit: {t:?} {o} {d}"
                );
                assert!(
                    f32_with_t.hits & valid & bit == 0 || hit,
                    "f32 certain of a miss: {t:?} {o} {d}"
                );
            }
        }
        assert!(any || !inside, "leak through the fan at {o} + t {d}");
    }

    fn point(r: f64) -> impl Strategy<Value = DVec3> {
        (-r..r, -r..r, -r..r).prop_map(|(x, y, z)| DVec3::new(x, y, z))
    }

    /// A point on a grid of 1/64: exact in f32 and f64, so rays hit
    /// vertices and edges exactly.
    fn grid(r: i32) -> impl Strategy<Value = DVec3> {
        (-r..r, -r..r, -r..r).prop_map(|(x, y, z)| DVec3::new(x as f64, y as f64, z as f64) / 64.0)
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(400))]

        #[test]
        fn rays_through_fan_vertices_and_edges(
            c in point(3.0),
            rim in prop::collection::vec((0.2..2.0f64, 0.0..1.0f64), 6),
            axes in (point(1.0), point(1.0)),
            o in point(6.0),
            s in 0.0..1.0f64,
            far in 1.0..1e3f64,
            log_delta in -9.0..-4.0f64,
        ) {
            let delta = 10f64.powf(log_delta);
            let (a, b) = axes;
            let n = a.cross(b);
            prop_assume!(n.length() > 0.1);
            let u = a.normalize();
            let v = n.cross(u).normalize();
            // Rim points at increasing angles: a star-shaped closed fan.
            let rim: Vec<DVec3> = rim
                .iter()
                .enumerate()
                .map(|(i, &(r, jitter))| {
                    let phi = std::f64::consts::TAU * (i as f64 + 0.8 * jitter) / 6.0;
                    c + r * (phi.cos() * u + phi.sin() * v)
                })
                .collect();
            let tris = fan(c, &rim);
            prop_assume!((o - c).dot(n).abs() > 1e-3);
            // The shared vertex, points on the six shared edges, inside.
            let mut targets = vec![c];
            targets.extend(rim.iter().map(|&p| c + s * (p - c)));
            for target in targets {
                let d = target - o;
                check(&tris, o, d, 1e-9, f64::INFINITY, true);
                // The same ray as a segment ending just past the fan, and one
                // ending just before it (t-interval decisions).
                check(&tris, o, d, 1e-9, 1.0 + delta, true);
                check(&tris, o, d, 1e-9, 1.0 - delta, false);
                check(&tris, o, d, 1.0 - delta, f64::INFINITY, true);
                check(&tris, o, d, 1.0 + delta, f64::INFINITY, false);
                check(&tris, o, d * far, 1e-12, f64::INFINITY, true);
            }
        }

        #[test]
        fn grid_rays_through_grid_fans(
            c in grid(128),
            rim in prop::collection::vec(grid(128), 5),
            o in grid(512),
        ) {
            // Not necessarily planar or star-shaped: only the f32 test's
            // agreement with the f64 test is checked, on rays through the
            // exact shared vertex and the exact midpoints of the spokes.
            let tris = fan(c, &rim);
            let mut targets = vec![c];
            targets.extend(rim.iter().map(|&p| (c + p) * 0.5));
            for target in targets {
                let d = target - o;
                prop_assume!(d.length() > 0.0);
                check(&tris, o, d, 1e-9, f64::INFINITY, false);
                check(&tris, o, d, 1e-9, 1.0, false);
            }
        }
    }
}
