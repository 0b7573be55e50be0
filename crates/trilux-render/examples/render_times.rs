//! Render time per scene at 256×256 for 16 and 64 samples per pixel, from
//! one default-quality solve per scene (the render alone is timed: the
//! view-independent solve is shared by every view). Prints a Markdown table
//! for docs/results.md.
//!
//! Run: `cargo run --release -p trilux-render --example render_times [-- SCENE.xml ...]`

use std::path::PathBuf;
use std::time::Instant;

use trilux_render::{RadianceSolution, RenderSettings, ViewOverrides, render, solve_scene};
use trilux_solver::{Quality, SolverSettings};

fn times<const N: usize, S: RadianceSolution<N>>(
    scene: &trilux_scene::Scene,
    sol: &S,
) -> Result<Vec<f64>, Box<dyn std::error::Error>> {
    let view = ViewOverrides {
        width: Some(256),
        height: Some(256),
        ..Default::default()
    };
    let mut out = Vec::new();
    for spp in [16, 64] {
        let settings = RenderSettings {
            spp,
            ..RenderSettings::for_scene(scene.camera.as_ref().ok_or("no camera")?)
        };
        let (_, stats) = render(scene, sol, &view, &settings, |_, _| {})?;
        out.push(stats.seconds);
    }
    Ok(out)
}

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
    println!("| scene | bands | solve s | render 16 spp s | render 64 spp s |");
    println!("|---|---|---|---|---|");
    for p in paths {
        let scene = trilux_scene::load(&p)?;
        let t = Instant::now();
        let (bands, r) = if scene.spectral {
            let sol = solve_scene::<{ trilux_color::SPECTRAL_BANDS }>(
                &scene,
                SolverSettings::preset(Quality::Default),
            )?;
            let solve = t.elapsed().as_secs_f64();
            (trilux_color::SPECTRAL_BANDS, (solve, times(&scene, &sol)?))
        } else {
            let sol = solve_scene::<3>(&scene, SolverSettings::preset(Quality::Default))?;
            let solve = t.elapsed().as_secs_f64();
            (3, (solve, times(&scene, &sol)?))
        };
        let name = p
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        println!(
            "| {name} | {bands} | {:.2} | {:.2} | {:.2} |",
            r.0, r.1[0], r.1[1]
        );
    }
    Ok(())
}
