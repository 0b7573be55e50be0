//! Visibility between elements: the fraction of stratified shadow segments
//! that reach the other element unobstructed (paper §4.6 caches F × V).
//! A segment through surfaces that let light through
//! ([`crate::transmission`]) counts for the fraction they let through, so
//! that V is the mean transmittance of the segments, not a count.
//!
//! Segment k joins the k-th point of an Owen-scrambled Sobol sequence on
//! each element (independent scrambles on the two sides, seeded by the
//! element ids, so results are deterministic, and the same for (a, b) and
//! (b, a)). Only segments whose end points face each other (both one-sided
//! cosines positive) carry light and are counted; if none do, the plain
//! fraction over all segments is returned (the form factor is then zero
//! anyway). A segment with an end on a buried part of its face
//! ([`crate::burial`]) counts as blocked, when a burial map is given.

use glam::DVec3;
use rayon::prelude::*;

use crate::burial::BurialMap;
use crate::face::{FaceElement, FaceId};
use crate::forest::ElementForest;
use crate::ids::ElementId;
use crate::sampling::SurfaceSample;
use crate::sequence::{seed_of, sobol2};

/// Shadow-segment visibility over an element forest, optionally with the
/// buried parts of faces counted as blocked.
#[derive(Clone, Copy, Debug)]
pub struct Visibility<'a> {
    forest: &'a ElementForest,
    burial: Option<&'a BurialMap>,
}

impl<'a> Visibility<'a> {
    /// Visibility between the elements of `forest`; segments ending on a
    /// buried part of `burial` count as blocked.
    pub fn new(forest: &'a ElementForest, burial: Option<&'a BurialMap>) -> Self {
        Visibility { forest, burial }
    }

    /// The forest whose elements this visibility is between.
    pub fn forest(&self) -> &'a ElementForest {
        self.forest
    }

    /// The burial map segments are checked against, if any.
    pub fn burial(&self) -> Option<&'a BurialMap> {
        self.burial
    }

    /// Visible fraction between `a` and `b` from `samples` shadow segments
    /// (at most 65 536), counting the segments between the two faces that
    /// face each other (module docs).
    pub fn fraction(&self, a: FaceElement, b: FaceElement, samples: u32) -> f64 {
        let n = samples.clamp(1, 1 << 16);
        let seed = seed_of(a.element.min(b.element), a.element.max(b.element));
        let geom = self.forest.geometry();
        let (mut facing, mut facing_visible, mut visible) = (0u32, 0.0, 0.0);
        let mut hint = None;
        for k in 0..n {
            let (x, y) = self.segment_ends(a.element, b.element, k, seed);
            let d = y.point - x.point;
            let faces =
                a.side.sign() * x.normal.dot(d) > 0.0 && b.side.sign() * y.normal.dot(d) < 0.0;
            let vis = if self.buried_end(a, &x, b, &y) {
                0.0
            } else {
                geom.transmittance_hint(x.point, y.point, &mut hint)
            };
            visible += vis;
            if faces {
                facing += 1;
                facing_visible += vis;
            }
        }
        if facing > 0 {
            facing_visible / facing as f64
        } else {
            visible / n as f64
        }
    }

    /// Kernel-weighted visible fraction Σ K vis / Σ K over the same
    /// stratified segments, K = cos θ_a cos θ_b / r² (the form-factor
    /// kernel): the factor V such that F · V estimates the occluded form
    /// factor ∫∫ K vis / (π A_a) when occlusion and K are correlated (a
    /// blocker near one end, partial occlusion of a large element). Falls
    /// back to [`Visibility::fraction`] when no segment carries light.
    pub fn weighted(&self, a: FaceElement, b: FaceElement, samples: u32) -> f64 {
        let n = samples.clamp(1, 1 << 16);
        let seed = seed_of(a.element.min(b.element), a.element.max(b.element));
        let geom = self.forest.geometry();
        let (sa, sb) = (a.side.sign(), b.side.sign());
        let (mut total, mut seen) = (0.0, 0.0);
        let mut hint = None;
        for k in 0..n {
            let (x, y) = self.segment_ends(a.element, b.element, k, seed);
            let d = y.point - x.point;
            let r2 = d.length_squared();
            let (ca, cb) = (sa * x.normal.dot(d), -sb * y.normal.dot(d));
            if ca <= 0.0 || cb <= 0.0 || r2 <= 0.0 || x.pdf_area <= 0.0 || y.pdf_area <= 0.0 {
                continue;
            }
            // Weight by the kernel over the sampling densities (the
            // integrand of ∫∫ K dA dA).
            let w = ca * cb / (r2 * r2 * x.pdf_area * y.pdf_area);
            if !w.is_finite() {
                continue;
            }
            total += w;
            if !self.buried_end(a, &x, b, &y) {
                seen += w * geom.transmittance_hint(x.point, y.point, &mut hint);
            }
        }
        if total > 0.0 {
            (seen / total).clamp(0.0, 1.0)
        } else {
            self.fraction(a, b, samples)
        }
    }

    /// [`Visibility::fraction`] for many element pairs, in parallel.
    pub fn fraction_batch(&self, pairs: &[(FaceElement, FaceElement)], samples: u32) -> Vec<f64> {
        pairs
            .par_iter()
            .map(|&(a, b)| self.fraction(a, b, samples))
            .collect()
    }

    /// The shadow segments [`Visibility::fraction`] traces between `a` and
    /// `b` (for callers that batch or trace them their own way).
    pub fn segments(&self, a: ElementId, b: ElementId, samples: u32) -> Vec<(DVec3, DVec3)> {
        let n = samples.clamp(1, 1 << 16);
        let seed = seed_of(a.min(b), a.max(b));
        (0..n)
            .map(|k| {
                let (x, y) = self.segment_ends(a, b, k, seed);
                (x.point, y.point)
            })
            .collect()
    }

    /// True if either end of a segment lies on a buried part of its face
    /// ([`crate::burial`]): such segments carry no light.
    #[inline]
    fn buried_end(
        &self,
        a: FaceElement,
        x: &SurfaceSample,
        b: FaceElement,
        y: &SurfaceSample,
    ) -> bool {
        self.burial.is_some_and(|m| {
            let face = |e: FaceElement| FaceId::new(self.forest.element(e.element).surface, e.side);
            m.is_buried(face(a), x.coord) || m.is_buried(face(b), y.coord)
        })
    }

    /// The ends of shadow segment `k` between `a` and `b`. The lower element
    /// id always draws from the same Sobol dimensions, so (a, b) and (b, a)
    /// trace the same segments and visibility is symmetric.
    fn segment_ends(
        &self,
        a: ElementId,
        b: ElementId,
        k: u32,
        seed: u32,
    ) -> (SurfaceSample, SurfaceSample) {
        let first = |e: ElementId| self.forest.sample_element(e, sobol2(k, 0, seed));
        let second = |e: ElementId| {
            self.forest
                .sample_element(e, sobol2(k, 2, seed ^ 0x5bd1_e995))
        };
        if a <= b {
            (first(a), second(b))
        } else {
            (second(a), first(b))
        }
    }
}
