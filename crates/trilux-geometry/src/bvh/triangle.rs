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
}

impl RayPre {
    pub(crate) fn new(o: DVec3, d: DVec3) -> RayPre {
        let a = d.abs();
        let kz = if a.x >= a.y && a.x >= a.z {
            0
        } else if a.y >= a.z {
            1
        } else {
            2
        };
        let mut kx = (kz + 1) % 3;
        let mut ky = (kx + 1) % 3;
        if d[kz] < 0.0 {
            std::mem::swap(&mut kx, &mut ky);
        }
        RayPre {
            o,
            d,
            k: [kx, ky, kz],
            s: [d[kx] / d[kz], d[ky] / d[kz], 1.0 / d[kz]],
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
    let a = v[0] - r.o;
    let b = v[1] - r.o;
    let c = v[2] - r.o;
    let ax = a[kx] - sx * a[kz];
    let ay = a[ky] - sy * a[kz];
    let bx = b[kx] - sx * b[kz];
    let by = b[ky] - sy * b[kz];
    let cx = c[kx] - sx * c[kz];
    let cy = c[ky] - sy * c[kz];
    let u = cx * by - cy * bx;
    let vv = ax * cy - ay * cx;
    let w = bx * ay - by * ax;
    if (u < 0.0 || vv < 0.0 || w < 0.0) && (u > 0.0 || vv > 0.0 || w > 0.0) {
        return None;
    }
    let det = u + vv + w;
    if det == 0.0 {
        return None;
    }
    let t = (u * sz * a[kz] + vv * sz * b[kz] + w * sz * c[kz]) / det;
    if !(t > tmin && t < tmax) {
        return None;
    }
    Some((t, DVec2::new(vv / det, w / det)))
}
