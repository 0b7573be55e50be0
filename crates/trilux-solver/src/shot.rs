//! One shot of the progressive loop, as named phases (paper §4.1–4.4):
//!
//! 1. [`Solver::take_source`]: δΦ_S leaves the residual; the source is
//!    pushed and pulled (lazily, only now: §4.4) and becomes the sender.
//! 2. [`stage_one`]: pair links from the source to every receiving face
//!    (the two-point part), in parallel.
//! 3. [`shot_scale`]: the links may not carry more flux than the source
//!    had; a stored source is scaled up to carry its whole key.
//! 4. [`Solver::stage_two`]: three-point links into the stored hierarchies
//!    of every glossy receiving face, in parallel over those hierarchies.
//! 5. `receive`: per pair link (a "group"), the Lambertian share goes
//!    straight into j's radiance, the glossy share is renormalised
//!    (`glossy`) or waits (`deferred`) and the ledger books what was
//!    absorbed.
//! 6. [`Solver::apply_node_links`] and [`Solver::unlink`]: the node links add
//!    their (renormalised) radiance, then links die and δL of the source is
//!    zeroed (links live for one shot: memory O(n + k²), §4.2).

use std::collections::HashMap;
use std::f64::consts::PI;
use std::ops::Range;

use rayon::prelude::*;
use trilux_color::Spectrum;
use trilux_geometry::{ElementId, FaceId, PerFace};

use crate::batch::batches;
use crate::cluster_transport::{FarField, far_links};
use crate::deferred::GlossyIn;
use crate::interaction::Hierarchy;
use crate::link::{NodeLink, NodeLinks, PairLink, PairShot, Sender, Sent};
use crate::refine::{Incidence, IncidenceMemo, Lateness, RefineContext, TripleTask};
use crate::solver::{Solver, Source};
use crate::state::RootThroughputs;
use crate::throughput::Throughput;

/// The most a stored interaction's shot is scaled up to carry its whole
/// unshot flux (see [`shot_scale`]).
const MAX_STORED_SHOT_SCALE: f64 = 1.25;

/// What sends during a shot.
pub(crate) enum Sending<const N: usize> {
    /// A face's two-point tree.
    Radiosity(FaceId),
    /// A stored hierarchy, taken out of the solver while it sends — or, for
    /// a face's interaction with itself (paper §5.2's secondary
    /// interactions of a glossy concave surface), a copy, the original
    /// staying in place to receive from its own shot.
    Stored {
        index: u32,
        hierarchy: Hierarchy<N>,
        is_self: bool,
    },
    /// A glossy face's far field (`cluster_transport`), taken out of the
    /// solver while it sends (nothing it sends to can send back within
    /// the shot), with its unshot radiance by receiving surface.
    Far {
        field: FarField<N>,
        by_surface: Vec<Spectrum<N>>,
    },
}

impl<const N: usize> Sending<N> {
    /// The sending face.
    fn face(&self) -> FaceId {
        match self {
            Sending::Radiosity(f) => *f,
            Sending::Stored { hierarchy, .. } => hierarchy.from,
            Sending::Far { field, .. } => field.face,
        }
    }
}

/// The shot-level scale per band (phase 3): links may not carry more flux
/// than the source had (form-factor error could otherwise create energy).
/// A stored interaction I→K sends all its unshot flux to K (its key was
/// summed as π T_IK δL), so its links are also scaled *up* to carry it
/// when their own throughput estimates, made at other levels, fall short
/// (up to [`MAX_STORED_SHOT_SCALE`]); without this the shortfall left as
/// "escaped" light, 0.3 % of every bounce in the uniform Cornell box. A
/// Lambertian source's shortfall is light that really leaves (an open
/// scene).
fn shot_scale<const N: usize>(
    pair_links: &[PairLink<N>],
    phi: Spectrum<N>,
    stored_source: bool,
) -> Spectrum<N> {
    let mut arrived = Spectrum::<N>::zero();
    for l in pair_links {
        arrived += l.unshot * (PI * l.t);
    }
    Spectrum::<N>::new(std::array::from_fn(|b| {
        if arrived[b] > phi[b] && arrived[b] > 0.0 {
            phi[b] / arrived[b]
        } else if stored_source && arrived[b] > 0.0 {
            (phi[b] / arrived[b]).min(MAX_STORED_SHOT_SCALE)
        } else {
            1.0
        }
    }))
}

/// Phase 2: pair links to every receiving face, in parallel: from the
/// roots of the two surfaces for a Lambertian source, from the root pair
/// of a stored hierarchy (whose nodes give the unshot radiance of every
/// sub-pair: `Sender::sent_radiance`).
fn stage_one<const N: usize>(
    ctx: &RefineContext<'_, N>,
    sender: &Sender<'_, N>,
    send_face: FaceId,
    (pairs, roots): (&[(ElementId, FaceId, ElementId)], &[Throughput]),
) -> Vec<PairLink<N>> {
    pairs
        .par_iter()
        .enumerate()
        .flat_map_iter(|(k, &(i, r, j))| {
            let mut out = Vec::new();
            let shot = PairShot {
                sender,
                si: send_face,
                sj: r,
            };
            let budget = ctx.settings.ff_eps;
            match roots.get(k) {
                Some(&th) => ctx.refine_pair_with(shot, (i, j, th), budget, &mut out),
                None => ctx.refine_pair(shot, i, j, budget, &mut out),
            }
            out
        })
        .collect()
}

/// The root pairs' throughputs of a face's shot, in the order of its
/// near partners (`pairs`): those not yet made are made in parallel and
/// kept in `slots` (`state::RootThroughputs`).
fn root_throughputs<const N: usize>(
    ctx: &RefineContext<'_, N>,
    slots: &mut Vec<Option<Throughput>>,
    send_face: FaceId,
    pairs: &[(ElementId, FaceId, ElementId)],
) -> Vec<Throughput> {
    if slots.len() != pairs.len() {
        *slots = vec![None; pairs.len()];
    }
    if slots.iter().all(Option::is_some) {
        return slots.iter().map(|t| t.unwrap_or_default()).collect();
    }
    slots
        .par_iter_mut()
        .zip(pairs)
        .map(|(slot, &(i, r, j))| {
            *slot.get_or_insert_with(|| ctx.throughput(r.of(j), send_face.of(i)))
        })
        .collect()
}

/// What stage 2 produced: node links, and per hierarchy the flux that
/// splits could not keep.
type StageTwo<const N: usize> = Vec<(Vec<NodeLink<N>>, u32, Spectrum<N>)>;

/// A shot's groups: its pair links, what becomes of each one's glossy
/// share (`deferred`), and the shot's scale (phase 3).
pub(crate) struct Groups<const N: usize> {
    pub links: Vec<PairLink<N>>,
    pub plan: Vec<GlossyIn<N>>,
    pub scale: Spectrum<N>,
}

/// The pair links whose glossy shares a shot refines (δL zero for one
/// that waits), each with the scale of its node links.
pub(crate) struct Glossy<const N: usize> {
    pub links: Vec<PairLink<N>>,
    pub scales: Vec<Spectrum<N>>,
}

impl<const N: usize> Groups<N> {
    fn glossy(&self) -> Glossy<N> {
        let (links, scales) = self
            .plan
            .iter()
            .zip(&self.links)
            .map(|(p, l)| p.link(l, self.scale))
            .unzip();
        Glossy { links, scales }
    }
}

/// The sender of a shot's own light; a release of waiting light (`None`)
/// has none: each of its groups sends its sum.
fn shot_sender<'a, const N: usize>(
    sending: Option<&'a Sending<N>>,
    field: &'a crate::radiosity::ElementRadiance<N>,
) -> Sender<'a, N> {
    match sending {
        Some(Sending::Radiosity(f)) => Sender::Radiosity {
            field,
            side: f.side(),
            sent: Sent::Unshot,
            emission: Spectrum::zero(),
        },
        Some(Sending::Stored { hierarchy, .. }) => Sender::Stored {
            hierarchy,
            sent: Sent::Unshot,
        },
        Some(Sending::Far { by_surface, .. }) => Sender::Far { by_surface },
        None => Sender::Uniform {
            unshot: Spectrum::zero(),
        },
    }
}

/// A shot's sending (`None` for a release of waiting light), its groups
/// and, per group, the uniform sender of a released sum.
type ShotGroups<'a, const N: usize> = (
    Option<&'a Sending<N>>,
    &'a Groups<N>,
    &'a [Option<Sender<'static, N>>],
);

/// Each group's sender and sending face: the shot's own (`sender`), or a
/// released sum's uniform sender from its own face.
fn group_senders<'s, const N: usize>(
    (sending, groups, uniform): ShotGroups<'s, N>,
    sender: &'s Sender<'s, N>,
) -> Vec<(&'s Sender<'s, N>, FaceId)> {
    let shot_face = sending.map(Sending::face);
    groups
        .plan
        .iter()
        .zip(uniform)
        .zip(&groups.links)
        .map(|((p, u), l)| {
            (
                u.as_ref().unwrap_or(sender),
                p.send_face(shot_face.unwrap_or(l.face)),
            )
        })
        .collect()
}

impl<const N: usize> Solver<N> {
    /// One shot from `source` (module docs); returns the number of links it
    /// made.
    pub(crate) fn shoot(&mut self, source: Source) -> usize {
        match source {
            Source::Light(k) => return self.shoot_light(k as usize),
            Source::Deferred(face) => return self.release_deferred(face),
            _ => {}
        }
        let Some((phi, sending)) = self.take_source(source) else {
            return 0;
        };
        let send_face = sending.face();
        // The emission a face's first shot carries (the rest is reflected
        // light: `ambient`).
        let emission = match source {
            Source::Radiosity(face) => self
                .state
                .unshot_emission
                .remove(&face)
                .unwrap_or_else(Spectrum::zero),
            _ => Spectrum::zero(),
        };
        let share = crate::ambient::Interreflection::reflected_share(phi, emission);
        self.state.interreflection.book_shot(phi, share);
        let (links, near) = self.pair_links(&sending);
        let scale = shot_scale(&links, phi, matches!(source, Source::Stored(_)));
        let plan = self.plan_glossy(&links, near, send_face, (scale, share));
        let groups = Groups { links, plan, scale };
        let live = self.transfer(Some(&sending), &groups, (phi, share));
        self.unlink(sending);
        live
    }

    /// Decides, for every pair link of a shot from `send_face`, whether
    /// its glossy share is refined now, waits, or releases its pair's sum
    /// (`deferred`). Only links from the root of the sending face to the
    /// root of another glossy face may wait, and only stage 1's (the
    /// `near` first links), not the far links, whose pairs are not bounded
    /// by the near pairs.
    fn plan_glossy(
        &mut self,
        pair_links: &[PairLink<N>],
        near: usize,
        send_face: FaceId,
        scales: (Spectrum<N>, Spectrum<N>),
    ) -> Vec<GlossyIn<N>> {
        let threshold = self.setup.flux_threshold();
        // The uniform mode stays the paper's algorithm.
        let on = self.setup.settings.defer_glossy
            && self.setup.settings.transport == crate::settings::Transport::TwoPoint;
        let forest = self.setup.forest();
        let send_root = forest.root(send_face.surface());
        let mut plan = Vec::with_capacity(pair_links.len());
        for (g, l) in pair_links.iter().enumerate() {
            let may_wait = on
                && g < near
                && self.setup.faces[l.face].stored
                && l.face != send_face
                && l.i == send_root
                && l.j == forest.root(l.face.surface());
            let p = if may_wait {
                self.state.queue.touch(Source::Deferred(l.face));
                let deferred = &mut self.state.deferred;
                deferred.wait_or_release(l, send_face, threshold, scales)
            } else {
                GlossyIn::Now
            };
            self.state.stats.deferred_links += u64::from(matches!(p, GlossyIn::Wait { .. }));
            plan.push(p);
        }
        plan
    }

    /// After the last shot, every face's waiting light into its
    /// hierarchies: the solution then holds all the glossy light that
    /// arrived, as it would without deferral, and only what that light
    /// has not yet sent on stays in the residual.
    pub(crate) fn release_all_deferred(&mut self) {
        self.final_release = true;
        for face in self.state.deferred.waiting_faces() {
            self.shoot(Source::Deferred(face));
        }
        self.final_release = false;
    }

    /// The glossy light waiting at `face` (`deferred`) refined into its
    /// hierarchies: a shot that carries no new light.
    fn release_deferred(&mut self, face: FaceId) -> usize {
        self.state.stats.deferred_releases += 1;
        let root = self.setup.forest().root(face.surface());
        let (links, plan) = self.state.deferred.take(face, root);
        self.state.queue.touch(Source::Deferred(face));
        let groups = Groups {
            links,
            plan,
            scale: Spectrum::splat(1.0),
        };
        self.transfer(None, &groups, (Spectrum::zero(), Spectrum::zero()))
    }

    /// Phase 2: the pair links of the source, and how many of them are
    /// stage 1's (the far links follow).
    fn pair_links(&mut self, sending: &Sending<N>) -> (Vec<PairLink<N>>, usize) {
        let send_face = sending.face();
        let root_of = |f: FaceId| self.setup.forest().root(f.surface());
        let pairs: Vec<(ElementId, FaceId, ElementId)> = match sending {
            Sending::Radiosity(f) => self.setup.partners[*f]
                .iter()
                .map(|&r| (root_of(*f), r, root_of(r)))
                .collect(),
            Sending::Stored { hierarchy, .. } => {
                vec![(hierarchy.nodes[0].from, hierarchy.to, hierarchy.nodes[0].to)]
            }
            Sending::Far { .. } => Vec::new(),
        };
        let (links, near, late) = {
            let (mut ctx, _, roots) = self.split_for_shot();
            let roots = match sending {
                Sending::Radiosity(f) => {
                    root_throughputs(&ctx.refine, &mut roots.0[*f], send_face, &pairs)
                }
                _ => Vec::new(),
            };
            let sender = shot_sender(Some(sending), ctx.field);
            let mut links = stage_one(&ctx.refine, &sender, send_face, (&pairs, &roots));
            let near = links.len();
            links.extend(far_stage_one(&ctx.refine, ctx.field, sending));
            (links, near, std::mem::take(&mut ctx.refine.late))
        };
        self.book_late(late);
        (links, near)
    }

    /// Phases 4–6 for a shot's groups: three-point links into the glossy
    /// receivers' hierarchies (of the glossy shares refined now), what
    /// every group delivers, the node links applied. `sending` is `None`
    /// for a release of waiting light. Returns the number of links.
    fn transfer(
        &mut self,
        sending: Option<&Sending<N>>,
        groups: &Groups<N>,
        (phi, share): (Spectrum<N>, Spectrum<N>),
    ) -> usize {
        let glossy = groups.glossy();
        let uniform: Vec<Option<Sender<'static, N>>> = groups
            .plan
            .iter()
            .map(|p| match p {
                GlossyIn::Flush { unshot, .. } => Some(Sender::Uniform { unshot: *unshot }),
                _ => None,
            })
            .collect();
        let shot = (sending, groups, uniform.as_slice());
        let incidences = {
            let (ctx, _, _) = self.split_for_shot();
            let sender = shot_sender(sending, ctx.field);
            let senders = group_senders(shot, &sender);
            incidences(&ctx.refine, ctx.stored_from, &senders, &glossy.links)
        };
        let mut reception = self.begin_reception(groups, &glossy, &incidences);
        let (mut most, mut made) = (0, 0);
        let batches = batches(
            self.batch_hierarchies,
            &self.setup.stored_from,
            &glossy.links,
            &incidences,
        );
        let trim = batches.len() > 1;
        for batch in batches {
            let stage_two =
                self.stage_two_batch(shot, (&glossy.links, &incidences), (&batch, trim));
            let node_links = self.book_lost(stage_two);
            let n = node_links.iter().map(|(_, l)| l.len()).sum::<usize>();
            (most, made) = (most.max(n), made + n);
            self.reflect_batch((&glossy, &incidences), &node_links, &batch, &mut reception);
            self.apply_node_links(&node_links, &glossy.scales, &reception.scales);
        }
        self.receive(groups, reception, (phi, share));
        let live = groups.links.len() + most;
        self.state.stats.links_peak = self.state.stats.links_peak.max(live);
        self.state.stats.links_total += (groups.links.len() + made) as u64;
        live
    }

    /// Phase 4 for one batch of groups (`batches`), with what its
    /// refinement cut short at the deadline booked; `trim` when the shot
    /// has several batches.
    fn stage_two_batch(
        &mut self,
        shot: ShotGroups<'_, N>,
        (links, incidences): (&[PairLink<N>], &[Option<Incidence<N>>]),
        batch: (&[u32], bool),
    ) -> StageTwo<N> {
        let (stage_two, late) = {
            let (mut ctx, hierarchies, _) = self.split_for_shot();
            let sender = shot_sender(shot.0, ctx.field);
            let senders = group_senders(shot, &sender);
            let made = stage_two(
                &ctx.refine,
                &senders,
                (hierarchies, ctx.stored_from),
                (links, incidences),
                batch,
            );
            (made, std::mem::take(&mut ctx.refine.late))
        };
        self.book_late(late);
        stage_two
    }

    /// Phase 1: the source's unshot flux leaves the residual, the source is
    /// pushed and pulled, and its sender is made (`None` for a hierarchy
    /// that is not in place, which the loop never picks).
    fn take_source(&mut self, source: Source) -> Option<(Spectrum<N>, Sending<N>)> {
        self.state.queue.touch(source);
        match source {
            Source::Radiosity(face) => {
                let phi = std::mem::take(&mut self.state.face_flux[face]);
                let root = self.setup.forest().root(face.surface());
                let side = face.side();
                self.state.field.push_pull(
                    self.setup.forest(),
                    root,
                    side,
                    &self.setup.exposed_area[side],
                    self.setup.textures.as_ref(),
                );
                Some((phi, Sending::Radiosity(face)))
            }
            Source::Stored(index) => {
                let slot = &mut self.state.hierarchies[index as usize];
                let h = slot.as_mut()?;
                let phi = std::mem::take(&mut h.unshot_flux);
                let is_self = h.is_self();
                let hierarchy = if is_self {
                    // A face's interaction with itself receives from its own
                    // shot: it stays in place, a copy sends. The copy
                    // carries the unshot radiance, so the one in place drops
                    // it now: a split there that cannot keep its flux must
                    // not book as escaped light the copy is shooting.
                    h.push_pull();
                    let copy = h.clone();
                    h.clear_unshot();
                    copy
                } else {
                    let mut h = slot.take()?;
                    h.push_pull();
                    h
                };
                let sending = Sending::Stored {
                    index,
                    hierarchy,
                    is_self,
                };
                Some((phi, sending))
            }
            Source::Far(face) => {
                let mut field = self.state.far[face].take()?;
                debug_assert!(field.traced, "a far field with flux is traced");
                let phi = std::mem::take(&mut field.unshot_flux);
                let mut by_surface =
                    vec![Spectrum::zero(); self.setup.forest().geometry().surfaces().len()];
                let tree = &self.setup.clusters.tree;
                for b in &field.blocks {
                    for &s in tree.members_of(b.cluster) {
                        by_surface[s.index()] = b.unshot;
                    }
                }
                Some((phi, Sending::Far { field, by_surface }))
            }
            // Shot by `shoot_light` and `release_deferred`.
            Source::Light(_) | Source::Deferred(_) => None,
        }
    }

    /// The refinement context (the setup and the throughput cache) beside
    /// the stored hierarchies that stage 2 refines.
    #[allow(clippy::type_complexity)]
    fn split_for_shot(
        &mut self,
    ) -> (
        ShotContext<'_, N>,
        &mut Vec<Option<Hierarchy<N>>>,
        &mut RootThroughputs,
    ) {
        let deadline = self.deadline();
        let state = &mut self.state;
        let mut refine = self.setup.refine_context(&state.cache);
        refine.deadline = deadline;
        refine.final_release = self.final_release;
        let ctx = ShotContext {
            refine,
            field: &state.field,
            stored_from: &self.setup.stored_from,
        };
        (ctx, &mut state.hierarchies, &mut state.roots)
    }

    /// What the shot's refinement cut short at the deadline, into the
    /// stats.
    fn book_late(&mut self, late: Lateness) {
        let stats = &mut self.state.stats;
        stats.late_links += late.links.into_inner();
        stats.late_root_throughputs += late.roots.into_inner();
        stats.late_root_seconds += late.root_nanos.into_inner() as f64 * 1e-9;
    }

    /// Flux that a split could not keep leaves the residual (it is booked
    /// as escaped); the node links of every hierarchy, in order.
    fn book_lost(&mut self, stage_two: StageTwo<N>) -> NodeLinks<N> {
        let mut node_links = Vec::with_capacity(stage_two.len());
        for (links, h, lost) in stage_two {
            if let Some(hier) = self.state.hierarchies[h as usize].as_mut() {
                hier.unshot_flux = (hier.unshot_flux - lost).max(Spectrum::zero());
                self.state.queue.touch(Source::Stored(h));
            }
            for b in 0..N {
                self.state.ledger.escaped[b] += lost[b];
            }
            if !links.is_empty() {
                node_links.push((h, links));
            }
        }
        node_links
    }

    /// Phase 6a: every node link adds its radiance, scaled by its group's
    /// shot scale (`scales`) and renormalisation, to its node's L^G and the node's flux to its hierarchy's
    /// key (the renormalisation applies to both alike).
    fn apply_node_links(
        &mut self,
        node_links: &NodeLinks<N>,
        scales: &[Spectrum<N>],
        group_scale: &[(Spectrum<N>, Spectrum<N>)],
    ) {
        for (h, links) in node_links {
            let Some(hier) = self.state.hierarchies[*h as usize].as_mut() else {
                continue;
            };
            for nl in links {
                let node = &mut hier.nodes[nl.node as usize];
                let (midpoint, sampled) = group_scale[nl.group as usize];
                let dl = nl.gathered
                    * scales[nl.group as usize]
                    * if nl.sampled { sampled } else { midpoint };
                node.gathered += dl;
                let t = node.t;
                hier.unshot_flux += dl * (PI * t);
            }
            self.state.queue.touch(Source::Stored(*h));
        }
    }

    /// Phase 6b: δL over the source is zeroed, and a stored source goes
    /// back in place.
    fn unlink(&mut self, sending: Sending<N>) {
        match sending {
            Sending::Radiosity(face) => {
                let root = self.setup.forest().root(face.surface());
                self.state
                    .field
                    .clear_unshot(self.setup.forest(), root, face.side());
            }
            // Its unshot radiance was cleared when it was taken.
            Sending::Stored { is_self: true, .. } => {}
            Sending::Stored {
                index,
                mut hierarchy,
                is_self: false,
            } => {
                hierarchy.clear_unshot();
                self.state.hierarchies[index as usize] = Some(hierarchy);
                self.state.queue.touch(Source::Stored(index));
            }
            Sending::Far { mut field, .. } => {
                for b in &mut field.blocks {
                    b.unshot = Spectrum::zero();
                }
                let face = field.face;
                self.state.far[face] = Some(field);
                self.state.queue.touch(Source::Far(face));
            }
        }
    }
}

/// What a shot's refinement reads.
pub(crate) struct ShotContext<'a, const N: usize> {
    pub refine: RefineContext<'a, N>,
    pub field: &'a crate::radiosity::ElementRadiance<N>,
    /// The hierarchies of every sending face (`Setup::stored_from`).
    pub stored_from: &'a PerFace<Range<usize>>,
}

/// The fewest stored hierarchies a face needs for its faint glossy shares
/// to be received at the stored nodes above their element
/// (docs/solver.md, "Faint glossy shares"): below it, splitting each
/// hierarchy down to the element costs little, and the finer light is
/// kept (the coarser one moved a golden image; measured there).
const FAINT_MIN_HIERARCHIES: usize = 64;

/// Each pair link's part of its three-point links, once for all the
/// hierarchies that leave its receiving face (`None` for a link into a
/// face without stored interactions, or one that carries no light, such as
/// a glossy share that waits: `deferred`). Each group has its sender.
fn incidences<const N: usize>(
    ctx: &RefineContext<'_, N>,
    stored_from: &PerFace<Range<usize>>,
    senders: &[(&Sender<'_, N>, FaceId)],
    pair_links: &[PairLink<N>],
) -> Vec<Option<Incidence<N>>> {
    pair_links
        .par_iter()
        .zip(senders)
        .map(|(l, &(sender, send_face))| {
            let tij = crate::throughput::Throughput {
                t: l.t,
                v: 1.0,
                f: 0.0,
                spread: 0.0,
            };
            let mut inc = (ctx.faces[l.face].stored && !l.unshot.is_black())
                .then(|| ctx.incidence_with(sender, send_face.of(l.i), l.face.of(l.j), tij))
                .flatten()?;
            inc.coarse = stored_from[l.face].len() >= FAINT_MIN_HIERARCHIES
                && ctx.glossy_negligible(l.face, &inc);
            Some(inc)
        })
        .collect()
}

/// Phase 2, far part: pair links from the source to the members of its
/// far blocks (`cluster_transport`): from a face's root with its unshot
/// radiance, or from a far field with each block's own.
fn far_stage_one<const N: usize>(
    ctx: &RefineContext<'_, N>,
    field: &crate::radiosity::ElementRadiance<N>,
    sending: &Sending<N>,
) -> Vec<PairLink<N>> {
    let face = sending.face();
    let blocks = &ctx.clusters.cuts[face].far;
    let root = ctx.forest.root(face.surface());
    match sending {
        Sending::Radiosity(_) => {
            let dl = field.unshot[face.side()][root.index()];
            far_links(&ctx.far(), face.of(root), blocks, |_| dl)
        }
        Sending::Far { field, .. } => far_links(&ctx.far(), face.of(root), blocks, |b| {
            field.blocks[b].unshot
        }),
        Sending::Stored { .. } => Vec::new(),
    }
}

/// Phase 4: three-point links into the stored hierarchies of every glossy
/// receiving face, in parallel over those hierarchies (each task owns its
/// hierarchy, so the receiving trees grow without locks).
fn stage_two<const N: usize>(
    ctx: &RefineContext<'_, N>,
    senders: &[(&Sender<'_, N>, FaceId)],
    (hierarchies, stored_from): (&mut [Option<Hierarchy<N>>], &PerFace<Range<usize>>),
    (pair_links, incidences): (&[PairLink<N>], &[Option<Incidence<N>>]),
    (batch, trim): (&[u32], bool),
) -> StageTwo<N> {
    let mut groups_of_face: HashMap<FaceId, Vec<u32>> = HashMap::new();
    for &g in batch {
        if incidences[g as usize].is_some() {
            let face = pair_links[g as usize].face;
            groups_of_face.entry(face).or_default().push(g);
        }
    }
    let memo = IncidenceMemo::new();
    // The hierarchy sending this shot is out of its slot (unless it is a
    // face's interaction with itself, which receives).
    let ranges: Vec<Range<usize>> = groups_of_face
        .keys()
        .map(|&f| stored_from[f].clone())
        .collect();
    let tasks: Vec<(usize, &mut Hierarchy<N>)> = receiving(hierarchies, ranges)
        .into_iter()
        .flat_map(|(start, part)| {
            part.iter_mut()
                .enumerate()
                .filter_map(move |(k, hier)| hier.as_mut().map(|hier| (start + k, hier)))
        })
        .collect();
    tasks
        .into_par_iter()
        .map(|(h, hier)| {
            let groups = &groups_of_face[&hier.from];
            let (sender, si) = senders[groups[0] as usize];
            let mut task = TripleTask {
                sender,
                si,
                h: hier,
                group: 0,
                lost: Spectrum::zero(),
                out: Vec::new(),
                memo: &memo,
                local: Default::default(),
            };
            let mut nodes = Vec::new();
            for &g in groups {
                let l = &pair_links[g as usize];
                let Some(incidence) = &incidences[g as usize] else {
                    continue;
                };
                task.group = g;
                (task.sender, task.si) = senders[g as usize];
                ctx.nodes_for(task.h, (l.j, incidence.coarse), &mut task.lost, &mut nodes);
                for &n in &nodes {
                    // l.j, or past the deadline a stored node's coarser
                    // sender element above it.
                    let j = task.h.nodes[n as usize].from;
                    ctx.refine_triple(&mut task, l.i, j, n, Some(incidence));
                }
            }
            // A large shot's links live until their batch is received:
            // without the growth's spare capacity (0.5 GB of the
            // staircase's peak; a reallocation per hierarchy, so only
            // there).
            if trim {
                task.out.shrink_to_fit();
            }
            (task.out, h as u32, task.lost)
        })
        .collect()
}

/// The disjoint parts of `hierarchies` in `ranges` (with their first
/// index), so that stage 2 visits only the receiving faces' hierarchies.
fn receiving<T>(hierarchies: &mut [T], mut ranges: Vec<Range<usize>>) -> Vec<(usize, &mut [T])> {
    ranges.sort_by_key(|r| r.start);
    let mut out = Vec::with_capacity(ranges.len());
    let (mut rest, mut base) = (hierarchies, 0);
    for r in ranges.into_iter().filter(|r| !r.is_empty()) {
        let tail = std::mem::take(&mut rest).split_at_mut(r.start - base).1;
        let (part, tail) = tail.split_at_mut(r.len());
        out.push((r.start, part));
        (rest, base) = (tail, r.end);
    }
    out
}
