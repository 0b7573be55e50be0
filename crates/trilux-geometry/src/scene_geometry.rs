//! [`SceneGeometry`]: every input surface of a scene, their element trees,
//! and the ray-query structure, built once from the scene's shapes.

use std::f64::consts::FRAC_PI_2;

use glam::{DVec2, DVec3};

use crate::bounds::Bounds;
use crate::bvh::{Analytic, AnalyticKind, Bvh, Prim, TriOwner};
use crate::chart::{MeshData, Piece, build_charts};
use crate::element::{Element, rect_element};
use crate::error::{GeometryError, ShapeProblem};
use crate::ids::{ElementId, SurfaceId};
use crate::patch::Patch;
use crate::shape::{Shape, ShapeKind};
use crate::surface::{InputSurface, SurfaceCoord, SurfaceGeom, SurfaceKind, SurfacePoint};
use crate::transform::Affine;

/// The prepared, immutable-but-for-subdivision geometry of a scene.
#[derive(Clone, Debug)]
pub struct SceneGeometry {
    pub(crate) surfaces: Vec<InputSurface>,
    pub(crate) elements: Vec<Element>,
    pub(crate) pieces: Vec<Piece>,
    pub(crate) meshes: Vec<MeshData>,
    /// Shape index of each mesh.
    pub(crate) mesh_shape: Vec<u32>,
    pub(crate) analytic: Vec<Analytic>,
    pub(crate) bvh: Bvh,
    pub(crate) bounds: Bounds,
    /// Largest absolute coordinate of the scene: the scale of ray epsilons.
    pub(crate) extent: f64,
    /// Buried parts of faces, when the solver has probed them.
    pub(crate) burial: Option<crate::burial::BurialMap>,
}

impl SceneGeometry {
    /// Turns shapes into input surfaces, element-tree roots and a BVH.
    ///
    /// Errors name the offending shape: non-finite or singular transforms,
    /// non-finite parameters, non-positive radii, zero area, bad mesh
    /// indices. Non-uniform scale and shear are supported for every shape
    /// (a sphere becomes an exact ellipsoid, a disk an exact ellipse).
    pub fn build(shapes: &[Shape]) -> Result<SceneGeometry, GeometryError> {
        let mut g = SceneGeometry {
            surfaces: Vec::new(),
            elements: Vec::new(),
            pieces: Vec::new(),
            meshes: Vec::new(),
            mesh_shape: Vec::new(),
            analytic: Vec::new(),
            bvh: Bvh::default(),
            bounds: Bounds::EMPTY,
            extent: 0.0,
            burial: None,
        };
        let mut prims: Vec<Prim> = Vec::new();
        for (index, shape) in shapes.iter().enumerate() {
            g.add_shape(index, shape, &mut prims)
                .map_err(|problem| GeometryError {
                    shape: index,
                    problem,
                })?;
        }
        for s in &g.surfaces {
            g.bounds = g.bounds.union(s.bounds);
        }
        g.extent = if g.bounds.is_empty() {
            1.0
        } else {
            g.bounds
                .min
                .abs()
                .max(g.bounds.max.abs())
                .max_element()
                .max(1e-300)
        };
        g.bvh = Bvh::build(prims, &g.analytic, g.extent);
        Ok(g)
    }

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

    /// The point and front normal of a surface at `coord` (`None` if the
    /// coordinate kind does not fit the surface or names a triangle of
    /// another chart).
    pub fn surface_point(&self, surface: SurfaceId, coord: SurfaceCoord) -> Option<SurfacePoint> {
        let s = &self.surfaces[surface.index()];
        match (&s.geom, coord) {
            (SurfaceGeom::Patch(p), SurfaceCoord::Uv(uv)) => {
                let e = p.eval(uv.clamp(DVec2::ZERO, DVec2::ONE));
                Some(SurfacePoint {
                    point: e.p,
                    normal: e.n,
                })
            }
            (SurfaceGeom::Chart { mesh }, SurfaceCoord::Triangle { index, bary }) => {
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

    fn push_patch(
        &mut self,
        shape: usize,
        piece: u32,
        kind: SurfaceKind,
        patch: Patch,
        sees: (bool, bool),
    ) -> Result<(), ShapeProblem> {
        let id = SurfaceId(self.surfaces.len() as u32);
        let root = rect_element(&patch, id, DVec2::ZERO, DVec2::ONE, None, 0);
        if root.area <= 0.0 || !root.area.is_finite() {
            return Err(ShapeProblem::ZeroArea);
        }
        let eid = ElementId(self.elements.len() as u32);
        self.surfaces.push(InputSurface {
            shape: shape as u32,
            kind,
            root: eid,
            bounds: root.bounds,
            piece,
            area: root.area,
            planar: patch.is_planar(),
            front_sees_itself: sees.0,
            back_sees_itself: sees.1,
            geom: SurfaceGeom::Patch(Box::new(patch)),
        });
        self.elements.push(root);
        Ok(())
    }

    fn add_shape(
        &mut self,
        index: usize,
        shape: &Shape,
        prims: &mut Vec<Prim>,
    ) -> Result<(), ShapeProblem> {
        let xf = Affine::new(shape.world_from_object)?;
        let sign = if shape.flip_normals { -1.0 } else { 1.0 };
        let flip = shape.flip_normals;
        match &shape.kind {
            ShapeKind::Rectangle => {
                let p = [
                    DVec3::new(-1.0, -1.0, 0.0),
                    DVec3::new(1.0, -1.0, 0.0),
                    DVec3::new(1.0, 1.0, 0.0),
                    DVec3::new(-1.0, 1.0, 0.0),
                ]
                .map(|c| xf.point(c));
                let normal = sign * xf.normal(DVec3::Z);
                let sid = self.surfaces.len() as u32;
                self.push_patch(
                    index,
                    0,
                    SurfaceKind::Planar,
                    Patch::Quad { p, normal },
                    (false, false),
                )?;
                push_quad_prims(prims, sid, &p);
            }
            ShapeKind::Cube => {
                let corner = |i: usize| {
                    xf.point(DVec3::new(
                        if i & 1 != 0 { 1.0 } else { -1.0 },
                        if i & 2 != 0 { 1.0 } else { -1.0 },
                        if i & 4 != 0 { 1.0 } else { -1.0 },
                    ))
                };
                let c: Vec<DVec3> = (0..8).map(corner).collect();
                // Faces as (p00, p10, p11, p01) with (p10−p00)×(p01−p00)
                // pointing outwards in object space: −x, +x, −y, +y, −z, +z.
                let faces: [[usize; 4]; 6] = [
                    [0, 4, 6, 2],
                    [1, 3, 7, 5],
                    [0, 1, 5, 4],
                    [2, 6, 7, 3],
                    [0, 2, 3, 1],
                    [4, 5, 7, 6],
                ];
                for (k, f) in faces.iter().enumerate() {
                    let p = f.map(|i| c[i]);
                    // Mitsuba's cube is a mesh: the front follows the world
                    // winding of its triangles.
                    let normal = sign * (p[1] - p[0]).cross(p[3] - p[0]).normalize();
                    let sid = self.surfaces.len() as u32;
                    self.push_patch(
                        index,
                        k as u32,
                        SurfaceKind::Planar,
                        Patch::Quad { p, normal },
                        (false, false),
                    )?;
                    push_quad_prims(prims, sid, &p);
                }
            }
            ShapeKind::Disk => {
                let sid = self.surfaces.len() as u32;
                self.push_patch(
                    index,
                    0,
                    SurfaceKind::Planar,
                    Patch::Disk { xf, sign },
                    (false, false),
                )?;
                let a = self.analytic.len() as u32;
                self.analytic.push(Analytic {
                    kind: AnalyticKind::Disk,
                    xf,
                    first_surface: sid,
                    sign,
                });
                prims.push(Prim::Analytic(a));
            }
            ShapeKind::Sphere { center, radius } => {
                if !center.is_finite() {
                    return Err(ShapeProblem::NonFinite { what: "center" });
                }
                if !radius.is_finite() {
                    return Err(ShapeProblem::NonFinite { what: "radius" });
                }
                if *radius <= 0.0 {
                    return Err(ShapeProblem::BadRadius { radius: *radius });
                }
                let sid = self.surfaces.len() as u32;
                for j in 0..2u32 {
                    for i in 0..4u32 {
                        let patch = Patch::Sphere {
                            xf,
                            centre: *center,
                            radius: *radius,
                            phi0: i as f64 * FRAC_PI_2,
                            theta0: j as f64 * FRAC_PI_2,
                            sign,
                        };
                        self.push_patch(
                            index,
                            j * 4 + i,
                            SurfaceKind::Curved,
                            patch,
                            (flip, !flip),
                        )?;
                    }
                }
                let a = self.analytic.len() as u32;
                self.analytic.push(Analytic {
                    kind: AnalyticKind::Sphere {
                        centre: *center,
                        radius: *radius,
                    },
                    xf,
                    first_surface: sid,
                    sign,
                });
                prims.push(Prim::Analytic(a));
            }
            ShapeKind::Cylinder { p0, p1, radius } => {
                if !p0.is_finite() {
                    return Err(ShapeProblem::NonFinite { what: "p0" });
                }
                if !p1.is_finite() {
                    return Err(ShapeProblem::NonFinite { what: "p1" });
                }
                if !radius.is_finite() {
                    return Err(ShapeProblem::NonFinite { what: "radius" });
                }
                if *radius <= 0.0 {
                    return Err(ShapeProblem::BadRadius { radius: *radius });
                }
                let axis = *p1 - *p0;
                let Some(dir) = axis.try_normalize() else {
                    return Err(ShapeProblem::DegenerateAxis);
                };
                let (e1, e2) = dir.any_orthonormal_pair();
                let sid = self.surfaces.len() as u32;
                for i in 0..4u32 {
                    let patch = Patch::Cylinder {
                        xf,
                        p0: *p0,
                        axis,
                        e1,
                        e2,
                        radius: *radius,
                        phi0: i as f64 * FRAC_PI_2,
                        sign,
                    };
                    self.push_patch(index, i, SurfaceKind::Curved, patch, (flip, !flip))?;
                }
                let a = self.analytic.len() as u32;
                self.analytic.push(Analytic {
                    kind: AnalyticKind::Cylinder {
                        p0: *p0,
                        axis,
                        e1,
                        e2,
                        radius: *radius,
                    },
                    xf,
                    first_surface: sid,
                    sign,
                });
                prims.push(Prim::Analytic(a));
            }
            ShapeKind::Mesh(mesh) => self.add_mesh(index, mesh, &xf, sign, prims)?,
        }
        Ok(())
    }

    fn add_mesh(
        &mut self,
        index: usize,
        mesh: &crate::shape::TriangleMesh,
        xf: &Affine,
        sign: f64,
        prims: &mut Vec<Prim>,
    ) -> Result<(), ShapeProblem> {
        if mesh.triangles.is_empty() {
            return Err(ShapeProblem::EmptyMesh);
        }
        let count = mesh.positions.len();
        for (v, p) in mesh.positions.iter().enumerate() {
            if !p.is_finite() {
                return Err(ShapeProblem::NonFiniteVertex { vertex: v });
            }
        }
        for (t, tri) in mesh.triangles.iter().enumerate() {
            for &v in tri {
                if v as usize >= count {
                    return Err(ShapeProblem::IndexOutOfRange {
                        triangle: t,
                        vertex: v,
                        count,
                    });
                }
            }
        }
        let shading_normals = match (&mesh.normals, mesh.face_normals) {
            (Some(ns), false) => {
                if ns.len() != count {
                    return Err(ShapeProblem::NormalCountMismatch {
                        normals: ns.len(),
                        positions: count,
                    });
                }
                let mut out = Vec::with_capacity(count);
                for (v, n) in ns.iter().enumerate() {
                    if !n.is_finite() {
                        return Err(ShapeProblem::NonFiniteVertex { vertex: v });
                    }
                    out.push(xf.normal * *n);
                }
                Some(out)
            }
            _ => None,
        };
        let positions: Vec<DVec3> = mesh.positions.iter().map(|p| xf.point(*p)).collect();
        let scale = Bounds::from_points(positions.iter().copied())
            .diagonal()
            .length();
        let mut tri_normal = Vec::with_capacity(mesh.triangles.len());
        let mut tri_area = Vec::with_capacity(mesh.triangles.len());
        for tri in &mesh.triangles {
            let [a, b, c] = tri.map(|v| positions[v as usize]);
            let cr = (b - a).cross(c - a);
            let area = 0.5 * cr.length();
            if area > 1e-14 * scale * scale && area.is_finite() {
                tri_area.push(area);
                tri_normal.push(sign * cr / (2.0 * area));
            } else {
                tri_area.push(0.0);
                tri_normal.push(DVec3::ZERO);
            }
        }
        if tri_area.iter().all(|&a| a == 0.0) {
            return Err(ShapeProblem::ZeroArea);
        }
        let mesh_id = self.meshes.len() as u32;
        let mut data = MeshData {
            positions,
            triangles: mesh.triangles.clone(),
            shading_normals,
            tri_normal,
            tri_area,
            tri_surface: vec![u32::MAX; mesh.triangles.len()],
            tri_element: vec![u32::MAX; mesh.triangles.len()],
            sign,
        };
        let charts = build_charts(&data);
        for (k, chart) in charts.iter().enumerate() {
            let sid = self.surfaces.len() as u32;
            for &t in chart {
                data.tri_surface[t as usize] = sid;
            }
            let (front, back) = chart_self_visibility(&data, chart);
            let _ = k;
            self.surfaces.push(InputSurface {
                shape: index as u32,
                kind: SurfaceKind::Chart,
                root: ElementId(u32::MAX),
                bounds: Bounds::EMPTY,
                piece: k as u32,
                area: 0.0,
                planar: false,
                front_sees_itself: front,
                back_sees_itself: back,
                geom: SurfaceGeom::Chart { mesh: mesh_id },
            });
        }
        for (t, &s) in data.tri_surface.iter().enumerate() {
            if s != u32::MAX {
                let [a, b, c] = data.vertices(t as u32);
                prims.push(Prim::Tri {
                    v: [a, b, c],
                    owner: TriOwner::Mesh {
                        mesh: mesh_id,
                        tri: t as u32,
                    },
                });
            }
        }
        self.meshes.push(data);
        self.mesh_shape.push(index as u32);
        let first_sid = self.surfaces.len() - charts.len();
        for (k, chart) in charts.into_iter().enumerate() {
            let sid = SurfaceId((first_sid + k) as u32);
            let pieces: Vec<Piece> = chart.iter().map(|&t| Piece::whole(t)).collect();
            let root = self.make_cluster_element(sid, mesh_id, pieces, None, 0);
            let eid = ElementId(self.elements.len() as u32);
            let s = &mut self.surfaces[sid.index()];
            s.root = eid;
            s.bounds = root.bounds;
            s.area = root.area;
            s.planar = root.planar;
            self.elements.push(root);
        }
        Ok(())
    }
}

fn push_quad_prims(prims: &mut Vec<Prim>, surface: u32, p: &[DVec3; 4]) {
    prims.push(Prim::Tri {
        v: [p[0], p[1], p[2]],
        owner: TriOwner::Quad { surface },
    });
    prims.push(Prim::Tri {
        v: [p[0], p[2], p[3]],
        owner: TriOwner::Quad { surface },
    });
}

/// Whether the front (back) side of a chart can see its own front (back)
/// side: some triangle j has a vertex strictly in front of (behind) the
/// plane of triangle i while i has one strictly in front of (behind) j.
/// Only triangles with some chart vertex in front of (behind) their plane
/// can take part, so those are found first (O(n · vertices)); a convex
/// chart then costs no pair test at all.
fn chart_self_visibility(mesh: &MeshData, chart: &[u32]) -> (bool, bool) {
    let b = Bounds::from_points(chart.iter().flat_map(|&t| mesh.vertices(t)));
    let tol = 1e-9 * b.diagonal().length();
    let mut verts: Vec<u32> = chart
        .iter()
        .flat_map(|&t| mesh.triangles[t as usize])
        .collect();
    verts.sort_unstable();
    verts.dedup();
    let plane = |i: u32| (mesh.tri_normal[i as usize], mesh.vertices(i)[0]);
    let mut above = Vec::new();
    let mut below = Vec::new();
    for &i in chart {
        let (n, o) = plane(i);
        let d = verts.iter().map(|&v| n.dot(mesh.positions[v as usize] - o));
        let (mut a, mut bl) = (false, false);
        for x in d {
            a |= x > tol;
            bl |= x < -tol;
            if a && bl {
                break;
            }
        }
        if a {
            above.push(i);
        }
        if bl {
            below.push(i);
        }
    }
    let mutual = |set: &[u32], sign: f64| -> bool {
        let side = |i: u32, j: u32| {
            let (n, o) = plane(i);
            mesh.vertices(j).iter().any(|v| sign * n.dot(*v - o) > tol)
        };
        for (k, &i) in set.iter().enumerate() {
            for &j in &set[k + 1..] {
                if side(i, j) && side(j, i) {
                    return true;
                }
            }
        }
        false
    };
    (mutual(&above, 1.0), mutual(&below, -1.0))
}
