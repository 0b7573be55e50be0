//! # trilux-geometry — surfaces, elements, visibility, form factors
//!
//! Layer: the lowest geometric layer. Depends only on `glam`, `obvhs`,
//! `rayon`, `serde`, `thiserror` and `sobol_burley` (no other trilux crate),
//! so that it can be taken alone as a BVH + form-factor library.
//!
//! Contents, in the order the data flows:
//! - [`shape`]: the shapes a scene is made of, as plain data in Mitsuba 3's
//!   conventions ([`Shape`], [`ShapeKind`], [`TriangleMesh`]).
//! - [`scene_geometry`]: [`SceneGeometry::build`] turns shapes into input
//!   surfaces and a BVH; errors in [`error`].
//! - [`surface`]: [`InputSurface`] (planar, curved, chart) and
//!   [`SurfaceCoord`]; `patch` (private) holds the parametric pieces:
//!   planar quads, disks, 8 sphere pieces, 4 cylinder pieces.
//! - [`chart`]: triangle meshes as charts, chart elements as clusters of
//!   triangle pieces (the chart rule is documented there).
//! - [`element`]: the element trees ([`Element`], [`ElementId`]), lazily
//!   subdivided, with `locate` and `element_contains`.
//! - [`sampling`]: stratification-friendly point sampling with exact area
//!   densities ([`SurfaceSample`]).
//! - [`bvh`]: ray queries ([`Ray`], [`Hit`], `intersect`, `occluded` and
//!   their batch forms), robust at shared edges and against
//!   self-intersection.
//! - [`form_factor`]: element-to-element form factors with error estimates
//!   (Lambert's point-to-polygon formula integrated adaptively).
//! - [`visibility`]: visible fractions from stratified shadow segments.
//! - `quadrature` and `transform` (private): integration rules and affine
//!   maps.
#![forbid(unsafe_code)]

pub mod bounds;
pub mod bvh;
pub mod chart;
pub mod element;
pub mod error;
pub mod form_factor;
pub mod ids;
mod patch;
mod quadrature;
pub mod sampling;
pub mod scene_geometry;
pub mod shape;
pub mod surface;
mod transform;
pub mod visibility;

pub use bounds::Bounds;
pub use bvh::{Hit, RAY_EPSILON, Ray};
pub use chart::{CHART_CONE_DEG, CHART_MAX_TRIANGLES, Piece};
pub use element::{Element, ElementDomain};
pub use error::{GeometryError, ShapeProblem};
pub use form_factor::{
    FormFactor, FormFactorOptions, MAX_POLYGON_PIECES, Side, point_to_polygon,
    point_to_polygon_front,
};
pub use ids::{ElementId, SurfaceId};
pub use sampling::SurfaceSample;
pub use scene_geometry::SceneGeometry;
pub use shape::{Shape, ShapeKind, TriangleMesh};
pub use surface::{InputSurface, SurfaceCoord, SurfaceKind, SurfacePoint};
