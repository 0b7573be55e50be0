//! The sensor's plain data, shared by the scene loader (`trilux-scene`) and
//! the renderer (`trilux-render`): Mitsuba 3's `look_at` placement, the axis
//! a field of view is measured along ([`FovAxis`]) and the film's
//! reconstruction filters ([`rfilter`]). One definition of each, so that a
//! file's `<lookat>` and the command line's `--lookat` give the same camera.

pub mod rfilter;

use glam::{DMat4, DVec3, DVec4};
use serde::Serialize;

pub use rfilter::ReconstructionFilter;

/// The image axis along which a field of view is measured (Mitsuba's
/// `fov_axis`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum FovAxis {
    /// The horizontal axis (Mitsuba's default).
    X,
    /// The vertical axis.
    Y,
    /// Whichever of x and y is shorter.
    Smaller,
    /// Whichever of x and y is longer.
    Larger,
    /// The image diagonal.
    Diagonal,
}

impl FovAxis {
    /// The name used in scene files.
    pub fn name(self) -> &'static str {
        match self {
            FovAxis::X => "x",
            FovAxis::Y => "y",
            FovAxis::Smaller => "smaller",
            FovAxis::Larger => "larger",
            FovAxis::Diagonal => "diagonal",
        }
    }

    /// Parses a scene-file name (`x`, `y`, `smaller`, `larger`, `diagonal`).
    pub fn from_name(name: &str) -> Option<Self> {
        Some(match name {
            "x" => FovAxis::X,
            "y" => FovAxis::Y,
            "smaller" => FovAxis::Smaller,
            "larger" => FovAxis::Larger,
            "diagonal" => FovAxis::Diagonal,
            _ => return None,
        })
    }
}

/// Why [`look_at`] refuses a placement.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum LookAtError {
    /// The origin and the target are the same point, or the direction
    /// between them is not finite, or the origin is not finite.
    #[error("the viewing direction is zero or not finite")]
    Direction,
    /// `up` is parallel to the viewing direction, zero or not finite.
    #[error("up is parallel to the viewing direction (or zero)")]
    Up,
}

/// Mitsuba's `Transform4f.look_at`: camera space (+x left, +y up, +z
/// forward) to world space, the columns (left, up', dir, origin) with
/// dir = normalize(target − origin), left = normalize(up × dir) and
/// up' = dir × left.
///
/// Only up's direction matters: it is scaled to at most 1 before the cross
/// product, so that a huge up does not overflow, and refused when
/// |up × dir|² ≤ 10⁻²⁰ (nearly parallel to the view: the camera's roll
/// would be decided by rounding).
pub fn look_at(origin: DVec3, target: DVec3, up: DVec3) -> Result<DMat4, LookAtError> {
    let dir = (target - origin).normalize_or_zero();
    if dir == DVec3::ZERO || !origin.is_finite() {
        return Err(LookAtError::Direction);
    }
    let scale = up.abs().max_element();
    let up = if scale > 1.0 { up / scale } else { up };
    let left = up.cross(dir);
    if left.length_squared() <= 1e-20 || !left.is_finite() {
        return Err(LookAtError::Up);
    }
    let left = left.normalize();
    let new_up = dir.cross(left);
    Ok(DMat4::from_cols(
        left.extend(0.0),
        new_up.extend(0.0),
        dir.extend(0.0),
        DVec4::new(origin.x, origin.y, origin.z, 1.0),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn look_at_builds_an_orthonormal_frame_looking_at_the_target() {
        let m = look_at(
            DVec3::new(1.0, 2.0, 3.0),
            DVec3::new(1.0, 2.0, 0.0),
            DVec3::Y,
        )
        .unwrap();
        // Looking down −z with +y up:
        // left = up × dir = (0,1,0) × (0,0,−1) = (−1, 0, 0).
        assert_eq!(m.x_axis.truncate(), DVec3::new(-1.0, 0.0, 0.0));
        assert_eq!(m.y_axis.truncate(), DVec3::Y);
        assert_eq!(m.z_axis.truncate(), DVec3::new(0.0, 0.0, -1.0));
        assert_eq!(m.w_axis, DVec4::new(1.0, 2.0, 3.0, 1.0));
    }

    #[test]
    fn degenerate_placements_are_refused() {
        assert_eq!(
            look_at(DVec3::ZERO, DVec3::ZERO, DVec3::Y),
            Err(LookAtError::Direction)
        );
        assert_eq!(
            look_at(DVec3::ZERO, DVec3::Y, DVec3::Y),
            Err(LookAtError::Up)
        );
        assert_eq!(
            look_at(DVec3::splat(f64::NAN), DVec3::Y, DVec3::X),
            Err(LookAtError::Direction)
        );
        // Up 1e-11 off the view axis: |up × dir|² = 1e-22, refused rather
        // than left to rounding.
        let up = DVec3::new(1e-11, 1.0, 0.0);
        assert_eq!(look_at(DVec3::ZERO, DVec3::Y, up), Err(LookAtError::Up));
        // A huge up is scaled, not overflowed.
        assert!(look_at(DVec3::ZERO, DVec3::Z, DVec3::new(0.0, 1e300, 0.0)).is_ok());
    }
}
