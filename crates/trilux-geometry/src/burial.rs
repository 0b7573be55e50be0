//! Buried parts of surfaces: where another surface lies on or just in front
//! of a face, so that the face there neither receives nor sends light (the
//! floor under a box, a ceiling just above a lamp's back, a wall behind a
//! cupboard standing against it).
//!
//! Piecewise-constant radiance spreads what an element receives over its
//! whole area and sends it from its whole area. An element that straddles
//! the edge of a box standing on it receives on its open part only, but
//! would send a share of that light from its covered part, into the box,
//! where it is lost: a systematic energy sink at every contact, which
//! refinement shrinks only linearly. A [`BurialMap`] marks the covered
//! parts once ([`BurialMap::probe`]), so that shadow segments from or to a
//! buried point count as blocked (it is handed to
//! [`crate::Visibility`]) and the solver spreads an element's light over
//! its exposed area only ([`BurialMap::exposed_fraction`]).
//!
//! **The test.** A point of a face is buried when each of 9 probe rays
//! into the face's hemisphere (the normal, and 8 directions 60° from it)
//! meets another shape within `reach`, a distance of the order of the
//! map's cell size. The probes start a hair behind the face and ignore its
//! own shape, so a coincident face (a box's bottom on the floor) counts.
//! A face seen through a gap wider than `reach` stays exposed: the light
//! that enters the gap is then resolved by visibility, as everywhere else.
//! Shapes that let light through ([`crate::transmission`]: a pane of
//! glass close in front of a face, the sky's box just outside a window)
//! cover nothing: the probes go on through them.
//!
//! **Crossings** ([`crate::crossing`], [`BurialMap::probe_with_light`]):
//! on a face that another surface crosses, the parts the crossing cuts off
//! from the light (outside a room whose floor runs past its walls, inside
//! a box sunk into the floor) are marked in the same grid, with the same
//! consequences.
//!
//! **Resolution.** A parametric surface's face gets an R × R grid of cells
//! in (u, v), refined 4 × 4 along the outlines of buried regions; a chart's
//! face one probe per midpoint sub-triangle (4 per triangle).

use std::collections::HashMap;

use glam::{DVec2, DVec3};
use rayon::prelude::*;

use crate::crossing::{LightFaces, Reach, crossed_faces};
use crate::element::ElementDomain;
use crate::face::{FaceElement, FaceId, PerFace};
use crate::forest::ElementForest;
use crate::geometry::{Geometry, Ray};
use crate::surface::{SurfaceCoord, SurfaceGeom};

/// Which cells of which faces are buried.
#[derive(Clone, Debug, Default)]
pub struct BurialMap {
    /// `None`: not probed (all exposed).
    faces: PerFace<Option<FaceBurial>>,
}

#[derive(Clone, Debug)]
enum FaceBurial {
    /// `res` × `res` cells over (u, v), row-major in v; true = buried.
    Grid { res: u32, buried: Vec<bool> },
    /// Per mesh triangle, 4 bits (corner a, corner b, corner c, middle).
    Triangles { buried: HashMap<u32, u8> },
}

/// The centroids of the four midpoint sub-triangles, in barycentrics
/// (b1, b2): corners at vertex 0, 1, 2, then the middle one.
const SUB_CENTROIDS: [(f64, f64); 4] = [
    (1.0 / 6.0, 1.0 / 6.0),
    (2.0 / 3.0, 1.0 / 6.0),
    (1.0 / 6.0, 2.0 / 3.0),
    (1.0 / 3.0, 1.0 / 3.0),
];

/// The midpoint sub-triangle holding barycentrics (b1, b2).
fn sub_triangle(bary: DVec2) -> usize {
    let b0 = 1.0 - bary.x - bary.y;
    if b0 >= 0.5 {
        0
    } else if bary.x >= 0.5 {
        1
    } else if bary.y >= 0.5 {
        2
    } else {
        3
    }
}

/// What to probe: one face of a surface, at a grid resolution (ignored for
/// charts).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BurialRequest {
    /// The face.
    pub face: FaceId,
    /// Cells per side of the (u, v) grid.
    pub resolution: u32,
}

impl BurialMap {
    /// Probes the requested faces for buried parts (module docs), in
    /// parallel.
    pub fn probe(geom: &Geometry, requests: &[BurialRequest]) -> BurialMap {
        Self::probe_with_light(geom, requests, None)
    }

    /// [`BurialMap::probe`], and with `light` the parts of crossed faces
    /// that a crossing cuts off from the light are marked as buried too
    /// ([`crate::crossing`]).
    pub fn probe_with_light(
        geom: &Geometry,
        requests: &[BurialRequest],
        light: Option<&LightFaces>,
    ) -> BurialMap {
        let mut faces = PerFace::from_fn(geom.surfaces().len(), |_| None);
        let crossed = match light {
            Some(_) => crossed_faces(geom),
            None => Vec::new(),
        };
        let reach = light.map(|light| Reach {
            geom,
            light,
            crossed: &crossed,
        });
        let probed: Vec<(FaceId, FaceBurial)> = requests
            .par_iter()
            .filter(|r| r.face.surface().index() < geom.surfaces().len())
            .map(|r| {
                let cut = reach.as_ref().filter(|_| {
                    crossed
                        .get(r.face.surface().index())
                        .copied()
                        .unwrap_or(false)
                });
                (r.face, probe_face(geom, r, cut))
            })
            .collect();
        for (face, f) in probed {
            faces[face] = Some(f);
        }
        BurialMap { faces }
    }

    /// True if the point `coord` of face `face` is buried.
    pub fn is_buried(&self, face: FaceId, coord: SurfaceCoord) -> bool {
        match (self.faces.get(face), coord) {
            (Some(Some(FaceBurial::Grid { res, buried })), SurfaceCoord::Uv(uv)) => {
                let r = *res as f64;
                let i = ((uv.x * r) as i64).clamp(0, *res as i64 - 1) as usize;
                let j = ((uv.y * r) as i64).clamp(0, *res as i64 - 1) as usize;
                buried[j * *res as usize + i]
            }
            (
                Some(Some(FaceBurial::Triangles { buried })),
                SurfaceCoord::Triangle { index, bary },
            ) => buried
                .get(&index)
                .is_some_and(|bits| bits & (1 << sub_triangle(bary)) != 0),
            _ => false,
        }
    }

    /// True if no face has a buried cell.
    pub fn is_empty(&self) -> bool {
        self.faces.values().flatten().all(|f| match f {
            FaceBurial::Grid { buried, .. } => !buried.contains(&true),
            FaceBurial::Triangles { buried } => buried.values().all(|&b| b == 0),
        })
    }

    /// The exposed share of an element's face, in [0, 1] (1 where the face
    /// was not probed): the fraction of its grid cells (of its pieces'
    /// area, for chart clusters) that are not buried.
    pub fn exposed_fraction(&self, forest: &ElementForest, fe: FaceElement) -> f64 {
        let (id, e) = (fe.element, forest.element(fe.element));
        let Some(Some(face)) = self.faces.get(FaceId::new(e.surface, fe.side)) else {
            return 1.0;
        };
        match (face, e.domain) {
            (FaceBurial::Grid { res, buried }, ElementDomain::Rect { min, max }) => {
                let r = *res as f64;
                let cells = |lo: f64, hi: f64| {
                    let a = ((lo * r).round() as i64).clamp(0, *res as i64 - 1);
                    let b = ((hi * r).round() as i64).clamp(a + 1, *res as i64);
                    (a as usize, b as usize)
                };
                let (i0, i1) = cells(min.x, max.x);
                let (j0, j1) = cells(min.y, max.y);
                let mut open = 0usize;
                for j in j0..j1 {
                    for i in i0..i1 {
                        open += usize::from(!buried[j * *res as usize + i]);
                    }
                }
                open as f64 / ((i1 - i0) * (j1 - j0)) as f64
            }
            (FaceBurial::Triangles { buried }, ElementDomain::Cluster { .. }) => {
                let (mut open, mut total) = (0.0, 0.0);
                for p in forest.element_pieces(id) {
                    let [a, b, c] = p.bary;
                    // Sub-triangle area fraction × the triangle's area.
                    let w = 0.5 * ((b - a).perp_dot(c - a)).abs() * 2.0;
                    let area = w * forest.geometry().triangle_area(e.surface, p.triangle);
                    let centre = (a + b + c) / 3.0;
                    let bits = buried.get(&p.triangle).copied().unwrap_or(0);
                    total += area;
                    if bits & (1 << sub_triangle(centre)) == 0 {
                        open += area;
                    }
                }
                if total > 0.0 { open / total } else { 1.0 }
            }
            _ => 1.0,
        }
    }
}

/// Probes one face: a grid over (u, v) for parametric surfaces, four
/// probes per triangle for charts.
fn probe_face(geom: &Geometry, r: &BurialRequest, reach: Option<&Reach<'_>>) -> FaceBurial {
    match &geom.surface(r.face.surface()).geom {
        SurfaceGeom::Patch(_) => probe_grid(geom, r, reach),
        SurfaceGeom::Chart { mesh, .. } => probe_triangles(geom, r.face, *mesh),
    }
}

/// The centre of cell (i, j) of a `res` × `res` grid over (u, v).
fn cell_centre(i: u32, j: u32, res: u32) -> DVec2 {
    DVec2::new((i as f64 + 0.5) / res as f64, (j as f64 + 0.5) / res as f64)
}

/// A parametric face: one probe per coarse cell; where buried and exposed
/// cells meet (a box's outline), FINE × FINE probes per cell, so that the
/// cells straddling the outline, which send light into the box from their
/// covered part, are few.
fn probe_grid(geom: &Geometry, r: &BurialRequest, reach: Option<&Reach<'_>>) -> FaceBurial {
    const FINE: u32 = 4;
    let surface = r.face.surface();
    let s = geom.surface(surface);
    let sign = r.face.side().sign();
    let coarse = r.resolution.clamp(1, 256);
    // Cells are about sqrt(area)/res across.
    let cut_off = reach;
    let reach = s.area.sqrt() / coarse as f64;
    let probe_uv = |uv: DVec2| {
        geom.surface_point(surface, SurfaceCoord::Uv(uv))
            .is_some_and(|p| {
                let n = p.normal * sign;
                probe(geom, p.point, n, s.shape, reach)
                    || cut_off.is_some_and(|c| !c.is_lit(p.point, n))
            })
    };
    let first: Vec<bool> = (0..coarse * coarse)
        .map(|c| probe_uv(cell_centre(c % coarse, c / coarse, coarse)))
        .collect();
    if !first.contains(&true) {
        return FaceBurial::Grid {
            res: coarse,
            buried: first,
        };
    }
    let at = |i: i64, j: i64| -> Option<bool> {
        (i >= 0 && j >= 0 && i < coarse as i64 && j < coarse as i64)
            .then(|| first[(j * coarse as i64 + i) as usize])
    };
    let res = coarse * FINE;
    let mut buried = vec![false; (res * res) as usize];
    for j in 0..coarse {
        for i in 0..coarse {
            let here = first[(j * coarse + i) as usize];
            let boundary = (-1..=1).any(|dj| {
                (-1..=1).any(|di| at(i as i64 + di, j as i64 + dj).is_some_and(|b| b != here))
            });
            for sj in 0..FINE {
                for si in 0..FINE {
                    let (fi, fj) = (i * FINE + si, j * FINE + sj);
                    buried[(fj * res + fi) as usize] = if boundary {
                        probe_uv(cell_centre(fi, fj, res))
                    } else {
                        here
                    };
                }
            }
        }
    }
    FaceBurial::Grid { res, buried }
}

/// A chart's face: one probe per midpoint sub-triangle of each triangle.
fn probe_triangles(geom: &Geometry, face: FaceId, mesh: u32) -> FaceBurial {
    let surface = face.surface();
    let shape = geom.surface(surface).shape;
    let sign = face.side().sign();
    let m = &geom.meshes[mesh as usize];
    let mut buried = HashMap::new();
    for (t, &owner) in m.tri_surface.iter().enumerate() {
        if owner != surface.0 {
            continue;
        }
        let reach = (0.25 * m.tri_area[t]).sqrt();
        let mut bits = 0u8;
        for (k, &(b1, b2)) in SUB_CENTROIDS.iter().enumerate() {
            let coord = SurfaceCoord::Triangle {
                index: t as u32,
                bary: DVec2::new(b1, b2),
            };
            if geom
                .surface_point(surface, coord)
                .is_some_and(|p| probe(geom, p.point, p.normal * sign, shape, reach))
            {
                bits |= 1 << k;
            }
        }
        if bits != 0 {
            buried.insert(t as u32, bits);
        }
    }
    FaceBurial::Triangles { buried }
}

/// The largest reach, as a fraction of the scene's bounding diagonal.
/// Burial is contact (a box on the floor, a cupboard against a wall); a
/// cell's size stands for contact only while cells are small. A floor
/// that runs 220 m out under the sky as two triangles has probes reaching
/// 78 m, and every one of them met the ceiling 3 m up: the whole classroom
/// floor was buried, and with it the light it reflects (docs/solver.md,
/// "Buried parts of faces").
const MAX_REACH: f64 = 0.01;

/// True if every probe ray from `p` into the hemisphere of `n` meets
/// another shape within `reach` (at most [`MAX_REACH`] of the scene's
/// diagonal).
fn probe(geom: &Geometry, p: DVec3, n: DVec3, own_shape: u32, reach: f64) -> bool {
    let reach = reach.min(MAX_REACH * geom.bounds().diagonal().length());
    if !(p.is_finite() && n.is_finite() && reach > 0.0) {
        return false;
    }
    // Start a hair behind the face so that a coincident face is met.
    let behind = 1e-6 * geom.extent();
    let origin = p - n * behind;
    let (t, b) = n.any_orthonormal_pair();
    let (sin, cos) = (60f64.to_radians().sin(), 60f64.to_radians().cos());
    let dirs = std::iter::once(n).chain((0..8).map(|k| {
        let phi = k as f64 * std::f64::consts::FRAC_PI_4;
        cos * n + sin * (phi.cos() * t + phi.sin() * b)
    }));
    for d in dirs {
        // Distances count from the face, not from the probe's origin.
        let t_max = reach + behind / d.dot(n).max(1e-3);
        if geom
            .intersect_opaque_ignoring(&Ray { origin, dir: d }, t_max, own_shape)
            .is_none()
        {
            return false;
        }
    }
    true
}
