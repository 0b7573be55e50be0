//! Solves a scene in RGB mode and prints, per shape, its area and the area
//! mean of the reflected radiance leaving its front face, as JSON: the
//! numbers `tests/golden/surface_irradiance.py` compares with Mitsuba 3's
//! irradiance meters (mean exitant radiance of a diffuse face = ρ Ē / π).
//!
//! ```text
//! cargo run --release -p trilux-solver --example surface_radiance -- SCENE [draft|default|high] [CR|-] [MAX_SHOTS]
//! ```
//!
//! The environment variables `TRILUX_MAX_DEPTH`, `TRILUX_FF_EPS`,
//! `TRILUX_FR_EPS`, `TRILUX_FLUX_EPS` and `TRILUX_VISIBILITY_SAMPLES` override single
//! settings of the preset (for experiments).
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test, bench or example may panic

use std::path::PathBuf;

use trilux_geometry::Side;
use trilux_solver::{Quality, SceneDescription, Solver, SolverSettings};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let path = PathBuf::from(
        args.next()
            .ok_or("usage: surface_radiance SCENE [QUALITY] [CR]")?,
    );
    let quality = match args.next().as_deref() {
        None | Some("default") => Quality::Default,
        Some("draft") => Quality::Draft,
        Some("high") => Quality::High,
        Some(q) => return Err(format!("unknown quality {q}").into()),
    };
    let scene = trilux_scene::load(&path)?;
    let (shapes, bsdfs, emission) = (
        scene.geometry_shapes(),
        scene.bsdf_params(),
        scene.emitter_radiance(),
    );
    let input = SceneDescription {
        shapes: &shapes,
        bsdfs: &bsdfs,
        emission: &emission,
    };
    let mut settings = SolverSettings::preset(quality);
    if let Some(cr) = args.next().filter(|a| a != "-") {
        settings.convergence = cr.parse()?;
    }
    if let Some(shots) = args.next() {
        settings.max_shots = shots.parse()?;
    }
    // Single settings may be overridden for experiments.
    settings.override_from(|name| std::env::var(name).ok())?;
    let solution = Solver::<3>::from_description(&input, settings)?.solve(|_| {});
    let geom = solution.forest().geometry();
    let mut rows = Vec::new();
    for shape in 0..input.shapes.len() as u32 {
        let area: f64 = geom
            .surfaces_of_shape(shape)
            .into_iter()
            .map(|s| geom.surface(s).area())
            .sum();
        let mean = solution.shape_mean_radiance(shape, Side::Front);
        rows.push(format!(
            "{{\"shape\": {shape}, \"area\": {area}, \"radiance\": [{}, {}, {}]}}",
            mean[0], mean[1], mean[2]
        ));
    }
    let st = solution.stats();
    println!(
        "{{\"convergence_ratio\": {}, \"shapes\": [\n  {}\n]}}",
        st.convergence_ratio,
        rows.join(",\n  ")
    );
    Ok(())
}
