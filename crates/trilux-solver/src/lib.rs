//! # trilux-solver — progressive hierarchical three-point transport
//!
//! Layer: depends on `trilux-color`, `trilux-geometry`, `trilux-brdf` and
//! `trilux-scene` (only for [`SceneInput::from_scene`]; the solver never
//! parses: it works on a [`SolverInput`]).
//! Implements Dumont, Bouatouch & Gosselin (1997), "A Progressive Algorithm
//! for Three Point Transport", following `notes/algorithm.md`.
//!
//! Contents, in reading order:
//! - [`input`]: what the solver takes from a loaded scene.
//! - [`settings`]: FFErr, FrErr, MinArea, the photometric threshold, CR
//!   target, quality presets, two-point or uniform transport.
//! - `sides`: the faces of input surfaces that send and receive light.
//! - `throughput`: T = A F V per element pair, cached (paper §4.6).
//! - `radiosity`: two-point radiance of Lambertian parts, push-pull.
//! - `interaction`: interaction hierarchies (paper §3.2), flux-weighted
//!   push-pull (§4.4, §5.6), point lookup (§4.5).
//! - `refine`: RefineAndLink with its three subdivision cases (§3.2.2, §4.3).
//! - [`solver`]: the progressive shooting loop (§4, Fig. 7 and 9).
//! - [`ledger`]: where the energy went (notes §7).
//! - [`solution`]: the radiance query for final gathering and the file format.
//! - [`stats`]: what `--stats` writes.
#![forbid(unsafe_code)]
// Band loops index several per-band arrays in step.
#![allow(clippy::needless_range_loop)]

pub mod error;
pub mod input;
mod interaction;
pub mod ledger;
mod radiosity;
mod refine;
pub mod settings;
mod sides;
pub mod solution;
pub mod solver;
pub mod stats;
mod throughput;

pub use error::SolverError;
pub use input::SceneInput;
pub use interaction::Split;
pub use ledger::Ledger;
pub use settings::{Quality, SolverSettings, Transport};
pub use solution::{FORMAT_VERSION, Solution, SurfaceSite, solve_hash};
pub use solver::{Progress, Solver, SolverInput};
pub use stats::SolveStats;
