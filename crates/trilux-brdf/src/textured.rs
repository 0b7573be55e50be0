//! Textured materials: a BSDF whose Lambertian reflectance and glossy
//! weight vary over a surface ([`TexturedBsdf`]), and the material at one
//! point ([`Shading`]).
//!
//! A texture stands for one parameter of a [`BsdfParams`] tree
//! ([`TextureSlot`]): the `reflectance` of a `diffuse`, the
//! `specular_reflectance` of a `roughconductor` or the `weight` of a
//! `blendbsdf`, found by its [`Branch`] path from the top of the tree. The
//! parameter's value at a point is `offset + scale ⊙ texture(u, v)`
//! (a weight takes the luminance); the tree itself holds the *nominal*
//! value, the one at the texture's mean, so that [`Bsdf::new`] of the
//! tree is the material on average.
//!
//! Every supported parameter enters the BRDF linearly, so one side of a
//! textured material at a point x is
//!
//! ```text
//! fr(x; wi, wo) = ρ_d(x)/π + g(x) ⊙ fr_glossy(wi, wo)
//! ```
//!
//! with ρ_d(x) its Lambertian reflectance and g(x) the ratio of its glossy
//! weight to the nominal one (per band), provided each side has at most one
//! `roughconductor` (checked by [`TexturedBsdf::new`]): the microfacet
//! lobe's shape never varies, only how much of it there is. The solver
//! takes ρ_d and g of each element's average slot values; the renderer
//! takes them at each hit. A slot may be the product of two lookups
//! ([`SlotFactor`]): still linear in each, and an element's average of it
//! is the average of the product.
//!
//! The one exception to a fixed shape is a [`SlotKind::Roughness`] slot
//! (glTF's roughness, α = max(r², 0.01)): the renderer's material at a hit
//! ([`TexturedBsdf::at`]) is the nominal one with that point's α; the
//! solver keeps the nominal α, the one at the texture's mean roughness
//! (docs/gltf.md, "Metalness and roughness textures").

use std::borrow::Cow;

use glam::{DVec2, DVec3};
use trilux_color::{ColorParam, Role, Spectrum};
use trilux_frame::{Side, Sided};

use crate::bsdf::{Bsdf, BsdfSample};
use crate::error::BrdfError;
use crate::params::BsdfParams;
pub use crate::slot::{Branch, MIN_GLTF_ALPHA, SlotFactor, SlotKind, TextureSlot, gltf_alpha};

/// Most textures one material takes.
pub const MAX_SLOTS: usize = 4;

/// The values of a material's slots at a point (or averaged over an
/// element), in slot order: RGB for colours, the luminance in every
/// channel for weights.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SlotValues(pub [[f64; 3]; MAX_SLOTS]);

/// One side's Lambertian reflectance ρ_d and glossy ratio g at a point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointParts<const N: usize> {
    /// ρ_d (fr_d = ρ_d/π).
    pub rho: Spectrum<N>,
    /// The glossy weight over the nominal one, per band.
    pub glossy: Spectrum<N>,
}

#[derive(Clone, Debug, PartialEq)]
enum Value<const N: usize> {
    Const(Spectrum<N>),
    Slot(usize),
}

#[derive(Clone, Debug, PartialEq)]
enum Node<const N: usize> {
    Diffuse(Value<N>),
    Conductor(Value<N>),
    /// A plastic: ρ_d = scale ⊙ ρ' + fixed with ρ' = d/(1 − F_dr), or
    /// d/(1 − d F_dr) when `nonlinear` (d the diffuse reflectance), glossy
    /// weight `glossy`.
    Plastic {
        diffuse: Value<N>,
        scale: Spectrum<N>,
        fixed: Spectrum<N>,
        glossy: Spectrum<N>,
        fdr: f64,
        nonlinear: bool,
    },
    Blend {
        weight: Value<N>,
        first: Box<Node<N>>,
        second: Box<Node<N>>,
    },
}

impl<const N: usize> Node<N> {
    fn value(v: &Value<N>, slots: &[Spectrum<N>]) -> Spectrum<N> {
        match v {
            Value::Const(s) => *s,
            Value::Slot(i) => slots[*i],
        }
    }

    /// (ρ_d, glossy weight) of this side for the slot values.
    fn parts(&self, slots: &[Spectrum<N>]) -> (Spectrum<N>, Spectrum<N>) {
        match self {
            Node::Diffuse(v) => (Self::value(v, slots), Spectrum::zero()),
            Node::Conductor(v) => (Spectrum::zero(), Self::value(v, slots)),
            Node::Plastic {
                diffuse,
                scale,
                fixed,
                glossy,
                fdr,
                nonlinear,
            } => {
                let d = Self::value(diffuse, slots);
                let base = Spectrum::from_fn(|b| {
                    let denom = 1.0 - if *nonlinear { d[b] * fdr } else { *fdr };
                    d[b] / denom
                });
                (base * *scale + *fixed, *glossy)
            }
            Node::Blend {
                weight,
                first,
                second,
            } => {
                let w = Self::value(weight, slots);
                let one_minus = Spectrum::splat(1.0) - w;
                let (r1, g1) = first.parts(slots);
                let (r2, g2) = second.parts(slots);
                (r1 * one_minus + r2 * w, g1 * one_minus + g2 * w)
            }
        }
    }

    fn conductors(&self) -> usize {
        match self {
            Node::Diffuse(_) => 0,
            Node::Conductor(_) => 1,
            Node::Plastic { glossy, .. } => usize::from(!glossy.is_black()),
            Node::Blend { first, second, .. } => first.conductors() + second.conductors(),
        }
    }
}

/// A material with textures (module docs): its nominal [`Bsdf`], and
/// how its slots make ρ_d and g at a point.
#[derive(Clone, Debug)]
pub struct TexturedBsdf<const N: usize> {
    bsdf: Bsdf<N>,
    sides: Sided<Option<Node<N>>>,
    slots: Vec<TextureSlot>,
    nominal_glossy: Sided<Spectrum<N>>,
    /// The roughness slot, if any, and the sides whose conductor it sets.
    roughness: Option<(usize, Sided<bool>)>,
}

fn color<const N: usize>(c: &ColorParam, what: &'static str) -> Result<Spectrum<N>, BrdfError> {
    c.to_spectrum::<N>(Role::Reflectance)
        .map_err(|source| BrdfError::Color { what, source })
}

/// The compiled side of `p` at `path`; `slots` found on the way are
/// replaced by their indices.
fn compile<const N: usize>(
    p: &BsdfParams,
    path: &mut Vec<Branch>,
    slots: &[TextureSlot],
    used: &mut [bool],
) -> Result<Node<N>, BrdfError> {
    let slot = |kind: SlotKind, path: &[Branch], used: &mut [bool]| {
        let i = slots
            .iter()
            .position(|s| s.kind == kind && s.path.as_slice() == path)?;
        used[i] = true;
        Some(Value::Slot(i))
    };
    Ok(match p {
        BsdfParams::Diffuse { reflectance } => {
            Node::Diffuse(match slot(SlotKind::Reflectance, path, used) {
                Some(v) => v,
                None => Value::Const(color(reflectance, "diffuse reflectance")?),
            })
        }
        BsdfParams::RoughConductor(rc) => {
            // A roughness slot changes the lobe's shape, not ρ_d or g:
            // `TexturedBsdf::at` takes it.
            let _ = slot(SlotKind::Roughness, path, used);
            Node::Conductor(match slot(SlotKind::SpecularReflectance, path, used) {
                Some(v) => v,
                None => Value::Const(color(
                    &rc.specular_reflectance,
                    "roughconductor specular_reflectance",
                )?),
            })
        }
        BsdfParams::Plastic(pp) => {
            let diffuse = slot(SlotKind::Reflectance, path, used);
            plastic_node(pp, diffuse)?
        }
        BsdfParams::Blend {
            weight,
            first,
            second,
        } => {
            let w = match slot(SlotKind::Weight, path, used) {
                Some(v) => v,
                None => Value::Const(Spectrum::splat(*weight)),
            };
            path.push(Branch::First);
            let first = compile(first, path, slots, used)?;
            path.pop();
            path.push(Branch::Second);
            let second = compile(second, path, slots, used)?;
            path.pop();
            Node::Blend {
                weight: w,
                first: Box::new(first),
                second: Box::new(second),
            }
        }
        BsdfParams::TwoSided { .. } => return Err(BrdfError::NestedTwoSided),
    })
}

/// A plastic's node: ρ_d per unit ρ' (the base's T̄²/η²), the fixed part
/// (the smooth coat's mirror albedo), the glossy weight (its specular
/// reflectance when the coat is rough) and F_dr. ρ_d is not linear in a
/// `nonlinear` plastic's texture: the solve takes it at the element's
/// average reflectance, the render at each hit.
fn plastic_node<const N: usize>(
    pp: &crate::params::PlasticParams,
    diffuse: Option<Value<N>>,
) -> Result<Node<N>, BrdfError> {
    let p: crate::plastic::Plastic<N> = crate::bsdf::plastic(pp)?;
    let t = p.mean_transmittance();
    let scale = Spectrum::splat(t * t / (p.eta * p.eta));
    let fixed = if p.coat.is_none() {
        p.specular_reflectance * (1.0 - t)
    } else {
        Spectrum::zero()
    };
    let glossy = if p.coat.is_some() {
        p.specular_reflectance
    } else {
        Spectrum::zero()
    };
    let diffuse = match diffuse {
        Some(v) => v,
        None => Value::Const(color(
            &pp.diffuse_reflectance,
            "plastic diffuse_reflectance",
        )?),
    };
    Ok(Node::Plastic {
        diffuse,
        scale,
        fixed,
        glossy,
        fdr: p.internal_reflectance(),
        nonlinear: pp.nonlinear,
    })
}

/// Writes `value` into the parameter `kind` of the BSDF at `path`
/// (`None` when there is no such parameter).
fn set_nominal(p: &mut BsdfParams, path: &[Branch], kind: SlotKind, value: [f64; 3]) -> Option<()> {
    match (p, path.split_first()) {
        (BsdfParams::Diffuse { reflectance }, None) if kind == SlotKind::Reflectance => {
            *reflectance = ColorParam::Rgb(value);
        }
        (BsdfParams::Plastic(pp), None) if kind == SlotKind::Reflectance => {
            pp.diffuse_reflectance = ColorParam::Rgb(value);
        }
        (BsdfParams::RoughConductor(rc), None) if kind == SlotKind::SpecularReflectance => {
            rc.specular_reflectance = ColorParam::Rgb(value);
        }
        (BsdfParams::RoughConductor(rc), None) if kind == SlotKind::Roughness => {
            rc.alpha = gltf_alpha(value[0]);
        }
        (BsdfParams::Blend { weight, .. }, None) if kind == SlotKind::Weight => *weight = value[0],
        (BsdfParams::Blend { first, .. }, Some((Branch::First, rest))) => {
            set_nominal(first, rest, kind, value)?;
        }
        (BsdfParams::Blend { second, .. }, Some((Branch::Second, rest))) => {
            set_nominal(second, rest, kind, value)?;
        }
        (BsdfParams::TwoSided { front, .. }, Some((Branch::Front, rest))) => {
            set_nominal(front, rest, kind, value)?;
        }
        (
            BsdfParams::TwoSided {
                back: Some(back), ..
            },
            Some((Branch::Back, rest)),
        ) => {
            set_nominal(back, rest, kind, value)?;
        }
        _ => return None,
    }
    Some(())
}

impl<const N: usize> TexturedBsdf<N> {
    /// The material `params` with the textures `slots` (each textured
    /// parameter's value in `params` is replaced by its nominal value). Refused: more than [`MAX_SLOTS`]
    /// slots, a slot whose path or kind names no parameter, a side with
    /// textures and more than one `roughconductor`, and band counts other
    /// than 3 (textures are RGB; a spectral solve would upsample every
    /// lookup).
    pub fn new(params: &BsdfParams, slots: Vec<TextureSlot>) -> Result<Self, BrdfError> {
        if N != 3 {
            return Err(BrdfError::TexturedSpectral);
        }
        if slots.len() > MAX_SLOTS {
            return Err(BrdfError::TooManyTextures(slots.len()));
        }
        let mut params = params.clone();
        for (i, slot) in slots.iter().enumerate() {
            let nominal = slot.nominal();
            set_nominal(&mut params, &slot.path, slot.kind, nominal).ok_or_else(|| {
                BrdfError::TextureSlot(format!("{:?} at {:?}", slots[i].kind, slots[i].path))
            })?;
        }
        let params = &params;
        let bsdf = Bsdf::new(params)?;
        let mut used = vec![false; slots.len()];
        let (front, back) = match params {
            BsdfParams::TwoSided { front, back } => {
                let f = compile(front, &mut vec![Branch::Front], &slots, &mut used)?;
                let b = match back {
                    Some(b) => compile(b, &mut vec![Branch::Back], &slots, &mut used)?,
                    None => f.clone(),
                };
                (Some(f), Some(b))
            }
            other => (
                Some(compile(other, &mut Vec::new(), &slots, &mut used)?),
                None,
            ),
        };
        if let Some(i) = used.iter().position(|u| !u) {
            return Err(BrdfError::TextureSlot(format!(
                "{:?} at {:?}",
                slots[i].kind, slots[i].path
            )));
        }
        let sides = Sided { front, back };
        for (_, node) in sides.iter() {
            if node.as_ref().is_some_and(|n| n.conductors() > 1) {
                return Err(BrdfError::TexturedConductors);
            }
        }
        let roughness = roughness_sides(params, &slots);
        let mut t = TexturedBsdf {
            bsdf,
            sides,
            slots,
            nominal_glossy: Sided::from_fn(|_| Spectrum::zero()),
            roughness,
        };
        let nominal = t.nominal_values();
        t.nominal_glossy = Sided::from_fn(|side| {
            t.sides[side]
                .as_ref()
                .map_or(Spectrum::zero(), |n| n.parts(&t.spectra(&nominal)).1)
        });
        Ok(t)
    }

    /// The nominal material (every textured parameter at the texture's
    /// mean).
    pub fn bsdf(&self) -> &Bsdf<N> {
        &self.bsdf
    }

    /// The textures.
    pub fn slots(&self) -> &[TextureSlot] {
        &self.slots
    }

    /// The slot values at the textures' means.
    pub fn nominal_values(&self) -> SlotValues {
        let mut v = [[0.0; 3]; MAX_SLOTS];
        for (i, s) in self.slots.iter().enumerate() {
            v[i] = s.nominal();
        }
        SlotValues(v)
    }

    /// Every slot's value at texture coordinates `uv`.
    pub fn values_at(&self, uv: DVec2) -> SlotValues {
        let mut v = [[0.0; 3]; MAX_SLOTS];
        for (i, s) in self.slots.iter().enumerate() {
            v[i] = s.at(uv);
        }
        SlotValues(v)
    }

    fn spectra(&self, v: &SlotValues) -> [Spectrum<N>; MAX_SLOTS] {
        // N = 3 (checked by `new`): RGB is the spectrum.
        v.0.map(|rgb| Spectrum::from_fn(|b| rgb.get(b).copied().unwrap_or(0.0)))
    }

    /// ρ_d and g of both sides for slot values `v` (a point's, or an
    /// element's average).
    pub fn parts(&self, v: &SlotValues) -> Sided<PointParts<N>> {
        let spectra = self.spectra(v);
        Sided::from_fn(|side| match &self.sides[side] {
            None => PointParts {
                rho: Spectrum::zero(),
                glossy: Spectrum::zero(),
            },
            Some(node) => {
                let (rho, gw) = node.parts(&spectra);
                let nominal = self.nominal_glossy[side];
                let glossy = Spectrum::from_fn(|b| {
                    if nominal[b] > 0.0 {
                        gw[b] / nominal[b]
                    } else {
                        0.0
                    }
                });
                PointParts { rho, glossy }
            }
        })
    }

    /// The material at texture coordinates `uv`: ρ_d and g of the point's
    /// slot values and, with a roughness slot, the nominal material with
    /// the point's α = max(r², 0.01) (the lobe's shape at that point).
    pub fn at(&self, uv: DVec2) -> Shading<'_, N> {
        let values = self.values_at(uv);
        let bsdf = match &self.roughness {
            Some((i, sides)) => {
                Cow::Owned(self.bsdf.with_alpha(sides, gltf_alpha(values.0[*i][0])))
            }
            None => Cow::Borrowed(&self.bsdf),
        };
        Shading {
            bsdf,
            parts: Some(self.parts(&values)),
        }
    }
}

/// The roughness slot of `slots` and the sides of `params` its path
/// reaches: a `twosided` without a back has its front on both sides.
fn roughness_sides(params: &BsdfParams, slots: &[TextureSlot]) -> Option<(usize, Sided<bool>)> {
    let i = slots.iter().position(|s| s.kind == SlotKind::Roughness)?;
    let sides = match (params, slots[i].path.first()) {
        (BsdfParams::TwoSided { back: None, .. }, Some(Branch::Front)) => Sided {
            front: true,
            back: true,
        },
        (BsdfParams::TwoSided { .. }, Some(Branch::Back)) => Sided {
            front: false,
            back: true,
        },
        _ => Sided {
            front: true,
            back: false,
        },
    };
    Some((i, sides))
}

/// The material at one point: a [`Bsdf`], with the point's ρ_d and g when
/// the material is textured (module docs). Its methods are [`Bsdf`]'s.
#[derive(Clone, Debug)]
pub struct Shading<'a, const N: usize> {
    bsdf: Cow<'a, Bsdf<N>>,
    parts: Option<Sided<PointParts<N>>>,
}

impl<'a, const N: usize> Shading<'a, N> {
    /// An untextured material, the same everywhere.
    pub fn uniform(bsdf: &'a Bsdf<N>) -> Self {
        Shading {
            bsdf: Cow::Borrowed(bsdf),
            parts: None,
        }
    }

    /// The nominal material with the parts `parts` (an element's).
    pub fn with_parts(bsdf: &'a Bsdf<N>, parts: Sided<PointParts<N>>) -> Self {
        Shading {
            bsdf: Cow::Borrowed(bsdf),
            parts: Some(parts),
        }
    }

    /// The side that reflects towards viewer `wo` when light comes from
    /// `wi` (local frame), if any.
    fn reflecting(wi: DVec3, wo: DVec3) -> Option<Side> {
        match Side::of_local(wo)? {
            Side::Front if wi.z > 0.0 => Some(Side::Front),
            Side::Back if wi.z < 0.0 => Some(Side::Back),
            _ => None,
        }
    }

    /// fr(wi, wo), without the cosine.
    pub fn eval(&self, wi: DVec3, wo: DVec3) -> Spectrum<N> {
        let Some(parts) = &self.parts else {
            return self.bsdf.eval(wi, wo);
        };
        match Self::reflecting(wi, wo) {
            Some(side) if !self.bsdf.is_black(side) => {
                let p = parts[side];
                p.rho * std::f64::consts::FRAC_1_PI + self.bsdf.eval_glossy(wi, wo) * p.glossy
            }
            _ => Spectrum::zero(),
        }
    }

    /// The non-Lambertian part of fr(wi, wo).
    pub fn eval_glossy(&self, wi: DVec3, wo: DVec3) -> Spectrum<N> {
        let g = self.bsdf.eval_glossy(wi, wo);
        match (&self.parts, Side::of_local(wo)) {
            (Some(parts), Some(side)) => g * parts[side].glossy,
            _ => g,
        }
    }

    /// fr less its Lambertian part (see [`Bsdf::eval_non_lambertian`]): at
    /// a textured point, the glossy part times g plus the nominal
    /// material's non-Lambertian base term (a plastic's) scaled by the
    /// point's ρ_d over the nominal ρ_d.
    pub fn eval_non_lambertian(&self, wi: DVec3, wo: DVec3) -> Spectrum<N> {
        let all = self.bsdf.eval_non_lambertian(wi, wo);
        let (Some(parts), Some(side)) = (&self.parts, Self::reflecting(wi, wo)) else {
            return all;
        };
        let g = self.bsdf.eval_glossy(wi, wo);
        let nominal = self.bsdf.diffuse_albedo(side);
        let p = parts[side];
        let ratio = Spectrum::from_fn(|b| {
            if nominal[b] > 0.0 {
                p.rho[b] / nominal[b]
            } else {
                0.0
            }
        });
        g * p.glossy + (all - g) * ratio
    }

    /// The Lambertian reflectance ρ_d on `side`.
    pub fn diffuse_albedo(&self, side: Side) -> Spectrum<N> {
        match &self.parts {
            Some(parts) if !self.bsdf.is_black(side) => parts[side].rho,
            Some(_) => Spectrum::zero(),
            None => self.bsdf.diffuse_albedo(side),
        }
    }

    /// True when `side` has a non-Lambertian part.
    pub fn has_glossy(&self, side: Side) -> bool {
        self.bsdf.has_glossy(side)
    }

    /// The smallest roughness α of a conductor part of `side`.
    pub fn min_alpha(&self, side: Side) -> Option<f64> {
        self.bsdf.min_alpha(side)
    }

    /// Samples wi for viewer `wo` from the nominal material's density,
    /// weighted by this point's fr (see [`Bsdf::sample`]).
    pub fn sample(&self, wo: DVec3, u: DVec2) -> Option<BsdfSample<N>> {
        let s = self.bsdf.sample(wo, u)?;
        if self.parts.is_none() {
            return Some(s);
        }
        let weight = self.eval(s.wi, wo) * (s.wi.z.abs() / s.pdf);
        weight.is_finite().then_some(BsdfSample { weight, ..s })
    }

    /// The density of [`Shading::sample`] (the nominal material's).
    pub fn pdf(&self, wo: DVec3, wi: DVec3) -> f64 {
        self.bsdf.pdf(wo, wi)
    }

    /// Directional albedo for viewer `wo`: ρ_d + g ⊙ the nominal glossy
    /// albedo.
    pub fn albedo(&self, wo: DVec3) -> Spectrum<N> {
        let a = self.bsdf.albedo(wo);
        match (&self.parts, Side::of_local(wo)) {
            (Some(parts), Some(side)) => {
                let glossy = (a - self.bsdf.diffuse_albedo(side)).max(Spectrum::zero());
                self.diffuse_albedo(side) + glossy * parts[side].glossy
            }
            _ => a,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::{Distribution, RoughConductorParams};
    use crate::texture::{Filter, Texture, UvTransform, Wrap};
    use std::sync::Arc;

    fn checker() -> Arc<Texture> {
        // 2 × 1: black, white.
        Arc::new(
            Texture::new(
                2,
                1,
                vec![[0.0; 3], [1.0; 3]],
                [Wrap::Repeat; 2],
                Filter::Nearest,
            )
            .unwrap(),
        )
    }

    fn blend(weight: f64, rho: f64, s: f64) -> BsdfParams {
        BsdfParams::Blend {
            weight,
            first: Box::new(BsdfParams::Diffuse {
                reflectance: ColorParam::Float(rho),
            }),
            second: Box::new(BsdfParams::RoughConductor(RoughConductorParams {
                distribution: Distribution::Ggx,
                alpha: 0.3,
                eta_k: None,
                specular_reflectance: ColorParam::Float(s),
            })),
        }
    }

    fn slot(path: Vec<Branch>, kind: SlotKind, scale: f64) -> TextureSlot {
        TextureSlot {
            path,
            kind,
            texture: checker(),
            scale: [scale; 3],
            offset: [0.0; 3],
            to_uv: UvTransform::IDENTITY,
            factor: None,
            max: 1.0,
        }
    }

    /// A textured point is the untextured material with the texture's value
    /// written in: ρ_d, fr and the albedo agree with `Bsdf` built from the
    /// point's parameters.
    #[test]
    fn a_point_is_the_material_with_its_values() {
        let slots = vec![
            slot(vec![Branch::First], SlotKind::Reflectance, 0.8),
            slot(vec![Branch::Second], SlotKind::SpecularReflectance, 0.6),
        ];
        // Nominal: the mean 0.5 of the texture times the scale.
        let t: TexturedBsdf<3> = TexturedBsdf::new(&blend(0.4, 0.4, 0.3), slots).unwrap();
        let white = DVec2::new(0.75, 0.5);
        let black = DVec2::new(0.25, 0.5);
        let direct: Bsdf<3> = Bsdf::new(&blend(0.4, 0.8, 0.6)).unwrap();
        let at = t.at(white);
        let (wi, wo) = (
            DVec3::new(0.3, 0.1, 0.9).normalize(),
            DVec3::new(-0.2, 0.0, 1.0).normalize(),
        );
        let (a, b) = (at.eval(wi, wo), direct.eval(wi, wo));
        assert!((a.0[0] - b.0[0]).abs() < 1e-12 * b.0[0], "{a:?} {b:?}");
        assert!((at.diffuse_albedo(Side::Front).0[1] - 0.6 * 0.8).abs() < 1e-12);
        let (a, b) = (at.albedo(wo), direct.albedo(wo));
        assert!((a.0[2] - b.0[2]).abs() < 1e-9, "{a:?} {b:?}");
        let dark = t.at(black);
        assert_eq!(dark.eval(wi, wo), Spectrum::zero());
        assert!(dark.eval(-wi, wo).is_black(), "no transmission");
    }

    #[test]
    fn weight_textures_move_light_between_parts() {
        let slots = vec![slot(Vec::new(), SlotKind::Weight, 1.0)];
        let t: TexturedBsdf<3> = TexturedBsdf::new(&blend(0.5, 0.5, 1.0), slots).unwrap();
        let p = t.parts(&t.values_at(DVec2::new(0.75, 0.0)));
        assert_eq!(p.front.rho, Spectrum::zero());
        assert!((p.front.glossy.0[0] - 2.0).abs() < 1e-12);
        assert_eq!(p.back.rho, Spectrum::zero());
    }

    /// A slot with a factor is offset + scale ⊙ t + f · (offset' + scale' ⊙ t)
    /// with t and f each looked up with its own mapping: here t of the
    /// black/white checker at u, f of a 2 × 1 texture (0.25, 0.75) at
    /// u + 0.5 (so that the two lookups differ at every point).
    #[test]
    fn a_factor_is_a_second_lookup_multiplying_its_term() {
        let f = Texture::new(
            2,
            1,
            vec![[0.25; 3], [0.75; 3]],
            [Wrap::Repeat; 2],
            Filter::Nearest,
        )
        .unwrap();
        let mut s = slot(Vec::new(), SlotKind::Reflectance, 0.5);
        s.offset = [0.1; 3];
        s.factor = Some(SlotFactor {
            texture: Arc::new(f),
            to_uv: UvTransform([1.0, 0.0, 0.5, 0.0, 1.0, 0.0]),
            scale: [-0.4; 3],
            offset: [0.2; 3],
        });
        // u = 0.25: t = 0, f = 0.75 → 0.1 + 0.75 · 0.2 = 0.25.
        assert!((s.at(DVec2::new(0.25, 0.5))[0] - 0.25).abs() < 1e-12);
        // u = 0.75: t = 1, f = 0.25 → 0.1 + 0.5 + 0.25 · (0.2 − 0.4) = 0.55.
        assert!((s.at(DVec2::new(0.75, 0.5))[1] - 0.55).abs() < 1e-12);
        // Nominal: the means t = 0.5, f = 0.5 → 0.1 + 0.25 + 0.5 · 0.0 = 0.35.
        assert!((s.nominal()[2] - 0.35).abs() < 1e-12);
        // A bound above 1 lets a point pass 1; the nominal stays within 1.
        s.scale = [2.0; 3];
        s.max = 1.5;
        assert!((s.at(DVec2::new(0.75, 0.5))[0] - 1.5).abs() < 1e-12);
        assert!(s.nominal()[0] <= 1.0);
    }

    /// A roughness slot gives each point the α of its roughness,
    /// α = max(r², 0.01) (glTF), and the nominal material the α of the
    /// mean roughness: r = 0.6 t on the checker.
    #[test]
    fn a_roughness_slot_sets_each_points_alpha() {
        let conductor = |alpha: f64| {
            BsdfParams::RoughConductor(RoughConductorParams {
                distribution: Distribution::Ggx,
                alpha,
                eta_k: None,
                specular_reflectance: ColorParam::Float(0.7),
            })
        };
        let t: TexturedBsdf<3> = TexturedBsdf::new(
            &conductor(0.5),
            vec![slot(Vec::new(), SlotKind::Roughness, 0.6)],
        )
        .unwrap();
        // Mean r = 0.3: α = 0.09.
        assert_eq!(t.bsdf().min_alpha(Side::Front), Some(0.3 * 0.3));
        let (wi, wo) = (
            DVec3::new(0.3, 0.1, 0.9).normalize(),
            DVec3::new(-0.2, 0.0, 1.0).normalize(),
        );
        for (u, alpha) in [(0.75, 0.36), (0.25, 0.01)] {
            let at = t.at(DVec2::new(u, 0.5));
            let direct: Bsdf<3> = Bsdf::new(&conductor(alpha)).unwrap();
            let (a, b) = (at.eval(wi, wo), direct.eval(wi, wo));
            assert!(
                (a.0[0] - b.0[0]).abs() <= 1e-12 * b.0[0],
                "{u}: {a:?} {b:?}"
            );
            assert_eq!(at.min_alpha(Side::Front), Some(alpha));
            let (a, b) = (at.albedo(wo), direct.albedo(wo));
            assert!((a.0[1] - b.0[1]).abs() < 1e-9, "{u}: {a:?} {b:?}");
        }
        // On a diffuse part, a roughness slot names no parameter.
        assert!(
            TexturedBsdf::<3>::new(
                &blend(0.5, 0.5, 0.5),
                vec![slot(vec![Branch::First], SlotKind::Roughness, 1.0)]
            )
            .is_err()
        );
    }

    #[test]
    fn refuses_what_it_cannot_represent() {
        let one = || vec![slot(vec![Branch::First], SlotKind::Reflectance, 1.0)];
        let two_conductors = BsdfParams::Blend {
            weight: 0.5,
            first: Box::new(blend(0.5, 0.5, 0.5)),
            second: Box::new(blend(0.5, 0.5, 0.5)),
        };
        assert_eq!(
            TexturedBsdf::<3>::new(
                &two_conductors,
                vec![slot(
                    vec![Branch::First, Branch::First],
                    SlotKind::Reflectance,
                    1.0
                )]
            )
            .err(),
            Some(BrdfError::TexturedConductors)
        );
        assert!(
            TexturedBsdf::<3>::new(
                &blend(0.5, 0.5, 0.5),
                vec![slot(vec![Branch::Second], SlotKind::Reflectance, 1.0)]
            )
            .is_err()
        );
        assert_eq!(
            TexturedBsdf::<20>::new(&blend(0.5, 0.5, 0.5), one()).err(),
            Some(BrdfError::TexturedSpectral)
        );
    }
}
