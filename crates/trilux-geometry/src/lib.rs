//! # trilux-geometry — surfaces, elements, visibility, form factors
//!
//! Layer: depends only on `glam`, `obvhs` and `rayon` (no other trilux crate),
//! so that it can be taken alone as a BVH + form-factor library.
//!
//! Contents:
//! - [`shape`]: the shapes a scene is made of, as plain data in Mitsuba 3's
//!   conventions ([`Shape`], [`ShapeKind`], [`TriangleMesh`]).
#![forbid(unsafe_code)]

pub mod shape;

pub use shape::{Shape, ShapeKind, TriangleMesh};
