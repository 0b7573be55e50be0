//! The glTF node hierarchy → shapes and a camera, and (at finish) the
//! meshes and textures of those shapes.
//!
//! - **Transforms**: a node's `matrix` or `translation`/`rotation`/`scale`,
//!   composed from the scene's roots down (column vectors, parent × child).
//!   A node reached twice is refused (glTF's node graph is a set of
//!   disjoint trees), and so is a hierarchy deeper than [`MAX_NODE_DEPTH`].
//! - **Meshes**: every primitive of a node's mesh is one shape whose
//!   vertices are put into world space (normals by the inverse transpose),
//!   so that the winding rule of glTF (counter-clockwise in world space is
//!   the front, whatever the determinant) is the one trilux's meshes use.
//!   Only `TRIANGLES` (mode 4) is taken. Without `NORMAL` the mesh is
//!   flat-shaded (glTF's rule); `TEXCOORD_0` is kept when present.
//! - **Cameras**: perspective only; glTF's camera looks down −z with +y up,
//!   Mitsuba's (trilux's) down +z with +x to the left, so the camera's
//!   world transform is the node's (its scale removed) times diag(−1, 1,
//!   −1). `yfov` is the vertical field of view; the film is 768 pixels wide
//!   and as high as `aspectRatio` makes it (576 without one).
//! - **Lights** (`KHR_lights_punctual`): point, spot and directional
//!   lights, placed by their nodes (`super::lights`: units, falloff and
//!   what is ignored).

use std::collections::{BTreeMap, HashMap, HashSet};
use std::fmt;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use glam::{DMat3, DMat4, DVec2, DVec3};
use trilux_brdf::BsdfParams;
use trilux_color::ColorParam;
use trilux_geometry::{Shape, ShapeKind, TriangleMesh};

use super::accessor::{self, Kind};
use super::buffers::{Buffers, data_uri, relative_path};
use super::material::{Alpha, Mapped, TextureUse, map};
use crate::camera::{Camera, FovAxis, ReconstructionFilter};
use crate::cutout::{AlphaRule, CutoutRequest};
use crate::error::{Errors, Result, SceneError, SourceLocation};
use crate::limits::{
    MAX_GLTF_NODES, MAX_GLTF_TRIANGLES, MAX_MESH_TRIANGLES, MAX_MESH_VERTICES, MAX_NODE_DEPTH,
    MAX_SHAPES,
};
use crate::scene::{AreaEmitter, Light, Scene, SceneShape};
use crate::shape::check_area;
use crate::textures::{ImageSource, TextureRequest};

/// One mesh primitive placed by a node: read at finish.
#[derive(Clone, Debug)]
struct Placed {
    shape: usize,
    mesh: usize,
    primitive: usize,
    world: DMat4,
}

/// The warning for a primitive whose material is clear everywhere.
fn left_out(file: &Path, here: &str) -> String {
    format!(
        "{}: {here}: its material's alpha is below its alphaCutoff everywhere (alphaMode MASK): the primitive is left out",
        file.display()
    )
}

/// The texture requests and cut-outs of [`GltfMeshes::finish`], by shape.
pub(crate) type GltfTextures = (Vec<(usize, TextureRequest)>, Vec<(usize, CutoutRequest)>);

/// What [`GltfMeshes::finish`] reads: the document, its binary chunk, the
/// placed primitives and the textures of their materials.
pub(crate) struct GltfMeshes {
    file: Arc<Path>,
    document: gltf::Document,
    blob: Option<Vec<u8>>,
    placed: Vec<Placed>,
    textures: Vec<(usize, TextureUse)>,
}

impl fmt::Debug for GltfMeshes {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("GltfMeshes")
            .field("file", &self.file)
            .field("placed", &self.placed)
            .field("textures", &self.textures.len())
            .finish()
    }
}

/// The scene of `gltf` (its default scene, else its first) with `camera`.
/// The errors of each node, primitive and material go into `errors`,
/// their place the order of the walk; a limit passed is returned at once.
pub(crate) fn build(
    file: &Arc<Path>,
    gltf: gltf::Gltf,
    camera: Option<&str>,
    errors: &mut Errors,
) -> Result<(Scene, GltfMeshes)> {
    let doc = &gltf.document;
    let at = |p: String, m: String| SceneError::at(&SourceLocation::json(file, p), m);
    let root = doc
        .default_scene()
        .or_else(|| doc.scenes().next())
        .ok_or_else(|| at("/scenes".into(), "the file has no scene".into()))?;
    let mut walk = Walk {
        file,
        shapes: Vec::new(),
        placed: Vec::new(),
        textures: Vec::new(),
        cameras: Vec::new(),
        materials: HashMap::new(),
        errors,
        bsdf_counts: BTreeMap::new(),
        seen: HashSet::new(),
        triangles: 0,
        lights: Vec::new(),
        warnings: Vec::new(),
    };
    for node in root.nodes() {
        walk.node(&node, DMat4::IDENTITY, 1)?;
    }
    let camera = walk
        .errors
        .keep(choose_camera(file, &walk.cameras, camera))
        .flatten();
    let camera_names = walk
        .cameras
        .iter()
        .map(|c| c.names.iter().flatten().next().cloned())
        .collect();
    let scene = Scene {
        path: file.to_path_buf(),
        shapes: walk.shapes,
        lights: walk.lights,
        camera,
        max_depth: None,
        max_depth_location: None,
        hide_emitters: false,
        spectral: false,
        bsdf_counts: walk.bsdf_counts,
        camera_names,
        environment: None,
        warnings: walk.warnings,
    };
    let meshes = GltfMeshes {
        file: Arc::clone(file),
        document: gltf.document,
        blob: gltf.blob,
        placed: walk.placed,
        textures: walk.textures,
    };
    Ok((scene, meshes))
}

/// The state of the node walk.
struct Walk<'f> {
    file: &'f Arc<Path>,
    shapes: Vec<SceneShape>,
    placed: Vec<Placed>,
    textures: Vec<(usize, TextureUse)>,
    /// (camera name, node name, node index, camera, world transform).
    cameras: Vec<CameraNode>,
    /// Each material mapped, `None` for one that failed (its error is
    /// reported once).
    materials: HashMap<Option<usize>, Option<Mapped>>,
    /// The errors found (a limit passed is returned instead).
    errors: &'f mut Errors,
    bsdf_counts: BTreeMap<String, usize>,
    seen: HashSet<usize>,
    triangles: usize,
    /// The punctual lights (`super::lights`).
    lights: Vec<Light>,
    /// What loading left out (a light's `range`).
    warnings: Vec<String>,
}

struct CameraNode {
    names: [Option<String>; 2],
    node: usize,
    yfov: f64,
    aspect: Option<f64>,
    znear: f64,
    zfar: Option<f64>,
    world: DMat4,
}

impl Walk<'_> {
    fn at(&self, p: String, m: impl Into<String>) -> SceneError {
        SceneError::at(&SourceLocation::json(self.file, p), m)
    }

    fn node(&mut self, node: &gltf::Node<'_>, parent: DMat4, depth: usize) -> Result<()> {
        let i = node.index();
        let here = format!("/nodes/{i}");
        if depth > MAX_NODE_DEPTH {
            return Err(self.at(
                here,
                format!(
                    "the node hierarchy is deeper than {MAX_NODE_DEPTH} levels (docs/limits.md)"
                ),
            ));
        }
        if self.seen.len() == MAX_GLTF_NODES {
            return Err(self.at(
                here,
                format!("the scene has more than {MAX_GLTF_NODES} nodes (docs/limits.md)"),
            ));
        }
        if !self.seen.insert(i) {
            let e = self.at(
                here,
                "the node is reached twice (glTF's nodes form disjoint trees)",
            );
            self.errors.push(e);
            return Ok(());
        }
        let m = node.transform().matrix();
        let local = DMat4::from_cols_array_2d(&m.map(|c| c.map(f64::from)));
        if !local.is_finite() {
            let e = self.at(here, "the node's transform has a number that is not finite");
            self.errors.push(e);
            return Ok(());
        }
        let world = parent * local;
        let checked = self.check_node(node, &here, world);
        self.errors.keep(checked);
        if let Some(mesh) = node.mesh() {
            for p in mesh.primitives() {
                self.primitive(node, &mesh, &p, world)?;
            }
        }
        for child in node.children() {
            self.node(&child, world, depth + 1)?;
        }
        Ok(())
    }

    /// Refuses what node `node` (at `here`) carries and trilux does not
    /// take (a punctual light, an extension, an orthographic camera), and
    /// notes its perspective camera.
    fn check_node(&mut self, node: &gltf::Node<'_>, here: &str, world: DMat4) -> Result<()> {
        if let Some(light) = node.light() {
            let place = format!("{here}/extensions/KHR_lights_punctual");
            let loc = SourceLocation::json(self.file, place.clone());
            match super::lights::light(&light, world, loc.clone()) {
                Ok((l, warning)) => {
                    self.lights.push(l);
                    self.warnings.extend(warning.map(|w| format!("{loc}: {w}")));
                }
                Err(m) => return Err(self.at(place, m)),
            }
        }
        if let Some(name) = node.extensions().and_then(|e| {
            e.keys()
                .find(|k| !super::IGNORED_EXTENSIONS.contains(&k.as_str()))
        }) {
            let named = node
                .name()
                .map(|n| format!("node \"{n}\": "))
                .unwrap_or_default();
            return Err(self.at(
                format!("{here}/extensions/{name}"),
                format!("{named}{}", super::refusal(name)),
            ));
        }
        if let Some(c) = node.camera() {
            match c.projection() {
                gltf::camera::Projection::Perspective(p) => self.cameras.push(CameraNode {
                    names: [
                        c.name().map(str::to_string),
                        node.name().map(str::to_string),
                    ],
                    node: node.index(),
                    yfov: f64::from(p.yfov()),
                    aspect: p.aspect_ratio().map(f64::from),
                    znear: f64::from(p.znear()),
                    zfar: p.zfar().map(f64::from),
                    world,
                }),
                gltf::camera::Projection::Orthographic(_) => {
                    return Err(self.at(
                        format!("/cameras/{}", c.index()),
                        "orthographic cameras are not supported (only perspective)",
                    ));
                }
            }
        }
        Ok(())
    }

    /// Places primitive `p` of `mesh` as a shape; its errors (and its
    /// material's, once) go into `errors`, a limit passed is returned.
    fn primitive(
        &mut self,
        node: &gltf::Node<'_>,
        mesh: &gltf::Mesh<'_>,
        p: &gltf::Primitive<'_>,
        world: DMat4,
    ) -> Result<()> {
        let here = format!("/meshes/{}/primitives/{}", mesh.index(), p.index());
        let material = p.material();
        let key = material.index();
        if !self.materials.contains_key(&key) {
            let mapped = self.errors.keep(map(self.file, &material));
            for t in mapped.iter().flat_map(|m| &m.types) {
                *self.bsdf_counts.entry((*t).to_string()).or_default() += 1;
            }
            self.warnings
                .extend(mapped.iter().flat_map(|m| m.warnings.iter().cloned()));
            self.materials.insert(key, mapped);
        }
        if p.mode() != gltf::mesh::Mode::Triangles {
            let e = self.at(
                format!("{here}/mode"),
                format!(
                    "primitive mode {:?} is not supported (only TRIANGLES)",
                    p.mode()
                ),
            );
            self.errors.push(e);
            return Ok(());
        }
        let Some(positions) = p.get(&gltf::Semantic::Positions) else {
            let e = self.at(
                format!("{here}/attributes"),
                "the primitive has no POSITION",
            );
            self.errors.push(e);
            return Ok(());
        };
        if self.shapes.len() == MAX_SHAPES {
            return Err(self.at(
                format!("/nodes/{}", node.index()),
                format!(
                    "the scene places more than {MAX_SHAPES} mesh primitives (shapes), the limit (docs/limits.md)"
                ),
            ));
        }
        let corners = p.indices().map_or(positions.count(), |a| a.count());
        self.triangles += corners / 3;
        if self.triangles > MAX_GLTF_TRIANGLES {
            return Err(self.at(
                here,
                format!(
                    "the scene places more than {MAX_GLTF_TRIANGLES} triangles (docs/limits.md)"
                ),
            ));
        }
        let Some(Some(mapped)) = self.materials.get(&key) else {
            return Ok(());
        };
        if let Alpha::Transparent = mapped.alpha {
            self.warnings.push(left_out(self.file, &here));
            return Ok(());
        }
        let shape = self.shapes.len();
        let location = SourceLocation::json(self.file, format!("/nodes/{}", node.index()));
        let emitter = emitter(self.file, mapped, key);
        self.textures
            .extend(mapped.uses().map(|t| (shape, t.clone())));
        let bsdf: BsdfParams = mapped.bsdf.clone();
        self.shapes.push(SceneShape {
            id: node.name().or(mesh.name()).map(str::to_string),
            shape: Shape {
                kind: ShapeKind::Mesh(TriangleMesh::default()),
                world_from_object: DMat4::IDENTITY,
                flip_normals: false,
            },
            bsdf,
            emitter,
            textures: Vec::new(),
            normal_map: None,
            transmission: None,
            location,
        });
        self.placed.push(Placed {
            shape,
            mesh: mesh.index(),
            primitive: p.index(),
            world,
        });
        Ok(())
    }
}

/// The area emitter of a mapped material, if it emits.
fn emitter(file: &Arc<Path>, mapped: &Mapped, key: Option<usize>) -> Option<AreaEmitter> {
    mapped
        .emission
        .clone()
        .map(|radiance: ColorParam| AreaEmitter {
            radiance,
            location: SourceLocation::json(
                file,
                format!(
                    "/materials/{}/emissiveFactor",
                    key.map_or("-".into(), |k| k.to_string())
                ),
            ),
        })
}

/// The camera named `name` (a camera's or its node's name), else the first.
fn choose_camera(
    file: &Arc<Path>,
    cameras: &[CameraNode],
    name: Option<&str>,
) -> Result<Option<Camera>> {
    let chosen = match name {
        None => cameras.first(),
        Some(n) => Some(
            cameras
                .iter()
                .find(|c| c.names.iter().flatten().any(|x| x == n))
                .ok_or_else(|| {
                    let known: Vec<String> = cameras
                        .iter()
                        .filter_map(|c| c.names.iter().flatten().next().cloned())
                        .collect();
                    SceneError::at(
                        &SourceLocation::json(file, "/cameras"),
                        format!(
                            "no camera named \"{n}\" (the scene's cameras: {})",
                            if known.is_empty() {
                                "none".into()
                            } else {
                                known.join(", ")
                            }
                        ),
                    )
                })?,
        ),
    };
    chosen.map(|c| camera(file, c)).transpose()
}

fn camera(file: &Arc<Path>, c: &CameraNode) -> Result<Camera> {
    let location = SourceLocation::json(file, format!("/nodes/{}", c.node));
    let err = |m: String| SceneError::at(&location, m);
    let fov = c.yfov.to_degrees();
    if !(fov > 0.0 && fov < 180.0) {
        return Err(err(format!(
            "yfov must lie strictly between 0 and π, found {}",
            c.yfov
        )));
    }
    // Scale removed: each axis of the node's rotation normalised.
    let l = DMat3::from_mat4(c.world);
    let axes = [l.x_axis, l.y_axis, l.z_axis].map(|a| a.normalize_or_zero());
    if axes.contains(&DVec3::ZERO)
        || axes[0].dot(axes[1]).abs() > 1e-3
        || axes[0].dot(axes[2]).abs() > 1e-3
        || axes[1].dot(axes[2]).abs() > 1e-3
    {
        return Err(err(
            "the camera's node transform is singular or shears".into()
        ));
    }
    let origin = c.world.w_axis.truncate();
    let largest = origin.abs().max_element();
    if !trilux_geometry::limits::within(largest) {
        return Err(err(format!(
            "the camera's position: {}",
            trilux_geometry::limits::beyond(largest)
        )));
    }
    // glTF: looks down −z, +x right; Mitsuba: down +z, +x left.
    let world_from_camera = DMat4::from_cols(
        (-axes[0]).extend(0.0),
        axes[1].extend(0.0),
        (-axes[2]).extend(0.0),
        origin.extend(1.0),
    );
    let far_clip = c.zfar.unwrap_or(f64::INFINITY);
    let near_clip = c.znear;
    if !(near_clip.is_finite() && near_clip > 0.0 && far_clip > near_clip) {
        return Err(err(format!(
            "znear {near_clip} must be positive and below zfar {far_clip}"
        )));
    }
    let width = 768u32;
    let height = match c.aspect {
        Some(a) if a.is_finite() && a > 0.0 => {
            ((f64::from(width) / a).round() as u32).clamp(1, crate::limits::MAX_FILM_EDGE)
        }
        Some(a) => return Err(err(format!("aspectRatio must be positive, found {a}"))),
        None => 576,
    };
    Ok(Camera {
        origin,
        target: origin - axes[2],
        up: axes[1],
        world_from_camera,
        fov,
        fov_axis: FovAxis::Y,
        width,
        height,
        rfilter: ReconstructionFilter::default(),
        sample_count: 4,
        near_clip,
        far_clip,
        principal_point_offset: [0.0; 2],
        crop: None,
        sample_border: false,
        response: None,
        location,
    })
}

impl GltfMeshes {
    /// The external files of the glTF: buffers and images named by a
    /// `uri` that is not a `data:` URI.
    pub fn input_files(&self) -> Vec<PathBuf> {
        let folder = self.file.parent().unwrap_or(Path::new(""));
        let buffers = self.document.buffers().filter_map(|b| match b.source() {
            gltf::buffer::Source::Uri(uri) => Some(uri),
            gltf::buffer::Source::Bin => None,
        });
        let images = self.document.images().filter_map(|i| match i.source() {
            gltf::image::Source::Uri { uri, .. } => Some(uri),
            gltf::image::Source::View { .. } => None,
        });
        buffers
            .chain(images)
            .filter(|uri| data_uri(uri).is_none())
            .filter_map(|uri| relative_path(folder, uri).ok())
            .collect()
    }

    /// Reads every placed primitive's mesh into `scene` and returns the
    /// texture requests of their materials and their cut-outs
    /// (`alphaMode` `MASK`); the errors of each mesh and image go into
    /// `errors` (a failed mesh's textures are not requested).
    pub fn finish(self, scene: &mut Scene, errors: &mut Errors) -> GltfTextures {
        let mut buffers = Buffers::new(
            Arc::clone(&self.file),
            self.blob.clone(),
            self.document.buffers().count(),
        );
        let mut failed = HashSet::new();
        for placed in &self.placed {
            let read = self.read_mesh(&mut buffers, placed).and_then(|mesh| {
                let shape = &mut scene.shapes[placed.shape];
                shape.shape.kind = ShapeKind::Mesh(mesh);
                let describe = format!("mesh {} primitive {}", placed.mesh, placed.primitive);
                check_area(&shape.shape, &shape.location, &describe)
            });
            if errors.keep(read).is_none() {
                failed.insert(placed.shape);
            }
        }
        let folder: PathBuf = self
            .file
            .parent()
            .map(Path::to_path_buf)
            .unwrap_or_default();
        let mut images: HashMap<usize, ImageSource> = HashMap::new();
        let mut out = Vec::with_capacity(self.textures.len());
        let mut cutouts = Vec::new();
        for (shape, t) in &self.textures {
            if failed.contains(shape) {
                continue;
            }
            let read = self.cached_source(&mut buffers, &folder, &mut images, t.image);
            let Some(source) = errors.keep(read) else {
                continue;
            };
            let factor = match &t.factor {
                None => None,
                Some(f) => {
                    let read = self.cached_source(&mut buffers, &folder, &mut images, f.image);
                    let Some(source) = errors.keep(read) else {
                        continue;
                    };
                    Some(Box::new(request(f, source)))
                }
            };
            let request = TextureRequest {
                factor,
                max: t.max,
                ..request(t, source)
            };
            match t.cutoff {
                Some(cutoff) => cutouts.push((
                    *shape,
                    CutoutRequest {
                        texture: request,
                        rule: AlphaRule::Cutoff(cutoff),
                    },
                )),
                None => out.push((*shape, request)),
            }
        }
        (out, cutouts)
    }

    /// [`Self::image_source`], read once per image.
    fn cached_source(
        &self,
        buffers: &mut Buffers,
        folder: &Path,
        images: &mut HashMap<usize, ImageSource>,
        index: usize,
    ) -> Result<ImageSource> {
        if let Some(s) = images.get(&index) {
            return Ok(s.clone());
        }
        let s = self.image_source(buffers, folder, index)?;
        images.insert(index, s.clone());
        Ok(s)
    }

    fn image_source(
        &self,
        buffers: &mut Buffers,
        folder: &Path,
        index: usize,
    ) -> Result<ImageSource> {
        let at = |m: String| {
            SceneError::at(
                &SourceLocation::json(&self.file, format!("/images/{index}")),
                m,
            )
        };
        let image = self
            .document
            .images()
            .nth(index)
            .ok_or_else(|| at("no such image".into()))?;
        // `Image::source` unwraps what the crate's validation lets through:
        // a buffer view without a mimeType, an image with neither source.
        let json = &self.document.as_json().images[index];
        match (&json.buffer_view, &json.uri, &json.mime_type) {
            (Some(view), _, _) if view.value() >= self.document.views().len() => {
                return Err(at(format!("bufferView {} does not exist", view.value())));
            }
            (Some(_), _, None) => {
                return Err(at("an image in a bufferView needs a mimeType".into()));
            }
            (None, None, _) => return Err(at("an image needs a uri or a bufferView".into())),
            _ => {}
        }
        Ok(match image.source() {
            gltf::image::Source::View { view, .. } => ImageSource::Bytes(buffers.view(&view)?),
            gltf::image::Source::Uri { uri, .. } => match data_uri(uri) {
                Some(r) => ImageSource::Bytes(Arc::from(r.map_err(|m| at(m.into()))?)),
                None => ImageSource::File(relative_path(folder, uri).map_err(at)?),
            },
        })
    }

    fn read_mesh(&self, buffers: &mut Buffers, placed: &Placed) -> Result<TriangleMesh> {
        let here = format!("/meshes/{}/primitives/{}", placed.mesh, placed.primitive);
        let at = |m: String| SceneError::at(&SourceLocation::json(&self.file, here.clone()), m);
        let p = self
            .document
            .meshes()
            .nth(placed.mesh)
            .and_then(|m| m.primitives().nth(placed.primitive))
            .ok_or_else(|| at("no such primitive".into()))?;
        let get = |s: gltf::Semantic| p.get(&s);
        let pos_acc = get(gltf::Semantic::Positions).ok_or_else(|| at("no POSITION".into()))?;
        let pos = accessor::read(&self.file, buffers, &pos_acc, Kind::Vec3, "POSITION")?;
        let n = pos.len() / 3;
        if n > MAX_MESH_VERTICES {
            return Err(at(format!(
                "{n} vertices; the limit is {MAX_MESH_VERTICES} (docs/limits.md)"
            )));
        }
        let mut attribute =
            |s: gltf::Semantic, kind: Kind, name: &str, width: usize| -> Result<Option<Vec<f64>>> {
                let Some(a) = get(s) else { return Ok(None) };
                let v = accessor::read(&self.file, buffers, &a, kind, name)?;
                if v.len() != n * width {
                    return Err(at(format!(
                        "{name} has {} elements but POSITION has {n}",
                        v.len() / width
                    )));
                }
                Ok(Some(v))
            };
        let normals = attribute(gltf::Semantic::Normals, Kind::Vec3, "NORMAL", 3)?;
        let texcoords = attribute(gltf::Semantic::TexCoords(0), Kind::Vec2, "TEXCOORD_0", 2)?;
        let indices: Vec<u32> = match p.indices() {
            Some(a) => {
                let v = accessor::read(&self.file, buffers, &a, Kind::Index, "indices")?;
                if let Some(bad) = v.iter().find(|&&i| i as usize >= n) {
                    return Err(SceneError::at(
                        &SourceLocation::json(&self.file, format!("/accessors/{}", a.index())),
                        format!("indices: index {bad} is out of range for {n} vertices"),
                    ));
                }
                v.into_iter().map(|i| i as u32).collect()
            }
            None => (0..n as u32).collect(),
        };
        if !indices.len().is_multiple_of(3) || indices.is_empty() {
            return Err(at(format!(
                "{} vertex indices do not make whole triangles",
                indices.len()
            )));
        }
        if indices.len() / 3 > MAX_MESH_TRIANGLES {
            return Err(at(format!(
                "{} triangles; the limit is {MAX_MESH_TRIANGLES} (docs/limits.md)",
                indices.len() / 3
            )));
        }
        let world = placed.world;
        let normal_matrix = DMat3::from_mat4(world).inverse().transpose();
        let positions = pos
            .chunks_exact(3)
            .map(|c| world.transform_point3(DVec3::new(c[0], c[1], c[2])))
            .collect();
        let normals = normals.map(|v| {
            v.chunks_exact(3)
                .map(|c| (normal_matrix * DVec3::new(c[0], c[1], c[2])).normalize_or(DVec3::Z))
                .collect()
        });
        Ok(TriangleMesh {
            positions,
            face_normals: normals.is_none(),
            normals,
            triangles: indices
                .chunks_exact(3)
                .map(|t| [t[0], t[1], t[2]])
                .collect(),
            texcoords: texcoords
                .map(|v| v.chunks_exact(2).map(|c| DVec2::new(c[0], c[1])).collect()),
        })
    }
}

/// The request of texture use `t` reading `source` (no factor).
fn request(t: &TextureUse, source: ImageSource) -> TextureRequest {
    TextureRequest {
        path: t.path.clone(),
        kind: t.kind,
        source,
        sampling: t.sampling,
        scale: t.scale,
        offset: t.offset,
        to_uv: t.to_uv,
        location: t.location.clone(),
        normal: t.normal,
        factor: None,
        max: 1.0,
    }
}
