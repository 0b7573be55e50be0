//! # trilux-frame — the two sides of a surface and its local frame
//!
//! Layer: the bottom, beside `trilux-color` and `trilux-files`; depends
//! only on `glam` and `serde`. The vocabulary that the geometry
//! (`trilux-geometry`: faces of input surfaces) and the reflectance models
//! (`trilux-brdf`: a lobe per side, shading frames) share, in a crate of its
//! own so that neither depends on the other:
//!
//! - [`side`]: [`Side`], front or back of a surface, and [`Sided`], one
//!   value per side.
//! - [`basis`]: [`coordinate_system`], the orthonormal basis around a unit
//!   normal (Mitsuba 3's), the one definition of every tangent frame.

pub mod basis;
pub mod side;

pub use basis::coordinate_system;
pub use side::{Side, Sided};
