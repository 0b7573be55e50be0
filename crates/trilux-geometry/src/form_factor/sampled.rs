//! The sampled form factor of large clusters (more than
//! [`super::MAX_POLYGON_PIECES`] pieces on a side that must be integrated):
//! points stratified by piece on the integrated side (at least one
//! Owen-scrambled Sobol point in every piece, `samples` in all at least),
//! with Lambert's closed form towards the other side when it is polygonal,
//! and the kernel towards a sampled point of it otherwise.
//!
//! F = Σ w g / A_from; its error is the standard error from collapsing
//! neighbouring strata (Morton or Sobol neighbours) in pairs,
//! Var ≈ Σ (y_a − y_b)², y = w g.

use glam::DVec3;

use crate::element::ElementDomain;
use crate::face::FaceElement;
use crate::forest::ElementForest;
use crate::sampling::square_to_triangle;
use crate::sequence::{seed_of, sobol2};
use crate::surface::SurfaceGeom;

use super::lambert::{Poly, lambert_sum};
use super::{FormFactor, kernel};

/// The sides of the pair that are polygonal, if any.
pub(crate) struct OtherSide<'p> {
    /// The receiver as polygons.
    pub to: Option<&'p [Poly]>,
    /// The sender as polygons.
    pub from: Option<&'p [Poly]>,
}

/// The sampled estimate of F_{from→to} (module docs).
pub(crate) fn estimate(
    forest: &ElementForest,
    from: FaceElement,
    to: FaceElement,
    polys: OtherSide<'_>,
    samples: u32,
) -> FormFactor {
    let a_from = forest.element(from.element).area;
    let a_to = forest.element(to.element).area;
    let seed = seed_of(from.element, to.element);
    let (values, weights): (Vec<f64>, Vec<f64>) = if let Some(p) = polys.to {
        stratified_points(forest, from, seed, 0, samples)
            .into_iter()
            .map(|(x, n, w)| (lambert_sum(x, n, p), w))
            .unzip()
    } else if let Some(p) = polys.from {
        stratified_points(forest, to, seed, 2, samples)
            .into_iter()
            .map(|(y, m, w)| (lambert_sum(y, m, p) * a_to / a_from, w * a_from / a_to))
            .unzip()
    } else {
        let xs = stratified_points(forest, from, seed, 0, samples);
        let n = xs.len() as u32;
        xs.into_iter()
            .enumerate()
            .map(|(k, (x, nx, w))| {
                let y = forest.sample_element(to.element, sobol2(k as u32 % n, 2, seed));
                let g = if y.pdf_area > 0.0 {
                    (kernel(x, nx, y.point, to.side.sign() * y.normal) / y.pdf_area).min(1.0)
                } else {
                    0.0
                };
                (g, w)
            })
            .unzip()
    };
    let total: f64 = values.iter().zip(&weights).map(|(g, w)| g * w).sum();
    let var: f64 = values
        .chunks(2)
        .zip(weights.chunks(2))
        .map(|(g, w)| {
            if g.len() == 2 {
                (g[0] * w[0] - g[1] * w[1]).powi(2)
            } else {
                0.0
            }
        })
        .sum();
    let (lo, hi) = values
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &g| {
            (lo.min(g), hi.max(g))
        });
    FormFactor::from_integral(total, var.sqrt(), a_from, lo, hi)
}

/// Stratified points (point, side normal, weight) of an element with
/// weights summing (in expectation) to its area: for a cluster of at most
/// 4096 pieces, ⌈samples / pieces⌉ (at least one) Sobol points in every
/// piece, each weighted by its share of the piece's area; otherwise
/// `samples` Sobol points mapped by `sample_element` with weight
/// 1/(pdf · n).
fn stratified_points(
    forest: &ElementForest,
    fe: FaceElement,
    seed: u32,
    dim: u32,
    samples: u32,
) -> Vec<(DVec3, DVec3, f64)> {
    let (id, sign) = (fe.element, fe.side.sign());
    let samples = samples.clamp(4, 1 << 16);
    let e = forest.element(id);
    if let (ElementDomain::Cluster { count, .. }, SurfaceGeom::Chart { mesh, .. }) =
        (e.domain, &forest.geometry().surface(e.surface).geom)
        && count <= 4096
    {
        let m = &forest.geometry().meshes[*mesh as usize];
        let per_piece = samples.div_ceil(count).max(1);
        let mut out = Vec::with_capacity((count * per_piece) as usize);
        for (k, p) in forest.element_pieces(id).iter().enumerate() {
            let a = m.tri_area[p.triangle as usize] * p.area_fraction() / per_piece as f64;
            let n = sign * m.tri_normal[p.triangle as usize];
            let piece_seed = seed ^ (k as u32).wrapping_mul(0x9E37_79B9);
            for j in 0..per_piece {
                let u = if per_piece == 1 {
                    sobol2(k as u32, dim, seed)
                } else {
                    sobol2(j, dim, piece_seed)
                };
                let l = square_to_triangle(u);
                let b = l[0] * p.bary[0] + l[1] * p.bary[1] + l[2] * p.bary[2];
                out.push((m.point(p.triangle, b), n, a));
            }
        }
        return out;
    }
    (0..samples)
        .map(|k| {
            let s = forest.sample_element(id, sobol2(k, dim, seed));
            let w = if s.pdf_area > 0.0 {
                1.0 / (s.pdf_area * samples as f64)
            } else {
                0.0
            };
            (s.point, sign * s.normal, w)
        })
        .collect()
}
