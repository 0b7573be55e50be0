//! Renders a scene file with direct light only (a stand-in solution that
//! knows no indirect light), e.g. to compare with Mitsuba 3's path tracer at
//! `max_depth` 2 before a solve is available.
//!
//! Run: `cargo run --release -p trilux-render --example direct_light -- SCENE.xml OUT.exr [SIZE] [SPP] [rgb|spectral]`

use std::path::Path;

use trilux_color::Spectrum;
use trilux_geometry::SceneGeometry;
use trilux_render::{DirectOnly, ExtraBounce, RenderSettings, ViewOverrides, render};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [scene, out, rest @ ..] = args.as_slice() else {
        return Err("usage: direct_light SCENE.xml OUT.exr [SIZE] [SPP] [rgb|spectral]".into());
    };
    let size: Option<u32> = rest.first().map(|s| s.parse()).transpose()?;
    let spp: Option<u32> = rest.get(1).map(|s| s.parse()).transpose()?;
    let spectral = rest.get(2).map(String::as_str) == Some("spectral");
    let scene = trilux_scene::load(scene)?;
    let camera = scene.camera.as_ref().ok_or("the scene has no camera")?;
    let mut settings = RenderSettings::for_scene(camera);
    settings.spp = spp.unwrap_or(settings.spp);
    settings.extra_bounce = ExtraBounce::Never;
    let view = ViewOverrides {
        width: size,
        height: size,
        ..Default::default()
    };
    let geometry = SceneGeometry::build(&scene.geometry_shapes())?;
    let (image, stats) = if spectral {
        let sol = DirectOnly::<10> {
            geometry,
            constant: Spectrum::splat(0.0),
        };
        render(&scene, &sol, &view, &settings, |_, _| {})?
    } else {
        let sol = DirectOnly::<3> {
            geometry,
            constant: Spectrum::splat(0.0),
        };
        render(&scene, &sol, &view, &settings, |_, _| {})?
    };
    image.write_exr(Path::new(out))?;
    println!("{:.2} s, mean {:?}", stats.seconds, image.mean());
    Ok(())
}
