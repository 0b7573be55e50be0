//! Disks, spheres and cylinders, intersected exactly in f64 and in object
//! space (the ray is mapped by `object_from_world`; t is unchanged by an
//! affine map): sphere and cylinder by a quadratic solved in the
//! numerically stable form (discriminant from the perpendicular distance,
//! Haines et al., Ray Tracing Gems ch. 7), the disk by the plane z = 0. A
//! whole sphere (tube) is one primitive, so the seams between its input
//! surfaces cannot leak.

use glam::{DVec2, DVec3};

use crate::bounds::Bounds;
use crate::patch::{angle_2pi, half, quarter};
use crate::transform::Affine;

#[derive(Clone, Copy, Debug)]
pub(crate) enum AnalyticKind {
    Disk,
    Sphere {
        centre: DVec3,
        radius: f64,
    },
    Cylinder {
        p0: DVec3,
        axis: DVec3,
        e1: DVec3,
        e2: DVec3,
        radius: f64,
    },
}

/// A disk, sphere or cylinder intersected exactly.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Analytic {
    pub kind: AnalyticKind,
    pub xf: Affine,
    pub first_surface: u32,
    pub sign: f64,
}

/// Roots of |f + s·dn|² = r² (dn unit) in increasing order, stable form.
#[inline]
fn sphere_roots(f: DVec3, dn: DVec3, r: f64) -> Option<(f64, f64)> {
    let bb = -f.dot(dn);
    let l = f + bb * dn;
    let ll = l.length();
    let disc = (r - ll) * (r + ll);
    if disc < 0.0 {
        return None;
    }
    let sq = disc.sqrt();
    let cc = (f.length() - r) * (f.length() + r);
    let q = bb + sq.copysign(bb);
    if q == 0.0 {
        return Some((0.0, 0.0));
    }
    let (s0, s1) = (cc / q, q);
    Some(if s0 <= s1 { (s0, s1) } else { (s1, s0) })
}

impl Analytic {
    /// t of the first intersection with the true shape in (tmin, tmax).
    pub(crate) fn intersect(&self, o: DVec3, d: DVec3, tmin: f64, tmax: f64) -> Option<f64> {
        let oo = self.xf.object_from_world.transform_point3(o);
        let od = self.xf.linear_inv * d;
        match self.kind {
            AnalyticKind::Disk => {
                if od.z == 0.0 {
                    return None;
                }
                let t = -oo.z / od.z;
                if !(t > tmin && t < tmax) {
                    return None;
                }
                let p = oo + t * od;
                (p.x * p.x + p.y * p.y <= 1.0).then_some(t)
            }
            AnalyticKind::Sphere { centre, radius } => {
                let dl = od.length();
                let (s0, s1) = sphere_roots(oo - centre, od / dl, radius)?;
                [s0 / dl, s1 / dl]
                    .into_iter()
                    .find(|&t| t > tmin && t < tmax)
            }
            AnalyticKind::Cylinder {
                p0,
                axis,
                e1,
                e2,
                radius,
            } => {
                let f = oo - p0;
                let f2 = DVec3::new(f.dot(e1), f.dot(e2), 0.0);
                let d2 = DVec3::new(od.dot(e1), od.dot(e2), 0.0);
                let dl = d2.length();
                if dl == 0.0 {
                    return None;
                }
                let (s0, s1) = sphere_roots(f2, d2 / dl, radius)?;
                let l2 = axis.length_squared();
                [s0 / dl, s1 / dl].into_iter().find(|&t| {
                    let z = (f + t * od).dot(axis) / l2;
                    t > tmin && t < tmax && (0.0..=1.0).contains(&z)
                })
            }
        }
    }

    /// World bounds of the whole shape.
    pub(crate) fn bounds(&self) -> Bounds {
        let corners: Vec<DVec3> = match self.kind {
            AnalyticKind::Disk => [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
                .iter()
                .map(|&(x, y)| DVec3::new(x, y, 0.0))
                .collect(),
            AnalyticKind::Sphere { centre, radius } => (0..8)
                .map(|i| {
                    centre
                        + radius
                            * DVec3::new(
                                if i & 1 != 0 { 1.0 } else { -1.0 },
                                if i & 2 != 0 { 1.0 } else { -1.0 },
                                if i & 4 != 0 { 1.0 } else { -1.0 },
                            )
                })
                .collect(),
            AnalyticKind::Cylinder {
                p0,
                axis,
                e1,
                e2,
                radius,
            } => (0..8)
                .map(|i| {
                    p0 + if i & 4 != 0 { axis } else { DVec3::ZERO }
                        + radius * (if i & 1 != 0 { e1 } else { -e1 })
                        + radius * (if i & 2 != 0 { e2 } else { -e2 })
                })
                .collect(),
        };
        Bounds::from_points(corners.into_iter().map(|c| self.xf.point(c)))
    }

    /// Surface, coordinate and front normal of the point at ray parameter t.
    pub(crate) fn surface_at(&self, o: DVec3, d: DVec3, t: f64) -> (u32, DVec2, DVec3) {
        let p = self.xf.object_from_world.transform_point3(o) + t * (self.xf.linear_inv * d);
        match self.kind {
            AnalyticKind::Disk => {
                let r = (p.x * p.x + p.y * p.y).sqrt().min(1.0);
                let v = angle_2pi(p.y, p.x) / std::f64::consts::TAU;
                (
                    self.first_surface,
                    DVec2::new(r, v),
                    self.sign * self.xf.normal(DVec3::Z),
                )
            }
            AnalyticKind::Sphere { centre, radius } => {
                let rel = (p - centre) / radius;
                let phi = angle_2pi(rel.y, rel.x);
                let theta = (rel.z / rel.length()).clamp(-1.0, 1.0).acos();
                let (i, u) = quarter(phi);
                let (j, v) = half(theta);
                (
                    self.first_surface + j * 4 + i,
                    DVec2::new(u, v),
                    self.sign * self.xf.normal(rel),
                )
            }
            AnalyticKind::Cylinder {
                p0, axis, e1, e2, ..
            } => {
                let f = p - p0;
                let (x, y) = (f.dot(e1), f.dot(e2));
                let phi = angle_2pi(y, x);
                let (i, u) = quarter(phi);
                let v = (f.dot(axis) / axis.length_squared()).clamp(0.0, 1.0);
                let radial = x * e1 + y * e2;
                (
                    self.first_surface + i,
                    DVec2::new(u, v),
                    self.sign * self.xf.normal(radial),
                )
            }
        }
    }
}
