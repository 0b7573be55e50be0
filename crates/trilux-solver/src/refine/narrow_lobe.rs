//! Narrow lobes (docs/solver.md, "Narrow lobes"): a glossy lobe narrow
//! against a receiver K is not estimated by the midpoint rule over K but
//! sampled — directions of j's lobe traced from stratified points of j to
//! where they land — and K is split where the lobe lands unevenly over it.

use std::sync::OnceLock;

use glam::DVec2;
use trilux_brdf::{LobeSample, is_narrow, lobe_width, sample_glossy_lobe};
use trilux_color::Spectrum;
use trilux_geometry::{ElementId, FaceId, Ray, Side, SurfaceCoord};

use super::context::RefineContext;
use crate::settings::Transport;

/// Where one sampled direction of j's glossy lobe (for light from i) met
/// the scene, and the share of the light arriving at j it carries.
#[derive(Clone, Copy, Debug)]
pub(crate) struct LobeHit<const N: usize> {
    /// The face hit (the side the ray arrived on).
    pub face: FaceId,
    /// The point hit, in its surface's coordinates.
    pub coord: SurfaceCoord,
    /// Its share of the flux arriving at j (sums to at most j's glossy
    /// albedo over all hits).
    pub share: Spectrum<N>,
}

/// Stratified points over j (and over i, paired with them) from which the
/// lobe of a pair (i, j) is sampled, as a side of a square grid.
const LOBE_POINT_GRID: u32 = 4;
/// Directions sampled per point of j, as a side of a square grid.
const LOBE_DIRECTION_GRID: u32 = 2;
/// The fewest sampled hits in a receiver for its footprint (where in K the
/// lobe lands) to be trusted enough to split K for it.
const FOOTPRINT_MIN_HITS: usize = 8;
/// The largest share of a sampled link's flux allowed to land in one
/// quadrant of K beyond that quadrant's share of K's area before K is
/// split (docs/solver.md, "Narrow lobes").
const FOOTPRINT_TOLERANCE: f64 = 0.25;

impl<const N: usize> RefineContext<'_, N> {
    /// The sampled glossy lobe of the pair (i, j) (docs/solver.md, "Narrow
    /// lobes"): from stratified points y over j, each lit from a point of i
    /// (paired stratum by stratum, so that both areas are averaged),
    /// [`LOBE_DIRECTION_GRID`]² directions of fr_glossy cos at y, each
    /// traced to the first surface it meets. The shares are normalised per
    /// point to the glossy albedo there, so they sum to at most the glossy
    /// albedo (what leaves through the open part of the hemisphere, or
    /// towards a face without stored interactions, is left out).
    fn lobe_hits(&self, sj: FaceId, i: ElementId, j: ElementId) -> Vec<LobeHit<N>> {
        let geom = self.forest.geometry();
        let shape = self.faces[sj].shape;
        let bsdf = &self.materials[shape];
        let side = sj.side();
        let sign = side.sign();
        let eps = 1e-7 * geom.bounds().diagonal().length();
        let n = LOBE_POINT_GRID;
        let points = f64::from(n * n);
        let mut out = Vec::new();
        let mut samples: Vec<LobeSample<N>> = Vec::new();
        for a in 0..n {
            for b in 0..n {
                let u = DVec2::new(
                    (f64::from(a) + 0.5) / f64::from(n),
                    (f64::from(b) + 0.5) / f64::from(n),
                );
                // i's stratum: the grid transposed and shifted, so that
                // the pairs are not aligned.
                let v = DVec2::new(
                    (f64::from((b + 1) % n) + 0.5) / f64::from(n),
                    (f64::from((a + 2) % n) + 0.5) / f64::from(n),
                );
                let y = self.forest.sample_element(j, u);
                let x = self.forest.sample_element(i, v);
                let frame = trilux_brdf::Frame::from_normal(y.normal);
                let wi = frame.to_local((x.point - y.point).normalize_or_zero());
                if wi.z * sign <= 0.0 {
                    continue;
                }
                let glossy_albedo = (self.albedo[shape].albedo(wi) - bsdf.diffuse_albedo(side))
                    .max(Spectrum::zero());
                samples.clear();
                sample_glossy_lobe(
                    bsdf,
                    wi,
                    glossy_albedo,
                    LOBE_DIRECTION_GRID,
                    1.0 / points,
                    &mut samples,
                );
                let origin = y.point + y.normal * (sign * eps);
                for smp in &samples {
                    let ray = Ray {
                        origin,
                        dir: frame.to_world(smp.wo),
                    };
                    let Some(hit) = geom.intersect(&ray, f64::INFINITY) else {
                        continue;
                    };
                    out.push(LobeHit {
                        face: FaceId::new(hit.surface, Side::from_back(!hit.front_facing(&ray))),
                        coord: hit.coord,
                        share: smp.share,
                    });
                }
            }
        }
        out
    }

    /// The sampled lobe's share that lands in element k of face `to`, with
    /// the hits there; `None` when the lobe is not sampled for this link
    /// (it is not narrow against K; docs/solver.md, "Narrow lobes").
    pub(super) fn sampled_share(
        &self,
        lobe: &OnceLock<Vec<LobeHit<N>>>,
        (sj, i, j): (FaceId, ElementId, ElementId),
        to: FaceId,
        k: ElementId,
    ) -> Option<(Spectrum<N>, Vec<LobeHit<N>>)> {
        if self.settings.transport != Transport::TwoPoint {
            return None;
        }
        let bsdf = &self.materials[self.faces[sj].shape];
        let width = lobe_width(bsdf, sj.side())?;
        let (ej, ek) = (self.forest.element(j), self.forest.element(k));
        let dist = (ek.centre - ej.centre).length();
        let radius = 0.5 * ek.bounds.diagonal().length();
        let angular_radius = if dist > radius {
            (radius / dist).asin()
        } else {
            std::f64::consts::FRAC_PI_2
        };
        if !is_narrow(width, angular_radius) {
            return None;
        }
        let hits = lobe.get_or_init(|| self.lobe_hits(sj, i, j));
        let inside: Vec<LobeHit<N>> = hits
            .iter()
            .filter(|h| h.face == to && self.forest.element_contains(k, h.coord))
            .copied()
            .collect();
        let share = inside.iter().fold(Spectrum::zero(), |acc, h| acc + h.share);
        Some((share, inside))
    }

    /// True when the sampled lobe lands unevenly over K's quadrants: some
    /// quadrant receives a share of the hits' flux more than
    /// [`FOOTPRINT_TOLERANCE`] beyond its share of K's area, so piecewise
    /// constant radiance over K would put the light in the wrong place.
    pub(super) fn footprint_uneven(&self, k: ElementId, inside: &[LobeHit<N>]) -> bool {
        if inside.len() < FOOTPRINT_MIN_HITS {
            return false;
        }
        let Some(children) = self.forest.element(k).children() else {
            return false;
        };
        let total: f64 = inside.iter().map(|h| h.share.sum()).sum();
        let area = self.forest.element(k).area;
        if !(total > 0.0 && area > 0.0) {
            return false;
        }
        children.iter().any(|&c| {
            let got: f64 = inside
                .iter()
                .filter(|h| self.forest.element_contains(c, h.coord))
                .map(|h| h.share.sum())
                .sum();
            got / total - self.forest.element(c).area / area > FOOTPRINT_TOLERANCE
        })
    }
}
