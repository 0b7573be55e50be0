//! Renders a scene file with direct light only (a stand-in solution that
//! knows no indirect light), e.g. to compare with Mitsuba 3's path tracer at
//! `max_depth` 2.
//!
//! Run: `cargo run --release -p trilux --example direct_light -- SCENE.xml OUT.exr [SIZE] [SPP] [rgb|spectral]`
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test, bench or example may panic

use std::path::Path;

use trilux::{PipelineError, ViewOverrides, prepare, scene_camera};
use trilux_color::{Mode, WithBands};
use trilux_render::{DirectOnly, ExtraBounce, Image, RenderSettings, RenderStats, render};

/// The render, once the band count is known.
struct Direct<'a> {
    scene: &'a trilux_scene::Scene,
    view: ViewOverrides,
    settings: RenderSettings,
}

impl WithBands for Direct<'_> {
    type Output = Result<(Image, RenderStats), PipelineError>;
    fn run<const N: usize>(self) -> Self::Output {
        let camera = scene_camera(self.scene, &self.view)?;
        let solution = DirectOnly::<N>::new(prepare::<N>(self.scene)?);
        Ok(render(&solution, &camera, &self.settings, |_, _| {})?)
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [scene, out, rest @ ..] = args.as_slice() else {
        return Err("usage: direct_light SCENE.xml OUT.exr [SIZE] [SPP] [rgb|spectral]".into());
    };
    let size: Option<u32> = rest.first().map(|s| s.parse()).transpose()?;
    let spp: Option<u32> = rest.get(1).map(|s| s.parse()).transpose()?;
    let mode = match rest.get(2).map(String::as_str) {
        Some("spectral") => Mode::Spectral,
        _ => Mode::Rgb,
    };
    let scene = trilux_scene::load(scene)?;
    let camera = scene.camera.as_ref().ok_or("the scene has no camera")?;
    let mut settings = trilux::render_settings(camera);
    settings.spp = spp.unwrap_or(settings.spp);
    settings.extra_bounce = ExtraBounce::Never;
    let view = ViewOverrides {
        width: size,
        height: size,
        ..Default::default()
    };
    let (image, stats) = mode.with_bands(Direct {
        scene: &scene,
        view,
        settings,
    })?;
    image.write_exr(Path::new(out))?;
    println!("{:.2} s, mean {:?}", stats.seconds, image.mean());
    Ok(())
}
