//! Errors raised while turning shapes into input surfaces.
//!
//! Every error names the index of the offending shape in the slice given to
//! [`crate::Geometry::build`], so that the scene loader can map it back
//! to a file location.

use thiserror::Error;

/// A shape could not be turned into input surfaces.
#[derive(Debug, Clone, PartialEq, Error)]
#[error("shape {shape}: {problem}")]
pub struct GeometryError {
    /// Index of the shape in the slice given to `Geometry::build`.
    pub shape: usize,
    /// What is wrong with it.
    pub problem: ShapeProblem,
}

/// What is wrong with a shape.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum ShapeProblem {
    /// The transform has a NaN or infinite entry.
    #[error("the transform world_from_object has a non-finite entry")]
    NonFiniteTransform,
    /// The transform is singular (zero determinant) or projective.
    #[error("the transform world_from_object is singular or not affine")]
    SingularTransform,
    /// A parameter is NaN or infinite.
    #[error("{what} is not finite")]
    NonFinite {
        /// The parameter's name.
        what: &'static str,
    },
    /// A radius is zero or negative.
    #[error("the radius must be positive (got {radius})")]
    BadRadius {
        /// The radius as given.
        radius: f64,
    },
    /// The cylinder's end points coincide.
    #[error("the cylinder's end points p0 and p1 coincide")]
    DegenerateAxis,
    /// The shape (or every triangle of a mesh) has zero area.
    #[error("the shape has zero area")]
    ZeroArea,
    /// The mesh has no triangles.
    #[error("the mesh has no triangles")]
    EmptyMesh,
    /// A triangle refers to a vertex that does not exist.
    #[error("triangle {triangle} refers to vertex {vertex}, but the mesh has {count} vertices")]
    IndexOutOfRange {
        /// Triangle index.
        triangle: usize,
        /// The bad vertex index.
        vertex: u32,
        /// Number of vertices in the mesh.
        count: usize,
    },
    /// A vertex position or normal is not finite.
    #[error("vertex {vertex} has a non-finite position or normal")]
    NonFiniteVertex {
        /// Vertex index.
        vertex: usize,
    },
    /// A point of the shape lies beyond [`crate::limits::MAX_COORDINATE`].
    #[error(
        "the shape reaches coordinate {coordinate:.3e}, beyond the coordinate limit ±{:e} (docs/limits.md)",
        crate::limits::MAX_COORDINATE
    )]
    BeyondCoordinateLimit {
        /// The largest absolute coordinate of the shape.
        coordinate: f64,
    },
    /// The whole scene (this being its largest shape) is smaller than
    /// [`crate::limits::MIN_SCENE_SIZE`].
    #[error(
        "the whole scene is {size:.3e} across, below the smallest size {:e} (docs/limits.md): scale it up",
        crate::limits::MIN_SCENE_SIZE
    )]
    SceneTooSmall {
        /// The diagonal of the scene's bounding box.
        size: f64,
    },
    /// The scene lies too far from the origin for its size (this shape
    /// reaching furthest).
    #[error(
        "the shape reaches coordinate {coordinate:.3e}, more than {:e} times the scene's size {size:.3e} (docs/limits.md): move the scene nearer the origin",
        crate::limits::MAX_OFFSET_RATIO
    )]
    FarFromOrigin {
        /// The shape's largest absolute coordinate.
        coordinate: f64,
        /// The diagonal of the scene's bounding box.
        size: f64,
    },
    /// The mesh has per-vertex normals, but not one per vertex.
    #[error("the mesh has {normals} normals for {positions} vertices")]
    NormalCountMismatch {
        /// Number of normals.
        normals: usize,
        /// Number of positions.
        positions: usize,
    },
}
