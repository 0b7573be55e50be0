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

use trilux_geometry::ElementId;

use crate::tessellate::ShapeMesh;

/// Vertex values of `mesh` from each leaf's value (module docs); a vertex
/// no triangle uses gets zero.
pub fn vertex_values(
    mesh: &ShapeMesh,
    leaf_value: impl Fn(ElementId) -> [f64; 3],
) -> Vec<[f64; 3]> {
    let mut sum = vec![[0.0; 3]; mesh.positions.len()];
    let mut weight = vec![0.0; mesh.positions.len()];
    let mut last: Option<(ElementId, [f64; 3])> = None;
    for (t, (tri, &owner)) in mesh.triangles.iter().zip(&mesh.owners).enumerate() {
        let f = match last {
            Some((e, f)) if e == owner => f,
            _ => leaf_value(owner),
        };
        last = Some((owner, f));
        let a = mesh.triangle_area(t);
        for &v in tri {
            let v = v as usize;
            weight[v] += a;
            for (s, x) in sum[v].iter_mut().zip(f) {
                *s += a * x;
            }
        }
    }
    sum.iter()
        .zip(&weight)
        .map(|(s, &w)| if w > 0.0 { s.map(|x| x / w) } else { [0.0; 3] })
        .collect()
}

/// The flux Σ_T A_T mean(v_T) (without the factor π) of the triangles of
/// `mesh` for which `keep` holds, with vertex values `values`.
pub fn baked_flux(
    mesh: &ShapeMesh,
    values: &[[f64; 3]],
    keep: impl Fn(ElementId) -> bool,
) -> [f64; 3] {
    let mut flux = [0.0; 3];
    for (t, (tri, &owner)) in mesh.triangles.iter().zip(&mesh.owners).enumerate() {
        if !keep(owner) {
            continue;
        }
        let a = mesh.triangle_area(t) / 3.0;
        for &v in tri {
            for (f, x) in flux.iter_mut().zip(values[v as usize]) {
                *f += a * x;
            }
        }
    }
    flux
}
