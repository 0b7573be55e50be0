//! Contacts: lines along which another surface ends on a mesh triangle, or
//! passes through it (a wall standing on a floor that runs on past it).
//!
//! Piecewise-constant elements that straddle such a line average the light
//! of both sides. A ground of two triangles 221 m across, under a room
//! whose walls stand on it, makes elements metres wide that carry the
//! sky-lit outside's light in under the walls (the converted classroom read
//! 1.43 of Mitsuba's mean, converged). So, before its charts are made, a
//! mesh triangle with contacts is cut along them into convex cells, and the
//! cells on the two sides of a contact go to different charts: no element
//! straddles a wall. Burial and crossings ([`crate::burial`],
//! [`crate::crossing`]) still mark what the cells hide or cut off.
//!
//! **A contact** of triangle T is a triangle W of any planar shape (mesh
//! triangles, rectangles, cube faces; not disks or curved shapes) that is
//! transverse to T (the normals' cosine at most [`MAX_COS`]) and meets T's
//! plane inside T: its vertices within [`SNAP`] of its own height above
//! the plane count as on the plane (a wall modelled to end 2 mm below the
//! floor), and the segment where W meets the plane, projected on it and
//! clipped to T, is the contact. Contacts on one line (within
//! [`MERGE`] × T's size) are one **cut**: the plane through that line
//! normal to T. Contacts are pooled over the coplanar large triangles of
//! T's shape (a wall crossing a ground of two triangles counts whole on
//! both), and a line cuts when its contacts add up to at least
//! [`MIN_CONTACT`] of the largest one's size √(2 area) (at most
//! [`MAX_CUTS`], the longest); it cuts each of those triangles that it
//! leaves at least [`MIN_PIECE`] of the triangle's size on both sides
//! of. Only triangles of at least [`MIN_SIZE`] of the
//! scene's diagonal are cut: a ground plane or a floor slab, not the
//! furniture (at 5 % the committed living room gained 893 charts and took
//! twice as long, for the same image). A table leg on a large floor
//! triangle makes no cut, the walls of a room on a ground plane do; the
//! sides of a large box resting on it cut it along the box's footprint,
//! whose cells burial then covers.
//!
//! **Cells.** Every cut divides every cell it crosses (T's barycentric
//! coordinates; a split point is computed from its edge's ends in one
//! order, so the two cells on either side of an edge share it bit for
//! bit), unless one part would reach less than [`MIN_CELL`] of T's size
//! from the line; a cell's corner within [`SNAP_CELL`] of T's size from
//! the line counts as on it. So no cell is a sliver (a 32-bit bake cannot
//! resolve its elements, and they mean nothing). Each convex cell is fanned
//! into triangles and made a chart of its own. Cells are not joined into
//! regions bounded by the contacts: a door leaves a gap in a room's walls,
//! and one chart for the inside and the outside would let a link at its
//! coarse elements carry the sky's light to both alike (the classroom's,
//! grown that way, read 1.12).
//! Only large triangles are cut, so the charts this adds are few.

use std::collections::HashMap;

use glam::{DVec2, DVec3};
use rayon::prelude::*;

use crate::bounds::Bounds;
use crate::bvh::{BoxTree, Prim, TriOwner};
use crate::chart::MeshData;

/// Largest |cos| between the normals of a contact and its triangle (about
/// 18°: a ramp meeting the floor at a shallower angle is no wall).
pub(crate) const MAX_COS: f64 = 0.95;
/// A contact's vertex lies on the plane when within this fraction of the
/// contact's height above the plane.
pub(crate) const SNAP: f64 = 0.05;
/// Contacts closer than this fraction of the triangle's size to one line
/// are on that line.
pub(crate) const MERGE: f64 = 1e-4;
/// The least total contact length of a cut, relative to the triangle's
/// size.
pub(crate) const MIN_CONTACT: f64 = 0.02;
/// The least extent of the triangle on each side of a cut, relative to its
/// size.
pub(crate) const MIN_PIECE: f64 = 1e-2;
/// The least size of a triangle that is cut, relative to the diagonal of
/// the box around every planar triangle of the scene.
pub(crate) const MIN_SIZE: f64 = 0.2;
/// The least reach of a part of a split cell from the line, relative to
/// the triangle's size.
pub(crate) const MIN_CELL: f64 = 1e-4;
/// Corners of a cell closer to a cut's line than this fraction of the
/// triangle's size count as on it.
pub(crate) const SNAP_CELL: f64 = 2e-3;
/// Fan triangles of less than this fraction of the cut triangle's area are
/// left out (three corners on one line, up to rounding).
pub(crate) const FAN_MIN_AREA: f64 = 1e-9;
/// Most cuts per triangle (the longest are kept): 16 lines make at most
/// 137 cells.
pub(crate) const MAX_CUTS: usize = 16;

/// The plane through a contact line, normal to the triangle it cuts.
#[derive(Clone, Debug)]
pub(crate) struct Cut {
    /// Unit normal m of the cutting plane (it lies in the triangle's plane).
    normal: DVec3,
    /// The plane is m · x = offset.
    offset: f64,
    /// The total length of the contacts on it, clipped to the triangle.
    length: f64,
}

/// The cuts of the mesh triangles of a scene: shape → triangle → cuts.
pub(crate) type Cuts = HashMap<u32, HashMap<u32, Vec<Cut>>>;

/// A triangle's plane and size, the frame of its contact search.
struct Receiver {
    v: [DVec3; 3],
    normal: DVec3,
    /// √(2 area): the length of a leg of the isosceles right triangle of
    /// the same area.
    size: f64,
}

/// The cuts of every mesh triangle of `prims` (module docs); empty when
/// no surface ends on another's large mesh triangle. Scenes without
/// large mesh triangles cost a pass over the boxes.
pub(crate) fn find_cuts(prims: &[Prim]) -> Cuts {
    let boxes: Vec<Bounds> = prims
        .iter()
        .map(|p| match p {
            Prim::Tri { v, .. } => Bounds::from_points(*v),
            Prim::Analytic { .. } => Bounds::EMPTY,
        })
        .collect();
    let scene = boxes
        .iter()
        .fold(Bounds::EMPTY, |a, b| a.union(*b))
        .diagonal()
        .length();
    let receivers: Vec<(usize, u32, u32, Receiver)> = prims
        .iter()
        .enumerate()
        .filter_map(|(i, p)| {
            let (shape, tri, t) = receiver(p)?;
            (t.size >= MIN_SIZE * scene).then_some((i, shape, tri, t))
        })
        .collect();
    if receivers.is_empty() {
        return Cuts::new();
    }
    // A contact's vertices within SNAP of its height count as on the plane:
    // its box, grown by that, meets the plane's triangle wherever it could.
    let reach: Vec<Bounds> = boxes
        .iter()
        .map(|b| {
            if b.is_empty() {
                *b
            } else {
                b.padded(SNAP * b.diagonal().length())
            }
        })
        .collect();
    let tree = BoxTree::new(&reach);
    let lines: Vec<Vec<Cut>> = receivers
        .par_iter()
        .map(|(i, _, _, t)| lines_of(t, *i, prims, &tree))
        .collect();
    let mut planes: Vec<Plane> = Vec::new();
    for ((_, shape, tri, t), lines) in receivers.into_iter().zip(lines) {
        let k = match planes.iter().position(|p| p.holds(shape, &t)) {
            Some(k) => k,
            None => {
                planes.push(Plane::new(shape, &t));
                planes.len() - 1
            }
        };
        planes[k].add(tri, t, lines);
    }
    let mut out = Cuts::new();
    for plane in planes {
        plane.cuts(&mut out);
    }
    out
}

/// The coplanar large triangles of one shape (a ground of two triangles)
/// and the lines of contacts on them: a wall's contact counts over the
/// whole plane, not only the part on one triangle, so that every
/// triangle it crosses is cut along it.
struct Plane {
    shape: u32,
    normal: DVec3,
    offset: f64,
    /// The largest triangle's size.
    size: f64,
    triangles: Vec<(u32, Receiver)>,
    lines: Vec<Cut>,
}

impl Plane {
    fn new(shape: u32, t: &Receiver) -> Plane {
        Plane {
            shape,
            normal: t.normal,
            offset: t.normal.dot(t.v[0]),
            size: t.size,
            triangles: Vec::new(),
            lines: Vec::new(),
        }
    }

    /// Whether triangle `t` of `shape` lies in this plane.
    fn holds(&self, shape: u32, t: &Receiver) -> bool {
        shape == self.shape
            && self.normal.dot(t.normal) >= 1.0 - 1e-9
            && t.v
                .iter()
                .all(|v| (self.normal.dot(*v) - self.offset).abs() <= MERGE * self.size.max(t.size))
    }

    fn add(&mut self, tri: u32, t: Receiver, lines: Vec<Cut>) {
        self.size = self.size.max(t.size);
        for line in lines {
            merge_line(&mut self.lines, line, MERGE * self.size);
        }
        self.triangles.push((tri, t));
    }

    /// The cuts of each triangle: the plane's lines whose contacts add up
    /// to [`MIN_CONTACT`] of its largest triangle (at most [`MAX_CUTS`],
    /// the longest) that leave [`MIN_PIECE`] of the triangle on both sides.
    fn cuts(mut self, out: &mut Cuts) {
        self.lines.retain(|c| c.length >= MIN_CONTACT * self.size);
        self.lines.sort_by(|a, b| b.length.total_cmp(&a.length));
        self.lines.truncate(MAX_CUTS);
        for (tri, t) in &self.triangles {
            let margin = MIN_PIECE * t.size;
            let cuts: Vec<Cut> = self
                .lines
                .iter()
                .filter(|c| {
                    let side = t.v.map(|v| c.normal.dot(v) - c.offset);
                    side.iter().any(|&x| x < -margin) && side.iter().any(|&x| x > margin)
                })
                .cloned()
                .collect();
            if !cuts.is_empty() {
                out.entry(self.shape).or_default().insert(*tri, cuts);
            }
        }
    }
}

/// A mesh triangle as a receiver of cuts, with its shape and index in its
/// mesh (`None` for anything else).
fn receiver(p: &Prim) -> Option<(u32, u32, Receiver)> {
    let Prim::Tri {
        v,
        normal,
        owner: TriOwner::Mesh { tri, .. },
        shape,
        ..
    } = *p
    else {
        return None;
    };
    let size = (v[1] - v[0]).cross(v[2] - v[0]).length().sqrt();
    Some((shape, tri, Receiver { v, normal, size }))
}

/// The lines of the contacts on one triangle (index `me` in `prims`), each
/// with its contacts' total length.
fn lines_of(t: &Receiver, me: usize, prims: &[Prim], tree: &BoxTree) -> Vec<Cut> {
    let query = Bounds::from_points(t.v);
    let mut lines: Vec<Cut> = Vec::new();
    tree.overlapping(&query, |j| {
        if j == me {
            return;
        }
        if let Prim::Tri { v, normal, .. } = prims[j]
            && normal.dot(t.normal).abs() <= MAX_COS
            && let Some([p, q]) = contact(t, &v)
            && let Some(normal) = (q - p).cross(t.normal).try_normalize()
        {
            let line = Cut {
                normal,
                offset: normal.dot(p),
                length: p.distance(q),
            };
            merge_line(&mut lines, line, MERGE * t.size);
        }
    });
    lines
}

/// Where triangle `w` meets the plane of `t`, projected on it and clipped
/// to `t`; `None` when it does not, or only at a point.
fn contact(t: &Receiver, w: &[DVec3; 3]) -> Option<[DVec3; 2]> {
    let d = w.map(|p| t.normal.dot(p - t.v[0]));
    let height = d.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
    if height <= 0.0 {
        return None;
    }
    let s = d.map(|x| if x.abs() <= SNAP * height { 0.0 } else { x });
    // At most three points: a vertex on the plane, or a crossing of the
    // edge after it.
    let (mut on, mut count) = ([DVec3::ZERO; 3], 0);
    for i in 0..3 {
        let j = (i + 1) % 3;
        if s[i] == 0.0 {
            on[count] = w[i];
            count += 1;
        } else if s[j] != 0.0 && (s[i] > 0.0) != (s[j] > 0.0) {
            on[count] = w[i] + (w[j] - w[i]) * (d[i] / (d[i] - d[j]));
            count += 1;
        }
    }
    let (p, q) = farthest_pair(&on[..count])?;
    let project = |x: DVec3| x - t.normal * t.normal.dot(x - t.v[0]);
    clip_to_triangle(t, project(p), project(q))
}

/// The two points of `points` farthest apart (`None` for fewer than two).
fn farthest_pair(points: &[DVec3]) -> Option<(DVec3, DVec3)> {
    let mut best: Option<(f64, DVec3, DVec3)> = None;
    for (k, &a) in points.iter().enumerate() {
        for &b in &points[k + 1..] {
            let l = a.distance_squared(b);
            if best.is_none_or(|(m, _, _)| l > m) {
                best = Some((l, a, b));
            }
        }
    }
    best.filter(|b| b.0 > 0.0).map(|(_, a, b)| (a, b))
}

/// The part of segment pq (in t's plane) inside t (Cyrus–Beck), if it has
/// a length.
fn clip_to_triangle(t: &Receiver, p: DVec3, q: DVec3) -> Option<[DVec3; 2]> {
    let (mut lo, mut hi) = (0.0_f64, 1.0_f64);
    for i in 0..3 {
        let (a, b, c) = (t.v[i], t.v[(i + 1) % 3], t.v[(i + 2) % 3]);
        let mut inward = t.normal.cross(b - a);
        if inward.dot(c - a) < 0.0 {
            inward = -inward;
        }
        let (fp, fq) = (inward.dot(p - a), inward.dot(q - a));
        if fp < 0.0 && fq < 0.0 {
            return None;
        }
        if (fp < 0.0) != (fq < 0.0) {
            let x = fp / (fp - fq);
            if fp < 0.0 {
                lo = lo.max(x);
            } else {
                hi = hi.min(x);
            }
        }
    }
    (hi > lo).then(|| [p + (q - p) * lo, p + (q - p) * hi])
}

/// Adds `line` to the one of `lines` it lies on (within `tol`), or to the
/// list.
fn merge_line(lines: &mut Vec<Cut>, line: Cut, tol: f64) {
    for c in lines.iter_mut() {
        let cos = c.normal.dot(line.normal);
        if cos.abs() >= 1.0 - 1e-9 && (c.offset - cos.signum() * line.offset).abs() <= tol {
            c.length += line.length;
            return;
        }
    }
    lines.push(line);
}

/// Cuts the triangles of `mesh` named in `cuts` (module docs): their cells
/// are appended as new triangles, the cut triangles left degenerate (no
/// chart, not traced). Returns each cell's triangles, one chart each.
pub(crate) fn cut_mesh(mesh: &mut MeshData, cuts: &HashMap<u32, Vec<Cut>>) -> Vec<Vec<u32>> {
    let mut order: Vec<u32> = cuts.keys().copied().collect();
    order.sort_unstable();
    let mut charts = Vec::new();
    for t in order {
        let cells = cells(mesh, t, &cuts[&t]);
        charts.extend(fan(mesh, t, &cells).into_iter().filter(|c| !c.is_empty()));
        mesh.tri_area[t as usize] = 0.0;
        mesh.tri_normal[t as usize] = DVec3::ZERO;
    }
    charts
}

/// A convex cell of a cut triangle, its corners in the triangle's
/// barycentric coordinates (b1, b2).
type Cell = Vec<DVec2>;

/// The cells of triangle `t` after every cut.
fn cells(mesh: &MeshData, t: u32, cuts: &[Cut]) -> Vec<Cell> {
    let [a, b, c] = mesh.vertices(t);
    let size = (b - a).cross(c - a).length().sqrt();
    let (width, snap) = (MIN_CELL * size, SNAP_CELL * size);
    let mut cells = vec![vec![DVec2::ZERO, DVec2::X, DVec2::Y]];
    for cut in cuts {
        // The cut's signed distance (m) is affine in the barycentrics. A
        // corner within `snap` of the line counts as on it: the cut then
        // passes through the corner instead of leaving a sliver beside it
        // (a box's side that passes 6 mm from a floor triangle's corner).
        let s0 = cut.normal.dot(a) - cut.offset;
        let (sx, sy) = (cut.normal.dot(b - a), cut.normal.dot(c - a));
        let dist = |p: DVec2| {
            let d = s0 + sx * p.x + sy * p.y;
            if d.abs() <= snap { 0.0 } else { d }
        };
        cells = cells
            .into_iter()
            .flat_map(|cell| split(cell, &dist, width))
            .collect();
    }
    cells
}

/// A convex cell split by the line dist = 0: one cell, or two when both
/// parts reach at least `width` (m) from the line. A line that only clips
/// a corner of the cell, or runs along an edge close by, would leave a
/// sliver whose elements are too thin to mean anything (and which a 32-bit
/// bake cannot resolve); the cell is then left whole, the line's vertex
/// on its neighbour's edge lying on this cell's edge.
fn split(cell: Cell, dist: &impl Fn(DVec2) -> f64, width: f64) -> Vec<Cell> {
    let (mut neg, mut pos) = (Vec::new(), Vec::new());
    let n = cell.len();
    for i in 0..n {
        let (p, q) = (cell[i], cell[(i + 1) % n]);
        let (dp, dq) = (dist(p), dist(q));
        if dp <= 0.0 {
            neg.push(p);
        }
        if dp >= 0.0 {
            pos.push(p);
        }
        if (dp < 0.0 && dq > 0.0) || (dp > 0.0 && dq < 0.0) {
            let x = edge_point(p, q, dist);
            neg.push(x);
            pos.push(x);
        }
    }
    let reach = |part: &[DVec2]| part.iter().fold(0.0_f64, |m, &p| m.max(dist(p).abs()));
    if neg.len() < 3 || pos.len() < 3 || reach(&neg) < width || reach(&pos) < width {
        return vec![cell];
    }
    vec![neg, pos]
}

/// Where edge pq meets dist = 0, computed from the ends in one fixed order
/// so that the cells on both sides of the edge get the same point.
fn edge_point(p: DVec2, q: DVec2, dist: &impl Fn(DVec2) -> f64) -> DVec2 {
    let key = |x: DVec2| (x.x.to_bits(), x.y.to_bits());
    let (u, v) = if key(p) <= key(q) { (p, q) } else { (q, p) };
    let (du, dv) = (dist(u), dist(v));
    u + (v - u) * (du / (du - dv))
}

/// Fans every cell into triangles appended to `mesh` (their corners new
/// vertices, shading normals and texture coordinates interpolated from
/// triangle `t`'s); returns each cell's new triangles.
fn fan(mesh: &mut MeshData, t: u32, cells: &[Cell]) -> Vec<Vec<u32>> {
    let normal = mesh.tri_normal[t as usize];
    let mut index: HashMap<(u64, u64), u32> = HashMap::new();
    let mut out = Vec::with_capacity(cells.len());
    for cell in cells {
        let ids: Vec<u32> = cell
            .iter()
            .map(|&p| {
                *index
                    .entry((p.x.to_bits(), p.y.to_bits()))
                    .or_insert_with(|| vertex(mesh, t, p))
            })
            .collect();
        let mut tris = Vec::new();
        for k in 1..ids.len().saturating_sub(1) {
            let tri = [ids[0], ids[k], ids[k + 1]];
            let [p, q, r] = tri.map(|v| mesh.positions[v as usize]);
            let area = 0.5 * (q - p).cross(r - p).length();
            if area > FAN_MIN_AREA * mesh.tri_area[t as usize] {
                tris.push(mesh.triangles.len() as u32);
                mesh.triangles.push(tri);
                mesh.tri_normal.push(normal);
                mesh.tri_area.push(area);
                mesh.tri_surface.push(u32::MAX);
            }
        }
        out.push(tris);
    }
    out
}

/// A new vertex at barycentrics `p` of triangle `t` (its own corners
/// reused), its attributes interpolated.
fn vertex(mesh: &mut MeshData, t: u32, p: DVec2) -> u32 {
    let corners = mesh.triangles[t as usize];
    let w = [1.0 - p.x - p.y, p.x, p.y];
    if let Some(k) = w.iter().position(|&x| x == 1.0) {
        return corners[k];
    }
    let position = mesh.point(t, p);
    mesh.positions.push(position);
    if let Some(ns) = &mut mesh.shading_normals {
        // Left unnormalised, as the mesh's own: a hit interpolates and
        // normalises, so the cells shade exactly as the triangle did.
        let n = (0..3)
            .map(|k| ns[corners[k] as usize] * w[k])
            .sum::<DVec3>();
        ns.push(n);
    }
    if let Some(uv) = &mut mesh.texcoords {
        let x = (0..3)
            .map(|k| uv[corners[k] as usize] * w[k])
            .sum::<DVec2>();
        uv.push(x);
    }
    (mesh.positions.len() - 1) as u32
}
