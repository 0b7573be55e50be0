//! Stage 5 of loading: the files a scene names — OBJ, PLY and serialized
//! meshes, glTF buffers, texture images — read only once the whole scene
//! file is checked. Zero-area triangles are left out here, each shape's
//! count a line of [`Scene::warnings`], and so are meshes of zero area (an
//! emitting one is refused, as Mitsuba refuses it).
//!
//! A [`Pending`] scene is everything the scene file says, its meshes still
//! empty and its textures unread: a command checks its camera, film and
//! options against it before it spends the time (and memory) of reading
//! them ([`Pending::finish`]).

use crate::cutout::CutoutRequest;
use crate::error::{Errors, Result, SceneError};
use crate::gltf::GltfMeshes;
use crate::scene::Scene;
use crate::shape::{MeshRequest, check_area};
use crate::textures::{ImageSource, TextureCache, TextureRequest};
use std::sync::Arc;

use glam::{DMat4, DVec3};
use trilux_geometry::{ShapeKind, TriangleMesh};

/// What a scene still has to read, by shape index.
#[derive(Debug, Default)]
pub(crate) struct Requests {
    /// OBJ and PLY meshes.
    pub meshes: Vec<(usize, MeshRequest)>,
    /// Textures of materials.
    pub textures: Vec<(usize, TextureRequest)>,
    /// Textured opacities (cut-outs).
    pub cutouts: Vec<(usize, CutoutRequest)>,
    /// The meshes of a glTF file (its buffers are read by `finish`).
    pub gltf: Option<GltfMeshes>,
    /// The files the scene file `<include>`s (already read).
    pub includes: Vec<std::path::PathBuf>,
}

/// A loaded scene whose meshes and textures are not read yet (module
/// docs).
#[derive(Debug)]
pub struct Pending {
    scene: Scene,
    requests: Requests,
}

impl Pending {
    pub(crate) fn new(scene: Scene, requests: Requests) -> Self {
        Pending { scene, requests }
    }

    /// A glTF scene whose buffers and images `meshes` will read.
    pub(crate) fn gltf((scene, meshes): (Scene, GltfMeshes)) -> Self {
        Pending::new(
            scene,
            Requests {
                gltf: Some(meshes),
                ..Requests::default()
            },
        )
    }

    /// The scene as the file states it; mesh shapes have empty meshes.
    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// Every file the scene reads: the scene file, the files it includes,
    /// its OBJ and PLY meshes, its texture images, a glTF file's external
    /// buffers and images (relative names joined to the scene's folder).
    /// A command compares its outputs with them, so that no output
    /// overwrites an input.
    pub fn input_files(&self) -> Vec<std::path::PathBuf> {
        let mut files = vec![self.scene.path.clone()];
        files.extend(self.requests.includes.iter().cloned());
        files.extend(self.requests.meshes.iter().map(|(_, r)| r.path.clone()));
        files.extend(
            self.requests
                .textures
                .iter()
                .filter_map(|(_, r)| match &r.source {
                    ImageSource::File(p) => Some(p.clone()),
                    _ => None,
                }),
        );
        if let Some(gltf) = &self.requests.gltf {
            files.extend(gltf.input_files());
        }
        files
    }

    /// Reads every mesh and texture; errors point at the place in the
    /// scene that names the file. A mesh or texture that fails does not
    /// stop the others: their errors are returned together.
    pub fn finish(mut self) -> Result<Scene> {
        let mut errors = Errors::default();
        let mut flat = Vec::new();
        let mut failed = std::collections::HashSet::new();
        for (index, request) in self.requests.meshes {
            match read_mesh(&mut self.scene, index, &request) {
                Ok(true) => flat.push(index),
                Ok(false) => {}
                Err(e) => {
                    failed.insert(index);
                    errors.push(e);
                }
            }
        }
        let mut cache = TextureCache::default();
        let mut textures = self.requests.textures;
        let mut cutouts = self.requests.cutouts;
        if let Some(gltf) = self.requests.gltf {
            let (t, c) = gltf.finish(&mut self.scene, &mut errors);
            textures.extend(t);
            cutouts.extend(c);
        }
        for (index, request) in &textures {
            if failed.contains(index) {
                continue;
            }
            let shape = &mut self.scene.shapes[*index];
            if let ShapeKind::Mesh(m) = &shape.shape.kind
                && m.texcoords.is_none()
            {
                errors.push(SceneError::at(
                    &request.location,
                    "this texture's shape has no texture coordinates (OBJ vt, PLY u v, glTF TEXCOORD_0)",
                ));
                continue;
            }
            if let Some(p) = request.normal {
                if let Some(map) = errors.keep(cache.normal_map(request, p)) {
                    shape.normal_map = Some(Arc::new(map));
                }
            } else if let Some(slot) = errors.keep(cache.slot(request)) {
                shape.textures.push(slot);
            }
        }
        for (index, request) in &cutouts {
            if failed.contains(index) {
                continue;
            }
            if let ShapeKind::Mesh(m) = &self.scene.shapes[*index].shape.kind
                && m.texcoords.is_none()
            {
                // Said once per shape: by its material's textures if any.
                if !textures.iter().any(|(i, _)| i == index) {
                    errors.push(SceneError::at(
                        &request.texture.location,
                        "this cut-out's shape has no texture coordinates (OBJ vt, PLY u v, glTF TEXCOORD_0)",
                    ));
                }
                continue;
            }
            if let Some(t) = errors.keep(request.finish(&mut cache)) {
                self.scene.shapes[*index].transmission = Some(t);
            }
        }
        let clear = crate::cutout::leave_out_clear(&mut self.scene);
        flat.extend(clear);
        // Last, so that the indices of the requests above stay valid.
        let mut index = 0;
        self.scene.shapes.retain(|_| {
            index += 1;
            !flat.contains(&(index - 1))
        });
        crate::environment::enclose(&mut self.scene);
        errors.or(self.scene)
    }
}

/// Reads the mesh of `request` into shape `index` of `scene`; true when
/// every triangle has zero area (the shape is to be left out, with a
/// warning).
fn read_mesh(scene: &mut Scene, index: usize, request: &MeshRequest) -> Result<bool> {
    let mut mesh = request
        .format
        .load(&request.path, request.face_normals, request.flip_tex_coords)
        .map_err(|e| SceneError::at(&request.filename, e))?;
    let scene_shape = &mut scene.shapes[index];
    let shape = &mut scene_shape.shape;
    let (total, dropped) = drop_zero_area(&mut mesh, &shape.world_from_object);
    shape.kind = ShapeKind::Mesh(mesh);
    let element = request.format.element();
    if let (true, Some(emitter)) = (dropped == total, &scene_shape.emitter) {
        return Err(SceneError::at(
            &emitter.location,
            format!(
                "every triangle of this {element} has zero area: it has no surface to emit from (Mitsuba refuses it too)"
            ),
        ));
    }
    if dropped == total {
        scene.warnings.push(format!(
            "{}: every triangle of this {element} has zero area: it is left out (Mitsuba loads it and never hits it)",
            request.shape
        ));
        return Ok(true);
    }
    if dropped > 0 {
        scene.warnings.push(format!(
            "{}: {dropped} of the {total} triangles of this {element} have zero area and are left out",
            request.shape
        ));
    }
    check_area(shape, &request.shape, element)?;
    Ok(false)
}

/// Leaves out the triangles of `mesh` that have zero area once
/// `world_from_object` places them, by the geometry layer's rule (area at
/// most 1e-14 of the squared diagonal of the placed vertices: it makes no
/// surface of them) and returns how many triangles there were and how
/// many are left out. Non-finite areas are kept, for the geometry layer to
/// refuse.
fn drop_zero_area(mesh: &mut TriangleMesh, world_from_object: &DMat4) -> (usize, usize) {
    let placed: Vec<DVec3> = mesh
        .positions
        .iter()
        .map(|p| world_from_object.transform_point3(*p))
        .collect();
    let (lo, hi) = placed.iter().fold(
        (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
        |(lo, hi), p| (lo.min(*p), hi.max(*p)),
    );
    let diagonal = (hi - lo).length_squared();
    let total = mesh.triangles.len();
    mesh.triangles.retain(|t| {
        // The readers check every index against the vertices.
        let [a, b, c] = t.map(|i| placed.get(i as usize).copied().unwrap_or(DVec3::NAN));
        let area = 0.5 * (b - a).cross(c - a).length();
        // Kept unless comparably small (NaN compares to nothing).
        !matches!(
            area.partial_cmp(&(1e-14 * diagonal)),
            Some(std::cmp::Ordering::Less | std::cmp::Ordering::Equal)
        )
    });
    (total, total - mesh.triangles.len())
}
