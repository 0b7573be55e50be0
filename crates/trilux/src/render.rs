//! `trilux render SCENE`: solve (or load a saved solve) and render a view by
//! final gathering.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use clap::{Args, ValueEnum};
use trilux::pipeline::RenderPlan;
use trilux::view::{ViewOverrides, apply_integrator, render_settings};
use trilux_render::{Estimator, ExtraBounce};

use crate::options::{
    LookAt, Product, SolveOptions, parse_exposure, parse_film_edge, parse_fov, parse_lookat,
    parse_spp, parse_target_error, parse_threads,
};
use crate::output::{
    DEFAULT_FOLDER, Format, Kind, Outputs, UsageError, default_output, named, stats_json,
};

/// Where the gather continues one bounce before reading the solution.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum ExtraBounceArg {
    /// At every hit: the solution's remaining bias is diluted by a bounce.
    Always,
    /// Only where its steps would show (close hits, narrow lobes, glossy or
    /// smooth-shaded hits): faster.
    Auto,
    /// Nowhere: the paper's §4.5.
    Never,
}

/// How a camera sample reads the solution.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum GatherArg {
    /// A light sample and a BSDF-sampled gather ray at the first hit, the
    /// solution read where the gather ray lands (paper §4.5).
    Paths,
    /// The solution's gather links re-evaluated at every pixel for
    /// Lambertian parts, sampled rays for glossy parts (docs/rendering.md).
    Links,
    /// The solution as a control variate: --lookups solution lookups at
    /// the first hit plus a path-traced residual; unbiased whatever the
    /// solution's error (docs/rendering.md).
    Control,
}

/// Arguments of `trilux render`.
#[derive(Debug, Args)]
pub struct RenderArgs {
    /// The scene file (Mitsuba 3 XML subset, or glTF 2.0: .gltf, .glb).
    pub scene: PathBuf,
    #[command(flatten)]
    pub params: crate::options::SceneParams,
    /// The glTF camera to render from (a camera's or its node's name;
    /// default: the first camera of the scene).
    #[arg(long)]
    pub camera: Option<String>,
    /// Output image, its format by its name: .exr (linear sRGB radiance) or
    /// .png (sRGB-encoded, --exposure); another name is refused. Default:
    /// out/<scene name>.exr unless --png names the image (the folder is
    /// made when missing).
    #[arg(short = 'o', long = "output")]
    pub output: Option<PathBuf>,
    /// Write an sRGB-encoded PNG (a .png name), besides -o's image or
    /// instead of the default EXR.
    #[arg(long)]
    pub png: Option<PathBuf>,
    /// The PNG's exposure in stops: values scaled by 2^stops before
    /// clamping to [0, 1] (the EXR keeps the radiance).
    #[arg(long, default_value_t = 0.0, value_parser = parse_exposure, allow_hyphen_values = true)]
    pub exposure: f64,
    /// Write solve and render statistics as JSON.
    #[arg(long)]
    pub stats: Option<PathBuf>,
    /// Camera samples per pixel (default: the scene sampler's sample_count).
    #[arg(long, value_parser = parse_spp)]
    pub spp: Option<u32>,
    /// Film width in pixels (default: the scene's; docs/limits.md).
    #[arg(long, value_parser = parse_film_edge)]
    pub width: Option<u32>,
    /// Film height in pixels (default: the scene's; docs/limits.md).
    #[arg(long, value_parser = parse_film_edge)]
    pub height: Option<u32>,
    /// Worker threads (default: all cores).
    #[arg(long, value_parser = parse_threads)]
    pub threads: Option<u32>,
    /// Seed of the sample sequences.
    #[arg(long, default_value_t = 0)]
    pub seed: u32,
    /// Render from a saved solution instead of solving (`trilux solve`; it
    /// must have been made with the same --quality, --convergence and
    /// --mode).
    #[arg(long)]
    pub solution: Option<PathBuf>,
    /// Another view: eye and target, optionally up (`ox,oy,oz,tx,ty,tz[,ux,uy,uz]`).
    #[arg(long, allow_hyphen_values = true, value_parser = parse_lookat)]
    pub lookat: Option<LookAt>,
    /// Field of view in degrees along the scene's fov_axis.
    #[arg(long, allow_hyphen_values = true, value_parser = parse_fov)]
    pub fov: Option<f64>,
    /// How a camera sample reads the solution [default: paths; control
    /// when the scene's integrator limits path length (max_depth), which
    /// only the control variate honours].
    #[arg(long, value_enum)]
    pub gather: Option<GatherArg>,
    /// A noise-free preview for walkthroughs: the solution with its links'
    /// own visibility, no random rays (one sample a pixel unless --spp).
    #[arg(long, conflicts_with_all = ["gather", "target_error"])]
    pub preview: bool,
    /// Adaptive sampling: samples go where the pilot saw noise, for about
    /// this RMS relative error a pixel (e.g. 0.02; docs/rendering.md);
    /// --spp is then the most a pixel takes (at least 4).
    #[arg(long, value_parser = parse_target_error)]
    pub target_error: Option<f64>,
    /// Where the path gather continues one bounce before reading the
    /// solution (--gather paths).
    #[arg(long, value_enum, default_value = "always")]
    pub extra_bounce: ExtraBounceArg,
    /// Solution lookups per camera sample of the control variate
    /// (--gather control), 1 to 32; 1 is a plain path tracer.
    #[arg(long, default_value_t = trilux_render::control::DEFAULT_LOOKUPS,
          value_parser = clap::value_parser!(u32).range(1..=i64::from(trilux_render::control::MAX_LOOKUPS)))]
    pub lookups: u32,
    #[command(flatten)]
    pub options: SolveOptions,
}

/// The images a render writes: the one `-o` names (its format by its
/// name), else `out/<scene>.exr` unless `--png` names one; and the PNG.
struct Images {
    /// `-o`'s image and its format, or the default EXR.
    image: Option<(PathBuf, Format)>,
    /// `--png`'s.
    png: Option<PathBuf>,
    /// True when `image` is the default (its folder `out/` made when
    /// missing).
    default: bool,
}

impl RenderArgs {
    /// The images asked for, each name checked against its format
    /// (`output::named`): a usage error before any file is read.
    fn images(&self) -> Result<Images, UsageError> {
        let png = match &self.png {
            Some(p) => {
                named(p, "--png", Kind::Png)?;
                Some(p.clone())
            }
            None => None,
        };
        let image = match &self.output {
            Some(p) => Some((p.clone(), named(p, "-o", Kind::Image)?)),
            None if png.is_none() => Some((default_output(&self.scene, "exr"), Format::Exr)),
            None => None,
        };
        Ok(Images {
            image,
            png,
            default: self.output.is_none() && self.png.is_none(),
        })
    }

    /// Every output planned (the default `out/` made when missing, only
    /// while planning and writing) and checked against the inputs, before
    /// any work: the image, then the PNG and the statistics when asked for.
    /// `in_out`: the outputs are in `out/`, which is made when missing
    /// (the default render's, `main.rs`).
    fn plan_outputs(&self, images: &Images, in_out: bool) -> Result<Outputs> {
        let mut outputs = Vec::new();
        outputs.extend(images.image.as_ref().map(|(p, _)| (p.as_path(), "image")));
        outputs.extend(images.png.as_deref().map(|p| (p, "PNG")));
        outputs.extend(self.stats.as_deref().map(|p| (p, "statistics")));
        let mut inputs = vec![self.scene.as_path()];
        inputs.extend(self.solution.as_deref());
        let folder = (images.default || in_out).then(|| Path::new(DEFAULT_FOLDER));
        Outputs::plan(&outputs, &inputs, folder)
    }

    /// Samples, seed, filter, estimator and extra-bounce rule of this
    /// render, and the warning when the estimator chosen cannot honour the
    /// scene's `max_depth` (`apply_integrator`).
    fn render_plan(
        &self,
        scene: &trilux_scene::Scene,
        camera: &trilux_scene::Camera,
    ) -> (RenderPlan, Option<String>) {
        let mut settings = render_settings(camera);
        settings.spp = self
            .spp
            .unwrap_or(if self.preview { 1 } else { settings.spp });
        settings.seed = self.seed;
        let chosen = match (self.preview, self.gather) {
            (true, _) => Some(Estimator::Preview),
            (false, Some(GatherArg::Links)) => Some(Estimator::Links),
            (false, Some(GatherArg::Paths)) => Some(Estimator::Paths),
            (false, Some(GatherArg::Control)) => Some(Estimator::Control),
            (false, None) => None,
        };
        let warning = apply_integrator(&mut settings, scene, chosen);
        settings.lookups = self.lookups;
        settings.target_error = self.target_error;
        settings.extra_bounce = match self.extra_bounce {
            ExtraBounceArg::Always => ExtraBounce::Always,
            ExtraBounceArg::Auto => ExtraBounce::Auto { close_factor: 1.0 },
            ExtraBounceArg::Never => ExtraBounce::Never,
        };
        let plan = RenderPlan {
            view: ViewOverrides {
                lookat: self.lookat,
                fov: self.fov,
                width: self.width,
                height: self.height,
            },
            settings,
        };
        (plan, warning)
    }
}

/// Runs `trilux render`.
pub fn run(args: &RenderArgs) -> Result<()> {
    run_into(args, false)
}

/// Runs `trilux render`; with `in_out` its outputs are named in `out/`,
/// made when missing as for a default output (the command without
/// arguments: `main.rs`).
pub fn run_into(args: &RenderArgs, in_out: bool) -> Result<()> {
    let images = args.images()?;
    crate::set_threads(args.threads);
    let outputs = args.plan_outputs(&images, in_out)?;
    let pending =
        trilux_scene::open_with_camera(&args.scene, args.camera.as_deref(), &args.params.define)?;
    outputs.check_inputs(&pending.input_files())?;
    let camera = pending.scene().camera.as_ref().with_context(|| {
        let what = if trilux_scene::gltf::is_gltf(&args.scene) {
            "perspective camera"
        } else {
            "<sensor>"
        };
        format!(
            "{}: the scene has no {what} to render from",
            args.scene.display()
        )
    })?;
    let (render, warning) = args.render_plan(pending.scene(), camera);
    if let Some(w) = warning {
        crate::streams::eprint_line(&format!("warning: {w}"));
    }
    let render = Product::Render(render);
    let plan = args
        .options
        .plan(pending.scene(), args.solution.as_deref(), render);
    let crate::plan::Finished {
        outcome,
        mut record,
    } = crate::plan::run_plan(pending, &plan, None)?;
    record.set("png_exposure", serde_json::json!(args.exposure));
    let image = outcome
        .image
        .as_ref()
        .context("the render produced no image")?;
    let mut files = Vec::new();
    match &images.image {
        Some((_, Format::Png)) => files.push(image.png_bytes(args.exposure)?),
        Some(_) => files.push(exr_with_record(image, &record)?),
        None => {}
    }
    if images.png.is_some() {
        files.push(image.png_bytes(args.exposure)?);
    }
    if args.stats.is_some() {
        let render = outcome.render.as_ref();
        files.push(stats_json(
            &outcome.solve,
            render,
            outcome.render_seconds,
            &record,
        )?);
    }
    outputs.write(&files)?;
    crate::warn(&outcome);
    outputs.report(None)
}

/// The EXR file of `image` with `record` in its header
/// (`Record::exr_attributes`).
fn exr_with_record(
    image: &trilux_render::Image,
    record: &crate::record::Record,
) -> Result<Vec<u8>> {
    let attributes = record.exr_attributes()?;
    let pairs: Vec<(&str, &str)> = attributes.iter().map(|(k, v)| (*k, v.as_str())).collect();
    Ok(image.exr_bytes_with(&pairs)?)
}
