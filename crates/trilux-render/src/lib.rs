//! # trilux-render — final gathering from a solution
//!
//! Layer: the top library layer. It may depend on every trilux library crate
//! (`trilux-color`, `trilux-files`, `trilux-geometry`, `trilux-brdf`,
//! `trilux-scene`, `trilux-solver`); nothing depends on it but the `trilux` command and
//! `xtask`.
//!
//! A view-independent solution (paper §3–§5) says how much light leaves every
//! element towards every other; this crate turns it into a picture as the
//! paper's §4.5 describes ("Final Gathering", Fig. 11): a ray from the eye
//! meets the scene at x_s, gather rays from x_s meet it at x_d, and the
//! radiance leaving x_d towards x_s is read from the solution. The gather
//! adds light sampling with multiple importance sampling, and one extra
//! bounce where the solution's piecewise-constant steps would show
//! ([`gather`]).
//!
//! Contents, in the order an image is made:
//! - [`camera`]: Mitsuba 3's `perspective` sensor (fov, `fov_axis`, `lookat`).
//! - [`view`]: the scene's sensor as a [`Camera`], with command-line
//!   overrides (`--lookat`, `--fov`, film size).
//! - [`sampler`]: Owen-scrambled Sobol samples (sobol_burley), one sequence
//!   per pixel, decorrelated by the seed.
//! - [`gather`]: the abstraction the integrator is written against
//!   ([`GatherScene`]) and the final-gather estimator itself.
//! - [`link_gather`]: rendering from the solution's gather links (the
//!   default) and the noise-free preview; [`link_sum`]: the sum over the
//!   links at one point.
//! - [`solved`]: [`GatherScene`] for trilux's geometry, BRDFs and a
//!   solution ([`RadianceSolution`]).
//! - [`pipeline`]: the one orchestration — prepare a loaded scene in its
//!   mode, solve it or load a saved solution, save it, render a view.
//! - [`filter`]: reconstruction filters (Mitsuba's Gaussian, box).
//! - [`film`]: splatting samples through the filter, per-pixel normalisation.
//! - [`driver`]: tiles rendered in parallel (rayon), merged deterministically.
//! - [`image`]: the finished [`Image`], its EXR (ZIP) and PNG files (never
//!   with a non-finite pixel; written through `trilux-files`).
//! - [`analytic`]: analytic scenes with known answers (tests, benches).
//! - [`mod@compare`]: relative RMSE and mean ratio against a reference image.
//! - [`bands`]: small helpers on per-band radiance arrays.
//! - [`error`]: the error type, [`RenderError`].
#![forbid(unsafe_code)]

pub mod analytic;
pub mod bands;
pub mod camera;
pub mod compare;
pub mod driver;
pub mod error;
pub mod film;
pub mod filter;
pub mod gather;
pub mod image;
pub mod link_gather;
pub mod link_sum;
pub mod pipeline;
pub mod sampler;
pub mod solved;
pub mod view;

pub use camera::{Camera, FovAxis, Ray};
pub use compare::{Comparison, compare};
pub use driver::{Estimator, RenderSettings, RenderStats, render, render_image};
pub use error::RenderError;
pub use film::Film;
pub use filter::ReconstructionFilter;
pub use gather::{
    BsdfSample, ExtraBounce, GatherScene, GatherStats, LightSample, SurfacePoint, power_heuristic,
};
pub use image::Image;
pub use pipeline::{Observer, Outcome, Plan, RenderPlan, SolutionSource, prepare, scene_camera};
pub use sampler::PixelSampler;
pub use solved::{DirectOnly, RadianceSolution, SolvedScene};
pub use view::{ViewOverrides, camera_of, filter_of};
