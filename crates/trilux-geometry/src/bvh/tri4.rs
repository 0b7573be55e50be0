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

    /// Bit `i` set unless lane `i` is certainly missed by the f64 test
    /// (module docs).
    #[inline(always)]
    pub(crate) fn candidates(&self, r: &Ray4) -> u32 {
        let [kx, ky, kz] = r.k;
        let project = |v: &[Vec4; 3]| {
            let z = v[kz] - r.o[2];
            let x = (v[kx] - r.o[0]) - r.sx * z;
            let y = (v[ky] - r.o[1]) - r.sy * z;
            (x, y, x.abs() + y.abs())
        };
        let (ax, ay, sa) = project(&self.v[0]);
        let (bx, by, sb) = project(&self.v[1]);
        let (cx, cy, sc) = project(&self.v[2]);
        let u = cx * by - cy * bx;
        let v = ax * cy - ay * cx;
        let w = bx * ay - by * ax;
        let s = sa.max(sb).max(sc);
        let e = (r.e1 * (s + r.e1) + Vec4::splat(U) * s * s) * Vec4::splat(2.0 * (1.0 + 16.0 * U));
        let ne = -e;
        let neg = u.cmplt(ne) | v.cmplt(ne) | w.cmplt(ne);
        let pos = u.cmpgt(e) | v.cmpgt(e) | w.cmpgt(e);
        !(neg & pos).bitmask() & 0xf
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
    /// Bound on the error of a sheared coordinate, 10uR.
    e1: Vec4,
}

impl Ray4 {
    /// The filter's constants for the f64 test's ray `pre` in a scene of
    /// largest absolute coordinate `extent`.
    pub(crate) fn new(pre: &RayPre, extent: f64) -> Ray4 {
        let [kx, ky, kz] = pre.k;
        let o = pre.o;
        let r = o.abs().max_element() + extent;
        // Rounded up to f32, so that the bound stays a bound.
        let e1 = (10.0 * f64::from(U) * r) as f32;
        Ray4 {
            o: [o[kx], o[ky], o[kz]].map(|c| Vec4::splat(c as f32)),
            sx: Vec4::splat(pre.s[0] as f32),
            sy: Vec4::splat(pre.s[1] as f32),
            k: pre.k,
            e1: Vec4::splat(e1.next_up()),
        }
    }
}
