//! Transport sides: the two faces of an input surface, each with its own
//! outgoing light.
//!
//! Mitsuba 3's surfaces are one-sided: the back of a `diffuse` or
//! `roughconductor` is black and area emitters emit on the front only;
//! `twosided` makes the back reflect too. The solver therefore works with
//! *sides*: (input surface, front or back). A side that reflects or emits is
//! a light source for shooting; every side that light can reach is a
//! receiver (a black side only absorbs, which the energy ledger must count).

use glam::{DVec2, DVec3};
use trilux_brdf::{Bsdf, Side as BsdfSide};
use trilux_color::Spectrum;
use trilux_geometry::{SceneGeometry, SurfaceId};

use crate::settings::Transport;

/// Index of a side in the solver's side table.
pub type SideId = u32;

/// One face of an input surface as the solver sees it.
#[derive(Clone, Debug)]
pub(crate) struct TransportSide<const N: usize> {
    /// The input surface.
    pub surface: SurfaceId,
    /// The back face (against the geometric normal) rather than the front.
    pub back: bool,
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

impl<const N: usize> TransportSide<N> {
    /// True when nothing leaves this side: it only absorbs.
    pub fn is_absorber(&self) -> bool {
        !self.stored && self.rho_d.is_black() && self.emission.is_black()
    }

    /// The sign that turns the geometric (front) normal into this side's.
    pub fn sign(&self) -> f64 {
        if self.back { -1.0 } else { 1.0 }
    }
}

/// Builds the sides of every input surface: a front side always (it receives
/// light even when black), a back side when the material reflects there
/// (`twosided`) or when the surface is open and its back can be reached
/// (kept as an absorber so that the ledger counts the light it takes).
pub(crate) fn build_sides<const N: usize>(
    geom: &SceneGeometry,
    materials: &[Bsdf<N>],
    emission: &[Spectrum<N>],
    transport: Transport,
) -> Vec<TransportSide<N>> {
    let mut sides = Vec::new();
    for (index, surface) in geom.surfaces().iter().enumerate() {
        let id = SurfaceId(index as u32);
        let shape = surface.shape as usize;
        let bsdf = &materials[shape];
        for back in [false, true] {
            let side = if back {
                BsdfSide::Back
            } else {
                BsdfSide::Front
            };
            let rho = bsdf.diffuse_albedo(side);
            let glossy = bsdf.has_glossy(side);
            let (rho_d, stored) = match transport {
                Transport::TwoPoint => (rho, glossy),
                Transport::Uniform => (Spectrum::zero(), !bsdf.is_black(side)),
            };
            let le = if back {
                Spectrum::zero()
            } else {
                emission[shape]
            };
            sides.push(TransportSide {
                surface: id,
                back,
                shape,
                rho_d,
                stored,
                emission: le,
            });
        }
    }
    sides
}

/// Points and side-oriented normals spread over an input surface, for the
/// eligibility test.
fn probe_points(geom: &SceneGeometry, surface: SurfaceId, sign: f64) -> Vec<(DVec3, DVec3)> {
    const G: usize = 7;
    let mut out = Vec::with_capacity(G * G);
    for a in 0..G {
        for b in 0..G {
            // Include the boundary: (a, b) / (G − 1), nudged inside.
            let u = DVec2::new(
                (a as f64 / (G - 1) as f64).clamp(1e-6, 1.0 - 1e-6),
                (b as f64 / (G - 1) as f64).clamp(1e-6, 1.0 - 1e-6),
            );
            let s = geom.sample_surface(surface, u);
            out.push((s.point, s.normal * sign));
        }
    }
    out
}

/// Which pairs of sides can exchange light: a side that sees itself with
/// itself, and sender side `a` and receiver side `b` of
/// different input surfaces such that some point of `b` lies in front
/// of `a` and some point of `a` in front of `b`, both as seen by the same pair
/// of points. Exact for planar surfaces (probing the corners and interior
/// suffices: the conditions are linear), a dense probe for curved ones.
pub(crate) fn eligible_pairs<const N: usize>(
    geom: &SceneGeometry,
    sides: &[TransportSide<N>],
) -> Vec<Vec<SideId>> {
    use rayon::prelude::*;
    let probes: Vec<Vec<(DVec3, DVec3)>> = sides
        .par_iter()
        .map(|s| probe_points(geom, s.surface, s.sign()))
        .collect();
    let scale = geom.bounds().diagonal().length().max(1e-300);
    let eps = 1e-9 * scale;
    (0..sides.len())
        .into_par_iter()
        .map(|a| {
            let mut out = Vec::new();
            if sides[a].is_absorber() {
                return out;
            }
            for (b, side_b) in sides.iter().enumerate() {
                if side_b.surface == sides[a].surface {
                    continue;
                }
                let faces = probes[a].iter().any(|&(p, np)| {
                    probes[b].iter().any(|&(q, nq)| {
                        let d = q - p;
                        d.dot(np) > eps && -d.dot(nq) > eps
                    })
                });
                if faces {
                    out.push(b as SideId);
                }
            }
            // A face of a concave surface (a pleated curtain's chart, the
            // inside of a tube) also lights itself: the links between its
            // own non-coplanar elements are the secondary interactions of
            // paper §5.2 (coplanar pairs get a zero form factor), two-point
            // for its Lambertian part and through its interaction with
            // itself for its glossy part.
            let s = geom.surface(sides[a].surface);
            let sees_itself = if sides[a].back {
                s.back_can_see_itself()
            } else {
                s.can_see_itself()
            };
            if sees_itself {
                out.push(a as SideId);
            }
            out
        })
        .collect()
}
