//! Golden images: trilux renders against Mitsuba 3 references.
//!
//! References live in `tests/golden/` (made by
//! `tests/golden/make_references.py`): `NAME.exr` (linear sRGB),
//! `NAME.mask.exr` (1 where an emitter is directly visible, dilated by 1 px)
//! and `NAME.json` (how it was made, its size and its own noise).
//!
//! Metrics: `trilux_render::compare` (relative RMSE `sqrt(Σ (a − r)² / Σ
//! r²)` and mean ratio `Σ a / Σ r` over unmasked pixels and the three
//! channels; both also over all pixels).
//!
//! Commands:
//! - `cargo xtask golden compare IMAGE.exr REFERENCE.exr [--mask MASK.exr]`
//!   prints the metrics of any two EXRs of the same size;
//! - `cargo xtask golden [--spp N] [--quality Q] [--gather G] [--only NAME]...` solves and
//!   renders every scene that has a reference, at the reference's size
//!   (in-process, with the library the `trilux` command uses) and at the
//!   scene's own render settings (its sampler's sample count unless
//!   `--spp`), and compares, failing above [`MAX_REL_RMSE`] or outside
//!   [`MAX_MEAN_BIAS`].

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use trilux::{Observer, Plan, RenderPlan, SolutionSource, ViewOverrides};
use trilux_render::{Comparison, Estimator, Image, RenderSettings, compare};
use trilux_solver::{Quality, SolverSettings};

/// Largest accepted relative RMSE (unmasked) of a trilux render at 64 spp
/// against its reference: the final gather's own noise at 64 spp and
/// 128×128 (1.4–1.9 % on the paper scenes, measured by `cargo xtask
/// sweep`), plus the references' noise (≤ 0.4 %), plus at most about 3 % of
/// solution bias.
pub const MAX_REL_RMSE: f64 = 0.05;
/// Largest accepted |mean ratio − 1| (unmasked): 1 %, the energy-bias bound.
pub const MAX_MEAN_BIAS: f64 = 0.01;

/// The repository root (xtask lives one level below it).
pub fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .map(Path::to_path_buf)
        .unwrap_or_else(|| PathBuf::from("."))
}

/// One stored reference.
#[derive(Clone, Debug)]
pub struct Reference {
    /// Scene name (file stem in scenes/).
    pub name: String,
    /// The reference image.
    pub image: Image,
    /// Its emitter mask, if stored.
    pub mask: Option<Image>,
    /// Its own estimated relative RMSE (from the sidecar JSON).
    pub noise: Option<f64>,
}

/// Every reference in tests/golden/ (optionally only those named).
pub fn references(only: &[String]) -> Result<Vec<Reference>> {
    let dir = root().join("tests/golden");
    let mut names: Vec<String> = std::fs::read_dir(&dir)
        .with_context(|| format!("reading {}", dir.display()))?
        .filter_map(|e| e.ok())
        .filter_map(|e| {
            let n = e.file_name().to_string_lossy().into_owned();
            n.strip_suffix(".json").map(str::to_owned)
        })
        .filter(|n| only.is_empty() || only.contains(n))
        .collect();
    names.sort();
    let mut out = Vec::new();
    for name in names {
        let image = Image::read_exr(&dir.join(format!("{name}.exr")))?;
        let mask_path = dir.join(format!("{name}.mask.exr"));
        let mask = if mask_path.exists() {
            Some(Image::read_exr(&mask_path)?)
        } else {
            None
        };
        let json: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(dir.join(format!("{name}.json")))?)
                .with_context(|| format!("parsing tests/golden/{name}.json"))?;
        let noise = json.get("noise_rel_rmse_unmasked").and_then(|v| v.as_f64());
        out.push(Reference {
            name,
            image,
            mask,
            noise,
        });
    }
    Ok(out)
}

/// What one trilux run of `scenes/NAME.xml` does, in-process through
/// `trilux::pipeline::run` (the same code the command runs).
pub struct TriluxSpec<'a> {
    /// Scene name (file stem in scenes/).
    pub name: &'a str,
    /// Film size (the reference's).
    pub size: (u32, u32),
    /// Quality preset of the solve.
    pub quality: Quality,
    /// Solve, or load a saved solution.
    pub source: SolutionSource<'a>,
    /// Save the solution there.
    pub save: Option<&'a Path>,
    /// Render with these changes to the scene's render settings (`None`:
    /// no render).
    pub render: Option<&'a dyn Fn(&mut RenderSettings)>,
}

/// What a trilux run gave.
pub struct TriluxRun {
    /// The rendered image (when the spec renders).
    pub image: Option<Image>,
    /// Seconds of preparing the scene plus solving or loading.
    pub solve_seconds: f64,
    /// Seconds of the render.
    pub render_seconds: f64,
    /// Convergence ratio reached.
    pub convergence_ratio: f64,
}

/// The scene file of a reference: `scenes/NAME.xml`, `.gltf` or `.glb`.
pub fn scene_path(name: &str) -> PathBuf {
    ["xml", "gltf", "glb"]
        .iter()
        .map(|ext| root().join(format!("scenes/{name}.{ext}")))
        .find(|p| p.exists())
        .unwrap_or_else(|| root().join(format!("scenes/{name}.xml")))
}

/// Runs `spec` (see [`TriluxSpec`]).
pub fn run_trilux(spec: &TriluxSpec<'_>) -> Result<TriluxRun> {
    let path = scene_path(spec.name);
    let scene = trilux_scene::load(&path).map_err(|e| anyhow::anyhow!("{e}"))?;
    let camera = scene.camera.as_ref().context("the scene has no camera")?;
    let render = spec.render.map(|tweak| {
        let mut settings = trilux::render_settings(camera);
        tweak(&mut settings);
        let view = ViewOverrides {
            width: Some(spec.size.0),
            height: Some(spec.size.1),
            ..Default::default()
        };
        RenderPlan { view, settings }
    });
    let plan = Plan {
        mode: scene.mode(),
        solver: SolverSettings::preset(spec.quality),
        source: spec.source,
        save: spec.save,
        solution_file: false,
        bake: None,
        render,
    };
    let outcome = Observer::quiet(|o| trilux::pipeline::run(&scene, &plan, o))?;
    Ok(TriluxRun {
        image: outcome.image,
        solve_seconds: outcome.prepare_seconds + outcome.solve_seconds,
        render_seconds: outcome.render_seconds,
        convergence_ratio: outcome.solve.convergence_ratio,
    })
}

/// An estimator by name.
pub fn estimator(name: &str) -> Result<Estimator> {
    Ok(match name {
        "links" => Estimator::Links,
        "paths" => Estimator::Paths,
        "preview" => Estimator::Preview,
        "control" => Estimator::Control,
        other => bail!("unknown estimator {other} (links, paths, preview, control)"),
    })
}

/// A quality preset by name.
pub fn quality(name: &str) -> Result<Quality> {
    Ok(match name {
        "draft" => Quality::Draft,
        "default" => Quality::Default,
        "high" => Quality::High,
        other => bail!("unknown quality {other}"),
    })
}

fn print(name: &str, c: &Comparison) {
    println!(
        "{name:<20} relRMSE {:.4} (all pixels {:.4})  mean ratio {:.4} (all pixels {:.4})  masked {}",
        c.rel_rmse, c.rel_rmse_all, c.mean_ratio, c.mean_ratio_all, c.masked
    );
}

/// `cargo xtask golden ...`
pub fn main(args: &[String]) -> Result<()> {
    if args.first().map(String::as_str) == Some("compare") {
        let [image, reference, rest @ ..] = &args[1..] else {
            bail!("usage: cargo xtask golden compare IMAGE.exr REFERENCE.exr [--mask MASK.exr]");
        };
        let mask = match rest {
            [flag, m] if flag == "--mask" => Some(Image::read_exr(Path::new(m))?),
            [] => None,
            _ => {
                bail!("usage: cargo xtask golden compare IMAGE.exr REFERENCE.exr [--mask MASK.exr]")
            }
        };
        let c = compare(
            &Image::read_exr(Path::new(image))?,
            &Image::read_exr(Path::new(reference))?,
            mask.as_ref(),
        )?;
        print(image, &c);
        return Ok(());
    }
    let mut spp = None;
    let mut gather = None;
    let mut quality_name = "default".to_string();
    let mut only = Vec::new();
    let mut solutions: Option<PathBuf> = None;
    let mut it = args.iter();
    while let Some(a) = it.next() {
        match a.as_str() {
            "--spp" => spp = Some(it.next().context("--spp needs a value")?.parse()?),
            "--quality" => quality_name = it.next().context("--quality needs a value")?.clone(),
            "--only" => only.push(it.next().context("--only needs a scene name")?.clone()),
            "--gather" => gather = Some(estimator(it.next().context("--gather needs a name")?)?),
            "--save-solutions" => {
                solutions = Some(PathBuf::from(
                    it.next().context("--save-solutions needs a folder")?,
                ))
            }
            other => bail!("unknown argument {other}"),
        }
    }
    if let Some(dir) = &solutions {
        std::fs::create_dir_all(dir)?;
    }
    let mut failed = Vec::new();
    for r in references(&only)? {
        let save = solutions
            .as_ref()
            .map(|d| d.join(format!("{}.sol", r.name)));
        let spec = TriluxSpec {
            name: &r.name,
            size: (r.image.width(), r.image.height()),
            quality: quality(&quality_name)?,
            source: SolutionSource::Solve,
            save: save.as_deref(),
            render: Some(&|s: &mut RenderSettings| {
                if let Some(spp) = spp {
                    s.spp = spp;
                }
                if let Some(g) = gather {
                    s.estimator = g;
                }
            }),
        };
        let run = run_trilux(&spec)?;
        let image = run.image.context("the run renders")?;
        let c = compare(&image, &r.image, r.mask.as_ref())?;
        print(&r.name, &c);
        println!(
            "{:<20} solve {:.2} s (CR {:.4}), render {:.2} s, reference noise {:?}",
            "", run.solve_seconds, run.convergence_ratio, run.render_seconds, r.noise
        );
        if c.rel_rmse > MAX_REL_RMSE || (c.mean_ratio - 1.0).abs() > MAX_MEAN_BIAS {
            failed.push(r.name.clone());
        }
    }
    if !failed.is_empty() {
        bail!(
            "golden images differ beyond relRMSE {MAX_REL_RMSE} or mean bias {MAX_MEAN_BIAS}: {}",
            failed.join(", ")
        );
    }
    Ok(())
}
