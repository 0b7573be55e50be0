//! Solves a scene file and renders it by final gathering.
//!
//! The short way is the one-call API (`trilux::render_file`, example
//! `render_file`); this example assembles the `Plan` itself to reach what
//! that API keeps at the command's defaults (single solver settings from
//! the environment, the extra bounce) and to print the render's counters.
//!
//! Run: `cargo run --release -p trilux --example render_scene -- SCENE.xml OUT.exr [SIZE] [SPP] [draft|default|high] [never|auto|always]`
//!
//! Prints the solve and render times and the image mean. Spectral scenes
//! solve and render in their spectral bands. OUT ending in `.png` writes an
//! 8-bit sRGB PNG (exposure 0, clamped), anything else a linear EXR.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test, bench or example may panic

use std::path::Path;

use trilux::{Observer, Plan, RenderPlan, SolutionSource, ViewOverrides};
use trilux_render::ExtraBounce;
use trilux_solver::{Quality, SolverSettings};

fn print_stats(s: &trilux_solver::SolveStats) {
    let sum = |v: &[f64]| v.iter().sum::<f64>();
    let e = sum(&s.emitted_flux);
    println!(
        "CR {:.4}, shots {}, elements {}, interactions {}, gather links {}; of emitted: absorbed {:.4}, escaped {:.4}, residual {:.4}",
        s.convergence_ratio,
        s.shots,
        s.elements,
        s.interactions,
        s.gather_links,
        sum(&s.absorbed_flux) / e,
        sum(&s.escaped_flux) / e,
        sum(&s.residual_flux) / e
    );
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [scene, out, rest @ ..] = args.as_slice() else {
        return Err("usage: render_scene SCENE.xml OUT.exr [SIZE] [SPP] [QUALITY] [EXTRA]".into());
    };
    let size: Option<u32> = rest.first().map(|s| s.parse()).transpose()?;
    let spp: Option<u32> = rest.get(1).map(|s| s.parse()).transpose()?;
    let quality = match rest.get(2).map(String::as_str) {
        Some("draft") => Quality::Draft,
        Some("high") => Quality::High,
        _ => Quality::Default,
    };
    let extra = match rest.get(3).map(String::as_str) {
        Some("never") => ExtraBounce::Never,
        Some("auto") => ExtraBounce::Auto { close_factor: 1.0 },
        _ => ExtraBounce::Always,
    };
    let scene = trilux_scene::load(scene)?;
    let camera = scene.camera.as_ref().ok_or("the scene has no camera")?;
    let mut settings = trilux::render_settings(camera);
    settings.spp = spp.unwrap_or(settings.spp);
    settings.extra_bounce = extra;
    // Single solver settings may be overridden for experiments
    // (`SolverSettings::override_from`: TRILUX_FF_EPS and the like).
    let mut solver = SolverSettings::preset(quality);
    solver.override_from(|name| std::env::var(name).ok())?;
    let plan = Plan {
        mode: scene.mode(),
        solver,
        source: SolutionSource::Solve,
        save: None,
        solution_file: false,
        bake: None,
        render: Some(RenderPlan {
            view: ViewOverrides {
                width: size,
                height: size,
                ..Default::default()
            },
            settings,
        }),
    };
    let outcome = Observer::quiet(|o| trilux::pipeline::run(&scene, &plan, o))?;
    print_stats(&outcome.solve);
    let (Some(image), Some(stats)) = (&outcome.image, &outcome.render) else {
        return Err("the plan renders an image".into());
    };
    let out = Path::new(out);
    if out.extension().is_some_and(|e| e == "png") {
        image.write_png(out, 0.0)?;
    } else {
        image.write_exr(out)?;
    }
    println!(
        "solve {:.2} s, render {:.2} s, {} link senders, {} shadow rays, extra bounces {} of {} gather rays, mean {:?}",
        outcome.solve_seconds,
        stats.seconds,
        stats.gather.link_senders,
        stats.gather.shadow_rays,
        stats.gather.extra_bounces,
        stats.gather.gather_rays,
        image.mean()
    );
    Ok(())
}
