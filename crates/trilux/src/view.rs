//! From a loaded scene's sensor to a [`Camera`] and render settings, with
//! the command line's overrides (another view of the same solution:
//! `--lookat`, `--fov`, `--width`, `--height`).

use glam::{DVec2, DVec3};
use trilux_geometry::look_at;
use trilux_render::{Camera, Estimator, ReconstructionFilter, RenderError, RenderSettings};

/// Changes to the scene's camera asked for on the command line.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ViewOverrides {
    /// New eye, target and up (up defaults to the scene camera's up).
    pub lookat: Option<(DVec3, DVec3, Option<DVec3>)>,
    /// New field of view in degrees, along the scene's `fov_axis`.
    pub fov: Option<f64>,
    /// New film width.
    pub width: Option<u32>,
    /// New film height.
    pub height: Option<u32>,
}

/// The film filter a scene asks for.
pub fn filter_of(c: &trilux_scene::Camera) -> ReconstructionFilter {
    c.rfilter
}

/// The scene's own sample count and film filter, other settings default.
pub fn render_settings(camera: &trilux_scene::Camera) -> RenderSettings {
    RenderSettings {
        spp: camera.sample_count.max(1),
        filter: filter_of(camera),
        ..RenderSettings::default()
    }
}

/// Applies what the scene's integrator asks of the image (Mitsuba's
/// `max_depth` and `hide_emitters`) to `settings`, whose estimator is
/// `chosen` on the command line (`None`: none was). A finite `max_depth`
/// makes the default estimator the control variate, the one that honours
/// it; another chosen explicitly renders every bounce, and the returned
/// warning (with the place the file sets the limit) says so.
pub fn apply_integrator(
    settings: &mut RenderSettings,
    scene: &trilux_scene::Scene,
    chosen: Option<Estimator>,
) -> Option<String> {
    settings.hide_emitters = scene.hide_emitters;
    let limit = scene
        .max_depth
        .filter(|d| *d >= 0)
        .map(|d| u32::try_from(d).unwrap_or(u32::MAX));
    settings.estimator = match (chosen, limit) {
        (Some(e), _) => e,
        (None, Some(_)) => Estimator::Control,
        (None, None) => Estimator::Paths,
    };
    let depth = limit?;
    if settings.estimator == Estimator::Control {
        settings.max_depth = Some(depth);
        return None;
    }
    let at = scene
        .max_depth_location
        .as_ref()
        .map_or_else(|| scene.path.display().to_string(), ToString::to_string);
    Some(format!(
        "{at}: max_depth {depth} is not honoured by this estimator: the solution it reads carries light over paths of every length (--gather control honours it)"
    ))
}

/// The camera of the scene's sensor, with overrides applied.
pub fn camera_of(c: &trilux_scene::Camera, o: &ViewOverrides) -> Result<Camera, RenderError> {
    let world_from_camera = match o.lookat {
        Some((origin, target, up)) => {
            let up = up.unwrap_or(c.up);
            look_at(origin, target, up).map_err(|_| {
                RenderError::Camera(format!(
                    "lookat origin {origin}, target {target}, up {up} is degenerate"
                ))
            })?
        }
        None => c.world_from_camera,
    };
    let camera = Camera::new(
        world_from_camera,
        o.fov.unwrap_or(c.fov),
        c.fov_axis,
        o.width.unwrap_or(c.width),
        o.height.unwrap_or(c.height),
    )?
    .with_clip(c.near_clip, c.far_clip)?
    .with_principal_point_offset(DVec2::from(c.principal_point_offset));
    let camera = if c.sample_border {
        camera.with_sample_border(c.rfilter.border_size())
    } else {
        camera
    };
    // A film size given on the command line is a new film: no crop.
    match c.crop {
        Some(crop) if o.width.is_none() && o.height.is_none() => {
            camera.with_crop(crop.offset, crop.size)
        }
        _ => Ok(camera),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const SCENE: &str = r#"<scene version="3.0.0">
        <sensor type="perspective">
            <float name="fov" value="40"/>
            <string name="fov_axis" value="y"/>
            <transform name="to_world"><lookat origin="1, 2, 3" target="1, 2, 0" up="0, 1, 0"/></transform>
            <film type="hdrfilm"><integer name="width" value="30"/><integer name="height" value="20"/>
                <rfilter type="box"/></film>
        </sensor>
        <shape type="rectangle"/>
    </scene>"#;

    #[test]
    fn scene_camera_and_overrides() {
        let scene = trilux_scene::load_str(SCENE, "inline.xml").unwrap();
        let c = scene.camera.as_ref().unwrap();
        assert_eq!(filter_of(c), ReconstructionFilter::Box);
        let cam = camera_of(c, &ViewOverrides::default()).unwrap();
        assert_eq!((cam.width(), cam.height()), (30, 20));
        let centre = cam.ray_unit(DVec2::splat(0.5));
        assert!((centre.dir - DVec3::new(0.0, 0.0, -1.0)).length() < 1e-12);
        assert!((centre.origin - DVec3::new(1.0, 2.0, 3.0)).length() < 1e-12);
        // fov 40 along y: the top edge of the film is 20° above the axis.
        let top = cam.ray_unit(DVec2::new(0.5, 0.0));
        assert!((top.dir.y.atan2(-top.dir.z).to_degrees() - 20.0).abs() < 1e-9);

        let o = ViewOverrides {
            lookat: Some((DVec3::ZERO, DVec3::X, None)),
            fov: Some(60.0),
            width: Some(8),
            height: None,
        };
        let cam = camera_of(c, &o).unwrap();
        assert_eq!((cam.width(), cam.height()), (8, 20));
        assert!((cam.ray_unit(DVec2::splat(0.5)).dir - DVec3::X).length() < 1e-12);
        let bad = ViewOverrides {
            fov: Some(-1.0),
            ..Default::default()
        };
        assert!(camera_of(c, &bad).is_err());
    }
}
