//! The watertight ray–triangle test of Woop, Benthin and Wald ("Watertight
//! Ray/Triangle Intersection", JCGT 2(1), 2013) in f64: the ray is
//! translated to the origin, permuted so that its largest direction
//! component is z, and sheared onto +z; the triangle's three 2-D edge
//! functions then decide the hit. Edge values of exactly zero count as
//! inside, and the edge shared by two triangles gets the same value (up to
//! sign) from both, so a ray through an edge or a vertex hits at least one
//! of the triangles that share it.
//!
//! This f64 test gives every answer ([`super::tri4`] only rules out, in f32,
//! the triangles this test would certainly miss).

use glam::{DVec2, DVec3};

/// Ray data precomputed for the watertight triangle test.
#[derive(Clone, Copy)]
pub(crate) struct RayPre {
    pub o: DVec3,
    pub d: DVec3,
    /// Axis permutation: z is the largest direction component.
    pub k: [usize; 3],
    /// Shear constants (d_x / d_z, d_y / d_z, 1 / d_z) after permutation.
    pub s: [f64; 3],
    /// The origin, permuted.
    pub ok: [f64; 3],
}

impl RayPre {
    #[inline(always)]
    pub(crate) fn new(o: DVec3, d: DVec3) -> RayPre {
        // k_z: the largest |d| component (the first of equals); k_x, k_y
        // the next two, swapped when d_kz < 0 (winding preserved). Selected
        // without branches: ray directions are random.
        const AXES: [[usize; 3]; 6] = [
            [1, 2, 0],
            [2, 0, 1],
            [0, 1, 2],
            [2, 1, 0],
            [0, 2, 1],
            [1, 0, 2],
        ];
        let a = d.abs();
        let is_x = (a.x >= a.y) & (a.x >= a.z);
        let is_y = a.y >= a.z;
        let kz = usize::from(!is_x) * (1 + usize::from(!is_y));
        let k = AXES[kz + 3 * usize::from(d[kz] < 0.0)];
        let [kx, ky, kz] = k;
        RayPre {
            o,
            d,
            k,
            s: [d[kx] / d[kz], d[ky] / d[kz], 1.0 / d[kz]],
            ok: [o[kx], o[ky], o[kz]],
        }
    }
}

/// Watertight ray–triangle test (Woop et al. 2013) in f64. Returns t and the
/// barycentrics (b1, b2) of vertices 1 and 2.
#[inline]
pub(crate) fn intersect_triangle(
    r: &RayPre,
    v: &[DVec3; 3],
    tmin: f64,
    tmax: f64,
) -> Option<(f64, DVec2)> {
    let [kx, ky, kz] = r.k;
    let [sx, sy, sz] = r.s;
    let [ox, oy, oz] = r.ok;
    // Translated, permuted and sheared vertices (straight from the vertex
    // components: no permuted copy, so nothing goes through the stack).
    let project = |p: &DVec3| {
        let z = p[kz] - oz;
        ((p[kx] - ox) - sx * z, (p[ky] - oy) - sy * z, z)
    };
    let (ax, ay, az) = project(&v[0]);
    let (bx, by, bz) = project(&v[1]);
    let (cx, cy, cz) = project(&v[2]);
    let u = cx * by - cy * bx;
    let vv = ax * cy - ay * cx;
    let w = bx * ay - by * ax;
    // Non-short-circuit: one branch, not six unpredictable ones.
    let neg = (u < 0.0) | (vv < 0.0) | (w < 0.0);
    let pos = (u > 0.0) | (vv > 0.0) | (w > 0.0);
    if neg & pos {
        return None;
    }
    let det = u + vv + w;
    if det == 0.0 {
        return None;
    }
    let num = u * sz * az + vv * sz * bz + w * sz * cz;
    // Most misses here are far outside (tmin, tmax) (the triangle a ray
    // starts on, triangles behind it or beyond the closest hit so far):
    // decide those without the division, with a margin of 10⁻¹² (far
    // above the products' rounding), so that the decision is the one the
    // quotient below would give.
    let (n, d) = if det > 0.0 { (num, det) } else { (-num, -det) };
    if n < tmin * d * (1.0 - 1e-12) || n > tmax * d * (1.0 + 1e-12) {
        return None;
    }
    let t = num / det;
    if !(t > tmin && t < tmax) {
        return None;
    }
    Some((t, DVec2::new(vv / det, w / det)))
}
