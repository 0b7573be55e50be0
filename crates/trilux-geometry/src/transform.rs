//! Affine transforms with their inverse and normal matrix precomputed.

use glam::{DMat3, DMat4, DVec3};

/// `world_from_object` split into what the geometry needs: points map by
/// `m`, tangent vectors by `linear`, normals by `normal` (the inverse
/// transpose of `linear`), and world points back by `object_from_world`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Affine {
    pub m: DMat4,
    pub object_from_world: DMat4,
    pub linear: DMat3,
    pub linear_inv: DMat3,
    pub normal: DMat3,
    /// `Some(s)` when `linear` is `s` times a rotation (or reflection):
    /// closed-form areas apply.
    pub similarity: Option<f64>,
}

impl Affine {
    /// `None` when the matrix is not finite, singular or projective.
    pub fn new(m: DMat4) -> Result<Affine, crate::ShapeProblem> {
        if !m.is_finite() {
            return Err(crate::ShapeProblem::NonFiniteTransform);
        }
        let row3 = m.row(3);
        if row3.x != 0.0 || row3.y != 0.0 || row3.z != 0.0 || row3.w != 1.0 {
            return Err(crate::ShapeProblem::SingularTransform);
        }
        let linear = DMat3::from_mat4(m);
        let det = linear.determinant();
        let scale = linear
            .x_axis
            .length()
            .max(linear.y_axis.length())
            .max(linear.z_axis.length());
        if det.abs() <= 1e-14 * scale * scale * scale || !det.is_finite() {
            return Err(crate::ShapeProblem::SingularTransform);
        }
        let linear_inv = linear.inverse();
        let normal = linear_inv.transpose();
        let s = det.abs().cbrt();
        let ltl = linear.transpose() * linear;
        let dev = (ltl - DMat3::from_diagonal(DVec3::splat(s * s))).to_cols_array();
        let similarity = if dev.iter().all(|d| d.abs() <= 1e-12 * s * s) {
            Some(s)
        } else {
            None
        };
        Ok(Affine {
            m,
            object_from_world: m.inverse(),
            linear,
            linear_inv,
            normal,
            similarity,
        })
    }

    #[inline]
    pub fn point(&self, p: DVec3) -> DVec3 {
        self.m.transform_point3(p)
    }

    #[inline]
    pub fn vector(&self, v: DVec3) -> DVec3 {
        self.linear * v
    }

    /// A unit normal in world space.
    #[inline]
    pub fn normal(&self, n: DVec3) -> DVec3 {
        (self.normal * n).normalize()
    }
}
