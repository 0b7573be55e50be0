//! The final gather's refinement (`gather_links` describes the links):
//! once the solve has converged, every Lambertian sender — the two-point
//! tree of a face, with its final radiance L + Le — is refined against
//! every receiving face once more, exactly as a shot refines, and its far
//! blocks are expanded into one link per member face.
//!
//! Its cost is bounded by flux and by time (docs/solver.md, "The final
//! gather"): senders go in order of the flux they send, a pair whose
//! bounded flux is below the photometric threshold is linked at its roots
//! without tracing the root pair's many shadow rays, and once the time
//! budget is spent the remaining senders are linked at their roots only.

use std::f64::consts::PI;
use std::time::Instant;

use rayon::prelude::*;
use trilux_color::Spectrum;
use trilux_geometry::{ElementId, FaceId};

use crate::faces::TransportFace;
use crate::gather_links::{GatherLink, GatherLinks, LinkSource};
use crate::link::{PairLink, PairShot, Sender, Sent};
use crate::radiosity::ElementRadiance;
use crate::refine::RefineContext;
use crate::setup::Setup;
use crate::throughput::ThroughputCache;

/// Senders refined between two looks at the clock: enough to keep every
/// thread busy, few enough that the gather stops soon after its budget.
const BATCH: usize = 32;

/// What the final gather did (the stats' `gather_*` fields).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct GatherReport {
    /// Senders (faces that send light).
    pub senders: usize,
    /// Senders reached after the deadline, linked at their roots.
    pub coarse_senders: usize,
    /// Pairs linked without tracing, their bounded flux negligible.
    pub bounded_pairs: u64,
}

/// One sender's links: its place in face order, its links keyed by
/// receiver, and how many of its pairs were linked by their bound.
type SenderLinks = (usize, Vec<(u64, GatherLink)>, u64);

/// How one sender is gathered.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Depth {
    /// Refined as a shot refines (negligible pairs by their bound).
    Refined,
    /// At the roots only (the time budget is spent).
    Roots,
}

/// The gather links of the converged solution (module docs): from the
/// final two-point radiance `field`, refined through `cache`; senders
/// reached after `deadline` are linked at their roots only.
pub(crate) fn gather_links<const N: usize>(
    setup: &Setup<N>,
    field: &ElementRadiance<N>,
    cache: &ThroughputCache,
    deadline: Option<Instant>,
) -> (GatherLinks, GatherReport) {
    let ctx = setup.refine_context(cache);
    let forest = setup.forest();
    // A glossy face without a Lambertian part holds two-point radiance
    // only from lights without area and the sky (their glossy share,
    // `light_shot`).
    let lights = !setup.scene.lights().is_empty() || setup.scene.sky().is_some();
    let mut faces: Vec<(usize, FaceId, &TransportFace<N>, f64)> = setup
        .faces
        .iter()
        .filter(|(_, f)| !(f.rho_d.is_black() && f.emission.is_black()) || (lights && f.stored))
        .filter(|&(face, f)| !sent(setup, field, face, f).is_black())
        .enumerate()
        .map(|(k, (face, f))| {
            let flux = PI * sent(setup, field, face, f).sum() * area(setup, face);
            (k, face, f, flux)
        })
        .collect();
    // The brightest senders first: if the budget runs out, what is left
    // coarse carries the least light.
    faces.sort_by(|a, b| b.3.total_cmp(&a.3));
    let mut report = GatherReport {
        senders: faces.len(),
        ..GatherReport::default()
    };
    // Per sender in face order, so that the links' order (and the saved
    // solution) does not depend on the senders' brightness order.
    let mut by_sender: Vec<Vec<(u64, GatherLink)>> = vec![Vec::new(); faces.len()];
    for batch in faces.chunks(BATCH) {
        let depth = if deadline.is_some_and(|d| Instant::now() >= d) {
            report.coarse_senders += batch.len();
            Depth::Roots
        } else {
            Depth::Refined
        };
        let made: Vec<SenderLinks> = batch
            .par_iter()
            .map(|&(k, face, f, _)| {
                let sender = Sender::Radiosity {
                    field,
                    side: face.side(),
                    sent: Sent::Final,
                    emission: f.emission,
                };
                let partners = &setup.partners[face];
                let (mut out, bounded) = links(&ctx, &sender, (face, partners), depth);
                out.extend(far_gather_links(&ctx, field, face, f));
                (k, out, bounded)
            })
            .collect();
        for (k, out, bounded) in made {
            by_sender[k] = out;
            report.bounded_pairs += bounded;
        }
    }
    let pairs: Vec<(u64, GatherLink)> = by_sender.into_iter().flatten().collect();
    (
        GatherLinks::from_pairs(forest.element_count(), pairs),
        report,
    )
}

/// The radiance L + Le a face sends (its root's average).
fn sent<const N: usize>(
    setup: &Setup<N>,
    field: &ElementRadiance<N>,
    face: FaceId,
    f: &TransportFace<N>,
) -> Spectrum<N> {
    let root = setup.forest().root(face.surface());
    field.radiance[face.side()][root.index()] + f.emission
}

/// A face's exposed area.
fn area<const N: usize>(setup: &Setup<N>, face: FaceId) -> f64 {
    let root = setup.forest().root(face.surface());
    setup.exposed_area[face.side()][root.index()]
}

/// The gather links from one sender face to its near partners, keyed by
/// receiver, and how many pairs were linked by their bound.
fn links<const N: usize>(
    ctx: &RefineContext<'_, N>,
    sender: &Sender<'_, N>,
    (send_face, partners): (FaceId, &[FaceId]),
    depth: Depth,
) -> (Vec<(u64, GatherLink)>, u64) {
    let forest = ctx.forest;
    let i = forest.root(send_face.surface());
    let mut out: Vec<PairLink<N>> = Vec::new();
    let mut roots: Vec<(u64, GatherLink)> = Vec::new();
    let mut bounded = 0;
    for &r in partners {
        let j = forest.root(r.surface());
        let unshot = sender.sent_radiance(forest, i, j);
        if unshot.is_black() {
            continue;
        }
        let bound = ctx.clusters.tree.throughput_bound(
            send_face.surface(),
            forest.element(i).area,
            r.surface(),
            forest.element(j).area,
        );
        if depth == Depth::Roots || PI * bound * unshot.sum() < ctx.flux_threshold {
            bounded += u64::from(depth == Depth::Refined);
            let v = ctx.cheap_visibility(r.of(j), send_face.of(i));
            if v > 0.0 {
                roots.push((r.of(j).key(), gather_link(send_face, i, v)));
            }
            continue;
        }
        let shot = PairShot {
            sender,
            si: send_face,
            sj: r,
        };
        // The renderer evaluates the point form factor at every pixel, so
        // the receiver-side form-factor spread does not matter here:
        // refinement only separates partial visibility and uneven sender
        // radiance (an unbounded spread budget).
        ctx.refine_pair(shot, i, j, f64::INFINITY, &mut out);
    }
    let refined = out.into_iter().filter(|l| !l.unshot.is_black()).map(|l| {
        let v = ctx.throughput(l.face.of(l.j), send_face.of(l.i)).v;
        (l.face.of(l.j).key(), gather_link(send_face, l.i, v))
    });
    roots.extend(refined);
    (roots, bounded)
}

fn gather_link(face: FaceId, sender: ElementId, visibility: f64) -> GatherLink {
    GatherLink {
        sender,
        sender_face: face,
        source: LinkSource::Face(face),
        visibility: visibility as f32,
    }
}

/// The gather links of one Lambertian sender face towards the members of
/// its far blocks (`cluster_transport`): the cluster links expanded at
/// link time into one link per member face, from the sender's root
/// element, with the block's visible fraction. So the renderer's links
/// still cover every sender of every receiving element exactly once.
fn far_gather_links<const N: usize>(
    ctx: &RefineContext<'_, N>,
    field: &ElementRadiance<N>,
    face: FaceId,
    f: &TransportFace<N>,
) -> Vec<(u64, GatherLink)> {
    let far = ctx.far();
    let root = ctx.forest.root(face.surface());
    let sent = field.radiance[face.side()][root.index()] + f.emission;
    let mut out = Vec::new();
    if sent.is_black() {
        return out;
    }
    for block in &ctx.clusters.cuts[face].far {
        let v = far.block_visibility(face.of(root), block);
        if v <= 0.0 {
            continue;
        }
        far.members(face.of(root), block.cluster, |m| {
            let link = gather_link(face, root, v);
            out.push((m.face.of(ctx.forest.root(m.face.surface())).key(), link));
        });
    }
    out
}

#[cfg(test)]
mod tests {
    use std::collections::BTreeSet;
    use std::time::Instant;

    use glam::DVec3;
    use trilux_geometry::FaceId;

    use super::*;
    use crate::state::ShotState;
    use crate::test_scenes as ts;

    /// The (receiving face, sending face) pairs the links cover.
    fn covered(
        links: &GatherLinks,
        forest: &trilux_geometry::ElementForest,
    ) -> BTreeSet<(u32, u32)> {
        let face = |e: trilux_geometry::FaceElement| {
            FaceId::new(forest.element(e.element).surface, e.side).0
        };
        links
            .iter()
            .map(|(e, l)| (face(e), l.sender_face.0))
            .collect()
    }

    /// A gather whose budget is already spent links every sender at its
    /// roots: no sender is refined, yet every (receiver, sender) pair the
    /// refined gather covers is still covered (the renderer misses no
    /// light), with one link per pair.
    #[test]
    fn a_spent_budget_links_every_sender_at_its_roots() {
        let shapes = [
            ts::square(DVec3::new(0.0, 0.0, 1.0), 0.5, true),
            ts::square(DVec3::ZERO, 2.0, false),
            ts::square(DVec3::new(0.5, 0.0, 0.5), 0.5, true),
        ];
        let setup = ts::setup(
            &shapes,
            &[ts::diffuse(0.0), ts::diffuse(0.5), ts::diffuse(0.5)],
            &[Some(1.0), None, None],
            ts::settings(4),
        );
        let state = ShotState::new(&setup);
        let cache = ThroughputCache::new(1 << 16);
        let (full, report) = gather_links(&setup, &state.field, &cache, None);
        assert_eq!((report.senders, report.coarse_senders), (1, 0));
        let past = Instant::now();
        let (coarse, report) = gather_links(&setup, &state.field, &cache, Some(past));
        assert_eq!((report.senders, report.coarse_senders), (1, 1));
        let forest = setup.forest();
        assert!(
            full.len() > coarse.len(),
            "the refined gather splits: {} links, coarse {}",
            full.len(),
            coarse.len()
        );
        assert_eq!(covered(&full, forest), covered(&coarse, forest));
        assert_eq!(coarse.len(), covered(&coarse, forest).len());
    }
}
