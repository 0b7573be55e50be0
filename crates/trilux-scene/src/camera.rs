//! The camera (`<sensor type="perspective">`), its film and its sampler.
//!
//! Mitsuba 3 conventions: the camera looks down its local +z axis, +x points
//! to the left of the image and +y up (see [`crate::transform`] for
//! `lookat`). `fov` is in degrees along `fov_axis`; without `fov`, Mitsuba's
//! default 50 mm lens on a 36 × 24 mm film gives 2·atan(√(36² + 24²)/100) ≈
//! 46.79° along the diagonal. The film defaults to 768 × 576 with a Gaussian
//! reconstruction filter; the sampler to 4 samples per pixel.

use glam::{DMat4, DVec3};
use serde::Serialize;
use trilux_color::ColorParam;

use crate::error::SourceLocation;
pub use trilux_geometry::sensor::{FovAxis, ReconstructionFilter};

/// A crop window of the film, in pixels.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct Crop {
    /// Its top-left pixel.
    pub offset: [u32; 2],
    /// Its width and height.
    pub size: [u32; 2],
}

/// A perspective camera with its film and sample count.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Camera {
    /// Eye position (world space).
    pub origin: DVec3,
    /// A point the camera looks at: the `lookat` target when `to_world` is
    /// one `<lookat>`, else one unit along the viewing direction.
    pub target: DVec3,
    /// Up direction: as written in `<lookat>`, else the camera's +y axis in
    /// world space.
    pub up: DVec3,
    /// Mitsuba's sensor `to_world` (camera space: looking down +z, +x left).
    pub world_from_camera: DMat4,
    /// Field of view in degrees, along `fov_axis`.
    pub fov: f64,
    /// Axis along which `fov` is measured.
    pub fov_axis: FovAxis,
    /// Film width in pixels.
    pub width: u32,
    /// Film height in pixels.
    pub height: u32,
    /// Film reconstruction filter.
    pub rfilter: ReconstructionFilter,
    /// Samples per pixel (the sampler's `sample_count`).
    pub sample_count: u32,
    /// Distance of the near clip plane along the view axis (Mitsuba's
    /// `near_clip`, glTF's `znear`; 0 when the file gives none): nothing
    /// nearer is seen.
    pub near_clip: f64,
    /// Distance of the far clip plane (Mitsuba's `far_clip`, glTF's
    /// `zfar`; infinite when the file gives none). trilux renders without
    /// one, so a far plane that would cut the scene is refused when the
    /// scene is prepared.
    pub far_clip: f64,
    /// Mitsuba's `principal_point_offset_x`, `_y`: the image centre's
    /// shift, in film widths and heights (the ray through film position s
    /// is the unshifted ray through s + offset).
    pub principal_point_offset: [f64; 2],
    /// The part of the film rendered (Mitsuba's `crop_*`); the image has
    /// its size.
    pub crop: Option<Crop>,
    /// Mitsuba's `sample_border`: the film is also sampled beyond its edge
    /// (the filter's border), so edge pixels get what the filter spreads
    /// from outside.
    pub sample_border: bool,
    /// Mitsuba's `srf`: the sensor's spectral response, multiplying the
    /// radiance before the CIE observer sees it (a sampled one makes the
    /// scene spectral, as Mitsuba reads it in spectral variants only).
    pub response: Option<ColorParam>,
    /// Where the `<sensor>` is written.
    #[serde(skip)]
    pub location: SourceLocation,
}

impl Camera {
    /// The horizontal field of view in degrees, converted from `fov` along
    /// `fov_axis` with the film's aspect ratio as Mitsuba's `parse_fov` does.
    pub fn x_fov(&self) -> f64 {
        let aspect = self.width as f64 / self.height as f64;
        let half_tan = (0.5 * self.fov.to_radians()).tan();
        let from_y = || (2.0 * (half_tan * aspect).atan()).to_degrees();
        match self.fov_axis {
            FovAxis::X => self.fov,
            FovAxis::Y => from_y(),
            FovAxis::Diagonal => {
                (2.0 * (half_tan / (1.0 + 1.0 / (aspect * aspect)).sqrt()).atan()).to_degrees()
            }
            FovAxis::Smaller if aspect > 1.0 => from_y(),
            FovAxis::Smaller => self.fov,
            FovAxis::Larger if aspect > 1.0 => self.fov,
            FovAxis::Larger => from_y(),
        }
    }
}

/// Mitsuba's default field of view (50 mm lens, 36 × 24 mm film), along the
/// diagonal, in degrees.
pub(crate) fn default_fov() -> f64 {
    (2.0 * ((36f64 * 36.0 + 24.0 * 24.0).sqrt() / 100.0).atan()).to_degrees()
}
