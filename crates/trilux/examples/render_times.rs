//! Render time per scene at 256×256 for 16 and 64 samples per pixel, from
//! one default-quality solve per scene saved to a file (the render alone is
//! timed: the view-independent solve is shared by every view). Prints a
//! Markdown table for docs/results.md.
//!
//! Run: `cargo run --release -p trilux --example render_times [-- SCENE.xml ...]`
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test, bench or example may panic

use std::path::PathBuf;

use trilux::{Observer, Plan, RenderPlan, SolutionSource, ViewOverrides};
use trilux_render::RenderSettings;
use trilux_solver::{Quality, SolverSettings};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut paths: Vec<PathBuf> = std::env::args().skip(1).map(PathBuf::from).collect();
    if paths.is_empty() {
        let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
        paths = std::fs::read_dir(&dir)?
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.extension().is_some_and(|x| x == "xml"))
            .collect();
        paths.sort();
    }
    let file = std::env::temp_dir().join(format!("trilux-times-{}.sol", std::process::id()));
    println!("| scene | bands | solve s | render 16 spp s | render 64 spp s |");
    println!("|---|---|---|---|---|");
    for p in paths {
        let scene = trilux_scene::load(&p)?;
        let camera = scene.camera.as_ref().ok_or("no camera")?;
        let mut plan = Plan {
            mode: scene.mode(),
            solver: SolverSettings::preset(Quality::Default),
            source: SolutionSource::Solve,
            save: Some(&file),
            solution_file: false,
            bake: None,
            render: None,
        };
        let solved = Observer::quiet(|o| trilux::pipeline::run(&scene, &plan, o))?;
        plan.source = SolutionSource::Load(&file);
        plan.save = None;
        let mut times = Vec::new();
        for spp in [16, 64] {
            plan.render = Some(RenderPlan {
                view: ViewOverrides {
                    width: Some(256),
                    height: Some(256),
                    ..Default::default()
                },
                settings: RenderSettings {
                    spp,
                    ..trilux::render_settings(camera)
                },
            });
            let r = Observer::quiet(|o| trilux::pipeline::run(&scene, &plan, o))?;
            times.push(r.render_seconds);
        }
        let name = p
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        println!(
            "| {name} | {} | {:.2} | {:.2} | {:.2} |",
            solved.solve.bands, solved.solve_seconds, times[0], times[1]
        );
    }
    let _ = std::fs::remove_file(&file);
    Ok(())
}
