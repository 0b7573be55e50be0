//! Vertex colours from the leaves' radiance: flux-conserving averaging.
//!
//! Every triangle T of a [`ShapeMesh`] carries the value f_T of the leaf it
//! belongs to: the leaf's exitant radiance averaged over its area, buried
//! parts counting as black (L · A_exposed / A). A vertex takes the
//! area-weighted mean of the triangles around it,
//!
//!   v_i = Σ_{T ∋ i} A_T f_T / Σ_{T ∋ i} A_T.
//!
//! A viewer interpolates linearly over each triangle, so the flux it shows
//! is
//!
//!   Σ_T A_T (v_a + v_b + v_c)/3 = Σ_i v_i Σ_{T ∋ i} A_T/3 = Σ_T A_T f_T,
//!
//! the leaves' own flux over the tessellated area, whatever the
//! triangulation (the lumped-mass projection of a piecewise-constant field
//! onto piecewise-linear functions). Every input surface has its own
//! vertices (`tessellate`), so this holds per surface and side.
//!
//! Error bound: a vertex value is a convex combination of the values of
//! the leaves that touch the vertex, so the colour anywhere in a leaf lies
//! between the least and the greatest value of the leaves touching its
//! triangles' vertices. The centre vertex of a fan touches only its own
//! leaf: there the colour is the leaf's value exactly (a parametric leaf's
//! centre, a one-piece chart leaf's centroid).

use std::collections::BTreeMap;

use trilux_geometry::ElementId;

use crate::tessellate::ShapeMesh;

/// Vertex values of `mesh` from each leaf's value (module docs), each
/// triangle weighted by its area times `weight` of its leaf (per channel):
/// 1 for plain surfaces; for a textured side, whose file shows the light
/// E/π times an albedo map, the leaf's mean albedo ρ̄, so that
/// Σ_T A_T ρ̄_T (v_a + v_b + v_c)/3 is again the leaves' flux. A vertex no
/// triangle uses gets zero.
pub(crate) fn vertex_values(
    mesh: &ShapeMesh,
    value: impl Fn(ElementId) -> [f64; 3],
    weight: impl Fn(ElementId) -> [f64; 3],
) -> Vec<[f64; 3]> {
    let n = mesh.positions.len();
    let (mut sum, mut total) = (vec![[0.0; 3]; n], vec![[0.0; 3]; n]);
    let (mut plain, mut area) = (vec![[0.0; 3]; n], vec![0.0; n]);
    let mut last: Option<(ElementId, [f64; 3], [f64; 3])> = None;
    for (t, (tri, &owner)) in mesh.triangles.iter().zip(&mesh.owners).enumerate() {
        let (f, w) = match last {
            Some((e, f, w)) if e == owner => (f, w),
            _ => (value(owner), weight(owner)),
        };
        last = Some((owner, f, w));
        let a = mesh.triangle_area(t);
        for &v in tri {
            let v = v as usize;
            area[v] += a;
            for c in 0..3 {
                sum[v][c] += a * w[c] * f[c];
                total[v][c] += a * w[c];
                plain[v][c] += a * f[c];
            }
        }
    }
    (0..n)
        .map(|v| {
            std::array::from_fn(|c| match (total[v][c] > 0.0, area[v] > 0.0) {
                (true, _) => sum[v][c] / total[v][c],
                // Every weight zero (a black albedo): the plain mean.
                (false, true) => plain[v][c] / area[v],
                (false, false) => 0.0,
            })
        })
        .collect()
}

/// The flux Σ_T A_T w_T mean(v_T) (without the factor π) of the triangles
/// of `mesh`, with vertex values `values` and the weights of
/// `vertex_values`, summed by `key` of each triangle's leaf (its input
/// surface, say), in one pass.
pub(crate) fn baked_flux<K: Ord>(
    mesh: &ShapeMesh,
    values: &[[f64; 3]],
    weight: impl Fn(ElementId) -> [f64; 3],
    key: impl Fn(ElementId) -> K,
) -> BTreeMap<K, [f64; 3]> {
    let mut flux = BTreeMap::new();
    for (t, (tri, &owner)) in mesh.triangles.iter().zip(&mesh.owners).enumerate() {
        let (a, w) = (mesh.triangle_area(t) / 3.0, weight(owner));
        let sum: &mut [f64; 3] = flux.entry(key(owner)).or_insert([0.0; 3]);
        for &v in tri {
            for c in 0..3 {
                sum[c] += a * w[c] * values[v as usize][c];
            }
        }
    }
    flux
}
