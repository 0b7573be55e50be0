//! The link sum at a point: the radiance arriving at x from the solution's
//! senders, E(x)/π = Σ_i L_i F(x → i) V(x, i), over the gather links of
//! the elements containing x (`trilux_solver::gather_links`).
//!
//! 1. **Links of a leaf.** The links of x's leaf and of its ancestors cover
//!    every sender once. They are gathered once per leaf and kept
//!    ([`LinkField`]): a sender is *near* when it is closer to the leaf than
//!    `NEAR_FIELD` × (its size + the leaf's size), else *far*.
//! 2. **Far field.** Over a leaf, far senders' contributions L_i F(x → i)
//!    vary smoothly (their distance exceeds both sizes), so the sum of the
//!    fully visible ones is computed exactly at the leaf's four corners and
//!    interpolated bilinearly at x, in its logarithm (`CornerValues`);
//!    the same for the partly visible ones with the links' own visible
//!    fractions. On mesh clusters, which have no (u, v) corners, the far
//!    terms are evaluated at x.
//! 3. **Near field.** A near sender is evaluated at x with the point form
//!    factor computed exactly. Its radiance is its element's average: where
//!    a child's radiance differs from it by δ, the error is at most about
//!    δ · F(x → i), and the sender is refined into its children where that
//!    bound exceeds `NEAR_FIELD_TOLERANCE` of the whole sum (a cut chosen
//!    per point, as lightcuts do: Walter et al. 2005). Curved senders near
//!    x are refined too: their point form factor comes from a fixed rule,
//!    accurate only from afar. The senders left at their average near x are
//!    reported ([`LinkCache::coarse_near`]) for the renderer's near-field
//!    correction (`link_gather`).
//! 4. **Reuse within a pixel.** The near sum changes little across a
//!    pixel's footprint: a pixel's samples that land on the same leaf reuse
//!    the near terms of the first ([`LinkCache`]), whose point is uniform
//!    over the footprint, so that the pixel's mean is unbiased.
//! 5. **Visibility.** Links whose shadow rays all passed in the solve need
//!    no ray, unless their sender emits: a few rays between two elements do
//!    not prove that no small occluder casts a sharp shadow, and direct
//!    shadows are what a viewer sees first. The *traced* links (partly
//!    visible ones and those from emitters) are either taken with the
//!    visible fraction v_k the solve measured (`Cached`) or corrected by
//!    `PARTIAL_RAYS` shadow rays (`Traced`): each picks a traced sender
//!    k with probability p_k ∝ a weight w_k (its contribution, at the
//!    corners for far senders) and a point y on it with area density p(y),
//!    so that L_k G(x, y) (V(x, y) − v_k) / (p(y) p_k), G = cos θ_x cos θ_y
//!    / (π r²), is unbiased for what the cached sum misses,
//!    Σ_k L_k (∫ G V dA − v_k F_k). The cached sum is a control variate:
//!    where the solve's fractions are right (an unoccluded emitter, as in
//!    the furnace) the rays add no noise, and only real shadows cost
//!    variance. V is weighted by the form factor's kernel, not by area: a
//!    sender seen partly at grazing angles would otherwise be biased.

use std::sync::OnceLock;

use glam::DVec3;
use trilux_color::Spectrum;
use trilux_geometry::{Element, FaceElement, PointFormFactors, Side, SurfaceCoord};
use trilux_solver::LinkSource;

use crate::records::{GatherStats, LinkVisibility};
use crate::solution::RadianceSolution;

/// A sender closer to a receiving leaf than this many times their sizes is
/// evaluated at the point, and may be refined into its children.
pub(crate) const NEAR_FIELD: f64 = 1.0;

/// The error bound (relative to the whole sum) above which a near sender
/// is refined.
pub(crate) const NEAR_FIELD_TOLERANCE: f64 = 0.002;

/// Shadow rays per link sum for its traced links (step 5).
pub(crate) const PARTIAL_RAYS: u32 = 2;

/// The point a link sum is evaluated at.
pub struct Receiver {
    /// The point.
    pub x: DVec3,
    /// Its unit normal on the viewer's side.
    pub n: DVec3,
    /// Its coordinates on its surface (for the far field's interpolation).
    pub coord: SurfaceCoord,
    /// The leaf element (and face side) containing it.
    pub leaf: FaceElement,
}

/// A gather link as one receiving leaf sees it.
#[derive(Clone, Copy, Debug)]
struct Link<const N: usize> {
    sender: FaceElement,
    source: LinkSource,
    /// The sender's radiance L.
    l: Spectrum<N>,
    /// The link's measured visible fraction.
    v: f64,
    /// Traced with shadow rays when the visibility is traced: partly
    /// visible links, and every link from an emitter (a few shadow rays of
    /// the solve passing between two elements do not prove that a small
    /// occluder casts no sharp shadow on the receiver).
    traced: bool,
}

/// One sender's unoccluded contribution at a point.
#[derive(Clone, Copy, Debug)]
struct Term<const N: usize> {
    link: Link<N>,
    /// L F(x → sender).
    c: Spectrum<N>,
}

/// A smooth positive quantity at a leaf's four corners, interpolated
/// bilinearly in its logarithm where all four are positive: far-field
/// irradiance falls off about as a power of distance, which a linear
/// interpolation overestimates (by up to 0.7 % over a leaf of 1/8 at twice
/// a light's size away; 0.09 % in the logarithm:
/// crates/trilux/tests/link_gather.rs).
#[derive(Clone, Debug)]
struct CornerValues<const N: usize> {
    values: [Spectrum<N>; 4],
    /// ln of the values (−∞ where a value is not positive).
    logs: [Spectrum<N>; 4],
}

impl<const N: usize> CornerValues<N> {
    fn new(values: [Spectrum<N>; 4]) -> Self {
        let logs = values.map(|v| v.map(|x| if x > 0.0 { x.ln() } else { f64::NEG_INFINITY }));
        CornerValues { values, logs }
    }

    /// The value at bilinear weights `w`.
    fn at(&self, w: &[f64; 4]) -> Spectrum<N> {
        let mut out = Spectrum::zero();
        for b in 0..N {
            let logs = [0, 1, 2, 3].map(|k| self.logs[k][b]);
            out[b] = if logs.iter().all(|l| l.is_finite()) {
                (0..4).map(|k| w[k] * logs[k]).sum::<f64>().exp()
            } else {
                (0..4).map(|k| w[k] * self.values[k][b]).sum()
            };
        }
        out
    }
}

/// The far field of a leaf at its corners (module docs, step 2).
#[derive(Clone, Debug)]
struct Corners<const N: usize> {
    /// Σ L F of the fully visible far links.
    full: CornerValues<N>,
    /// Σ L F v of the partly visible far links, v their measured fraction.
    partial: CornerValues<N>,
    /// Per partly visible far link, Σ over the corners of its L F (its
    /// shadow-ray pick weight).
    weights: Vec<f64>,
}

/// What every point of one receiving leaf shares (module docs, step 1).
#[derive(Clone, Debug)]
pub struct LeafLinks<const N: usize> {
    /// The fully visible far links (only on clusters: elsewhere the
    /// corners hold their sum).
    far_full: Vec<Link<N>>,
    far_partial: Vec<Link<N>>,
    near: Vec<Link<N>>,
    /// The far field at the corners; `None` for clusters.
    corners: Option<Corners<N>>,
}

/// The link sums' shared state over one solution: the point form factors
/// and every leaf's links, gathered on first use (from any thread).
pub struct LinkField<const N: usize> {
    ff: PointFormFactors,
    leaves: Vec<OnceLock<Box<LeafLinks<N>>>>,
}

impl<const N: usize> LinkField<N> {
    /// The state for a forest of `elements` elements (`ff` its shapes).
    pub fn new(ff: PointFormFactors, elements: usize) -> Self {
        LinkField {
            ff,
            leaves: (0..2 * elements).map(|_| OnceLock::new()).collect(),
        }
    }

    /// The point form factors.
    pub fn form_factors(&self) -> &PointFormFactors {
        &self.ff
    }

    /// The links of `leaf`, gathered on first use.
    fn leaf<S: RadianceSolution<N>>(
        &self,
        solution: &S,
        leaf: FaceElement,
        stats: &mut GatherStats,
    ) -> Option<&LeafLinks<N>> {
        let slot = self.leaves.get(leaf.key() as usize)?;
        Some(slot.get_or_init(|| Box::new(gather_leaf(solution, &self.ff, leaf, stats))))
    }
}

/// Step 1 and the corners of step 2 for one leaf.
fn gather_leaf<const N: usize, S: RadianceSolution<N>>(
    solution: &S,
    ff: &PointFormFactors,
    leaf: FaceElement,
    stats: &mut GatherStats,
) -> LeafLinks<N> {
    let forest = solution.forest();
    let le = forest.element(leaf.element);
    let mut out = LeafLinks {
        far_full: Vec::new(),
        far_partial: Vec::new(),
        near: Vec::new(),
        corners: None,
    };
    let emission = solution.scene().emission();
    let mut element = Some(leaf.element);
    while let Some(e) = element {
        solution.for_each_link(leaf.with(e), &mut |link, l| {
            if l.is_black() {
                return;
            }
            let sender = FaceElement::new(link.sender, link.sender_face.side());
            let shape = forest.geometry().surface(link.sender_face.surface()).shape as usize;
            let emits = sender.side == Side::Front && !emission[shape].is_black();
            let v = f64::from(link.visibility);
            let t = Link {
                sender,
                source: link.source,
                l,
                v,
                traced: v < 1.0 || emits,
            };
            if is_near(forest.element(sender.element), le) {
                out.near.push(t);
            } else if !t.traced {
                out.far_full.push(t);
            } else {
                out.far_partial.push(t);
            }
        });
        element = forest.element(e).parent;
    }
    if let Some(corners) = forest.element_corners(leaf.element) {
        let sign = leaf.side.sign();
        let mut full = [Spectrum::zero(); 4];
        let mut partial = [Spectrum::zero(); 4];
        let mut weights = vec![0.0; out.far_partial.len()];
        for (k, &(x, n)) in corners.iter().enumerate() {
            let n = n * sign;
            for t in &out.far_full {
                full[k] += t.l * ff.eval(x, n, t.sender);
            }
            for (i, t) in out.far_partial.iter().enumerate() {
                let f = ff.eval(x, n, t.sender);
                partial[k] += t.l * (f * t.v);
                weights[i] += t.l.sum() * f;
            }
        }
        stats.link_senders += 4 * (out.far_full.len() + out.far_partial.len()) as u64;
        out.corners = Some(Corners {
            full: CornerValues::new(full),
            partial: CornerValues::new(partial),
            weights,
        });
        // The corners hold all the fully visible far links say.
        out.far_full = Vec::new();
    }
    out.far_partial.shrink_to_fit();
    out.near.shrink_to_fit();
    out
}

/// What a pixel's first sample on a leaf leaves for the next ones.
#[derive(Clone, Debug, Default)]
struct LeafSum<const N: usize> {
    leaf: Option<FaceElement>,
    /// Σ of the fully visible near terms (and, on clusters, far terms).
    full: Spectrum<N>,
    /// The partly visible near terms (and, on clusters, far terms).
    partial: Vec<Term<N>>,
    /// The near senders the sum took at their average radiance (leaves, or
    /// refined no further): where a sample's cosine ray meets one of them,
    /// the renderer corrects the average by the link sum there.
    coarse_near: Vec<FaceElement>,
}

/// A pixel's near sums, one per leaf its samples landed on (a pixel's
/// footprint spans a few leaves).
#[derive(Clone, Debug)]
pub struct LinkCache<const N: usize> {
    entries: [LeafSum<N>; CACHED_LEAVES],
    /// The entry to overwrite next.
    next: usize,
    /// The entry the last sum used.
    last: Option<usize>,
    /// Scratch: the near terms before refinement.
    near: Vec<Term<N>>,
    /// Scratch: shadow-ray pick weights.
    weights: Vec<f64>,
}

/// Leaves a pixel's cache remembers.
const CACHED_LEAVES: usize = 4;

impl<const N: usize> Default for LinkCache<N> {
    fn default() -> Self {
        LinkCache {
            entries: std::array::from_fn(|_| LeafSum::default()),
            next: 0,
            last: None,
            near: Vec::new(),
            weights: Vec::new(),
        }
    }
}

impl<const N: usize> LinkCache<N> {
    /// Forgets everything (a new pixel).
    pub fn clear(&mut self) {
        for e in &mut self.entries {
            e.leaf = None;
        }
        self.next = 0;
        self.last = None;
    }

    /// The near senders the last link sum took at their average
    /// (`LeafSum::coarse_near`).
    pub fn coarse_near(&self) -> &[FaceElement] {
        self.last
            .map_or(&[], |k| self.entries[k].coarse_near.as_slice())
    }
}

/// The link sum at `r` (module docs), reusing `cache` when it holds the
/// same leaf.
pub fn link_sum<const N: usize, S: RadianceSolution<N>>(
    solution: &S,
    field: &LinkField<N>,
    r: &Receiver,
    visibility: LinkVisibility<'_>,
    cache: &mut LinkCache<N>,
    stats: &mut GatherStats,
) -> Spectrum<N> {
    let Some(links) = field.leaf(solution, r.leaf, stats) else {
        return Spectrum::zero();
    };
    let far = far_field(solution, r, links);
    let k = match cache.entries.iter().position(|e| e.leaf == Some(r.leaf)) {
        Some(k) => k,
        None => {
            let k = cache.next;
            cache.next = (k + 1) % CACHED_LEAVES;
            let mut near = std::mem::take(&mut cache.near);
            let cut = !matches!(visibility, LinkVisibility::Secondary);
            let entry = &mut cache.entries[k];
            let far_total = far.full.sum() + far.partial.sum();
            fill(
                solution, &field.ff, r, links, far_total, entry, &mut near, cut, stats,
            );
            cache.near = near;
            k
        }
    };
    cache.last = Some(k);
    let entry = &cache.entries[k];
    let near: Spectrum<N> = entry.partial.iter().map(|t| t.c * t.link.v).sum();
    let cached = far.full + entry.full + near + far.partial;
    match visibility {
        LinkVisibility::Cached | LinkVisibility::Secondary => cached,
        LinkVisibility::Traced { sampler, dim } => {
            let rays = PartialRays {
                far: links
                    .corners
                    .as_ref()
                    .map(|c| (&links.far_partial[..], &c.weights[..])),
                near: &entry.partial,
                sampler,
                dim,
            };
            let residual = rays.estimate(solution, r, &mut cache.weights, stats);
            // A sample may overshoot below zero where the solve's fractions
            // overstate the visibility; radiance stays non-negative.
            (cached + residual).map(|x| x.max(0.0))
        }
    }
}

/// The far field at `r` interpolated from the corners (zero on clusters,
/// whose far terms are in the pixel's entry).
struct Far<const N: usize> {
    full: Spectrum<N>,
    partial: Spectrum<N>,
}

fn far_field<const N: usize, S: RadianceSolution<N>>(
    solution: &S,
    r: &Receiver,
    links: &LeafLinks<N>,
) -> Far<N> {
    let zero = Far {
        full: Spectrum::zero(),
        partial: Spectrum::zero(),
    };
    let Some(c) = &links.corners else {
        return zero;
    };
    let Some(w) = solution.forest().bilinear_weights(r.leaf.element, r.coord) else {
        return zero;
    };
    Far {
        full: c.full.at(&w),
        partial: c.partial.at(&w),
    }
}

/// The near terms at `r` (and, on clusters, the far ones): fully visible
/// ones summed, partial ones kept, near ones refined when `cut` (step 3).
#[allow(clippy::too_many_arguments)]
fn fill<const N: usize, S: RadianceSolution<N>>(
    solution: &S,
    ff: &PointFormFactors,
    r: &Receiver,
    links: &LeafLinks<N>,
    far_total: f64,
    entry: &mut LeafSum<N>,
    near: &mut Vec<Term<N>>,
    cut: bool,
    stats: &mut GatherStats,
) {
    entry.leaf = Some(r.leaf);
    entry.full = Spectrum::zero();
    entry.partial.clear();
    entry.coarse_near.clear();
    let term = |t: &Link<N>| Term {
        link: *t,
        c: t.l * ff.eval(r.x, r.n, t.sender),
    };
    if links.corners.is_none() {
        for t in links.far_full.iter().chain(&links.far_partial).map(term) {
            if !t.link.traced {
                entry.full += t.c;
            } else if t.c.sum() > 0.0 {
                entry.partial.push(t);
            }
        }
        stats.link_senders += (links.far_full.len() + links.far_partial.len()) as u64;
    }
    near.clear();
    near.extend(links.near.iter().map(term));
    stats.link_senders += near.len() as u64;
    if !cut {
        for &t in near.iter() {
            if !t.link.traced {
                entry.full += t.c;
            } else if t.c.sum() > 0.0 {
                entry.partial.push(t);
            }
        }
        return;
    }
    let total = far_total
        + entry.full.sum()
        + entry
            .partial
            .iter()
            .map(|t| t.c.sum() * t.link.v)
            .sum::<f64>()
        + near.iter().map(|t| t.c.sum() * t.link.v).sum::<f64>();
    let LeafSum {
        full,
        partial,
        coarse_near,
        ..
    } = entry;
    for &t in near.iter() {
        let tolerance = NEAR_FIELD_TOLERANCE * total;
        near_field(solution, ff, r, t, tolerance, stats, &mut |t, is_near| {
            if is_near {
                coarse_near.push(t.link.sender);
            }
            if !t.link.traced {
                *full += t.c;
            } else {
                partial.push(t);
            }
        });
    }
}

/// Step 3: refines a term near the receiver into its children while its
/// error bound exceeds `tolerance`, handing the final terms to `out` with
/// whether they are still near the point.
fn near_field<const N: usize, S: RadianceSolution<N>>(
    solution: &S,
    ff: &PointFormFactors,
    r: &Receiver,
    t: Term<N>,
    tolerance: f64,
    stats: &mut GatherStats,
    out: &mut dyn FnMut(Term<N>, bool),
) {
    let forest = solution.forest();
    let e = forest.element(t.link.sender.element);
    let near = (e.centre - r.x).length() < NEAR_FIELD * e.bounds.diagonal().length();
    let (Some(children), LinkSource::Face(face), true) = (e.children(), t.link.source, near) else {
        if t.c.sum() > 0.0 {
            out(t, near);
        }
        return;
    };
    let lc = children.map(|c| solution.face_radiance(face, c));
    let mean = t.link.l.sum();
    let delta = lc
        .iter()
        .map(|l| (l.sum() - mean).abs())
        .fold(0.0, f64::max);
    let f = if mean > 0.0 { t.c.sum() / mean } else { 0.0 };
    if e.is_planar() && delta * f <= tolerance {
        return out(t, true);
    }
    for (c, l) in children.into_iter().zip(lc) {
        let sender = t.link.sender.with(c);
        stats.link_senders += 1;
        let f = ff.eval(r.x, r.n, sender);
        if f > 0.0 && !l.is_black() {
            let child = Term {
                link: Link {
                    sender,
                    l,
                    ..t.link
                },
                c: l * f,
            };
            near_field(solution, ff, r, child, tolerance, stats, out);
        }
    }
}

/// True when the sender `s` is near the receiving leaf `leaf` (step 1).
fn is_near(s: &Element, leaf: &Element) -> bool {
    let reach = s.bounds.diagonal().length() + leaf.bounds.diagonal().length();
    (s.centre - leaf.centre).length() < NEAR_FIELD * reach
}

/// Step 5's shadow rays over a point's partly visible terms.
struct PartialRays<'a, const N: usize> {
    /// The leaf's far partial links with their pick weights (`None` on
    /// clusters, whose far terms are among `near`).
    far: Option<(&'a [Link<N>], &'a [f64])>,
    /// The pixel entry's partial terms, with their contributions.
    near: &'a [Term<N>],
    sampler: &'a crate::sampler::PixelSampler,
    dim: u32,
}

impl<const N: usize> PartialRays<'_, N> {
    /// The estimate of Σ_k L_k (∫ G V dA − v_k F_k), what the solve's
    /// fractions miss (module docs, step 5).
    fn estimate<S: RadianceSolution<N>>(
        &self,
        solution: &S,
        r: &Receiver,
        weights: &mut Vec<f64>,
        stats: &mut GatherStats,
    ) -> Spectrum<N> {
        let (far, far_w) = self.far.unwrap_or((&[], &[]));
        weights.clear();
        weights.extend_from_slice(far_w);
        weights.extend(self.near.iter().map(|t| t.c.sum()));
        let total: f64 = weights.iter().sum();
        if total.is_nan() || total <= 0.0 {
            return Spectrum::zero();
        }
        let forest = solution.forest();
        let mut sum = Spectrum::<N>::zero();
        for k in 0..PARTIAL_RAYS {
            let chosen = pick(weights, self.sampler.get1(self.dim + 3 * k) * total);
            let link = match chosen.checked_sub(far.len()) {
                None => far[chosen],
                Some(i) => self.near[i].link,
            };
            if link.l.is_black() || weights[chosen] <= 0.0 {
                continue;
            }
            let u = self.sampler.get2(self.dim + 3 * k + 1);
            let y = forest.sample_element(link.sender.element, u);
            let d = y.point - r.x;
            let d2 = d.length_squared();
            let w = d / d2.sqrt();
            let cos_y = y.normal.dot(-w) * link.sender.side.sign();
            let g = r.n.dot(w).max(0.0) * cos_y.max(0.0) / (std::f64::consts::PI * d2);
            if !(g > 0.0 && g.is_finite() && y.pdf_area > 0.0) {
                continue;
            }
            stats.shadow_rays += 1;
            let visible = forest.geometry().transmittance(r.x, y.point);
            // L G (V − v) / pdf(y), divided by the pick probability w_k / Σ w.
            sum += link.l * (g / y.pdf_area * total / weights[chosen] * (visible - link.v));
        }
        sum * (1.0 / f64::from(PARTIAL_RAYS))
    }
}

/// The index whose cumulative weight first exceeds `target`.
fn pick(weights: &[f64], target: f64) -> usize {
    let mut acc = 0.0;
    for (i, w) in weights.iter().enumerate() {
        acc += w;
        if target < acc {
            return i;
        }
    }
    weights.len().saturating_sub(1)
}
