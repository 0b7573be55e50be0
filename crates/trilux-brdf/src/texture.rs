//! Bitmap textures: a reflectance (or a blend weight) that varies over a
//! surface, looked up at texture coordinates (u, v) exactly as Mitsuba 3's
//! `bitmap` texture looks them up.
//!
//! A [`Texture`] holds linear RGB texels, row 0 first (the top row of the
//! image file); (u, v) = (0, 0) is the top-left corner of the image and
//! (1, 1) its bottom-right corner (glTF's convention, and Mitsuba's once its
//! OBJ loader has flipped `vt`). Decoding image files (PNG, JPEG, the sRGB
//! transfer curve) is the scene layer's; this module only samples.
//!
//! Lookups (Mitsuba 3, `bitmap.cpp`):
//! - **bilinear** (`filter_type="bilinear"`, the default): the texel
//!   centres sit at (i + ½)/width; p = uv·res − ½, the four texels around p
//!   are wrapped and blended with weights from p's fractional part;
//! - **nearest**: the texel ⌊uv·res⌋, wrapped.
//!
//! Wrap modes map a texel index i outside 0..n back into it: `repeat`
//! (i mod n), `mirror` (m = i mod 2n, then m or 2n − 1 − m), `clamp`
//! (the nearest edge texel) — glTF's REPEAT, MIRRORED_REPEAT and
//! CLAMP_TO_EDGE.

use std::fmt;

use glam::DVec2;
use serde::{Deserialize, Serialize, Serializer};

use crate::error::BrdfError;

/// How texel indices outside the image wrap back into it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Wrap {
    /// The image tiles the plane (Mitsuba's default, glTF's REPEAT).
    Repeat,
    /// Every other tile is mirrored (glTF's MIRRORED_REPEAT).
    Mirror,
    /// The edge texels extend outwards (glTF's CLAMP_TO_EDGE).
    Clamp,
}

impl Wrap {
    /// The index `i` wrapped into `0..n` (`n` ≥ 1).
    #[inline]
    pub fn apply(self, i: i64, n: i64) -> usize {
        let j = match self {
            Wrap::Repeat => i.rem_euclid(n),
            Wrap::Clamp => i.clamp(0, n - 1),
            Wrap::Mirror => {
                let m = i.rem_euclid(2 * n);
                if m < n { m } else { 2 * n - 1 - m }
            }
        };
        j as usize
    }
}

/// An affine map of texture coordinates, Mitsuba's `to_uv`:
/// (u, v) ↦ (`m[0]·u + m[1]·v + m[2]`, `m[3]·u + m[4]·v + m[5]`), applied
/// before the lookup (a scale of 4 tiles the image 4 times).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct UvTransform(pub [f64; 6]);

impl UvTransform {
    /// (u, v) unchanged.
    pub const IDENTITY: UvTransform = UvTransform([1.0, 0.0, 0.0, 0.0, 1.0, 0.0]);

    /// The coordinates `uv` maps to.
    #[inline]
    pub fn apply(&self, uv: DVec2) -> DVec2 {
        let m = &self.0;
        DVec2::new(
            m[0] * uv.x + m[1] * uv.y + m[2],
            m[3] * uv.x + m[4] * uv.y + m[5],
        )
    }
}

impl Default for UvTransform {
    fn default() -> Self {
        Self::IDENTITY
    }
}

/// How a lookup between texel centres is filtered.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Filter {
    /// Bilinear interpolation of the four nearest texels (Mitsuba's default).
    Bilinear,
    /// The texel that contains the point.
    Nearest,
}

/// An image of linear RGB texels with its wrap modes and filter (module
/// docs).
#[derive(Clone, PartialEq)]
pub struct Texture {
    width: u32,
    height: u32,
    texels: Vec<[f32; 3]>,
    wrap: [Wrap; 2],
    filter: Filter,
    mean: [f64; 3],
    hash: u64,
}

impl fmt::Debug for Texture {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Texture")
            .field("width", &self.width)
            .field("height", &self.height)
            .field("wrap", &self.wrap)
            .field("filter", &self.filter)
            .field("hash", &format_args!("{:016x}", self.hash))
            .finish()
    }
}

/// A texture serialises as its size, modes and a hash of its texels (what
/// a solution's scene hash needs), not as its texels.
impl Serialize for Texture {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        (self.width, self.height, self.wrap, self.filter, self.hash).serialize(s)
    }
}

impl Texture {
    /// A texture of `width` × `height` texels, row 0 first; `wrap` for u
    /// and v. Every texel must be finite and non-negative.
    pub fn new(
        width: u32,
        height: u32,
        texels: Vec<[f32; 3]>,
        wrap: [Wrap; 2],
        filter: Filter,
    ) -> Result<Self, BrdfError> {
        if width == 0 || height == 0 || texels.len() as u64 != u64::from(width) * u64::from(height)
        {
            return Err(BrdfError::TextureSize {
                width,
                height,
                texels: texels.len(),
            });
        }
        if texels
            .iter()
            .flatten()
            .any(|v| !(v.is_finite() && *v >= 0.0))
        {
            return Err(BrdfError::TextureValue);
        }
        let mut sum = [0.0f64; 3];
        let mut hash = 0xcbf2_9ce4_8422_2325u64;
        let mut feed = |bytes: &[u8]| {
            for &b in bytes {
                hash ^= u64::from(b);
                hash = hash.wrapping_mul(0x0100_0000_01b3);
            }
        };
        feed(&width.to_le_bytes());
        feed(&height.to_le_bytes());
        for t in &texels {
            for c in 0..3 {
                sum[c] += f64::from(t[c]);
                feed(&t[c].to_le_bytes());
            }
        }
        let n = texels.len() as f64;
        Ok(Texture {
            width,
            height,
            texels,
            wrap,
            filter,
            mean: sum.map(|s| s / n),
            hash,
        })
    }

    /// Width in texels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Height in texels.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// The wrap modes for u and v.
    pub fn wrap(&self) -> [Wrap; 2] {
        self.wrap
    }

    /// The filter.
    pub fn filter(&self) -> Filter {
        self.filter
    }

    /// The mean of every texel: the texture's average over one tile.
    pub fn mean(&self) -> [f64; 3] {
        self.mean
    }

    /// A hash of the size and the texels (FNV-1a), stable across machines.
    pub fn content_hash(&self) -> u64 {
        self.hash
    }

    #[inline]
    fn texel(&self, x: i64, y: i64) -> [f64; 3] {
        let (w, h) = (i64::from(self.width), i64::from(self.height));
        let i = self.wrap[1].apply(y, h) * self.width as usize + self.wrap[0].apply(x, w);
        self.texels[i].map(f64::from)
    }

    /// The linear RGB value at `uv` (module docs); a coordinate that is not
    /// finite reads texel (0, 0).
    pub fn eval(&self, uv: DVec2) -> [f64; 3] {
        let uv = if uv.is_finite() { uv } else { DVec2::ZERO };
        // Far outside [0, 1] the f64 → i64 conversion saturates; wrapping
        // keeps any index in range.
        let res = DVec2::new(f64::from(self.width), f64::from(self.height));
        match self.filter {
            Filter::Nearest => {
                let p = (uv * res).floor();
                self.texel(p.x as i64, p.y as i64)
            }
            Filter::Bilinear => {
                let p = uv * res - 0.5;
                let f = p.floor();
                let (w1, (x, y)) = (p - f, (f.x as i64, f.y as i64));
                let w0 = DVec2::ONE - w1;
                let (a, b) = (self.texel(x, y), self.texel(x + 1, y));
                let (c, d) = (self.texel(x, y + 1), self.texel(x + 1, y + 1));
                std::array::from_fn(|k| {
                    w0.y * (w0.x * a[k] + w1.x * b[k]) + w1.y * (w0.x * c[k] + w1.x * d[k])
                })
            }
        }
    }
}

impl Texture {
    /// The gradient (∂h/∂u, ∂h/∂v) of the luminance h of the texture at
    /// the surface's `uv`, looked up through `to_uv`, exactly as Mitsuba
    /// 3.9.1's `bitmap::eval_1_grad` computes it (the height field of a
    /// bump map): zero for the `nearest` filter; for `bilinear`, with the
    /// four texels f00, f10, f01, f11 around p = uv'·res − ½ and the
    /// weights w1 = p − ⌊p⌋, w0 = 1 − w1,
    ///
    /// ```text
    /// ∂f/∂x = w0.y (f10 − f00) + w1.y (f11 − f01)
    /// ∂f/∂y = w0.x (f01 − f00) + w1.x (f11 − f10)
    /// ∇_uv h = res ⊙ (Mᵀ (∂f/∂x, ∂f/∂y))
    /// ```
    ///
    /// with M the linear part of `to_uv` (Mitsuba multiplies by the
    /// resolution after the transpose; the same for any `to_uv` without
    /// shear or rotation). Zero where `uv` is not finite.
    pub fn luminance_gradient(&self, uv: DVec2, to_uv: &UvTransform) -> DVec2 {
        if self.filter == Filter::Nearest || !uv.is_finite() {
            return DVec2::ZERO;
        }
        let res = DVec2::new(f64::from(self.width), f64::from(self.height));
        let p = to_uv.apply(uv) * res - 0.5;
        let f = p.floor();
        let (w1, (x, y)) = (p - f, (f.x as i64, f.y as i64));
        let w0 = DVec2::ONE - w1;
        let h = |x, y| trilux_color::luminance(self.texel(x, y));
        let (f00, f10) = (h(x, y), h(x + 1, y));
        let (f01, f11) = (h(x, y + 1), h(x + 1, y + 1));
        let dx = w0.y * (f10 - f00) + w1.y * (f11 - f01);
        let dy = w0.x * (f01 - f00) + w1.x * (f11 - f10);
        let m = &to_uv.0;
        res * DVec2::new(m[0] * dx + m[3] * dy, m[1] * dx + m[4] * dy)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ramp(filter: Filter, wrap: Wrap) -> Texture {
        // 4 × 1: 0, 1, 2, 3 in every channel.
        let texels = (0..4).map(|i| [i as f32; 3]).collect();
        Texture::new(4, 1, texels, [wrap; 2], filter).unwrap()
    }

    #[test]
    fn wraps_as_mitsuba_does() {
        // Dr.Jit's `Texture::wrap` (Mitsuba 3's bitmap): div = trunc(i' / n)
        // with i' = i + 1 when i < 0, mod = i − div·n (+ n if negative),
        // mirrored unless (div even) xor (i < 0).
        for n in 1..6i64 {
            for i in -20..20i64 {
                let div = if i < 0 { i + 1 } else { i } / n;
                let mut m = i - div * n;
                if m < 0 {
                    m += n;
                }
                let mirrored = if ((div & 1) == 0) ^ (i < 0) {
                    m
                } else {
                    n - 1 - m
                };
                assert_eq!(Wrap::Repeat.apply(i, n), m as usize);
                assert_eq!(Wrap::Mirror.apply(i, n), mirrored as usize, "i {i} n {n}");
                assert_eq!(Wrap::Clamp.apply(i, n), i.clamp(0, n - 1) as usize);
            }
        }
        // Mitsuba 3.9.1 itself (scalar_rgb, a 3 × 1 raw bitmap holding its
        // texel index, filter nearest, wrap mirror, at u = (i + ½)/3 for
        // i = −20..−9).
        let mitsuba = [1, 0, 0, 1, 2, 2, 1, 0, 0, 1, 2, 2];
        for (k, expected) in mitsuba.into_iter().enumerate() {
            assert_eq!(
                Wrap::Mirror.apply(k as i64 - 20, 3),
                expected,
                "i {}",
                k as i64 - 20
            );
        }
    }

    #[test]
    fn bilinear_interpolates_between_texel_centres() {
        let t = ramp(Filter::Bilinear, Wrap::Clamp);
        // Texel i's centre is at u = (i + 0.5) / 4.
        for i in 0..4 {
            let u = (i as f64 + 0.5) / 4.0;
            assert!((t.eval(DVec2::new(u, 0.5))[0] - i as f64).abs() < 1e-12);
        }
        // A quarter of the way from centre 1 to centre 2.
        let u = (1.5 + 0.25) / 4.0;
        assert!((t.eval(DVec2::new(u, 0.5))[1] - 1.25).abs() < 1e-12);
        // Clamped beyond the edge centres; repeat blends 3 with 0.
        assert_eq!(t.eval(DVec2::new(0.0, 0.5))[0], 0.0);
        let r = ramp(Filter::Bilinear, Wrap::Repeat);
        assert!((r.eval(DVec2::new(1.0, 0.5))[0] - 1.5).abs() < 1e-12);
        let n = ramp(Filter::Nearest, Wrap::Repeat);
        assert_eq!(n.eval(DVec2::new(0.99, 0.0))[0], 3.0);
        assert_eq!(n.eval(DVec2::new(1.01, 0.0))[0], 0.0);
        assert_eq!(n.eval(DVec2::new(f64::NAN, 0.0))[0], 0.0);
        assert_eq!(t.mean(), [1.5; 3]);
    }

    #[test]
    fn refuses_bad_texels() {
        assert!(Texture::new(2, 2, vec![[0.0; 3]; 3], [Wrap::Repeat; 2], Filter::Nearest).is_err());
        assert!(
            Texture::new(
                1,
                1,
                vec![[f32::NAN; 3]],
                [Wrap::Repeat; 2],
                Filter::Nearest
            )
            .is_err()
        );
    }
}
