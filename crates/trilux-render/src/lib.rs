//! # trilux-render — final gathering from a solution
//!
//! Layer: the top library layer. It depends on `trilux-color`,
//! `trilux-files` (image outputs, the film's limits), `trilux-geometry`,
//! `trilux-brdf` and `trilux-solver`, not on the scene model or the bake:
//! the orchestration from a scene file to an image is the `trilux` crate's
//! (`trilux::pipeline`). Nothing depends on it but the `trilux` crate and
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
//! - [`sampler`]: Owen-scrambled Sobol samples (sobol_burley), one sequence
//!   per pixel, decorrelated by the seed.
//! - [`records`]: the records passed between a scene and the estimators
//!   (hits, light and BSDF samples, link visibility, counters).
//! - [`solution`]: what the renderer reads from a solution
//!   ([`RadianceSolution`]; the solver's, or [`DirectOnly`]).
//! - [`link_sum`]: the sum over the solution's gather links at one point.
//! - [`scene`]: what the estimators ask of a scene: the core
//!   [`GatherScene`] and, for a scene backed by a full solution,
//!   [`SolutionGather`].
//! - [`mis`]: light sampling and BSDF-hit emission with multiple importance
//!   sampling, shared by the estimators.
//! - [`gather`]: the path gather of paper §4.5 (the default estimator).
//! - [`link_gather`]: rendering from the solution's gather links, and the
//!   noise-free preview.
//! - [`glossy_fit`]: the preview's glossy light, fitted per corner of a
//!   leaf element as the directional bake fits it per vertex, cached.
//! - [`glossy_irradiance`]: the preview's light from glossy senders onto
//!   Lambertian parts, per corner, cached likewise.
//! - [`control`]: the solution as a control variate (lookups plus a
//!   path-traced residual): unbiased whatever the solution's error.
//! - [`solved`]: [`GatherScene`] and [`SolutionGather`] for trilux's
//!   geometry, BRDFs and a solution ([`SolvedScene`]).
//! - [`filter`]: reconstruction filters (Mitsuba's Gaussian, box, ...).
//! - [`film`]: splatting samples through the filter, per-pixel normalisation.
//! - `adaptive` (private): how many samples each pixel takes under
//!   adaptive sampling (allotted from the pilots of the other colour of a
//!   checkerboard, so that no pixel's count depends on its own samples).
//! - [`driver`]: tiles rendered in parallel (rayon), merged deterministically.
//! - [`image`]: the finished [`Image`], its EXR (ZIP) and PNG files (never
//!   with a non-finite pixel; written through `trilux-files`).
//! - [`analytic`]: analytic scenes with known answers (tests, benches).
//! - [`mod@compare`]: relative RMSE and mean ratio against a reference image.
//! - [`error`]: the error type, [`RenderError`].
#![forbid(unsafe_code)]

mod adaptive;
pub mod analytic;
pub mod camera;
pub mod compare;
pub mod control;
pub mod driver;
pub mod error;
pub mod film;
pub mod filter;
pub mod gather;
pub mod glossy_fit;
pub mod glossy_irradiance;
pub mod image;
pub mod link_gather;
pub mod link_sum;
pub mod mis;
pub mod preview;
pub mod records;
pub mod sampler;
pub mod scene;
pub mod solution;
pub mod solved;

pub use camera::{Camera, FovAxis, Ray};
pub use compare::{Comparison, compare};
pub use driver::{
    Estimator, RenderSettings, RenderStats, render, render_image, render_with_response,
};
pub use error::RenderError;
pub use film::Film;
pub use filter::ReconstructionFilter;
pub use gather::ExtraBounce;
pub use image::Image;
pub use mis::{power_heuristic, punctual_direct};
pub use records::{
    BsdfSample, FitKey, FitSite, GatherStats, LightSample, LinkVisibility, PunctualSample, SkyRay,
    SurfacePoint,
};
pub use sampler::PixelSampler;
pub use scene::{GatherScene, SolutionGather};
pub use solution::{DirectOnly, RadianceSolution};
pub use solved::SolvedScene;
