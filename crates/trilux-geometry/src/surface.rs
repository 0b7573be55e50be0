//! Input surfaces: the patches of the scene as given (paper §3), each the
//! root of one element tree of an [`crate::ElementForest`].

use glam::{DVec2, DVec3};
use serde::{Deserialize, Serialize};

use crate::bounds::Bounds;
use crate::patch::Patch;

/// What kind of input surface this is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[non_exhaustive]
pub enum SurfaceKind {
    /// A planar piece: a rectangle, a cube face, a disk. Children are
    /// coplanar.
    Planar,
    /// A curved parametric piece of a sphere or cylinder: children lie on the
    /// true surface and are not coplanar (paper §5).
    Curved,
    /// A chart of a triangle mesh: elements are clusters of triangles.
    Chart,
}

/// A point of an input surface, in its own coordinates.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum SurfaceCoord {
    /// (u, v) ∈ \[0,1\]² on a parametric surface (planar or curved).
    Uv(DVec2),
    /// A point of a mesh triangle (its index in the mesh of the shape), with
    /// barycentric coordinates (b1, b2) for its second and third vertex.
    Triangle {
        /// Index of the triangle in its mesh.
        index: u32,
        /// Barycentric coordinates of vertices 1 and 2.
        bary: DVec2,
    },
}

/// One input surface: a parametric piece of a shape or a chart of a mesh.
#[derive(Clone, Debug)]
pub struct InputSurface {
    /// Index of the shape (in the slice given to `Geometry::build`)
    /// this surface belongs to.
    pub shape: u32,
    /// Planar, curved or chart.
    pub kind: SurfaceKind,
    /// World-space bounds.
    pub bounds: Bounds,
    /// Which piece of its shape this is (0 for a lone surface: cube faces
    /// 0..6, sphere pieces 0..8, cylinder pieces 0..4, chart index).
    pub piece: u32,
    pub(crate) area: f64,
    pub(crate) planar: bool,
    pub(crate) front_sees_itself: bool,
    pub(crate) back_sees_itself: bool,
    pub(crate) geom: SurfaceGeom,
}

/// How an input surface is represented.
#[derive(Clone, Debug)]
pub(crate) enum SurfaceGeom {
    Patch(Box<Patch>),
    /// A chart of mesh `mesh` (index into the scene's meshes) made of
    /// `triangles`, in the order the chart grew.
    Chart {
        mesh: u32,
        triangles: Vec<u32>,
    },
}

impl InputSurface {
    /// Total area (exact for parametric pieces; the sum of triangle areas for
    /// charts).
    pub fn area(&self) -> f64 {
        self.area
    }

    /// True if the whole surface lies in one plane.
    pub fn is_planar(&self) -> bool {
        self.planar
    }

    /// True if the front side of this surface can send light to the front
    /// side of another part of itself (a concave chart, a sphere or cylinder
    /// piece whose normals point inwards): the solver's secondary
    /// interactions (paper §5) are needed for it.
    pub fn can_see_itself(&self) -> bool {
        self.front_sees_itself
    }

    /// The same for the back side (e.g. the inside of an open cylinder with
    /// outward normals, which a two-sided material would make reflect).
    pub fn back_can_see_itself(&self) -> bool {
        self.back_sees_itself
    }

    /// True if this is a chart of a mesh.
    pub fn is_chart(&self) -> bool {
        matches!(self.kind, SurfaceKind::Chart)
    }
}

/// A point on a surface with its front unit normal.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfacePoint {
    /// World-space position.
    pub point: DVec3,
    /// Front geometric unit normal.
    pub normal: DVec3,
}
