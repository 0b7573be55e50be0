//! RefineAndLink (paper §3.2.2, Fig. 4–5, §4.3; docs/solver.md).
//!
//! A shot refines in two stages, both creating links that live only for
//! this shot (paper §4.2):
//!
//! 1. **Pair links** i → j between the source's elements and the elements
//!    of every receiving side (the two-point part, as in hierarchical
//!    radiosity): refined until the form-factor estimates are below FFErr and
//!    visibility is not partial, or until the flux the link carries is below
//!    the photometric threshold. The flux arriving through a pair link is
//!    π T_ij δL_i; its Lambertian share goes straight into j's radiance.
//! 2. **Three-point links** (i j) → (j k), from each pair link into every
//!    stored interaction hierarchy leaving j's side (its glossy part):
//!    refined by the BRDF error FrErr, the form factor and visibility of
//!    (j, k), and the photometric criterion on the flux that would go on
//!    towards k. The three subdivision cases apply: split I
//!    (sender sub-pairs i_m j), split K (receiver nodes j k_m), or split J
//!    (matched pairs i j_m → j_m k only; docs/solver.md, "RefineAndLink").
//!
//! Senders are never stored in the sender's hierarchy by refinement: a
//! finer sender pair than the stored nodes is *virtual*, with the unshot
//! radiance of the deepest stored node containing it (piecewise constant, so
//! this is exact). Only receiving hierarchies grow, and they are disjoint
//! across the parallel tasks of one shot.

use std::f64::consts::PI;
use std::sync::OnceLock;

use glam::{DVec2, DVec3};
use trilux_brdf::area::Element as Driver;
use trilux_brdf::{
    AlbedoTable, Bsdf, ElementPoints, LobeSample, brdf_variation, is_narrow, lobe_width,
    sample_glossy_lobe,
};
use trilux_color::Spectrum;
use trilux_geometry::{
    ElementForest, ElementId, FaceElement, FaceId, PerFace, Ray, Side, Sided, SurfaceCoord,
    Visibility,
};

use crate::faces::TransportFace;
use crate::interaction::{Hierarchy, Node, Split};
use crate::radiosity::ElementRadiance;
use crate::settings::{SolverSettings, Transport};
use crate::textures::ElementTextures;
use crate::throughput::{Throughput, ThroughputCache, compute_throughput};

/// What a sender sends: its unshot radiance δL (a shot), or its final
/// radiance L plus emission (the gather links made after the solve).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Sent {
    /// δL, during the solve.
    Unshot,
    /// L + Le, after the solve.
    Final,
}

/// Where refinement takes the radiance a sender sends, by element pair.
pub(crate) enum Sender<'a, const N: usize> {
    /// A Lambertian face: the radiance of its element tree, the same
    /// towards every j.
    Radiosity {
        /// The face's per-element radiance.
        field: &'a ElementRadiance<N>,
        /// The side it sends from.
        side: Side,
        /// Unshot or final radiance.
        sent: Sent,
        /// The face's emitted radiance (added to the final radiance).
        emission: Spectrum<N>,
    },
    /// A stored interaction hierarchy.
    Stored {
        /// The hierarchy.
        hierarchy: &'a Hierarchy<N>,
        /// Unshot or final radiance.
        sent: Sent,
    },
    /// A glossy face's far field (`cluster_transport`): the unshot
    /// radiance it sends towards each receiving surface, by surface (zero
    /// for surfaces outside its far blocks).
    Far {
        /// δL towards every input surface.
        by_surface: &'a [Spectrum<N>],
    },
}

impl<const N: usize> Sender<'_, N> {
    /// The radiance element i sends towards element j.
    fn unshot(&self, forest: &ElementForest, i: ElementId, j: ElementId) -> Spectrum<N> {
        match *self {
            Sender::Radiosity {
                field,
                side,
                sent,
                emission,
            } => match sent {
                Sent::Unshot => field.unshot[side][i.index()],
                Sent::Final => field.radiance[side][i.index()] + emission,
            },
            Sender::Stored { hierarchy, sent } => {
                let node = &hierarchy.nodes[hierarchy.node_for(forest, i, j) as usize];
                match sent {
                    Sent::Unshot => node.unshot,
                    Sent::Final => node.radiance,
                }
            }
            Sender::Far { by_surface } => by_surface
                .get(forest.element(j).surface.index())
                .copied()
                .unwrap_or_else(Spectrum::zero),
        }
    }
}

/// How many times the rays a pair with a partly buried or cut-off element
/// gets (see `RefineContext::throughput`).
const CUT_OFF_VISIBILITY: u32 = 9;

/// The shadow rays for a pair: `base`, or [`CUT_OFF_VISIBILITY`]× that
/// when an element of the pair is partly cut off by a crossing (see
/// `RefineContext::throughput`).
pub(crate) fn visibility_samples_for(
    partly_cut: &Sided<Vec<bool>>,
    pair: [FaceElement; 2],
    base: u32,
) -> u32 {
    let cut = |e: FaceElement| {
        partly_cut[e.side]
            .get(e.element.index())
            .copied()
            .unwrap_or(false)
    };
    if pair.into_iter().any(cut) {
        base * CUT_OFF_VISIBILITY
    } else {
        base
    }
}

/// Largest relative error, from the sender's unshot radiance varying over
/// it, that a pair link may carry (see `RefineContext::sender_varies`).
const SENDER_VARIATION: f64 = 0.01;

/// What every pair link of one stage-1 refinement shares: where the unshot
/// radiance comes from, the sending face and the receiving face.
#[derive(Clone, Copy)]
pub(crate) struct PairShot<'s, const N: usize> {
    /// Unshot radiance by element pair.
    pub sender: &'s Sender<'s, N>,
    /// The sending face.
    pub si: FaceId,
    /// The receiving face.
    pub sj: FaceId,
}

/// A transient link of stage 1.
#[derive(Clone, Debug)]
pub(crate) struct PairLink<const N: usize> {
    /// Sending element.
    pub i: ElementId,
    /// Receiving element.
    pub j: ElementId,
    /// Receiving face.
    pub face: FaceId,
    /// T_ij.
    pub t: f64,
    /// δL_i sent along the link.
    pub unshot: Spectrum<N>,
}

/// A transient link of stage 2: a radiance increment for one node.
#[derive(Clone, Debug)]
pub(crate) struct NodeLink<const N: usize> {
    /// Index of the receiving hierarchy.
    pub hierarchy: u32,
    /// Node within it.
    pub node: u32,
    /// The pair link (stage 1) this transfer belongs to.
    pub group: u32,
    /// ΔL^G = δL_ij · R(i→j→k) (paper §4.2, step 2).
    pub gathered: Spectrum<N>,
    /// R was estimated by sampling the lobe (docs/solver.md, "Narrow
    /// lobes"): the link's flux already conserves energy and is not
    /// renormalised.
    pub sampled: bool,
}

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

/// What a three-point link (i j) → (j k) takes from its pair (i, j), the
/// same for every receiver node k: computed once per pair link and handed
/// down the K-side recursion.
#[derive(Clone, Debug)]
pub(crate) struct Incidence<const N: usize> {
    /// T_ij.
    tij: Throughput,
    /// δL sent from i towards j.
    unshot: Spectrum<N>,
    /// The light's arrival at j's centre (`RefineContext::incident`);
    /// `None` when no part of i is on the receiving side.
    incoming: Option<Incoming>,
    /// i has points on both sides of j's tangent plane.
    straddle_i: bool,
    /// The sampled lobe of the pair (docs/solver.md, "Narrow lobes"),
    /// traced when a link first needs it and shared by every hierarchy the
    /// pair link feeds (they borrow one incidence).
    lobe: OnceLock<Vec<LobeHit<N>>>,
}

impl<const N: usize> Incidence<N> {
    /// The unit direction (world space) from j's centre towards the part
    /// of i the light comes from; `None` when no part is on the receiving
    /// side.
    pub fn direction(&self) -> Option<DVec3> {
        self.incoming.map(|inc| inc.frame.to_world(inc.wi))
    }
}

/// Where light from i arrives at j: j's front frame, and the direction of
/// incidence in it.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Incoming {
    /// j's frame (its front normal as z).
    frame: trilux_brdf::Frame,
    /// The direction towards i's part on the receiving side, local.
    wi: DVec3,
}

/// The refinement oracle's errors for one three-point link, each relative
/// to its bound (≤ 1 is accurate enough).
#[derive(Clone, Copy, Debug)]
struct TripleErrors {
    /// π F̂_ji (fr_max − fr_min) / FrErr.
    brdf: f64,
    /// The spread of F(y → j) over y in K, / FFErr.
    ff: f64,
    /// (j, k) partly visible, or K straddling j's tangent plane.
    partial: bool,
    /// The element whose variation drives the BRDF error.
    driver: Driver,
}

/// One receiving hierarchy refined against the pair links of one shot
/// (stage 2): what the recursion carries besides the three elements.
pub(crate) struct TripleTask<'t, const N: usize> {
    /// Where the shot's unshot radiance comes from.
    pub sender: &'t Sender<'t, N>,
    /// The sending side.
    pub si: FaceId,
    /// The receiving hierarchy (this task owns it for the shot).
    pub h: &'t mut Hierarchy<N>,
    /// Its index among the solver's hierarchies.
    pub h_index: u32,
    /// The pair link being refined.
    pub group: u32,
    /// Flux that splits could not keep.
    pub lost: Spectrum<N>,
    /// The links made.
    pub out: Vec<NodeLink<N>>,
}

impl<const N: usize> TripleTask<'_, N> {
    /// Keeps a link that carries light (a zero of the BRDF carries none).
    fn push(&mut self, link: NodeLink<N>) {
        if !link.gathered.is_black() {
            self.out.push(link);
        }
    }
}

/// Everything refinement reads, shared by the parallel tasks of a shot.
pub(crate) struct RefineContext<'a, const N: usize> {
    pub forest: &'a ElementForest,
    /// Shadow-ray visibility, with the scene's buried parts.
    pub visibility: Visibility<'a>,
    pub settings: &'a SolverSettings,
    pub faces: &'a PerFace<TransportFace<N>>,
    pub materials: &'a [Bsdf<N>],
    pub cache: &'a ThroughputCache,
    /// Photometric threshold in watts (band sum): flux_eps × IF.
    pub flux_threshold: f64,
    /// `element_points` of every element, computed once.
    pub points: &'a [[DVec3; 5]],
    /// The centres of every element's 2×2 quadrants (its midpoint rule).
    pub interior: &'a [[DVec3; 4]],
    /// Exposed area of every element's faces, `[back][element]`.
    pub exposed_area: &'a Sided<Vec<f64>>,
    /// ρ_d and g of textured elements (`crate::textures`).
    pub textures: Option<&'a ElementTextures<N>>,
    /// The cluster hierarchy and every face's cut (`cluster_transport`).
    pub clusters: &'a crate::cluster_transport::Clusters,
    /// Directional albedo per material (the sampled lobes' scale).
    pub albedo: &'a [AlbedoTable<N>],
}

impl<'a, const N: usize> RefineContext<'a, N> {
    /// What far links read.
    pub fn far(&self) -> crate::cluster_transport::FarContext<'a> {
        crate::cluster_transport::FarContext {
            forest: self.forest,
            tree: &self.clusters.tree,
            exposed_area: self.exposed_area,
            burial: self.visibility.burial(),
            enclosed: &self.clusters.enclosed,
        }
    }
}

/// Point-to-disc estimate of F_{a→b} (Hanrahan, Salzman & Aupperle 1991): b seen from a's
/// centre as a disc of the same area.
fn disc_estimate(pa: DVec3, na: DVec3, pb: DVec3, nb: DVec3, area_b: f64) -> f64 {
    let d = pb - pa;
    let r2 = d.length_squared();
    if r2 <= 0.0 {
        return 1.0;
    }
    let r = r2.sqrt();
    let ca = (na.dot(d) / r).max(0.0);
    let cb = (-nb.dot(d) / r).max(0.0);
    // Elements that do not face each other at their centres may still
    // exchange light near their edges: use the larger cosines' bound.
    let (ca, cb) = if ca == 0.0 || cb == 0.0 {
        (1.0, 1.0)
    } else {
        (ca, cb)
    };
    (area_b * ca * cb / (PI * r2 + area_b)).min(1.0)
}

impl<const N: usize> RefineContext<'_, N> {
    /// T through the cache, for `recv` receiving from `send` (T is
    /// symmetric; the spread is over the receiver).
    pub fn throughput(&self, recv: FaceElement, send: FaceElement) -> Throughput {
        let (a, b) = (recv, send);
        if let Some(t) = self.cache.get(a, b) {
            return t;
        }
        // A pair inside a pair that all its shadow rays (64 or more at the
        // levels refinement starts from) found unoccluded is unoccluded too:
        // its sub-segments lie in the parent pair's shaft.
        let parent_visible =
            |x: FaceElement, y: FaceElement| self.cache.get(x, y).is_some_and(|t| t.v >= 1.0);
        let up = |s: FaceElement| self.forest.element(s.element).parent.map(|p| s.with(p));
        let visible = up(a).is_some_and(|pa| parent_visible(pa, b))
            || up(b).is_some_and(|pb| parent_visible(a, pb));
        // Segments that end on a buried or cut-off part count as blocked,
        // which leaves the visible fraction of an element pair that is
        // partly cut off (a floor element across a wall that crosses it) a
        // ratio of two noisy sums, biased low by a few per cent at 16 rays
        // (docs/solver.md, "Crossings"): such pairs of crossed surfaces get
        // [`CUT_OFF_VISIBILITY`]× the rays.
        let samples = visibility_samples_for(
            &self.clusters.partly_cut,
            [a, b],
            self.settings.visibility_samples,
        );
        let t = compute_throughput(&self.visibility, a, b, samples, visible);
        self.cache.insert(a, b, t);
        t
    }

    /// Both point-to-disc estimates F̂_{a→b} and F̂_{b→a}.
    fn ff_estimates(&self, a: FaceElement, b: FaceElement) -> (f64, f64) {
        let (ea, eb) = (
            self.forest.element(a.element),
            self.forest.element(b.element),
        );
        let na = ea.normal * a.side.sign();
        let nb = eb.normal * b.side.sign();
        (
            disc_estimate(ea.centre, na, eb.centre, nb, eb.area),
            disc_estimate(eb.centre, nb, ea.centre, na, ea.area),
        )
    }

    /// Stage 1: refines the pair (i, j) and appends pair links. `budget`
    /// is the form-factor spread over j this link may have: FFErr for a
    /// root pair, shared among the children when the sender is split (the
    /// receiver-side errors of sibling senders add up on j).
    pub fn refine_pair(
        &self,
        shot: PairShot<'_, N>,
        i: ElementId,
        j: ElementId,
        budget: f64,
        out: &mut Vec<PairLink<N>>,
    ) {
        let PairShot { sender, si, sj } = shot;
        let th = self.throughput(sj.of(j), si.of(i));
        let (ei, ej) = (self.forest.element(i), self.forest.element(j));
        if th.t <= 0.0 {
            // Fully occluded or facing away. Near the roots a handful of
            // shadow rays may miss a gap: look one level further there.
            if ei.depth + ej.depth < 2
                && th.v == 0.0
                && self.unoccluded_positive(si.of(i), sj.of(j))
            {
                self.split_pair(shot, i, j, budget, out);
            }
            return;
        }
        let unshot = sender.unshot(self.forest, i, j);
        if unshot.is_black() {
            return;
        }
        let link = PairLink {
            i,
            j,
            face: sj,
            t: th.t,
            unshot,
        };
        let flux = PI * th.t * unshot.sum();
        // A black receiver only absorbs, but it is refined like any other:
        // a link made high up would send the sender's *average* unshot
        // radiance, also from the parts that cannot see the receiver (the
        // floor under a box sending into the box's black inside).
        if flux < self.flux_threshold {
            out.push(link);
            return;
        }
        // A link sends the sender's *average* unshot radiance; where that
        // radiance varies over the sender in step with the form factor to
        // j (the bright middle of a floor sees more of the ceiling than its
        // corners), the average is biased. Compare the transfer resolved
        // over the sender's children with the averaged one (point-to-disc
        // estimates) and split the sender when they differ.
        if self.sender_varies(shot, i, j) {
            self.split_sender(shot, i, j, budget, true, out);
            return;
        }
        // The transfer is accurate when the point form factor varies little
        // over the receiver (so that pushing it down unchanged is right).
        let partial = th.v > 0.0 && th.v < 1.0;
        if th.spread <= budget && !partial {
            out.push(link);
            return;
        }
        if !self.split_pair(shot, i, j, budget, out) {
            out.push(link);
        }
    }

    /// True when the transfer i → j resolved over i's children differs
    /// from the one made with i's average unshot radiance by more than
    /// [`SENDER_VARIATION`] (relative): Σ_c a_c δL_c F̂_cj against
    /// δL̄_i Σ_c a_c F̂_cj, with a_c the children's exposed areas (so that
    /// δL̄_i = Σ a_c δL_c / Σ a_c) and F̂ point-to-disc estimates.
    fn sender_varies(&self, shot: PairShot<'_, N>, i: ElementId, j: ElementId) -> bool {
        let PairShot { sender, si, sj } = shot;
        let Sender::Radiosity { side: s, .. } = *sender else {
            return false;
        };
        let Some(children) = self.forest.element(i).children() else {
            return false;
        };
        let ej = self.forest.element(j);
        let nj = ej.normal * sj.side().sign();
        let ni = si.side().sign();
        let (mut resolved, mut weight, mut mean) = (0.0, 0.0, 0.0);
        for c in children {
            let ec = self.forest.element(c);
            let a = self.exposed_area[s][c.index()];
            let f = a * disc_estimate(ec.centre, ec.normal * ni, ej.centre, nj, ej.area);
            let dl = sender.unshot(self.forest, c, j).sum();
            resolved += f * dl;
            weight += f;
            mean += a * dl;
        }
        let total_area: f64 = children
            .iter()
            .map(|c| self.exposed_area[s][c.index()])
            .sum();
        if total_area <= 0.0 || weight <= 0.0 {
            return false;
        }
        let averaged = weight * mean / total_area;
        (resolved - averaged).abs() > SENDER_VARIATION * averaged
    }

    fn unoccluded_positive(&self, i: FaceElement, j: FaceElement) -> bool {
        self.throughput(j, i).f > 0.0
    }

    /// Refines the sender's children against j; with `share_budget`, each
    /// with its area's share of the spread budget.
    fn split_sender(
        &self,
        shot: PairShot<'_, N>,
        i: ElementId,
        j: ElementId,
        budget: f64,
        share_budget: bool,
        out: &mut Vec<PairLink<N>>,
    ) {
        let area = self.forest.element(i).area;
        for c in self.forest.element(i).children().into_iter().flatten() {
            let share = if share_budget {
                self.forest.element(c).area / area
            } else {
                1.0
            };
            self.refine_pair(shot, c, j, budget * share, out);
        }
    }

    /// Splits the larger splittable element of the pair; false if neither
    /// can be split.
    fn split_pair(
        &self,
        shot: PairShot<'_, N>,
        i: ElementId,
        j: ElementId,
        budget: f64,
        out: &mut Vec<PairLink<N>>,
    ) -> bool {
        let (ei, ej) = (self.forest.element(i), self.forest.element(j));
        let split_i = match (ei.children(), ej.children()) {
            // Both splittable: the receiver, unless the sender is much larger.
            (Some(_), Some(_)) => ei.area > 4.0 * ej.area,
            (Some(_), None) => true,
            (None, Some(_)) => false,
            (None, None) => return false,
        };
        if split_i {
            // A sender much larger than its receiver: split by size (the
            // budget stays, as before any sender-variation split).
            self.split_sender(shot, i, j, budget, false, out);
        } else {
            for c in ej.children().into_iter().flatten() {
                self.refine_pair(shot, i, c, budget, out);
            }
        }
        true
    }

    /// The direction of incidence at j's centre from i, in j's (front)
    /// frame, on the receiving side `sign` (±1): towards i's centre, or,
    /// when that centre lies behind j's tangent plane although part of i is
    /// in front (i straddles the plane; T_ij counts only that part), towards
    /// the mean of i's sample points in front. `None` when none is.
    fn incident(
        &self,
        frame: &trilux_brdf::Frame,
        i: ElementId,
        j: ElementId,
        sign: f64,
    ) -> Option<DVec3> {
        let cj = self.forest.element(j).centre;
        let wi = frame.to_local((self.forest.element(i).centre - cj).normalize_or_zero());
        if wi.z * sign > 0.0 {
            return Some(wi);
        }
        let (mut sum, mut count) = (DVec3::ZERO, 0u32);
        for &p in self.points[i.index()]
            .iter()
            .chain(&self.interior[i.index()])
        {
            let w = frame.to_local(p - cj);
            if w.z * sign > 0.0 {
                sum += w.normalize_or_zero();
                count += 1;
            }
        }
        (count > 0)
            .then(|| sum.normalize_or_zero())
            .filter(|w| w.z * sign > 0.0)
    }

    /// fr(i→j→k) for light arriving at j's centre from `wi` (j's front
    /// frame), for stored transport (the glossy part in two-point mode, the
    /// whole BRDF in uniform mode); `None` when none of K's sample points is
    /// on wi's side of j (a zero of the geometry, not of the BRDF).
    fn fr_centre(
        &self,
        bsdf: &Bsdf<N>,
        incoming: &Incoming,
        j: ElementId,
        k: ElementId,
    ) -> Option<Spectrum<N>> {
        let ej = self.forest.element(j);
        let Incoming { frame, wi } = *incoming;
        // The discretised fr over K (paper Eq. 5's fr_KJI): the midpoint rule
        // on K's 2×2 quadrants rather than its centre alone, so that a glossy
        // lobe that falls between K's centre and its edges is not missed
        // by a link made early (photometric criterion) on a large K.
        // Only the points on wi's side of j count: the throughput of (j, k)
        // already covers just the part of K in front of j.
        let mut sum = Spectrum::zero();
        let mut count = 0u32;
        for &p in &self.interior[k.index()] {
            let wo = frame.to_local((p - ej.centre).normalize_or_zero());
            if wo.z * wi.z <= 0.0 {
                continue;
            }
            count += 1;
            sum += match self.settings.transport {
                Transport::TwoPoint => bsdf.eval_glossy(wi, wo),
                Transport::Uniform => bsdf.eval(wi, wo),
            };
        }
        (count > 0).then(|| sum * (1.0 / f64::from(count)))
    }

    /// fr at the mirror direction of `wi` about j, if that direction
    /// passes within K's angular radius (plus a margin for the lobe's
    /// width) of K's centre, as seen from j's centre.
    fn peak_fr(
        &self,
        bsdf: &Bsdf<N>,
        incoming: &Incoming,
        j: ElementId,
        k: ElementId,
    ) -> Option<Spectrum<N>> {
        let g = self.forest;
        let (ej, ek) = (g.element(j), g.element(k));
        let Incoming { frame, wi } = *incoming;
        let mirror = DVec3::new(-wi.x, -wi.y, wi.z);
        let to_k = ek.centre - ej.centre;
        let dist = to_k.length();
        if dist <= 0.0 || wi.z == 0.0 {
            return None;
        }
        let radius = 0.5 * ek.bounds.diagonal().length();
        let cone = (radius / dist).atan() + 0.2;
        let angle = frame.to_world(mirror).angle_between(to_k);
        (angle <= cone).then(|| bsdf.eval_glossy(wi, mirror))
    }

    /// The spread of fr over the three elements and the element driving it
    /// (docs/solver.md, "Refinement"): only computed when the cheaper tests
    /// did not already decide.
    fn fr_variation(
        &self,
        bsdf: &Bsdf<N>,
        i: ElementId,
        j: ElementId,
        k: ElementId,
    ) -> (f64, Driver) {
        let g = self.forest;
        let (ei, ej, ek) = (g.element(i), g.element(j), g.element(k));
        fn pts<'p>(e: &trilux_geometry::Element, p: &'p [DVec3; 5]) -> ElementPoints<'p> {
            ElementPoints {
                centre: e.centre,
                normal: e.normal,
                points: &p[..],
            }
        }
        let variation = brdf_variation(
            bsdf,
            &pts(ei, &self.points[i.index()]),
            &pts(ej, &self.points[j.index()]),
            &pts(ek, &self.points[k.index()]),
        );
        let spread = (variation.fr_max - variation.fr_min).max_value().max(0.0);
        (spread, variation.driver())
    }

    /// True when element `e` has points on both sides of the tangent plane
    /// of `j` at its centre.
    fn straddles(&self, e: ElementId, j: ElementId) -> bool {
        let ej = self.forest.element(j);
        let scale = ej.bounds.diagonal().length().max(1e-300);
        let (mut front, mut back) = (false, false);
        for &p in &self.points[e.index()] {
            let d = (p - ej.centre).dot(ej.normal);
            front |= d > 1e-9 * scale;
            back |= d < -1e-9 * scale;
        }
        front && back
    }

    /// The pair (i, j)'s part of every three-point link (i j) → (j k):
    /// `None` when no light passes from i to j.
    pub fn incidence(
        &self,
        sender: &Sender<'_, N>,
        i: FaceElement,
        j: FaceElement,
    ) -> Option<Incidence<N>> {
        self.incidence_with(sender, i, j, self.throughput(j, i))
    }

    /// [`Self::incidence`] with T_ij already known (a pair link's own: a
    /// far link's T is the cluster estimate, not the pair's exact one).
    pub fn incidence_with(
        &self,
        sender: &Sender<'_, N>,
        i: FaceElement,
        j: FaceElement,
        tij: Throughput,
    ) -> Option<Incidence<N>> {
        if tij.t <= 0.0 {
            return None;
        }
        let unshot = sender.unshot(self.forest, i.element, j.element);
        if unshot.is_black() {
            return None;
        }
        let frame = trilux_brdf::Frame::from_normal(self.forest.element(j.element).normal);
        Some(Incidence {
            tij,
            unshot,
            incoming: self
                .incident(&frame, i.element, j.element, j.side.sign())
                .map(|wi| Incoming { frame, wi }),
            straddle_i: self.straddles(i.element, j.element),
            lobe: OnceLock::new(),
        })
    }

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
    fn sampled_share(
        &self,
        known: &Incidence<N>,
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
        let hits = known.lobe.get_or_init(|| self.lobe_hits(sj, i, j));
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
    fn footprint_uneven(&self, k: ElementId, inside: &[LobeHit<N>]) -> bool {
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

    /// Stage 2: refines the three-point link (i j) → node `n` of the task's
    /// hierarchy (whose sender element is j) and appends node links.
    pub fn refine_triple(
        &self,
        task: &mut TripleTask<'_, N>,
        i: ElementId,
        j: ElementId,
        n: u32,
        known: Option<&Incidence<N>>,
    ) {
        let (si, sj) = (task.si, task.h.from);
        // T_ij, δL_ij and the incidence at j are the same for every receiver
        // node of one (i, j): the K-side recursion hands them down.
        // A (sub)element of i makes its own incidence; a node below the
        // pair's receives the pair's.
        let owned;
        let known = match known {
            Some(k) => k,
            None => {
                let Some(k) = self.incidence(task.sender, si.of(i), sj.of(j)) else {
                    return;
                };
                owned = k;
                &owned
            }
        };
        let node = &task.h.nodes[n as usize];
        debug_assert_eq!(node.from, j);
        let (k, tjk, vjk, spread_jk) = (node.to, node.t, node.v, node.spread);
        if tjk <= 0.0 {
            self.retry_unseen_node(task, i, j, n, known);
            return;
        }
        let bsdf = &self.materials[self.faces[sj].shape];
        // R(i→j→k) = π F_{j→i} fr with F_{j→i} = T_ij / A_j over j's
        // exposed area (light arrives and leaves there only).
        let aj = self.exposed_area[sj.side()][j.index()];
        if aj <= 0.0 {
            return;
        }
        let straddle_k = self.straddles(k, j);
        let Some(fr) = known
            .incoming
            .and_then(|inc| self.fr_centre(bsdf, &inc, j, k))
        else {
            self.split_across_plane(task, i, j, n, known, straddle_k);
            return;
        };
        // A lobe narrow against K: its sampled share that lands in K
        // (docs/solver.md, "Narrow lobes").
        if let Some((share, inside)) = self.sampled_share(known, (sj, i, j), task.h.to, k) {
            let g = self
                .textures
                .map_or(Spectrum::splat(1.0), |t| t.glossy(sj, j));
            // The flux on towards k is π T_ij δL · share, so ΔL^G = δL ·
            // share · T_ij / T_jk.
            let gathered = known.unshot * share * g * (known.tij.t / tjk);
            let link = NodeLink {
                hierarchy: task.h_index,
                node: n,
                group: task.group,
                gathered,
                sampled: true,
            };
            if PI * tjk * gathered.sum() < self.flux_threshold {
                task.push(link);
                return;
            }
            let errors = TripleErrors {
                // Where in K the lobe lands, not fr's variation, decides.
                brdf: if self.footprint_uneven(k, &inside) {
                    2.0
                } else {
                    0.0
                },
                ff: spread_jk / self.settings.ff_eps,
                partial: (vjk > 0.0 && vjk < 1.0) || straddle_k,
                driver: Driver::K,
            };
            self.link_or_split(task, (i, j, n), known, link, errors);
            return;
        }
        // A textured j: its glossy part is g(j) times the nominal one.
        let (fr, texture_variation) = match self.textures {
            Some(t) => (fr * t.glossy(sj, j), t.glossy_variation(self.forest, sj, j)),
            None => (fr, 0.0),
        };
        let gathered = known.unshot * fr * (PI * known.tij.t / aj);
        let link = NodeLink {
            hierarchy: task.h_index,
            node: n,
            group: task.group,
            gathered,
            sampled: false,
        };
        if self.below_photometric(bsdf, known, j, &task.h.nodes[n as usize], aj, gathered) {
            task.push(link);
            return;
        }
        let (spread, driver) = self.fr_variation(bsdf, i, j, k);
        // fr's spread over the three elements, and over j the texture's.
        let spread = match self.textures {
            Some(t) => spread * t.glossy(sj, j).max_value() + fr.max_value() * texture_variation,
            None => spread,
        };
        let driver = if texture_variation > 0.0 && spread > 0.0 {
            Driver::J
        } else {
            driver
        };
        let (fji, _) = self.ff_estimates(sj.of(j), si.of(i));
        let errors = TripleErrors {
            brdf: PI * fji * spread / self.settings.fr_eps,
            // The same oracle as stage 1, for the flux this node will carry
            // on: how much the point form factor F(y → j) varies over y in k.
            ff: spread_jk / self.settings.ff_eps,
            partial: (vjk > 0.0 && vjk < 1.0) || straddle_k,
            driver,
        };
        self.link_or_split(task, (i, j, n), known, link, errors);
    }

    /// A node whose elements were found not to see each other: as in stage
    /// 1, near the roots a few shadow rays may miss a gap, so look one
    /// level further (splitting the larger of J and K) before giving the
    /// pair up.
    fn retry_unseen_node(
        &self,
        task: &mut TripleTask<'_, N>,
        i: ElementId,
        j: ElementId,
        n: u32,
        known: &Incidence<N>,
    ) {
        let k = task.h.nodes[n as usize].to;
        let (ej, ek) = (self.forest.element(j), self.forest.element(k));
        if ej.depth + ek.depth < 2 && self.throughput(task.h.to.of(k), task.h.from.of(j)).f > 0.0 {
            let side = if ej.area >= ek.area {
                Driver::J
            } else {
                Driver::K
            };
            self.split_triple(side, task, i, j, n, known);
        }
    }

    /// No sample point of i or K on the receiving side of j: an element
    /// that lies partly behind j's tangent plane still carries light
    /// through its part in front, so refine it like partial visibility. (A
    /// zero of the BRDF itself, a lobe far from K, is not refined for: the
    /// peak bound of [`Self::below_photometric`] decides whether the lobe
    /// may be near.)
    fn split_across_plane(
        &self,
        task: &mut TripleTask<'_, N>,
        i: ElementId,
        j: ElementId,
        n: u32,
        known: &Incidence<N>,
        straddle_k: bool,
    ) {
        let k = task.h.nodes[n as usize].to;
        let order = match (known.straddle_i, straddle_k) {
            (true, true) if self.forest.element(i).area >= self.forest.element(k).area => {
                [Driver::I, Driver::K]
            }
            (true, true) => [Driver::K, Driver::I],
            (true, false) => [Driver::I, Driver::I],
            (false, true) => [Driver::K, Driver::K],
            (false, false) => return,
        };
        for d in order {
            if self.split_triple(d, task, i, j, n, known) {
                return;
            }
        }
    }

    /// The photometric criterion (paper §4.3) on the flux π T_jk ΔL^G the
    /// link would send on towards k. The midpoint estimate of fr over K
    /// misses a narrow lobe whose peak falls between K's sample points, and
    /// such links would stay coarse *because* they were underestimated: the
    /// flux is also bounded with fr at the mirror direction when that
    /// direction passes near K.
    fn below_photometric(
        &self,
        bsdf: &Bsdf<N>,
        known: &Incidence<N>,
        j: ElementId,
        node: &Node<N>,
        aj: f64,
        gathered: Spectrum<N>,
    ) -> bool {
        let (k, tjk) = (node.to, node.t);
        let flux_to_k = PI * tjk * gathered.sum();
        flux_to_k < self.flux_threshold
            && known
                .incoming
                .and_then(|inc| self.peak_fr(bsdf, &inc, j, k))
                .is_none_or(|peak| {
                    PI * tjk * (known.unshot * peak).sum() * (PI * known.tij.t / aj)
                        < self.flux_threshold
                })
    }

    /// Links when every error is within its bound; otherwise splits the
    /// element that matters most (the BRDF's driver when the BRDF error
    /// dominates, otherwise the larger of J and K), trying the others when
    /// it cannot split, and links when none can.
    fn link_or_split(
        &self,
        task: &mut TripleTask<'_, N>,
        (i, j, n): (ElementId, ElementId, u32),
        known: &Incidence<N>,
        link: NodeLink<N>,
        e: TripleErrors,
    ) {
        let accurate = e.brdf <= 1.0 && e.ff <= 1.0 && !e.partial;
        if accurate && !known.straddle_i {
            task.push(link);
            return;
        }
        if accurate {
            if !self.split_triple(Driver::I, task, i, j, n, known) {
                task.push(link);
            }
            return;
        }
        let k = task.h.nodes[n as usize].to;
        let (ej, ek) = (self.forest.element(j), self.forest.element(k));
        let first = if e.brdf >= e.ff.max(if e.partial { 1.0 } else { 0.0 }) {
            e.driver
        } else if ej.area >= ek.area {
            Driver::J
        } else {
            Driver::K
        };
        // The preferred element first, then the others: no allocation on
        // this hot path.
        let rest = match first {
            Driver::I => [Driver::J, Driver::K],
            Driver::J => [Driver::K, Driver::I],
            Driver::K => [Driver::J, Driver::I],
        };
        for d in [first, rest[0], rest[1]] {
            if self.split_triple(d, task, i, j, n, known) {
                return;
            }
        }
        task.push(link);
    }

    /// Applies one of the three subdivision cases (docs/solver.md,
    /// "RefineAndLink"), following an existing split of the receiving node
    /// when it is on the other side. False when the chosen element cannot be
    /// split.
    fn split_triple(
        &self,
        which: Driver,
        task: &mut TripleTask<'_, N>,
        i: ElementId,
        j: ElementId,
        n: u32,
        known: &Incidence<N>,
    ) -> bool {
        let node_split = task.h.nodes[n as usize].split;
        let which = match (which, node_split) {
            (Driver::I, _) => Driver::I,
            (_, Split::From) => Driver::J,
            (_, Split::To) => Driver::K,
            (w, Split::None) => w,
        };
        match which {
            Driver::I => {
                let Some(children) = self.forest.element(i).children() else {
                    return false;
                };
                for c in children {
                    self.refine_triple(task, c, j, n, None);
                }
                true
            }
            Driver::K => {
                let Some(nodes) = self.node_children(task.h, n, Split::To, &mut task.lost) else {
                    return false;
                };
                for c in nodes {
                    self.refine_triple(task, i, j, c, Some(known));
                }
                true
            }
            Driver::J => {
                let Some(nodes) = self.node_children(task.h, n, Split::From, &mut task.lost) else {
                    return false;
                };
                for c in nodes {
                    let jm = task.h.nodes[c as usize].from;
                    self.refine_triple(task, i, jm, c, None);
                }
                true
            }
        }
    }

    /// The children of node `n`, splitting it on `side` first if it is a
    /// leaf. `None` if it is a leaf whose element on that side cannot split.
    pub fn node_children(
        &self,
        h: &mut Hierarchy<N>,
        n: u32,
        side: Split,
        lost: &mut Spectrum<N>,
    ) -> Option<[u32; 4]> {
        if let Some(c) = h.children(n) {
            return Some(c);
        }
        let (a, b) = (h.nodes[n as usize].from, h.nodes[n as usize].to);
        let (sa, sb) = (h.from, h.to);
        let split_elem = if side == Split::From { a } else { b };
        let children = self.forest.element(split_elem).children()?;
        let pairs = children.map(|c| if side == Split::From { (c, b) } else { (a, c) });
        let throughputs = pairs.map(|(x, y)| self.throughput(sb.of(y), sa.of(x)));
        *lost += h.split(n, side, pairs, throughputs);
        h.children(n)
    }

    /// The nodes of `h` whose sender element is exactly `j`, splitting on
    /// the sender side down to `j` where needed and descending through
    /// receiver-side splits (they keep the same sender element).
    pub fn nodes_for(
        &self,
        h: &mut Hierarchy<N>,
        j: ElementId,
        lost: &mut Spectrum<N>,
    ) -> Vec<u32> {
        // The chain of elements from the surface's root down to j.
        let mut chain = vec![j];
        let mut cur = j;
        while let Some(p) = self.forest.element(cur).parent {
            chain.push(p);
            cur = p;
        }
        chain.reverse();
        let mut out = Vec::new();
        let mut stack = vec![(0u32, 0usize)];
        while let Some((n, depth)) = stack.pop() {
            let from = h.nodes[n as usize].from;
            if from != chain[depth] {
                continue;
            }
            if depth + 1 == chain.len() {
                out.push(n);
                continue;
            }
            match h.nodes[n as usize].split {
                Split::To => {
                    if let Some(c) = h.children(n) {
                        stack.extend(c.iter().map(|&c| (c, depth)));
                    }
                }
                Split::From | Split::None => {
                    if let Some(c) = self.node_children(h, n, Split::From, lost) {
                        stack.extend(c.iter().map(|&c| (c, depth + 1)));
                    }
                }
            }
        }
        out
    }
}
