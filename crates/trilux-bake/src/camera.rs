//! The scene's camera as a glTF camera node.
//!
//! Mitsuba's camera space looks along +z with +y up and +x to the left; a
//! glTF camera looks along −z with +y up and +x to the right. The node's
//! rotation therefore has the columns (−left, up, −forward) of Mitsuba's
//! `to_world`, which is a proper rotation (determinant +1).

use glam::{DMat3, DMat4, DQuat, DVec3};
use serde_json::{Value, json};

/// A pinhole camera in Mitsuba's conventions.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BakeCamera {
    /// Camera space (+x left, +y up, +z forward) to world; scale is
    /// removed.
    pub world_from_camera: DMat4,
    /// Vertical field of view, radians.
    pub yfov: f64,
    /// Film width / height.
    pub aspect: f64,
}

impl BakeCamera {
    /// The node's translation and rotation (unit quaternion x, y, z, w),
    /// `None` when the transform has no usable axes.
    pub fn pose(&self) -> Option<(DVec3, DQuat)> {
        let m = self.world_from_camera;
        let left = m.x_axis.truncate().try_normalize()?;
        let forward = m.z_axis.truncate().try_normalize()?;
        let up = forward.cross(left).try_normalize()?;
        let rotation = DQuat::from_mat3(&DMat3::from_cols(-left, up, -forward)).normalize();
        let origin = m.w_axis.truncate();
        (origin.is_finite() && rotation.is_finite()).then_some((origin, rotation))
    }

    /// The glTF camera object, with clip planes for a scene of `extent`
    /// (its bounding box's size) seen from `distance` at most.
    pub(crate) fn gltf_camera(&self, extent: f64, distance: f64) -> Value {
        let znear = (1e-3 * extent).max(1e-6);
        let zfar = (2.0 * (extent + distance)).max(10.0 * znear);
        json!({
            "type": "perspective",
            "perspective": {
                "yfov": self.yfov,
                "aspectRatio": self.aspect,
                "znear": znear,
                "zfar": zfar,
            }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Mitsuba's look-at from (0, 0, 5) towards the origin with +y up: the
    /// glTF camera then has the identity rotation (it looks down −z).
    #[test]
    fn looking_down_minus_z_is_the_identity() {
        let (eye, dir, up) = (DVec3::new(0.0, 0.0, 5.0), DVec3::NEG_Z, DVec3::Y);
        let left = up.cross(dir).normalize();
        let m = DMat4::from_cols(
            left.extend(0.0),
            dir.cross(left).extend(0.0),
            dir.extend(0.0),
            eye.extend(1.0),
        );
        let cam = BakeCamera {
            world_from_camera: m,
            yfov: 0.5,
            aspect: 1.0,
        };
        let (t, q) = cam.pose().unwrap();
        assert_eq!(t, eye);
        assert!(q.angle_between(DQuat::IDENTITY) < 1e-12, "{q:?}");
        // The camera's −z axis is Mitsuba's forward.
        assert!((q * DVec3::NEG_Z - dir).length() < 1e-12);
    }

    /// A camera looking along +x with +z up: glTF's −z must map to +x and
    /// glTF's +y to +z.
    #[test]
    fn axes_follow_the_look_at() {
        let (dir, up) = (DVec3::X, DVec3::Z);
        let left = up.cross(dir).normalize();
        let m = DMat4::from_cols(
            left.extend(0.0),
            dir.cross(left).extend(0.0),
            (2.0 * dir).extend(0.0),
            DVec3::ONE.extend(1.0),
        );
        let cam = BakeCamera {
            world_from_camera: m,
            yfov: 0.5,
            aspect: 2.0,
        };
        let (_, q) = cam.pose().unwrap();
        assert!((q * DVec3::NEG_Z - DVec3::X).length() < 1e-12);
        assert!((q * DVec3::Y - DVec3::Z).length() < 1e-12);
        assert!((q * DVec3::X - (-left)).length() < 1e-12);
    }
}
