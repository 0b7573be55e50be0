//! Elements: the nodes of an input surface's tree (paper §3.2), stored in
//! one arena with `u32` indices and created lazily by
//! [`SceneGeometry::subdivide`].
//!
//! A parametric element is a (u, v) rectangle of its surface; its four
//! children are the quadrants (0: low u low v, 1: high u low v, 2: low u
//! high v, 3: high u high v), evaluated on the true surface. A chart element
//! is a cluster of triangle pieces ([`crate::chart`]).

use glam::{DVec2, DVec3};
use serde::{Deserialize, Serialize};

use crate::bounds::Bounds;
use crate::chart::{Piece, split_cluster};
use crate::ids::{ElementId, SurfaceId};
use crate::patch::Patch;
use crate::scene_geometry::SceneGeometry;
use crate::surface::{SurfaceCoord, SurfaceGeom};

const NO_CHILD: u32 = u32::MAX;

/// What part of its input surface an element covers.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum ElementDomain {
    /// The (u, v) rectangle [min, max] of a parametric surface.
    Rect {
        /// Lower (u, v) corner.
        min: DVec2,
        /// Upper (u, v) corner.
        max: DVec2,
    },
    /// A cluster of chart pieces: `count` pieces from `first` in the piece
    /// arena (see [`SceneGeometry::element_pieces`]).
    Cluster {
        /// First piece.
        first: u32,
        /// Number of pieces.
        count: u32,
    },
}

/// A node of an element tree.
#[derive(Clone, Debug)]
pub struct Element {
    /// The input surface this element belongs to.
    pub surface: SurfaceId,
    /// The parent element (`None` for the root of an input surface).
    pub parent: Option<ElementId>,
    /// Depth below the root (root = 0).
    pub depth: u32,
    /// Area (exact: closed forms or adaptive quadrature for parametric
    /// pieces, sums of triangle areas for clusters; see [`crate::chart`]).
    pub area: f64,
    /// A point on the element near its middle: the image of the uv centre,
    /// or for a cluster the centroid of the piece nearest the area centroid.
    pub centre: DVec3,
    /// Front unit normal at `centre` (for a cluster: the normalised
    /// area-weighted mean of its pieces' normals).
    pub normal: DVec3,
    /// Cosine of the half-angle of a cone around `normal` containing the
    /// element's normals: 1 for planar elements. For curved pieces it is the
    /// largest angle to `normal` over a 5×5 uv grid plus the largest angle
    /// between neighbouring grid normals (a conservative bound); for
    /// clusters it is exact over the pieces.
    pub normal_cone_cos: f64,
    /// World-space bounds (exact for planar quads and clusters; for curved
    /// pieces the bounds of a 9×9 grid grown by the maximal sagitta).
    pub bounds: Bounds,
    /// What part of the surface the element covers.
    pub domain: ElementDomain,
    pub(crate) first_child: u32,
    pub(crate) planar: bool,
}

impl Element {
    /// The four children, if this element has been subdivided.
    pub fn children(&self) -> Option<[ElementId; 4]> {
        (self.first_child != NO_CHILD).then(|| {
            let f = self.first_child;
            [
                ElementId(f),
                ElementId(f + 1),
                ElementId(f + 2),
                ElementId(f + 3),
            ]
        })
    }

    /// True if this element has no children yet.
    pub fn is_leaf(&self) -> bool {
        self.first_child == NO_CHILD
    }

    /// True if the element lies in one plane (its normal cone is a line).
    pub fn is_planar(&self) -> bool {
        self.planar
    }
}

impl SceneGeometry {
    /// The element with this id. Panics if the id is not from this geometry.
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

    /// Area-weighted sums of the shading normals and of the geometric
    /// normals over a chart element's pieces, (Σ A n_s, Σ A n_g), when its
    /// mesh has smooth shading normals; `None` otherwise. The irradiance a
    /// Lambertian BSDF sees about its shading normals, from a distant
    /// source in direction d, is (Σ A n_s · d)/(Σ A n_g · d) times the one
    /// about the geometric normals.
    pub fn shading_moments(&self, id: ElementId) -> Option<(DVec3, DVec3)> {
        let e = &self.elements[id.index()];
        let SurfaceGeom::Chart { mesh } = &self.surfaces[e.surface.index()].geom else {
            return None;
        };
        let m = &self.meshes[*mesh as usize];
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
        match parent.domain {
            ElementDomain::Rect { min, max } => {
                let mid = 0.5 * (min + max);
                let quads = [
                    (min, mid),
                    (DVec2::new(mid.x, min.y), DVec2::new(max.x, mid.y)),
                    (DVec2::new(min.x, mid.y), DVec2::new(mid.x, max.y)),
                    (mid, max),
                ];
                for (a, b) in quads {
                    let e = self.make_rect_element(surface, a, b, Some(id), parent.depth + 1);
                    self.elements.push(e);
                }
            }
            ElementDomain::Cluster { first: pf, count } => {
                let mesh = match self.surfaces[surface.index()].geom {
                    SurfaceGeom::Chart { mesh } => mesh,
                    SurfaceGeom::Patch(_) => {
                        unreachable!("cluster element on a parametric surface")
                    }
                };
                let own: Vec<Piece> = self.pieces[pf as usize..(pf + count) as usize].to_vec();
                let groups = split_cluster(&own, &self.meshes[mesh as usize]);
                for g in groups {
                    let e = self.make_cluster_element(surface, mesh, g, Some(id), parent.depth + 1);
                    self.elements.push(e);
                }
            }
        }
        self.elements[id.index()].first_child = first;
        [
            ElementId(first),
            ElementId(first + 1),
            ElementId(first + 2),
            ElementId(first + 3),
        ]
    }

    pub(crate) fn make_rect_element(
        &self,
        surface: SurfaceId,
        min: DVec2,
        max: DVec2,
        parent: Option<ElementId>,
        depth: u32,
    ) -> Element {
        let patch = match &self.surfaces[surface.index()].geom {
            SurfaceGeom::Patch(p) => p,
            SurfaceGeom::Chart { .. } => unreachable!("rect element on a chart"),
        };
        rect_element(patch, surface, min, max, parent, depth)
    }

    pub(crate) fn make_cluster_element(
        &mut self,
        surface: SurfaceId,
        mesh: u32,
        mut pieces: Vec<Piece>,
        parent: Option<ElementId>,
        depth: u32,
    ) -> Element {
        let m = &self.meshes[mesh as usize];
        // Order the pieces along a Morton curve of their centroids, so that
        // the area-CDF sampling of `sample_element` maps stratified u.x to
        // spatially stratified points.
        crate::chart::morton_sort(&mut pieces, m);
        let mut area = 0.0;
        let mut sum_n = DVec3::ZERO;
        let mut sum_c = DVec3::ZERO;
        let mut bounds = Bounds::EMPTY;
        let mut largest = (0.0, DVec3::Z);
        for p in &pieces {
            let a = m.tri_area[p.triangle as usize] * p.area_fraction();
            let n = m.tri_normal[p.triangle as usize];
            let c = p.corners(m);
            area += a;
            sum_n += a * n;
            sum_c += a * (c[0] + c[1] + c[2]) / 3.0;
            bounds = bounds.with_point(c[0]).with_point(c[1]).with_point(c[2]);
            if a > largest.0 {
                largest = (a, n);
            }
        }
        let normal = sum_n.try_normalize().unwrap_or(largest.1);
        let centroid = if area > 0.0 {
            sum_c / area
        } else {
            bounds.centre()
        };
        let mut cone = 1.0f64;
        let mut best = (f64::INFINITY, centroid);
        let mut planar = true;
        let plane_d = normal.dot(pieces.first().map(|p| p.corners(m)[0]).unwrap_or(centroid));
        let tol = 1e-9 * bounds.diagonal().length().max(1e-300);
        for p in &pieces {
            let n = m.tri_normal[p.triangle as usize];
            cone = cone.min(n.dot(normal));
            let c = p.corners(m);
            let pc = (c[0] + c[1] + c[2]) / 3.0;
            let d = (pc - centroid).length_squared();
            if d < best.0 {
                best = (d, pc);
            }
            if c.iter().any(|v| (normal.dot(*v) - plane_d).abs() > tol) {
                planar = false;
            }
        }
        if cone < 1.0 - 1e-12 {
            planar = false;
        }
        let first = self.pieces.len() as u32;
        let count = pieces.len() as u32;
        // The caller pushes this element next: it becomes the deepest
        // element holding each of its whole triangles.
        let id = self.elements.len() as u32;
        let mesh_data = &mut self.meshes[mesh as usize];
        for p in pieces.iter().filter(|p| p.is_whole()) {
            mesh_data.tri_element[p.triangle as usize] = id;
        }
        self.pieces.extend(pieces);
        Element {
            surface,
            parent,
            depth,
            area,
            centre: best.1,
            normal,
            normal_cone_cos: if planar { 1.0 } else { cone.clamp(-1.0, 1.0) },
            bounds,
            domain: ElementDomain::Cluster { first, count },
            first_child: NO_CHILD,
            planar,
        }
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
        let mut id = self.surfaces[surface.index()].root;
        // Charts: jump to the deepest element holding the whole triangle
        // (below it, clusters have fewer than 4 pieces).
        if let (SurfaceGeom::Chart { mesh }, SurfaceCoord::Triangle { index, .. }) =
            (&self.surfaces[surface.index()].geom, coord)
        {
            let m = &self.meshes[*mesh as usize];
            if m.tri_surface.get(index as usize) == Some(&surface.0) {
                let e = m.tri_element[index as usize];
                if e != u32::MAX {
                    id = ElementId(e);
                }
            }
        }
        while let Some(children) = self.elements[id.index()].children() {
            let next = match (self.elements[id.index()].domain, coord) {
                (ElementDomain::Rect { min, max }, SurfaceCoord::Uv(uv)) => {
                    let mid = 0.5 * (min + max);
                    let k = usize::from(uv.x >= mid.x) + 2 * usize::from(uv.y >= mid.y);
                    Some(children[k])
                }
                (ElementDomain::Cluster { .. }, SurfaceCoord::Triangle { index, bary }) => {
                    // The child containing the point; if rounding puts it in
                    // none, the child whose piece it is least outside of.
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
            };
            match next {
                Some(n) => id = n,
                None => break,
            }
        }
        id
    }

    /// Five points spread over the element, for BRDF variation estimates:
    /// four corners (uv corners; for clusters the piece corners extreme along
    /// the element's two tangent directions) and the centre.
    pub fn element_points(&self, id: ElementId) -> [DVec3; 5] {
        let e = &self.elements[id.index()];
        match (e.domain, &self.surfaces[e.surface.index()].geom) {
            (ElementDomain::Rect { min, max }, SurfaceGeom::Patch(patch)) => [
                patch.eval(min).p,
                patch.eval(DVec2::new(max.x, min.y)).p,
                patch.eval(max).p,
                patch.eval(DVec2::new(min.x, max.y)).p,
                e.centre,
            ],
            (ElementDomain::Cluster { .. }, SurfaceGeom::Chart { mesh }) => {
                let m = &self.meshes[*mesh as usize];
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
}

/// Builds the element for the uv rectangle [min, max] of a patch.
pub(crate) fn rect_element(
    patch: &Patch,
    surface: SurfaceId,
    min: DVec2,
    max: DVec2,
    parent: Option<ElementId>,
    depth: u32,
) -> Element {
    let mid = 0.5 * (min + max);
    let c = patch.eval(mid);
    let area = patch.area(min, max);
    let planar = patch.is_planar();
    let grid = |n: usize| {
        (0..n).flat_map(move |i| {
            (0..n).map(move |j| {
                DVec2::new(
                    min.x + (max.x - min.x) * i as f64 / (n - 1) as f64,
                    min.y + (max.y - min.y) * j as f64 / (n - 1) as f64,
                )
            })
        })
    };
    let (cone, bounds) = match patch {
        Patch::Quad { .. } => {
            let b = Bounds::from_points(
                [min, DVec2::new(max.x, min.y), max, DVec2::new(min.x, max.y)]
                    .map(|uv| patch.eval(uv).p),
            );
            // Interior points are computed with rounding: pad by a few ulps.
            let pad = 1e-14 * b.min.abs().max(b.max.abs()).max_element();
            (1.0, b.padded(pad))
        }
        _ => {
            // Smallest cosine to the centre normal over a 5×5 grid, widened
            // by the largest angle between neighbouring grid normals: every
            // point lies within half a grid step of a grid point, so this
            // bounds the whole element's normals.
            let n = 5;
            let normals: Vec<DVec3> = grid(n).map(|uv| patch.eval(uv).n).collect();
            let mut worst = 0.0f64;
            let mut step = 0.0f64;
            for i in 0..n {
                for j in 0..n {
                    let a = normals[i * n + j];
                    worst = worst.max(a.dot(c.n).clamp(-1.0, 1.0).acos());
                    if i + 1 < n {
                        step = step.max(a.dot(normals[(i + 1) * n + j]).clamp(-1.0, 1.0).acos());
                    }
                    if j + 1 < n {
                        step = step.max(a.dot(normals[i * n + j + 1]).clamp(-1.0, 1.0).acos());
                    }
                }
            }
            let cone = (worst + step).min(std::f64::consts::PI).cos();
            let mut b = Bounds::EMPTY;
            let mut step = 0.0f64;
            for uv in grid(9) {
                let pp = patch.eval(uv);
                b = b.with_point(pp.p);
                step = step
                    .max(pp.dpdu.length() * (max.x - min.x) / 8.0)
                    .max(pp.dpdv.length() * (max.y - min.y) / 8.0);
            }
            // Between grid points the surface bulges by at most the sagitta of
            // an arc of length `step` on a quarter-turn piece: < step²/radius;
            // `step` itself is a safe upper bound for our pieces.
            (
                if planar { 1.0 } else { cone.clamp(-1.0, 1.0) },
                b.padded(step),
            )
        }
    };
    Element {
        surface,
        parent,
        depth,
        area,
        centre: c.p,
        normal: c.n,
        normal_cone_cos: cone,
        bounds,
        domain: ElementDomain::Rect { min, max },
        first_child: NO_CHILD,
        planar,
    }
}
