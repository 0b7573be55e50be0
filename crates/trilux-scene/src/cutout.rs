//! Cut-outs: an opacity α(u, v) read from a texture (leaves, fabric,
//! railings cut out of a few quads), the fraction 1 − α(u, v) of the light
//! let through at each crossing (trilux-geometry's `Transmittance::Cutout`).
//!
//! Two owners define α:
//!
//! - Mitsuba 3's `mask` with a `bitmap` (or `checkerboard`) `opacity`: α is
//!   the texture read as a float texture, Mitsuba's `eval_1` of a bitmap:
//!   the luminance of its linear RGB value (a grey image: the value
//!   itself; an alpha channel is dropped, as Mitsuba's `bitmap` drops it),
//!   with the bitmap's filter, wrap mode and `to_uv`;
//! - glTF 2.0's `alphaMode` `MASK`: with a = baseColorFactor.a ×
//!   baseColorTexture.a (the alpha channel, linear), α = 1 where a ≥
//!   `alphaCutoff` (default 0.5) and 0 elsewhere (glTF 2.0, 3.9.4).
//!
//! The texture is the shape's like any other (read by [`Pending::finish`],
//! each image once); the map holds its slot.
//!
//! [`Pending::finish`]: crate::Pending::finish

use std::sync::Arc;

use glam::DVec2;
use trilux_brdf::TextureSlot;
use trilux_color::luminance;
use trilux_geometry::{Cutout, OpacityMap, Transmittance};

use crate::error::Result;
use crate::scene::Scene;
use crate::textures::{TextureCache, TextureRequest};

/// The shapes of `scene` that let all the light through everywhere (a
/// `mask` of opacity 0, a cut-out whose opacity is 0 over its whole
/// texture: the filtered value of texels that are all 0, or all below the
/// cutoff, is too) and emit nothing: nothing to see, nothing blocked,
/// nothing reflected. Their indices, each with a warning line: the caller
/// leaves them out.
pub(crate) fn leave_out_clear(scene: &mut Scene) -> Vec<usize> {
    let mut clear = Vec::new();
    for (i, s) in scene.shapes.iter().enumerate() {
        let all_through = match &s.transmission {
            Some(Transmittance::Constant(t)) => *t >= 1.0,
            Some(Transmittance::Cutout(c)) => c.0.mean() <= 0.0,
            _ => false,
        };
        if all_through && s.emitter.is_none() {
            scene.warnings.push(format!(
                "{}: this shape lets all the light through everywhere (its opacity is 0): it is left out",
                s.location
            ));
            clear.push(i);
        }
    }
    clear
}

/// How α comes from the texture's value (module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum AlphaRule {
    /// Mitsuba's `mask`: α = the value's luminance, in [0, 1].
    Opacity,
    /// glTF's `MASK`: α = 1 where the value (every channel holds the
    /// alpha) is at least `cutoff`, else 0.
    Cutoff(f64),
}

/// A cut-out of one shape, its texture not read yet.
#[derive(Clone, Debug)]
pub(crate) struct CutoutRequest {
    /// The texture (its `path` and `kind` are not used).
    pub texture: TextureRequest,
    /// How α comes from it.
    pub rule: AlphaRule,
}

impl CutoutRequest {
    /// The shape's transmittance, its texture read through `cache`.
    pub fn finish(&self, cache: &mut TextureCache) -> Result<Transmittance> {
        let slot = cache.slot(&self.texture)?;
        Ok(Transmittance::Cutout(Cutout(Arc::new(
            TextureOpacity::new(slot, self.rule),
        ))))
    }
}

/// α over a texture slot (module docs).
#[derive(Debug)]
struct TextureOpacity {
    slot: TextureSlot,
    rule: AlphaRule,
    mean: f64,
    hash: u64,
}

impl TextureOpacity {
    fn new(slot: TextureSlot, rule: AlphaRule) -> Self {
        let t = &slot.texture;
        // The mean over one tile: for the luminance (affine in the texels)
        // that of the mean texel; for a threshold, the texels' own mean,
        // read at their centres (where either filter gives the texel).
        let mean = match rule {
            AlphaRule::Opacity => opacity_of(&slot, rule, t.mean()),
            AlphaRule::Cutoff(_) => {
                let (w, h) = (t.width(), t.height());
                let sum: f64 = (0..h)
                    .flat_map(|y| (0..w).map(move |x| (x, y)))
                    .map(|(x, y)| {
                        let uv = DVec2::new(
                            (f64::from(x) + 0.5) / f64::from(w),
                            (f64::from(y) + 0.5) / f64::from(h),
                        );
                        opacity_of(&slot, rule, t.eval(uv))
                    })
                    .sum();
                sum / (f64::from(w) * f64::from(h))
            }
        };
        let mut hash = 0xcbf2_9ce4_8422_2325u64;
        let words = [t.content_hash()]
            .into_iter()
            .chain(slot.scale.iter().chain(&slot.offset).map(|v| v.to_bits()))
            .chain(slot.to_uv.0.iter().map(|v| v.to_bits()))
            .chain([match rule {
                AlphaRule::Opacity => u64::MAX,
                AlphaRule::Cutoff(c) => c.to_bits(),
            }])
            .chain(t.wrap().map(|w| w as u64))
            .chain([t.filter() as u64]);
        for w in words {
            for b in w.to_le_bytes() {
                hash ^= u64::from(b);
                hash = hash.wrapping_mul(0x0100_0000_01b3);
            }
        }
        TextureOpacity {
            slot,
            rule,
            mean,
            hash,
        }
    }
}

/// α for the texture value `rgb` (module docs), in [0, 1].
fn opacity_of(slot: &TextureSlot, rule: AlphaRule, rgb: [f64; 3]) -> f64 {
    let v = slot.value(rgb);
    let alpha = match rule {
        AlphaRule::Opacity => luminance(v),
        AlphaRule::Cutoff(cutoff) => {
            if v[0] >= cutoff {
                1.0
            } else {
                0.0
            }
        }
    };
    if alpha.is_nan() {
        1.0
    } else {
        alpha.clamp(0.0, 1.0)
    }
}

impl OpacityMap for TextureOpacity {
    fn opacity(&self, uv: DVec2) -> f64 {
        let s = &self.slot;
        opacity_of(s, self.rule, s.texture.eval(s.to_uv.apply(uv)))
    }

    fn mean(&self) -> f64 {
        self.mean
    }

    fn content_hash(&self) -> u64 {
        self.hash
    }
}
