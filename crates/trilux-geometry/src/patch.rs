//! Parametric input surfaces: the map (u, v) ∈ [0,1]² → world space for
//! planar quads, disks, and the pieces of spheres and cylinders.
//!
//! Every piece lies on the true shape: a sphere piece is an exact
//! (φ, θ) rectangle of the (possibly non-uniformly scaled) sphere, a cylinder
//! piece an exact (φ, z) rectangle of the tube. Non-uniform scale and shear
//! are supported everywhere (a sphere becomes an ellipsoid, a disk an
//! ellipse): shapes are evaluated in object space and mapped by the affine
//! `world_from_object`, which is exact.

use std::f64::consts::{FRAC_PI_2, TAU};

use glam::{DVec2, DVec3};

use crate::quadrature::integrate_rect;
use crate::transform::Affine;

/// A parametric piece of a shape.
#[derive(Clone, Debug)]
pub(crate) enum Patch {
    /// Planar bilinear quad with corners p00, p10, p11, p01 (so the image of
    /// a uv rectangle is a straight-edged planar quad). `normal` is the front.
    Quad { p: [DVec3; 4], normal: DVec3 },
    /// The unit disk of object space: r = u, φ = 2π v.
    Disk { xf: Affine, sign: f64 },
    /// A (φ, θ) rectangle of a sphere in object space:
    /// φ = phi0 + u·π/2, θ = theta0 + v·π/2.
    Sphere {
        xf: Affine,
        centre: DVec3,
        radius: f64,
        phi0: f64,
        theta0: f64,
        sign: f64,
    },
    /// A (φ, z) rectangle of an open tube in object space:
    /// p0 + v·axis + r (cos φ e1 + sin φ e2), φ = phi0 + u·π/2.
    Cylinder {
        xf: Affine,
        p0: DVec3,
        axis: DVec3,
        e1: DVec3,
        e2: DVec3,
        radius: f64,
        phi0: f64,
        sign: f64,
    },
}

/// A point of a patch with its tangents and front unit normal.
#[derive(Clone, Copy, Debug)]
pub(crate) struct PatchPoint {
    pub p: DVec3,
    pub dpdu: DVec3,
    pub dpdv: DVec3,
    pub n: DVec3,
}

impl PatchPoint {
    /// |∂p/∂u × ∂p/∂v|: the area density of the parametrisation.
    #[inline]
    pub fn jacobian(&self) -> f64 {
        self.dpdu.cross(self.dpdv).length()
    }
}

/// Quarter-turn piece angle used by sphere and cylinder pieces.
pub(crate) const PIECE_ANGLE: f64 = FRAC_PI_2;

impl Patch {
    /// True if the patch lies in one plane.
    pub fn is_planar(&self) -> bool {
        matches!(self, Patch::Quad { .. } | Patch::Disk { .. })
    }

    /// The point, tangents and front normal at (u, v).
    pub fn eval(&self, uv: DVec2) -> PatchPoint {
        let (u, v) = (uv.x, uv.y);
        match self {
            Patch::Quad { p, normal } => {
                let p = *p;
                let pt =
                    (1.0 - v) * ((1.0 - u) * p[0] + u * p[1]) + v * ((1.0 - u) * p[3] + u * p[2]);
                let dpdu = (1.0 - v) * (p[1] - p[0]) + v * (p[2] - p[3]);
                let dpdv = (1.0 - u) * (p[3] - p[0]) + u * (p[2] - p[1]);
                PatchPoint {
                    p: pt,
                    dpdu,
                    dpdv,
                    n: *normal,
                }
            }
            Patch::Disk { xf, sign } => {
                let (s, c) = (TAU * v).sin_cos();
                let po = DVec3::new(u * c, u * s, 0.0);
                PatchPoint {
                    p: xf.point(po),
                    dpdu: xf.vector(DVec3::new(c, s, 0.0)),
                    dpdv: xf.vector(DVec3::new(-u * s * TAU, u * c * TAU, 0.0)),
                    n: *sign * xf.normal(DVec3::Z),
                }
            }
            Patch::Sphere {
                xf,
                centre,
                radius,
                phi0,
                theta0,
                sign,
            } => {
                let phi = phi0 + u * PIECE_ANGLE;
                let theta = theta0 + v * PIECE_ANGLE;
                let (sp, cp) = phi.sin_cos();
                let (st, ct) = theta.sin_cos();
                let dir = DVec3::new(st * cp, st * sp, ct);
                let r = *radius;
                PatchPoint {
                    p: xf.point(*centre + r * dir),
                    dpdu: xf.vector(DVec3::new(-st * sp, st * cp, 0.0) * (r * PIECE_ANGLE)),
                    dpdv: xf.vector(DVec3::new(ct * cp, ct * sp, -st) * (r * PIECE_ANGLE)),
                    n: *sign * xf.normal(dir),
                }
            }
            Patch::Cylinder {
                xf,
                p0,
                axis,
                e1,
                e2,
                radius,
                phi0,
                sign,
            } => {
                let phi = phi0 + u * PIECE_ANGLE;
                let (s, c) = phi.sin_cos();
                let radial = c * *e1 + s * *e2;
                PatchPoint {
                    p: xf.point(*p0 + v * *axis + *radius * radial),
                    dpdu: xf.vector((-s * *e1 + c * *e2) * (*radius * PIECE_ANGLE)),
                    dpdv: xf.vector(*axis),
                    n: *sign * xf.normal(radial),
                }
            }
        }
    }

    /// Area of the image of the uv rectangle [min, max]: exact in closed
    /// form for quads, disks, and spheres or cylinders under a similarity;
    /// adaptive Gauss–Legendre (relative accuracy ≈ 1e-12) otherwise.
    pub fn area(&self, min: DVec2, max: DVec2) -> f64 {
        match self {
            Patch::Quad { .. } => {
                // For a planar bilinear map ∂p/∂u × ∂p/∂v is affine in (u, v):
                // its value at the centre is its mean.
                self.eval(0.5 * (min + max)).jacobian() * (max.x - min.x) * (max.y - min.y)
            }
            Patch::Disk { xf, .. } => {
                let k = xf.vector(DVec3::X).cross(xf.vector(DVec3::Y)).length();
                k * TAU * (max.y - min.y) * 0.5 * (max.x * max.x - min.x * min.x)
            }
            Patch::Sphere {
                xf, radius, theta0, ..
            } if xf.similarity.is_some() => {
                let s = xf.similarity.unwrap_or(1.0);
                let r = s * radius;
                let t0 = theta0 + min.y * PIECE_ANGLE;
                let t1 = theta0 + max.y * PIECE_ANGLE;
                r * r * (max.x - min.x) * PIECE_ANGLE * (t0.cos() - t1.cos())
            }
            Patch::Cylinder {
                xf, radius, axis, ..
            } if xf.similarity.is_some() => {
                let s = xf.similarity.unwrap_or(1.0);
                s * radius * (max.x - min.x) * PIECE_ANGLE * s * axis.length() * (max.y - min.y)
            }
            _ => integrate_rect(
                &|u, v| self.eval(DVec2::new(u, v)).jacobian(),
                [min.x, max.x],
                [min.y, max.y],
                1e-12,
                6,
            ),
        }
    }
}

/// Angle in [0, 2π) of (x, y).
#[inline]
pub(crate) fn angle_2pi(y: f64, x: f64) -> f64 {
    let a = y.atan2(x);
    if a < 0.0 {
        (a + TAU).min(TAU.next_down())
    } else {
        a
    }
}

/// Splits an angle in [0, 2π) into a quarter-turn piece index and the local
/// coordinate in [0, 1].
#[inline]
pub(crate) fn quarter(phi: f64) -> (u32, f64) {
    let q = (phi / PIECE_ANGLE).floor().clamp(0.0, 3.0);
    let u = ((phi - q * PIECE_ANGLE) / PIECE_ANGLE).clamp(0.0, 1.0);
    (q as u32, u)
}

/// θ ∈ [0, π] into hemisphere index and local coordinate.
#[inline]
pub(crate) fn half(theta: f64) -> (u32, f64) {
    if theta < FRAC_PI_2 {
        (0, (theta / PIECE_ANGLE).clamp(0.0, 1.0))
    } else {
        (1, ((theta - FRAC_PI_2) / PIECE_ANGLE).clamp(0.0, 1.0))
    }
}

/// Inverse of the bilinear map of a planar quad: the (u, v) of a point `x`
/// in the quad's plane (Quilez's closed form in the dominant 2-D projection),
/// clamped to [0,1]².
pub(crate) fn inverse_bilinear(p: &[DVec3; 4], normal: DVec3, x: DVec3) -> DVec2 {
    // Project onto the plane's dominant axes.
    let a = normal.abs();
    let (i, j) = if a.x >= a.y && a.x >= a.z {
        (1, 2)
    } else if a.y >= a.z {
        (2, 0)
    } else {
        (0, 1)
    };
    let pr = |q: DVec3| DVec2::new(q[i], q[j]);
    let (pa, pb, pc, pd) = (pr(p[0]), pr(p[1]), pr(p[2]), pr(p[3]));
    let e = pb - pa;
    let f = pd - pa;
    let g = pa - pb + pc - pd;
    let h = pr(x) - pa;
    let cross = |a: DVec2, b: DVec2| a.x * b.y - a.y * b.x;
    let k2 = cross(g, f);
    let k1 = cross(e, f) + cross(h, g);
    let k0 = cross(h, e);
    let v = if k2.abs() <= 1e-12 * k1.abs() {
        -k0 / k1
    } else {
        let w = (k1 * k1 - 4.0 * k0 * k2).max(0.0).sqrt();
        // Stable root choice: the root in [0, 1].
        let q = -0.5 * (k1 + k1.signum() * w);
        let r1 = q / k2;
        let r2 = if q != 0.0 { k0 / q } else { r1 };
        if (-1e-9..=1.0 + 1e-9).contains(&r1) {
            r1
        } else {
            r2
        }
    };
    let den = e + g * v;
    let u = if den.x.abs() >= den.y.abs() {
        (h.x - f.x * v) / den.x
    } else {
        (h.y - f.y * v) / den.y
    };
    let fix = |t: f64| {
        if t.is_finite() {
            t.clamp(0.0, 1.0)
        } else {
            0.0
        }
    };
    DVec2::new(fix(u), fix(v))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn inverse_bilinear_inverts_a_general_planar_quad() {
        let p = [
            DVec3::new(0.0, 0.0, 1.0),
            DVec3::new(2.0, 0.3, 1.0),
            DVec3::new(2.5, 1.7, 1.0),
            DVec3::new(-0.4, 1.2, 1.0),
        ];
        let quad = Patch::Quad {
            p,
            normal: DVec3::Z,
        };
        for &(u, v) in &[(0.1, 0.2), (0.9, 0.95), (0.5, 0.5), (0.0, 1.0), (1.0, 0.0)] {
            let x = quad.eval(DVec2::new(u, v)).p;
            let uv = inverse_bilinear(&p, DVec3::Z, x);
            assert!((uv - DVec2::new(u, v)).length() < 1e-12, "{u} {v} -> {uv}");
        }
    }
}
