//! Stage 1 of RefineAndLink: pair links i → j from the source's elements
//! to the elements of a receiving face (the two-point part, as in
//! hierarchical radiosity; paper §3.2.2, §4.3). A link is made when the
//! flux it carries is below the photometric threshold, or when the
//! sender's radiance does not vary against the form factor, the point form
//! factor's spread over j is within its budget and visibility is not
//! partial; otherwise the larger element is split (docs/solver.md,
//! "Refinement").

use std::f64::consts::PI;

use trilux_geometry::{ElementId, FaceElement};

use super::context::{RefineContext, disc_estimate};
use crate::link::{PairLink, PairShot, Sender};
use crate::throughput::Throughput;

/// Largest relative error, from the sender's unshot radiance varying over
/// it, that a pair link may carry (see `RefineContext::sender_varies`).
const SENDER_VARIATION: f64 = 0.01;

impl<const N: usize> RefineContext<'_, N> {
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
        let th = self.throughput(shot.sj.of(j), shot.si.of(i));
        self.refine_pair_with(shot, (i, j, th), budget, out);
    }

    /// [`Self::refine_pair`] with T_ij already known (a root pair's, kept
    /// by the shot's state: `state::RootThroughputs`).
    pub fn refine_pair_with(
        &self,
        shot: PairShot<'_, N>,
        (i, j, th): (ElementId, ElementId, Throughput),
        budget: f64,
        out: &mut Vec<PairLink<N>>,
    ) {
        let PairShot { sender, si, sj } = shot;
        let (ei, ej) = (self.forest.element(i), self.forest.element(j));
        if th.t <= 0.0 {
            // Fully occluded or facing away. Near the roots a handful of
            // shadow rays may miss a gap: look one level further there
            // (not past the deadline), unless all the light the pair could
            // carry unoccluded, π A_j F_ji δL_i, is below the photometric
            // threshold.
            if ei.depth + ej.depth < 2
                && th.v == 0.0
                && !self.past_deadline()
                && PI * ej.area * th.f * sender.sent_radiance(self.forest, i, j).sum()
                    >= self.flux_threshold
                && self.unoccluded_positive(si.of(i), sj.of(j))
            {
                self.split_pair(shot, i, j, budget, out);
            }
            return;
        }
        let unshot = sender.sent_radiance(self.forest, i, j);
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
        let varies = self.sender_varies(shot, i, j);
        // The transfer is accurate when the point form factor varies little
        // over the receiver (so that pushing it down unchanged is right).
        let partial = th.v > 0.0 && th.v < 1.0;
        if !varies && th.spread <= budget && !partial {
            out.push(link);
            return;
        }
        // Past the solve's deadline the pair is linked where it stands, as
        // the photometric criterion links a small flux: the same light,
        // carried coarser (docs/solver.md, "The deadline inside a shot").
        if self.past_deadline() {
            self.count_late_link();
            out.push(link);
            return;
        }
        if varies {
            self.split_sender(shot, i, j, budget, true, out);
        } else if !self.split_pair(shot, i, j, budget, out) {
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
            let dl = sender.sent_radiance(self.forest, c, j).sum();
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
}

#[cfg(test)]
mod tests {
    //! The stage-1 oracle against answers that follow from its definition:
    //! the photometric criterion, refinement down to the depth limit, and
    //! which element of a pair is split.
    #![allow(clippy::unwrap_used, clippy::expect_used)] // tests may panic

    use std::collections::HashSet;

    use glam::DVec3;
    use trilux_color::Spectrum;

    use super::*;
    use crate::link::Sent;
    use crate::setup::Setup;
    use crate::state::ShotState;
    use crate::test_scenes as ts;
    use crate::throughput::ThroughputCache;

    /// An emitter (Le = 1 in every band) of side `sender` facing down at
    /// height 1 over a grey receiver of side `receiver` facing up.
    fn plates(sender: f64, receiver: f64, depth: u32) -> (Setup<3>, ShotState<3>) {
        let shapes = [
            ts::square(DVec3::new(0.0, 0.0, 1.0), sender, true),
            ts::square(DVec3::ZERO, receiver, false),
        ];
        let setup = ts::setup(
            &shapes,
            &[ts::diffuse(0.0), ts::diffuse(0.5)],
            &[Some(1.0), None],
            ts::settings(depth),
        );
        let state = ShotState::new(&setup);
        (setup, state)
    }

    /// Stage 1 from the emitter's root to the receiver's root with the
    /// given photometric threshold and form-factor budget; also the root
    /// link's flux π T δL (band sum).
    fn refine(
        setup: &Setup<3>,
        state: &ShotState<3>,
        threshold: impl Fn(f64) -> f64,
        budget: f64,
    ) -> (Vec<PairLink<3>>, f64) {
        let (links, flux, _) = refine_by(setup, state, threshold, budget, None);
        (links, flux)
    }

    /// [`refine`] with a deadline; also the links counted late.
    fn refine_by(
        setup: &Setup<3>,
        state: &ShotState<3>,
        threshold: impl Fn(f64) -> f64,
        budget: f64,
        deadline: Option<std::time::Instant>,
    ) -> (Vec<PairLink<3>>, f64, u64) {
        let cache = ThroughputCache::new(1 << 16);
        refine_with(setup, state, &cache, threshold, budget, deadline)
    }

    /// [`refine_by`] with the throughput cache given (to see what it made).
    fn refine_with(
        setup: &Setup<3>,
        state: &ShotState<3>,
        cache: &ThroughputCache,
        threshold: impl Fn(f64) -> f64,
        budget: f64,
        deadline: Option<std::time::Instant>,
    ) -> (Vec<PairLink<3>>, f64, u64) {
        let mut ctx = setup.refine_context(cache);
        ctx.deadline = deadline;
        let (si, sj) = (ts::front(0), ts::front(1));
        let (ri, rj) = (ts::root(ctx.forest, si), ts::root(ctx.forest, sj));
        let root_flux = PI * ctx.throughput(rj, ri).t * 3.0;
        ctx.flux_threshold = threshold(root_flux);
        let sender = Sender::Radiosity {
            field: &state.field,
            side: si.side(),
            sent: Sent::Unshot,
            emission: Spectrum::zero(),
        };
        let shot = PairShot {
            sender: &sender,
            si,
            sj,
        };
        let mut out = Vec::new();
        ctx.refine_pair(shot, ri.element, rj.element, budget, &mut out);
        let late = ctx.late.links.load(std::sync::atomic::Ordering::Relaxed);
        (out, root_flux, late)
    }

    /// A pair reached after the solve's deadline is linked where it
    /// stands: with no photometric threshold and no form-factor budget
    /// (which refine it to the depth limit before the deadline), the one
    /// link made is the root link the photometric criterion makes, the
    /// same T and δL (the same light, coarser), and it is counted late. A
    /// deadline still ahead changes nothing.
    #[test]
    fn a_pair_reached_after_the_deadline_is_linked_where_it_stands() {
        use std::time::{Duration, Instant};
        let (setup, state) = plates(1.0, 1.0, 2);
        let (coarse, _) = refine(&setup, &state, |_| f64::INFINITY, 0.0);
        let (late, _, count) = refine_by(&setup, &state, |_| 0.0, 0.0, Some(Instant::now()));
        assert_eq!(late.len(), 1);
        assert_eq!(count, 1);
        let (a, b) = (&late[0], &coarse[0]);
        assert_eq!((a.i, a.j, a.t, a.unshot), (b.i, b.j, b.t, b.unshot));
        let ahead = Instant::now() + Duration::from_secs(365 * 24 * 3600);
        let (fine, _, count) = refine_by(&setup, &state, |_| 0.0, 0.0, Some(ahead));
        let (free, _) = refine(&setup, &state, |_| 0.0, 0.0);
        assert_eq!(count, 0);
        assert_eq!(fine.len(), 16 * 16, "every pair of leaves");
        let key = |l: &PairLink<3>| (l.i, l.j, l.t.to_bits());
        assert_eq!(
            fine.iter().map(key).collect::<Vec<_>>(),
            free.iter().map(key).collect::<Vec<_>>()
        );
    }

    /// A root pair whose shadow rays are all blocked (a wide plate halfway
    /// between the plates) is looked into one level down for a gap the
    /// rays missed, but only when the light it could carry unoccluded,
    /// π A_j F_ji δL_i, reaches the photometric threshold: below it (late
    /// shots) no child pair's throughput is made.
    #[test]
    fn an_occluded_root_pair_is_retried_only_above_the_threshold() {
        let shapes = [
            ts::square(DVec3::new(0.0, 0.0, 1.0), 1.0, true),
            ts::square(DVec3::ZERO, 1.0, false),
            ts::square(DVec3::new(0.0, 0.0, 0.5), 3.0, false),
        ];
        let setup = ts::setup(
            &shapes,
            &[ts::diffuse(0.0), ts::diffuse(0.5), ts::diffuse(0.5)],
            &[Some(1.0), None, None],
            ts::settings(2),
        );
        let state = ShotState::new(&setup);
        let unoccluded = PI * 0.199825 * 3.0;
        let forest = setup.forest();
        let (si, sj) = (ts::front(0), ts::front(1));
        let (ri, rj) = (ts::root(forest, si), ts::root(forest, sj));
        let child = forest.element(rj.element).children().unwrap()[0];
        for (threshold, retried) in [(1.05 * unoccluded, false), (0.95 * unoccluded, true)] {
            let cache = ThroughputCache::new(1 << 16);
            let (out, _, _) = refine_with(&setup, &state, &cache, |_| threshold, 0.0, None);
            assert!(out.is_empty(), "nothing passes the plate");
            assert_eq!(cache.get(rj, ri).map(|t| t.v), Some(0.0));
            let made = cache.get(sj.of(child), ri).is_some();
            assert_eq!(made, retried, "threshold {threshold}");
        }
    }

    /// Parallel, directly opposed unit squares at distance 1 exchange
    /// F = 0.199825 (docs/validation.md, closed form (a)): the root link
    /// carries π · 0.199825 · 3 W. Below a threshold above that, the root
    /// link is made as it is, however coarse; above, it is refined.
    #[test]
    fn a_link_below_the_photometric_threshold_is_not_refined() {
        let (setup, state) = plates(1.0, 1.0, 3);
        let flux = PI * 0.199825 * 3.0;
        let (links, _) = refine(&setup, &state, |_| 1.05 * flux, 0.0);
        assert_eq!(links.len(), 1, "one root link");
        let forest = setup.forest();
        assert_eq!(links[0].i, forest.root(ts::front(0).surface()));
        assert_eq!(links[0].j, forest.root(ts::front(1).surface()));
        assert!(
            (links[0].t - 0.199825).abs() < 0.01 * 0.199825,
            "{}",
            links[0].t
        );
        assert_eq!(links[0].unshot, Spectrum::splat(1.0));
        let (links, _) = refine(&setup, &state, |_| 0.95 * flux, 0.0);
        assert!(links.len() > 1, "refined");
    }

    /// With no photometric threshold and no form-factor budget, nothing is
    /// accurate enough: the pair is refined until neither element can
    /// split. Every link then joins two leaves at their surface's depth
    /// limit, and the links cover the sender × receiver product exactly
    /// once (every pair of leaves, none twice), so their throughputs sum
    /// to the whole pair's, A F = 0.199825.
    #[test]
    fn a_link_above_the_threshold_is_refined_to_the_depth_limit() {
        let depth = 2;
        let (setup, state) = plates(1.0, 1.0, depth);
        let forest = setup.forest();
        assert_eq!(setup.discretisation.depth_limits(), [depth, depth]);
        let (links, _) = refine(&setup, &state, |_| 0.0, 0.0);
        let mut pairs = HashSet::new();
        for l in &links {
            for e in [l.i, l.j] {
                assert!(forest.element(e).children().is_none());
                assert_eq!(forest.element(e).depth, depth);
            }
            assert!(pairs.insert((l.i, l.j)), "pair linked twice");
        }
        let n = 4usize.pow(depth);
        assert_eq!(pairs.len(), n * n, "every pair of leaves");
        let t: f64 = links.iter().map(|l| l.t).sum();
        assert!((t - 0.199825).abs() < 0.02 * 0.199825, "Σ T = {t}");
    }

    /// Which element a refined pair splits (docs/solver.md, "Refinement",
    /// stage 1, step 4): the receiver, unless the sender is more than 4×
    /// larger. With a threshold of half the root link's flux, the root
    /// link is refined and each child link (a quarter of it, by symmetry)
    /// is made at once, so the links show the one split.
    #[test]
    fn the_larger_element_is_split() {
        // (sender side, receiver side, the sender is split)
        for (sender, receiver, split_sender) in [
            (1.0, 1.0, false),
            (4.0, 1.0, true),
            (1.0, 4.0, false),
            // 3.6× the area: within the 4× margin, the receiver is split.
            (1.9, 1.0, false),
        ] {
            let (setup, state) = plates(sender, receiver, 3);
            let forest = setup.forest();
            let (links, _) = refine(&setup, &state, |f| 0.5 * f, 0.0);
            let (ri, rj) = (
                forest.root(ts::front(0).surface()),
                forest.root(ts::front(1).surface()),
            );
            let (split, kept) = if split_sender { (ri, rj) } else { (rj, ri) };
            let children: HashSet<_> = forest.element(split).children().unwrap().into();
            assert_eq!(links.len(), 4, "{sender} over {receiver}");
            for l in &links {
                let (s, k) = if split_sender { (l.i, l.j) } else { (l.j, l.i) };
                assert_eq!(k, kept, "{sender} over {receiver}");
                assert!(children.contains(&s), "{sender} over {receiver}");
            }
        }
    }
}
