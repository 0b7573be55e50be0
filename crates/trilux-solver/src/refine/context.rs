//! What refinement reads ([`RefineContext`]): the element trees, the
//! scene's faces and materials, the throughput cache and the photometric
//! threshold, shared by the parallel tasks of a shot; T through the cache
//! and the point-to-disc form-factor estimates both stages use.

use std::f64::consts::PI;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

use glam::DVec3;
use trilux_brdf::{AlbedoTable, Bsdf};
use trilux_geometry::{ElementForest, FaceElement, FaceId, PerFace, Sided, Visibility};

use crate::cluster_transport::{Clusters, FarContext};
use crate::faces::TransportFace;
use crate::interaction::Hierarchy;
use crate::settings::SolverSettings;
use crate::textures::ElementTextures;
use crate::throughput::{Throughput, ThroughputCache, compute_throughput, throughput_with_rays};

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
    pub clusters: &'a Clusters,
    /// Directional albedo per material (the sampled lobes' scale).
    pub albedo: &'a [AlbedoTable<N>],
    /// When the solve's time budget runs out: refinement reached after it
    /// links where it stands (docs/solver.md, "The deadline inside a
    /// shot"). `None` without a budget.
    pub deadline: Option<Instant>,
    /// What refinement cut short because the deadline had passed.
    pub late: Lateness,
    /// The release of the waiting glossy light after the last shot
    /// (docs/solver.md, "Deferred glossy reception"): its roots are made
    /// with the base rays, as past the deadline.
    pub final_release: bool,
}

/// What a shot's refinement did after the deadline (the stats' `late_*`
/// fields), counted across its parallel tasks.
#[derive(Debug, Default)]
pub(crate) struct Lateness {
    /// Links made where refinement would have split (or nodes used where
    /// it would have split the stored hierarchy down to a pair link's
    /// receiver).
    pub links: AtomicU64,
    /// Root throughputs made after the deadline.
    pub roots: AtomicU64,
    /// Their CPU time in nanoseconds, summed over threads.
    pub root_nanos: AtomicU64,
}

impl<'a, const N: usize> RefineContext<'a, N> {
    /// What far links read.
    pub fn far(&self) -> FarContext<'a> {
        FarContext {
            forest: self.forest,
            tree: &self.clusters.tree,
            exposed_area: self.exposed_area,
            burial: self.visibility.burial(),
            enclosed: &self.clusters.enclosed,
            points: &self.clusters.points,
        }
    }
}

/// Point-to-disc estimate of F_{a→b} (Hanrahan, Salzman & Aupperle 1991): b seen from a's
/// centre as a disc of the same area.
pub(super) fn disc_estimate(pa: DVec3, na: DVec3, pb: DVec3, nb: DVec3, area_b: f64) -> f64 {
    if (pb - pa).length_squared() <= 0.0 {
        return 1.0;
    }
    // Elements that do not face each other at their centres may still
    // exchange light near their edges: use the larger cosines' bound.
    disc_facing(pa, na, pb, nb, area_b).unwrap_or_else(|| {
        let r2 = (pb - pa).length_squared();
        (area_b / (PI * r2 + area_b)).min(1.0)
    })
}

/// A cos θ_a cos θ_b / (π r² + A) from `pa` to a disc of area `area_b`
/// at `pb`, when the two face each other (both cosines positive); `None`
/// otherwise, and for coincident points.
pub(crate) fn disc_facing(pa: DVec3, na: DVec3, pb: DVec3, nb: DVec3, area_b: f64) -> Option<f64> {
    let d = pb - pa;
    let r2 = d.length_squared();
    if r2 <= 0.0 {
        return None;
    }
    let r = r2.sqrt();
    let (ca, cb) = (na.dot(d) / r, -nb.dot(d) / r);
    (ca > 0.0 && cb > 0.0).then(|| (area_b * ca * cb / (PI * r2 + area_b)).min(1.0))
}

impl<const N: usize> RefineContext<'_, N> {
    /// True once the deadline has passed (one look at the clock; never
    /// without a budget).
    pub fn past_deadline(&self) -> bool {
        self.deadline.is_some_and(|d| Instant::now() >= d)
    }

    /// Counts a link made coarser because the deadline had passed.
    pub fn count_late_link(&self) {
        self.late.links.fetch_add(1, Ordering::Relaxed);
    }

    /// True, and counted, once the deadline has passed: the caller links
    /// where it stands instead of refining.
    pub fn cut_short(&self) -> bool {
        let late = self.past_deadline();
        if late {
            self.count_late_link();
        }
        late
    }

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

    /// The visible fraction of a pair from the base number of shadow
    /// rays (not the ×16 of a root pair), or the cached one: for gather
    /// links whose flux is negligible or whose sender comes after the
    /// time budget. Not cached, so that refinement never takes it for a
    /// root pair's T.
    pub fn cheap_visibility(&self, recv: FaceElement, send: FaceElement) -> f64 {
        if let Some(t) = self.cache.get(recv, send) {
            return t.v;
        }
        let samples = visibility_samples_for(
            &self.clusters.partly_cut,
            [recv, send],
            self.settings.visibility_samples,
        );
        self.visibility.weighted(recv, send, samples)
    }

    /// Makes the root throughput of a pending hierarchy (light is about to
    /// arrive at its sender face): the same T the setup used to make for
    /// every root pair, with the root pair's shadow rays; past the deadline
    /// with the base rays only (docs/solver.md, "The deadline inside a
    /// shot").
    pub fn make_root(&self, h: &mut Hierarchy<N>) {
        if !h.pending {
            return;
        }
        let root_of = |f: FaceId| f.of(self.forest.root(f.surface()));
        let pair = [root_of(h.to), root_of(h.from)];
        let samples = visibility_samples_for(
            &self.clusters.partly_cut,
            pair,
            self.settings.visibility_samples,
        );
        // Past the deadline, the base rays (not ×16): the root throughputs
        // were most of what a cut-short shot still spent (docs/results.md,
        // "Real interiors"); timed there.
        let late = self.past_deadline().then(Instant::now);
        h.make_root(if late.is_some() || self.final_release {
            throughput_with_rays(&self.visibility, pair[0], pair[1], samples, false)
        } else {
            compute_throughput(&self.visibility, pair[0], pair[1], samples, false)
        });
        if let Some(start) = late {
            let nanos = u64::try_from(start.elapsed().as_nanos()).unwrap_or(u64::MAX);
            self.late.roots.fetch_add(1, Ordering::Relaxed);
            self.late.root_nanos.fetch_add(nanos, Ordering::Relaxed);
        }
    }

    /// Both point-to-disc estimates F̂_{a→b} and F̂_{b→a}.
    pub(super) fn ff_estimates(&self, a: FaceElement, b: FaceElement) -> (f64, f64) {
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
}
