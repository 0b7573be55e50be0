//! Textured faces in the solve: each element's Lambertian reflectance ρ_d
//! and glossy ratio g (`trilux_brdf::textured`) from the textures'
//! area-weighted average over the element's footprint.
//!
//! - **Leaves** (the finest potential elements): the slot values averaged
//!   over an 8 × 8 grid of points spread uniformly by area, each weighted
//!   by 1/density (exact area weights), then ρ_d and g of that average.
//! - **Parents**: the average of their children's ρ_d and g weighted by
//!   the children's exposed areas, the weights of the radiosity pull, so
//!   that light gathered high up and pushed down keeps its flux.
//! - **Push** (`radiosity`): a link delivers irradiance × ρ_d(j) into
//!   j's gathered radiance; going down to a child c it is scaled by
//!   ρ_d(c)/ρ_d(j), which is pushing the *irradiance* down and reflecting
//!   it with each leaf's own reflectance. A texture that varies within j
//!   is so resolved at the leaves whatever element the link reached, and
//!   Σ_c A_c ρ_d(c)/ρ_d(j) = A_j keeps the flux exact.
//! - **Glossy part**: three-point links at j carry g(j) times the nominal
//!   glossy BRDF; the BRDF criterion adds to fr's spread the share by which
//!   g varies over j's children (`refine`), so elements where a texture
//!   varies are refined as a varying BRDF would be.

use glam::DVec2;
use trilux_brdf::{PointParts, SlotValues, TexturedBsdf, textured::MAX_SLOTS};
use trilux_color::Spectrum;
use trilux_geometry::{ElementForest, ElementId, FaceId, Side, Sided};

use crate::prepared::PreparedScene;

/// Points per side of the grid that averages a leaf's slot values.
const GRID: usize = 8;

/// ρ_d and g of every element of a textured face (module docs).
#[derive(Clone, Debug)]
pub struct ElementTextures<const N: usize> {
    /// By element index: `None` for elements of uniform materials.
    parts: Vec<Option<Sided<PointParts<N>>>>,
}

impl<const N: usize> ElementTextures<N> {
    /// The textures' averages over every element of `forest` (`None` when
    /// no material has textures).
    pub fn new(
        forest: &ElementForest,
        scene: &PreparedScene<N>,
        exposed_area: &Sided<Vec<f64>>,
    ) -> Option<Self> {
        if !scene.has_textures() {
            return None;
        }
        let mut parts = vec![None; forest.element_count()];
        for (s, surface) in forest.geometry().surfaces().iter().enumerate() {
            let Some(t) = scene.textured(surface.shape as usize) else {
                continue;
            };
            let root = forest.root(trilux_geometry::SurfaceId(s as u32));
            fill(forest, t, root, exposed_area, &mut parts);
        }
        Some(ElementTextures { parts })
    }

    /// ρ_d of element `e` on `face`'s side, when `e` is textured.
    #[inline]
    pub fn rho(&self, face: FaceId, e: ElementId) -> Option<Spectrum<N>> {
        self.parts[e.index()].as_ref().map(|p| p[face.side()].rho)
    }

    /// g of element `e` on `face`'s side (1 where it is not textured).
    #[inline]
    pub fn glossy(&self, face: FaceId, e: ElementId) -> Spectrum<N> {
        self.parts[e.index()]
            .as_ref()
            .map_or(Spectrum::splat(1.0), |p| p[face.side()].glossy)
    }

    /// The largest relative difference, over bands and children, between
    /// g of `e` and g of its children (0 for leaves and uniform elements).
    pub fn glossy_variation(&self, forest: &ElementForest, face: FaceId, e: ElementId) -> f64 {
        let (Some(children), Some(_)) = (forest.element(e).children(), &self.parts[e.index()])
        else {
            return 0.0;
        };
        let g = self.glossy(face, e);
        let mut worst: f64 = 0.0;
        for c in children {
            let gc = self.glossy(face, c);
            for b in 0..N {
                let scale = g[b].max(gc[b]);
                if scale > 0.0 {
                    worst = worst.max((gc[b] - g[b]).abs() / scale);
                }
            }
        }
        worst
    }

    /// The factor ρ_d(child)/ρ_d(parent) by which gathered radiance is
    /// pushed from `parent` to `child` on `side` (1 for uniform elements).
    #[inline]
    pub fn push_ratio(&self, side: Side, parent: ElementId, child: ElementId) -> Spectrum<N> {
        match (&self.parts[parent.index()], &self.parts[child.index()]) {
            (Some(p), Some(c)) => {
                let (p, c) = (p[side].rho, c[side].rho);
                Spectrum::from_fn(|b| if p[b] > 0.0 { c[b] / p[b] } else { 0.0 })
            }
            _ => Spectrum::splat(1.0),
        }
    }
}

/// Fills `parts` for `e` and everything below it; returns `e`'s parts.
fn fill<const N: usize>(
    forest: &ElementForest,
    t: &TexturedBsdf<N>,
    e: ElementId,
    exposed_area: &Sided<Vec<f64>>,
    parts: &mut [Option<Sided<PointParts<N>>>],
) -> Sided<PointParts<N>> {
    let p = match forest.element(e).children() {
        None => t.parts(&leaf_average(forest, t, e)),
        Some(children) => {
            let kids = children.map(|c| (c, fill(forest, t, c, exposed_area, parts)));
            Sided::from_fn(|side| {
                let area = |c: ElementId| {
                    let a = exposed_area[side][c.index()];
                    if kids
                        .iter()
                        .any(|(k, _)| exposed_area[side][k.index()] > 0.0)
                    {
                        a
                    } else {
                        forest.element(c).area
                    }
                };
                let total: f64 = kids.iter().map(|(c, _)| area(*c)).sum();
                let mut rho = Spectrum::zero();
                let mut glossy = Spectrum::zero();
                for (c, k) in &kids {
                    let w = if total > 0.0 { area(*c) / total } else { 0.25 };
                    rho += k[side].rho * w;
                    glossy += k[side].glossy * w;
                }
                PointParts { rho, glossy }
            })
        }
    };
    parts[e.index()] = Some(p.clone());
    p
}

/// The slot values of `t` averaged over leaf `e` (module docs).
fn leaf_average<const N: usize>(
    forest: &ElementForest,
    t: &TexturedBsdf<N>,
    e: ElementId,
) -> SlotValues {
    let geometry = forest.geometry();
    let surface = forest.element(e).surface;
    let mut sum = [[0.0; 3]; MAX_SLOTS];
    let mut weight = 0.0;
    for a in 0..GRID {
        for b in 0..GRID {
            let u = DVec2::new(
                (a as f64 + 0.5) / GRID as f64,
                (b as f64 + 0.5) / GRID as f64,
            );
            let s = forest.sample_element(e, u);
            let Some(uv) = geometry.texcoord(surface, s.coord) else {
                continue;
            };
            if !(s.pdf_area > 0.0 && s.pdf_area.is_finite()) {
                continue;
            }
            let w = 1.0 / s.pdf_area;
            let v = t.values_at(uv);
            for (acc, x) in sum.iter_mut().zip(v.0) {
                for c in 0..3 {
                    acc[c] += w * x[c];
                }
            }
            weight += w;
        }
    }
    if weight > 0.0 {
        SlotValues(sum.map(|x| x.map(|c| c / weight)))
    } else {
        t.nominal_values()
    }
}
