//! [`ElementForest`]: the element trees of every input surface of a
//! [`Geometry`], in one arena (paper §3.2).
//!
//! The forest owns what subdivision changes — the elements and the pieces
//! of chart clusters — and shares the immutable geometry it refines. Every
//! input surface has one root, created with the forest, and
//! `root(surface) == ElementId(surface)`. Children are made lazily by
//! [`ElementForest::subdivide`] (idempotent): the four uv quadrants of a
//! parametric element, evaluated on the true surface, or the four
//! sub-clusters of a chart element ([`crate::chart`]).

use std::sync::Arc;

use glam::{DVec2, DVec3};

use crate::chart::{Piece, cluster_element, split_cluster};
use crate::element::{Element, ElementDomain, rect_element};
use crate::geometry::Geometry;
use crate::ids::{ElementId, SurfaceId};
use crate::sampling::{SurfaceSample, piece_ends, sample_cluster, sample_rect};
use crate::surface::{SurfaceCoord, SurfaceGeom};

/// The element trees of a scene (see the module docs).
#[derive(Clone, Debug)]
pub struct ElementForest {
    geometry: Arc<Geometry>,
    elements: Vec<Element>,
    pieces: Vec<Piece>,
    /// Per piece, the running sum of its element's piece areas up to it
    /// (`sampling::piece_ends`), for sampling in O(log n).
    piece_ends: Vec<f64>,
    /// Per mesh, per triangle: the deepest element holding the whole
    /// triangle (a shortcut for `locate`).
    tri_element: Vec<Vec<u32>>,
}

impl ElementForest {
    /// The forest of roots only: one element per input surface.
    pub fn new(geometry: Arc<Geometry>) -> ElementForest {
        let mut forest = ElementForest {
            tri_element: geometry
                .meshes
                .iter()
                .map(|m| vec![u32::MAX; m.triangles.len()])
                .collect(),
            geometry,
            elements: Vec::new(),
            pieces: Vec::new(),
            piece_ends: Vec::new(),
        };
        for s in 0..forest.geometry.surfaces().len() as u32 {
            let root = forest.make_root(SurfaceId(s));
            forest.elements.push(root);
        }
        forest
    }

    fn make_root(&mut self, surface: SurfaceId) -> Element {
        let g = Arc::clone(&self.geometry);
        match &g.surface(surface).geom {
            SurfaceGeom::Patch(patch) => {
                rect_element(patch, surface, DVec2::ZERO, DVec2::ONE, None, 0)
            }
            SurfaceGeom::Chart { mesh, triangles } => {
                let pieces = triangles.iter().map(|&t| Piece::whole(t)).collect();
                self.push_cluster(surface, *mesh, pieces, None, 0)
            }
        }
    }

    /// The geometry these trees refine.
    pub fn geometry(&self) -> &Geometry {
        &self.geometry
    }

    /// The geometry, shared.
    pub fn shared_geometry(&self) -> &Arc<Geometry> {
        &self.geometry
    }

    /// The root element of an input surface.
    #[inline]
    pub fn root(&self, surface: SurfaceId) -> ElementId {
        ElementId(surface.0)
    }

    /// The element with this id. Panics if the id is not from this forest.
    #[inline]
    pub fn element(&self, id: ElementId) -> &Element {
        &self.elements[id.index()]
    }

    /// Number of elements created so far (roots and all children).
    pub fn element_count(&self) -> usize {
        self.elements.len()
    }

    /// The pieces of a chart element (empty for parametric elements).
    pub fn element_pieces(&self, id: ElementId) -> &[Piece] {
        match self.elements[id.index()].domain {
            ElementDomain::Cluster { first, count } => {
                &self.pieces[first as usize..(first + count) as usize]
            }
            ElementDomain::Rect { .. } => &[],
        }
    }

    /// The running sums of a chart element's piece areas.
    fn element_piece_ends(&self, id: ElementId) -> &[f64] {
        match self.elements[id.index()].domain {
            ElementDomain::Cluster { first, count } => {
                &self.piece_ends[first as usize..(first + count) as usize]
            }
            ElementDomain::Rect { .. } => &[],
        }
    }

    /// The leaves under `id` (itself when it has no children), depth first.
    pub fn leaves(&self, id: ElementId) -> Vec<ElementId> {
        let mut out = Vec::new();
        let mut stack = vec![id];
        while let Some(e) = stack.pop() {
            match self.element(e).children() {
                Some(c) => stack.extend(c),
                None => out.push(e),
            }
        }
        out
    }

    /// Stores a cluster element's pieces and makes it the deepest element
    /// holding each of its whole triangles (the caller pushes it next).
    fn push_cluster(
        &mut self,
        surface: SurfaceId,
        mesh: u32,
        pieces: Vec<Piece>,
        parent: Option<ElementId>,
        depth: u32,
    ) -> Element {
        let m = &self.geometry.meshes[mesh as usize];
        let first = self.pieces.len() as u32;
        let (element, pieces) = cluster_element(m, surface, pieces, parent, depth, first);
        let id = self.elements.len() as u32;
        for p in pieces.iter().filter(|p| p.is_whole()) {
            self.tri_element[mesh as usize][p.triangle as usize] = id;
        }
        self.piece_ends.extend(piece_ends(m, &pieces));
        self.pieces.extend(pieces);
        element
    }

    /// Splits an element into its four children (creating them on first
    /// call; later calls return the same ids). Children lie on the true
    /// surface.
    pub fn subdivide(&mut self, id: ElementId) -> [ElementId; 4] {
        if let Some(c) = self.elements[id.index()].children() {
            return c;
        }
        let parent = self.elements[id.index()].clone();
        let surface = parent.surface;
        let first = self.elements.len() as u32;
        let g = Arc::clone(&self.geometry);
        match (parent.domain, &g.surface(surface).geom) {
            (ElementDomain::Rect { min, max }, SurfaceGeom::Patch(patch)) => {
                let mid = 0.5 * (min + max);
                let quads = [
                    (min, mid),
                    (DVec2::new(mid.x, min.y), DVec2::new(max.x, mid.y)),
                    (DVec2::new(min.x, mid.y), DVec2::new(mid.x, max.y)),
                    (mid, max),
                ];
                for (a, b) in quads {
                    let e = rect_element(patch, surface, a, b, Some(id), parent.depth + 1);
                    self.elements.push(e);
                }
            }
            (ElementDomain::Cluster { .. }, SurfaceGeom::Chart { mesh, .. }) => {
                let own = self.element_pieces(id).to_vec();
                let groups = split_cluster(&own, &g.meshes[*mesh as usize]);
                for group in groups {
                    let e = self.push_cluster(surface, *mesh, group, Some(id), parent.depth + 1);
                    self.elements.push(e);
                }
            }
            _ => unreachable!("element domain does not match its surface"),
        }
        self.elements[id.index()].first_child = first;
        [
            ElementId(first),
            ElementId(first + 1),
            ElementId(first + 2),
            ElementId(first + 3),
        ]
    }

    /// Subdivides a surface's tree uniformly, `depth` levels below its root.
    pub fn subdivide_to_depth(&mut self, surface: SurfaceId, depth: u32) {
        let mut level = vec![self.root(surface)];
        for _ in 0..depth {
            let mut next = Vec::with_capacity(level.len() * 4);
            for e in level {
                next.extend(self.subdivide(e));
            }
            level = next;
        }
    }

    /// Area-weighted sums of the shading normals and of the geometric
    /// normals over a chart element's pieces, (Σ A n_s, Σ A n_g), when its
    /// mesh has smooth shading normals; `None` otherwise. The irradiance a
    /// Lambertian BSDF sees about its shading normals, from a distant
    /// source in direction d, is (Σ A n_s · d)/(Σ A n_g · d) times the one
    /// about the geometric normals.
    pub fn shading_moments(&self, id: ElementId) -> Option<(DVec3, DVec3)> {
        let m = self
            .geometry
            .chart_mesh(self.elements[id.index()].surface)?;
        m.shading_normals.as_ref()?;
        let (mut s, mut g) = (DVec3::ZERO, DVec3::ZERO);
        for p in self.element_pieces(id) {
            let a = m.tri_area[p.triangle as usize] * p.area_fraction();
            let centre = (p.bary[0] + p.bary[1] + p.bary[2]) / 3.0;
            s += a * m.shading_normal(p.triangle, centre);
            g += a * m.tri_normal[p.triangle as usize];
        }
        Some((s, g))
    }

    /// True if the surface point `coord` lies in element `id` (boundaries
    /// included).
    pub fn element_contains(&self, id: ElementId, coord: SurfaceCoord) -> bool {
        let e = &self.elements[id.index()];
        match (e.domain, coord) {
            (ElementDomain::Rect { min, max }, SurfaceCoord::Uv(uv)) => {
                uv.x >= min.x && uv.x <= max.x && uv.y >= min.y && uv.y <= max.y
            }
            (ElementDomain::Cluster { .. }, SurfaceCoord::Triangle { index, bary }) => self
                .element_pieces(id)
                .iter()
                .any(|p| p.contains(index, bary)),
            _ => false,
        }
    }

    /// The deepest existing element of `surface` containing `coord` (the
    /// root if the coordinate kind does not match the surface).
    pub fn locate(&self, surface: SurfaceId, coord: SurfaceCoord) -> ElementId {
        let mut id = self.locate_start(surface, coord);
        while let Some(children) = self.elements[id.index()].children() {
            match self.child_containing(id, children, coord) {
                Some(n) => id = n,
                None => break,
            }
        }
        id
    }

    /// Where `locate` starts: for a chart, the deepest element holding the
    /// whole triangle (below it, clusters have fewer than 4 pieces).
    fn locate_start(&self, surface: SurfaceId, coord: SurfaceCoord) -> ElementId {
        if let (Some(mesh), SurfaceCoord::Triangle { index, .. }) =
            (self.geometry.chart_mesh_index(surface), coord)
        {
            let m = &self.geometry.meshes[mesh as usize];
            if m.tri_surface.get(index as usize) == Some(&surface.0) {
                let e = self.tri_element[mesh as usize][index as usize];
                if e != u32::MAX {
                    return ElementId(e);
                }
            }
        }
        self.root(surface)
    }

    /// The child of `id` containing `coord`; for clusters, if rounding puts
    /// the point in none, the child whose piece it is least outside of.
    fn child_containing(
        &self,
        id: ElementId,
        children: [ElementId; 4],
        coord: SurfaceCoord,
    ) -> Option<ElementId> {
        match (self.elements[id.index()].domain, coord) {
            (ElementDomain::Rect { min, max }, SurfaceCoord::Uv(uv)) => {
                let mid = 0.5 * (min + max);
                let k = usize::from(uv.x >= mid.x) + 2 * usize::from(uv.y >= mid.y);
                Some(children[k])
            }
            (ElementDomain::Cluster { .. }, SurfaceCoord::Triangle { index, bary }) => {
                let mut best = (f64::NEG_INFINITY, None);
                for &c in &children {
                    for p in self.element_pieces(c) {
                        if p.triangle == index {
                            let l = p.local(bary);
                            let m = l[0].min(l[1]).min(l[2]);
                            if m > best.0 {
                                best = (m, Some(c));
                            }
                        }
                    }
                    if best.0 >= 0.0 {
                        break;
                    }
                }
                best.1
            }
            _ => None,
        }
    }

    /// Five points spread over the element, for BRDF variation estimates:
    /// four corners (uv corners; for clusters the piece corners extreme along
    /// the element's two tangent directions) and the centre.
    pub fn element_points(&self, id: ElementId) -> [DVec3; 5] {
        let e = &self.elements[id.index()];
        match (e.domain, &self.geometry.surface(e.surface).geom) {
            (ElementDomain::Rect { min, max }, SurfaceGeom::Patch(patch)) => [
                patch.eval(min).p,
                patch.eval(DVec2::new(max.x, min.y)).p,
                patch.eval(max).p,
                patch.eval(DVec2::new(min.x, max.y)).p,
                e.centre,
            ],
            (ElementDomain::Cluster { .. }, SurfaceGeom::Chart { mesh, .. }) => {
                let m = &self.geometry.meshes[*mesh as usize];
                let (t1, t2) = e.normal.any_orthonormal_pair();
                let mut ext = [(f64::INFINITY, e.centre); 4];
                for p in self.element_pieces(id) {
                    for v in p.corners(m) {
                        let d = v - e.centre;
                        let keys = [d.dot(t1), -d.dot(t1), d.dot(t2), -d.dot(t2)];
                        for k in 0..4 {
                            if -keys[k] < ext[k].0 {
                                ext[k] = (-keys[k], v);
                            }
                        }
                    }
                }
                [ext[0].1, ext[2].1, ext[1].1, ext[3].1, e.centre]
            }
            _ => [e.centre; 5],
        }
    }

    /// The corners of a parametric element in the order (min.u, min.v),
    /// (max.u, min.v), (min.u, max.v), (max.u, max.v), each with its front
    /// unit normal, so that a smooth quantity sampled there can be
    /// interpolated bilinearly ([`Self::bilinear_weights`]); `None` for
    /// mesh clusters, which have no (u, v) domain.
    pub fn element_corners(&self, id: ElementId) -> Option<[(DVec3, DVec3); 4]> {
        let e = &self.elements[id.index()];
        match (e.domain, &self.geometry.surface(e.surface).geom) {
            (ElementDomain::Rect { min, max }, SurfaceGeom::Patch(patch)) => {
                let corner = |u: f64, v: f64| {
                    let p = patch.eval(DVec2::new(u, v));
                    (p.p, p.n)
                };
                Some([
                    corner(min.x, min.y),
                    corner(max.x, min.y),
                    corner(min.x, max.y),
                    corner(max.x, max.y),
                ])
            }
            _ => None,
        }
    }

    /// The bilinear weights of the point `coord` over the corners of
    /// [`Self::element_corners`] (they sum to 1); `None` for clusters and
    /// for a coordinate of another kind.
    pub fn bilinear_weights(&self, id: ElementId, coord: SurfaceCoord) -> Option<[f64; 4]> {
        let e = &self.elements[id.index()];
        let (ElementDomain::Rect { min, max }, SurfaceCoord::Uv(uv)) = (e.domain, coord) else {
            return None;
        };
        let size = max - min;
        if size.x <= 0.0 || size.y <= 0.0 {
            return None;
        }
        let st = ((uv - min) / size).clamp(DVec2::ZERO, DVec2::ONE);
        let (s, t) = (st.x, st.y);
        Some([(1.0 - s) * (1.0 - t), s * (1.0 - t), (1.0 - s) * t, s * t])
    }

    /// Samples a point of element `id` from `u` ∈ [0,1)², with its exact
    /// area density ([`crate::sampling`]).
    pub fn sample_element(&self, id: ElementId, u: DVec2) -> SurfaceSample {
        let u = u.clamp(DVec2::ZERO, DVec2::splat(1.0 - f64::EPSILON));
        let e = &self.elements[id.index()];
        match (e.domain, &self.geometry.surface(e.surface).geom) {
            (ElementDomain::Rect { min, max }, SurfaceGeom::Patch(patch)) => {
                sample_rect(patch, min, max, e.area, u)
            }
            (ElementDomain::Cluster { .. }, SurfaceGeom::Chart { mesh, .. }) => sample_cluster(
                &self.geometry.meshes[*mesh as usize],
                self.element_pieces(id),
                self.element_piece_ends(id),
                e.area,
                u,
            ),
            _ => unreachable!("element domain does not match its surface"),
        }
    }

    /// Samples a point of a whole input surface (its root element).
    pub fn sample_surface(&self, surface: SurfaceId, u: DVec2) -> SurfaceSample {
        self.sample_element(self.root(surface), u)
    }
}
