//! Renders the analytic lit floor (a diffuse floor under a square light)
//! with the final gather and writes `out/analytic-floor.exr` and `.png`.
//!
//! Run: `cargo run --release -p trilux-render --example analytic_floor`
//!
//! The printed check compares the centre pixel with the closed form
//! ρ · Le · F(point → square).
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test, bench or example may panic

use std::path::Path;

use glam::DVec3;
use trilux_render::analytic::LitFloor;
use trilux_render::camera::look_at;
use trilux_render::{Camera, FovAxis, RenderSettings, render_image};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let scene = LitFloor {
        rho: 0.8,
        s: 0.5,
        h: 1.0,
        le: 5.0,
    };
    let eye = DVec3::new(0.0, -2.5, 1.2);
    let target = DVec3::new(0.0, 0.0, 0.0);
    let camera = Camera::new(look_at(eye, target, DVec3::Z)?, 50.0, FovAxis::X, 160, 120)?;
    let settings = RenderSettings {
        spp: 64,
        ..Default::default()
    };
    let (image, stats) = render_image::<_, 3>(&scene, &camera, &settings, |l| l.0, |_, _| {})?;
    std::fs::create_dir_all("out")?;
    image.write_exr(Path::new("out/analytic-floor.exr"))?;
    image.write_png(Path::new("out/analytic-floor.png"), 0.0)?;
    let centre = image.get(80, 60)[0];
    println!(
        "{:.2} s, {} camera rays; centre pixel {centre:.4}, closed form {:.4}",
        stats.seconds,
        stats.gather.camera_rays,
        scene.expected(target)
    );
    Ok(())
}
