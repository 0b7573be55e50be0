//! View independence: one solve, several views. Solves a scene once, then
//! renders a short walkthrough (the camera moves along a line and turns
//! towards a fixed target) into `out/walkthrough-NN.png` and `.exr`.
//!
//! Run: `cargo run --release -p trilux --example walkthrough [-- SCENE.xml [FRAMES] [SIZE] [SPP]]`
//! (default scenes/paper-scene1.xml, 6 frames, 128×128, 32 spp).
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test, bench or example may panic

use std::path::{Path, PathBuf};
use std::time::Instant;

use glam::DVec3;
use trilux::{Observer, Plan, RenderPlan, SolutionSource, ViewOverrides};
use trilux_render::RenderSettings;
use trilux_solver::{Quality, SolverSettings};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let path = args.first().map(PathBuf::from).unwrap_or_else(|| {
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenes/paper-scene1.xml")
    });
    let frames: usize = args
        .get(1)
        .map(|s| s.parse())
        .transpose()?
        .unwrap_or(6)
        .max(1);
    let size: u32 = args.get(2).map(|s| s.parse()).transpose()?.unwrap_or(128);
    let spp: u32 = args.get(3).map(|s| s.parse()).transpose()?.unwrap_or(32);
    let scene = trilux_scene::load(&path)?;
    let camera = scene.camera.clone().ok_or("the scene has no camera")?;
    let file = std::env::temp_dir().join(format!("trilux-walk-{}.sol", std::process::id()));
    let mut plan = Plan {
        mode: scene.mode(),
        solver: SolverSettings::preset(Quality::Default),
        source: SolutionSource::Solve,
        save: Some(&file),
        solution_file: false,
        bake: None,
        render: None,
    };
    let t = Instant::now();
    Observer::quiet(|o| trilux::pipeline::run(&scene, &plan, o))?;
    println!("solved once in {:.2} s", t.elapsed().as_secs_f64());
    plan.source = SolutionSource::Load(&file);
    plan.save = None;

    // Walk sideways across the view and a little forward, looking at the
    // scene camera's target.
    let forward = (camera.target - camera.origin).normalize();
    let side = forward.cross(camera.up).normalize();
    let reach = 0.25 * (camera.target - camera.origin).length();
    std::fs::create_dir_all("out")?;
    let settings = RenderSettings {
        spp,
        ..trilux::render_settings(&camera)
    };
    for k in 0..frames {
        let s = if frames > 1 {
            k as f64 / (frames - 1) as f64
        } else {
            0.5
        };
        let eye: DVec3 = camera.origin + side * reach * (s - 0.5) + forward * reach * 0.3 * s;
        plan.render = Some(RenderPlan {
            view: ViewOverrides {
                lookat: Some((eye, camera.target, Some(camera.up))),
                width: Some(size),
                height: Some(size),
                ..Default::default()
            },
            settings,
        });
        let frame = Observer::quiet(|o| trilux::pipeline::run(&scene, &plan, o))?;
        let image = frame.image.ok_or("the plan renders")?;
        image.write_png(Path::new(&format!("out/walkthrough-{k:02}.png")), 0.0)?;
        image.write_exr(Path::new(&format!("out/walkthrough-{k:02}.exr")))?;
        println!(
            "frame {k}: eye {eye:.3}, loaded in {:.3} s, rendered in {:.2} s (no solve)",
            frame.solve_seconds, frame.render_seconds
        );
    }
    let _ = std::fs::remove_file(&file);
    Ok(())
}
