//! Stage 2 of RefineAndLink: three-point links (i j) → (j k) from each
//! pair link into the stored interaction hierarchies leaving j's side (its
//! glossy part; paper §3.2.2, Fig. 4–5, §4.3). Refined by the BRDF error
//! FrErr, the form factor and visibility of (j, k) and the photometric
//! criterion on the flux that would go on towards k, with the three
//! subdivision cases: split I (sender sub-pairs i_m j), split K (receiver
//! nodes j k_m) or split J (matched pairs i j_m → j_m k only;
//! docs/solver.md, "RefineAndLink").

use std::f64::consts::PI;
use std::sync::OnceLock;

use glam::DVec3;
use trilux_brdf::area::Element as Driver;
use trilux_brdf::{Bsdf, ElementPoints, brdf_variation};
use trilux_color::Spectrum;
use trilux_geometry::{ElementId, FaceElement, FaceId};

use super::context::RefineContext;
use super::incidences::{IncidenceMemo, LocalMemo};
use super::narrow_lobe::LobeHit;
use crate::interaction::{Hierarchy, Node, Split};
use crate::link::{NodeLink, Sender};
use crate::settings::Transport;
use crate::throughput::Throughput;

/// The most a sampled link's radiance increment may be of its sender's
/// δL (docs/solver.md, "Narrow lobes"). Its expectation is at most the
/// glossy albedo (≤ 1), but S_K · T_ij / T_jk is a ratio of two sampled
/// estimates whose fluctuations above 1 are real light: held to 1,
/// metal-box's mirrors lost 0.14 % of its image, to 2 0.06 %, to 4 0.02 %.
/// 4 still bounds surfaces in contact, where T_jk came out 800 times too
/// low.
pub(super) const MAX_SAMPLED_GAIN: f64 = 4.0;

/// What a three-point link (i j) → (j k) takes from its pair (i, j), the
/// same for every receiver node k: computed once per pair link and handed
/// down the K-side recursion.
#[derive(Clone, Debug)]
pub(crate) struct Incidence<const N: usize> {
    /// T_ij.
    pub(super) tij: Throughput,
    /// δL sent from i towards j.
    pub(super) unshot: Spectrum<N>,
    /// j (a node above j may receive the pair's light after the deadline).
    j: ElementId,
    /// The light's arrival at j's centre (`RefineContext::incident`);
    /// `None` when no part of i is on the receiving side.
    incoming: Option<Incoming>,
    /// i has points on both sides of j's tangent plane.
    pub(super) straddle_i: bool,
    /// The sampled lobe of the pair (docs/solver.md, "Narrow lobes"),
    /// traced when a link first needs it and shared by every hierarchy the
    /// pair link feeds (they borrow one incidence).
    lobe: OnceLock<Vec<LobeHit<N>>>,
    /// The pair's whole glossy share is below the photometric threshold
    /// ([`RefineContext::glossy_negligible`]): stage 2 receives it at the
    /// stored nodes above j, unsplit (docs/solver.md, "Faint glossy
    /// shares").
    pub(crate) coarse: bool,
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
pub(super) struct TripleErrors {
    /// π F̂_ji (fr_max − fr_min) / FrErr.
    pub(super) brdf: f64,
    /// The spread of F(y → j) over y in K, / FFErr.
    pub(super) ff: f64,
    /// (j, k) partly visible, or K straddling j's tangent plane.
    pub(super) partial: bool,
    /// The element whose variation drives the BRDF error.
    pub(super) driver: Driver,
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
    /// The pair link being refined.
    pub group: u32,
    /// Flux that splits could not keep.
    pub lost: Spectrum<N>,
    /// The links made.
    pub out: Vec<NodeLink<N>>,
    /// The shot's sub-pair incidences, shared with its other tasks.
    pub memo: &'t IncidenceMemo<Incidence<N>>,
    /// The incidences this task has already asked the shared table for.
    pub local: LocalMemo<Incidence<N>>,
}

impl<const N: usize> TripleTask<'_, N> {
    /// Keeps a link that carries light (a zero of the BRDF carries none).
    fn push(&mut self, link: NodeLink<N>) {
        if !link.gathered.is_black() {
            self.out.push(link);
        }
    }
}

impl<const N: usize> RefineContext<'_, N> {
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
        let unshot = sender.sent_radiance(self.forest, i.element, j.element);
        if unshot.is_black() {
            return None;
        }
        let frame = trilux_brdf::Frame::from_normal(self.forest.element(j.element).normal);
        Some(Incidence {
            tij,
            unshot,
            j: j.element,
            incoming: self
                .incident(&frame, i.element, j.element, j.side.sign())
                .map(|wi| Incoming { frame, wi }),
            straddle_i: self.straddles(i.element, j.element),
            lobe: OnceLock::new(),
            coarse: false,
        })
    }

    /// True when the glossy flux the pair brings to j, π T_ij (δL_i ·
    /// ρ_g(ω_i)) with ρ_g the glossy albedo (directional albedo less ρ_d,
    /// times j's texture) for the light's direction at j's centre, is below
    /// the photometric threshold. Every three-point link of the pair then
    /// carries less (the group's links together reflect at most ρ_g of
    /// what arrived), so the paper's criterion would link each where it
    /// stands. Two-point transport only (the uniform mode's links carry
    /// the whole fr).
    pub fn glossy_negligible(&self, face: FaceId, inc: &Incidence<N>) -> bool {
        self.glossy_flux_bound(face, inc)
            .is_some_and(|bound| bound < self.flux_threshold)
    }

    /// π T_ij (δL_i · ρ_g(ω_i)) of [`Self::glossy_negligible`] (band sum);
    /// `None` when no part of i is in front of j, or in uniform mode.
    pub fn glossy_flux_bound(&self, face: FaceId, inc: &Incidence<N>) -> Option<f64> {
        let incoming = inc.incoming?;
        if self.settings.transport != Transport::TwoPoint {
            return None;
        }
        let shape = self.faces[face].shape;
        let bsdf = &self.materials[shape];
        let g = self
            .textures
            .map_or(Spectrum::splat(1.0), |t| t.glossy(face, inc.j));
        let glossy_albedo = (self.albedo[shape].albedo(incoming.wi)
            - bsdf.diffuse_albedo(face.side()))
        .max(Spectrum::zero())
            * g;
        Some(PI * inc.tij.t * (inc.unshot * glossy_albedo).sum())
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
                let (sender, pair) = (task.sender, (si.of(i), sj.of(j)));
                let made = task.memo.get_or_make(&mut task.local, pair.0, pair.1, || {
                    self.incidence(sender, pair.0, pair.1)
                });
                let Some(k) = made else { return };
                owned = k;
                &*owned
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
        if let Some((share, inside)) =
            self.sampled_share(&known.lobe, (sj, i, known.j), task.h.to, k)
        {
            self.link_sampled(task, (i, j, n), known, (share, &inside), straddle_k);
            return;
        }
        // A textured j: its glossy part is g(j) times the nominal one.
        let (fr, texture_variation) = match self.textures {
            Some(t) => (fr * t.glossy(sj, j), t.glossy_variation(self.forest, sj, j)),
            None => (fr, 0.0),
        };
        let gathered = known.unshot * fr * (PI * known.tij.t / aj);
        let link = NodeLink {
            node: n,
            group: task.group,
            gathered,
            sampled: false,
        };
        // A faint glossy share, or past the deadline: linked as it stands,
        // before the costly oracle.
        if known.coarse
            || self.below_photometric(bsdf, known, j, &task.h.nodes[n as usize], aj, gathered)
            || self.cut_short()
        {
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

    /// A link whose receiver K is reached by a sampled narrow lobe
    /// (docs/solver.md, "Narrow lobes"): its radiance from the sampled
    /// `share` of the lobe landing in K, refined where the hits `inside` K
    /// land unevenly over it.
    pub(super) fn link_sampled(
        &self,
        task: &mut TripleTask<'_, N>,
        (i, j, n): (ElementId, ElementId, u32),
        known: &Incidence<N>,
        (share, inside): (Spectrum<N>, &[LobeHit<N>]),
        straddle_k: bool,
    ) {
        let sj = task.h.from;
        let node = &task.h.nodes[n as usize];
        let (k, tjk, vjk, spread_jk) = (node.to, node.t, node.v, node.spread);
        let g = self
            .textures
            .map_or(Spectrum::splat(1.0), |t| t.glossy(sj, j));
        // The flux on towards k is π T_ij δL · share, so ΔL^G = δL ·
        // share · T_ij / T_jk, at most MAX_SAMPLED_GAIN δL (its
        // expectation is at most δL: ∫ fr cos dω ≤ 1), where a T_jk
        // estimated low (surfaces in contact) would make it unbounded.
        let ratio = known.tij.t / tjk;
        let reflected = Spectrum::from_fn(|b| (share[b] * ratio).min(MAX_SAMPLED_GAIN));
        let gathered = known.unshot * reflected * g;
        let link = NodeLink {
            node: n,
            group: task.group,
            gathered,
            sampled: true,
        };
        if PI * tjk * gathered.sum() < self.flux_threshold || self.cut_short() {
            task.push(link);
            return;
        }
        let errors = TripleErrors {
            // Where in K the lobe lands, not fr's variation, decides.
            brdf: if self.footprint_uneven(k, inside) {
                2.0
            } else {
                0.0
            },
            ff: spread_jk / self.settings.ff_eps,
            partial: (vjk > 0.0 && vjk < 1.0) || straddle_k,
            driver: Driver::K,
        };
        self.link_or_split(task, (i, j, n), known, link, errors);
    }

    /// A node whose elements were found not to see each other: as in stage
    /// 1, near the roots a few shadow rays may miss a gap, so look one
    /// level further (splitting the larger of J and K) before giving the
    /// pair up, when the pair's light is worth it
    /// ([`Self::searches_further`]).
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
        let near_roots = ej.depth + ek.depth < 2;
        if near_roots
            && self.searches_further(known)
            && self.throughput(task.h.to.of(k), task.h.from.of(j)).f > 0.0
        {
            let side = if ej.area >= ek.area {
                Driver::J
            } else {
                Driver::K
            };
            self.split_triple(side, task, i, j, n, known);
        }
    }

    /// Whether a pair's light is worth a search beyond its links' own
    /// elements (an unseen pair retried one level down, an element
    /// straddling j's plane split for its part in front): not past the
    /// deadline, not for a faint glossy share, nor when the whole pair
    /// link carries less than the photometric threshold (docs/solver.md,
    /// "Refinement"); the group's renormalisation makes up.
    fn searches_further(&self, known: &Incidence<N>) -> bool {
        !known.coarse
            && !self.past_deadline()
            && PI * known.tij.t * known.unshot.sum() >= self.flux_threshold
    }

    /// No sample point of i or K on the receiving side of j: an element
    /// that lies partly behind j's tangent plane still carries light
    /// through its part in front, so refine it like partial visibility. (A
    /// zero of the BRDF itself, a lobe far from K, is not refined for: the
    /// peak bound of [`Self::below_photometric`] decides whether the lobe
    /// may be near.)
    pub(super) fn split_across_plane(
        &self,
        task: &mut TripleTask<'_, N>,
        i: ElementId,
        j: ElementId,
        n: u32,
        known: &Incidence<N>,
        straddle_k: bool,
    ) {
        if !self.searches_further(known) {
            return;
        }
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
    pub(super) fn link_or_split(
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

    /// The nodes of `h` whose sender element is exactly `j`, into `out`
    /// (cleared first), splitting on the sender side down to `j` where
    /// needed and descending through receiver-side splits (they keep the
    /// same sender element). Past the deadline a leaf above `j` is not
    /// split: it is returned as it stands (its sender element above `j`),
    /// and counted late; so is it, uncounted, for a `coarse` pair (a
    /// glossy share below the photometric threshold). Stage 2 calls this
    /// once per pair link and hierarchy, so it allocates nothing but
    /// `out`'s growth.
    pub fn nodes_for(
        &self,
        h: &mut Hierarchy<N>,
        (j, coarse): (ElementId, bool),
        lost: &mut Spectrum<N>,
        out: &mut Vec<u32>,
    ) {
        out.clear();
        self.make_root(h);
        // A link to the whole surface (every link of a shot below the
        // photometric threshold) is the root node's.
        if h.nodes[0].from == j {
            out.push(0);
            return;
        }
        let target = self.forest.element(j).depth as usize;
        // The element on the chain from the surface's root down to j at
        // `depth` (j's ancestor; elements are a few levels deep).
        let on_chain = |depth: usize| {
            let mut e = j;
            for _ in depth..target {
                e = self.forest.element(e).parent.unwrap_or(e);
            }
            e
        };
        let mut stack = vec![(0u32, 0usize)];
        while let Some((n, depth)) = stack.pop() {
            if h.nodes[n as usize].from != on_chain(depth) {
                continue;
            }
            if depth == target {
                out.push(n);
                continue;
            }
            match h.nodes[n as usize].split {
                Split::To => {
                    if let Some(c) = h.children(n) {
                        stack.extend(c.iter().map(|&c| (c, depth)));
                    }
                }
                Split::None if coarse => out.push(n),
                Split::None if self.past_deadline() => {
                    self.count_late_link();
                    out.push(n);
                }
                Split::From | Split::None => {
                    if let Some(c) = self.node_children(h, n, Split::From, lost) {
                        stack.extend(c.iter().map(|&c| (c, depth + 1)));
                    }
                }
            }
        }
    }
}
