//! [`Geometry`]: the immutable geometry of a scene — its input surfaces,
//! its meshes and the ray-query structure — built once from the shapes
//! ([`crate::build`]) and shared by everything that follows (element
//! forests, visibility, the solver, the renderer).
//!
//! Ray queries are answered here: the BVH (the private `bvh` module) finds the
//! primitive, and this module turns it into a [`Hit`] on an input surface.
//! The self-intersection rule: a ray ignores hits closer than
//! ε = [`RAY_EPSILON`] × (|origin|∞ + scene extent), measured along the ray;
//! [`Geometry::occluded`] ignores the same distance at both ends. In f64 the
//! re-hit of a ray's own surface lies within ~1e-15 × |origin| / cos θ of
//! the origin, so ε = 1e-9 relative absorbs it for any ray more than ~1e-6
//! rad from grazing, while staying far below any real feature.

use glam::{DVec2, DVec3};
use rayon::prelude::*;

use crate::bounds::Bounds;
pub use crate::bvh::BvhStats;
use crate::bvh::{Bvh, Prim, PrimHit, QueryRay, TriOwner};
use crate::chart::MeshData;
use crate::ids::SurfaceId;
use crate::patch::{Patch, inverse_bilinear};
use crate::surface::{InputSurface, SurfaceCoord, SurfaceGeom, SurfacePoint};

/// Queries per rayon task in the batch calls.
const BATCH_CHUNK: usize = 64;

/// Relative self-intersection epsilon (see the module docs).
pub const RAY_EPSILON: f64 = 1e-9;

/// A ray: points `origin + t · dir` for t > 0. `dir` need not be unit
/// length; `t` is measured in units of `dir`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    /// Start point.
    pub origin: DVec3,
    /// Direction (non-zero).
    pub dir: DVec3,
}

/// The closest intersection of a ray with the scene.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// The input surface hit.
    pub surface: SurfaceId,
    /// Where on that surface.
    pub coord: SurfaceCoord,
    /// World-space hit point.
    pub point: DVec3,
    /// Front-side unit geometric normal of the surface (after
    /// `flip_normals`), whichever side the ray arrived from.
    pub geometric_normal: DVec3,
    /// Unit shading normal (interpolated vertex normals of meshes, else the
    /// geometric normal), on the front side.
    pub shading_normal: DVec3,
    /// Ray parameter of the hit, in units of `dir`.
    pub t: f64,
}

impl Hit {
    /// True if the ray arrived on the front side (`dir · n < 0`).
    pub fn front_facing(&self, ray: &Ray) -> bool {
        ray.dir.dot(self.geometric_normal) < 0.0
    }
}

/// The immutable geometry of a scene: input surfaces, meshes, BVH.
#[derive(Clone, Debug)]
pub struct Geometry {
    pub(crate) surfaces: Vec<InputSurface>,
    pub(crate) meshes: Vec<MeshData>,
    pub(crate) bvh: Bvh,
    pub(crate) bounds: Bounds,
    /// Largest absolute coordinate of the scene: the scale of ray epsilons.
    pub(crate) extent: f64,
    /// The fraction of light each shape lets through, by shape; empty when
    /// every shape is opaque ([`crate::transmission`]).
    pub(crate) transmitters: Vec<Option<crate::transmission::Transmittance>>,
}

impl Geometry {
    /// All input surfaces, indexed by [`SurfaceId`].
    pub fn surfaces(&self) -> &[InputSurface] {
        &self.surfaces
    }

    /// One input surface.
    pub fn surface(&self, id: SurfaceId) -> &InputSurface {
        &self.surfaces[id.index()]
    }

    /// The ids of the input surfaces made from shape `shape`.
    pub fn surfaces_of_shape(&self, shape: u32) -> Vec<SurfaceId> {
        (0..self.surfaces.len() as u32)
            .filter(|&i| self.surfaces[i as usize].shape == shape)
            .map(SurfaceId)
            .collect()
    }

    /// World-space bounds of the whole scene.
    pub fn bounds(&self) -> Bounds {
        self.bounds
    }

    /// Largest absolute coordinate of the scene (at least 1e-300): the
    /// scale of every relative tolerance.
    pub fn extent(&self) -> f64 {
        self.extent
    }

    /// Number of primitives in the BVH (triangles, including two per planar
    /// quad, and one per disk, sphere and cylinder).
    pub fn primitive_count(&self) -> usize {
        self.bvh.len()
    }

    /// Size and build time of the BVH.
    pub fn bvh_stats(&self) -> BvhStats {
        self.bvh.stats()
    }

    /// Every triangle the ray queries test (mesh triangles and the two
    /// halves of each planar quad; analytic shapes are not triangles), for
    /// handing the same geometry to another ray tracer.
    pub fn primitive_triangles(&self) -> Vec<[DVec3; 3]> {
        self.bvh.triangles().collect()
    }

    /// The parametric patch of a surface (`None` for mesh charts).
    pub(crate) fn patch(&self, surface: SurfaceId) -> Option<&Patch> {
        match &self.surfaces[surface.index()].geom {
            SurfaceGeom::Patch(p) => Some(p),
            SurfaceGeom::Chart { .. } => None,
        }
    }

    /// The mesh a chart belongs to (`None` for parametric surfaces).
    pub(crate) fn chart_mesh(&self, surface: SurfaceId) -> Option<&MeshData> {
        match &self.surfaces[surface.index()].geom {
            SurfaceGeom::Chart { mesh, .. } => Some(&self.meshes[*mesh as usize]),
            SurfaceGeom::Patch(_) => None,
        }
    }

    /// The index of the mesh a chart belongs to.
    pub(crate) fn chart_mesh_index(&self, surface: SurfaceId) -> Option<u32> {
        match &self.surfaces[surface.index()].geom {
            SurfaceGeom::Chart { mesh, .. } => Some(*mesh),
            SurfaceGeom::Patch(_) => None,
        }
    }

    /// Area of triangle `tri` of a chart's mesh (0 for parametric surfaces).
    pub(crate) fn triangle_area(&self, surface: SurfaceId, tri: u32) -> f64 {
        self.chart_mesh(surface)
            .and_then(|m| m.tri_area.get(tri as usize).copied())
            .unwrap_or(0.0)
    }

    /// The point and front normal of a surface at `coord` (`None` if the
    /// coordinate kind does not fit the surface or names a triangle of
    /// another chart).
    pub fn surface_point(&self, surface: SurfaceId, coord: SurfaceCoord) -> Option<SurfacePoint> {
        match (&self.surfaces[surface.index()].geom, coord) {
            (SurfaceGeom::Patch(p), SurfaceCoord::Uv(uv)) => {
                let e = p.eval(uv.clamp(DVec2::ZERO, DVec2::ONE));
                Some(SurfacePoint {
                    point: e.p,
                    normal: e.n,
                })
            }
            (SurfaceGeom::Chart { mesh, .. }, SurfaceCoord::Triangle { index, bary }) => {
                let m = &self.meshes[*mesh as usize];
                if m.tri_surface.get(index as usize) != Some(&surface.0) {
                    return None;
                }
                Some(SurfacePoint {
                    point: m.point(index, bary),
                    normal: m.tri_normal[index as usize],
                })
            }
            _ => None,
        }
    }

    /// The texture coordinates (u, v) at `coord`: for a mesh chart, its
    /// vertices' texture coordinates interpolated barycentrically (`None`
    /// for a mesh without them); for a parametric surface, its own (u, v),
    /// which for a `rectangle` is Mitsuba's (x/2 + 1/2, y/2 + 1/2) in
    /// object space (other parametric shapes have their own pieces'
    /// (u, v), which are not Mitsuba's: the scene layer refuses textures on
    /// them).
    pub fn texcoord(&self, surface: SurfaceId, coord: SurfaceCoord) -> Option<DVec2> {
        match (&self.surfaces[surface.index()].geom, coord) {
            (SurfaceGeom::Patch(_), SurfaceCoord::Uv(uv)) => {
                Some(uv.clamp(DVec2::ZERO, DVec2::ONE))
            }
            (SurfaceGeom::Chart { mesh, .. }, SurfaceCoord::Triangle { index, bary }) => {
                let m = &self.meshes[*mesh as usize];
                let t = m.triangles.get(index as usize)?;
                let uv = m.texcoords.as_ref()?;
                let [a, b, c] = t.map(|i| uv[i as usize]);
                Some(a * (1.0 - bary.x - bary.y) + b * bary.x + c * bary.y)
            }
            _ => None,
        }
    }

    #[inline]
    fn ray_epsilon(&self, o: DVec3) -> f64 {
        RAY_EPSILON * (o.abs().max_element() + self.extent)
    }

    /// A query ray and its tmin (ε / |dir|); `None` for a ray that is not
    /// finite or has a zero direction.
    #[inline]
    fn query(&self, ray: &Ray) -> Option<(QueryRay, f64)> {
        let q = QueryRay::new(ray.origin, ray.dir)?;
        Some((q, RAY_EPSILON * (q.omax + self.extent) / q.len))
    }

    /// The closest hit along `ray` with ε < t < `t_max` (ε: module docs).
    pub fn intersect(&self, ray: &Ray, t_max: f64) -> Option<Hit> {
        let (q, tmin) = self.query(ray)?;
        let h = self.bvh.closest(&q, tmin, t_max, None)?;
        Some(self.make_hit(ray.origin, ray.dir, h))
    }

    /// [`Geometry::intersect`] that ignores one shape's primitives (probes
    /// that start on a surface and must see what lies on it, even
    /// coincident with it).
    pub fn intersect_ignoring(&self, ray: &Ray, t_max: f64, shape: u32) -> Option<Hit> {
        let (q, tmin) = self.query(ray)?;
        let h = self.bvh.closest(&q, tmin, t_max, Some(shape))?;
        Some(self.make_hit(ray.origin, ray.dir, h))
    }

    /// True if `ray` hits anything with ε < t < `t_max`.
    pub fn ray_occluded(&self, ray: &Ray, t_max: f64) -> bool {
        self.query(ray)
            .is_some_and(|(q, tmin)| self.bvh.any(&q, tmin, t_max, &mut None))
    }

    /// True if something lies strictly between points `p` and `q`. Safe when
    /// `p` and `q` lie on surfaces: hits within ε of either end are ignored.
    pub fn occluded(&self, p: DVec3, q: DVec3) -> bool {
        self.occluded_hint(p, q, &mut None)
    }

    /// [`Geometry::occluded`] for coherent segments (e.g. between the same
    /// two elements): `hint` carries the last occluder found from one call
    /// to the next and is tested first. Start with `None`.
    pub fn occluded_hint(&self, p: DVec3, q: DVec3, hint: &mut Option<u32>) -> bool {
        self.segment(p, q)
            .is_some_and(|(r, tmin, tmax)| self.bvh.any(&r, tmin, tmax, hint))
    }

    /// [`Geometry::intersect`] for many rays, in parallel (rayon).
    pub fn intersect_batch(&self, rays: &[Ray], t_max: f64) -> Vec<Option<Hit>> {
        rays.par_iter()
            .with_min_len(BATCH_CHUNK)
            .map(|r| self.intersect(r, t_max))
            .collect()
    }

    /// [`Geometry::occluded`] for many segments, in parallel (rayon).
    pub fn occluded_batch(&self, segments: &[(DVec3, DVec3)]) -> Vec<bool> {
        segments
            .par_iter()
            .with_min_len(BATCH_CHUNK)
            .map(|&(p, q)| self.occluded(p, q))
            .collect()
    }

    /// The query ray and interval of segment (p, q) for
    /// [`Geometry::occluded`]: `None` if there is nothing between them.
    #[inline]
    fn segment(&self, p: DVec3, q: DVec3) -> Option<(QueryRay, f64, f64)> {
        let r = QueryRay::new(p, q - p)?;
        let tmin = RAY_EPSILON * (r.omax + self.extent) / r.len;
        let tmax = 1.0 - self.ray_epsilon(q) / r.len;
        (tmin < tmax).then_some((r, tmin, tmax))
    }

    /// The ray, tmin and tmax of segment (p, q) as [`Geometry::occluded`]
    /// takes them, `dir` = q − p.
    pub(crate) fn segment_interval(&self, p: DVec3, q: DVec3) -> Option<(Ray, f64, f64)> {
        let (r, tmin, tmax) = self.segment(p, q)?;
        Some((
            Ray {
                origin: r.o,
                dir: r.d,
            },
            tmin,
            tmax,
        ))
    }

    /// The tmin of `ray` (ε / |dir|), `None` for a ray that is not finite
    /// or has a zero direction.
    pub(crate) fn ray_tmin(&self, ray: &Ray) -> Option<f64> {
        self.query(ray).map(|(_, tmin)| tmin)
    }

    /// The self-intersection distance ε at a point (module docs).
    pub(crate) fn epsilon_at(&self, p: DVec3) -> f64 {
        self.ray_epsilon(p)
    }

    /// The closest hit along `ray` with `tmin` < t < `tmax`, and the shape
    /// it belongs to.
    pub(crate) fn closest_in(&self, ray: &Ray, tmin: f64, tmax: f64) -> Option<(Hit, u32)> {
        let q = QueryRay::new(ray.origin, ray.dir)?;
        let h = self.bvh.closest(&q, tmin, tmax, None)?;
        let shape = self.bvh.prim(h.prim).shape();
        Some((self.make_hit(ray.origin, ray.dir, h), shape))
    }

    /// [`Geometry::closest_in`] ignoring shape `skip`.
    pub(crate) fn closest_ignoring(
        &self,
        ray: &Ray,
        tmin: f64,
        tmax: f64,
        skip: u32,
    ) -> Option<(Hit, u32)> {
        let q = QueryRay::new(ray.origin, ray.dir)?;
        let h = self.bvh.closest(&q, tmin, tmax, Some(skip))?;
        let shape = self.bvh.prim(h.prim).shape();
        Some((self.make_hit(ray.origin, ray.dir, h), shape))
    }

    /// Brute force closest hit over every primitive, without the BVH: the
    /// reference for tests.
    pub fn intersect_brute_force(&self, ray: &Ray, t_max: f64) -> Option<Hit> {
        let tmin = self.ray_epsilon(ray.origin) / ray.dir.length();
        let h = self
            .bvh
            .closest_brute_force(ray.origin, ray.dir, tmin, t_max)?;
        Some(self.make_hit(ray.origin, ray.dir, h))
    }

    /// The input surface, coordinates and normals of a primitive hit.
    fn make_hit(&self, o: DVec3, d: DVec3, h: PrimHit) -> Hit {
        let point = o + h.t * d;
        let flat = |surface: u32, coord: SurfaceCoord, n: DVec3| Hit {
            surface: SurfaceId(surface),
            coord,
            point,
            geometric_normal: n,
            shading_normal: n,
            t: h.t,
        };
        match *self.bvh.prim(h.prim) {
            Prim::Tri {
                normal,
                surface,
                owner: TriOwner::Mesh { mesh, tri },
                ..
            } => {
                let coord = SurfaceCoord::Triangle {
                    index: tri,
                    bary: h.bary,
                };
                let m = &self.meshes[mesh as usize];
                let shading_normal = if m.shading_normals.is_some() {
                    m.shading_normal(tri, h.bary)
                } else {
                    normal
                };
                Hit {
                    shading_normal,
                    ..flat(surface, coord, normal)
                }
            }
            Prim::Tri {
                normal,
                surface,
                owner: TriOwner::Quad { second, affine },
                ..
            } => {
                let (b1, b2) = (h.bary.x, h.bary.y);
                let uv = match (affine, second) {
                    (true, false) => DVec2::new(b1 + b2, b2).clamp(DVec2::ZERO, DVec2::ONE),
                    (true, true) => DVec2::new(b1, b1 + b2).clamp(DVec2::ZERO, DVec2::ONE),
                    (false, _) => match self.patch(SurfaceId(surface)) {
                        Some(Patch::Quad { p, normal }) => inverse_bilinear(p, *normal, point),
                        _ => DVec2::ZERO,
                    },
                };
                flat(surface, SurfaceCoord::Uv(uv), normal)
            }
            Prim::Analytic { index, .. } => {
                let (s, uv, n) = self.bvh.analytic(index).surface_at(o, d, h.t);
                flat(s, SurfaceCoord::Uv(uv), n)
            }
        }
    }
}
