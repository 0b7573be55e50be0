//! Elements: the nodes of an input surface's tree (paper §3.2), stored in
//! the arena of an [`crate::ElementForest`] with `u32` indices and created
//! lazily by [`crate::ElementForest::subdivide`].
//!
//! A parametric element is a (u, v) rectangle of its surface; its four
//! children are the quadrants (0: low u low v, 1: high u low v, 2: low u
//! high v, 3: high u high v), evaluated on the true surface. A chart element
//! is a cluster of triangle pieces ([`crate::chart`]).

use glam::{DVec2, DVec3};
use serde::{Deserialize, Serialize};

use crate::bounds::Bounds;
use crate::ids::{ElementId, SurfaceId};
use crate::patch::Patch;

/// `first_child` of a leaf.
pub(crate) const NO_CHILD: u32 = u32::MAX;

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
    /// arena (see [`crate::ElementForest::element_pieces`]).
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
