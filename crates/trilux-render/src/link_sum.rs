//! The link sum at a point: the radiance arriving at x from the solution's
//! senders, E(x)/π = Σ_i L_i F(x → i) V(x, i), over the gather links of
//! the elements containing x (`trilux_solver::gather_links`).
//!
//! 1. **Far field.** Every link contributes L_i F(x → i) with the point
//!    form factor computed exactly (`trilux_geometry::point_form_factor`).
//! 2. **Near field.** A link's sender radiance is its element's average.
//!    Where x is close to the sender (within [`NEAR_FIELD`] × its size) and
//!    a child's radiance differs from the average by δ, the error of the
//!    average is at most about δ · F(x → i); the sender is refined into its
//!    children where that bound exceeds [`NEAR_FIELD_TOLERANCE`] of the
//!    whole sum (a lightcuts-style cut, Walter et al. 2005, chosen per
//!    point). Curved senders near x are refined too: their point form
//!    factor comes from a fixed rule, accurate only from afar.
//! 3. **Reuse within a pixel.** The sum changes little across a pixel's
//!    footprint: a pixel's samples that land on the same leaf reuse the
//!    fully visible sum and the partly visible terms of the first
//!    ([`LinkCache`]), whose point is uniform over the footprint, so that
//!    the pixel's mean is unbiased; every sample still traces its own
//!    shadow rays for the partly visible terms.
//! 4. **Partial visibility.** Links whose shadow rays all passed need no
//!    ray. The partly visible ones are either taken with the visible
//!    fraction the solve measured (`Cached`) or estimated together by
//!    [`PARTIAL_RAYS`] shadow rays: each picks a partly visible sender in
//!    proportion to its unoccluded contribution and a point on it
//!    uniformly, so that (Σ_k c_k) · (fraction of the rays that pass) is
//!    unbiased for Σ_k c_k V_k, V_k the sender's visible area fraction.

use glam::DVec3;
use trilux_color::Spectrum;
use trilux_geometry::{FaceElement, PointFormFactors};
use trilux_solver::LinkSource;

use crate::gather::GatherStats;
use crate::link_gather::LinkVisibility;
use crate::solved::RadianceSolution;

/// A sender closer to the receiver than this many times its own size may
/// be refined into its children.
pub const NEAR_FIELD: f64 = 1.0;

/// The error bound (relative to the whole sum) above which a near sender
/// is refined.
pub const NEAR_FIELD_TOLERANCE: f64 = 0.002;

/// Shadow rays per link sum for its partly visible links.
pub const PARTIAL_RAYS: u32 = 2;

/// The point a link sum is evaluated at.
pub struct Receiver {
    /// The point.
    pub x: DVec3,
    /// Its unit normal on the viewer's side.
    pub n: DVec3,
    /// The leaf element (and face side) containing it.
    pub leaf: FaceElement,
}

/// One sender's unoccluded contribution, before visibility.
#[derive(Clone, Copy, Debug)]
struct Term<const N: usize> {
    sender: FaceElement,
    source: LinkSource,
    /// The sender's radiance L.
    l: Spectrum<N>,
    /// L F(x → sender).
    c: Spectrum<N>,
    /// The link's measured visible fraction.
    v: f64,
}

/// What a pixel's first sample on a leaf leaves for the next ones.
#[derive(Clone, Debug, Default)]
struct LeafSum<const N: usize> {
    leaf: Option<FaceElement>,
    /// Σ of the fully visible terms.
    full: Spectrum<N>,
    /// The partly visible terms.
    partial: Vec<Term<N>>,
}

/// A pixel's link sums, one per leaf its samples landed on (a pixel's
/// footprint spans a few leaves).
#[derive(Clone, Debug)]
pub struct LinkCache<const N: usize> {
    entries: [LeafSum<N>; CACHED_LEAVES],
    /// The entry to overwrite next.
    next: usize,
    /// Scratch: the near terms before refinement.
    near: Vec<Term<N>>,
}

/// Leaves a pixel's cache remembers.
const CACHED_LEAVES: usize = 4;

impl<const N: usize> Default for LinkCache<N> {
    fn default() -> Self {
        LinkCache {
            entries: std::array::from_fn(|_| LeafSum::default()),
            next: 0,
            near: Vec::new(),
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
    }
}

/// The link sum at `r` (module docs), reusing `cache` when it holds the
/// same leaf.
pub fn link_sum<const N: usize, S: RadianceSolution<N>>(
    solution: &S,
    ff: &PointFormFactors,
    r: &Receiver,
    visibility: LinkVisibility<'_>,
    cache: &mut LinkCache<N>,
    stats: &mut GatherStats,
) -> Spectrum<N> {
    let k = match cache.entries.iter().position(|e| e.leaf == Some(r.leaf)) {
        Some(k) => k,
        None => {
            let k = cache.next;
            cache.next = (k + 1) % CACHED_LEAVES;
            let mut near = std::mem::take(&mut cache.near);
            fill(solution, ff, r, &mut cache.entries[k], &mut near, stats);
            refine_near(solution, ff, r, &mut cache.entries[k], &mut near, stats);
            cache.near = near;
            k
        }
    };
    let entry = &cache.entries[k];
    entry.full + partly_visible(solution, r, &entry.partial, visibility, stats)
}

/// The terms of every link into `r`'s leaf and its ancestors: the far ones
/// summed when fully visible, kept when partial; the near ones set aside.
fn fill<const N: usize, S: RadianceSolution<N>>(
    solution: &S,
    ff: &PointFormFactors,
    r: &Receiver,
    entry: &mut LeafSum<N>,
    near: &mut Vec<Term<N>>,
    stats: &mut GatherStats,
) {
    entry.leaf = Some(r.leaf);
    entry.full = Spectrum::zero();
    entry.partial.clear();
    near.clear();
    let forest = solution.forest();
    let mut element = Some(r.leaf.element);
    while let Some(e) = element {
        solution.for_each_link(FaceElement::new(e, r.leaf.side), &mut |link, l| {
            if l.is_black() {
                return;
            }
            let sender = FaceElement::new(link.sender, link.sender_face.side());
            let t = Term {
                sender,
                source: link.source,
                l,
                c: Spectrum::zero(),
                v: f64::from(link.visibility),
            };
            let se = forest.element(sender.element);
            if (se.centre - r.x).length() < NEAR_FIELD * se.bounds.diagonal().length() {
                near.push(t);
                return;
            }
            stats.link_senders += 1;
            let f = ff.eval(r.x, r.n, sender);
            if f > 0.0 {
                let t = Term { c: l * f, ..t };
                if t.v >= 1.0 {
                    entry.full += t.c;
                } else {
                    entry.partial.push(t);
                }
            }
        });
        element = forest.element(e).parent;
    }
}

/// Step 2 for every near term: its refined terms join the fully visible
/// sum or the partly visible list.
fn refine_near<const N: usize, S: RadianceSolution<N>>(
    solution: &S,
    ff: &PointFormFactors,
    r: &Receiver,
    entry: &mut LeafSum<N>,
    near: &mut [Term<N>],
    stats: &mut GatherStats,
) {
    for t in near.iter_mut() {
        t.c = t.l * ff.eval(r.x, r.n, t.sender);
    }
    stats.link_senders += near.len() as u64;
    let total = entry.full.sum()
        + entry.partial.iter().map(|t| t.c.sum() * t.v).sum::<f64>()
        + near.iter().map(|t| t.c.sum() * t.v).sum::<f64>();
    let (full, partial) = (&mut entry.full, &mut entry.partial);
    for &t in near.iter() {
        near_field(
            solution,
            ff,
            r,
            t,
            NEAR_FIELD_TOLERANCE * total,
            stats,
            &mut |t| {
                if t.v >= 1.0 {
                    *full += t.c;
                } else {
                    partial.push(t);
                }
            },
        );
    }
}

/// Step 2: refines a term near the receiver into its children while its
/// error bound exceeds `tolerance`, handing the final terms to `out`.
fn near_field<const N: usize, S: RadianceSolution<N>>(
    solution: &S,
    ff: &PointFormFactors,
    r: &Receiver,
    t: Term<N>,
    tolerance: f64,
    stats: &mut GatherStats,
    out: &mut dyn FnMut(Term<N>),
) {
    let forest = solution.forest();
    let e = forest.element(t.sender.element);
    let near = (e.centre - r.x).length() < NEAR_FIELD * e.bounds.diagonal().length();
    let (Some(children), LinkSource::Face(face), true) = (e.children(), t.source, near) else {
        if t.c.sum() > 0.0 {
            out(t);
        }
        return;
    };
    let lc = children.map(|c| solution.face_radiance(face, c));
    let mean = t.l.sum();
    let delta = lc
        .iter()
        .map(|l| (l.sum() - mean).abs())
        .fold(0.0, f64::max);
    let f = if mean > 0.0 { t.c.sum() / mean } else { 0.0 };
    if e.is_planar() && delta * f <= tolerance {
        return out(t);
    }
    for (c, l) in children.into_iter().zip(lc) {
        let sender = t.sender.with(c);
        stats.link_senders += 1;
        let f = ff.eval(r.x, r.n, sender);
        if f > 0.0 && !l.is_black() {
            let child = Term {
                sender,
                l,
                c: l * f,
                ..t
            };
            near_field(solution, ff, r, child, tolerance, stats, out);
        }
    }
}

/// Step 3: the partly visible terms, with their measured visibility or
/// sampled shadow rays.
fn partly_visible<const N: usize, S: RadianceSolution<N>>(
    solution: &S,
    r: &Receiver,
    terms: &[Term<N>],
    visibility: LinkVisibility<'_>,
    stats: &mut GatherStats,
) -> Spectrum<N> {
    if terms.is_empty() {
        return Spectrum::zero();
    }
    let LinkVisibility::Traced { sampler, dim } = visibility else {
        return terms.iter().map(|t| t.c * t.v).sum();
    };
    let weights: Vec<f64> = terms.iter().map(|t| t.c.sum()).collect();
    let total_w: f64 = weights.iter().sum();
    if total_w.is_nan() || total_w <= 0.0 {
        return Spectrum::zero();
    }
    let forest = solution.forest();
    let geom = forest.geometry();
    let mut sum = Spectrum::<N>::zero();
    for k in 0..PARTIAL_RAYS {
        let pick = sampler.get1(dim + 3 * k) * total_w;
        let mut acc = 0.0;
        let mut chosen = terms.len() - 1;
        for (i, w) in weights.iter().enumerate() {
            acc += w;
            if pick < acc {
                chosen = i;
                break;
            }
        }
        let t = &terms[chosen];
        let y = forest
            .sample_element(t.sender.element, sampler.get2(dim + 3 * k + 1))
            .point;
        stats.shadow_rays += 1;
        if !geom.occluded(r.x, y) {
            // c_k / p_k with p_k = w_k / Σ w.
            sum += t.c * (total_w / weights[chosen]);
        }
    }
    sum * (1.0 / f64::from(PARTIAL_RAYS))
}
