//! Four triangles at once in f32: the watertight test of Woop, Benthin and
//! Wald (JCGT 2013) on four SIMD lanes, used as a *conservative filter*.
//! It rules out a triangle only when the f64 test of [`super::triangle`]
//! would certainly miss it too; every lane it keeps is decided by that f64
//! test, which alone gives t and the barycentrics. Results are therefore
//! exactly those of the f64 test (same hits, same watertightness, same
//! self-intersection rule), at the cost of an f32 test for almost every
//! triangle the traversal reaches and an f64 test for the few near the ray.
//!
//! # Error bound
//!
//! Let u = 2⁻²⁴ (f32 unit roundoff) and R = |o|∞ + extent (the scene's
//! largest absolute coordinate bounds every vertex). Vertices V and origin O
//! are rounded to f32 (|ΔV| ≤ u|v|, |ΔO| ≤ u|o|) and the shear constants
//! s_x, s_y (|s| ≤ 1, computed in f64 as the f64 test does) are rounded too
//! (|Δs| ≤ u). Then, to first order in u:
//!
//! - a translated coordinate A = V − O is off by at most u|v| + u|o| +
//!   u|A| ≤ 2uR;
//! - a sheared coordinate a_x = A_kx − s_x A_kz (|a_x| ≤ 2R) is off by at most
//!   2uR + uR + 2uR + uR + 2uR = 8uR, and so is a_y; the filter uses
//!   e₁ = 10uR;
//! - an edge function U = c_x b_y − c_y b_x is off by at most
//!   e₁ (S_b + S_c) + 2e₁² + 2u S_b S_c, with S_p = |p_x| + |p_y|, and all
//!   three by at most E = 2 (e₁ (S + e₁) + u S²)(1 + 16u), S = max S_p (the
//!   factor covers the rounding of E itself and the higher-order terms).
//!
//! The f64 test's own error is below 10⁻¹³ R² < 2e₁² ≤ E. A lane is ruled
//! out only if one edge function is below −E and another above +E: the
//! exact edge functions, and the f64 ones, then have strictly mixed signs,
//! and the f64 test misses. NaN or infinite lanes (analytic primitives are
//! stored as NaN, overflowing coordinates become infinite) are never ruled
//! out, since every comparison with NaN is false.

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
