//! Every shape's leaf elements as welded triangles, each owned by the leaf
//! it covers.
//!
//! Rules:
//! - A parametric leaf (a (u, v) rectangle) is cut into m_u × m_v display
//!   cells, m powers of two, doubled along whichever direction brings the
//!   tessellated area closer to the leaf's exact area, until they are
//!   within `AREA_TOLERANCE` or the leaf has `MAX_CELLS` cells. A planar
//!   quad stays one cell; curved pieces and disks get as many as their
//!   curvature needs, so the baked flux is the solution's within that
//!   tolerance. A leaf cut at all is cut in both directions, so that its
//!   centre is a cell corner.
//! - A cell is a fan of triangles from its centre over its boundary: its
//!   corners, and every point where another cell's corner lies on one of
//!   its edges (found by halving the edge while its midpoint is such a
//!   corner: the element trees split at midpoints). Leaves at different
//!   depths therefore share their vertices — no cracks — across the
//!   surfaces of one shape too (a sphere's eight pieces).
//! - A chart leaf keeps its pieces, which are the mesh's own triangles or
//!   sub-triangles of them. A piece with another piece's corner on an edge,
//!   and the piece of a one-piece leaf, becomes a fan from its centroid.
//! - Vertices are welded per input surface by position (rounded to f32)
//!   when their normals are within `CREASE_DEG` and their texture
//!   coordinates agree (a mesh's texture seams keep their two vertices). Each surface keeps its
//!   own vertices, so that each keeps its own flux (`reconstruct`); where
//!   surfaces meet, their vertices take one position, the first computed,
//!   so the seam has no crack.
//! - Triangles are wound counter-clockwise seen from the front side;
//!   degenerate ones (a disk's centre, a sphere's poles) are left out.

use std::collections::{HashMap, HashSet};

use glam::{DVec2, DVec3};
use trilux_geometry::{
    ElementDomain, ElementForest, ElementId, Geometry, SurfaceCoord, SurfaceId, SurfacePoint,
};

/// Largest relative gap between a parametric leaf's tessellated area and
/// its exact area (unless `MAX_CELLS` stops the refinement first).
pub(crate) const AREA_TOLERANCE: f64 = 2e-3;
/// Most display cells per parametric leaf.
pub(crate) const MAX_CELLS: u32 = 1024;
/// Normals further apart than this keep separate vertices at one position.
pub(crate) const CREASE_DEG: f64 = 30.0;
/// Deepest halving of an edge when looking for a neighbour's corners.
const MAX_SPLIT_DEPTH: u32 = 30;

/// One shape's display mesh.
#[derive(Clone, Debug, Default)]
pub struct ShapeMesh {
    /// The shape's index in the scene.
    pub shape: u32,
    /// World-space vertex positions.
    pub positions: Vec<DVec3>,
    /// Front unit normals of the vertices.
    pub normals: Vec<DVec3>,
    /// Texture coordinates of the vertices (`Geometry::texcoord`), where
    /// the surface has them.
    pub texcoords: Vec<Option<DVec2>>,
    /// Where each vertex lies: its input surface and the surface's own
    /// coordinates (the first computed, for a welded vertex).
    pub sites: Vec<(SurfaceId, SurfaceCoord)>,
    /// Triangles, counter-clockwise seen from the front.
    pub triangles: Vec<[u32; 3]>,
    /// The leaf element each triangle covers part of.
    pub owners: Vec<ElementId>,
}

impl ShapeMesh {
    /// Area of triangle `t`.
    pub fn triangle_area(&self, t: usize) -> f64 {
        let [a, b, c] = self.triangles[t].map(|i| self.positions[i as usize]);
        0.5 * (b - a).cross(c - a).length()
    }
}

/// The display meshes of every shape of `forest`'s geometry (empty meshes
/// for shapes without surfaces), in shape order; the shapes for which
/// `textured` holds keep texture coordinates.
pub(crate) fn tessellate(forest: &ElementForest, textured: impl Fn(u32) -> bool) -> Vec<ShapeMesh> {
    let geometry = forest.geometry();
    let shapes = geometry
        .surfaces()
        .iter()
        .map(|s| s.shape + 1)
        .max()
        .unwrap_or(0);
    (0..shapes)
        .map(|shape| tessellate_shape(forest, shape, textured(shape)))
        .collect()
}

/// A polygon of a leaf to triangulate: its corners in the surface's own
/// coordinates, and whether it must be a fan even without split edges.
struct Cell {
    surface: SurfaceId,
    leaf: ElementId,
    /// The mesh triangle the corners are barycentrics of (charts).
    triangle: Option<u32>,
    corners: Vec<DVec2>,
    always_fan: bool,
}

impl Cell {
    fn coord(&self, p: DVec2) -> SurfaceCoord {
        match self.triangle {
            Some(index) => SurfaceCoord::Triangle { index, bary: p },
            None => SurfaceCoord::Uv(p),
        }
    }
}

fn tessellate_shape(forest: &ElementForest, shape: u32, textured: bool) -> ShapeMesh {
    let geometry = forest.geometry();
    let mut cells = Vec::new();
    for surface in geometry.surfaces_of_shape(shape) {
        for leaf in forest.leaves(forest.root(surface)) {
            leaf_cells(forest, surface, leaf, &mut cells);
        }
    }
    let mut b = Builder::new(geometry, shape, textured);
    for cell in &cells {
        for &c in &cell.corners {
            if let Some(p) = b.point(cell, c) {
                b.corners.insert(key(p.point));
            }
        }
    }
    for cell in &cells {
        b.triangulate(cell);
    }
    b.mesh
}

/// The cells of one leaf ([`Cell`]): display cells of a (u, v) rectangle,
/// or the pieces of a chart leaf.
fn leaf_cells(forest: &ElementForest, surface: SurfaceId, leaf: ElementId, out: &mut Vec<Cell>) {
    let element = forest.element(leaf);
    match element.domain {
        ElementDomain::Rect { min, max } => {
            let geometry = forest.geometry();
            let (mu, mv) = cell_counts(geometry, surface, min, max, element.area);
            let step = (max - min) / DVec2::new(f64::from(mu), f64::from(mv));
            for i in 0..mu {
                for j in 0..mv {
                    let lo = min + step * DVec2::new(f64::from(i), f64::from(j));
                    let hi = lo + step;
                    out.push(Cell {
                        surface,
                        leaf,
                        triangle: None,
                        corners: vec![lo, DVec2::new(hi.x, lo.y), hi, DVec2::new(lo.x, hi.y)],
                        always_fan: true,
                    });
                }
            }
        }
        ElementDomain::Cluster { .. } => {
            let pieces = forest.element_pieces(leaf);
            for piece in pieces {
                out.push(Cell {
                    surface,
                    leaf,
                    triangle: Some(piece.triangle),
                    corners: piece.bary.to_vec(),
                    always_fan: pieces.len() == 1,
                });
            }
        }
    }
}

/// Display cells (m_u, m_v) of the rectangle [min, max] (module docs).
fn cell_counts(
    geometry: &Geometry,
    surface: SurfaceId,
    min: DVec2,
    max: DVec2,
    exact: f64,
) -> (u32, u32) {
    let gap = |mu: u32, mv: u32| (exact - grid_area(geometry, surface, min, max, mu, mv)).abs();
    let (mut mu, mut mv) = (1, 1);
    while gap(mu, mv) > AREA_TOLERANCE * exact && mu * mv < MAX_CELLS {
        if gap(2 * mu, mv) <= gap(mu, 2 * mv) {
            mu *= 2;
        } else {
            mv *= 2;
        }
    }
    // The leaf's centre must be a vertex touching only this leaf's cells
    // (`reconstruct`): a 1 × m or m × 1 grid has it mid-edge.
    if (mu == 1) != (mv == 1) {
        (mu.max(2), mv.max(2))
    } else {
        (mu, mv)
    }
}

/// Area of the centre fans of an m_u × m_v grid of cells over [min, max].
fn grid_area(
    geometry: &Geometry,
    surface: SurfaceId,
    min: DVec2,
    max: DVec2,
    mu: u32,
    mv: u32,
) -> f64 {
    let at = |uv: DVec2| {
        geometry
            .surface_point(surface, SurfaceCoord::Uv(uv))
            .map_or(DVec3::ZERO, |p| p.point)
    };
    let step = (max - min) / DVec2::new(f64::from(mu), f64::from(mv));
    let mut area = 0.0;
    for i in 0..mu {
        for j in 0..mv {
            let lo = min + step * DVec2::new(f64::from(i), f64::from(j));
            let c = at(lo + 0.5 * step);
            let ring = [
                lo,
                lo + DVec2::new(step.x, 0.0),
                lo + step,
                lo + DVec2::new(0.0, step.y),
            ]
            .map(at);
            for k in 0..4 {
                area += 0.5 * (ring[k] - c).cross(ring[(k + 1) % 4] - c).length();
            }
        }
    }
    area
}

/// A position as the welding key: its coordinates rounded to f32 (−0 as
/// +0).
fn key(p: DVec3) -> [u32; 3] {
    p.as_vec3().to_array().map(|x| (x + 0.0).to_bits())
}

/// A located point: where it is, its texture coordinates, its surface
/// coordinates.
type Located = (SurfacePoint, Option<DVec2>, SurfaceCoord);

/// Builds one shape's mesh: the corner set, the welded vertices.
struct Builder<'g> {
    geometry: &'g Geometry,
    /// Every cell corner of the shape (for split edges).
    corners: HashSet<[u32; 3]>,
    /// Welded vertices by position key and surface.
    welded: HashMap<([u32; 3], SurfaceId), Vec<u32>>,
    /// The position every key was first given.
    canonical: HashMap<[u32; 3], DVec3>,
    crease_cos: f64,
    min_area: f64,
    textured: bool,
    mesh: ShapeMesh,
}

impl<'g> Builder<'g> {
    fn new(geometry: &'g Geometry, shape: u32, textured: bool) -> Self {
        let extent = geometry.extent().max(f64::MIN_POSITIVE);
        Builder {
            geometry,
            corners: HashSet::new(),
            welded: HashMap::new(),
            canonical: HashMap::new(),
            crease_cos: CREASE_DEG.to_radians().cos(),
            min_area: 1e-14 * extent * extent,
            textured,
            mesh: ShapeMesh {
                shape,
                ..ShapeMesh::default()
            },
        }
    }

    fn point(&self, cell: &Cell, p: DVec2) -> Option<SurfacePoint> {
        self.geometry.surface_point(cell.surface, cell.coord(p))
    }

    /// The point `p` of `cell` with its texture coordinates.
    fn located(&self, cell: &Cell, p: DVec2) -> Option<Located> {
        let coord = cell.coord(p);
        let point = self.geometry.surface_point(cell.surface, coord)?;
        let uv = match self.textured {
            true => self.geometry.texcoord(cell.surface, coord),
            false => None,
        };
        Some((point, uv, coord))
    }

    /// The welded vertex of `surface` at `p` with texture coordinates `uv`.
    fn vertex(&mut self, surface: SurfaceId, (p, uv, coord): Located) -> u32 {
        let k = key(p.point);
        let point = *self.canonical.entry(k).or_insert(p.point);
        let bucket = self.welded.entry((k, surface)).or_default();
        let (normals, texcoords) = (&self.mesh.normals, &self.mesh.texcoords);
        let same = |v: u32| {
            normals[v as usize].dot(p.normal) >= self.crease_cos && texcoords[v as usize] == uv
        };
        if let Some(&v) = bucket.iter().find(|&&v| same(v)) {
            return v;
        }
        let v = self.mesh.positions.len() as u32;
        self.mesh.positions.push(point);
        self.mesh.normals.push(p.normal);
        self.mesh.texcoords.push(uv);
        self.mesh.sites.push((surface, coord));
        bucket.push(v);
        v
    }

    /// The points of edge (a, b), b excluded, where other cells' corners
    /// split it. An edge that is one point in space (a disk's centre, a
    /// sphere's pole) is never split.
    fn edge(&self, cell: &Cell, a: DVec2, b: DVec2, depth: u32, out: &mut Vec<DVec2>) {
        let m = 0.5 * (a + b);
        let at = |p: DVec2| self.point(cell, p).map(|s| key(s.point));
        let split = depth < MAX_SPLIT_DEPTH
            && at(m)
                .is_some_and(|k| self.corners.contains(&k) && Some(k) != at(a) && Some(k) != at(b));
        if split {
            self.edge(cell, a, m, depth + 1, out);
            self.edge(cell, m, b, depth + 1, out);
        } else {
            out.push(a);
        }
    }

    /// The cell's triangles (module docs).
    fn triangulate(&mut self, cell: &Cell) {
        let n = cell.corners.len();
        let mut ring = Vec::with_capacity(n);
        for k in 0..n {
            self.edge(
                cell,
                cell.corners[k],
                cell.corners[(k + 1) % n],
                0,
                &mut ring,
            );
        }
        let ring: Vec<_> = ring.iter().filter_map(|&c| self.located(cell, c)).collect();
        if ring.len() == 3 && !cell.always_fan {
            let front = ring[0].0.normal + ring[1].0.normal + ring[2].0.normal;
            let v = [ring[0], ring[1], ring[2]].map(|p| self.vertex(cell.surface, p));
            self.triangle(v, front, cell.leaf);
            return;
        }
        let centre = cell.corners.iter().sum::<DVec2>() / n as f64;
        let Some(c) = self.located(cell, centre) else {
            return;
        };
        let front = c.0.normal;
        let cv = self.vertex(cell.surface, c);
        let vs: Vec<u32> = ring.iter().map(|&p| self.vertex(cell.surface, p)).collect();
        for k in 0..vs.len() {
            self.triangle([cv, vs[k], vs[(k + 1) % vs.len()]], front, cell.leaf);
        }
    }

    /// Adds a triangle wound to face `front`, unless it is degenerate.
    fn triangle(&mut self, mut v: [u32; 3], front: DVec3, leaf: ElementId) {
        let [a, b, c] = v.map(|i| self.mesh.positions[i as usize]);
        let n = (b - a).cross(c - a);
        if v[0] == v[1] || v[1] == v[2] || v[0] == v[2] || 0.5 * n.length() <= self.min_area {
            return;
        }
        if n.dot(front) < 0.0 {
            v.swap(1, 2);
        }
        self.mesh.triangles.push(v);
        self.mesh.owners.push(leaf);
    }
}
