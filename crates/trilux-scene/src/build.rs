//! Stage 4 of loading: the resolved tree → the [`Scene`] model.
//!
//! Top level: `<shape>`, `<sensor>` (one), `<integrator>` (at most one,
//! `crate::integrator`), `<bsdf>`, `<texture>`, `<emitter>`, `<film>`,
//! `<sampler>` and `<rfilter>` definitions (with an `id`, for `<ref>`s).
//! Anything else is refused with its location. Each top-level element is
//! built on its own, so that the errors of all of them are reported
//! together.

use std::path::Path;

use glam::{DMat4, DVec3};
use trilux_brdf::BsdfParams;
use trilux_color::ColorParam;

use crate::camera::{Camera, Crop, FovAxis, ReconstructionFilter, default_fov};
use crate::error::{Result, SceneError};
use crate::limits::MAX_SHAPES;
use crate::material::{TextureCollector, build_bsdf};
use crate::meshes::Requests;
use crate::props::Props;
use crate::resolve::Resolved;
use crate::scene::{AreaEmitter, Environment, Light, Scene, SceneShape};
use crate::shape::{MeshRequest, build_shape};
use crate::textures::TextureRequest;
use crate::xml::Element;
use trilux_geometry::ShapeKind;

/// Builds the scene from the resolved tree. `path` is the scene file. OBJ
/// shapes come with empty meshes and, beside the scene, the requests to
/// read them (shape index, request). Each top-level element is built on
/// its own: the errors of all of them are returned together (with those
/// `resolved` found), and the shape limit stops at once.
pub(crate) fn build(resolved: Resolved, path: &Path) -> Result<(Scene, Requests)> {
    let Resolved {
        scene: scene_el,
        failed,
        bsdf_counts,
        mut errors,
    } = resolved;
    errors.keep_at(0, scene_el.check_attrs(&["version"]));
    let mut b = Builder {
        folder: path.parent().unwrap_or(Path::new(".")),
        shapes: Vec::new(),
        lights: Vec::new(),
        shape_elements: 0,
        requests: Requests::default(),
        camera: None,
        sensor: None,
        integrator: None,
        params: None,
        environment: None,
    };
    for (k, (e, &failed)) in scene_el.children.iter().zip(&failed).enumerate() {
        if e.tag == "shape" {
            if b.shape_elements == MAX_SHAPES {
                return Err(errors.stop(SceneError::at(
                    &e.loc,
                    format!(
                        "the scene has more than {MAX_SHAPES} shapes, the limit (docs/limits.md)"
                    ),
                )));
            }
            b.shape_elements += 1;
        }
        if failed {
            // Its errors are reported; it still counts as the first
            // <sensor> or <integrator>.
            b.sensor = b.sensor.or((e.tag == "sensor").then_some(e));
            b.integrator = b.integrator.or((e.tag == "integrator").then_some(e));
        } else {
            errors.keep_at(k + 1, b.top_level(e));
        }
    }
    let Builder {
        shapes,
        lights,
        requests,
        camera,
        integrator,
        params,
        environment,
        ..
    } = b;
    let max_depth = params.as_ref().and_then(|p| p.max_depth);
    let spectral = shapes.iter().any(|s| {
        bsdf_is_sampled(&s.bsdf)
            || s.emitter
                .as_ref()
                .is_some_and(|em| em.radiance.is_sampled())
    }) || environment
        .as_ref()
        .is_some_and(|e| e.radiance.is_sampled())
        || lights.iter().any(|l| l.intensity.is_sampled())
        || camera
            .as_ref()
            .and_then(|c| c.response.as_ref())
            .is_some_and(ColorParam::is_sampled);
    let scene = Scene {
        path: path.to_path_buf(),
        shapes,
        lights,
        camera,
        max_depth,
        max_depth_location: integrator
            .filter(|_| max_depth.is_some())
            .map(crate::integrator::max_depth_location),
        hide_emitters: params.is_some_and(|p| p.hide_emitters),
        spectral,
        bsdf_counts,
        camera_names: Vec::new(),
        environment,
        warnings: Vec::new(),
    };
    errors.or((scene, requests))
}

/// What [`build`] has built so far.
struct Builder<'a> {
    /// The scene file's folder (relative file names start there).
    folder: &'a Path,
    shapes: Vec<SceneShape>,
    /// The lights without area (`crate::light`).
    lights: Vec<Light>,
    /// `<shape>` elements met, built or not (the limit counts them).
    shape_elements: usize,
    requests: Requests,
    camera: Option<Camera>,
    /// The first `<sensor>` and `<integrator>`, built or not.
    sensor: Option<&'a Element>,
    integrator: Option<&'a Element>,
    /// What the integrator asks of the image.
    params: Option<crate::integrator::IntegratorParams>,
    /// The `constant` emitter, if any.
    environment: Option<Environment>,
}

impl<'a> Builder<'a> {
    /// Builds top-level element `e` into the scene.
    fn top_level(&mut self, e: &'a Element) -> Result<()> {
        match e.tag.as_str() {
            "shape" => {
                let (shape, request, textures) = scene_shape(e, self.folder)?;
                let index = self.shapes.len();
                self.requests.meshes.extend(request.map(|r| (index, r)));
                let textures = textures.into_iter().map(|t| (index, t));
                self.requests.textures.extend(textures);
                self.shapes.push(shape);
            }
            "bsdf" => {
                // A definition: built once here so that errors in unused
                // definitions are reported too.
                build_bsdf(e, &mut TextureCollector::new(self.folder))?;
            }
            // A texture definition, checked where a <ref> places it (it
            // needs the name the <ref> gives it).
            "texture" if e.attr("id").is_some() => {}
            "sensor" => {
                if let Some(first) = self.sensor {
                    return Err(SceneError::at(
                        &e.loc,
                        format!(
                            "only one <sensor> is supported (the first is at line {})",
                            first.loc.line
                        ),
                    ));
                }
                self.sensor = Some(e);
                self.camera = Some(sensor(e)?);
            }
            "integrator" => {
                if let Some(first) = self.integrator {
                    return Err(SceneError::at(
                        &e.loc,
                        format!(
                            "only one <integrator> is allowed (the first is at line {})",
                            first.loc.line
                        ),
                    ));
                }
                self.integrator = Some(e);
                self.params = Some(crate::integrator::integrator(e)?);
            }
            "emitter"
                if e.attr("type")
                    .is_some_and(|t| matches!(t.value.as_str(), "constant" | "envmap")) =>
            {
                let env = if e.plugin_type()? == "envmap" {
                    Environment {
                        radiance: trilux_color::ColorParam::Float(0.0),
                        map: Some(crate::envmap::envmap(e, self.folder)?),
                        shape: None,
                        location: e.loc.clone(),
                    }
                } else {
                    crate::environment::constant(e)?
                };
                if let Some(first) = &self.environment {
                    return Err(crate::environment::second(e, first));
                }
                self.environment = Some(env);
            }
            "emitter" if matches!(e.plugin_type()?, "point" | "spot" | "directional") => {
                self.lights.push(crate::light::light(e)?);
            }
            "emitter" => top_level_emitter(e)?,
            "film" | "sampler" | "rfilter" if e.attr("id").is_some() => sensor_definition(e)?,
            other => {
                return Err(SceneError::at(
                    &e.loc,
                    format!(
                        "unsupported element <{other}> in <scene> (supported: shape, sensor, integrator, default, include, and bsdf, texture, emitter, film, sampler, rfilter with an id)"
                    ),
                ));
            }
        }
        Ok(())
    }
}

/// A top-level `<film>`, `<sampler>` or `<rfilter>` with an id is a
/// definition that a sensor's or a film's `<ref>` names, checked here so
/// that an unused one's errors are reported too.
fn sensor_definition(e: &Element) -> Result<()> {
    match e.tag.as_str() {
        "film" => film(e).map(|_| ()),
        "sampler" => sampler(e).map(|_| ()),
        _ => rfilter(e).map(|_| ()),
    }
}

/// A top-level area `<emitter id>` is a definition, attached to the shape
/// whose `<ref>` names it (checked here, so that an unused one's errors
/// are reported); any other is refused.
fn top_level_emitter(e: &Element) -> Result<()> {
    let t = e.plugin_type()?;
    let message = match t {
        "area" if e.attr("id").is_some() => return area_emitter(e).map(|_| ()),
        "area" => "an area <emitter> must be placed inside a <shape> (or given an id and named there by a <ref>)".to_string(),
        _ => format!(
            "unknown emitter plugin \"{t}\" (supported: area inside a shape; point, spot, directional, constant, envmap)"
        ),
    };
    Err(SceneError::at(&e.loc, message))
}

/// True when some colour of the BSDF is a sampled spectrum.
fn bsdf_is_sampled(b: &BsdfParams) -> bool {
    match b {
        BsdfParams::Diffuse { reflectance } => reflectance.is_sampled(),
        BsdfParams::RoughConductor(rc) => {
            rc.specular_reflectance.is_sampled()
                || rc
                    .eta_k
                    .as_ref()
                    .is_some_and(|(eta, k)| eta.is_sampled() || k.is_sampled())
        }
        BsdfParams::Plastic(p) => {
            p.diffuse_reflectance.is_sampled() || p.specular_reflectance.is_sampled()
        }
        BsdfParams::Blend { first, second, .. } => {
            bsdf_is_sampled(first) || bsdf_is_sampled(second)
        }
        BsdfParams::TwoSided { front, back } => {
            bsdf_is_sampled(front) || back.as_deref().is_some_and(bsdf_is_sampled)
        }
    }
}

type ShapeRequests = (SceneShape, Option<MeshRequest>, Vec<TextureRequest>);

fn scene_shape(e: &Element, folder: &Path) -> Result<ShapeRequests> {
    e.check_attrs(&["type", "id", "name"])?;
    let props = Props::new(e)?;
    let mut bsdf = None;
    let mut textures = TextureCollector::new(folder);
    let mut emitter = None;
    let mut transmission = None;
    for o in &props.objects {
        match o.tag.as_str() {
            "bsdf" => {
                if bsdf.is_some() {
                    return Err(SceneError::at(&o.loc, "a <shape> takes at most one <bsdf>"));
                }
                bsdf = Some(build_bsdf(o, &mut textures)?);
                transmission = crate::glass::transmission(o)?;
            }
            "emitter" => {
                if emitter.is_some() {
                    return Err(SceneError::at(
                        &o.loc,
                        "a <shape> takes at most one <emitter>",
                    ));
                }
                emitter = Some(area_emitter(o)?);
            }
            _ => {
                return Err(SceneError::at(
                    &o.loc,
                    format!("a <shape> cannot contain {}", o.describe()),
                ));
            }
        }
    }
    let (shape, request) = build_shape(&props, folder)?;
    props.finish()?;
    if !textures.requests.is_empty()
        && !matches!(shape.kind, ShapeKind::Rectangle | ShapeKind::Mesh(_))
    {
        return Err(SceneError::at(
            &e.loc,
            format!(
                "{} has a textured material, but only rectangle, obj and ply shapes have texture coordinates here",
                e.describe()
            ),
        ));
    }
    let shape = SceneShape {
        id: e.attr("id").map(|a| a.value.clone()),
        shape,
        // Without a <bsdf>, Mitsuba 3.9.1 makes an emitter's shape black
        // (its Shape constructor: diffuse 0) and any other diffuse 0.5.
        bsdf: bsdf.unwrap_or_else(|| match emitter {
            Some(_) => BsdfParams::Diffuse {
                reflectance: ColorParam::Float(0.0),
            },
            None => BsdfParams::default(),
        }),
        emitter,
        textures: Vec::new(),
        transmission,
        location: e.loc.clone(),
    };
    Ok((shape, request, textures.requests))
}

fn area_emitter(e: &Element) -> Result<AreaEmitter> {
    e.check_attrs(&["type", "id", "name"])?;
    let t = e.plugin_type()?;
    if t != "area" {
        return Err(SceneError::at(
            &e.required("type")?.loc,
            format!(
                "a shape's emitter must be \"area\", found \"{t}\" (point, spot and directional emitters stand at the top level of the scene)"
            ),
        ));
    }
    let props = Props::new(e)?;
    props.no_objects()?;
    // How often Mitsuba's light sampling picks this emitter: its noise, not
    // its image.
    props.float("sampling_weight")?;
    let radiance = crate::material::emitted_strength(&props, "radiance")?;
    props.finish()?;
    Ok(AreaEmitter {
        radiance,
        location: e.loc.clone(),
    })
}

fn sensor(e: &Element) -> Result<Camera> {
    e.check_attrs(&["type", "id", "name"])?;
    let t = e.plugin_type()?;
    if t != "perspective" {
        return Err(SceneError::at(
            &e.required("type")?.loc,
            format!("unknown sensor plugin \"{t}\" (only \"perspective\")"),
        ));
    }
    let props = Props::new(e)?;
    let (fov, fov_axis) = sensor_fov(&props)?;
    let pose = sensor_pose(&props)?;
    let (near_clip, far_clip) = clip_planes(&props)?;
    let principal_point_offset = principal_point_offset(&props)?;
    let children = sensor_children(&props)?;
    let response = sensor_response(&props)?;
    ignored_sensor_params(&props)?;
    props.finish()?;
    Ok(Camera {
        origin: pose.origin,
        target: pose.target,
        up: pose.up,
        world_from_camera: pose.world_from_camera,
        fov,
        fov_axis,
        width: children.film.width,
        height: children.film.height,
        rfilter: children.film.rfilter,
        sample_count: children.sample_count,
        near_clip,
        far_clip,
        principal_point_offset,
        crop: children.film.crop,
        sample_border: children.film.sample_border,
        response,
        location: e.loc.clone(),
    })
}

/// The sensor's `fov` (strictly between 0 and 180 degrees) and the axis it
/// spans; unwritten, Mitsuba's 50 mm lens along the diagonal.
fn sensor_fov(props: &Props<'_>) -> Result<(f64, FovAxis)> {
    if props.has("focal_length") {
        return focal_length_fov(props);
    }
    match props.float("fov")? {
        Some(fov) => {
            if !(fov > 0.0 && fov < 180.0) {
                return Err(SceneError::at(
                    &props.loc("fov"),
                    format!("fov must lie strictly between 0 and 180 degrees, found {fov}"),
                ));
            }
            let axis = match props.string("fov_axis")? {
                None => FovAxis::X,
                Some(name) => FovAxis::from_name(&name).ok_or_else(|| {
                    SceneError::at(
                        &props.loc("fov_axis"),
                        format!("unknown fov_axis \"{name}\" (x, y, smaller, larger or diagonal)"),
                    )
                })?,
            };
            Ok((fov, axis))
        }
        // Mitsuba's default: a 50 mm lens, fov along the diagonal.
        None if props.has("fov_axis") => Err(SceneError::at(
            &props.loc("fov_axis"),
            "fov_axis needs a fov (without fov, Mitsuba uses its 50 mm lens along the diagonal)",
        )),
        None => Ok((default_fov(), FovAxis::Diagonal)),
    }
}

/// Mitsuba's `focal_length` ("<x>mm" or "<x>", on a 36 × 24 mm film): the
/// field of view along the diagonal, 2 atan(43.27 mm / 2x).
fn focal_length_fov(props: &Props<'_>) -> Result<(f64, FovAxis)> {
    let loc = props.loc("focal_length");
    if props.has("fov") {
        return Err(SceneError::at(
            &loc,
            "give either focal_length or fov, not both (as Mitsuba asks)",
        ));
    }
    let text = props.string("focal_length")?.unwrap_or_default();
    let digits = text.trim().strip_suffix("mm").unwrap_or(text.trim());
    let diagonal = (36f64 * 36.0 + 24.0 * 24.0).sqrt();
    let fov = |f: f64| (2.0 * (diagonal / (2.0 * f)).atan()).to_degrees();
    match digits.parse::<f64>() {
        Ok(f) if f.is_finite() && f > 0.0 && fov(f) < 180.0 => Ok((fov(f), FovAxis::Diagonal)),
        _ => Err(SceneError::at(
            &loc,
            format!(
                "focal_length must be a positive length in millimetres such as \"35mm\", found \"{text}\""
            ),
        )),
    }
}

/// Parameters of Mitsuba's perspective sensor that do not change a
/// pinhole camera's image of a static scene, read (so their type is
/// checked) and ignored: `focus_distance` (only a lens has a focal plane)
/// and the shutter interval (nothing in a trilux scene moves).
fn ignored_sensor_params(props: &Props<'_>) -> Result<()> {
    props.float("focus_distance")?;
    let open = props.float("shutter_open")?.unwrap_or(0.0);
    let close = props.float("shutter_close")?.unwrap_or(0.0);
    if open > close {
        return Err(SceneError::at(
            &props.loc("shutter_open"),
            format!(
                "shutter_open {open} must not be later than shutter_close {close} (as Mitsuba asks)"
            ),
        ));
    }
    Ok(())
}

/// The sensor's `srf` (Mitsuba's spectral response, read in its spectral
/// variants): a spectrum or a constant, finite and non-negative. An
/// `<rgb>` response has no spectral meaning Mitsuba gives it here.
fn sensor_response(props: &Props<'_>) -> Result<Option<ColorParam>> {
    let Some(srf) = props.color("srf")? else {
        return Ok(None);
    };
    let at = || props.loc("srf");
    if matches!(srf, ColorParam::Rgb(_)) {
        return Err(SceneError::at(
            &at(),
            "srf: give the sensor's spectral response as a <spectrum> or <float>, not <rgb>",
        ));
    }
    if let Some(v) = srf
        .values()
        .into_iter()
        .find(|v| !(v.is_finite() && *v >= 0.0))
    {
        return Err(SceneError::at(
            &at(),
            format!("srf: the spectral response must be finite and non-negative, found {v}"),
        ));
    }
    // A malformed spectrum (wavelengths not ascending) is refused here,
    // before any work, not when the render converts it.
    srf.to_spectrum::<3>(trilux_color::Role::Unbounded)
        .map_err(|e| SceneError::at(&at(), format!("srf: {e}")))?;
    Ok(Some(srf))
}

/// Where the sensor stands and looks: its `to_world` (a rigid motion) and
/// the target and up vector of its `<lookat>`, or else those its matrix
/// implies (the camera looks along +z with +y up).
struct SensorPose {
    world_from_camera: DMat4,
    origin: DVec3,
    target: DVec3,
    up: DVec3,
}

/// The sensor's [`SensorPose`]: its `to_world` must not scale and must
/// place the camera within the geometry's coordinate limits.
fn sensor_pose(props: &Props<'_>) -> Result<SensorPose> {
    let transform = props.transform("to_world")?;
    let world_from_camera = transform.as_ref().map_or(DMat4::IDENTITY, |t| t.matrix);
    let l = crate::transform::linear_part(&world_from_camera);
    for axis in [l.x_axis, l.y_axis, l.z_axis] {
        if (axis.length() - 1.0).abs() > 1e-3 {
            return Err(SceneError::at(
                &props.loc("to_world"),
                "the sensor's to_world must not scale (Mitsuba refuses scale factors in a camera transform)",
            ));
        }
    }
    let origin = world_from_camera.transform_point3(DVec3::ZERO);
    let largest = origin.abs().max_element();
    if !trilux_geometry::limits::within(largest) {
        return Err(SceneError::at(
            &props.loc("to_world"),
            format!(
                "the camera's position: {}",
                trilux_geometry::limits::beyond(largest)
            ),
        ));
    }
    let (target, up) = match transform.as_ref().and_then(|t| t.lookat) {
        Some(la) => (la.target, la.up),
        None => (
            origin + world_from_camera.transform_vector3(DVec3::Z),
            world_from_camera.transform_vector3(DVec3::Y),
        ),
    };
    Ok(SensorPose {
        world_from_camera,
        origin,
        target,
        up,
    })
}

/// `principal_point_offset_x` and `_y`, in film sizes, each within [-1, 1].
fn principal_point_offset(props: &Props<'_>) -> Result<[f64; 2]> {
    let mut principal_point_offset = [0.0; 2];
    for (k, name) in ["principal_point_offset_x", "principal_point_offset_y"]
        .iter()
        .enumerate()
    {
        let v = props.float(name)?.unwrap_or(0.0);
        if !(v.is_finite() && v.abs() <= 1.0) {
            return Err(SceneError::at(
                &props.loc(name),
                format!("{name} must be within [-1, 1] (film sizes), found {v}"),
            ));
        }
        principal_point_offset[k] = v;
    }
    Ok(principal_point_offset)
}

/// What a sensor's children set: its `<film>` and its `<sampler>`'s
/// sample count (each at most once; Mitsuba's defaults when absent).
struct SensorChildren {
    film: FilmParams,
    sample_count: u32,
}

/// Reads a sensor's one `<film>` and one `<sampler>`; anything else, or a
/// second of either, is an error.
fn sensor_children(props: &Props<'_>) -> Result<SensorChildren> {
    let mut film_params = FilmParams {
        width: 768,
        height: 576,
        rfilter: ReconstructionFilter::default(),
        crop: None,
        sample_border: false,
    };
    let mut sample_count = 4;
    let mut seen_film = false;
    let mut seen_sampler = false;
    for o in &props.objects {
        match o.tag.as_str() {
            "film" if !seen_film => {
                seen_film = true;
                film_params = film(o)?;
            }
            "sampler" if !seen_sampler => {
                seen_sampler = true;
                sample_count = sampler(o)?;
            }
            _ => {
                return Err(SceneError::at(
                    &o.loc,
                    format!(
                        "a <sensor> takes one <film> and one <sampler>; unexpected {}",
                        o.describe()
                    ),
                ));
            }
        }
    }
    Ok(SensorChildren {
        film: film_params,
        sample_count,
    })
}

/// `near_clip` and `far_clip` as written: positive, finite, near < far.
/// Unwritten, there is none (0 and ∞), not Mitsuba's 0.01 and 10⁴: those
/// would hide a scene smaller than a centimetre or larger than 10 km, and
/// trilux renders scenes from 1e-6 to 1e15 across (docs/limits.md).
fn clip_planes(props: &Props<'_>) -> Result<(f64, f64)> {
    let near = props.float("near_clip")?;
    let far = props.float("far_clip")?;
    for (name, v) in [("near_clip", near), ("far_clip", far)] {
        let Some(v) = v else { continue };
        if !(v.is_finite() && v > 0.0) {
            return Err(SceneError::at(
                &props.loc(name),
                format!("{name} must be a positive number, found {v}"),
            ));
        }
    }
    let (near, far) = (near.unwrap_or(0.0), far.unwrap_or(f64::INFINITY));
    if near >= far {
        return Err(SceneError::at(
            &props.loc("far_clip"),
            format!("far_clip {far} must be larger than near_clip {near}"),
        ));
    }
    Ok((near, far))
}

fn positive_u32(props: &Props<'_>, name: &str, default: u32) -> Result<u32> {
    match props.integer(name)? {
        None => Ok(default),
        Some(v) => u32::try_from(v).ok().filter(|&v| v > 0).ok_or_else(|| {
            SceneError::at(
                &props.loc(name),
                format!("{name} must be a positive integer, found {v}"),
            )
        }),
    }
}

/// What a `<film>` says.
struct FilmParams {
    width: u32,
    height: u32,
    rfilter: ReconstructionFilter,
    crop: Option<Crop>,
    sample_border: bool,
}

fn film(e: &Element) -> Result<FilmParams> {
    e.check_attrs(&["type", "id", "name"])?;
    let t = e.plugin_type()?;
    if t != "hdrfilm" {
        return Err(SceneError::at(
            &e.required("type")?.loc,
            format!("unknown film plugin \"{t}\" (only \"hdrfilm\")"),
        ));
    }
    let props = Props::new(e)?;
    let width = positive_u32(&props, "width", 768)?;
    let height = positive_u32(&props, "height", 576)?;
    crate::limits::check_film(width, height).map_err(|m| {
        let at = if props.has("width") {
            "width"
        } else {
            "height"
        };
        SceneError::at(&props.loc(at), m)
    })?;
    // What the output file holds and how it is written: trilux's command
    // line decides (EXR, PNG); radiance is the same.
    // `compensate` (Kahan summation) and `banner` change the sums' rounding
    // and the file's pixels' text, not the light.
    props.ignore(&[
        "pixel_format",
        "component_format",
        "file_format",
        "compensate",
        "banner",
    ]);
    let sample_border = props.boolean("sample_border")?.unwrap_or(false);
    let crop = crop_window(&props, width, height)?;
    let mut rfilter = ReconstructionFilter::default();
    for (i, o) in props.objects.iter().enumerate() {
        if o.tag != "rfilter" || i > 0 {
            return Err(SceneError::at(
                &o.loc,
                format!("a <film> takes one <rfilter>; unexpected {}", o.describe()),
            ));
        }
        rfilter = self::rfilter(o)?;
    }
    props.finish()?;
    Ok(FilmParams {
        width,
        height,
        rfilter,
        crop,
        sample_border,
    })
}

/// Mitsuba's `crop_offset_x`, `crop_offset_y`, `crop_width`,
/// `crop_height` (the whole film by default), within the film.
fn crop_window(props: &Props<'_>, width: u32, height: u32) -> Result<Option<Crop>> {
    let names = [
        "crop_offset_x",
        "crop_offset_y",
        "crop_width",
        "crop_height",
    ];
    if !names.iter().any(|n| props.has(n)) {
        return Ok(None);
    }
    let get =
        |name: &str, default: i64| -> Result<i64> { Ok(props.integer(name)?.unwrap_or(default)) };
    let (x, y) = (get(names[0], 0)?, get(names[1], 0)?);
    let w = get(names[2], i64::from(width) - x)?;
    let h = get(names[3], i64::from(height) - y)?;
    let fits = |o: i64, size: i64, full: u32| o >= 0 && size >= 1 && o + size <= i64::from(full);
    if !fits(x, w, width) || !fits(y, h, height) {
        let at = names
            .iter()
            .rev()
            .find(|n| props.has(n))
            .copied()
            .unwrap_or(names[0]);
        return Err(SceneError::at(
            &props.loc(at),
            format!(
                "the crop window {w} × {h} at ({x}, {y}) must lie within the {width} × {height} film"
            ),
        ));
    }
    Ok(Some(Crop {
        offset: [x as u32, y as u32],
        size: [w as u32, h as u32],
    }))
}

/// An `<rfilter>` element, inside a film or defined for a `<ref>`.
fn rfilter(o: &Element) -> Result<ReconstructionFilter> {
    o.check_attrs(&["type", "id", "name"])?;
    let fp = Props::new(o)?;
    fp.no_objects()?;
    let rfilter = rfilter_of(o, &fp)?;
    fp.finish()?;
    Ok(rfilter)
}

/// Widest reconstruction filter, in pixels: every sample is added to
/// (2 r + 1)² pixels, so a radius of thousands would make each sample cost
/// millions of additions (docs/limits.md).
const MAX_FILTER_RADIUS: f64 = 16.0;

/// An `<rfilter>` with its parameters (Mitsuba's names and defaults).
fn rfilter_of(o: &Element, fp: &Props<'_>) -> Result<ReconstructionFilter> {
    let positive = |name: &str, default: f64, radius_per_unit: f64| -> Result<f64> {
        let v = fp.float(name)?.unwrap_or(default);
        if !(v > 0.0 && v * radius_per_unit <= MAX_FILTER_RADIUS) {
            return Err(SceneError::at(
                &fp.loc(name),
                format!(
                    "{name} must be positive and make a filter radius of at most {MAX_FILTER_RADIUS} px, found {v}"
                ),
            ));
        }
        Ok(v)
    };
    let finite = |name: &str, default: f64| -> Result<f64> {
        let v = fp.float(name)?.unwrap_or(default);
        if !v.is_finite() {
            return Err(SceneError::at(
                &fp.loc(name),
                format!("{name} must be a finite number"),
            ));
        }
        Ok(v)
    };
    Ok(match o.plugin_type()? {
        "gaussian" => ReconstructionFilter::Gaussian {
            stddev: positive("stddev", 0.5, 4.0)?,
        },
        "box" => ReconstructionFilter::Box,
        "tent" => ReconstructionFilter::Tent {
            radius: positive("radius", 1.0, 1.0)?,
        },
        "mitchell" => ReconstructionFilter::Mitchell {
            b: finite("B", 1.0 / 3.0)?,
            c: finite("C", 1.0 / 3.0)?,
        },
        "catmullrom" => ReconstructionFilter::Mitchell { b: 0.0, c: 0.5 },
        "lanczos" => {
            let lobes = fp.integer("lobes")?.unwrap_or(3);
            if !(1..=MAX_FILTER_RADIUS as i64).contains(&lobes) {
                return Err(SceneError::at(
                    &fp.loc("lobes"),
                    format!("lobes must be between 1 and {MAX_FILTER_RADIUS}, found {lobes}"),
                ));
            }
            ReconstructionFilter::Lanczos {
                lobes: lobes as u32,
            }
        }
        other => {
            return Err(SceneError::at(
                &o.required("type")?.loc,
                format!(
                    "unknown rfilter plugin \"{other}\" (gaussian, box, tent, mitchell, catmullrom or lanczos)"
                ),
            ));
        }
    })
}

fn sampler(e: &Element) -> Result<u32> {
    e.check_attrs(&["type", "id", "name"])?;
    // Mitsuba 3.9.1's samplers all converge to the same image; trilux uses
    // its own low-discrepancy sequences in their place.
    let t = e.plugin_type()?;
    const SAMPLERS: [&str; 5] = [
        "independent",
        "stratified",
        "multijitter",
        "orthogonal",
        "ldsampler",
    ];
    if !SAMPLERS.contains(&t) {
        return Err(SceneError::at(
            &e.required("type")?.loc,
            format!("unknown sampler plugin \"{t}\" ({})", SAMPLERS.join(", ")),
        ));
    }
    let props = Props::new(e)?;
    props.no_objects()?;
    let n = positive_u32(&props, "sample_count", 4)?;
    let max = crate::limits::MAX_SAMPLES_PER_PIXEL;
    if n > max {
        return Err(SceneError::at(
            &props.loc("sample_count"),
            format!("sample_count {n} is more than the {max} samples per pixel trilux renders"),
        ));
    }
    // Mitsuba's seed picks other random numbers, and `jitter` and
    // `strength` (stratified, multijitter, orthogonal) place them
    // otherwise: the noise, not the image it converges to; trilux's
    // sequences are its own (`--seed`).
    props.integer("seed")?;
    props.boolean("jitter")?;
    props.integer("strength")?;
    props.finish()?;
    Ok(n)
}
