//! Crossings: parts of a face that another surface cuts off from the light
//! (a floor running past the walls of its room, the floor inside a box
//! sunk into it, the part of the box below the floor). They receive
//! nothing, and piecewise-constant radiance averaged over them makes the
//! element that straddles the crossing too dark (2 % over a whole room,
//! 8 % along its walls).
//!
//! This extends the burial probes ([`crate::burial`]): a cell of a
//! *crossed* face that is cut off is marked exactly like a buried one, so
//! visibility treats segments ending there as blocked and the solver
//! spreads an element's light over the rest of it (its exposed area).
//!
//! **Crossed faces.** Face A of a planar parametric surface is crossed
//! when some planar parametric surface B of another shape has A's corners
//! on both sides of its plane, each at least `MIN_CROSSING` of A's size
//! away from it, B's bounds meet A's bounds, and B's corners lie on both
//! sides of A's plane in the same sense: the two pass through each other.
//! A wall ending on the floor does not cross it, nor does a box resting on
//! the floor (or sunk into it by a modelling sliver, as in the Cornell
//! box); a floor and a wall that both run past each other, or a box sunk
//! into the floor, do. Not handled: a floor running past a wall that ends
//! on it (its outside part stays dark and is averaged in, as before), and
//! curved surfaces (a cylinder through a wall): only planar faces are
//! tested. Only crossed faces are probed, so scenes without crossings cost
//! nothing.
//!
//! **Cut off.** A point p of a crossed face is *lit* when
//! 1. a segment from p to one of `EMITTER_SAMPLES` points of some
//!    emitter's front face is unoccluded (both facing; panes of glass
//!    between let light through), or
//! 2. one of `REACH_RAYS` rays from p into its hemisphere meets a face
//!    that sends light (`senders`) at a point that is lit by test 1, or
//!    that lies on a face that is not crossed (whose every point counts as
//!    reached);
//!
//! otherwise it is cut off. The outside of a closed room sees no emitter,
//! and its rays meet the walls' black backs, the cut-off parts of other
//! crossed faces, or nothing.

use glam::{DVec2, DVec3};

use crate::face::{FaceId, PerFace, Side};
use crate::geometry::{Geometry, Ray};
use crate::ids::SurfaceId;
use crate::surface::SurfaceCoord;

/// The least depth (relative to the square root of the face's area) by
/// which a face must reach past the crossing plane on both sides for the
/// crossing to count (the modelling slivers of the Cornell box, a few
/// tenths of a per cent, do not).
pub(crate) const MIN_CROSSING: f64 = 0.05;

/// Segments to each emitter per probe point.
pub(crate) const EMITTER_SAMPLES: u32 = 4;
/// Reach rays per probe point.
pub(crate) const REACH_RAYS: u32 = 16;

/// What the crossing probe needs to know of the light: which faces emit,
/// and which send light at all (emit or reflect).
#[derive(Clone, Debug, Default)]
pub struct LightFaces {
    /// Fronts of emitters.
    pub emitters: Vec<FaceId>,
    /// Faces that emit or reflect.
    pub senders: PerFace<bool>,
}

/// The k-th point of a 2-D R2 sequence (Roberts 2018), offset by `shift`.
fn r2(k: u32, shift: f64) -> DVec2 {
    const G: f64 = 1.324_717_957_244_746;
    let k = f64::from(k);
    DVec2::new((shift + k / G).fract(), (shift + k / (G * G)).fract())
}

/// The corners of a parametric surface (`None` for a chart).
fn corners(geom: &Geometry, s: SurfaceId) -> Option<[DVec3; 4]> {
    geom.patch(s)?;
    let at = |u: f64, v: f64| {
        geom.surface_point(s, SurfaceCoord::Uv(DVec2::new(u, v)))
            .map(|p| p.point)
    };
    Some([at(0.0, 0.0)?, at(1.0, 0.0)?, at(0.0, 1.0)?, at(1.0, 1.0)?])
}

/// True when planar surface `a` and some planar surface of another shape
/// pass through each other (module docs).
pub fn is_crossed(geom: &Geometry, a: SurfaceId) -> bool {
    let Some(pa) = corners(geom, a) else {
        return false;
    };
    let sa = geom.surface(a);
    let tol = 1e-6 * geom.extent();
    let bounds = sa.bounds.padded(tol);
    // A sliver thinner than `MIN_CROSSING` of the face's size is below
    // the element resolution: not a crossing.
    let reach = (MIN_CROSSING * sa.area().sqrt()).max(tol);
    let a_plane = sa
        .is_planar()
        .then(|| geom.surface_point(a, SurfaceCoord::Uv(DVec2::splat(0.5))))
        .flatten()
        .map(|p| (p.point, p.normal));
    geom.surfaces().iter().enumerate().any(|(b, sb)| {
        if sb.shape == sa.shape || !sb.is_planar() {
            return false;
        }
        let bb = sb.bounds.padded(tol);
        let overlap = bounds.min.cmple(bb.max).all() && bb.min.cmple(bounds.max).all();
        if !overlap {
            return false;
        }
        let Some(p) = geom.surface_point(SurfaceId(b as u32), SurfaceCoord::Uv(DVec2::splat(0.5)))
        else {
            return false;
        };
        let d = pa.map(|c| (c - p.point).dot(p.normal));
        let a_through_b = d.iter().any(|&x| x > reach) && d.iter().any(|&x| x < -reach);
        // And B must pass through A's plane (a box resting on the floor,
        // or sunk into it by a sliver, does not cross it).
        let b_through_a = match (a_plane, corners(geom, SurfaceId(b as u32))) {
            (Some((o, n)), Some(pb)) => {
                let reach_b = (MIN_CROSSING * sb.area().sqrt()).max(tol);
                let e = pb.map(|c| (c - o).dot(n));
                e.iter().any(|&x| x > reach_b) && e.iter().any(|&x| x < -reach_b)
            }
            _ => false,
        };
        a_through_b && b_through_a
    })
}

/// The crossed faces among `faces`.
pub fn crossed_faces(geom: &Geometry) -> Vec<bool> {
    (0..geom.surfaces().len() as u32)
        .map(|s| is_crossed(geom, SurfaceId(s)))
        .collect()
}

/// What the probe of one face reads.
pub(crate) struct Reach<'a> {
    pub geom: &'a Geometry,
    pub light: &'a LightFaces,
    /// Crossed surfaces.
    pub crossed: &'a [bool],
}

impl Reach<'_> {
    /// True when `p` (normal `n`, on the side that sends and receives)
    /// sees an emitter's front through an unoccluded segment.
    fn sees_emitter(&self, p: DVec3, n: DVec3) -> bool {
        let eps = 1e-7 * self.geom.extent();
        self.light.emitters.iter().any(|&e| {
            (0..EMITTER_SAMPLES).any(|k| {
                let Some(q) = self
                    .geom
                    .surface_point(e.surface(), SurfaceCoord::Uv(r2(k, 0.5)))
                else {
                    return false;
                };
                let d = q.point - p;
                d.dot(n) > 0.0
                    && -d.dot(q.normal * e.side().sign()) > 0.0
                    && self.geom.transmittance(p + n * eps, q.point) > 0.0
            })
        })
    }

    /// True when point `p` of a crossed face (normal `n` on its sending
    /// side) is lit (module docs).
    pub(crate) fn is_lit(&self, p: DVec3, n: DVec3) -> bool {
        if self.sees_emitter(p, n) {
            return true;
        }
        let (t, b) = n.any_orthonormal_pair();
        let eps = 1e-7 * self.geom.extent();
        (0..REACH_RAYS).any(|k| {
            // Cosine-distributed directions.
            let u = r2(k, 0.25);
            let (r, phi) = (u.x.sqrt(), 2.0 * std::f64::consts::PI * u.y);
            let d = (r * phi.cos()) * t + (r * phi.sin()) * b + (1.0 - u.x).max(0.0).sqrt() * n;
            let ray = Ray {
                origin: p + n * eps,
                dir: d,
            };
            let Some((hit, _)) = self.geom.intersect_through(&ray, f64::INFINITY) else {
                return false;
            };
            let side = Side::from_back(!hit.front_facing(&ray));
            let face = FaceId::new(hit.surface, side);
            if !self.light.senders.get(face).copied().unwrap_or(false) {
                return false;
            }
            if !self
                .crossed
                .get(hit.surface.index())
                .copied()
                .unwrap_or(false)
            {
                return true;
            }
            let hn = hit.geometric_normal * side.sign();
            self.sees_emitter(hit.point, hn)
        })
    }
}
