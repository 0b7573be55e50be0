//! The ambient term as the solution's readers add it (`crate::ambient`):
//! a lit face of reflectance ρ sends ρ · A_amb more than the stopped solve
//! gave it, its Lambertian part ρ_d · A_amb and its glossy part its glossy
//! albedo times A_amb (uniform incident radiance reflects as the
//! directional albedo). Faces the solve never lit (the outside of a closed
//! room, the inside of a closed box) stay dark.

use glam::{DVec2, DVec3};
use trilux_color::Spectrum;
use trilux_geometry::{ElementForest, ElementId, FaceId, Side, Sided, SurfaceCoord};

use super::{FarRecord, Parts};
use crate::prepared::PreparedScene;

/// Polar angles (degrees) and cosine weights of the glossy albedo's mean
/// over the hemisphere (the midpoint rule in cos² θ).
const ALBEDO_ANGLES: [f64; 4] = [20.705, 37.761, 52.239, 69.295];

/// What the readers need to add the ambient term.
#[derive(Clone, Debug, Default)]
pub(super) struct AmbientTerm<const N: usize> {
    /// Cohen's A_amb per band (zero: no term), used where `local` is not.
    pub radiance: Spectrum<N>,
    /// Whether the readers add it.
    pub on: bool,
    /// Per side and element, the local term's E / (1 − a)
    /// (`crate::local_ambient`): when present it replaces `radiance`. An
    /// element above the leaves holds their exposed-area mean, so a
    /// face's root holds the face's.
    local: Option<Sided<Vec<Spectrum<N>>>>,
    /// Per face index: the solve lit the face.
    lit: Vec<bool>,
    /// Per shape, [front, back]: the glossy part's albedo, averaged over
    /// the hemisphere (zero without a glossy part).
    glossy_albedo: Vec<[Spectrum<N>; 2]>,
}

impl<const N: usize> AmbientTerm<N> {
    /// The term of a solution's parts: the local term when the parts hold
    /// it, else A_amb from its stats (none for a solution saved before the
    /// term existed); the faces it lit.
    pub fn new(p: &Parts<N>, local: Option<Sided<Vec<Spectrum<N>>>>) -> Self {
        let a = &p.stats.ambient.radiance;
        let radiance = if a.len() == N && a.iter().all(|x| x.is_finite() && *x >= 0.0) {
            Spectrum::new(std::array::from_fn(|b| a[b]))
        } else {
            Spectrum::zero()
        };
        let forest = p.discretisation.forest();
        let local = local.filter(|l| {
            Side::BOTH
                .iter()
                .all(|&s| l[s].len() == forest.element_count())
                && Side::BOTH
                    .iter()
                    .any(|&s| l[s].iter().any(|x| x.max_value() > 0.0))
        });
        if radiance.is_black() && local.is_none() {
            return AmbientTerm::default();
        }
        // A face is lit when the solve left light at its root, or the
        // residual's bounces reach it.
        let surfaces = forest.geometry().surfaces().len();
        let mut lit: Vec<bool> = (0..2 * surfaces as u32)
            .map(|k| {
                let face = FaceId(k);
                let root = forest.root(face.surface()).index();
                p.radiance[face.side()][root].max_value() > 0.0
                    || local
                        .as_ref()
                        .is_some_and(|l| l[face.side()][root].max_value() > 0.0)
            })
            .collect();
        for h in &p.hierarchies {
            if h.nodes.iter().any(|n| n.radiance.max_value() > 0.0) {
                lit[h.from.index()] = true;
            }
        }
        for FarRecord { face, blocks } in &p.far {
            if blocks.iter().any(|(_, l)| l.max_value() > 0.0) {
                lit[face.index()] = true;
            }
        }
        AmbientTerm {
            radiance,
            on: true,
            local,
            lit,
            glossy_albedo: p.scene.materials().iter().map(glossy_albedo).collect(),
        }
    }

    /// The local term's per-element values, when the solution has them.
    pub fn local(&self) -> Option<&Sided<Vec<Spectrum<N>>>> {
        self.local.as_ref()
    }

    /// True when the term adds nothing anywhere.
    pub fn is_empty(&self) -> bool {
        self.radiance.is_black() && self.local.is_none()
    }

    /// The term's radiance at element `e` of `face` (before the face's
    /// reflectance).
    fn level(&self, face: FaceId, e: ElementId) -> Spectrum<N> {
        match &self.local {
            Some(l) => l[face.side()]
                .get(e.index())
                .copied()
                .unwrap_or_else(Spectrum::zero),
            None => self.radiance,
        }
    }

    /// The term's radiance over the whole of `face` (its root's: the
    /// exposed-area mean of its leaves).
    fn face_level(&self, forest: &ElementForest, face: FaceId) -> Spectrum<N> {
        self.level(face, forest.root(face.surface()))
    }

    fn active(&self, face: FaceId) -> bool {
        self.on && self.lit.get(face.index()).copied().unwrap_or(false)
    }

    /// ρ_d · A_amb at the point `coord` gives of `face`, in its element
    /// `e` (a textured material is read there; `coord` is called only
    /// then).
    pub fn lambertian(
        &self,
        scene: &PreparedScene<N>,
        face: FaceId,
        e: ElementId,
        coord: impl FnOnce() -> SurfaceCoord,
    ) -> Spectrum<N> {
        if !self.active(face) {
            return Spectrum::zero();
        }
        let shape = scene.geometry().surface(face.surface()).shape as usize;
        let rho = match scene.textured(shape) {
            Some(_) => scene
                .shading(shape, face.surface(), coord())
                .diffuse_albedo(face.side()),
            None => scene.material(shape).diffuse_albedo(face.side()),
        };
        rho * self.level(face, e)
    }

    /// ρ_d · A_amb at element `e` of `face` (read at its middle).
    pub fn lambertian_element(
        &self,
        scene: &PreparedScene<N>,
        forest: &ElementForest,
        face: FaceId,
        e: ElementId,
    ) -> Spectrum<N> {
        self.lambertian(scene, face, e, || {
            forest.sample_element(e, DVec2::splat(0.5)).coord
        })
    }

    /// The glossy part's albedo · A_amb on `face`.
    pub fn glossy(
        &self,
        scene: &PreparedScene<N>,
        forest: &ElementForest,
        face: FaceId,
    ) -> Spectrum<N> {
        if !self.active(face) {
            return Spectrum::zero();
        }
        let shape = scene.geometry().surface(face.surface()).shape as usize;
        let side = usize::from(face.side() == Side::Back);
        self.glossy_albedo.get(shape).map_or(Spectrum::zero(), |a| {
            a[side] * self.face_level(forest, face)
        })
    }
}

/// The glossy part's directional albedo (less ρ_d), averaged over the
/// hemisphere with cosine weights, per side.
pub(crate) fn glossy_albedo<const N: usize>(b: &trilux_brdf::Bsdf<N>) -> [Spectrum<N>; 2] {
    Side::BOTH.map(|side| {
        if !b.has_glossy(side) {
            return Spectrum::zero();
        }
        let sign = if side == Side::Front { 1.0 } else { -1.0 };
        let sum: Spectrum<N> = ALBEDO_ANGLES
            .iter()
            .map(|deg: &f64| {
                let th = deg.to_radians();
                let wo = DVec3::new(th.sin(), 0.0, sign * th.cos());
                (b.albedo(wo) - b.diffuse_albedo(side)).max(Spectrum::zero())
            })
            .sum();
        sum * (1.0 / ALBEDO_ANGLES.len() as f64)
    })
}
