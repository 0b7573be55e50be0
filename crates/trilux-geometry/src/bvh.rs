//! Ray queries: closest hit and occlusion over the whole scene.
//!
//! # Structure
//!
//! One obvhs compressed wide BVH (CWBVH, PLOC build) over all primitives:
//! mesh triangles, the two triangles of every planar quad, and one custom
//! primitive per disk, sphere and cylinder (its box). obvhs only sees f32
//! boxes and an f32 copy of the ray; every primitive test runs in f64 on the
//! original ray, and obvhs is told a conservatively rounded-up distance for
//! pruning. Boxes are padded by 4e-6 × the scene's extent, and rays are
//! first clipped (in f64) to the scene's box so that the f32 origin is never
//! far outside it: the f32 ray error is then far below the padding, so the
//! traversal never misses a primitive the f64 ray hits. obvhs also culls
//! boxes that end within 1e-4 (absolute) of the ray's origin, so the f32 ray
//! starts 2e-4 + 2 × padding before the first point of interest (found by a
//! Mitsuba cross-check: a ray entering an axis-aligned cube face missed it).
//!
//! # Robustness
//!
//! - **Shared edges.** Triangles (mesh triangles and the halves of quads, so
//!   also the six faces of a cube, whose corners are shared bit-for-bit) use
//!   the watertight test of Woop, Benthin and Wald (JCGT 2013) in f64, with
//!   edge values of exactly zero counted as inside: a ray through an edge or
//!   vertex hits at least one of the triangles that share it.
//! - **Analytic shapes** are intersected exactly, in object space (the ray
//!   is mapped by `object_from_world`; t is unchanged by an affine map):
//!   sphere and cylinder by a quadratic solved in the numerically stable form
//!   (discriminant from the perpendicular distance, Haines et al., Ray
//!   Tracing Gems ch. 7), disk by the plane z = 0. The whole sphere (tube)
//!   is one primitive, so the seams between its pieces cannot leak.
//! - **Self-intersection** is the caller's: every query takes the ray
//!   interval (tmin, tmax), and [`crate::Geometry`] sets tmin from its
//!   relative epsilon ([`crate::RAY_EPSILON`]).
//!
//! This module knows primitives only; [`crate::Geometry`] turns a
//! [`PrimHit`] into a hit on an input surface.

use glam::{DVec2, DVec3, Vec3A};
use obvhs::{BvhBuildParams, aabb::Aabb, cwbvh::CwBvh, cwbvh::builder::build_cwbvh, ray::RayHit};

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

/// What a triangle primitive belongs to.
#[derive(Clone, Copy, Debug)]
pub(crate) enum TriOwner {
    Mesh { mesh: u32, tri: u32 },
    Quad { surface: u32 },
}

/// A primitive of the BVH, with the scene shape it belongs to (so that a
/// query can ignore one shape).
#[derive(Clone, Copy, Debug)]
pub(crate) enum Prim {
    /// A triangle of a mesh or half of a planar quad.
    Tri {
        v: [DVec3; 3],
        owner: TriOwner,
        shape: u32,
    },
    /// A disk, sphere or cylinder: an index into the analytic shapes.
    Analytic { index: u32, shape: u32 },
}

impl Prim {
    fn shape(&self) -> u32 {
        match *self {
            Prim::Tri { shape, .. } | Prim::Analytic { shape, .. } => shape,
        }
    }
}

#[derive(Clone, Debug)]
pub(crate) struct Bvh {
    cw: Option<CwBvh>,
    /// Primitives in BVH order.
    prims: Vec<Prim>,
    analytic: Vec<Analytic>,
    /// Box padding: 4e-6 × the scene's extent.
    pad: f64,
    /// The scene's box, to which rays are clipped before traversal.
    bounds: Bounds,
}

struct BoxPrim(Aabb);

impl obvhs::Boundable for BoxPrim {
    fn aabb(&self) -> Aabb {
        self.0
    }
}

/// Ray data precomputed for the watertight triangle test.
#[derive(Clone, Copy)]
pub(crate) struct RayPre {
    o: DVec3,
    d: DVec3,
    k: [usize; 3],
    s: [f64; 3],
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
    fn bounds(&self) -> Bounds {
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

/// Which primitive a closest-hit search found, and where.
#[derive(Clone, Copy, Debug)]
pub(crate) struct PrimHit {
    /// Index of the primitive (BVH order).
    pub prim: usize,
    /// Ray parameter, in units of the query's direction.
    pub t: f64,
    /// Barycentrics (b1, b2) for triangles, zero for analytic shapes.
    pub bary: DVec2,
}

impl Bvh {
    /// Builds the CWBVH over `prims` (PLOC, obvhs's medium preset), with
    /// boxes padded by 4e-6 × `extent`.
    pub(crate) fn build(
        prims: Vec<Prim>,
        analytic: Vec<Analytic>,
        bounds: Bounds,
        extent: f64,
    ) -> Bvh {
        let pad = 4e-6 * extent;
        if prims.is_empty() {
            return Bvh {
                cw: None,
                prims,
                analytic,
                pad,
                bounds,
            };
        }
        let boxes: Vec<BoxPrim> = prims
            .iter()
            .map(|p| {
                let b = match p {
                    Prim::Tri { v, .. } => Bounds::from_points(*v),
                    Prim::Analytic { index, .. } => analytic[*index as usize].bounds(),
                }
                .padded(pad);
                BoxPrim(Aabb::new(b.min.as_vec3a(), b.max.as_vec3a()))
            })
            .collect();
        let cw = build_cwbvh(
            &boxes,
            BvhBuildParams::medium_build(),
            &mut std::time::Duration::default(),
        );
        let ordered = cw
            .primitive_indices
            .iter()
            .map(|&i| prims[i as usize])
            .collect();
        Bvh {
            cw: Some(cw),
            prims: ordered,
            analytic,
            pad,
            bounds,
        }
    }

    /// Number of primitives (triangles and analytic shapes).
    pub(crate) fn len(&self) -> usize {
        self.prims.len()
    }

    /// A primitive, by its index in BVH order.
    pub(crate) fn prim(&self, id: usize) -> &Prim {
        &self.prims[id]
    }

    /// An analytic shape.
    pub(crate) fn analytic(&self, index: u32) -> &Analytic {
        &self.analytic[index as usize]
    }

    #[inline]
    fn test_prim(&self, prim: &Prim, pre: &RayPre, tmin: f64, tmax: f64) -> Option<(f64, DVec2)> {
        match prim {
            Prim::Tri { v, .. } => intersect_triangle(pre, v, tmin, tmax),
            Prim::Analytic { index, .. } => self.analytic[*index as usize]
                .intersect(pre.o, pre.d, tmin, tmax)
                .map(|t| (t, DVec2::ZERO)),
        }
    }

    /// Clips a ray to the padded scene box; returns the f32 traversal ray
    /// (unit direction) and the offset/scale mapping its t back to ours.
    fn traversal_ray(
        &self,
        o: DVec3,
        d: DVec3,
        tmin: f64,
        tmax: f64,
    ) -> Option<(obvhs::ray::Ray, f64, f64)> {
        let len = d.length();
        if len <= 0.0 || !len.is_finite() || !o.is_finite() {
            return None;
        }
        let b = self.bounds.padded(2.0 * self.pad + 1e-300);
        let inv = 1.0 / d;
        let t1 = (b.min - o) * inv;
        let t2 = (b.max - o) * inv;
        let near = t1.min(t2);
        let far = t1.max(t2);
        // NaN (0 × ∞ for a zero direction component on a slab edge) counts
        // as unbounded.
        let tn = [near.x, near.y, near.z]
            .into_iter()
            .filter(|x| !x.is_nan())
            .fold(tmin, f64::max);
        let tf = [far.x, far.y, far.z]
            .into_iter()
            .filter(|x| !x.is_nan())
            .fold(tmax, f64::min);
        if tn > tf {
            return None;
        }
        // obvhs culls every box whose exit lies within 1e-4 (absolute) of the
        // traversal ray's origin (`EPSILON` in its node test): start the f32
        // ray a little before the first point we care about.
        let back = 2e-4 + 2.0 * self.pad;
        let start = tn.max(tmin).max(0.0) - back / len;
        let origin = o + start * d;
        let dn = d / len;
        let span = ((tf - start) * len) as f32;
        let ray = obvhs::ray::Ray::new(
            origin.as_vec3a(),
            // obvhs's box test misses with negative-zero direction components.
            Vec3A::from(dn.as_vec3()).map(|c| if c == 0.0 { 0.0 } else { c }),
            0.0,
            span.next_up(),
        );
        Some((ray, start, len))
    }

    /// The closest primitive hit in (tmin, tmax), ignoring the primitives of
    /// shape `skip`.
    pub(crate) fn closest(
        &self,
        o: DVec3,
        d: DVec3,
        tmin: f64,
        tmax: f64,
        skip: Option<u32>,
    ) -> Option<PrimHit> {
        let cw = self.cw.as_ref()?;
        let (ray32, start, len) = self.traversal_ray(o, d, tmin, tmax)?;
        let pre = RayPre::new(o, d);
        let mut best: Option<PrimHit> = None;
        let mut best_t = tmax;
        let mut rh = RayHit::none();
        cw.ray_traverse(ray32, &mut rh, |_, id| {
            let prim = &self.prims[id];
            if skip == Some(prim.shape()) {
                return f32::INFINITY;
            }
            if let Some((t, bary)) = self.test_prim(prim, &pre, tmin, best_t) {
                best_t = t;
                best = Some(PrimHit { prim: id, t, bary });
                (((t - start) * len) as f32).next_up()
            } else {
                f32::INFINITY
            }
        });
        best
    }

    /// True if any primitive is hit in (tmin, tmax). Tries the primitive in
    /// `hint` (the last occluder found, for coherent segments) first, and
    /// stores the occluder it finds there.
    pub(crate) fn any(
        &self,
        o: DVec3,
        d: DVec3,
        tmin: f64,
        tmax: f64,
        hint: &mut Option<u32>,
    ) -> bool {
        let Some(cw) = self.cw.as_ref() else {
            return false;
        };
        let pre = RayPre::new(o, d);
        if let Some(h) = *hint
            && self
                .test_prim(&self.prims[h as usize], &pre, tmin, tmax)
                .is_some()
        {
            return true;
        }
        let Some((ray32, _, _)) = self.traversal_ray(o, d, tmin, tmax) else {
            return false;
        };
        let mut found = None;
        let miss = cw.ray_traverse_miss(ray32, |_, id| {
            if self.test_prim(&self.prims[id], &pre, tmin, tmax).is_some() {
                found = Some(id as u32);
                0.0
            } else {
                f32::INFINITY
            }
        });
        if found.is_some() {
            *hint = found;
        }
        !miss
    }

    /// The closest hit over every primitive, without the tree (the
    /// reference for tests).
    pub(crate) fn closest_brute_force(
        &self,
        o: DVec3,
        d: DVec3,
        tmin: f64,
        tmax: f64,
    ) -> Option<PrimHit> {
        let pre = RayPre::new(o, d);
        let mut best: Option<PrimHit> = None;
        let mut best_t = tmax;
        for (i, p) in self.prims.iter().enumerate() {
            if let Some((t, bary)) = self.test_prim(p, &pre, tmin, best_t) {
                best_t = t;
                best = Some(PrimHit { prim: i, t, bary });
            }
        }
        best
    }
}
