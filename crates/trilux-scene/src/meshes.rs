//! Stage 5 of loading: the OBJ files a scene names, read only once the
//! whole scene file is checked.
//!
//! A [`Pending`] scene is everything the scene file says, its meshes still
//! empty: a command checks its camera, film and options against it before
//! it spends the time (and memory) of reading meshes ([`Pending::finish`]).

use crate::error::{Result, SceneError};
use crate::obj::load_obj;
use crate::scene::Scene;
use crate::shape::{MeshRequest, check_area};
use trilux_geometry::ShapeKind;

/// A loaded scene whose OBJ meshes are not read yet (module docs).
#[derive(Debug)]
pub struct Pending {
    scene: Scene,
    meshes: Vec<(usize, MeshRequest)>,
}

impl Pending {
    pub(crate) fn new(scene: Scene, meshes: Vec<(usize, MeshRequest)>) -> Self {
        Pending { scene, meshes }
    }

    /// The scene as the file states it; OBJ shapes have empty meshes.
    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// Reads every OBJ file; errors point at the file name in the scene.
    pub fn finish(mut self) -> Result<Scene> {
        for (index, request) in self.meshes {
            let mesh = load_obj(&request.path, request.face_normals)
                .map_err(|e| SceneError::at(&request.filename, e.to_string()))?;
            let shape = &mut self.scene.shapes[index].shape;
            shape.kind = ShapeKind::Mesh(mesh);
            check_area(shape, &request.shape, "<shape type=\"obj\">")?;
        }
        Ok(self.scene)
    }
}
