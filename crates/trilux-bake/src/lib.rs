//! # trilux-bake — the solution's light as a glTF 2.0 binary
//!
//! Layer: above `trilux-solver` (it reads a [`trilux_solver::Solution`])
//! and beside `trilux-render`; the `trilux` crate's pipeline calls it. Depends on
//! `trilux-color`, `trilux-geometry`, `trilux-brdf` and `trilux-solver`
//! (and rayon, to fit vertices in parallel).
//!
//! A view-independent solution is what a walkthrough needs: solve once,
//! look around freely. [`bake()`](bake()) writes the solution's view-independent
//! (Lambertian) light as a `.glb` that any glTF viewer shows: every input
//! surface tessellated at its leaf elements, the outgoing radiance as
//! linear vertex colours (`COLOR_0`), materials unlit
//! (`KHR_materials_unlit`). docs/bake.md is the user's account.
//!
//! Contents, in the order a bake runs:
//! - `tessellate` (private, as are `albedo`, `camera` and `glb`): every
//!   shape's leaves as welded triangles ([`ShapeMesh`]), each owned by one leaf;
//!   T-junctions split so that neighbours share vertices.
//! - [`reconstruct`]: vertex colours from the leaves' radiance by
//!   flux-conserving averaging (the rule and its error bound are there).
//! - [`gathered`]: the diffuse light as the renderer reads it at each
//!   vertex ([`GatheredLight`]), on request ([`DiffuseLight`]).
//! - `albedo`: textured materials as an albedo map times the light.
//! - `camera`: the scene's camera ([`BakeCamera`]) as a glTF camera node.
//! - [`directional`]: the glossy light of glossy sides per vertex,
//!   fitted from a [`GlossyLight`]: order-2 spherical harmonics plus one
//!   spherical Gaussian ([`lobe`]), or order-2 harmonics alone.
//! - [`sh`] and [`lobe`]: the fitting code, `trilux_geometry::glossy_fit`'s
//!   (the renderer's preview fits the same form), re-exported.
//! - `glb`: the glTF JSON and the binary container.
//! - [`bake()`](bake()): the whole, with its [`BakeStats`].
//! - [`mod@error`]: the error type, [`BakeError`].
#![forbid(unsafe_code)]

mod albedo;
pub mod bake;
mod camera;
pub mod directional;
pub mod error;
pub mod gathered;
mod glb;
pub mod reconstruct;
mod tessellate;

pub use bake::{BakeInput, BakeOptions, BakeStats, Baked, MIN_GLOSSY_DIRECTIONS, bake};
pub use camera::BakeCamera;
pub use directional::{GlossyForm, GlossyLight, GlossyPoint, GlossySamples};
pub use error::BakeError;
pub use gathered::{DiffuseLight, GatheredLight};
pub use tessellate::ShapeMesh;
/// The fitting code, shared with the renderer's preview
/// (`trilux_geometry::glossy_fit`).
pub use trilux_geometry::glossy_fit::{lobe, sh};
