//! # trilux-geometry — surfaces, elements, visibility, form factors
//!
//! Layer: the lowest geometric layer. Depends only on `trilux-frame` (the
//! two sides of a surface and the tangent frame, shared with
//! `trilux-brdf`), `glam`, `obvhs`, `rdst`, `rayon`, `serde`, `thiserror`
//! and `sobol_burley`, so that it can be taken alone as a BVH +
//! form-factor library. All public
//! geometry is f64 (`glam::DVec3`).
//!
//! ## In brief
//!
//! ```
//! use std::sync::Arc;
//! use glam::{DMat4, DVec2, DVec3};
//! use trilux_geometry::{
//!     ElementForest, FaceElement, Geometry, Ray, Shape, ShapeKind, SurfaceId, Visibility,
//!     form_factor_front,
//! };
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
//! let geometry = Arc::new(Geometry::build(&shapes)?);
//! let mut forest = ElementForest::new(geometry.clone());
//! let (a, b) = (forest.root(SurfaceId(0)), forest.root(SurfaceId(1)));
//! let f = form_factor_front(&forest, a, b); // Lambert's formula, adaptive cubature
//! assert!((f.value - 0.199825).abs() < 1e-5 && f.error < 1e-4);
//! let visibility = Visibility::new(&forest, None);
//! assert_eq!(visibility.fraction(FaceElement::front(a), FaceElement::front(b), 16), 1.0);
//!
//! let children = forest.subdivide(a); // lazily created, idempotent
//! let s = forest.sample_element(children[3], DVec2::new(0.5, 0.5));
//! assert_eq!(forest.locate(SurfaceId(0), s.coord), children[3]);
//!
//! let hit = geometry.intersect(&Ray { origin: s.point, dir: DVec3::Z }, f64::INFINITY).unwrap();
//! assert_eq!(hit.surface, SurfaceId(1));
//! assert!(!geometry.occluded(s.point, hit.point));
//! # Ok::<(), trilux_geometry::GeometryError>(())
//! ```
//!
//! ## Contents, in the order the data flows
//!
//! - [`shape`]: the shapes a scene is made of, as plain data in Mitsuba 3's
//!   conventions ([`Shape`], [`ShapeKind`], [`TriangleMesh`]); checked
//!   against Mitsuba 3.9 ray hits in `tests/mitsuba.rs`.
//! - [`build`]: [`Geometry::build`] turns shapes into input surfaces and
//!   BVH primitives; errors in [`error`] name the shape; the coordinates it
//!   accepts are in [`limits`].
//! - [`geometry`]: the immutable [`Geometry`] (input surfaces, meshes, BVH)
//!   and its ray queries ([`Ray`], [`Hit`], `intersect`, `occluded` and
//!   their rayon batch forms).
//! - [`surface`]: [`InputSurface`] (planar, curved, chart) and
//!   [`SurfaceCoord`]. The private `patch` module holds the parametric
//!   pieces: rectangles and cube faces (planar bilinear quads), disks (polar:
//!   r = u, φ = 2πv), spheres (8 pieces: 4 quarter-turns in φ × 2
//!   hemispheres), cylinders (4 quarter-turns in φ; open tubes). Non-uniform
//!   scale and shear are supported exactly for every shape (ellipsoids,
//!   elliptic tubes and disks): shapes are evaluated in object space and
//!   mapped by the affine transform.
//! - [`face`]: faces ([`FaceId`], [`PerFace`]) and an element seen from
//!   one side ([`FaceElement`]); the two sides of a surface ([`Side`]) and
//!   per-side storage ([`Sided`]) are `trilux-frame`'s, re-exported.
//! - [`chart`]: triangle meshes as charts (≤ 512 triangles, 60° normal cone,
//!   grown compactly over shared edges), chart elements as clusters of
//!   triangle pieces (the rules are documented there).
//! - `contact` (private): mesh triangles that other surfaces end on (a
//!   ground plane under the walls of a room) cut along those contacts
//!   before their charts are made, so that no element straddles a wall.
//! - [`element`] and [`forest`]: the element trees ([`Element`],
//!   [`ElementId`]) of an [`ElementForest`], lazily subdivided into 4
//!   children on the true surface, with `locate`, `element_contains` and
//!   `element_points`.
//! - [`sampling`]: stratification-friendly point sampling with exact area
//!   densities ([`SurfaceSample`]).
//! - `bvh` (private): one obvhs CWBVH over every primitive, f64 watertight
//!   triangle tests, exact analytic shapes (robustness rules documented
//!   there).
//! - [`form_factor`](mod@form_factor): element-to-element form factors with error estimates
//!   (Lambert's point-to-polygon formula integrated adaptively; pair
//!   cubature for curved pieces and disks; stratified sampling for large
//!   clusters), face to face ([`FaceElement`]).
//! - [`burial`]: the parts of faces that another shape covers (the floor
//!   under a box), probed once into a [`BurialMap`].
//! - [`crossing`]: parts of crossed faces (a floor running past the walls,
//!   a box sunk into the floor) cut off from the light, marked in the
//!   burial map.
//! - [`transmission`]: shapes that let a fraction of the light through
//!   ([`Transmittance`]: a thin dielectric slab, a constant fraction, a
//!   cut-out of varying opacity over an [`OpacityMap`]), and
//!   [`through`], the segment and ray queries that multiply their
//!   fractions (`Geometry::transmittance`, `Geometry::intersect_through`).
//! - [`visibility`]: visible fractions from stratified shadow segments
//!   ([`Visibility`], which takes the burial map explicitly).
//! - [`coordinate_system`]: the orthonormal basis around a unit vector
//!   (Duff et al.), the one tangent frame every crate builds on
//!   (`trilux-frame`'s, re-exported).
//! - [`punctual`]: lights without area ([`Punctual`]: point, spot with
//!   its [`SpotFalloff`], directional) and the light they bring to a point
//!   ([`Arrival`]), shared by the loader, the solver and the renderer.
//! - [`glossy_fit`]: a point's glossy light as a function of direction,
//!   order-2 spherical harmonics plus one spherical Gaussian, fitted by
//!   least squares (shared by the directional bake and the preview).
//! - [`sensor`]: the camera's plain data shared by the scene loader and
//!   the renderer: Mitsuba's `look_at` ([`look_at`]), the field of view's
//!   axis ([`FovAxis`]) and the film's reconstruction filters
//!   ([`ReconstructionFilter`]).
//! - `quadrature`, `sequence` and `transform` (private): integration rules,
//!   seeded Sobol points and affine maps.
#![forbid(unsafe_code)]

pub mod bounds;
pub mod build;
pub mod burial;
mod bvh;
pub mod chart;
mod contact;
pub mod crossing;
pub mod element;
pub mod error;
pub mod face;
pub mod forest;
pub mod form_factor;
pub mod geometry;
pub mod glossy_fit;
pub mod ids;
pub mod limits;
mod patch;
pub mod punctual;
mod quadrature;
pub mod sampling;
pub mod sensor;
mod sequence;
pub mod shape;
pub mod surface;
pub mod through;
mod transform;
pub mod transmission;
pub mod visibility;

pub use bounds::Bounds;
pub use burial::{BurialMap, BurialRequest};
#[cfg(feature = "trace-stats")]
pub use bvh::stats as trace_stats;
pub use chart::{CHART_CONE_DEG, CHART_MAX_EDGE_TRIANGLES, CHART_MAX_TRIANGLES, Piece};
pub use crossing::LightFaces;
pub use element::{Element, ElementDomain};
pub use error::{GeometryError, ShapeProblem};
pub use face::{FaceElement, FaceId, PerFace, Side, Sided};
pub use forest::ElementForest;
pub use form_factor::{
    FormFactor, FormFactorOptions, MAX_POLYGON_PIECES, PointFormFactors, form_factor,
    form_factor_batch, form_factor_front, point_form_factor, point_to_polygon,
    point_to_polygon_front,
};
pub use geometry::{BvhStats, Geometry, Hit, RAY_EPSILON, Ray};
pub use ids::{ElementId, SurfaceId};
pub use punctual::{Arrival, Punctual, SpotFalloff};
pub use sampling::SurfaceSample;
pub use sensor::{FovAxis, LookAtError, ReconstructionFilter, look_at};
pub use shape::{Shape, ShapeKind, TriangleMesh};
pub use surface::{InputSurface, SurfaceCoord, SurfaceKind, SurfacePoint};
pub use transmission::{Cutout, OpacityMap, Transmittance};
pub use trilux_frame::coordinate_system;
pub use visibility::Visibility;
