//! Triangle meshes as charts, and chart elements as clusters of triangle
//! pieces.
//!
//! # How charts are chosen
//!
//! A mesh never becomes one input surface per triangle (k input surfaces
//! make k² root interactions; docs/architecture.md, "Meshes"). Instead its triangles
//! are grouped into **charts**, each one input surface:
//!
//! 1. Triangles are connected through shared edges. Vertices are welded by
//!    exact position first, so a mesh whose loader duplicated vertices (for
//!    normals or texture coordinates) is still connected. An edge shared by
//!    more than [`CHART_MAX_EDGE_TRIANGLES`] (8) triangles connects none of them:
//!    it is no surface (coincident copies of one triangle, pages of a book),
//!    and its k triangles would make k² neighbour pairs (200 000 copies of
//!    one triangle asked for 8 GiB); step 4 groups them instead.
//! 2. A chart grows from the first unassigned triangle (in file order),
//!    always adding the connected candidate whose centroid is closest to the
//!    seed's centroid (so charts are compact, roughly round), as long as
//!    - the candidate's normal is within [`CHART_CONE_DEG`] (60°) of the
//!      seed's normal (normal-cone bound), and
//!    - the chart has fewer than [`CHART_MAX_TRIANGLES`] (512) triangles.
//! 3. A chart left smaller than an eighth of the cap is merged into an
//!    adjacent chart when that keeps both bounds (cap allowing 1.5×).
//! 4. Charts still smaller than that (disconnected pieces: triangle soups,
//!    separate parts) are grouped along the Morton curve of their centroids,
//!    consecutive ones joining while the group stays under the cap and within
//!    the normal cone. A chart need not be connected, so a soup of 8192
//!    separate triangles still makes a handful of input surfaces.
//!
//! Degenerate (zero-area) triangles belong to no chart and are not traced.
//!
//! # Elements of a chart
//!
//! An element of a chart is a **cluster of pieces**; a piece is a whole mesh
//! triangle or a sub-triangle of one (in the triangle's barycentric
//! coordinates). The root holds the chart's triangles. Every element has
//! exactly 4 children:
//! - n ≥ 4 pieces: 4 sub-clusters by two levels of median cuts of the piece
//!   centroids along the longest axis of their box (sizes ⌈n/4⌉ or so);
//! - 3 pieces: the largest is bisected (midpoint of its longest edge), the
//!   other two stay whole: 4 single pieces;
//! - 2 pieces: both are bisected: 4 single pieces;
//! - 1 piece: the midpoint split in barycentrics (4 sub-triangles).
//!
//! So every branch reaches single-piece elements after about log₄ n levels,
//! and the leaves of any subdivided tree partition every triangle of the
//! chart exactly once.

use std::collections::{BinaryHeap, HashMap};

use glam::{DVec2, DVec3};
use serde::{Deserialize, Serialize};

use crate::bounds::Bounds;
use crate::element::{Element, ElementDomain, NO_CHILD};
use crate::ids::{ElementId, SurfaceId};

/// Largest number of triangles in one chart.
pub const CHART_MAX_TRIANGLES: usize = 512;
/// Half-angle, in degrees, of the normal cone of a chart around its seed.
pub const CHART_CONE_DEG: f64 = 60.0;
/// Most triangles an edge may have and still connect them (module docs):
/// a closed surface has 2 on every edge, a T-shaped joint 3 or 4.
pub const CHART_MAX_EDGE_TRIANGLES: usize = 8;

/// A mesh in world space, with per-triangle data.
#[derive(Clone, Debug)]
pub(crate) struct MeshData {
    pub positions: Vec<DVec3>,
    pub triangles: Vec<[u32; 3]>,
    /// World-space shading normals (unit), when the mesh has them and
    /// `face_normals` is false.
    pub shading_normals: Option<Vec<DVec3>>,
    /// Front unit normal per triangle (after `flip_normals`); zero for
    /// degenerate triangles.
    pub tri_normal: Vec<DVec3>,
    pub tri_area: Vec<f64>,
    /// Input surface of each triangle (`u32::MAX` for degenerate ones).
    pub tri_surface: Vec<u32>,
    /// +1 or −1 (flip_normals), applied to shading normals.
    pub sign: f64,
    /// Per-vertex texture coordinates, when the mesh has them.
    pub texcoords: Option<Vec<DVec2>>,
}

impl MeshData {
    #[inline]
    pub fn vertices(&self, tri: u32) -> [DVec3; 3] {
        let t = self.triangles[tri as usize];
        [
            self.positions[t[0] as usize],
            self.positions[t[1] as usize],
            self.positions[t[2] as usize],
        ]
    }

    /// The point with barycentrics (b1, b2) of a triangle.
    #[inline]
    pub fn point(&self, tri: u32, b: DVec2) -> DVec3 {
        let [a, p1, p2] = self.vertices(tri);
        a + b.x * (p1 - a) + b.y * (p2 - a)
    }

    /// Shading normal at barycentrics (b1, b2) (the face normal when the
    /// mesh has no usable vertex normals).
    pub fn shading_normal(&self, tri: u32, b: DVec2) -> DVec3 {
        if let Some(ns) = &self.shading_normals {
            let t = self.triangles[tri as usize];
            let n = (1.0 - b.x - b.y) * ns[t[0] as usize]
                + b.x * ns[t[1] as usize]
                + b.y * ns[t[2] as usize];
            let n = self.sign * n;
            if let Some(n) = n.try_normalize() {
                return n;
            }
        }
        self.tri_normal[tri as usize]
    }
}

/// A piece of a chart element: a mesh triangle or a sub-triangle of it,
/// given by the barycentric coordinates (b1, b2) of its three corners.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Piece {
    /// Index of the triangle in its mesh.
    pub triangle: u32,
    /// Corners in the triangle's barycentric coordinates (b1, b2).
    pub bary: [DVec2; 3],
}

impl Piece {
    /// True if this piece is its whole triangle.
    pub fn is_whole(&self) -> bool {
        self.bary == [DVec2::ZERO, DVec2::X, DVec2::Y]
    }

    /// The whole triangle.
    pub fn whole(triangle: u32) -> Piece {
        Piece {
            triangle,
            bary: [DVec2::ZERO, DVec2::X, DVec2::Y],
        }
    }

    /// The four midpoint sub-triangles (three corners, then the middle one).
    pub fn split(&self) -> [Piece; 4] {
        let [a, b, c] = self.bary;
        let (ab, bc, ca) = (0.5 * (a + b), 0.5 * (b + c), 0.5 * (c + a));
        let t = self.triangle;
        [
            Piece {
                triangle: t,
                bary: [a, ab, ca],
            },
            Piece {
                triangle: t,
                bary: [ab, b, bc],
            },
            Piece {
                triangle: t,
                bary: [ca, bc, c],
            },
            Piece {
                triangle: t,
                bary: [bc, ca, ab],
            },
        ]
    }

    /// The two halves of this piece, cut from the midpoint of its longest
    /// edge (in world space) to the opposite corner.
    pub(crate) fn bisect(&self, mesh: &MeshData) -> [Piece; 2] {
        let w = self.corners(mesh);
        let len = |i: usize| (w[(i + 1) % 3] - w[i]).length_squared();
        let k = (0..3)
            .max_by(|&i, &j| len(i).total_cmp(&len(j)))
            .unwrap_or(0);
        let (a, b, c) = (self.bary[k], self.bary[(k + 1) % 3], self.bary[(k + 2) % 3]);
        let m = 0.5 * (a + b);
        let t = self.triangle;
        [
            Piece {
                triangle: t,
                bary: [a, m, c],
            },
            Piece {
                triangle: t,
                bary: [m, b, c],
            },
        ]
    }

    /// Barycentric coordinates of the triangle-barycentric point `b` with
    /// respect to this piece's corners.
    pub fn local(&self, b: DVec2) -> [f64; 3] {
        let [p0, p1, p2] = self.bary;
        let e1 = p1 - p0;
        let e2 = p2 - p0;
        let d = b - p0;
        let det = e1.x * e2.y - e1.y * e2.x;
        let l1 = (d.x * e2.y - d.y * e2.x) / det;
        let l2 = (e1.x * d.y - e1.y * d.x) / det;
        [1.0 - l1 - l2, l1, l2]
    }

    /// True if the triangle-barycentric point lies in this piece (with a
    /// tolerance of 1e-9 in the piece's own barycentrics).
    pub fn contains(&self, triangle: u32, b: DVec2) -> bool {
        triangle == self.triangle && self.local(b).iter().all(|&l| l >= -1e-9)
    }

    /// The world corners of this piece.
    pub(crate) fn corners(&self, mesh: &MeshData) -> [DVec3; 3] {
        self.bary.map(|b| mesh.point(self.triangle, b))
    }

    /// Fraction of the triangle's area covered by this piece.
    pub fn area_fraction(&self) -> f64 {
        let [a, b, c] = self.bary;
        let e1 = b - a;
        let e2 = c - a;
        (e1.x * e2.y - e1.y * e2.x).abs()
    }
}

/// Groups the non-degenerate triangles of a mesh into charts (module
/// docs), around `fixed` charts made beforehand (the cells of cut
/// triangles, [`crate::contact`]): their triangles join no other chart,
/// and they come last.
pub(crate) fn build_charts(mesh: &MeshData, fixed: Vec<Vec<u32>>) -> Vec<Vec<u32>> {
    build_charts_counted(mesh, fixed).0
}

/// [`build_charts`], and the number of neighbours it visited: the work of
/// growing and merging charts, at most 3 × ([`CHART_MAX_EDGE_TRIANGLES`] − 1)
/// for each time a triangle is added to a chart or tried for a merge.
pub(crate) fn build_charts_counted(
    mesh: &MeshData,
    fixed: Vec<Vec<u32>>,
) -> (Vec<Vec<u32>>, usize) {
    let adjacency = Adjacency::new(mesh);
    let cos_cone = CHART_CONE_DEG.to_radians().cos();
    let mut chart_of = vec![u32::MAX; mesh.triangles.len()];
    for &t in fixed.iter().flatten() {
        chart_of[t as usize] = FIXED;
    }
    let mut charts = grow_charts(mesh, &adjacency, cos_cone, &mut chart_of);
    merge_small_charts(mesh, &adjacency, cos_cone, &mut charts, &mut chart_of);
    charts.retain(|c| !c.is_empty());
    let mut charts = group_small_charts(mesh, charts, cos_cone);
    charts.extend(fixed);
    (charts, adjacency.visited.get())
}

/// The chart of a triangle that belongs to a fixed chart.
const FIXED: u32 = u32::MAX - 1;

/// Which triangles share an edge, after welding vertices by exact position
/// (a loader may duplicate vertices for normals or texture coordinates).
struct Adjacency<'m> {
    mesh: &'m MeshData,
    /// The welded index of every vertex.
    canon: Vec<u32>,
    /// Welded edge (low, high) → the non-degenerate triangles that have it
    /// (edges of more than [`CHART_MAX_EDGE_TRIANGLES`] left out).
    edges: HashMap<(u32, u32), Vec<u32>>,
    /// Neighbours returned so far (the work, for the tests).
    visited: std::cell::Cell<usize>,
}

impl<'m> Adjacency<'m> {
    fn new(mesh: &'m MeshData) -> Self {
        let mut weld: HashMap<[u64; 3], u32> = HashMap::new();
        let canon: Vec<u32> = mesh
            .positions
            .iter()
            .map(|p| {
                let key = [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()];
                let next = weld.len() as u32;
                *weld.entry(key).or_insert(next)
            })
            .collect();
        let mut adjacency = Adjacency {
            mesh,
            canon,
            edges: HashMap::new(),
            visited: std::cell::Cell::new(0),
        };
        for (t, &area) in mesh.tri_area.iter().enumerate() {
            if area <= 0.0 {
                continue;
            }
            let edges: Vec<(u32, u32)> = adjacency.edges_of(t as u32).collect();
            for edge in edges {
                adjacency.edges.entry(edge).or_default().push(t as u32);
            }
        }
        adjacency
            .edges
            .retain(|_, triangles| triangles.len() <= CHART_MAX_EDGE_TRIANGLES);
        adjacency
    }

    /// The welded edges of triangle `t` (degenerate ones left out).
    fn edges_of(&self, t: u32) -> impl Iterator<Item = (u32, u32)> + '_ {
        let tri = self.mesh.triangles[t as usize];
        (0..3).filter_map(move |k| {
            let a = self.canon[tri[k] as usize];
            let b = self.canon[tri[(k + 1) % 3] as usize];
            (a != b).then(|| (a.min(b), a.max(b)))
        })
    }

    /// The triangles sharing an edge with `t`.
    fn neighbours(&self, t: u32) -> Vec<u32> {
        let mut out = Vec::new();
        for edge in self.edges_of(t) {
            if let Some(list) = self.edges.get(&edge) {
                out.extend(list.iter().copied().filter(|&o| o != t));
            }
        }
        self.visited.set(self.visited.get() + out.len());
        out
    }
}

fn centroid(mesh: &MeshData, t: u32) -> DVec3 {
    let [a, b, c] = mesh.vertices(t);
    (a + b + c) / 3.0
}

/// Grows charts from seeds in file order, always adding the connected
/// candidate nearest the seed's centroid within the normal cone, up to the
/// cap. Returns the charts; `chart_of` (unassigned: `u32::MAX`) gets the
/// chart of every triangle.
fn grow_charts(
    mesh: &MeshData,
    adjacency: &Adjacency<'_>,
    cos_cone: f64,
    chart_of: &mut [u32],
) -> Vec<Vec<u32>> {
    let n = mesh.triangles.len();
    let mut charts: Vec<Vec<u32>> = Vec::new();
    for seed in 0..n as u32 {
        if chart_of[seed as usize] != u32::MAX || mesh.tri_area[seed as usize] <= 0.0 {
            continue;
        }
        let id = charts.len() as u32;
        let seed_n = mesh.tri_normal[seed as usize];
        let seed_c = centroid(mesh, seed);
        let mut members = Vec::new();
        // Max-heap on negated distance (ordered bits of a non-negative f64).
        let mut heap: BinaryHeap<(std::cmp::Reverse<u64>, u32)> = BinaryHeap::new();
        heap.push((std::cmp::Reverse(0), seed));
        while let Some((_, t)) = heap.pop() {
            if chart_of[t as usize] != u32::MAX {
                continue;
            }
            if members.len() >= CHART_MAX_TRIANGLES {
                break;
            }
            chart_of[t as usize] = id;
            members.push(t);
            for o in adjacency.neighbours(t) {
                if chart_of[o as usize] == u32::MAX
                    && mesh.tri_normal[o as usize].dot(seed_n) >= cos_cone
                {
                    let d = (centroid(mesh, o) - seed_c).length();
                    heap.push((std::cmp::Reverse(d.to_bits()), o));
                }
            }
        }
        charts.push(members);
    }
    charts
}

/// Merges every chart smaller than an eighth of the cap into a neighbouring
/// chart when both bounds still hold (the cap allowing 1.5×); merged charts
/// are left empty.
fn merge_small_charts(
    mesh: &MeshData,
    adjacency: &Adjacency<'_>,
    cos_cone: f64,
    charts: &mut [Vec<u32>],
    chart_of: &mut [u32],
) {
    let small = CHART_MAX_TRIANGLES / 8;
    for c in 0..charts.len() {
        if charts[c].is_empty() || charts[c].len() >= small {
            continue;
        }
        let fits = |oc: usize| {
            oc != c
                && !charts[oc].is_empty()
                && charts[oc].len() + charts[c].len() <= CHART_MAX_TRIANGLES * 3 / 2
                && {
                    let seed_n = mesh.tri_normal[charts[oc][0] as usize];
                    charts[c]
                        .iter()
                        .all(|&m| mesh.tri_normal[m as usize].dot(seed_n) >= cos_cone)
                }
        };
        let target = charts[c].iter().find_map(|&t| {
            adjacency
                .neighbours(t)
                .into_iter()
                .map(|o| chart_of[o as usize] as usize)
                .find(|&oc| oc < charts.len() && fits(oc))
        });
        if let Some(oc) = target {
            let moved = std::mem::take(&mut charts[c]);
            for &m in &moved {
                chart_of[m as usize] = oc as u32;
            }
            charts[oc].extend(moved);
        }
    }
}

/// Groups the charts still smaller than an eighth of the cap (disconnected
/// pieces: triangle soups, foliage, separate parts) along the Morton curve of
/// their centroids: consecutive small charts join while the group stays under
/// the cap and within the normal cone of its first triangle.
fn group_small_charts(mesh: &MeshData, charts: Vec<Vec<u32>>, cos_cone: f64) -> Vec<Vec<u32>> {
    let small = CHART_MAX_TRIANGLES / 8;
    let (mut out, smalls): (Vec<Vec<u32>>, Vec<Vec<u32>>) =
        charts.into_iter().partition(|c| c.len() >= small);
    if smalls.len() < 2 {
        out.extend(smalls);
        return out;
    }
    let centroid = |c: &[u32]| {
        let mut s = DVec3::ZERO;
        for &t in c {
            let [a, b, d] = mesh.vertices(t);
            s += (a + b + d) / 3.0;
        }
        s / c.len() as f64
    };
    let cents: Vec<DVec3> = smalls.iter().map(|c| centroid(c)).collect();
    let lo = cents
        .iter()
        .fold(DVec3::splat(f64::INFINITY), |a, b| a.min(*b));
    let hi = cents
        .iter()
        .fold(DVec3::splat(f64::NEG_INFINITY), |a, b| a.max(*b));
    let scale = (hi - lo).max_element().max(1e-300);
    let mut order: Vec<usize> = (0..smalls.len()).collect();
    order.sort_by_cached_key(|&k| morton3((cents[k] - lo) / scale));
    let mut group: Vec<u32> = Vec::new();
    let mut seed_n = DVec3::ZERO;
    for k in order {
        let c = &smalls[k];
        let fits = !group.is_empty()
            && group.len() + c.len() <= CHART_MAX_TRIANGLES
            && c.iter()
                .all(|&t| mesh.tri_normal[t as usize].dot(seed_n) >= cos_cone);
        if !fits {
            if !group.is_empty() {
                out.push(std::mem::take(&mut group));
            }
            seed_n = mesh.tri_normal[c[0] as usize];
            if !c
                .iter()
                .all(|&t| mesh.tri_normal[t as usize].dot(seed_n) >= cos_cone)
            {
                out.push(c.clone());
                continue;
            }
        }
        group.extend_from_slice(c);
    }
    if !group.is_empty() {
        out.push(group);
    }
    out
}

/// Morton code of a point in [0, 1]³ (21 bits per axis).
fn morton3(q: DVec3) -> u64 {
    let spread = |v: u64| {
        let mut x = v & 0x1f_ffff;
        x = (x | (x << 32)) & 0x1f_0000_0000_ffff;
        x = (x | (x << 16)) & 0x1f_0000_ff00_00ff;
        x = (x | (x << 8)) & 0x100f_00f0_0f00_f00f;
        x = (x | (x << 4)) & 0x10c3_0c30_c30c_30c3;
        (x | (x << 2)) & 0x1249_2492_4924_9249
    };
    let q = q.clamp(DVec3::ZERO, DVec3::ONE) * 2_097_151.0;
    spread(q.x as u64) | (spread(q.y as u64) << 1) | (spread(q.z as u64) << 2)
}

/// Sorts pieces along the Morton (Z-order) curve of their centroids in their
/// bounding box (21 bits per axis).
pub(crate) fn morton_sort(pieces: &mut [Piece], mesh: &MeshData) {
    if pieces.len() < 3 {
        return;
    }
    let centroid = |p: &Piece| {
        let [a, b, c] = p.corners(mesh);
        (a + b + c) / 3.0
    };
    let mut lo = DVec3::splat(f64::INFINITY);
    let mut hi = DVec3::splat(f64::NEG_INFINITY);
    for p in pieces.iter() {
        let c = centroid(p);
        lo = lo.min(c);
        hi = hi.max(c);
    }
    let scale = (hi - lo).max_element().max(1e-300);
    pieces.sort_by_cached_key(|p| morton3((centroid(p) - lo) / scale));
}

/// Splits a cluster's pieces into four non-empty groups (module docs).
pub(crate) fn split_cluster(pieces: &[Piece], mesh: &MeshData) -> [Vec<Piece>; 4] {
    let area = |p: &Piece| mesh.tri_area[p.triangle as usize] * p.area_fraction();
    match pieces {
        [p] => return p.split().map(|q| vec![q]),
        [a, b] => {
            let [a0, a1] = a.bisect(mesh);
            let [b0, b1] = b.bisect(mesh);
            return [vec![a0], vec![a1], vec![b0], vec![b1]];
        }
        [a, b, c] => {
            let mut v = [*a, *b, *c];
            v.sort_by(|x, y| area(y).total_cmp(&area(x)));
            let [l0, l1] = v[0].bisect(mesh);
            return [vec![l0], vec![l1], vec![v[1]], vec![v[2]]];
        }
        _ => {}
    }
    let mut all: Vec<Piece> = pieces.to_vec();
    let centroid = |p: &Piece| {
        let [a, b, c] = p.corners(mesh);
        (a + b + c) / 3.0
    };
    let median_cut = |v: &mut Vec<Piece>| -> Vec<Piece> {
        let mut lo = DVec3::splat(f64::INFINITY);
        let mut hi = DVec3::splat(f64::NEG_INFINITY);
        for p in v.iter() {
            let c = centroid(p);
            lo = lo.min(c);
            hi = hi.max(c);
        }
        let d = hi - lo;
        let axis = if d.x >= d.y && d.x >= d.z {
            0
        } else if d.y >= d.z {
            1
        } else {
            2
        };
        v.sort_by(|a, b| centroid(a)[axis].total_cmp(&centroid(b)[axis]));
        let half = v.len().div_ceil(2);
        v.split_off(half)
    };
    let mut right = median_cut(&mut all);
    let left_hi = median_cut(&mut all);
    let right_hi = median_cut(&mut right);
    [all, left_hi, right, right_hi]
}

/// The element of a cluster of pieces of one chart: its pieces ordered along
/// a Morton curve of their centroids (so that the area-CDF sampling of
/// [`crate::sampling`] maps stratified u to spatially stratified points),
/// area, normal (the normalised area-weighted mean), centre (the centroid of
/// the piece nearest the area centroid), exact normal cone and bounds. The
/// pieces are to be stored from index `first_piece` of the piece arena;
/// they are returned in that order.
pub(crate) fn cluster_element(
    m: &MeshData,
    surface: SurfaceId,
    mut pieces: Vec<Piece>,
    parent: Option<ElementId>,
    depth: u32,
    first_piece: u32,
) -> (Element, Vec<Piece>) {
    morton_sort(&mut pieces, m);
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
    let (cone, centre, planar) = cluster_shape(m, &pieces, normal, centroid, bounds);
    let element = Element {
        surface,
        parent,
        depth,
        area,
        centre,
        normal,
        normal_cone_cos: if planar { 1.0 } else { cone.clamp(-1.0, 1.0) },
        bounds,
        domain: ElementDomain::Cluster {
            first: first_piece,
            count: pieces.len() as u32,
        },
        first_child: NO_CHILD,
        planar,
    };
    (element, pieces)
}

/// The normal cone's cosine, the centre (the piece centroid nearest
/// `centroid`) and planarity of a cluster.
fn cluster_shape(
    m: &MeshData,
    pieces: &[Piece],
    normal: DVec3,
    centroid: DVec3,
    bounds: Bounds,
) -> (f64, DVec3, bool) {
    let mut cone = 1.0f64;
    let mut best = (f64::INFINITY, centroid);
    let mut planar = true;
    let plane_d = normal.dot(pieces.first().map(|p| p.corners(m)[0]).unwrap_or(centroid));
    let tol = 1e-9 * bounds.diagonal().length().max(1e-300);
    for p in pieces {
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
    (cone, best.1, planar)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A grid of `2 · side²` triangles in z = 0 (every inner edge shared
    /// by two), then `copies` copies of one triangle, each with its own
    /// three vertices at the same places (welded into one triangle).
    fn grid_and_copies(side: u32, copies: u32) -> MeshData {
        let mut positions = Vec::new();
        for j in 0..=side {
            for i in 0..=side {
                positions.push(DVec3::new(f64::from(i), f64::from(j), 0.0));
            }
        }
        let v = |i: u32, j: u32| j * (side + 1) + i;
        let mut triangles = Vec::new();
        for j in 0..side {
            for i in 0..side {
                triangles.push([v(i, j), v(i + 1, j), v(i + 1, j + 1)]);
                triangles.push([v(i, j), v(i + 1, j + 1), v(i, j + 1)]);
            }
        }
        for _ in 0..copies {
            let first = positions.len() as u32;
            positions.extend([DVec3::new(0.0, 0.0, 5.0), DVec3::X * 3.0, DVec3::Y * 3.0]);
            triangles.push([first, first + 1, first + 2]);
        }
        let n = triangles.len();
        let mut mesh = MeshData {
            positions,
            triangles,
            shading_normals: None,
            tri_normal: vec![DVec3::Z; n],
            tri_area: vec![0.5; n],
            tri_surface: vec![u32::MAX; n],
            sign: 1.0,
            texcoords: None,
        };
        for t in 0..n as u32 {
            let [a, b, c] = mesh.vertices(t);
            let cr = (b - a).cross(c - a);
            mesh.tri_area[t as usize] = 0.5 * cr.length();
            mesh.tri_normal[t as usize] = cr.normalize();
        }
        mesh
    }

    /// The charts of `mesh`, checked to partition its triangles within the
    /// cap, and the work of making them.
    fn charts(mesh: &MeshData) -> (usize, usize) {
        let (charts, work) = build_charts_counted(mesh, Vec::new());
        let mut seen = vec![false; mesh.triangles.len()];
        for c in &charts {
            let cap = CHART_MAX_TRIANGLES * 3 / 2; // merging allows 1.5×
            assert!(!c.is_empty() && c.len() <= cap, "{}", c.len());
            for &t in c {
                assert!(!seen[t as usize], "triangle {t} in two charts");
                seen[t as usize] = true;
            }
        }
        assert!(seen.iter().all(|&s| s), "every triangle in a chart");
        (charts.len(), work)
    }

    /// Coincident triangles cost work proportional to their number: 4 times
    /// as many (with a grid 4 times as large beside them) visit about 4
    /// times as many neighbours, at most 3 × 7 per triangle and pass. When
    /// an edge connected all its triangles, each copy visited every other:
    /// 200 000 copies asked for 8 GiB.
    #[test]
    fn coincident_triangles_cost_linear_work() {
        let (charts_small, small) = charts(&grid_and_copies(32, 2_048));
        let (charts_large, large) = charts(&grid_and_copies(64, 8_192));
        eprintln!("{small} and {large} neighbours visited");
        for (work, triangles) in [(small, 2 * 32 * 32 + 2_048), (large, 2 * 64 * 64 + 8_192)] {
            assert!(work <= 2 * 3 * 7 * triangles, "{work} for {triangles}");
        }
        let ratio = large as f64 / small as f64;
        assert!(
            (3.5..4.5).contains(&ratio),
            "work ×{ratio} for ×4 triangles"
        );
        // The copies fill charts of the cap (2 048 / 512 = 4), as any soup
        // of separate triangles does; the grid makes at least 2 · side² /
        // 512 more (4), and at most twice that.
        assert!((4 + 4..=4 + 8).contains(&charts_small), "{charts_small}");
        assert!(
            (16 + 16..=16 + 32).contains(&charts_large),
            "{charts_large}"
        );
    }

    /// Up to the limit an edge still connects its triangles: a fan of 8
    /// triangles around one edge, each tilted less than the cone from the
    /// first, is one chart, where the same fan of 9 is 9 pieces grouped
    /// again by position (here into one chart too, by the Morton pass).
    #[test]
    fn an_edge_connects_up_to_the_limit() {
        let mesh = |k: usize| {
            let mut positions = vec![DVec3::ZERO, DVec3::X];
            let mut triangles = Vec::new();
            for i in 0..k {
                let a = (i as f64) * 0.05;
                positions.push(DVec3::new(0.5, a.cos(), a.sin()));
                triangles.push([0, 1, 2 + i as u32]);
            }
            let n = triangles.len();
            let mut m = MeshData {
                positions,
                triangles,
                shading_normals: None,
                tri_normal: vec![DVec3::Z; n],
                tri_area: vec![0.0; n],
                tri_surface: vec![u32::MAX; n],
                sign: 1.0,
                texcoords: None,
            };
            for t in 0..n as u32 {
                let [a, b, c] = m.vertices(t);
                let cr = (b - a).cross(c - a);
                m.tri_area[t as usize] = 0.5 * cr.length();
                m.tri_normal[t as usize] = cr.normalize();
            }
            m
        };
        let (_, work) = build_charts_counted(&mesh(CHART_MAX_EDGE_TRIANGLES), Vec::new());
        // Growing visits the 7 others from each of the 8, and so does the
        // try to merge the small chart into another (there is none).
        assert_eq!(
            work,
            2 * CHART_MAX_EDGE_TRIANGLES * (CHART_MAX_EDGE_TRIANGLES - 1)
        );
        let (charts, work) = build_charts_counted(&mesh(CHART_MAX_EDGE_TRIANGLES + 1), Vec::new());
        assert_eq!(work, 0);
        assert_eq!(charts.len(), 1);
    }
}
