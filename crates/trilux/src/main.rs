//! The `trilux` command: solve, render and inspect scenes (design.md §3).
//!
//! Runtime errors print one line `error: ...` on stderr and exit with status
//! 1; command-line usage errors keep clap's message and exit with status 2.
//! Subcommands live one per module; `render` and `solve` join `info` here
//! as variants of [`Command`]. Number-list options whose values may begin
//! with '-' (`--lookat -0.5,1,2,...`) need `#[arg(allow_hyphen_values =
//! true)]` on the argument (`allow_negative_numbers` only covers plain
//! numbers, not comma lists).

mod info;
mod power;
mod render;
mod solve;

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand, ValueEnum};

/// Progressive hierarchical three-point light transport.
#[derive(Debug, Parser)]
#[command(name = "trilux", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Print what a scene file loads to: shapes, input surfaces, materials,
    /// emitters, camera.
    Info(info::InfoArgs),
    /// Solve the light of a scene once and save the solution.
    Solve(solve::SolveArgs),
    /// Render a view of a scene by final gathering (solving first, or from
    /// a saved solution).
    Render(render::RenderArgs),
}

/// How light is carried: 3 RGB bands or spectral bands.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum ModeArg {
    /// Linear sRGB, 3 bands.
    Rgb,
    /// Spectral bands (10 by default).
    Spectral,
}

/// The bundled default scene (the Cornell box): `scenes/cornell-box.xml`
/// below the current folder, else in the source tree this binary was built
/// from.
pub fn default_scene() -> PathBuf {
    let local = PathBuf::from("scenes/cornell-box.xml");
    if local.exists() {
        return local;
    }
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenes/cornell-box.xml")
}

/// The statistics JSON of design.md §3: the solver's figures plus the
/// render time.
pub fn stats_json(stats: &trilux_solver::SolveStats, render_seconds: f64) -> serde_json::Value {
    let mut value = serde_json::to_value(stats).unwrap_or(serde_json::Value::Null);
    if let Some(map) = value.as_object_mut() {
        map.insert("render_seconds".into(), serde_json::json!(render_seconds));
    }
    value
}

fn run(cli: Cli) -> anyhow::Result<()> {
    match cli.command {
        Some(Command::Info(args)) => info::run(&args),
        Some(Command::Solve(args)) => solve::run(&args),
        Some(Command::Render(args)) => render::run(&args),
        // The main job: render the bundled default scene into out/.
        None => {
            let scene = default_scene();
            std::fs::create_dir_all("out")
                .map_err(|e| anyhow::anyhow!("out: cannot create the folder: {e}"))?;
            let exr = render::default_output(&scene);
            let png = exr.with_extension("png");
            let args = render::RenderArgs {
                scene,
                output: Some(exr.clone()),
                png: Some(png.clone()),
                stats: Some(exr.with_extension("json")),
                spp: None,
                width: None,
                height: None,
                threads: None,
                seed: 0,
                solution: None,
                lookat: None,
                fov: None,
                extra_bounce: "always".into(),
                options: solve::SolveOptions {
                    quality: "default".into(),
                    convergence: None,
                    mode: None,
                },
            };
            render::run(&args)?;
            println!("wrote {} and {}", exr.display(), png.display());
            Ok(())
        }
    }
}

fn main() -> ExitCode {
    // Usage errors exit here with clap's message and status 2.
    let cli = Cli::parse();
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            let message = e.to_string().replace(['\n', '\r'], " ");
            eprintln!("error: {message}");
            ExitCode::FAILURE
        }
    }
}
