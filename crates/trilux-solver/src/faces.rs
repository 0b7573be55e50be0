//! Transport faces: the two faces of an input surface, each with its own
//! outgoing light ([`trilux_geometry::face`]).
//!
//! A face that reflects or emits is a light source for shooting; every face
//! that light can reach is a receiver (a black face only absorbs, which the
//! energy ledger must count).

use glam::{DVec2, DVec3};
use trilux_brdf::Bsdf;
use trilux_color::Spectrum;
use trilux_geometry::{ElementForest, FaceId, PerFace, Side, SurfaceId};

use crate::facing::{FaceProbes, facing, rounding_bound};
use crate::settings::Transport;

/// One face of an input surface as the solver sees it.
#[derive(Clone, Debug)]
pub(crate) struct TransportFace<const N: usize> {
    /// Index of the shape (and so of its material) in the scene.
    pub shape: usize,
    /// ρ_d of the two-point (Lambertian) part: fr_d = ρ_d/π. Zero in uniform
    /// mode, where every reflection goes through stored interactions.
    pub rho_d: Spectrum<N>,
    /// Reflection here needs stored interactions (a glossy part, or any
    /// reflection in uniform mode).
    pub stored: bool,
    /// Emitted radiance Le (front of an area emitter).
    pub emission: Spectrum<N>,
}

impl<const N: usize> TransportFace<N> {
    /// True when nothing leaves this face: it only absorbs.
    pub fn is_absorber(&self) -> bool {
        !self.stored && self.rho_d.is_black() && self.emission.is_black()
    }
}

/// Builds both faces of every input surface: every face receives light
/// (a black one only absorbs, kept so that the ledger counts what it
/// takes); a face reflects what its side of the material reflects
/// (`twosided` for a back), and only fronts emit.
pub(crate) fn build_faces<const N: usize>(
    forest: &ElementForest,
    materials: &[Bsdf<N>],
    emission: &[Spectrum<N>],
    transport: Transport,
) -> PerFace<TransportFace<N>> {
    let surfaces = forest.geometry().surfaces();
    PerFace::from_fn(surfaces.len(), |face| {
        let shape = surfaces[face.surface().index()].shape as usize;
        let bsdf = &materials[shape];
        let side = face.side();
        let rho = bsdf.diffuse_albedo(side);
        let glossy = bsdf.has_glossy(side);
        let (rho_d, stored) = match transport {
            Transport::TwoPoint => (rho, glossy),
            Transport::Uniform => (Spectrum::zero(), !bsdf.is_black(side)),
        };
        let emission = match side {
            Side::Front => emission[shape],
            Side::Back => Spectrum::zero(),
        };
        TransportFace {
            shape,
            rho_d,
            stored,
            emission,
        }
    })
}

/// Points and face-oriented normals spread over an input surface, for the
/// eligibility test.
fn probe_points(forest: &ElementForest, surface: SurfaceId, sign: f64) -> Vec<(DVec3, DVec3)> {
    const G: usize = 7;
    let mut out = Vec::with_capacity(G * G);
    for a in 0..G {
        for b in 0..G {
            // Include the boundary: (a, b) / (G − 1), nudged inside.
            let u = DVec2::new(
                (a as f64 / (G - 1) as f64).clamp(1e-6, 1.0 - 1e-6),
                (b as f64 / (G - 1) as f64).clamp(1e-6, 1.0 - 1e-6),
            );
            let s = forest.sample_surface(surface, u);
            out.push((s.point, s.normal * sign));
        }
    }
    out
}

/// Which pairs of faces can exchange light, among each face's near
/// candidates (`cluster_transport::Cut::near`; every other face when
/// clustering is off): a face that sees itself with itself, and sender
/// face `a` and receiver face `b` of different input surfaces such that
/// some point of `b` lies in front of `a` and some point of `a` in front of
/// `b`, both as seen by the same pair of points. Exact for planar surfaces
/// (probing the corners and interior suffices: the conditions are
/// linear), a dense probe for curved ones. Most pairs are decided by
/// separated bounds, with the joint test's answer (`facing`).
pub(crate) fn eligible_pairs<const N: usize>(
    forest: &ElementForest,
    faces: &PerFace<TransportFace<N>>,
    candidates: &PerFace<Vec<FaceId>>,
) -> PerFace<Vec<FaceId>> {
    use rayon::prelude::*;
    let ids: Vec<FaceId> = faces.iter().map(|(f, _)| f).collect();
    let probes: Vec<FaceProbes> = ids
        .par_iter()
        .map(|f| FaceProbes::new(probe_points(forest, f.surface(), f.side().sign())))
        .collect();
    let scale = forest.geometry().bounds().diagonal().length().max(1e-300);
    let eps = 1e-9 * scale;
    let tau = rounding_bound(probes.iter().map(FaceProbes::extent).fold(0.0, f64::max));
    let lists: Vec<Vec<FaceId>> = ids
        .par_iter()
        .map(|&a| {
            let mut out = Vec::new();
            if faces[a].is_absorber() {
                return out;
            }
            for &b in &candidates[a] {
                if b.surface() == a.surface() {
                    continue;
                }
                if facing(&probes[a.index()], &probes[b.index()], eps, tau) {
                    out.push(b);
                }
            }
            // A face of a concave surface (a pleated curtain's chart, the
            // inside of a tube) also lights itself: the links between its
            // own non-coplanar elements are the secondary interactions of
            // paper §5.2 (coplanar pairs get a zero form factor), two-point
            // for its Lambertian part and through its interaction with
            // itself for its glossy part.
            let s = forest.geometry().surface(a.surface());
            let sees_itself = match a.side() {
                Side::Front => s.can_see_itself(),
                Side::Back => s.back_can_see_itself(),
            };
            if sees_itself {
                out.push(a);
            }
            out
        })
        .collect();
    PerFace::from(lists)
}
