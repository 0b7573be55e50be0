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
//! - `discretisation`: each input surface's depth limit and the element
//!   trees subdivided to it, shared by the solver, its solution and the
//!   solution file.
//! - `faces`: the faces of input surfaces that send and receive light.
//! - `cluster`: the cluster hierarchy above the input surfaces (Smits,
//!   Arvo & Greenberg 1994); `cluster_transport`: each face's cut through
//!   it, far links to clusters and the far fields of glossy faces
//!   (Christensen et al. 1997).
//! - `divergence`: scenes with no finite solution (light never absorbed
//!   and never escaping), refused before the solve.
//! - `throughput`: T = A F V per element pair, cached (paper §4.6);
//!   `shards`: the shared tables' shards, each on its own cache lines.
//! - `radiosity`: two-point radiance of Lambertian parts, push-pull.
//! - `textures`: each element's texture average (ρ_d and the glossy
//!   ratio g of textured materials), pushed as irradiance.
//! - `interaction`: interaction hierarchies (paper §3.2), flux-weighted
//!   push-pull (§4.4, §5.6), point lookup (§4.5).
//! - `link`: what a sender sends, and the pair and node links of a shot
//!   (§4.2).
//! - `refine`: RefineAndLink (§3.2.2, §4.3): what refinement reads
//!   (`refine::context`), stage 1's pair links (`refine::pair`), stage
//!   2's three-point links with their three subdivision cases
//!   (`refine::triple`) and the sampled narrow lobes (`refine::narrow_lobe`).
//! - `setup`: what a solve fixes before its first shot (scene,
//!   discretisation, faces, buried parts, clusters, partners);
//!   `state`: what the shots change (unshot radiance, hierarchies, ledger).
//! - [`lights`]: lights without area (point, spot, directional) in
//!   bands, with their flux; `light_shot`: their shot, a point-to-element
//!   transfer into every leaf; [`sky`]: an environment map (Mitsuba's
//!   `envmap`), its lookup and its importance sampling, shot as they are.
//! - [`solver`]: the progressive loop (§4, Fig. 7 and 9); `shot`: one
//!   shot's phases (its tests in `shot_tests`), `receive` its fifth (what
//!   each link delivers), `batch` the receiving faces in batches;
//!   `glossy`: the glossy renormalisation; `deferred`: the glossy share of
//!   small links, summed per pair until it counts; `queue`: the next
//!   source and the residual from the sources a shot changed.
//! - [`gather_links`]: the final gather's links, kept for rendering;
//!   `final_gather`: the refinement that makes them.
//! - `ambient`: CR and Cohen's uniform ambient term; `local_ambient`: the
//!   residual's later bounces over the final links, which replace it.
//! - [`ledger`]: where the energy went.
//! - [`solution`]: the radiance query for final gathering and the file
//!   format (checksummed, every field validated).
//! - [`stats`]: what `--stats` writes.
#![forbid(unsafe_code)]
// Band loops index several per-band arrays in step.
#![allow(clippy::needless_range_loop)]

mod ambient;
mod batch;
mod cluster;
mod cluster_transport;
mod deferred;
mod discretisation;
mod divergence;
pub mod error;
mod faces;
mod facing;
mod final_gather;
pub mod gather_links;
mod glossy;
mod interaction;
pub mod ledger;
mod light_shot;
pub mod lights;
mod link;
mod local_ambient;
pub mod prepared;
mod queue;
mod radiosity;
mod receive;
mod refine;
pub mod settings;
mod setup;
mod shards;
mod shot;
#[cfg(test)]
mod shot_tests;
pub mod sky;
mod sky_shot;
pub mod solution;
pub mod solver;
mod state;
pub mod stats;
mod textures;
mod throughput;

/// Small scenes built by the unit tests.
#[cfg(test)]
mod test_scenes;

pub use error::SolverError;
pub use gather_links::{GatherLink, GatherLinks, LinkSource};
pub use interaction::Split;
pub use ledger::Ledger;
pub use lights::{LightError, PreparedLight};
pub use prepared::{PrepareError, PreparedScene, SceneDescription};
pub use settings::{Quality, SolverSettings, Transport};
pub use sky::{PreparedSky, SkyError, SkySample};
pub use solution::{FORMAT_VERSION, Solution, SurfaceSite, solve_hash};
pub use solver::{Progress, Solver};
pub use stats::{Ambient, SolveStats, StopReason, TracePoint};
pub use textures::ElementTextures;
