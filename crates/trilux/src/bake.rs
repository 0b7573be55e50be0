//! `trilux bake SCENE [-o OUT.glb] [--no-glossy] [--open]`: the solution's view-independent
//! light as a glTF 2.0 binary, for walkthroughs in any glTF viewer
//! (docs/bake.md; the file's layout is `trilux_bake`'s), and with `--open`
//! in trilux's own viewer on localhost (`serve`).

use std::path::{Path, PathBuf};

use crate::options::{Product, SolveOptions, parse_exposure, parse_threads};
use crate::output::{DEFAULT_FOLDER, Kind, Outputs, bake_stats_json, default_output, named};
use anyhow::{Context, Result};
use clap::Args;
use trilux_bake::{BakeOptions, DiffuseLight};

/// Arguments of `trilux bake`.
#[derive(Debug, Args)]
pub struct BakeArgs {
    /// The scene file (Mitsuba 3 XML subset, or glTF 2.0: .gltf, .glb).
    pub scene: PathBuf,
    #[command(flatten)]
    pub params: crate::options::SceneParams,
    /// Where to write the baked scene (a .glb name). Default:
    /// out/<scene name>.glb (the folder is made when missing).
    #[arg(short = 'o', long = "output")]
    pub output: Option<PathBuf>,
    /// Bake a saved solution instead of solving (`trilux solve`; it must
    /// have been made with the same --quality, --convergence and --mode).
    #[arg(long)]
    pub solution: Option<PathBuf>,
    /// COLOR_0's exposure in stops: radiance × 2^stops, clamped to [0, 1]
    /// (the _RADIANCE attribute keeps the radiance).
    #[arg(long, default_value_t = 0.0, value_parser = parse_exposure, allow_hyphen_values = true)]
    pub exposure: f64,
    /// Bake textured materials into the vertex colours too, instead of an
    /// albedo map times the light (smaller files; texture detail finer than
    /// the elements is lost).
    #[arg(long)]
    pub no_albedo_maps: bool,
    /// Bake the glossy (view-dependent) light of glossy materials too, as
    /// spherical harmonics per vertex that trilux's viewer shows
    /// (docs/bake.md). The default; kept for scripts that ask for it.
    #[arg(long, conflicts_with = "no_glossy")]
    pub glossy: bool,
    /// Leave the glossy light out (the materials marked glossy_left_out;
    /// a faster bake and a smaller file).
    #[arg(long)]
    pub no_glossy: bool,
    /// Directions per vertex the glossy light is fitted over (at least 16).
    #[arg(long, default_value_t = BakeOptions::default().glossy_directions)]
    pub glossy_directions: u32,
    /// BSDF-sampled gather rays per vertex for the glossy light, shared by
    /// its directions.
    #[arg(long, default_value_t = BakeOptions::default().glossy_samples)]
    pub glossy_samples: u32,
    /// Light samples per vertex for the glossy light, shared by its
    /// directions.
    #[arg(long, default_value_t = BakeOptions::default().glossy_light_samples)]
    pub glossy_light_samples: u32,
    /// Read the glossy light's gather hits through their links, as the
    /// full render does (slower), instead of the solution's radiance there.
    #[arg(long)]
    pub glossy_links: bool,
    /// Show the diffuse light the renderer reads at each vertex (as
    /// `trilux render --preview` does) instead of each leaf element's
    /// constant light averaged at the vertices (docs/bake.md, "What is
    /// baked"); slower, and the file no longer holds the solution's flux.
    #[arg(long)]
    pub gathered_light: bool,
    /// Write solve and bake statistics (file size, vertices, triangles) as
    /// JSON.
    #[arg(long)]
    pub stats: Option<PathBuf>,
    /// Then serve the viewer (docs/viewer, built into trilux) with the
    /// bake on 127.0.0.1, print its address and open it in the system
    /// browser ($BROWSER, else xdg-open); runs until stopped.
    #[arg(long)]
    pub open: bool,
    /// The port for --open (default: any free one).
    #[arg(long, requires = "open")]
    pub port: Option<u16>,
    /// Worker threads (default: all cores).
    #[arg(long, value_parser = parse_threads)]
    pub threads: Option<u32>,
    #[command(flatten)]
    pub options: SolveOptions,
}

/// Runs `trilux bake`.
pub fn run(args: &BakeArgs) -> Result<()> {
    let output = match &args.output {
        Some(path) => {
            named(path, "-o", Kind::Bake)?;
            path.clone()
        }
        None => default_output(&args.scene, "glb"),
    };
    crate::set_threads(args.threads);
    let mut outputs = vec![(output.as_path(), "baked scene")];
    outputs.extend(args.stats.as_deref().map(|p| (p, "statistics")));
    let mut inputs = vec![args.scene.as_path()];
    inputs.extend(args.solution.as_deref());
    let folder = args.output.is_none().then(|| Path::new(DEFAULT_FOLDER));
    let outputs = Outputs::plan(&outputs, &inputs, folder)?;
    // The viewer's port is taken before any work: one in use is refused now.
    let listener = args
        .open
        .then(|| crate::serve::listen(args.port.unwrap_or(0)))
        .transpose()?;
    let pending = trilux_scene::open_with_params(&args.scene, &args.params.define)?;
    outputs.check_inputs(&pending.input_files())?;
    let mut options = BakeOptions::default();
    options.exposure = args.exposure;
    options.albedo_maps = !args.no_albedo_maps;
    options.glossy = !args.no_glossy;
    options.glossy_directions = args.glossy_directions;
    options.glossy_samples = args.glossy_samples;
    options.glossy_light_samples = args.glossy_light_samples;
    options.glossy_links = args.glossy_links;
    if args.gathered_light {
        options.diffuse = DiffuseLight::Gathered;
    }
    let bake = Product::Bake(options);
    let plan = args
        .options
        .plan(pending.scene(), args.solution.as_deref(), bake);
    let crate::plan::Finished {
        mut outcome,
        record,
    } = crate::plan::run_plan(pending, &plan, None)?;
    let baked = outcome.baked.take().context("the bake produced no file")?;
    let mut files = vec![baked.glb.clone()];
    if args.stats.is_some() {
        files.push(bake_stats_json(&outcome.solve, &baked.stats, &record)?);
    }
    outputs.write(&files)?;
    crate::warn(&outcome);
    let s = &baked.stats;
    outputs.report(Some(&format!(
        "{} bytes: {} vertices, {} triangles; baked in {:.2} s",
        s.bytes, s.vertices, s.triangles, s.seconds
    )))?;
    if let Some(listener) = listener {
        crate::serve::serve(listener, &baked.glb, true)?;
    }
    Ok(())
}
