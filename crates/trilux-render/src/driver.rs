//! The render driver: tiles in parallel, merged deterministically.
//!
//! The film is cut into square tiles. rayon renders the tiles in any order
//! on any thread, each into its own [`Film`] with a border of the filter's
//! radius; the tiles are then merged into the image in tile order. Every
//! camera sample depends only on (seed, pixel, sample index), so the image is
//! the same bit for bit for a given seed, whatever the number of threads.

use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

use glam::DVec2;
use rayon::prelude::*;

use crate::camera::Camera;
use crate::error::RenderError;
use crate::film::Film;
use crate::filter::ReconstructionFilter;
use crate::gather::{ExtraBounce, FinalGather, GatherScene, GatherStats};
use crate::image::Image;
use crate::link_gather::{Caches, LinkGather, Preview};
use crate::sampler::{MAX_SAMPLES, PixelSampler, dims};

/// How a camera sample reads the solution.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Estimator {
    /// The solution's gather links at the primary hit (Lambertian parts
    /// without Monte Carlo noise but in penumbrae), a gather ray for glossy
    /// parts (`link_gather`).
    Links,
    /// The path gather of paper §4.5: a light sample and a BSDF-sampled
    /// gather ray at the primary hit, the solution read at the gather hit
    /// (or one bounce later, by the extra-bounce rule). The default.
    #[default]
    Paths,
    /// No random rays: the links with their own visibility, one mirror
    /// reading for glossy parts (`link_gather::Preview`).
    Preview,
}

/// How to render.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RenderSettings {
    /// Camera samples per pixel; each traces one light sample and one gather
    /// ray at the first hit (`--spp`).
    pub spp: u32,
    /// Seed of the sample sequences.
    pub seed: u32,
    /// Reconstruction filter (Mitsuba's Gaussian by default).
    pub filter: ReconstructionFilter,
    /// How a camera sample reads the solution.
    pub estimator: Estimator,
    /// When the path gather continues one bounce ([`ExtraBounce`]).
    pub extra_bounce: ExtraBounce,
    /// Tile edge in pixels.
    pub tile_size: u32,
}

impl Default for RenderSettings {
    fn default() -> Self {
        Self {
            spp: 64,
            seed: 0,
            filter: ReconstructionFilter::default(),
            estimator: Estimator::default(),
            extra_bounce: ExtraBounce::default(),
            tile_size: 16,
        }
    }
}

/// What a render did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RenderStats {
    /// Ray and sample counters.
    pub gather: GatherStats,
    /// Wall-clock seconds of the render.
    pub seconds: f64,
}

impl RenderSettings {
    /// Checks the ranges of the settings.
    pub fn validate(&self) -> Result<(), RenderError> {
        if self.spp == 0 || self.spp > MAX_SAMPLES {
            return Err(RenderError::Settings(format!(
                "samples per pixel {} must lie in 1..={MAX_SAMPLES}",
                self.spp
            )));
        }
        if self.tile_size == 0 {
            return Err(RenderError::Settings("tile size must be at least 1".into()));
        }
        if let ExtraBounce::Auto { close_factor } = self.extra_bounce
            && !(close_factor.is_finite() && close_factor >= 0.0)
        {
            return Err(RenderError::Settings(format!(
                "extra-bounce distance factor {close_factor} must be finite and ≥ 0"
            )));
        }
        Ok(())
    }
}

/// Renders `scene` through `camera`. `to_rgb` turns the N-band radiance of
/// one sample into linear sRGB (identity for N = 3); `progress(done, total)`
/// is called after each tile (from worker threads).
pub fn render_image<S, const N: usize>(
    scene: &S,
    camera: &Camera,
    settings: &RenderSettings,
    to_rgb: impl Fn(&[f64; N]) -> [f64; 3] + Sync,
    progress: impl Fn(usize, usize) + Sync,
) -> Result<(Image, RenderStats), RenderError>
where
    S: GatherScene<N>,
{
    settings.validate()?;
    let start = Instant::now();
    let (w, h) = (camera.width(), camera.height());
    let ts = settings.tile_size;
    let tiles_x = w.div_ceil(ts);
    let tiles_y = h.div_ceil(ts);
    let total = (tiles_x * tiles_y) as usize;
    let border = settings.filter.radius().ceil() as i64;
    let done = AtomicUsize::new(0);
    let paths = FinalGather {
        scene,
        extra: settings.extra_bounce,
    };
    let links = LinkGather {
        scene,
        fallback: FinalGather {
            scene,
            extra: settings.extra_bounce,
        },
        glossy_scene: scene.has_glossy_faces(),
    };
    let preview = Preview { scene };
    let sample = |origin,
                  dir,
                  sampler: &PixelSampler,
                  caches: &mut Caches<N>,
                  stats: &mut GatherStats|
     -> [f64; N] {
        match settings.estimator {
            Estimator::Links => links.camera_sample::<N>(origin, dir, sampler, caches, stats),
            Estimator::Paths => paths.camera_sample::<N>(origin, dir, sampler, stats),
            Estimator::Preview => preview.camera_sample::<N>(origin, dir, caches, stats),
        }
    };
    // Each dimension layout must fit the sequence (three gather levels and
    // the link gather's rays).
    const { assert!(dims::LINKS + 8 <= 256) };
    // The whole film first: a film too large for memory fails before work.
    let mut image = Film::new(0, 0, w as usize, h as usize, settings.filter)?;

    let tiles: Vec<Result<(Film, GatherStats), RenderError>> = (0..total)
        .into_par_iter()
        .map(|t| {
            let tx = (t as u32 % tiles_x) * ts;
            let ty = (t as u32 / tiles_x) * ts;
            let tw = ts.min(w - tx);
            let th = ts.min(h - ty);
            let mut film = Film::new(
                tx as i64 - border,
                ty as i64 - border,
                (tw as i64 + 2 * border) as usize,
                (th as i64 + 2 * border) as usize,
                settings.filter,
            )?;
            let mut stats = GatherStats::default();
            let mut caches = Caches::<N>::default();
            for y in ty..ty + th {
                for x in tx..tx + tw {
                    caches.pixel.clear();
                    let mut sampler = PixelSampler::new(settings.seed, x, y);
                    for s in 0..settings.spp {
                        sampler.start_sample(s);
                        let film_pos = DVec2::new(x as f64, y as f64) + sampler.get2(dims::FILM);
                        let ray = camera.ray(film_pos);
                        let l = sample(ray.origin, ray.dir, &sampler, &mut caches, &mut stats);
                        let rgb = to_rgb(&l);
                        if rgb.iter().all(|v| v.is_finite()) {
                            film.splat(film_pos.x, film_pos.y, rgb);
                        } else {
                            stats.dropped += 1;
                        }
                    }
                }
            }
            progress(done.fetch_add(1, Ordering::Relaxed) + 1, total);
            Ok((film, stats))
        })
        .collect();

    let mut stats = RenderStats::default();
    for tile in tiles {
        let (film, s) = tile?;
        image.merge(&film);
        stats.gather.add(&s);
    }
    stats.seconds = start.elapsed().as_secs_f64();
    Ok((image.develop(), stats))
}

/// Renders the scene of `solution` through `camera` with `settings`.
/// Spectral solutions (N ≠ 3) are converted per sample to linear sRGB
/// through CIE XYZ.
pub fn render<const N: usize, S: crate::solved::RadianceSolution<N>>(
    solution: &S,
    camera: &Camera,
    settings: &RenderSettings,
    progress: impl Fn(usize, usize) + Sync,
) -> Result<(Image, RenderStats), RenderError> {
    let solved = crate::solved::SolvedScene::new(solution);
    render_image::<_, N>(
        &solved,
        camera,
        settings,
        |l| trilux_color::Spectrum::<N>(*l).to_linear_srgb(),
        progress,
    )
}
