//! # trilux-scene — the scene model and its file formats
//!
//! Layer: depends on `trilux-color`, `trilux-geometry` and `trilux-brdf`
//! (their plain-data parameter types), `trilux-files` (bounded reads),
//! `glam`, `roxmltree` and `tobj`.
//! File formats live only here; the solver and the renderer never parse.
//!
//! Two formats load into the same model: glTF 2.0 (`.gltf`, `.glb`: the
//! [`gltf`] module, with its material mapping in docs/gltf.md) and the
//! Mitsuba 3 XML subset below. Textures (PNG, JPEG: [`image`]) are read
//! with the meshes, last (the private `textures` module).
//!
//! The XML loader reads the subset of Mitsuba 3's XML listed in the README with Mitsuba's semantics and defaults, and refuses
//! anything else with an error that displays as `FILE:LINE:COL: what is
//! wrong`. Like Mitsuba's parser it works in stages:
//!
//! 1. `xml`: XML text → an intermediate tree of elements and attributes,
//!    each with its source location; `<default>` and `$name` substitution.
//! 2. `resolve`: `<ref id>` replaced by the object it names (a BSDF,
//!    texture, emitter, film, sampler or filter).
//! 3. `build`: typed parameters (`props`, `value`, [`transform`], their
//!    numbers read by `numbers`) → the
//!    model: shapes ([`shape`]), materials (`material`), area lights,
//!    lights without area (`light`: point, spot, directional), the
//!    environment (`environment`: a `constant` sky's enclosure; `envmap`:
//!    an environment map's image, with `rgbe` for `.hdr` files) and the
//!    camera ([`camera`], its film's filter in [`rfilter`]), and the
//!    `integrator` a solve stands for.
//! 4. [`meshes`]: the OBJ, PLY and serialized files the shapes name
//!    ([`obj`], [`ply`], [`serialized`]) and the
//!    textures' images, read last, so that a command can check the camera
//!    and its options against the [`Pending`] scene first ([`open`]).
//!
//! Before all of it, the file must be a regular file of UTF-8 text
//! (`text`); every stage is bounded ([`limits`], docs/limits.md).
//!
//! The model ([`scene`]) knows nothing about XML:
//! [`Scene`] → [`SceneShape`] (a `trilux_geometry::Shape`, a
//! `trilux_brdf::BsdfParams`, an optional [`AreaEmitter`]) and a [`Camera`].
//!
//! ```no_run
//! let scene = trilux_scene::load("scenes/cornell-box.xml")?;
//! println!("{} shapes, spectral: {}", scene.shapes.len(), scene.spectral);
//! # Ok::<(), trilux_scene::SceneError>(())
//! ```
#![forbid(unsafe_code)]

mod build;
pub mod camera;
mod environment;
mod envmap;
pub mod error;
mod glass;
pub mod gltf;
pub mod image;
mod integrator;
mod ior;
mod light;
pub mod limits;
mod material;
pub mod meshes;
mod numbers;
pub mod obj;
pub mod ply;
mod props;
mod resolve;
mod rgbe;
/// The film's reconstruction filters (defined beside the rest of the
/// sensor's plain data in `trilux_geometry::sensor`).
pub use trilux_geometry::sensor::rfilter;
pub mod scene;
pub mod serialized;
pub mod shape;
mod text;
mod textures;
pub mod transform;
mod value;
mod xml;

use std::path::Path;
use std::sync::Arc;

pub use camera::{Camera, FovAxis, ReconstructionFilter};
pub use envmap::EnvMap;
pub use error::{SceneError, SourceLocation};
pub use meshes::Pending;
pub use scene::{AreaEmitter, Environment, Light, Scene, SceneShape};
pub use shape::surface_area;
pub use transform::LookAt;

/// Loads a scene file (Mitsuba 3 XML subset, or glTF 2.0 by its `.gltf`
/// or `.glb` extension).
pub fn load(path: impl AsRef<Path>) -> Result<Scene, SceneError> {
    load_with_params(path, &[])
}

/// Reads and checks a scene file, all but its meshes and textures; for a
/// glTF file, `camera` names the camera to use (a camera's or its node's
/// name; the first one otherwise). An XML scene has one `<sensor>`: naming
/// a camera for it is an error. `params` are `$name` values, as for
/// [`open_with_params`].
pub fn open_with_camera(
    path: impl AsRef<Path>,
    camera: Option<&str>,
    params: &[(String, String)],
) -> Result<Pending, SceneError> {
    let path = path.as_ref();
    if gltf::is_gltf(path) && params.is_empty() {
        return gltf::open(path, camera).map(Pending::gltf);
    }
    if let Some(name) = camera {
        return Err(SceneError::at(
            &SourceLocation {
                file: Arc::from(path),
                line: 1,
                col: 1,
                pointer: None,
            },
            format!(
                "--camera \"{name}\" chooses among a glTF file's cameras; this XML scene has one <sensor>"
            ),
        ));
    }
    open_with_params(path, params)
}

/// Reads a glTF or GLB file from bytes in memory; `path` names it in errors
/// and anchors relative URIs (for fuzzing and tests).
pub fn open_gltf_bytes(bytes: &[u8], path: impl AsRef<Path>) -> Result<Pending, SceneError> {
    gltf::open_bytes(bytes, &Arc::from(path.as_ref()), None).map(Pending::gltf)
}

/// Loads a scene file with values for its `$name` parameters (they override
/// the file's `<default>`s, like Mitsuba's `load_file(path, name=value)`).
pub fn load_with_params(
    path: impl AsRef<Path>,
    params: &[(String, String)],
) -> Result<Scene, SceneError> {
    open_with_params(path, params)?.finish()
}

/// Reads and checks a scene file, all but its OBJ meshes ([`Pending`]).
pub fn open(path: impl AsRef<Path>) -> Result<Pending, SceneError> {
    open_with_params(path, &[])
}

/// [`open`] with `$name` parameter values.
pub fn open_with_params(
    path: impl AsRef<Path>,
    params: &[(String, String)],
) -> Result<Pending, SceneError> {
    let path = path.as_ref();
    if gltf::is_gltf(path) {
        if !params.is_empty() {
            return Err(SceneError::at(
                &SourceLocation::json(&Arc::from(path), "/"),
                "$name parameters are for Mitsuba XML scenes, not glTF",
            ));
        }
        return gltf::open(path, None).map(Pending::gltf);
    }
    let bytes = trilux_files::read_limited(path, limits::MAX_SCENE_BYTES).map_err(|source| {
        SceneError::Read {
            path: path.to_path_buf(),
            source,
        }
    })?;
    let text = text::decode(&bytes, path)?;
    open_str(text, path, params)
}

/// Loads a scene from text; `path` names it in errors and anchors relative
/// file names (OBJ meshes resolve against `path`'s folder).
pub fn load_str(text: &str, path: impl AsRef<Path>) -> Result<Scene, SceneError> {
    load_str_with_params(text, path, &[])
}

/// [`load_str`] with `$name` parameter values.
pub fn load_str_with_params(
    text: &str,
    path: impl AsRef<Path>,
    params: &[(String, String)],
) -> Result<Scene, SceneError> {
    open_str(text, path.as_ref(), params)?.finish()
}

fn open_str(text: &str, path: &Path, params: &[(String, String)]) -> Result<Pending, SceneError> {
    let file: Arc<Path> = Arc::from(path);
    let (tree, includes) = xml::parse(text, &file, params)?;
    let resolved = resolve::resolve(&tree)?;
    let (scene, mut requests) = build::build(resolved, path)?;
    requests.includes = includes;
    Ok(Pending::new(scene, requests))
}
