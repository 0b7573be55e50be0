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
use trilux_color::Spectrum;

use crate::adaptive::{PILOT_SPP, Pilot, allot};
use crate::camera::Camera;
use crate::control::{ControlVariate, DEFAULT_LOOKUPS, MAX_LOOKUPS};
use crate::error::RenderError;
use crate::film::Film;
use crate::filter::ReconstructionFilter;
use crate::gather::{ExtraBounce, FinalGather};
use crate::glossy_fit::GlossyFits;
use crate::glossy_irradiance::GlossyIrradiance;
use crate::image::Image;
use crate::link_gather::{Caches, LinkGather};
use crate::preview::Preview;
use crate::records::GatherStats;
use crate::sampler::{MAX_SAMPLES, PixelSampler, dims};
use crate::scene::SolutionGather;
use crate::solution::RadianceSolution;
use crate::solved::SolvedScene;

/// How a camera sample reads the solution.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[non_exhaustive]
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
    /// No random rays at the pixel: the links with their own visibility,
    /// and glossy parts read from the directional bake's representation
    /// fitted at element corners (`preview::Preview`, `glossy_fit`).
    Preview,
    /// The solution as a control variate: its lookups along
    /// [`RenderSettings::lookups`] gather rays plus a path-traced residual;
    /// unbiased whatever the solution's error (`control`).
    Control,
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
    /// Adaptive sampling: the predicted RMS relative error a pixel (against
    /// the larger of its mean and the image's) the samples are allotted
    /// for, in proportion to each pixel's noise (docs/rendering.md, "Adaptive sampling");
    /// `spp` stays the most a pixel takes (at least [`MIN_ADAPTIVE_SPP`]).
    /// `None`: every pixel takes `spp`.
    pub target_error: Option<f64>,
    /// Tile edge in pixels.
    pub tile_size: u32,
    /// Lookup rays per camera sample of the control variate
    /// ([`Estimator::Control`], `--lookups`).
    pub lookups: u32,
    /// Mitsuba's `max_depth`: light is counted over paths of at most this
    /// many segments from the eye (1: emitters seen directly, 2: direct
    /// light, …); `None`: every length. Only [`Estimator::Control`] can
    /// honour a limit (the solution the others read carries every bounce),
    /// so [`Self::validate`] refuses one with them.
    pub max_depth: Option<u32>,
    /// Mitsuba's `hide_emitters`: a camera ray that meets an emitting
    /// surface counts as a miss (black, as Mitsuba 3.9.1 renders it).
    pub hide_emitters: bool,
}

/// Samples every pixel takes under adaptive sampling: its pilot's, which
/// its render keeps.
pub const MIN_ADAPTIVE_SPP: u32 = PILOT_SPP;

impl Default for RenderSettings {
    fn default() -> Self {
        Self {
            spp: 64,
            seed: 0,
            filter: ReconstructionFilter::default(),
            estimator: Estimator::default(),
            extra_bounce: ExtraBounce::default(),
            target_error: None,
            tile_size: 16,
            lookups: DEFAULT_LOOKUPS,
            max_depth: None,
            hide_emitters: false,
        }
    }
}

/// What a render did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[non_exhaustive]
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
        if self.lookups == 0 || self.lookups > MAX_LOOKUPS {
            return Err(RenderError::Settings(format!(
                "lookups per sample {} must lie in 1..={MAX_LOOKUPS}",
                self.lookups
            )));
        }
        if let Some(depth) = self.max_depth
            && self.estimator != Estimator::Control
        {
            return Err(RenderError::Settings(format!(
                "max_depth {depth} is honoured by the control-variate estimator only: the solution the {:?} estimator reads carries light over paths of every length",
                self.estimator
            )));
        }
        if self.tile_size == 0 {
            return Err(RenderError::Settings("tile size must be at least 1".into()));
        }
        if let Some(t) = self.target_error {
            if !(t.is_finite() && t > 0.0) {
                return Err(RenderError::Settings(format!(
                    "target error {t} must be finite and positive"
                )));
            }
            if self.spp < MIN_ADAPTIVE_SPP {
                return Err(RenderError::Settings(format!(
                    "adaptive sampling (--target-error) needs at least {MIN_ADAPTIVE_SPP} samples per pixel (--spp), not {}",
                    self.spp
                )));
            }
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

/// The four estimators over one scene, chosen by the settings.
struct Estimators<'a, S> {
    estimator: Estimator,
    control: ControlVariate<'a, S>,
    paths: FinalGather<'a, S>,
    links: LinkGather<'a, S>,
    preview: Preview<'a, S>,
}

impl<'a, S> Estimators<'a, S> {
    fn new<const N: usize>(scene: &'a S, settings: &RenderSettings) -> Self
    where
        S: SolutionGather<N>,
    {
        let hide_emitters = settings.hide_emitters;
        let paths = || FinalGather {
            scene,
            extra: settings.extra_bounce,
            hide_emitters,
        };
        Estimators {
            estimator: settings.estimator,
            control: ControlVariate {
                scene,
                lookups: settings.lookups,
                max_depth: settings.max_depth,
                hide_emitters,
            },
            paths: paths(),
            links: LinkGather {
                scene,
                fallback: paths(),
                glossy_scene: scene.has_glossy_faces(),
            },
            preview: Preview {
                scene,
                hide_emitters,
                fits: GlossyFits::default(),
                glossy_senders: GlossyIrradiance::default(),
            },
        }
    }

    /// One camera sample through film position `film_pos`.
    fn sample<const N: usize>(
        &self,
        camera: &Camera,
        film_pos: DVec2,
        sampler: &PixelSampler,
        caches: &mut Caches<N>,
        stats: &mut GatherStats,
    ) -> Spectrum<N>
    where
        S: SolutionGather<N>,
    {
        let ray = camera.ray(film_pos);
        let (o, d) = (ray.origin, ray.dir);
        match self.estimator {
            Estimator::Links => self.links.camera_sample::<N>(o, d, sampler, caches, stats),
            Estimator::Paths => self.paths.camera_sample::<N>(o, d, sampler, stats),
            Estimator::Preview => self.preview.camera_sample::<N>(o, d, caches, stats),
            Estimator::Control => self.control.camera_sample::<N>(o, d, sampler, stats),
        }
    }
}

/// Renders `scene` through `camera`. `to_rgb` turns the N-band radiance of
/// one sample into linear sRGB (identity for N = 3); `progress(done, total)`
/// is called after each tile (from worker threads).
pub fn render_image<S, const N: usize>(
    scene: &S,
    camera: &Camera,
    settings: &RenderSettings,
    to_rgb: impl Fn(&Spectrum<N>) -> [f64; 3] + Sync,
    progress: impl Fn(usize, usize) + Sync,
) -> Result<(Image, RenderStats), RenderError>
where
    S: SolutionGather<N>,
{
    render_tiles(scene, camera, settings, to_rgb, progress, true)
}

/// [`render_image`]; with `keep_pilot` false an adaptive render takes its
/// pilot samples again instead of keeping them (the tests' reference).
fn render_tiles<S, const N: usize>(
    scene: &S,
    camera: &Camera,
    settings: &RenderSettings,
    to_rgb: impl Fn(&Spectrum<N>) -> [f64; 3] + Sync,
    progress: impl Fn(usize, usize) + Sync,
    keep_pilot: bool,
) -> Result<(Image, RenderStats), RenderError>
where
    S: SolutionGather<N>,
{
    settings.validate()?;
    // A sample border (Mitsuba's `sample_border`): render the image grown
    // by it on every side, keep the inner part; its edge pixels have what
    // the filter spread from the border's samples.
    let b = camera.sample_border();
    if b > 0 {
        let bordered = camera.bordered();
        let (image, stats) =
            render_tiles(scene, &bordered, settings, to_rgb, progress, keep_pilot)?;
        return Ok((image.window(b, b, camera.width(), camera.height()), stats));
    }
    let start = Instant::now();
    let (w, h) = (camera.width(), camera.height());
    let ts = settings.tile_size;
    let (tiles_x, tiles_y) = (w.div_ceil(ts), h.div_ceil(ts));
    let total = (tiles_x * tiles_y) as usize;
    let done = AtomicUsize::new(0);
    let estimators = Estimators::new::<N>(scene, settings);
    // Each dimension layout must fit the sequence (three gather levels and
    // the link gather's rays).
    const { assert!(dims::LINKS + 8 <= 256) };
    // The whole film first: a film too large for memory fails before work.
    let mut image = Film::new(0, 0, w as usize, h as usize, settings.filter)?;
    let mut stats = RenderStats::default();
    let job = TileJob {
        estimators: &estimators,
        camera,
        settings,
        counts: None,
        kept: None,
        to_rgb: &to_rgb,
    };
    // Adaptive: each pixel's samples, allotted from the pilot of the other
    // checkerboard colour, and the pilot's samples kept.
    let (counts, kept) = match settings.target_error {
        Some(target) => {
            let (counts, kept, s) = job.pilot(target)?;
            stats.gather.add(&s);
            (Some(counts), keep_pilot.then_some(kept))
        }
        None => (None, None),
    };
    let job = TileJob {
        counts: counts.as_deref(),
        kept: kept.as_deref(),
        ..job
    };
    let tiles: Vec<Result<(Film, GatherStats), RenderError>> = (0..total)
        .into_par_iter()
        .map(|t| {
            let tx = (t as u32 % tiles_x) * ts;
            let ty = (t as u32 / tiles_x) * ts;
            let tile = (tx, ty, ts.min(w - tx), ts.min(h - ty));
            let out = job.render(tile);
            progress(done.fetch_add(1, Ordering::Relaxed) + 1, total);
            out
        })
        .collect();
    for tile in tiles {
        let (film, s) = tile?;
        image.merge(&film);
        stats.gather.add(&s);
    }
    stats.seconds = start.elapsed().as_secs_f64();
    Ok((image.develop(), stats))
}

/// The luminance of linear sRGB ([`trilux_color::luminance`]), 0 for a
/// non-finite value: a dropped sample must not poison the running variance.
fn luminance(rgb: [f64; 3]) -> f64 {
    let y = trilux_color::luminance(rgb);
    if y.is_finite() { y } else { 0.0 }
}

/// A pilot sample kept for its pixel's render: where on the film it fell
/// (the offset within the pixel; exact in f32, as Sobol's values are) and
/// its linear sRGB value, so the render splats it instead of taking it
/// again.
#[derive(Clone, Copy, Debug, Default)]
struct KeptSample {
    offset: [f32; 2],
    rgb: [f64; 3],
}

/// One row of the adaptive pilot: each pixel's statistics, its
/// [`PILOT_SPP`] samples (pixel x's at x · [`PILOT_SPP`]..), the counters.
type PilotRow = (Vec<Pilot>, Vec<KeptSample>, GatherStats);

/// The whole adaptive pilot: each pixel's count, the kept samples a row
/// each, the counters.
type PilotPass = (Vec<u32>, Vec<Vec<KeptSample>>, GatherStats);

/// What rendering one tile (or the adaptive pilot) needs.
struct TileJob<'a, S, F> {
    estimators: &'a Estimators<'a, S>,
    camera: &'a Camera,
    settings: &'a RenderSettings,
    /// Samples of each pixel (row-major) when adaptive.
    counts: Option<&'a [u32]>,
    /// The pilot's samples, a row each, when adaptive (`None`: the render
    /// takes them again).
    kept: Option<&'a [Vec<KeptSample>]>,
    to_rgb: &'a F,
}

impl<S, F> TileJob<'_, S, F> {
    /// The tile (x, y, width, height) into its own film, with a border of
    /// the filter's radius.
    fn render<const N: usize>(
        &self,
        (tx, ty, tw, th): (u32, u32, u32, u32),
    ) -> Result<(Film, GatherStats), RenderError>
    where
        S: SolutionGather<N>,
        F: Fn(&Spectrum<N>) -> [f64; 3] + Sync,
    {
        let border = self.settings.filter.radius().ceil() as i64;
        let mut film = Film::new(
            tx as i64 - border,
            ty as i64 - border,
            (tw as i64 + 2 * border) as usize,
            (th as i64 + 2 * border) as usize,
            self.settings.filter,
        )?;
        let mut stats = GatherStats::default();
        let mut caches = Caches::<N>::default();
        let width = self.camera.width() as usize;
        for y in ty..ty + th {
            for x in tx..tx + tw {
                let n = self
                    .counts
                    .map_or(self.settings.spp, |c| c[y as usize * width + x as usize]);
                let start = x as usize * PILOT_SPP as usize;
                let kept = self
                    .kept
                    .map(|rows| &rows[y as usize][start..start + PILOT_SPP as usize]);
                self.pixel(x, y, (n, kept), &mut film, &mut caches, &mut stats);
            }
        }
        Ok((film, stats))
    }

    /// Samples 0..n of pixel (x, y) into the film, each weighted 1/n when
    /// adaptive (so its neighbours see it as one unit of weight); the first
    /// ones from `kept` (the pilot's) when given, the rest taken.
    fn pixel<const N: usize>(
        &self,
        x: u32,
        y: u32,
        (n, kept): (u32, Option<&[KeptSample]>),
        film: &mut Film,
        caches: &mut Caches<N>,
        stats: &mut GatherStats,
    ) where
        S: SolutionGather<N>,
        F: Fn(&Spectrum<N>) -> [f64; 3] + Sync,
    {
        caches.pixel.clear();
        caches.scratch.clear();
        let weight = if self.counts.is_some() {
            1.0 / f64::from(n)
        } else {
            1.0
        };
        let mut splat = |film_pos: DVec2, rgb: [f64; 3], stats: &mut GatherStats| {
            if rgb.iter().all(|v| v.is_finite()) {
                film.splat_weighted(film_pos.x, film_pos.y, rgb, weight);
            } else {
                stats.dropped += 1;
            }
        };
        let kept = kept.unwrap_or_default();
        for s in kept {
            let offset = DVec2::new(f64::from(s.offset[0]), f64::from(s.offset[1]));
            splat(DVec2::new(x as f64, y as f64) + offset, s.rgb, stats);
        }
        let mut sampler = PixelSampler::new(self.settings.seed, x, y);
        for k in kept.len() as u32..n {
            let (film_pos, rgb) = self.sample(x, y, k, &mut sampler, caches, stats);
            splat(film_pos, rgb, stats);
        }
    }

    /// Camera sample `k` of pixel (x, y) from `sampler`: its film position
    /// and linear sRGB value.
    fn sample<const N: usize>(
        &self,
        x: u32,
        y: u32,
        k: u32,
        sampler: &mut PixelSampler,
        caches: &mut Caches<N>,
        stats: &mut GatherStats,
    ) -> (DVec2, [f64; 3])
    where
        S: SolutionGather<N>,
        F: Fn(&Spectrum<N>) -> [f64; 3] + Sync,
    {
        sampler.start_sample(k);
        let film_pos = DVec2::new(x as f64, y as f64) + sampler.get2(dims::FILM);
        let l = self
            .estimators
            .sample(self.camera, film_pos, sampler, caches, stats);
        (film_pos, (self.to_rgb)(&l))
    }

    /// The adaptive pilot: each pixel's count for `target`, the pilot's
    /// samples a row each, and the pilot's counters (rows collected in
    /// order: the same whatever the number of threads).
    fn pilot<const N: usize>(&self, target: f64) -> Result<PilotPass, RenderError>
    where
        S: SolutionGather<N>,
        F: Fn(&Spectrum<N>) -> [f64; 3] + Sync,
    {
        let (w, h) = (self.camera.width(), self.camera.height());
        let rows: Vec<_> = (0..h).into_par_iter().map(|y| self.pilot_row(y)).collect();
        let mut pilots = Vec::with_capacity(w as usize * h as usize);
        let mut kept = Vec::with_capacity(h as usize);
        let mut stats = GatherStats::default();
        for row in rows {
            let (row, samples, s) = row?;
            pilots.extend(row);
            kept.push(samples);
            stats.add(&s);
        }
        let counts = allot(&pilots, w as usize, target, self.settings.spp);
        Ok((counts, kept, stats))
    }

    /// The adaptive pilot of row `y`: the luminance statistics of the first
    /// [`PILOT_SPP`] samples of each pixel, and the samples, kept; an error,
    /// not an abort, when their memory cannot be had.
    fn pilot_row<const N: usize>(&self, y: u32) -> Result<PilotRow, RenderError>
    where
        S: SolutionGather<N>,
        F: Fn(&Spectrum<N>) -> [f64; 3] + Sync,
    {
        let mut caches = Caches::<N>::default();
        let mut stats = GatherStats::default();
        let width = self.camera.width();
        let mut row = Vec::with_capacity(width as usize);
        let mut kept = Vec::new();
        kept.try_reserve_exact(width as usize * PILOT_SPP as usize)
            .map_err(|_| {
                RenderError::Settings(format!(
                    "not enough memory for the adaptive pilot of a {width} × {} film (docs/limits.md)",
                    self.camera.height()
                ))
            })?;
        for x in 0..width {
            caches.pixel.clear();
            caches.scratch.clear();
            let mut sampler = PixelSampler::new(self.settings.seed, x, y);
            // Welford's running mean and variance of the luminance.
            let (mut mean, mut m2) = (0.0f64, 0.0f64);
            for k in 0..PILOT_SPP {
                let (_, rgb) = self.sample(x, y, k, &mut sampler, &mut caches, &mut stats);
                // The film offset again (`sample` drew it): f64 of an f32.
                let offset = sampler.get2(dims::FILM);
                kept.push(KeptSample {
                    offset: [offset.x as f32, offset.y as f32],
                    rgb,
                });
                let y_l = luminance(rgb);
                let delta = y_l - mean;
                mean += delta / f64::from(k + 1);
                m2 += delta * (y_l - mean);
            }
            row.push(Pilot {
                mean: mean as f32,
                var: (m2 / f64::from(PILOT_SPP - 1)) as f32,
            });
        }
        Ok((row, kept, stats))
    }
}

/// Renders the scene of `solution` through `camera` with `settings`.
/// Spectral solutions (N ≠ 3) are converted per sample to linear sRGB
/// through CIE XYZ.
pub fn render<const N: usize, S: RadianceSolution<N>>(
    solution: &S,
    camera: &Camera,
    settings: &RenderSettings,
    progress: impl Fn(usize, usize) + Sync,
) -> Result<(Image, RenderStats), RenderError> {
    let solved = SolvedScene::new(solution);
    render_image::<_, N>(&solved, camera, settings, |l| l.to_linear_srgb(), progress)
}

/// [`render`] through a sensor with a spectral `response` (per band, Mitsuba's
/// `srf`): each sample's radiance is multiplied by it before the CIE
/// observer turns it into colour, so the image is ∫ L srf x̄ȳz̄ dλ in
/// linear sRGB.
pub fn render_with_response<const N: usize, S: RadianceSolution<N>>(
    solution: &S,
    camera: &Camera,
    settings: &RenderSettings,
    response: Spectrum<N>,
    progress: impl Fn(usize, usize) + Sync,
) -> Result<(Image, RenderStats), RenderError> {
    let solved = SolvedScene::new(solution);
    let seen = |l: &Spectrum<N>| (*l * response).to_linear_srgb();
    render_image::<_, N>(&solved, camera, settings, seen, progress)
}

#[cfg(test)]
mod tests {
    use glam::DVec3;

    use super::*;
    use crate::analytic::LitFloor;
    use crate::camera::{FovAxis, look_at};

    #[test]
    fn the_kept_pilot_is_the_pilot_taken_again() {
        // A floor under a square lamp, the lamp in view: the counts vary.
        // Keeping the pilot's samples must give the image of taking them
        // again (same samples, same weights, same order) with PILOT_SPP
        // fewer camera samples a pixel.
        let scene = LitFloor {
            rho: 0.8,
            s: 0.5,
            h: 1.0,
            le: 5.0,
        };
        let m = look_at(
            DVec3::new(-2.5, -2.5, 0.5),
            DVec3::new(0.0, 0.0, 0.6),
            DVec3::Z,
        )
        .unwrap();
        let (w, h) = (20u32, 14u32);
        let camera = Camera::new(m, 60.0, FovAxis::X, w, h).unwrap();
        let settings = RenderSettings {
            spp: 64,
            target_error: Some(0.05),
            tile_size: 6,
            ..Default::default()
        };
        let run = |keep| {
            render_tiles::<_, 3>(&scene, &camera, &settings, |l| l.0, |_, _| {}, keep).unwrap()
        };
        let (kept, kept_stats) = run(true);
        let (again, again_stats) = run(false);
        let pixels = u64::from(w * h);
        let (k, a) = (
            kept_stats.gather.camera_rays,
            again_stats.gather.camera_rays,
        );
        assert_eq!(a - k, u64::from(PILOT_SPP) * pixels);
        // The counts adapted: between the pilot's and the cap.
        assert!(k > 2 * pixels && k < (64 - 4) * pixels, "{k} samples");
        assert_eq!(kept_stats.gather.dropped, again_stats.gather.dropped);
        let lit = kept.pixels().iter().filter(|p| p[0] > 0.01).count();
        assert!(lit > 20, "{lit} lit pixels");
        for (i, (p, q)) in kept.pixels().iter().zip(again.pixels()).enumerate() {
            for c in 0..3 {
                let tol = 1e-6 * p[c].abs().max(q[c].abs()) + 1e-9;
                assert!((p[c] - q[c]).abs() <= tol, "pixel {i}: {p:?} vs {q:?}");
            }
        }
    }
}
