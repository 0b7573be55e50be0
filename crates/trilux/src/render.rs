//! `trilux render SCENE`: solve (or load a saved solve) and render a view by
//! final gathering (design.md §3).

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result, bail};
use clap::Args;
use glam::DVec3;
use trilux_color::Mode;
use trilux_render::{Image, RenderSettings, ViewOverrides, render};
use trilux_scene::Scene;
use trilux_solver::{SceneInput, Solution, solve_hash};

use crate::solve::{SolveOptions, progress_bar, solve_with_progress, write_json};

/// Arguments of `trilux render`.
#[derive(Debug, Args)]
pub struct RenderArgs {
    /// The scene file (Mitsuba 3 XML subset).
    pub scene: PathBuf,
    /// Output EXR (linear sRGB). Default: out/<scene name>.exr.
    #[arg(short = 'o', long = "output")]
    pub output: Option<PathBuf>,
    /// Also write an sRGB-encoded PNG.
    #[arg(long)]
    pub png: Option<PathBuf>,
    /// Write solve and render statistics as JSON.
    #[arg(long)]
    pub stats: Option<PathBuf>,
    /// Camera samples per pixel (default: the scene sampler's sample_count).
    #[arg(long)]
    pub spp: Option<u32>,
    /// Film width in pixels (default: the scene's).
    #[arg(long)]
    pub width: Option<u32>,
    /// Film height in pixels (default: the scene's).
    #[arg(long)]
    pub height: Option<u32>,
    /// Worker threads (default: all cores).
    #[arg(long)]
    pub threads: Option<usize>,
    /// Seed of the sample sequences.
    #[arg(long, default_value_t = 0)]
    pub seed: u32,
    /// Render from a saved solution instead of solving (`trilux solve`).
    #[arg(long)]
    pub solution: Option<PathBuf>,
    /// Another view: eye and target, optionally up (`ox,oy,oz,tx,ty,tz[,ux,uy,uz]`).
    #[arg(long, allow_hyphen_values = true)]
    pub lookat: Option<String>,
    /// Field of view in degrees along the scene's fov_axis.
    #[arg(long, allow_hyphen_values = true)]
    pub fov: Option<f64>,
    /// Where the gather continues one bounce before reading the solution:
    /// at every hit (`always`, the default: the solution's remaining bias
    /// is diluted by a bounce), only where its steps would show (`auto`:
    /// close hits, narrow lobes, glossy or smooth-shaded hits; faster), or
    /// nowhere (`never`: the paper's §4.5).
    #[arg(long, value_parser = ["always", "auto", "never"], default_value = "always")]
    pub extra_bounce: String,
    #[command(flatten)]
    pub options: SolveOptions,
}

/// Parses `--lookat`.
fn parse_lookat(text: &str) -> Result<(DVec3, DVec3, Option<DVec3>)> {
    let values: Vec<f64> = text
        .split(',')
        .map(|v| v.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .with_context(|| format!("--lookat: '{text}' is not a comma-separated list of numbers"))?;
    if values.iter().any(|v| !v.is_finite()) {
        bail!("--lookat: values must be finite");
    }
    let v = |i: usize| DVec3::new(values[i], values[i + 1], values[i + 2]);
    match values.len() {
        6 => Ok((v(0), v(3), None)),
        9 => Ok((v(0), v(3), Some(v(6)))),
        n => bail!("--lookat takes 6 or 9 numbers (eye, target[, up]), got {n}"),
    }
}

/// The default output path for a scene: out/<stem>.exr.
pub fn default_output(scene: &Path) -> PathBuf {
    let stem = scene
        .file_stem()
        .map_or_else(|| "render".into(), |s| s.to_string_lossy().into_owned());
    PathBuf::from("out").join(format!("{stem}.exr"))
}

fn render_mode<const N: usize>(args: &RenderArgs, scene: &Scene, input: &SceneInput) -> Result<()> {
    let settings = args.options.settings()?;
    let solution: Solution<N> = match &args.solution {
        Some(path) => {
            let mut s = Solution::<N>::load(path, &input.as_input(), &settings)?;
            s.stats_mut().solve_seconds = 0.0;
            s
        }
        None => solve_with_progress::<N>(input, settings.clone())?,
    };
    let camera = scene.camera.as_ref().with_context(|| {
        format!(
            "{}: the scene has no <sensor> to render from",
            scene.path.display()
        )
    })?;
    let view = ViewOverrides {
        lookat: args.lookat.as_deref().map(parse_lookat).transpose()?,
        fov: args.fov,
        width: args.width,
        height: args.height,
    };
    if let Some(fov) = view.fov
        && !(fov.is_finite() && fov > 0.0 && fov < 180.0)
    {
        bail!("--fov must be in (0, 180) degrees, got {fov}");
    }
    let spp = args.spp.unwrap_or(camera.sample_count).max(1);
    let render_settings = RenderSettings {
        spp,
        seed: args.seed,
        filter: trilux_render::filter_of(camera),
        extra_bounce: match args.extra_bounce.as_str() {
            "auto" => trilux_render::ExtraBounce::Auto { close_factor: 1.0 },
            "never" => trilux_render::ExtraBounce::Never,
            _ => trilux_render::ExtraBounce::Always,
        },
        ..RenderSettings::default()
    };
    let output = args
        .output
        .clone()
        .unwrap_or_else(|| default_output(&args.scene));
    let start = Instant::now();
    let bar = progress_bar(1, "render");
    let (image, _stats) = render(scene, &solution, &view, &render_settings, |done, total| {
        if let Some(bar) = &bar {
            bar.set_length(total as u64);
            bar.set_position(done as u64);
            bar.set_message(format!("{done}/{total} tiles"));
        }
    })?;
    if let Some(bar) = bar {
        bar.finish_and_clear();
    }
    let render_seconds = start.elapsed().as_secs_f64();
    write_outputs(&image, &output, args.png.as_deref())?;
    if let Some(path) = &args.stats {
        write_json(path, &crate::stats_json(solution.stats(), render_seconds))?;
    }
    for w in &solution.stats().warnings {
        eprintln!("warning: {w}");
    }
    // Keep the hash in use so that a solution written by `solve` for this
    // scene is the one `--solution` accepts.
    let _ = solve_hash(&input.as_input(), &settings, N);
    Ok(())
}

/// Writes the EXR and, if asked, the PNG (exposure 0, clamped).
pub fn write_outputs(image: &Image, exr: &Path, png: Option<&Path>) -> Result<()> {
    image.write_exr(exr)?;
    if let Some(png) = png {
        image.write_png(png, 0.0)?;
    }
    Ok(())
}

/// Runs `trilux render`.
pub fn run(args: &RenderArgs) -> Result<()> {
    if let Some(n) = args.threads {
        if n == 0 {
            bail!("--threads must be at least 1");
        }
        // Fails only if a pool already exists, which cannot happen here.
        let _ = rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build_global();
    }
    let scene = trilux_scene::load(&args.scene)?;
    let input = SceneInput::from_scene(&scene);
    match args.options.mode(&scene) {
        Mode::Rgb => render_mode::<3>(args, &scene, &input),
        Mode::Spectral => render_mode::<{ trilux_color::SPECTRAL_BANDS }>(args, &scene, &input),
    }
}
