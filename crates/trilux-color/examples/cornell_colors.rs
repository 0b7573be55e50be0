//! The classic Cornell box's colours in both modes.
//!
//! Run: `cargo run -p trilux-color --example cornell_colors`
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test, bench or example may panic

use trilux_color::{Bands, ColorParam, Spectrum, srgb};

fn main() -> Result<(), trilux_color::ColorError> {
    let white = ColorParam::Sampled(vec![
        (400.0, 0.343),
        (500.0, 0.747),
        (600.0, 0.740),
        (700.0, 0.737),
    ]);
    let light = ColorParam::Sampled(vec![
        (400.0, 0.0),
        (500.0, 8.0),
        (600.0, 15.6),
        (700.0, 18.4),
    ]);

    // RGB mode converts exactly as Mitsuba 3 does.
    let w3: Spectrum<3> = white.reflectance()?;
    let l3: Spectrum<3> = light.emission()?;
    println!("RGB mode:      white {:?}  light {:?}", w3.0, l3.0);

    // Spectral mode: SPECTRAL_BANDS (20) bands, edges in nm:
    const N: usize = trilux_color::SPECTRAL_BANDS;
    println!("band edges:    {:?}", Bands::<N>::edges());
    let ws: Spectrum<N> = white.reflectance()?;
    let ls: Spectrum<N> = light.emission()?;
    println!("spectral mode: white {:?}", ws.0);
    println!("               light {:?}", ls.0);

    // What the light looks like: XYZ, linear sRGB, 8-bit sRGB (scaled to Y = 1).
    let xyz = ls.to_xyz();
    let scaled = xyz.map(|v| v / xyz[1]);
    println!(
        "light XYZ {:?} → sRGB bytes at Y = 1: {:?}",
        xyz,
        srgb::xyz_to_srgb_u8(scaled)
    );
    // RGB values in a spectral scene become smooth spectra.
    let red: Spectrum<10> = ColorParam::Rgb([0.8, 0.1, 0.1]).reflectance()?;
    println!("rgb (0.8, 0.1, 0.1) as a reflectance spectrum: {:?}", red.0);
    Ok(())
}
