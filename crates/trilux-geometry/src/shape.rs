//! Shapes as a scene states them, in Mitsuba 3's object-space conventions.
//!
//! These are plain data: the scene loader builds them, and the geometry layer
//! turns them into input surfaces (parametric pieces and mesh charts).

use glam::{DMat4, DVec2, DVec3};
use serde::{Deserialize, Serialize};

/// One `<shape>` of the scene, with its object-to-world transform.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Shape {
    /// What kind of shape, with its own parameters.
    pub kind: ShapeKind,
    /// Mitsuba's `to_world`, already composed (first listed acts first).
    pub world_from_object: DMat4,
    /// Mitsuba's `flip_normals`: the front side (the side that reflects and
    /// emits) becomes the other one.
    pub flip_normals: bool,
}

/// The shapes of the supported Mitsuba 3 subset, in object space.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum ShapeKind {
    /// `rectangle`: the square [-1, 1]² in the plane z = 0, normal +z.
    Rectangle,
    /// `cube`: the cube [-1, 1]³, normals pointing outwards.
    Cube,
    /// `disk`: the unit disk in the plane z = 0, normal +z.
    Disk,
    /// `sphere`: centre and radius in object space (then `to_world`),
    /// normals pointing outwards.
    Sphere {
        /// Centre in object space.
        center: DVec3,
        /// Radius in object space.
        radius: f64,
    },
    /// `cylinder`: an open tube from `p0` to `p1`, normals pointing outwards.
    Cylinder {
        /// Centre of the first end cap circle (object space).
        p0: DVec3,
        /// Centre of the second end cap circle (object space).
        p1: DVec3,
        /// Radius.
        radius: f64,
    },
    /// `obj`: a triangle mesh.
    Mesh(TriangleMesh),
}

/// A triangle mesh in object space (as read from an OBJ file).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct TriangleMesh {
    /// Vertex positions.
    pub positions: Vec<DVec3>,
    /// Per-vertex shading normals (OBJ `vn`), if the file has them.
    pub normals: Option<Vec<DVec3>>,
    /// Triangles as vertex indices, counter-clockwise seen from the front.
    pub triangles: Vec<[u32; 3]>,
    /// Mitsuba's `face_normals`: ignore vertex normals when shading.
    pub face_normals: bool,
    /// Per-vertex texture coordinates (u, v), if the mesh has them: v = 0
    /// is the first (top) row of an image, as in glTF and as Mitsuba keeps
    /// them once its OBJ loader has flipped `vt`.
    #[serde(default)]
    pub texcoords: Option<Vec<DVec2>>,
}
