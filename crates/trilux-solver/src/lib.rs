//! # trilux-solver — progressive hierarchical three-point transport
//!
//! Layer: depends on `trilux-color`, `trilux-geometry`, `trilux-brdf` and
//! `trilux-files` (the solution file's bounded read and safe write); it
//! never parses scene files: it takes a [`SceneDescription`], the plain data
//! the scene layer hands over, and prepares it once ([`PreparedScene`]).
//! Implements Dumont, Bouatouch & Gosselin (1997), "A Progressive Algorithm
//! for Three Point Transport"; docs/solver.md says where it departs.
//!
//! Contents, in reading order:
//! - [`prepared`]: the scene prepared for `N` bands — geometry, materials,
//!   emitters — shared by the solver, its solution and the renderer.
//! - [`settings`]: FFErr, FrErr, MinArea, the photometric threshold, CR
//!   target, quality presets, two-point or uniform transport.
//! - `faces`: the faces of input surfaces that send and receive light.
//! - `cluster`: the cluster hierarchy above the input surfaces (Smits,
//!   Arvo & Greenberg 1994); `cluster_transport`: each face's cut through
//!   it, far links to clusters and the far fields of glossy faces
//!   (Christensen et al. 1997).
//! - `divergence`: scenes with no finite solution (light never absorbed
//!   and never escaping), refused before the solve.
//! - `throughput`: T = A F V per element pair, cached (paper §4.6).
//! - `radiosity`: two-point radiance of Lambertian parts, push-pull.
//! - `textures`: each element's texture average (ρ_d and the glossy
//!   ratio g of textured materials), pushed as irradiance.
//! - `interaction`: interaction hierarchies (paper §3.2), flux-weighted
//!   push-pull (§4.4, §5.6), point lookup (§4.5).
//! - `refine`: RefineAndLink with its three subdivision cases (§3.2.2, §4.3).
//! - [`solver`]: preparing a solve and the progressive loop (§4, Fig. 7
//!   and 9); `shot`: one shot's phases; `glossy`: the glossy
//!   renormalisation.
//! - [`gather_links`]: the final gather's links, kept for rendering.
//! - [`ledger`]: where the energy went.
//! - [`solution`]: the radiance query for final gathering and the file
//!   format (checksummed, every field validated).
//! - [`stats`]: what `--stats` writes.
#![forbid(unsafe_code)]
// Band loops index several per-band arrays in step.
#![allow(clippy::needless_range_loop)]

mod cluster;
mod cluster_transport;
mod discretisation;
mod divergence;
pub mod error;
mod faces;
mod final_gather;
pub mod gather_links;
mod glossy;
mod interaction;
pub mod ledger;
mod link;
pub mod prepared;
mod radiosity;
mod refine;
pub mod settings;
mod setup;
mod shot;
pub mod solution;
pub mod solver;
mod state;
pub mod stats;
mod textures;
mod throughput;

pub use error::SolverError;
pub use gather_links::{GatherLink, GatherLinks, LinkSource};
pub use interaction::Split;
pub use ledger::Ledger;
pub use prepared::{PrepareError, PreparedScene, SceneDescription};
pub use settings::{Quality, SolverSettings, Transport};
pub use solution::{FORMAT_VERSION, Solution, SurfaceSite, solve_hash};
pub use solver::{Progress, Solver};
pub use stats::SolveStats;
pub use textures::ElementTextures;
#[cfg(test)]
mod test_scenes;
