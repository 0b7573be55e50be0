//! # trilux-geometry — surfaces, elements, visibility, form factors
//!
//! Layer: the lowest geometric layer. Depends only on `glam`, `obvhs`,
//! `rayon`, `serde`, `thiserror` and `sobol_burley` (no other trilux crate),
//! so that it can be taken alone as a BVH + form-factor library. All public
//! geometry is f64 (`glam::DVec3`).
//!
//! ## In brief
//!
//! ```
//! use glam::{DMat4, DVec2, DVec3};
//! use trilux_geometry::{Ray, SceneGeometry, Shape, ShapeKind};
//!
//! // Two unit squares facing each other one unit apart (Mitsuba's
//! // `rectangle` is [-1, 1]² at z = 0 with normal +z).
//! let half = DMat4::from_scale(DVec3::new(0.5, 0.5, 1.0));
//! let shapes = [
//!     Shape { kind: ShapeKind::Rectangle, world_from_object: half, flip_normals: false },
//!     Shape {
//!         kind: ShapeKind::Rectangle,
//!         world_from_object: DMat4::from_translation(DVec3::Z) * half,
//!         flip_normals: true,
//!     },
//! ];
//! let mut geom = SceneGeometry::build(&shapes)?;
//! let (a, b) = (geom.surfaces()[0].root, geom.surfaces()[1].root);
//! let f = geom.form_factor(a, b); // Lambert's formula, adaptive cubature
//! assert!((f.value - 0.199825).abs() < 1e-5 && f.error < 1e-4);
//! assert_eq!(geom.visibility(a, b, 16), 1.0);
//!
//! let children = geom.subdivide(a); // lazily created, idempotent
//! let s = geom.sample_element(children[3], DVec2::new(0.5, 0.5));
//! assert_eq!(geom.locate(geom.element(a).surface, s.coord), children[3]);
//!
//! let hit = geom.intersect(&Ray { origin: s.point, dir: DVec3::Z }, f64::INFINITY).unwrap();
//! assert_eq!(hit.surface, geom.element(b).surface);
//! assert!(!geom.occluded(s.point, hit.point));
//! # Ok::<(), trilux_geometry::GeometryError>(())
//! ```
//!
//! ## Contents, in the order the data flows
//!
//! - [`shape`]: the shapes a scene is made of, as plain data in Mitsuba 3's
//!   conventions ([`Shape`], [`ShapeKind`], [`TriangleMesh`]); checked
//!   against Mitsuba 3.9 ray hits in `tests/mitsuba.rs`.
//! - [`scene_geometry`]: [`SceneGeometry::build`] turns shapes into input
//!   surfaces and a BVH; errors in [`error`] name the shape.
//! - [`surface`]: [`InputSurface`] (planar, curved, chart) and
//!   [`SurfaceCoord`]. The private `patch` module holds the parametric
//!   pieces: rectangles and cube faces (planar bilinear quads), disks (polar:
//!   r = u, φ = 2πv), spheres (8 pieces: 4 quarter-turns in φ × 2
//!   hemispheres), cylinders (4 quarter-turns in φ; open tubes). Non-uniform
//!   scale and shear are supported exactly for every shape (ellipsoids,
//!   elliptic tubes and disks): shapes are evaluated in object space and
//!   mapped by the affine transform.
//! - [`chart`]: triangle meshes as charts (≤ 512 triangles, 60° normal cone,
//!   grown compactly over shared edges), chart elements as clusters of
//!   triangle pieces (the rules are documented there).
//! - [`element`]: the element trees ([`Element`], [`ElementId`]) in one
//!   arena, lazily subdivided into 4 children on the true surface, with
//!   `locate`, `element_contains` and `element_points`.
//! - [`sampling`]: stratification-friendly point sampling with exact area
//!   densities ([`SurfaceSample`]).
//! - [`bvh`]: ray queries ([`Ray`], [`Hit`], `intersect`, `occluded` and
//!   their rayon batch forms) over one obvhs CWBVH, with f64 watertight
//!   triangle tests, exact analytic shapes and a relative self-intersection
//!   epsilon (robustness rules documented there).
//! - [`form_factor`]: element-to-element form factors with error estimates
//!   (Lambert's point-to-polygon formula integrated adaptively; pair
//!   cubature for curved pieces and disks; stratified sampling for large
//!   clusters), per side for two-sided materials ([`Side`]).
//! - [`visibility`]: visible fractions from stratified shadow segments.
//! - [`burial`]: the parts of faces that another shape covers (the floor
//!   under a box), probed once; visibility treats them as blocked.
//! - `quadrature` and `transform` (private): integration rules and affine
//!   maps.
#![forbid(unsafe_code)]

pub mod bounds;
pub mod burial;
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
pub use burial::{BurialMap, BurialRequest};
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
