//! The `trilux` command: solve, render and inspect scenes.
//!
//! Runtime errors print one line `error: ...` on stderr (one a line for
//! a scene file's independent errors) and exit with status 1;
//! command-line usage errors (unknown options, malformed values) keep
//! clap's message and exit with status 2, before any file is read, and so
//! does an output named for a format trilux does not write (one line,
//! `output::named`). Each file written is reported as `wrote PATH`.
//! Subcommands live one per module; the work itself is
//! the library's (`trilux::pipeline`). Every output is planned before any work and
//! written all or none at the end (`output`); the scene's meshes are read
//! only once the camera and options are checked (`trilux_scene::open`). Number-list options whose values may begin
//! with '-' (`--lookat -0.5,1,2,...`) need `#[arg(allow_hyphen_values =
//! true)]` on the argument (`allow_negative_numbers` only covers plain
//! numbers, not comma lists). Standard streams are written through
//! `streams`, never `println!`: a closed pipe or a full disk on stdout or
//! stderr is handled, not a panic.

mod bake;
mod info;
mod interrupt;
mod options;
mod output;
mod plan;
mod power;
mod progress;
mod record;
mod render;
mod serve;
mod solve;
mod streams;
mod viewer;

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};

/// Progressive hierarchical three-point light transport.
///
/// With no command, renders the bundled Cornell box (scenes/cornell-box.xml)
/// into out/cornell-box.exr, .png and .json; without -o, `trilux render`
/// writes out/<scene name>.exr (unless --png names its image), `solve`
/// out/<scene name>.sol and `bake` out/<scene name>.glb.
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
    Render(Box<render::RenderArgs>),
    /// Bake the solution's view-independent light into a glTF binary
    /// (.glb) for walkthroughs in any glTF viewer.
    Bake(bake::BakeArgs),
    /// Serve an existing bake (.glb) in trilux's viewer on localhost,
    /// without solving again.
    View(viewer::ViewArgs),
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

/// Sets the size of rayon's global pool (once, before any parallel work).
pub fn set_threads(threads: Option<u32>) {
    if let Some(n) = threads {
        // Fails only if a pool already exists, which cannot happen here.
        let _ = rayon::ThreadPoolBuilder::new()
            .num_threads(n as usize)
            .build_global();
    }
}

/// Prints the warnings of a finished command: the solve's (caps reached,
/// clamped reflectances) and the render's samples left out.
pub fn warn(outcome: &trilux::Outcome) {
    for w in &outcome.solve.warnings {
        streams::eprint_line(&format!("warning: {w}"));
    }
    if let Some(r) = &outcome.render
        && r.gather.dropped > 0
    {
        streams::eprint_line(&format!(
            "warning: {} camera samples had a value that is not finite and were left out of the image",
            r.gather.dropped
        ));
    }
}

/// Prints what loading `scene` left out (zero-area triangles and meshes),
/// one warning line each.
pub fn warn_loading(scene: &trilux_scene::Scene) {
    for w in &scene.warnings {
        streams::eprint_line(&format!("warning: {w}"));
    }
}

/// Warns (one line on stderr) when `scene` has no emitter: its solution is
/// zero everywhere and a render of it black. Not an error, for `render`
/// as for `solve` and `bake`: the work on a dark scene is meaningless but
/// harmless (and quick: there is no light to shoot), and a user who forgot
/// the light is told so instead of being left with a black image.
pub fn warn_if_dark(scene: &trilux_scene::Scene) {
    if scene.shapes.iter().all(|s| s.emitter.is_none()) && scene.lights.is_empty() {
        streams::eprint_line(&format!(
            "warning: {}: the scene has no emitter: no light reaches any surface (an area emitter on a shape, a point, spot or directional emitter, an emissive glTF material or a KHR_lights_punctual light lights it)",
            scene.path.display()
        ));
    }
}

/// The main job: the bundled default scene rendered into out/.
fn render_default() -> anyhow::Result<()> {
    let scene = default_scene();
    let exr = output::default_output(&scene, "exr");
    let png = exr.with_extension("png");
    let stats = exr.with_extension("json");
    let mut argv = vec!["trilux".into(), "render".into(), scene.into_os_string()];
    argv.extend(["-o".into(), exr.into_os_string()]);
    argv.extend(["--png".into(), png.into_os_string()]);
    argv.extend(["--stats".into(), stats.into_os_string()]);
    let Cli {
        command: Some(Command::Render(args)),
    } = Cli::parse_from(argv)
    else {
        anyhow::bail!("the default render's arguments do not parse");
    };
    render::run_into(&args, true)
}

/// Runs the command; its status is 0 unless it says otherwise (an
/// interrupted solve, `interrupt`).
fn run(cli: Cli) -> anyhow::Result<ExitCode> {
    let done = match cli.command {
        Some(Command::Info(args)) => info::run(&args),
        Some(Command::Solve(args)) => return solve::run(&args),
        Some(Command::Render(args)) => render::run(&args),
        Some(Command::Bake(args)) => bake::run(&args),
        Some(Command::View(args)) => viewer::run(&args),
        None => render_default(),
    };
    done.map(|()| ExitCode::SUCCESS)
}

/// The longest line of an error message (a quoted value of megabytes
/// loses its middle).
const MAX_LINE_CHARS: usize = 1000;

/// Prints a usage error with clap's message, each line capped, and exits
/// with clap's status (2); help and version go to stdout as usual.
fn usage_error(e: clap::Error) -> ExitCode {
    if !e.use_stderr() {
        e.exit();
    }
    for line in e.render().to_string().lines() {
        streams::eprint_line(&trilux_scene::error::elide(line, MAX_LINE_CHARS));
    }
    ExitCode::from(u8::try_from(e.exit_code()).unwrap_or(2))
}

fn main() -> ExitCode {
    record::start();
    // Usage errors exit here with clap's message and status 2.
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => return usage_error(e),
    };
    match run(cli) {
        Ok(code) => code,
        Err(e) if e.is::<output::UsageError>() => {
            streams::eprint_line(&format!("error: {e}"));
            ExitCode::from(2)
        }
        Err(e) => {
            let lines = match scene_error(&e) {
                Some(scene) => scene.lines(),
                None => vec![e.to_string()],
            };
            for line in lines {
                let line = line.replace(['\n', '\r'], " ");
                let line = trilux_scene::error::elide(&line, MAX_LINE_CHARS);
                streams::eprint_line(&format!("error: {line}"));
            }
            ExitCode::FAILURE
        }
    }
}

/// The scene error `e` is, directly or as the pipeline's: its errors are
/// printed one a line (a file's independent errors together).
fn scene_error(e: &anyhow::Error) -> Option<&trilux_scene::SceneError> {
    if let Some(scene) = e.downcast_ref::<trilux_scene::SceneError>() {
        return Some(scene);
    }
    match e.downcast_ref::<trilux::PipelineError>() {
        Some(trilux::PipelineError::Scene(scene)) => Some(scene),
        _ => None,
    }
}
