//! The scene model: what the solver and the renderer consume. It knows
//! nothing of XML (the loader's stages live in `xml`, `resolve` and `build`).

use std::collections::BTreeMap;
use std::path::PathBuf;

use serde::Serialize;
use trilux_brdf::{BsdfParams, TextureSlot};
use trilux_color::{ColorParam, Mode};
use trilux_geometry::{Bounds, Geometry, Punctual, Shape, Transmittance};

use crate::camera::Camera;
use crate::error::{SceneError, SourceLocation};

/// An area light (`<emitter type="area">` inside a shape): one-sided
/// Lambertian emission from the front side of its shape.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct AreaEmitter {
    /// Emitted radiance as written (`radiance`; Mitsuba's default is 1).
    pub radiance: ColorParam,
    /// Where the `<emitter>` is written.
    #[serde(skip)]
    pub location: SourceLocation,
}

/// An environment emitter: `constant` or `envmap`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Environment {
    /// Radiance arriving from every direction (`radiance`, Mitsuba's
    /// default 1) of a `constant` sky (0 for an `envmap`).
    pub radiance: ColorParam,
    /// The image of an `envmap` (`None` for a `constant` sky), which no
    /// enclosure stands for (`crate::envmap`).
    pub map: Option<crate::envmap::EnvMap>,
    /// The index in [`Scene::shapes`] of the enclosure standing for it
    /// (set when the scene's meshes are read: its size needs them;
    /// `crate::environment` says why an enclosure).
    pub shape: Option<usize>,
    /// Where the `<emitter>` is written.
    #[serde(skip)]
    pub location: SourceLocation,
}

/// A light without area: Mitsuba's `point`, `spot` and `directional`
/// emitters, glTF's `KHR_lights_punctual` lights. A delta in position or
/// direction: no ray meets it, the solve shoots from it and the render
/// samples it by next-event estimation.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Light {
    /// Where it is and how its intensity varies with direction.
    pub punctual: Punctual,
    /// The radiant intensity (W sr⁻¹) of a point or spot light at full
    /// strength, or the irradiance (W m⁻²) of a directional light on a
    /// plane facing it (Mitsuba's `intensity` and `irradiance`).
    pub intensity: ColorParam,
    /// Where the light is written.
    #[serde(skip)]
    pub location: SourceLocation,
}

/// One `<shape>` with its material and optional area light.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SceneShape {
    /// The shape's `id` attribute, if any.
    pub id: Option<String>,
    /// Geometry in Mitsuba's object-space conventions, with `to_world`.
    pub shape: Shape,
    /// Its BSDF (Mitsuba's default `diffuse` 0.5 when none is given).
    pub bsdf: BsdfParams,
    /// The area light on it, if any.
    pub emitter: Option<AreaEmitter>,
    /// The textures of its material (empty for a uniform one); `bsdf`
    /// holds placeholders for the parameters they stand for.
    #[serde(skip)]
    pub textures: Vec<TextureSlot>,
    /// The fraction of light the shape lets through, undeviated, when its
    /// BSDF is a `thindielectric` (`crate::glass`).
    pub transmission: Option<Transmittance>,
    /// Where the `<shape>` is written.
    #[serde(skip)]
    pub location: SourceLocation,
}

/// A loaded scene.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Scene {
    /// The scene file.
    pub path: PathBuf,
    /// The shapes, in file order (index i is shape i of the geometry layer).
    pub shapes: Vec<SceneShape>,
    /// The lights without area, in file order.
    pub lights: Vec<Light>,
    /// The camera, when the file has a `<sensor>` (Mitsuba 3 loads scenes
    /// without one too; solving needs none, rendering does).
    pub camera: Option<Camera>,
    /// The integrator's `max_depth` (Mitsuba's longest path, -1 for no
    /// limit), when the file gives one: the renderer honours a finite one
    /// (`trilux::integrator_settings`).
    pub max_depth: Option<i64>,
    /// Where the file writes `max_depth` (its warnings name the place).
    #[serde(skip)]
    pub max_depth_location: Option<SourceLocation>,
    /// The integrator's `hide_emitters`: camera rays that meet an emitting
    /// surface render black.
    pub hide_emitters: bool,
    /// True when some `<spectrum>` in use gives wavelength:value pairs: the
    /// scene then solves in spectral bands by default.
    pub spectral: bool,
    /// Number of `<bsdf>` elements of each type written in the file (nested
    /// ones included; a referenced BSDF counts once).
    pub bsdf_counts: BTreeMap<String, usize>,
    /// A glTF file's cameras in the order its nodes are walked (the first
    /// is the default; `--camera` takes either name), each by its
    /// camera's name, else its node's, `None` when neither is named.
    /// Empty for an XML scene (its one `<sensor>` is `camera`).
    pub camera_names: Vec<Option<String>>,
    /// The `constant` environment emitter, if any; its enclosure is the
    /// last of [`Scene::shapes`] (`crate::environment`).
    pub environment: Option<Environment>,
    /// What loading left out, one line each with its place (zero-area
    /// triangles and meshes): the command prints them as warnings.
    #[serde(skip)]
    pub warnings: Vec<String>,
}

impl Scene {
    /// The mode this scene solves in unless overridden (`--mode`): spectral
    /// when [`Scene::spectral`], else RGB.
    pub fn mode(&self) -> Mode {
        if self.spectral {
            Mode::Spectral
        } else {
            Mode::Rgb
        }
    }

    /// The shapes as the geometry layer takes them (`Geometry::build`).
    pub fn geometry_shapes(&self) -> Vec<Shape> {
        self.shapes.iter().map(|s| s.shape.clone()).collect()
    }

    /// Every shape's BSDF parameters, in shape order.
    pub fn bsdf_params(&self) -> Vec<BsdfParams> {
        self.shapes.iter().map(|s| s.bsdf.clone()).collect()
    }

    /// Every shape's textures (empty lists for uniform materials), in shape
    /// order.
    pub fn texture_slots(&self) -> Vec<Vec<TextureSlot>> {
        self.shapes.iter().map(|s| s.textures.clone()).collect()
    }

    /// Every shape's transmittance (`None` for an opaque one), in shape
    /// order (`PreparedScene::with_transmission`).
    pub fn transmission_params(&self) -> Vec<Option<Transmittance>> {
        self.shapes.iter().map(|s| s.transmission).collect()
    }

    /// Every shape's emitted radiance (`None` without an emitter), in shape
    /// order.
    pub fn emitter_radiance(&self) -> Vec<Option<ColorParam>> {
        self.shapes
            .iter()
            .map(|s| s.emitter.as_ref().map(|e| e.radiance.clone()))
            .collect()
    }

    /// The box standing for the `constant` environment, if any (its
    /// lower and upper corners; `crate::environment`).
    pub fn enclosure(&self) -> Option<Bounds> {
        let shape = &self.shapes.get(self.environment.as_ref()?.shape?)?.shape;
        let m = shape.world_from_object;
        let (a, b) = (
            m.transform_point3(glam::DVec3::splat(-1.0)),
            m.transform_point3(glam::DVec3::splat(1.0)),
        );
        Some(Bounds {
            min: a.min(b),
            max: a.max(b),
        })
    }

    /// The environment map, if the scene's environment is an `envmap`.
    pub fn sky_map(&self) -> Option<&crate::envmap::EnvMap> {
        self.environment.as_ref()?.map.as_ref()
    }

    /// Every light without area as the solver takes it (where it is, its
    /// intensity), in file order.
    pub fn light_params(&self) -> Vec<(Punctual, ColorParam)> {
        self.lights
            .iter()
            .map(|l| (l.punctual, l.intensity.clone()))
            .collect()
    }

    /// Where shape `index` is written (the file's start when there is no
    /// such shape), for errors found after loading.
    pub fn shape_location(&self, index: usize) -> SourceLocation {
        match self.shapes.get(index) {
            Some(s) => s.location.clone(),
            None => SourceLocation {
                file: self.path.as_path().into(),
                line: 1,
                col: 1,
                pointer: None,
            },
        }
    }

    /// The geometry layer's view of the shapes (input surfaces, BVH). What
    /// the geometry layer refuses is reported at the `<shape>` that causes
    /// it, as `FILE:LINE:COL: ...`.
    pub fn build_geometry(&self) -> Result<Geometry, SceneError> {
        Geometry::build(&self.geometry_shapes())
            .map_err(|e| SceneError::at(&self.shape_location(e.shape), e.problem.to_string()))
    }

    /// Indices and shapes of the emitting shapes.
    pub fn emitters(&self) -> impl Iterator<Item = (usize, &SceneShape)> {
        self.shapes
            .iter()
            .enumerate()
            .filter(|(_, s)| s.emitter.is_some())
    }
}
