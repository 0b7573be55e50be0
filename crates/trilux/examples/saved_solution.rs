//! Rendering from a saved solution costs only the render: solves a scene
//! and saves the solution (trilux-solver's versioned file with the scene
//! hash), renders from it in memory, then loads it back and renders from
//! the file, timing each step. The file stores radiance in f32, so the two
//! images agree to f32 rounding (printed as a relative RMSE).
//!
//! Run: `cargo run --release -p trilux --example saved_solution [-- SCENE.xml [SIZE] [SPP]]`
//! (default scenes/cornell-box.xml in RGB mode, 128×128, 64 spp).
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test, bench or example may panic

use std::path::PathBuf;

use trilux::{Observer, Plan, RenderPlan, SolutionSource, ViewOverrides};
use trilux_color::Mode;
use trilux_render::RenderSettings;
use trilux_solver::{Quality, SolverSettings};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let path = args.first().map(PathBuf::from).unwrap_or_else(|| {
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenes/cornell-box.xml")
    });
    let size: u32 = args.get(1).map(|s| s.parse()).transpose()?.unwrap_or(128);
    let spp: u32 = args.get(2).map(|s| s.parse()).transpose()?.unwrap_or(64);
    let scene = trilux_scene::load(&path)?;
    let camera = scene.camera.clone().ok_or("the scene has no camera")?;
    let file = std::env::temp_dir().join(format!("trilux-saved-{}.sol", std::process::id()));
    let render = RenderPlan {
        view: ViewOverrides {
            width: Some(size),
            height: Some(size),
            ..Default::default()
        },
        settings: RenderSettings {
            spp,
            ..trilux::render_settings(&camera)
        },
    };
    let mut plan = Plan {
        mode: Mode::Rgb,
        solver: SolverSettings::preset(Quality::Default),
        source: SolutionSource::Solve,
        save: Some(&file),
        solution_file: false,
        bake: None,
        render: Some(render),
    };
    let solved = Observer::quiet(|o| trilux::pipeline::run(&scene, &plan, o))?;
    plan.source = SolutionSource::Load(&file);
    plan.save = None;
    let loaded = Observer::quiet(|o| trilux::pipeline::run(&scene, &plan, o))?;
    let _ = std::fs::remove_file(&file);
    let (Some(a), Some(b)) = (&solved.image, &loaded.image) else {
        return Err("both plans render".into());
    };
    let c = trilux_render::compare(b, a, None)?;
    println!(
        "solve {:.2} s (+ save); load {:.3} s; render from the solve {:.2} s, from the file {:.2} s; relRMSE between the two {:.2e}",
        solved.solve_seconds,
        loaded.solve_seconds,
        solved.render_seconds,
        loaded.render_seconds,
        c.rel_rmse
    );
    Ok(())
}
