//! Shading normals from textures: a normal map or a bump map turns the
//! shading normal at a point before its BSDF is evaluated, exactly as their
//! owners define it. Only the render reads them; the solve keeps the
//! geometric normal.
//!
//! At a point with shading normal n (front side), geometric normal n_g and
//! the partial derivatives ∂p/∂u, ∂p/∂v of the surface in its texture
//! coordinates, the *tangent frame* is (Mitsuba 3's
//! `SurfaceInteraction::initialize_sh_frame`, the glTF sample viewer's
//! tangents without a `TANGENT` attribute)
//!
//! ```text
//! s = normalize(∂p/∂u − n (n·∂p/∂u)),  t = n × s
//! ```
//!
//! (any orthonormal s, t about n where ∂p/∂u is unknown). Then:
//!
//! - **Normal map** (Mitsuba 3's `normalmap`, glTF's `normalTexture`):
//!   the texture's RGB is a normal in the tangent frame,
//!   n_l = (2·rgb − 1) ⊙ (k, k, 1) with glTF's `scale` k (1 for Mitsuba),
//!   normalised (green is t: "up" in glTF's convention).
//! - **Bump map** (Mitsuba 3's `bumpmap`): the luminance h of the texture
//!   is a height field; with ∇h = `scale`·(∂h/∂u, ∂h/∂v)
//!   ([`Texture::luminance_gradient`]) the perturbed partials are
//!   ∂p/∂u' = ∂p/∂u + n (∂h/∂u − n·∂p/∂u) (and the same for v), the
//!   normal n_b = normalize(∂p/∂u' × ∂p/∂v'), turned to the side of n_g,
//!   and n_l its coordinates in the tangent frame.
//!
//! Mitsuba (`flip_invalid_normals`, on by default, in both plugins) then
//! mirrors n_l across the normal when it faces away from the viewer
//! direction ω_o as seen in the tangent frame: where
//! (ω_o·n)(ω_o·n_l) ≤ 0, n_l = (−x, −y, z). glTF has no such rule.
//! The shading normal is the tangent frame's n_l in world space.

use std::sync::Arc;

use glam::{DVec2, DVec3};
use serde::Serialize;

use crate::frame::Frame;
use crate::texture::{Texture, UvTransform};

/// How a texture turns the shading normal (module docs).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub enum NormalPerturbation {
    /// A tangent-space normal n_l = (2·rgb − 1) ⊙ (`scale`, `scale`, 1);
    /// `flip` is Mitsuba's `flip_invalid_normals`.
    Normal {
        /// glTF's `normalTexture.scale` (1 for Mitsuba).
        scale: f64,
        /// Mitsuba's `flip_invalid_normals` (glTF: false).
        flip: bool,
    },
    /// A height field: the luminance times `scale` (Mitsuba's `bumpmap`).
    Bump {
        /// Mitsuba's `scale` (1 by default).
        scale: f64,
        /// Mitsuba's `flip_invalid_normals`.
        flip: bool,
    },
}

/// A texture that turns the shading normal of a material (module docs).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct NormalMap {
    /// How its values turn the normal.
    pub perturbation: NormalPerturbation,
    /// The image (linear values).
    #[serde(serialize_with = "texture_summary")]
    pub texture: Arc<Texture>,
    /// The map from the surface's texture coordinates to the image's.
    pub to_uv: UvTransform,
}

fn texture_summary<S: serde::Serializer>(t: &Arc<Texture>, s: S) -> Result<S::Ok, S::Error> {
    t.as_ref().serialize(s)
}

/// The differential geometry at a point that a [`NormalMap`] needs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TangentFrame {
    /// Unit shading normal, front side.
    pub n: DVec3,
    /// Unit geometric normal, front side.
    pub ng: DVec3,
    /// ∂p/∂u and ∂p/∂v, the surface's partial derivatives in its texture
    /// coordinates (`None` where they are not defined).
    pub dp_duv: Option<(DVec3, DVec3)>,
}

impl TangentFrame {
    /// The orthonormal frame (s, t, n) of the module docs.
    pub fn frame(&self) -> Frame {
        let s = self
            .dp_duv
            .and_then(|(du, _)| (du - self.n * self.n.dot(du)).try_normalize());
        match s {
            Some(s) => Frame {
                s,
                t: self.n.cross(s),
                n: self.n,
            },
            None => Frame::from_normal(self.n),
        }
    }
}

impl NormalMap {
    /// The shading normal (unit, world space, front side) at texture
    /// coordinates `uv` of the point `at`, seen from the unit viewer
    /// direction `wo` (module docs). `at.n` where the map gives no normal
    /// (a texel of 2·rgb − 1 = 0).
    pub fn perturb(&self, at: &TangentFrame, uv: DVec2, wo: DVec3) -> DVec3 {
        let frame = at.frame();
        let (local, flip) = match self.perturbation {
            NormalPerturbation::Normal { scale, flip } => {
                let rgb = self.texture.eval(self.to_uv.apply(uv));
                let n = DVec3::new(
                    scale * (2.0 * rgb[0] - 1.0),
                    scale * (2.0 * rgb[1] - 1.0),
                    2.0 * rgb[2] - 1.0,
                );
                (n, flip)
            }
            NormalPerturbation::Bump { scale, flip } => {
                (frame.to_local(self.bumped(at, uv, scale)), flip)
            }
        };
        let Some(mut local) = local.try_normalize() else {
            return at.n;
        };
        let wo = frame.to_local(wo);
        if flip && wo.z * wo.dot(local) <= 0.0 {
            local = DVec3::new(-local.x, -local.y, local.z);
        }
        // Unit already (an orthonormal frame), as in Mitsuba: the identity
        // map gives n back bit for bit.
        frame.to_world(local)
    }

    /// The bump-mapped normal n_b (world space; module docs).
    fn bumped(&self, at: &TangentFrame, uv: DVec2, scale: f64) -> DVec3 {
        let n = at.n;
        let (du, dv) = at.dp_duv.unwrap_or_else(|| {
            let f = Frame::from_normal(n);
            (f.s, f.t)
        });
        let grad = scale * self.texture.luminance_gradient(uv, &self.to_uv);
        let du = du + n * (grad.x - n.dot(du));
        let dv = dv + n * (grad.y - n.dot(dv));
        let nb = du.cross(dv).try_normalize().unwrap_or(n);
        if at.ng.dot(nb) < 0.0 { -nb } else { nb }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::texture::{Filter, Wrap};

    fn constant(rgb: [f32; 3]) -> Arc<Texture> {
        Arc::new(Texture::new(1, 1, vec![rgb], [Wrap::Repeat; 2], Filter::Bilinear).unwrap())
    }

    fn plane() -> TangentFrame {
        TangentFrame {
            n: DVec3::Z,
            ng: DVec3::Z,
            dp_duv: Some((DVec3::X * 2.0, DVec3::Y * 3.0)),
        }
    }

    fn normal_map(rgb: [f32; 3], scale: f64, flip: bool) -> NormalMap {
        NormalMap {
            perturbation: NormalPerturbation::Normal { scale, flip },
            texture: constant(rgb),
            to_uv: UvTransform::IDENTITY,
        }
    }

    /// (0.5, 0.5, 1) is the normal itself, bit for bit (0.5 is exact).
    #[test]
    fn the_identity_map_changes_nothing() {
        let n = DVec3::new(0.3, -0.2, 0.9).normalize();
        let at = TangentFrame {
            n,
            ng: DVec3::Z,
            dp_duv: Some((DVec3::new(1.0, 0.2, 0.0), DVec3::Y)),
        };
        let map = normal_map([0.5, 0.5, 1.0], 1.0, true);
        let wo = DVec3::new(0.1, 0.4, 0.8).normalize();
        assert_eq!(map.perturb(&at, DVec2::new(0.3, 0.7), wo), n);
    }

    /// Red tilts the normal towards ∂p/∂u, green towards n × ∂p/∂u; glTF's
    /// scale multiplies both.
    #[test]
    fn the_map_is_a_normal_in_the_tangent_frame() {
        let wo = DVec3::Z;
        // rgb = (1, 0.5, 1): n_l = (1, 0, 1)/√2, 45° towards +x.
        let p = normal_map([1.0, 0.5, 1.0], 1.0, true).perturb(&plane(), DVec2::ZERO, wo);
        assert!((p - DVec3::new(1.0, 0.0, 1.0).normalize()).length() < 1e-7);
        let p = normal_map([0.5, 1.0, 1.0], 0.5, false).perturb(&plane(), DVec2::ZERO, wo);
        assert!((p - DVec3::new(0.0, 0.5, 1.0).normalize()).length() < 1e-7);
    }

    /// Mitsuba's flip: a normal leaning away from the viewer is mirrored
    /// across n (x and y negated); without the flip it stays.
    #[test]
    fn normals_facing_away_from_the_viewer_are_mirrored() {
        // n_l ∝ (−1, 0, 0.05): beyond 87°, a viewer from +x sees its back.
        let rgb = [0.0, 0.5, 0.525];
        let wo = DVec3::new(1.0, 0.0, 0.2).normalize();
        let p = normal_map(rgb, 1.0, true).perturb(&plane(), DVec2::ZERO, wo);
        assert!(p.x > 0.99, "{p}");
        let q = normal_map(rgb, 1.0, false).perturb(&plane(), DVec2::ZERO, wo);
        assert!(q.x < -0.99, "{q}");
    }

    /// A linear height ramp h = a·u tilts the normal to
    /// normalize(−a·∂p/∂u/|∂p/∂u|² …): for ∂p/∂u = 2x̂, ∂p/∂v = 3ŷ,
    /// ∂p/∂u' = (2, 0, a), ∂p/∂v' = (0, 3, 0), n_b ∝ (−3a, 0, 6).
    #[test]
    fn a_height_ramp_tilts_as_its_slope() {
        // 4 × 1 texels 0, 0.25, 0.5, 0.75 (raw): ∂h/∂u = 0.25·4 = 1 between
        // texel centres.
        let texels = (0..4).map(|i| [i as f32 * 0.25; 3]).collect();
        let tex = Texture::new(4, 1, texels, [Wrap::Clamp; 2], Filter::Bilinear).unwrap();
        let scale = 0.7;
        let map = NormalMap {
            perturbation: NormalPerturbation::Bump { scale, flip: true },
            texture: Arc::new(tex),
            to_uv: UvTransform::IDENTITY,
        };
        let p = map.perturb(&plane(), DVec2::new(0.5, 0.5), DVec3::Z);
        let a = scale * 1.0;
        let expected = DVec3::new(-3.0 * a, 0.0, 6.0).normalize();
        assert!((p - expected).length() < 1e-12, "{p} {expected}");
        // A constant height changes nothing.
        let flat = NormalMap {
            texture: constant([0.3; 3]),
            ..map
        };
        assert_eq!(
            flat.perturb(&plane(), DVec2::new(0.5, 0.5), DVec3::Z),
            DVec3::Z
        );
    }
}
