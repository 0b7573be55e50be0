//! From shapes to [`Geometry`]: every shape becomes input surfaces (its
//! parametric pieces, or the charts of a mesh) and BVH primitives.
//!
//! - rectangle: one planar quad (two triangles in the BVH);
//! - cube: six planar quads, their corners shared bit for bit;
//! - disk: one planar polar patch, intersected analytically;
//! - sphere: 8 curved pieces (4 quarter-turns in φ × 2 hemispheres), one
//!   analytic primitive for the whole sphere (so its seams cannot leak);
//! - cylinder: 4 curved quarter-turn pieces of an open tube, one analytic
//!   primitive;
//! - mesh: charts ([`crate::chart`]), every non-degenerate triangle a BVH
//!   primitive (a repeat of an earlier triangle counts as degenerate).
//!
//! Errors name the shape ([`GeometryError`]).

use std::f64::consts::FRAC_PI_2;
use std::sync::Arc;

use glam::{DVec2, DVec3};

use crate::bounds::Bounds;
use crate::bvh::{Analytic, AnalyticKind, Bvh, Prim, TriOwner};
use crate::chart::{MeshData, Piece, build_charts, cluster_element};
use crate::contact::{Cuts, cut_mesh, find_cuts};
use crate::element::rect_element;
use crate::error::{GeometryError, ShapeProblem};
use crate::geometry::Geometry;
use crate::ids::SurfaceId;
use crate::limits::{MAX_OFFSET_RATIO, MIN_SCENE_SIZE, within};
use crate::patch::Patch;
use crate::shape::{Shape, ShapeKind, TriangleMesh};
use crate::surface::{InputSurface, SurfaceGeom, SurfaceKind};
use crate::transform::Affine;

impl Geometry {
    /// Turns shapes into input surfaces and a BVH.
    ///
    /// Errors name the offending shape: non-finite or singular transforms,
    /// non-finite parameters, non-positive radii, zero area, bad mesh
    /// indices, coordinates outside [`crate::limits`] (checked before the
    /// BVH is built). Non-uniform scale and shear are supported for every
    /// shape (a sphere becomes an exact ellipsoid, a disk an exact
    /// ellipse).
    pub fn build(shapes: &[Shape]) -> Result<Geometry, GeometryError> {
        let (b, reach) = add_shapes(shapes, Cuts::new())?;
        check_scale(&b, &reach)?;
        // Mesh triangles that other surfaces end on are cut along those
        // contacts ([`crate::contact`]), which needs every shape's
        // triangles: the shapes are added again with the cuts, only when
        // there are any.
        let cuts = find_cuts(&b.prims);
        let b = if cuts.is_empty() {
            b
        } else {
            add_shapes(shapes, cuts)?.0
        };
        Ok(b.finish())
    }

    /// [`Geometry::build`], shared.
    pub fn build_shared(shapes: &[Shape]) -> Result<Arc<Geometry>, GeometryError> {
        Geometry::build(shapes).map(Arc::new)
    }
}

/// Every shape added to a builder that makes `cuts`, and each shape's
/// (largest coordinate, diagonal).
fn add_shapes(shapes: &[Shape], cuts: Cuts) -> Result<(Builder, Vec<(f64, f64)>), GeometryError> {
    let mut b = Builder {
        cuts,
        ..Builder::default()
    };
    let mut reach = Vec::with_capacity(shapes.len());
    for (index, shape) in shapes.iter().enumerate() {
        b.shape = index as u32;
        let first = b.surfaces.len();
        let err = |problem| GeometryError {
            shape: index,
            problem,
        };
        b.add_shape(shape).map_err(err)?;
        let bounds = b.surfaces[first..]
            .iter()
            .fold(Bounds::EMPTY, |acc, s| acc.union(s.bounds));
        let coordinate = largest_coordinate(&bounds);
        if !within(coordinate) {
            return Err(err(ShapeProblem::BeyondCoordinateLimit { coordinate }));
        }
        reach.push((coordinate, bounds.diagonal().length()));
    }
    Ok((b, reach))
}

/// The largest absolute coordinate of a box (0 for an empty one).
fn largest_coordinate(b: &Bounds) -> f64 {
    if b.is_empty() {
        return 0.0;
    }
    b.min.abs().max(b.max.abs()).max_element()
}

/// Refuses a scene too small, or too far from the origin for its size
/// ([`crate::limits`]), naming the largest shape or the one reaching
/// furthest. `reach` is each shape's (largest coordinate, diagonal).
fn check_scale(b: &Builder, reach: &[(f64, f64)]) -> Result<(), GeometryError> {
    let bounds = b
        .surfaces
        .iter()
        .fold(Bounds::EMPTY, |a, s| a.union(s.bounds));
    if bounds.is_empty() {
        return Ok(());
    }
    let size = bounds.diagonal().length();
    let pick = |key: fn(&(f64, f64)) -> f64| {
        (0..reach.len())
            .max_by(|&i, &j| key(&reach[i]).total_cmp(&key(&reach[j])))
            .unwrap_or(0)
    };
    if size < MIN_SCENE_SIZE {
        return Err(GeometryError {
            shape: pick(|r| r.1),
            problem: ShapeProblem::SceneTooSmall { size },
        });
    }
    let far = pick(|r| r.0);
    let coordinate = reach.get(far).map_or(0.0, |r| r.0);
    if coordinate > MAX_OFFSET_RATIO * size {
        return Err(GeometryError {
            shape: far,
            problem: ShapeProblem::FarFromOrigin { coordinate, size },
        });
    }
    Ok(())
}

/// What the shapes become, collected shape by shape.
#[derive(Default)]
struct Builder {
    /// The shape being added.
    shape: u32,
    surfaces: Vec<InputSurface>,
    meshes: Vec<MeshData>,
    analytic: Vec<Analytic>,
    prims: Vec<Prim>,
    /// The cuts of mesh triangles to make ([`crate::contact`]).
    cuts: Cuts,
}

impl Builder {
    fn finish(self) -> Geometry {
        let bounds = self
            .surfaces
            .iter()
            .fold(Bounds::EMPTY, |b, s| b.union(s.bounds));
        let extent = if bounds.is_empty() {
            1.0
        } else {
            bounds
                .min
                .abs()
                .max(bounds.max.abs())
                .max_element()
                .max(1e-300)
        };
        let bvh = Bvh::build(self.prims, self.analytic, bounds, extent);
        Geometry {
            surfaces: self.surfaces,
            meshes: self.meshes,
            bvh,
            bounds,
            extent,
            transmitters: Vec::new(),
        }
    }

    fn next_surface(&self) -> u32 {
        self.surfaces.len() as u32
    }

    fn add_shape(&mut self, shape: &Shape) -> Result<(), ShapeProblem> {
        let xf = Affine::new(shape.world_from_object)?;
        let sign = if shape.flip_normals { -1.0 } else { 1.0 };
        match &shape.kind {
            ShapeKind::Rectangle => self.add_rectangle(&xf, sign),
            ShapeKind::Cube => self.add_cube(&xf, sign),
            ShapeKind::Disk => self.add_disk(xf, sign),
            ShapeKind::Sphere { center, radius } => self.add_sphere(xf, sign, *center, *radius),
            ShapeKind::Cylinder { p0, p1, radius } => {
                self.add_cylinder(xf, sign, *p0, *p1, *radius)
            }
            ShapeKind::Mesh(mesh) => self.add_mesh(mesh, &xf, sign),
        }
    }

    /// One parametric input surface; `sees` is whether its (front, back)
    /// can see itself.
    fn push_patch(
        &mut self,
        piece: u32,
        kind: SurfaceKind,
        patch: Patch,
        sees: (bool, bool),
    ) -> Result<(), ShapeProblem> {
        let id = SurfaceId(self.next_surface());
        let root = rect_element(&patch, id, DVec2::ZERO, DVec2::ONE, None, 0);
        if root.area <= 0.0 || !root.area.is_finite() {
            return Err(ShapeProblem::ZeroArea);
        }
        self.surfaces.push(InputSurface {
            shape: self.shape,
            kind,
            bounds: root.bounds,
            piece,
            area: root.area,
            planar: patch.is_planar(),
            front_sees_itself: sees.0,
            back_sees_itself: sees.1,
            geom: SurfaceGeom::Patch(Box::new(patch)),
        });
        Ok(())
    }

    /// A planar quad (p00, p10, p11, p01) as an input surface and two
    /// BVH triangles.
    fn push_quad(&mut self, piece: u32, p: [DVec3; 4], normal: DVec3) -> Result<(), ShapeProblem> {
        let surface = self.next_surface();
        self.push_patch(
            piece,
            SurfaceKind::Planar,
            Patch::Quad { p, normal },
            (false, false),
        )?;
        // Rectangles and cube faces are affine images of squares, so
        // parallelograms up to rounding: (u, v) is then affine in the
        // barycentrics of either half.
        let scale = (p[1] - p[0]).abs().max((p[3] - p[0]).abs()).max_element();
        let affine = (p[0] + p[2] - p[1] - p[3]).abs().max_element() <= 1e-12 * scale;
        for (second, v) in [(false, [p[0], p[1], p[2]]), (true, [p[0], p[2], p[3]])] {
            self.prims.push(Prim::Tri {
                v,
                normal,
                surface,
                owner: TriOwner::Quad { second, affine },
                shape: self.shape,
            });
        }
        Ok(())
    }

    fn push_analytic(&mut self, kind: AnalyticKind, xf: Affine, first_surface: u32, sign: f64) {
        let index = self.analytic.len() as u32;
        self.analytic.push(Analytic {
            kind,
            xf,
            first_surface,
            sign,
        });
        self.prims.push(Prim::Analytic {
            index,
            shape: self.shape,
        });
    }

    fn add_rectangle(&mut self, xf: &Affine, sign: f64) -> Result<(), ShapeProblem> {
        let p = [
            DVec3::new(-1.0, -1.0, 0.0),
            DVec3::new(1.0, -1.0, 0.0),
            DVec3::new(1.0, 1.0, 0.0),
            DVec3::new(-1.0, 1.0, 0.0),
        ]
        .map(|c| xf.point(c));
        self.push_quad(0, p, sign * xf.normal(DVec3::Z))
    }

    fn add_cube(&mut self, xf: &Affine, sign: f64) -> Result<(), ShapeProblem> {
        let corner = |i: usize| {
            xf.point(DVec3::new(
                if i & 1 != 0 { 1.0 } else { -1.0 },
                if i & 2 != 0 { 1.0 } else { -1.0 },
                if i & 4 != 0 { 1.0 } else { -1.0 },
            ))
        };
        let c: Vec<DVec3> = (0..8).map(corner).collect();
        // Faces as (p00, p10, p11, p01) with (p10−p00)×(p01−p00) pointing
        // outwards in object space: −x, +x, −y, +y, −z, +z.
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
            // Mitsuba's cube is a mesh: the front follows the world winding
            // of its triangles.
            let normal = sign * (p[1] - p[0]).cross(p[3] - p[0]).normalize();
            self.push_quad(k as u32, p, normal)?;
        }
        Ok(())
    }

    fn add_disk(&mut self, xf: Affine, sign: f64) -> Result<(), ShapeProblem> {
        let first = self.next_surface();
        self.push_patch(
            0,
            SurfaceKind::Planar,
            Patch::Disk { xf, sign },
            (false, false),
        )?;
        self.push_analytic(AnalyticKind::Disk, xf, first, sign);
        Ok(())
    }

    fn add_sphere(
        &mut self,
        xf: Affine,
        sign: f64,
        centre: DVec3,
        radius: f64,
    ) -> Result<(), ShapeProblem> {
        check_finite(centre, "center")?;
        check_radius(radius)?;
        let first = self.next_surface();
        // The inside sees itself: the back of outward normals, the front of
        // flipped ones.
        let flip = sign < 0.0;
        for j in 0..2u32 {
            for i in 0..4u32 {
                let patch = Patch::Sphere {
                    xf,
                    centre,
                    radius,
                    phi0: i as f64 * FRAC_PI_2,
                    theta0: j as f64 * FRAC_PI_2,
                    sign,
                };
                self.push_patch(j * 4 + i, SurfaceKind::Curved, patch, (flip, !flip))?;
            }
        }
        self.push_analytic(AnalyticKind::Sphere { centre, radius }, xf, first, sign);
        Ok(())
    }

    fn add_cylinder(
        &mut self,
        xf: Affine,
        sign: f64,
        p0: DVec3,
        p1: DVec3,
        radius: f64,
    ) -> Result<(), ShapeProblem> {
        check_finite(p0, "p0")?;
        check_finite(p1, "p1")?;
        check_radius(radius)?;
        let axis = p1 - p0;
        let Some(dir) = axis.try_normalize() else {
            return Err(ShapeProblem::DegenerateAxis);
        };
        let (e1, e2) = dir.any_orthonormal_pair();
        let first = self.next_surface();
        let flip = sign < 0.0;
        for i in 0..4u32 {
            let patch = Patch::Cylinder {
                xf,
                p0,
                axis,
                e1,
                e2,
                radius,
                phi0: i as f64 * FRAC_PI_2,
                sign,
            };
            self.push_patch(i, SurfaceKind::Curved, patch, (flip, !flip))?;
        }
        let kind = AnalyticKind::Cylinder {
            p0,
            axis,
            e1,
            e2,
            radius,
        };
        self.push_analytic(kind, xf, first, sign);
        Ok(())
    }

    /// A mesh: checked, moved to world space, split into charts (each an
    /// input surface), its triangles made BVH primitives.
    fn add_mesh(
        &mut self,
        mesh: &TriangleMesh,
        xf: &Affine,
        sign: f64,
    ) -> Result<(), ShapeProblem> {
        check_mesh(mesh)?;
        let mut data = world_mesh(mesh, xf, sign)?;
        let mesh_id = self.meshes.len() as u32;
        let cells = match self.cuts.remove(&self.shape) {
            Some(cuts) => cut_mesh(&mut data, &cuts),
            None => Vec::new(),
        };
        let charts = build_charts(&data, cells);
        let first = self.next_surface();
        for (k, chart) in charts.iter().enumerate() {
            for &t in chart {
                data.tri_surface[t as usize] = first + k as u32;
            }
        }
        for (k, chart) in charts.into_iter().enumerate() {
            let (front, back) = chart_self_visibility(&data, &chart);
            let pieces: Vec<Piece> = chart.iter().map(|&t| Piece::whole(t)).collect();
            let id = SurfaceId(first + k as u32);
            let (root, _) = cluster_element(&data, id, pieces, None, 0, 0);
            self.surfaces.push(InputSurface {
                shape: self.shape,
                kind: SurfaceKind::Chart,
                bounds: root.bounds,
                piece: k as u32,
                area: root.area,
                planar: root.is_planar(),
                front_sees_itself: front,
                back_sees_itself: back,
                geom: SurfaceGeom::Chart {
                    mesh: mesh_id,
                    triangles: chart,
                },
            });
        }
        for (t, &s) in data.tri_surface.iter().enumerate() {
            if s != u32::MAX {
                self.prims.push(Prim::Tri {
                    v: data.vertices(t as u32),
                    normal: data.tri_normal[t],
                    surface: s,
                    owner: TriOwner::Mesh {
                        mesh: mesh_id,
                        tri: t as u32,
                    },
                    shape: self.shape,
                });
            }
        }
        self.meshes.push(data);
        Ok(())
    }
}

fn check_finite(p: DVec3, what: &'static str) -> Result<(), ShapeProblem> {
    if p.is_finite() {
        Ok(())
    } else {
        Err(ShapeProblem::NonFinite { what })
    }
}

fn check_radius(radius: f64) -> Result<(), ShapeProblem> {
    if !radius.is_finite() {
        return Err(ShapeProblem::NonFinite { what: "radius" });
    }
    if radius <= 0.0 {
        return Err(ShapeProblem::BadRadius { radius });
    }
    Ok(())
}

/// Refuses empty meshes, non-finite vertices and out-of-range indices.
fn check_mesh(mesh: &TriangleMesh) -> Result<(), ShapeProblem> {
    if mesh.triangles.is_empty() {
        return Err(ShapeProblem::EmptyMesh);
    }
    let count = mesh.positions.len();
    if let Some(vertex) = mesh.positions.iter().position(|p| !p.is_finite()) {
        return Err(ShapeProblem::NonFiniteVertex { vertex });
    }
    for (t, tri) in mesh.triangles.iter().enumerate() {
        if let Some(&v) = tri.iter().find(|&&v| v as usize >= count) {
            return Err(ShapeProblem::IndexOutOfRange {
                triangle: t,
                vertex: v,
                count,
            });
        }
    }
    Ok(())
}

/// World-space shading normals, when the mesh has usable ones.
fn world_shading_normals(
    mesh: &TriangleMesh,
    xf: &Affine,
) -> Result<Option<Vec<DVec3>>, ShapeProblem> {
    let (Some(ns), false) = (&mesh.normals, mesh.face_normals) else {
        return Ok(None);
    };
    if ns.len() != mesh.positions.len() {
        return Err(ShapeProblem::NormalCountMismatch {
            normals: ns.len(),
            positions: mesh.positions.len(),
        });
    }
    if let Some(vertex) = ns.iter().position(|n| !n.is_finite()) {
        return Err(ShapeProblem::NonFiniteVertex { vertex });
    }
    Ok(Some(ns.iter().map(|n| xf.normal * *n).collect()))
}

/// The mesh in world space with per-triangle normals and areas; triangles
/// of area below 1e-14 of the mesh's squared diagonal count as degenerate
/// (zero area, no chart), and so does a repeat of an earlier triangle
/// ([`drop_repeats`]). Refuses a mesh whose triangles are all
/// degenerate.
fn world_mesh(mesh: &TriangleMesh, xf: &Affine, sign: f64) -> Result<MeshData, ShapeProblem> {
    let shading_normals = world_shading_normals(mesh, xf)?;
    let positions: Vec<DVec3> = mesh.positions.iter().map(|p| xf.point(*p)).collect();
    // Before any work on them: charts of points beyond the limit mean
    // nothing (and their areas may overflow).
    if let Some(coordinate) = positions
        .iter()
        .map(|p| p.abs().max_element())
        .find(|c| !within(*c))
    {
        return Err(ShapeProblem::BeyondCoordinateLimit { coordinate });
    }
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
    drop_repeats(&positions, &mesh.triangles, &mut tri_area, &mut tri_normal);
    if tri_area.iter().all(|&a| a == 0.0) {
        return Err(ShapeProblem::ZeroArea);
    }
    Ok(MeshData {
        positions,
        triangles: mesh.triangles.clone(),
        shading_normals,
        tri_normal,
        tri_area,
        tri_surface: vec![u32::MAX; mesh.triangles.len()],
        sign,
        texcoords: mesh
            .texcoords
            .clone()
            .filter(|t| t.len() == mesh.positions.len()),
    })
}

/// Leaves out (as degenerate: zero area, no chart, not traced) every
/// triangle whose three corners, in either winding, are those of an
/// earlier triangle of the mesh, and returns how many. A triangle already
/// has both sides, so a repeat adds no surface: it would receive and
/// reflect the surface's light a second time, and every ray through a
/// stack of copies tests each of them (200 000 copies of one triangle
/// made every ray test 200 000 triangles).
fn drop_repeats(
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    area: &mut [f64],
    normal: &mut [DVec3],
) -> usize {
    let mut weld: std::collections::HashMap<[u64; 3], u32> = Default::default();
    let canon: Vec<u32> = positions
        .iter()
        .map(|p| {
            let next = weld.len() as u32;
            *weld.entry(p.to_array().map(f64::to_bits)).or_insert(next)
        })
        .collect();
    let mut seen = std::collections::HashSet::with_capacity(triangles.len());
    let mut dropped = 0;
    for (t, tri) in triangles.iter().enumerate() {
        if area[t] == 0.0 {
            continue;
        }
        let mut key = tri.map(|v| canon[v as usize]);
        key.sort_unstable();
        if !seen.insert(key) {
            area[t] = 0.0;
            normal[t] = DVec3::ZERO;
            dropped += 1;
        }
    }
    dropped
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
