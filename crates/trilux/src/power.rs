//! Emitted power per band, P = π · L · A for each one-sided Lambertian area
//! emitter (radiance L in each band, area A), summed over the emitters,
//! plus I · ∫ falloff dω for each point (4π I) and spot light and E π R²
//! for each directional light (R the scene's bounding sphere's radius),
//! and π R² ∫ L dω for an environment map.
//!
//! L comes from trilux-color's emission conversion
//! ([`ColorParam::emission`](trilux_color::ColorParam::emission)), exactly as
//! the solver will see it: in RGB mode Mitsuba 3's conversions (a sampled
//! spectrum through CIE 1931 XYZ to linear sRGB; a constant `<spectrum>` as
//! the equal-energy spectrum), in spectral mode the band values of
//! trilux-color's bands. A is the shape's exact world-space area
//! ([`trilux_scene::surface_area`]).

use anyhow::{Result, anyhow};
use trilux_color::{ColorParam, Mode, Spectrum, WithBands};
use trilux_scene::{Scene, surface_area};

/// Total emitted power per band (W): Σ π · L · A over the area emitters
/// and the lights' flux, a directional light's over the bounding sphere
/// of radius `scene_radius` (as the solve counts it).
pub fn emitted_power(scene: &Scene, mode: Mode, scene_radius: f64) -> Result<Vec<f64>> {
    mode.with_bands(Power(scene, scene_radius))
}

/// [`emitted_power`] once the band count is known.
struct Power<'a>(&'a Scene, f64);

impl WithBands for Power<'_> {
    type Output = Result<Vec<f64>>;
    fn run<const N: usize>(self) -> Self::Output {
        let mut total = Spectrum::<N>::zero();
        for (_, s) in self.0.emitters() {
            let Some(emitter) = &s.emitter else { continue };
            let radiance = radiance::<N>(&emitter.radiance)
                .map_err(|e| anyhow!("{}: emitted radiance: {e}", emitter.location))?;
            total += radiance * (std::f64::consts::PI * surface_area(&s.shape));
        }
        // Point and spot lights send I · ∫ falloff dω, a directional one
        // E π R² (the solve's `emitted_flux` counts the same).
        for l in &self.0.lights {
            let i = radiance::<N>(&l.intensity)
                .map_err(|e| anyhow!("{}: intensity: {e}", l.location))?;
            total += i * l.punctual.flux_factor(self.1);
        }
        // An environment map sends π R² ∫ L dω (trilux-solver's `sky`).
        if let Some(sky) = trilux::pipeline::prepared_sky::<N>(self.0)? {
            total += sky.flux(self.1);
        }
        Ok(total.0.to_vec())
    }
}

fn radiance<const N: usize>(c: &ColorParam) -> Result<Spectrum<N>> {
    Ok(c.emission::<N>()?)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The check value of Mitsuba 3.9: the classic Cornell light
    /// in RGB mode is linear sRGB (20.7108, 10.8546, 2.77115). 1e-4 relative:
    /// the check value's six digits.
    #[test]
    fn cornell_light_in_rgb_matches_mitsuba() {
        let light = ColorParam::Sampled(vec![
            (400.0, 0.0),
            (500.0, 8.0),
            (600.0, 15.6),
            (700.0, 18.4),
        ]);
        let rgb = radiance::<3>(&light).expect("valid");
        for (got, want) in rgb.0.iter().zip([20.7108, 10.8546, 2.77115]) {
            assert!((got - want).abs() <= 1e-4 * want, "{rgb:?}");
        }
    }
}
