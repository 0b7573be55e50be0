//! Rendering from a saved solution costs only the render: solves a scene,
//! saves the solution (trilux-solver's versioned file with the scene hash),
//! loads it back and renders from it, timing each step; then renders from
//! the in-memory solution for comparison. The file stores radiance in f32,
//! so the two images agree to f32 rounding (printed as a relative RMSE).
//!
//! Run: `cargo run --release -p trilux-render --example saved_solution [-- SCENE.xml [SIZE] [SPP]]`
//! (default scenes/cornell-box.xml in RGB mode, 128×128, 64 spp).

use std::path::PathBuf;
use std::time::Instant;

use trilux_render::{RenderSettings, ViewOverrides, render};
use trilux_solver::{Quality, SceneInput, Solution, Solver, SolverSettings, solve_hash};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let path = args.first().map(PathBuf::from).unwrap_or_else(|| {
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenes/cornell-box.xml")
    });
    let size: u32 = args.get(1).map(|s| s.parse()).transpose()?.unwrap_or(128);
    let spp: u32 = args.get(2).map(|s| s.parse()).transpose()?.unwrap_or(64);
    let scene = trilux_scene::load(&path)?;
    let camera = scene.camera.clone().ok_or("the scene has no camera")?;
    let input = SceneInput::from_scene(&scene);
    let settings = SolverSettings::preset(Quality::Default);

    let t = Instant::now();
    let solution = Solver::<3>::new(&input.as_input(), settings.clone())?.solve(|_| {});
    let solve_s = t.elapsed().as_secs_f64();
    let file = std::env::temp_dir().join(format!("trilux-saved-{}.sol", std::process::id()));
    let t = Instant::now();
    solution.save(&file, solve_hash(&input.as_input(), &settings, 3))?;
    let save_s = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let loaded = Solution::<3>::load(&file, &input.as_input(), &settings)?;
    let load_s = t.elapsed().as_secs_f64();
    let _ = std::fs::remove_file(&file);

    let view = ViewOverrides {
        width: Some(size),
        height: Some(size),
        ..Default::default()
    };
    let rs = RenderSettings {
        spp,
        ..RenderSettings::for_scene(&camera)
    };
    let (a, sa) = render(&scene, &solution, &view, &rs, |_, _| {})?;
    let (b, sb) = render(&scene, &loaded, &view, &rs, |_, _| {})?;
    let c = trilux_render::compare(&b, &a, None)?;
    println!(
        "solve {solve_s:.2} s, save {save_s:.3} s, load {load_s:.3} s; render from the solve {:.2} s, from the file {:.2} s; relRMSE between the two {:.2e}",
        sa.seconds, sb.seconds, c.rel_rmse
    );
    Ok(())
}
