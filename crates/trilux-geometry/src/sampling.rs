//! Point sampling of elements and input surfaces, with the exact density
//! with respect to area.
//!
//! The maps are stratification-friendly: nearby `u` give nearby points, so
//! stratified or low-discrepancy `u` give stratified points.
//! - uv rectangles of quads and cylinder pieces: `u` maps linearly onto the
//!   rectangle; the area density is `1 / (|∂p/∂u × ∂p/∂v| · Δu · Δv)`
//!   (uniform for parallelograms and circular cylinders).
//! - disk elements: uniform in r² and φ, i.e. uniform in area (the polar map
//!   degenerates at the centre).
//! - sphere pieces: uniform in φ and z = cos θ on the object sphere (uniform
//!   in area unless scaled non-uniformly; the (φ, θ) map degenerates at the
//!   poles). Densities are finite and positive everywhere.
//! - clusters: `u.x` picks a piece by its area (and is rescaled to [0,1)
//!   within that piece), then the square-root map gives a uniform point of
//!   the triangle: density `1 / area` of the cluster.

use glam::{DVec2, DVec3};

use crate::chart::{MeshData, Piece};
use crate::patch::{PIECE_ANGLE, Patch};
use crate::surface::SurfaceCoord;

/// A point sampled on an element or surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceSample {
    /// World-space point.
    pub point: DVec3,
    /// Front geometric unit normal there.
    pub normal: DVec3,
    /// Density of the sample with respect to area (1/m²-like units).
    pub pdf_area: f64,
    /// The point in its surface's coordinates.
    pub coord: SurfaceCoord,
}

/// Point `k` of the `n`-point Hammersley set in [0, 1)²: (k + ½)/n and
/// the base-2 radical inverse of k. A fixed, well-stratified set that,
/// unlike cell midpoints of a grid, reaches the edges of the square (a
/// hemisphere's grazing ring under the cosine map).
pub fn hammersley(k: u32, n: u32) -> DVec2 {
    DVec2::new(
        (f64::from(k) + 0.5) / f64::from(n.max(1)),
        f64::from(k.reverse_bits()) / 4_294_967_296.0,
    )
}

/// Uniform point of a triangle from the unit square (square-root map):
/// barycentrics (b0, b1, b2).
#[inline]
pub(crate) fn square_to_triangle(u: DVec2) -> [f64; 3] {
    let s = u.x.sqrt();
    [1.0 - s, s * (1.0 - u.y), s * u.y]
}

/// Samples the uv rectangle [min, max] of a patch (of area `area`) from
/// `u` ∈ [0,1)². Where the uv map degenerates (disk centres, sphere poles)
/// it samples uniformly in r² or cos θ instead, so that the density stays
/// finite and positive everywhere.
pub(crate) fn sample_rect(
    patch: &Patch,
    min: DVec2,
    max: DVec2,
    area: f64,
    u: DVec2,
) -> SurfaceSample {
    let (uv, dens) = match patch {
        Patch::Disk { .. } => {
            let r2 = min.x * min.x + u.x * (max.x * max.x - min.x * min.x);
            let v = min.y + u.y * (max.y - min.y);
            (DVec2::new(r2.sqrt(), v), None)
        }
        Patch::Sphere { theta0, .. } => {
            let c0 = (theta0 + min.y * PIECE_ANGLE).cos();
            let c1 = (theta0 + max.y * PIECE_ANGLE).cos();
            let z = c0 + u.y * (c1 - c0);
            let theta = z.clamp(-1.0, 1.0).acos();
            let v = ((theta - theta0) / PIECE_ANGLE).clamp(min.y, max.y);
            (
                DVec2::new(min.x + u.x * (max.x - min.x), v),
                Some((c0 - c1).abs()),
            )
        }
        _ => (min + u * (max - min), None),
    };
    let pp = patch.eval(uv);
    let pdf = match (patch, dens) {
        // Uniform in area: the exact element area.
        (Patch::Disk { .. }, _) => 1.0 / area,
        // Uniform in (φ, z) on the object sphere: the world area element is
        // r² dφ dz times the tangent-plane area scale |det L| |L⁻ᵀ n| of the
        // linear map L.
        (
            Patch::Sphere {
                xf, radius, centre, ..
            },
            Some(dz),
        ) => {
            let p_obj = xf.object_from_world.transform_point3(pp.p);
            let n_obj = (p_obj - *centre).normalize();
            let scale = xf.linear.determinant().abs() * (xf.normal * n_obj).length();
            let jac = scale * radius * radius * (max.x - min.x) * PIECE_ANGLE * dz;
            if jac > 0.0 { 1.0 / jac } else { 0.0 }
        }
        _ => {
            let jac = pp.jacobian() * (max.x - min.x) * (max.y - min.y);
            if jac > 0.0 { 1.0 / jac } else { 0.0 }
        }
    };
    SurfaceSample {
        point: pp.p,
        normal: pp.n,
        pdf_area: pdf,
        coord: SurfaceCoord::Uv(uv),
    }
}

/// The running sums Σ_{i≤k} A_i of the pieces' areas, added in order.
pub(crate) fn piece_ends(m: &MeshData, pieces: &[Piece]) -> Vec<f64> {
    let mut acc = 0.0;
    pieces
        .iter()
        .map(|p| {
            acc += piece_area(m, p);
            acc
        })
        .collect()
}

fn piece_area(m: &MeshData, p: &Piece) -> f64 {
    m.tri_area[p.triangle as usize] * p.area_fraction()
}

/// The first piece whose running sum exceeds `target` (the last if none),
/// with the sum before it and its area (`area_of(k)`, `n` pieces).
fn chosen_piece(
    n: usize,
    area_of: impl Fn(usize) -> f64,
    ends: &[f64],
    target: f64,
) -> (usize, f64, f64) {
    let last = n - 1;
    // The sums are non-decreasing when finite: the search then finds what
    // the scan finds. Otherwise scan.
    // `!(target < e)`, not `e <= target`: the scan's test, NaN included.
    #[allow(clippy::neg_cmp_op_on_partial_ord)]
    let k = if ends[last].is_finite() {
        ends.partition_point(|&e| !(target < e)).min(last)
    } else {
        chosen_piece_linear(n, &area_of, target)
    };
    let start = if k == 0 { 0.0 } else { ends[k - 1] };
    (k, start, area_of(k))
}

/// The linear scan (the reference of the binary search).
fn chosen_piece_linear(n: usize, area_of: impl Fn(usize) -> f64, target: f64) -> usize {
    let mut acc = 0.0;
    for k in 0..n {
        let a = area_of(k);
        if target < acc + a || k + 1 == n {
            return k;
        }
        acc += a;
    }
    n - 1
}

/// Samples a cluster of `pieces` (of total area `area`) of a mesh: `u.x`
/// picks a piece by its area and is rescaled within it, then the
/// square-root map gives a uniform point of the piece. `ends` holds the
/// running sums of the pieces' areas ([`piece_ends`]): a binary search
/// picks the piece the linear scan would (the same sums, compared the
/// same way), in O(log n) for charts of thousands of triangles.
pub(crate) fn sample_cluster(
    m: &MeshData,
    pieces: &[Piece],
    ends: &[f64],
    area: f64,
    u: DVec2,
) -> SurfaceSample {
    let target = u.x * area;
    let (k, start, a) = chosen_piece(pieces.len(), |k| piece_area(m, &pieces[k]), ends, target);
    let ux = if a > 0.0 {
        ((target - start) / a).clamp(0.0, 1.0 - f64::EPSILON)
    } else {
        0.5
    };
    let l = square_to_triangle(DVec2::new(ux, u.y));
    let p = pieces[k];
    let bary = l[0] * p.bary[0] + l[1] * p.bary[1] + l[2] * p.bary[2];
    SurfaceSample {
        point: m.point(p.triangle, bary),
        normal: m.tri_normal[p.triangle as usize],
        pdf_area: 1.0 / area,
        coord: SurfaceCoord::Triangle {
            index: p.triangle,
            bary,
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The search picks the piece, start and area of the linear scan on
    /// random areas (zeros and exact running sums as targets included).
    #[test]
    fn binary_search_picks_the_linear_scans_piece() {
        let mut x = 0x2545_F491_4F6C_DD1Du64;
        let mut next = || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            (x >> 11) as f64 / (1u64 << 53) as f64
        };
        for case in 0..3_000 {
            let n = 1 + (next() * 40.0) as usize;
            let areas: Vec<f64> = (0..n)
                .map(|_| if next() < 0.2 { 0.0 } else { next() * 1e3 })
                .collect();
            let mut acc = 0.0;
            let ends: Vec<f64> = areas
                .iter()
                .map(|a| {
                    acc += a;
                    acc
                })
                .collect();
            let total = ends[n - 1];
            let targets = [
                next() * total,
                ends[(next() * n as f64) as usize],
                total,
                total * 1.5,
                0.0,
            ];
            for target in targets {
                let k = chosen_piece_linear(n, |k| areas[k], target);
                let start: f64 = areas[..k].iter().fold(0.0, |s, a| s + a);
                let got = chosen_piece(n, |k| areas[k], &ends, target);
                assert_eq!(got, (k, start, areas[k]), "case {case}, target {target}");
            }
        }
    }
}
