//! The ambient term as the solution's readers add it (`crate::ambient`):
//! a lit face of reflectance ρ sends ρ · A_amb more than the stopped solve
//! gave it, its Lambertian part ρ_d · A_amb and its glossy part its glossy
//! albedo times A_amb (uniform incident radiance reflects as the
//! directional albedo). Faces the solve never lit (the outside of a closed
//! room, the inside of a closed box) stay dark.

use glam::{DVec2, DVec3};
use trilux_color::Spectrum;
use trilux_geometry::{ElementId, FaceId, Side, SurfaceCoord};

use super::{FarRecord, Parts};
use crate::prepared::PreparedScene;

/// Polar angles (degrees) and cosine weights of the glossy albedo's mean
/// over the hemisphere (the midpoint rule in cos² θ).
const ALBEDO_ANGLES: [f64; 4] = [20.705, 37.761, 52.239, 69.295];

/// What the readers need to add the ambient term.
#[derive(Clone, Debug, Default)]
pub(super) struct AmbientTerm<const N: usize> {
    /// A_amb per band (zero: no term).
    pub radiance: Spectrum<N>,
    /// Whether the readers add it.
    pub on: bool,
    /// Per face index: the solve lit the face.
    lit: Vec<bool>,
    /// Per shape, [front, back]: the glossy part's albedo, averaged over
    /// the hemisphere (zero without a glossy part).
    glossy_albedo: Vec<[Spectrum<N>; 2]>,
}

impl<const N: usize> AmbientTerm<N> {
    /// The term of a solution's parts: A_amb from its stats (none for a
    /// solution saved before the term existed), the faces it lit.
    pub fn new(p: &Parts<N>) -> Self {
        let a = &p.stats.ambient.radiance;
        let radiance = if a.len() == N && a.iter().all(|x| x.is_finite() && *x >= 0.0) {
            Spectrum::new(std::array::from_fn(|b| a[b]))
        } else {
            Spectrum::zero()
        };
        if radiance.is_black() {
            return AmbientTerm::default();
        }
        let forest = p.discretisation.forest();
        let surfaces = forest.geometry().surfaces().len();
        let mut lit = vec![false; 2 * surfaces];
        for (k, l) in lit.iter_mut().enumerate() {
            let side = if k % 2 == 0 { Side::Front } else { Side::Back };
            let root = forest.root(trilux_geometry::SurfaceId((k / 2) as u32));
            *l = p.radiance[side][root.index()].max_value() > 0.0;
        }
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
            lit,
            glossy_albedo: p.scene.materials().iter().map(glossy_albedo).collect(),
        }
    }

    fn active(&self, face: FaceId) -> bool {
        self.on && self.lit.get(face.index()).copied().unwrap_or(false)
    }

    /// ρ_d · A_amb at the point `coord` gives of `face` (a textured
    /// material is read there; `coord` is called only then).
    pub fn lambertian(
        &self,
        scene: &PreparedScene<N>,
        face: FaceId,
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
        rho * self.radiance
    }

    /// ρ_d · A_amb at element `e` of `face` (read at its middle).
    pub fn lambertian_element(
        &self,
        scene: &PreparedScene<N>,
        forest: &trilux_geometry::ElementForest,
        face: FaceId,
        e: ElementId,
    ) -> Spectrum<N> {
        self.lambertian(scene, face, || {
            forest.sample_element(e, DVec2::splat(0.5)).coord
        })
    }

    /// The glossy part's albedo · A_amb on `face`.
    pub fn glossy(&self, scene: &PreparedScene<N>, face: FaceId) -> Spectrum<N> {
        if !self.active(face) {
            return Spectrum::zero();
        }
        let shape = scene.geometry().surface(face.surface()).shape as usize;
        let side = usize::from(face.side() == Side::Back);
        self.glossy_albedo
            .get(shape)
            .map_or(Spectrum::zero(), |a| a[side] * self.radiance)
    }
}

/// The glossy part's directional albedo (less ρ_d), averaged over the
/// hemisphere with cosine weights, per side.
fn glossy_albedo<const N: usize>(b: &trilux_brdf::Bsdf<N>) -> [Spectrum<N>; 2] {
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
