//! Unoccluded element-to-element form factors with an error estimate.
//!
//! F_{i→j} = (1/A_i) ∫_{A_i} ∫_{A_j} cos θ_x cos θ_y / (π r²) dA_y dA_x,
//! both cosines on the front sides (light leaves i's front towards j's
//! front); paper Eq. 5 uses F_{J→I} in the area reflectance.
//!
//! # Method
//!
//! - **Polygonal receiver** (a uv rectangle of a planar quad, or a cluster
//!   of at most [`MAX_POLYGON_PIECES`] triangle pieces): the inner integral
//!   is Lambert's closed form for a point and a polygon,
//!   F(dA_x → P) = (1/2π) |Σ_e β_e n_x · u_e| ([`lambert`]), after
//!   clipping P to x's tangent plane and dropping pieces whose front does not
//!   face x. The sender is first clipped to the receiver's front half-space
//!   (the integrand vanishes behind it, with a kink along the plane); for
//!   a non-planar cluster, to each piece's half-space in turn, integrating
//!   piece by piece (otherwise a sliver in front of one piece could hold no
//!   rule point and be missed). The outer integral over the sender is adaptive
//!   cubature: a degree-5 rule (3×3 Gauss–Legendre on uv rectangles,
//!   Dunavant's 7-point rule on triangles) on a domain is accepted at once
//!   if it agrees with the one-point rule within the domain's share of the
//!   tolerance; otherwise it is compared with the same rule on its four
//!   children, and where they differ by more than the tolerance the children
//!   are refined in turn (to `max_depth` levels). This resolves the
//!   logarithmic singularity along an edge shared with the receiver. Disk
//!   elements are integrated as quarter-turn sectors.
//! - **Polygonal sender, non-polygonal receiver**: the same, integrating
//!   over the receiver and using reciprocity A_i F_ij = A_j F_ji.
//! - **Neither polygonal** (disks, sphere and cylinder pieces): adaptive
//!   cubature of the kernel over the pair (the product of the two degree-5
//!   rules; each step compares splitting either element and refines the one
//!   that matters more, as hierarchical radiosity refines links, up to
//!   `max_depth + 2` splits): a deterministic point-sampled estimate.
//! - **Large clusters** (more than [`MAX_POLYGON_PIECES`] pieces on a side
//!   that must be integrated): a sampled estimate stratified by piece (at
//!   least one Owen-scrambled Sobol point in every piece, `samples` in all
//!   at least), with Lambert's form on the other side when it is polygonal
//!   and the kernel with a sampled point of the other element otherwise.
//!
//! `error` is the sum over the final subdomains of |fine − coarse| (a
//! conservative estimate of the error of the returned fine value; a domain
//! accepted at once contributes |degree-5 − one-point|), or, for sampled
//! estimates, the standard error from collapsing neighbouring strata in
//! pairs. `spread` is max − min of the point estimates of F_{from→to} seen
//! during the integration: how much the transfer varies over the integrated
//! element, the usual refinement oracle.
//!
//! Submodules: `cubature` (integration domains and adaptive rules),
//! [`lambert`] (the point-to-polygon closed form and its clipping),
//! `sampled` (the stratified estimate for large clusters); this module
//! turns elements into domains and polygons and picks the method.

pub(crate) mod cubature;
pub mod lambert;
pub mod point;
pub(crate) mod sampled;

use std::f64::consts::PI;

use glam::{DVec2, DVec3};
use rayon::prelude::*;

use crate::element::ElementDomain;
use crate::face::FaceElement;
use crate::forest::ElementForest;
use crate::ids::ElementId;
use crate::patch::Patch;
use crate::surface::SurfaceGeom;

use cubature::{QDom, integrate_pairs};
use lambert::{Poly, integrate_lambert};

pub use lambert::{point_to_polygon, point_to_polygon_front};
pub use point::PointFormFactors;

/// Clusters with at most this many pieces are treated as polygon sets
/// (Lambert's formula, deterministic cubature); larger ones are sampled.
pub const MAX_POLYGON_PIECES: usize = 8;

/// A form factor estimate.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FormFactor {
    /// The estimate of F_{from→to} (unoccluded), ≥ 0.
    pub value: f64,
    /// Estimated absolute error of `value` (module docs).
    pub error: f64,
    /// max − min of the point estimates of F_{from→to} over the integrated
    /// element (module docs).
    pub spread: f64,
}

impl FormFactor {
    /// From an integral ∫ F (an area times a form factor), its error and the
    /// range of the point values seen, over the sender's area `a_from`.
    fn from_integral(v: f64, e: f64, a_from: f64, lo: f64, hi: f64) -> FormFactor {
        FormFactor {
            value: (v / a_from).max(0.0),
            error: e / a_from,
            spread: if hi >= lo { hi - lo } else { 0.0 },
        }
    }
}

/// Accuracy settings for [`form_factor`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FormFactorOptions {
    /// Target relative accuracy of the adaptive cubature.
    pub rel_tol: f64,
    /// Maximum number of adaptive refinement levels.
    pub max_depth: u32,
    /// Number of sample pairs for sampled estimates (large clusters).
    pub samples: u32,
}

impl Default for FormFactorOptions {
    /// rel_tol 1e-3, 4 levels, 64 samples.
    fn default() -> Self {
        FormFactorOptions {
            rel_tol: 1e-3,
            max_depth: 4,
            samples: 64,
        }
    }
}

/// The point-to-point kernel cos θ_x cos θ_y / (π r²), one-sided.
#[inline]
pub(crate) fn kernel(x: DVec3, nx: DVec3, y: DVec3, ny: DVec3) -> f64 {
    let d = y - x;
    let r2 = d.length_squared();
    let cx = nx.dot(d);
    let cy = -ny.dot(d);
    if cx <= 0.0 || cy <= 0.0 || r2 == 0.0 {
        return 0.0;
    }
    cx * cy / (PI * r2 * r2)
}

/// Unoccluded form factor F_{from→to} between the front faces of two
/// elements, with the default accuracy ([`FormFactorOptions::default`]).
pub fn form_factor_front(forest: &ElementForest, from: ElementId, to: ElementId) -> FormFactor {
    form_factor(
        forest,
        FaceElement::front(from),
        FaceElement::front(to),
        &FormFactorOptions::default(),
    )
}

/// Many form factors at once, in parallel (rayon).
pub fn form_factor_batch(
    forest: &ElementForest,
    pairs: &[(FaceElement, FaceElement)],
    opts: &FormFactorOptions,
) -> Vec<FormFactor> {
    pairs
        .par_iter()
        .map(|&(a, b)| form_factor(forest, a, b, opts))
        .collect()
}

/// Unoccluded form factor from one face of an element to one face of
/// another (light leaving `from` on its side towards `to`, arriving on
/// `to`'s side), by the method of the module docs.
pub fn form_factor(
    forest: &ElementForest,
    from: FaceElement,
    to: FaceElement,
    opts: &FormFactorOptions,
) -> FormFactor {
    let a_from = forest.element(from.element).area;
    let a_to = forest.element(to.element).area;
    if coplanar(forest, from.element, to.element) {
        return FormFactor::default();
    }
    let depth = opts.max_depth;
    let tol = opts.rel_tol.max(1e-14);
    let to_polys = element_polygons(forest, to);
    let from_doms = element_domains(forest, from);
    if let (Some(polys), Some(doms)) = (&to_polys, &from_doms) {
        let (v, e, lo, hi) = integrate_lambert(doms, polys, tol, depth);
        return FormFactor::from_integral(v, e, a_from, lo, hi);
    }
    let from_polys = element_polygons(forest, from);
    let to_doms = element_domains(forest, to);
    if let (Some(polys), Some(doms)) = (&from_polys, &to_doms) {
        // Reciprocity: A_from F_from→to = A_to F_to→from.
        let ratio = a_to / a_from;
        let (v, e, lo, hi) = integrate_lambert(doms, polys, tol, depth);
        return FormFactor::from_integral(v, e, a_from, lo * ratio, hi * ratio);
    }
    if let (Some(fd), Some(td)) = (&from_doms, &to_doms) {
        let (v, e, lo, hi) = integrate_pairs(fd, td, tol, depth + 2);
        return FormFactor::from_integral(v, e, a_from, lo, hi);
    }
    let polys = sampled::OtherSide {
        to: to_polys.as_deref(),
        from: from_polys.as_deref(),
    };
    sampled::estimate(forest, from, to, polys, opts.samples)
}

/// The form factor from a differential area at `x` with unit normal `n` to
/// a face of an element, F(dA_x → to) = ∫_to cos θ_x cos θ_y / (π r²) dA_y
/// (unoccluded, one-sided on both ends): Lambert's closed form for quads
/// and clusters of triangle pieces (exact), the degree-5 rule of each
/// integration domain for curved pieces and disks (accurate when `x` is
/// farther than the element's size; a caller near the element refines it).
pub fn point_form_factor(forest: &ElementForest, x: DVec3, n: DVec3, to: FaceElement) -> f64 {
    if let Some(polys) = element_polygons_up_to(forest, to, usize::MAX) {
        return lambert::lambert_sum(x, n, &polys);
    }
    let Some(doms) = element_domains(forest, to) else {
        return 0.0;
    };
    let mut f = 0.0;
    for d in &doms {
        for (y, ny, w) in d.points() {
            f += w * kernel(x, n, y, ny);
        }
    }
    f.min(1.0)
}

/// True if both elements are planar and lie in the same plane (then no
/// light passes between them, whatever the sides).
pub(crate) fn coplanar(forest: &ElementForest, a: ElementId, b: ElementId) -> bool {
    let (ea, eb) = (forest.element(a), forest.element(b));
    if !(ea.is_planar() && eb.is_planar()) {
        return false;
    }
    if a == b {
        return true;
    }
    let scale = ea
        .bounds
        .diagonal()
        .length()
        .max(eb.bounds.diagonal().length())
        + ea.centre
            .abs()
            .max_element()
            .max(eb.centre.abs().max_element());
    // Symmetric in (a, b), so that F_ab and F_ba are both zero or both
    // computed (reciprocity): each centre lies in the other's plane.
    let d = eb.centre - ea.centre;
    ea.normal.dot(eb.normal).abs() > 1.0 - 1e-12
        && ea.normal.dot(d).abs() <= 1e-12 * scale
        && eb.normal.dot(d).abs() <= 1e-12 * scale
}

/// The element as polygons (fronts on its side), if it is polygonal: a uv
/// rectangle of a planar quad, or a cluster of at most
/// [`MAX_POLYGON_PIECES`] pieces.
fn element_polygons(forest: &ElementForest, fe: FaceElement) -> Option<Vec<Poly>> {
    element_polygons_up_to(forest, fe, MAX_POLYGON_PIECES)
}

/// [`element_polygons`] for clusters of at most `max_pieces` pieces.
fn element_polygons_up_to(
    forest: &ElementForest,
    fe: FaceElement,
    max_pieces: usize,
) -> Option<Vec<Poly>> {
    let (id, s) = (fe.element, fe.side.sign());
    let e = forest.element(id);
    match (e.domain, &forest.geometry().surface(e.surface).geom) {
        (ElementDomain::Rect { min, max }, SurfaceGeom::Patch(patch))
            if matches!(patch.as_ref(), Patch::Quad { .. }) =>
        {
            let normal = patch.eval(DVec2::ZERO).n;
            let v = [min, DVec2::new(max.x, min.y), max, DVec2::new(min.x, max.y)]
                .map(|uv| patch.eval(uv).p);
            Some(vec![Poly {
                v,
                len: 4,
                n: s * normal,
            }])
        }
        (ElementDomain::Cluster { count, .. }, SurfaceGeom::Chart { mesh, .. })
            if count as usize <= max_pieces =>
        {
            let m = &forest.geometry().meshes[*mesh as usize];
            Some(
                forest
                    .element_pieces(id)
                    .iter()
                    .map(|p| {
                        let [a, b, c] = p.corners(m);
                        Poly {
                            v: [a, b, c, c],
                            len: 3,
                            n: s * m.tri_normal[p.triangle as usize],
                        }
                    })
                    .collect(),
            )
        }
        _ => None,
    }
}

/// The element as integration domains (normals on its side), unless it is
/// a large cluster. Disk elements spanning more than a quarter turn are
/// integrated as quarter-turn sectors: a 3-point rule over a whole
/// revolution is poor.
fn element_domains(forest: &ElementForest, fe: FaceElement) -> Option<Vec<QDom<'_>>> {
    let (id, s) = (fe.element, fe.side.sign());
    let e = forest.element(id);
    match (e.domain, &forest.geometry().surface(e.surface).geom) {
        (ElementDomain::Rect { min, max }, SurfaceGeom::Patch(patch)) => {
            let turns = if matches!(patch.as_ref(), Patch::Disk { .. }) {
                ((max.y - min.y) / 0.25 - 1e-9).ceil().max(1.0) as usize
            } else {
                1
            };
            let dv = (max.y - min.y) / turns as f64;
            let sector = |k: usize| QDom::Rect {
                patch,
                min: DVec2::new(min.x, min.y + k as f64 * dv),
                max: DVec2::new(
                    max.x,
                    if k + 1 == turns {
                        max.y
                    } else {
                        min.y + (k + 1) as f64 * dv
                    },
                ),
                s,
            };
            Some((0..turns).map(sector).collect())
        }
        (ElementDomain::Cluster { count, .. }, SurfaceGeom::Chart { mesh, .. })
            if count as usize <= MAX_POLYGON_PIECES =>
        {
            let m = &forest.geometry().meshes[*mesh as usize];
            Some(
                forest
                    .element_pieces(id)
                    .iter()
                    .map(|p| QDom::Tri {
                        v: p.corners(m),
                        n: s * m.tri_normal[p.triangle as usize],
                    })
                    .collect(),
            )
        }
        _ => None,
    }
}
