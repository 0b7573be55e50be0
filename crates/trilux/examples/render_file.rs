//! The one-call API: a scene file to an image, as `trilux render` makes it
//! (`trilux::render_file`; the Python module calls the same).
//!
//! Run: `cargo run --release -p trilux --example render_file -- [SCENE] [OUT.exr] [SPP]`
//! (default scenes/cornell-box.xml, /tmp/render_file.exr, the scene's
//! sample count). Prints the image's size and mean.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test, bench or example may panic

use std::path::PathBuf;

use trilux::{SolveOptions, ViewOptions};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let scene = args.first().map(PathBuf::from).unwrap_or_else(|| {
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenes/cornell-box.xml")
    });
    let out = args.get(1).map_or_else(
        || std::env::temp_dir().join("render_file.exr"),
        PathBuf::from,
    );
    let mut view = ViewOptions::default();
    view.spp = args.get(2).map(|s| s.parse()).transpose()?;
    let image = trilux::render_file(&scene, &[], &SolveOptions::default(), &view)?;
    image.write_exr(&out)?;
    println!(
        "{}: {} × {}, mean {:?}",
        out.display(),
        image.width(),
        image.height(),
        image.mean()
    );
    Ok(())
}
