//! Textured materials: the diffuse albedo as a base-colour texture, the
//! light as vertex colours.
//!
//! On a side whose Lambertian reflectance varies over the surface (a
//! textured material), the renderer shows L(x) = ρ_d(x) · E(x)/π with ρ_d
//! at the hit. A bake at the leaves' resolution would blur the texture to
//! one value per leaf; instead the file carries
//! - an **albedo map**: ρ_d evaluated at every texel centre of the
//!   material's finest texture (the material's own rule, through
//!   `TexturedBsdf::at`, so blends and weights are included), with its wrap
//!   modes and filter (mipmapped when minified), as the material's
//!   `baseColorTexture` (sRGB, 8 bits);
//! - the **light** E/π per vertex: each leaf's radiance divided by the
//!   leaf's mean albedo ρ̄ (the solver's own averages), reconstructed with
//!   ρ̄ as the weight (`reconstruct`), so that the file's flux is again the
//!   leaves'.
//!
//! The viewer multiplies the two, as glTF defines base colour × `COLOR_0`.

use glam::DVec2;
use trilux_brdf::{Filter, TexturedBsdf, UvTransform, Wrap};
use trilux_color::srgb::linear_srgb_to_u8;
use trilux_geometry::Side;

/// Largest albedo map edge, in texels.
pub(crate) const MAX_MAP_EDGE: u32 = 2048;

/// A side's diffuse albedo sampled at texel centres, row 0 at v = 0.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct AlbedoMap {
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    /// Linear RGB albedo, row by row.
    pub texels: Vec<[f64; 3]>,
    /// Wrap modes along u and v.
    pub wrap: [Wrap; 2],
    /// The textures' filter.
    pub filter: Filter,
}

/// The albedo map of `side` of a textured material: `None` when that side
/// reflects no diffuse light anywhere (a black or purely glossy side), or
/// when a texture maps the surface's coordinates (`to_uv`,
/// `KHR_texture_transform`): the map is laid over the surface's own unit
/// square in the image's resolution, which a tiled, shifted or rotated
/// texture does not fit. Such a side is baked as vertex colours.
pub(crate) fn albedo_map<const N: usize>(
    textured: &TexturedBsdf<N>,
    side: Side,
) -> Option<AlbedoMap> {
    let slots = textured.slots();
    if slots.iter().any(|s| s.to_uv != UvTransform::IDENTITY) {
        return None;
    }
    let first = slots.first()?;
    let width = slots
        .iter()
        .map(|s| s.texture.width())
        .max()?
        .min(MAX_MAP_EDGE);
    let height = slots
        .iter()
        .map(|s| s.texture.height())
        .max()?
        .min(MAX_MAP_EDGE);
    let mut texels = Vec::with_capacity(width as usize * height as usize);
    for j in 0..height {
        for i in 0..width {
            let uv = DVec2::new(
                (f64::from(i) + 0.5) / f64::from(width),
                (f64::from(j) + 0.5) / f64::from(height),
            );
            let rho = textured.at(uv).diffuse_albedo(side).to_linear_srgb();
            texels.push(rho.map(|x| x.clamp(0.0, 1.0)));
        }
    }
    let any = texels.iter().flatten().any(|&x| x > 0.0);
    any.then(|| AlbedoMap {
        width,
        height,
        texels,
        wrap: first.texture.wrap(),
        filter: first.texture.filter(),
    })
}

impl AlbedoMap {
    /// The map as an 8-bit sRGB PNG (glTF's base colour is sRGB-encoded).
    pub fn png(&self) -> Result<Vec<u8>, png::EncodingError> {
        let mut out = Vec::new();
        {
            let mut encoder = png::Encoder::new(&mut out, self.width, self.height);
            encoder.set_color(png::ColorType::Rgb);
            encoder.set_depth(png::BitDepth::Eight);
            let mut writer = encoder.write_header()?;
            let bytes: Vec<u8> = self
                .texels
                .iter()
                .flat_map(|&t| linear_srgb_to_u8(t))
                .collect();
            writer.write_image_data(&bytes)?;
        }
        Ok(out)
    }

    /// The glTF sampler of this map.
    pub fn sampler(&self) -> serde_json::Value {
        let wrap = |w: Wrap| match w {
            Wrap::Repeat => 10497,
            Wrap::Mirror => 33648,
            Wrap::Clamp => 33071,
        };
        // Minified, a viewer averages texels through mipmaps (trilux's own
        // pictures average them through their pixel samples).
        let (mag, min) = match self.filter {
            Filter::Bilinear => (9729, 9987),
            Filter::Nearest => (9728, 9984),
        };
        serde_json::json!({
            "magFilter": mag,
            "minFilter": min,
            "wrapS": wrap(self.wrap[0]),
            "wrapT": wrap(self.wrap[1]),
        })
    }
}
