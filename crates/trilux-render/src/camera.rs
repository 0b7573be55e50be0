//! Mitsuba 3's `perspective` sensor.
//!
//! Conventions, checked against Mitsuba 3.9 (`sensor.sample_ray`, see
//! `tests/data/mitsuba_camera.py` and the test `camera_matches_mitsuba`):
//! - camera space looks along **+z**, with **+y up and +x to the left**;
//!   `lookat(origin, target, up)` builds the columns
//!   (left = normalize(up × dir), up' = dir × left, dir, origin)
//!   ([`trilux_geometry::look_at`], shared with the scene loader);
//! - a film position (s_x, s_y) ∈ \[0,1\]², (0, 0) being the top-left corner of
//!   the film, maps to the camera-space direction
//!   ((1 − 2 s_x)·tan(fov_x/2), (1 − 2 s_y)·tan(fov_x/2)/aspect, 1),
//!   aspect = width / height;
//! - `fov` is measured along `fov_axis`: `x` (Mitsuba's default), `y`,
//!   `smaller` / `larger` (the shorter / longer film side; on a square film
//!   `smaller` means x and `larger` means y, as Mitsuba decides with
//!   `aspect > 1`), or `diagonal`.
//!
//! Mitsuba starts its rays at the near clip plane (0.01 along the optical
//! axis); trilux starts them at the camera's origin. Nothing lies that close
//! to a camera in our scenes, so the two see the same first hit.

use glam::{DMat4, DVec2, DVec3};

pub use trilux_geometry::{FovAxis, Ray, look_at};

use crate::error::RenderError;

/// A pinhole camera with Mitsuba 3's conventions.
#[derive(Clone, Debug, PartialEq)]
pub struct Camera {
    world_from_camera: DMat4,
    origin: DVec3,
    tan_half_x: f64,
    tan_half_y: f64,
    width: u32,
    height: u32,
    /// Depth of the near clip plane: rays start on it.
    near_clip: f64,
    /// Depth of the far clip plane (checked against the scene, not
    /// clipped: `check_far_clip`).
    far_clip: f64,
    /// Mitsuba's principal point offset, in film sizes.
    offset: DVec2,
    /// The whole film's size, pixels (`width` × `height` is its crop
    /// window, at `crop_offset`).
    film_size: DVec2,
    crop_offset: DVec2,
    /// Pixels sampled beyond each edge of the image (Mitsuba's
    /// `sample_border`; 0 without).
    border: u32,
}

/// Mitsuba's `parse_fov`: the horizontal field of view (degrees) that
/// `fov` along `axis` means on a film of the given aspect (width / height).
pub fn horizontal_fov(fov_deg: f64, axis: FovAxis, aspect: f64) -> f64 {
    let axis = match axis {
        FovAxis::Smaller if aspect > 1.0 => FovAxis::Y,
        FovAxis::Smaller => FovAxis::X,
        FovAxis::Larger if aspect > 1.0 => FovAxis::X,
        FovAxis::Larger => FovAxis::Y,
        a => a,
    };
    let t = (fov_deg.to_radians() * 0.5).tan();
    match axis {
        FovAxis::Y => (2.0 * (t * aspect).atan()).to_degrees(),
        FovAxis::Diagonal => {
            (2.0 * (t * aspect / (aspect * aspect + 1.0).sqrt()).atan()).to_degrees()
        }
        _ => fov_deg,
    }
}

impl Camera {
    /// A camera at `world_from_camera` (any rigid transform; scale is
    /// removed by normalising directions) with field of view `fov_deg`
    /// along `axis` and a film of `width` × `height` pixels.
    pub fn new(
        world_from_camera: DMat4,
        fov_deg: f64,
        axis: FovAxis,
        width: u32,
        height: u32,
    ) -> Result<Self, RenderError> {
        trilux_files::film::check_film(width, height).map_err(RenderError::Camera)?;
        if !(fov_deg.is_finite() && fov_deg > 0.0 && fov_deg < 180.0) {
            return Err(RenderError::Camera(format!(
                "fov {fov_deg} must lie strictly between 0 and 180 degrees"
            )));
        }
        if !world_from_camera.is_finite() || world_from_camera.determinant().abs() < 1e-300 {
            return Err(RenderError::Camera(
                "to_world is singular or not finite".into(),
            ));
        }
        let aspect = width as f64 / height as f64;
        let fov_x = horizontal_fov(fov_deg, axis, aspect);
        if !(fov_x > 0.0 && fov_x < 180.0) {
            return Err(RenderError::Camera(format!(
                "fov {fov_deg} along {axis:?} means a horizontal fov of {fov_x} degrees"
            )));
        }
        let tan_half_x = (fov_x.to_radians() * 0.5).tan();
        Ok(Self {
            origin: world_from_camera.transform_point3(DVec3::ZERO),
            world_from_camera,
            tan_half_x,
            tan_half_y: tan_half_x / aspect,
            width,
            height,
            near_clip: 0.0,
            far_clip: f64::INFINITY,
            offset: DVec2::ZERO,
            film_size: DVec2::new(f64::from(width), f64::from(height)),
            crop_offset: DVec2::ZERO,
            border: 0,
        })
    }

    /// The camera with clip planes at depths `near` and `far` (Mitsuba's
    /// `near_clip`, `far_clip`): camera rays start on the near plane.
    pub fn with_clip(mut self, near: f64, far: f64) -> Result<Self, RenderError> {
        if !(near.is_finite() && near >= 0.0 && far > near) {
            return Err(RenderError::Camera(format!(
                "near_clip {near} must be non-negative and below far_clip {far}"
            )));
        }
        (self.near_clip, self.far_clip) = (near, far);
        Ok(self)
    }

    /// The camera rendering only the `size` pixels at `offset` of its film
    /// (Mitsuba's crop window): the image has the window's size, each
    /// pixel the ray it has in the whole film.
    pub fn with_crop(mut self, offset: [u32; 2], size: [u32; 2]) -> Result<Self, RenderError> {
        let fits =
            |k: usize, full: f64| size[k] >= 1 && f64::from(offset[k]) + f64::from(size[k]) <= full;
        if !(fits(0, self.film_size.x) && fits(1, self.film_size.y)) {
            return Err(RenderError::Camera(format!(
                "the crop window {} × {} at ({}, {}) must lie within the {} × {} film",
                size[0], size[1], offset[0], offset[1], self.film_size.x, self.film_size.y
            )));
        }
        (self.width, self.height) = (size[0], size[1]);
        self.crop_offset = DVec2::new(f64::from(offset[0]), f64::from(offset[1]));
        Ok(self)
    }

    /// The camera that also samples `border` pixels beyond each edge of
    /// its image (Mitsuba's `sample_border`, with the filter's
    /// `border_size`): edge pixels then get what the filter spreads from
    /// outside, as in Mitsuba. The image keeps its size.
    pub fn with_sample_border(mut self, border: u32) -> Self {
        self.border = border;
        self
    }

    /// Pixels sampled beyond each edge ([`Self::with_sample_border`]).
    pub fn sample_border(&self) -> u32 {
        self.border
    }

    /// The image grown by the sample border on every side, its pixel
    /// (i, j) the ray of this camera's (i − b, j − b): what a render with a
    /// sample border samples before it keeps the inner image.
    pub(crate) fn bordered(&self) -> Camera {
        let b = self.border;
        Camera {
            width: self.width + 2 * b,
            height: self.height + 2 * b,
            crop_offset: self.crop_offset - DVec2::splat(f64::from(b)),
            border: 0,
            ..self.clone()
        }
    }

    /// Width over height of the whole film (not of a crop window).
    pub fn film_aspect(&self) -> f64 {
        self.film_size.x / self.film_size.y
    }

    /// The camera with its principal point moved by `offset` film widths
    /// and heights (Mitsuba's `principal_point_offset_x`, `_y`).
    pub fn with_principal_point_offset(mut self, offset: DVec2) -> Self {
        self.offset = offset;
        self
    }

    /// Refuses a far clip plane that would cut geometry inside `bounds`
    /// (trilux does not clip there; with every corner of the bounds in
    /// front of the plane, not clipping is what Mitsuba renders).
    pub fn check_far_clip(&self, bounds: &trilux_geometry::Bounds) -> Result<(), RenderError> {
        let forward = self
            .world_from_camera
            .transform_vector3(DVec3::Z)
            .normalize();
        let mut deepest = f64::NEG_INFINITY;
        for i in 0..8 {
            let pick = |bit: usize, lo: f64, hi: f64| if i & bit == 0 { lo } else { hi };
            let corner = DVec3::new(
                pick(1, bounds.min.x, bounds.max.x),
                pick(2, bounds.min.y, bounds.max.y),
                pick(4, bounds.min.z, bounds.max.z),
            );
            deepest = deepest.max((corner - self.origin).dot(forward));
        }
        if deepest > self.far_clip {
            return Err(RenderError::Camera(format!(
                "far_clip {} would cut the scene, which reaches {deepest:.6} along the view; trilux renders without a far plane: raise far_clip",
                self.far_clip
            )));
        }
        Ok(())
    }

    /// Film width in pixels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Film height in pixels.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// Camera space (+x left, +y up, +z forward) to world.
    pub fn world_from_camera(&self) -> DMat4 {
        self.world_from_camera
    }

    /// The vertical field of view, radians.
    pub fn yfov(&self) -> f64 {
        2.0 * self.tan_half_y.atan()
    }

    /// The camera's position in world space.
    pub fn origin(&self) -> DVec3 {
        self.origin
    }

    /// The ray (with a unit direction) through the image position `film`
    /// given in pixels
    /// (x ∈ [0, width], y ∈ [0, height], (0, 0) the top-left corner; pixel
    /// (i, j) covers [i, i+1] × [j, j+1]), in the crop window when there
    /// is one.
    pub fn ray(&self, film: DVec2) -> Ray {
        self.ray_unit((film + self.crop_offset) / self.film_size)
    }

    /// The ray (with a unit direction) through the film position
    /// `s` ∈ \[0,1\]² (Mitsuba's position sample: (0, 0) is the top-left
    /// corner).
    pub fn ray_unit(&self, s: DVec2) -> Ray {
        let s = s + self.offset;
        let d_cam = DVec3::new(
            (1.0 - 2.0 * s.x) * self.tan_half_x,
            (1.0 - 2.0 * s.y) * self.tan_half_y,
            1.0,
        );
        // d_cam has depth 1: the ray meets the near plane at d·near.
        let d = self.world_from_camera.transform_vector3(d_cam);
        Ray {
            origin: self.origin + d * self.near_clip,
            dir: d.normalize(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fov_axes_on_square_film_are_all_equal_but_diagonal() {
        for a in [FovAxis::X, FovAxis::Y, FovAxis::Smaller, FovAxis::Larger] {
            assert!((horizontal_fov(40.0, a, 1.0) - 40.0).abs() < 1e-12);
        }
        // Diagonal of a square: tan(h/2) = tan(d/2)/sqrt(2).
        let h = horizontal_fov(90.0, FovAxis::Diagonal, 1.0);
        assert!(((h.to_radians() / 2.0).tan() - 1.0 / 2f64.sqrt()).abs() < 1e-12);
    }

    /// Mitsuba's clip planes: every camera ray starts on the near plane
    /// (depth `near` along the view axis, so near/cos θ from the eye); a
    /// far plane in front of any corner of the scene's bounds is refused.
    #[test]
    fn rays_start_on_the_near_plane_and_a_cutting_far_plane_is_refused() {
        let m = look_at(
            DVec3::new(1.0, 2.0, 3.0),
            DVec3::new(1.0, 2.0, 0.0),
            DVec3::Y,
        )
        .unwrap();
        let cam = Camera::new(m, 90.0, FovAxis::X, 8, 8)
            .unwrap()
            .with_clip(0.5, 10.0)
            .unwrap();
        let forward = DVec3::new(0.0, 0.0, -1.0);
        for s in [
            DVec2::new(0.5, 0.5),
            DVec2::new(0.0, 0.0),
            DVec2::new(0.9, 0.2),
        ] {
            let r = cam.ray_unit(s);
            let depth = (r.origin - cam.origin()).dot(forward);
            assert!((depth - 0.5).abs() < 1e-12, "{s}: depth {depth}");
            let along = (r.origin - cam.origin()).normalize();
            assert!((along - r.dir).length() < 1e-12, "on the ray through {s}");
        }
        // The corner (0, 0, −7.5) is 10.5 deep; −6.5 is 9.5 deep.
        let scene = |z: f64| trilux_geometry::Bounds {
            min: DVec3::new(0.0, 0.0, z),
            max: DVec3::new(1.0, 1.0, 0.0),
        };
        assert!(cam.check_far_clip(&scene(-6.5)).is_ok());
        let e = cam.check_far_clip(&scene(-7.5)).unwrap_err().to_string();
        assert!(e.contains("far_clip 10 would cut the scene"), "{e}");
        assert!(cam.clone().with_clip(1.0, 0.5).is_err());
        assert!(cam.with_clip(f64::NAN, 1.0).is_err());
    }

    /// Mitsuba 3.9.1 (`sample_ray` of a perspective sensor, fov 40 on a
    /// 30 × 20 film): with principal point offset (0.1, 0.05) the ray
    /// through (0.5, 0.5) is (−0.0725807, −0.0241936, 0.997069), the
    /// unshifted ray through (0.6, 0.55).
    #[test]
    fn the_principal_point_offset_is_mitsubas() {
        let cam = Camera::new(DMat4::IDENTITY, 40.0, FovAxis::X, 30, 20)
            .unwrap()
            .with_principal_point_offset(DVec2::new(0.1, 0.05));
        let d = cam.ray_unit(DVec2::splat(0.5)).dir;
        let mitsuba = DVec3::new(-0.072_580_7, -0.024_193_6, 0.997_069);
        assert!((d - mitsuba).length() < 1e-6, "{d}");
    }

    /// A crop window renders its part of the film: its pixel (i, j) has the
    /// whole film's ray at (i + x, j + y); the window must fit the film.
    #[test]
    fn a_crop_window_keeps_the_films_rays() {
        let full = Camera::new(DMat4::IDENTITY, 50.0, FovAxis::X, 80, 64).unwrap();
        let crop = full.clone().with_crop([20, 10], [40, 30]).unwrap();
        assert_eq!((crop.width(), crop.height()), (40, 30));
        assert_eq!(crop.film_aspect(), 80.0 / 64.0);
        for p in [
            DVec2::new(0.5, 0.5),
            DVec2::new(39.2, 29.9),
            DVec2::new(12.0, 3.3),
        ] {
            let (a, b) = (crop.ray(p), full.ray(p + DVec2::new(20.0, 10.0)));
            assert!(
                (a.dir - b.dir).length() < 1e-15 && a.origin == b.origin,
                "{p}"
            );
        }
        assert!(full.clone().with_crop([50, 0], [40, 30]).is_err());
        assert!(full.with_crop([0, 0], [0, 30]).is_err());
    }

    #[test]
    fn bad_cameras_are_errors() {
        let m = DMat4::IDENTITY;
        assert!(Camera::new(m, 0.0, FovAxis::X, 8, 8).is_err());
        assert!(Camera::new(m, 180.0, FovAxis::X, 8, 8).is_err());
        assert!(Camera::new(m, f64::NAN, FovAxis::X, 8, 8).is_err());
        assert!(Camera::new(m, 40.0, FovAxis::X, 0, 8).is_err());
        assert!(Camera::new(DMat4::ZERO, 40.0, FovAxis::X, 8, 8).is_err());
        assert!(look_at(DVec3::ZERO, DVec3::ZERO, DVec3::Y).is_err());
        assert!(look_at(DVec3::ZERO, DVec3::Y, DVec3::Y).is_err());
    }
}
