//! The final gather's refinement (`gather_links` describes the links):
//! once the solve has converged, every Lambertian sender — the two-point
//! tree of a face, with its final radiance L + Le — is refined against
//! every receiving face once more, exactly as a shot refines, and its far
//! blocks are expanded into one link per member face.

use rayon::prelude::*;
use trilux_geometry::{ElementId, FaceId};

use crate::faces::TransportFace;
use crate::gather_links::{GatherLink, GatherLinks, LinkSource};
use crate::link::{PairLink, PairShot, Sender, Sent};
use crate::radiosity::ElementRadiance;
use crate::refine::RefineContext;
use crate::setup::Setup;
use crate::throughput::ThroughputCache;

/// The gather links of the converged solution (module docs): from the
/// final two-point radiance `field`, refined through `cache`.
pub(crate) fn gather_links<const N: usize>(
    setup: &Setup<N>,
    field: &ElementRadiance<N>,
    cache: &ThroughputCache,
) -> GatherLinks {
    let ctx = setup.refine_context(cache);
    let forest = setup.forest();
    let faces: Vec<(FaceId, &TransportFace<N>)> = setup
        .faces
        .iter()
        .filter(|(_, f)| !(f.rho_d.is_black() && f.emission.is_black()))
        .collect();
    let from_faces = faces.par_iter().flat_map_iter(|&(face, f)| {
        let sender = Sender::Radiosity {
            field,
            side: face.side(),
            sent: Sent::Final,
            emission: f.emission,
        };
        let root = forest.root(face.surface());
        let pairs: Vec<_> = setup.partners[face]
            .iter()
            .map(|&r| (root, r, forest.root(r.surface())))
            .collect();
        let mut out = links(&ctx, &sender, face, &pairs, |_, _| LinkSource::Face(face));
        out.extend(far_gather_links(&ctx, field, face, f));
        out
    });
    let pairs: Vec<(u64, GatherLink)> = from_faces.collect();
    GatherLinks::from_pairs(forest.element_count(), pairs)
}

/// The gather links from one sender to the given (sender root, receiver
/// face, receiver root) pairs, keyed by receiver.
fn links<const N: usize>(
    ctx: &RefineContext<'_, N>,
    sender: &Sender<'_, N>,
    send_face: FaceId,
    pairs: &[(ElementId, FaceId, ElementId)],
    source: impl Fn(ElementId, ElementId) -> LinkSource,
) -> Vec<(u64, GatherLink)> {
    let mut out: Vec<PairLink<N>> = Vec::new();
    for &(i, r, j) in pairs {
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
    out.into_iter()
        .filter(|l| !l.unshot.is_black())
        .map(|l| {
            let v = ctx.throughput(l.face.of(l.j), send_face.of(l.i)).v;
            let link = GatherLink {
                sender: l.i,
                sender_face: send_face,
                source: source(l.i, l.j),
                visibility: v as f32,
            };
            (l.face.of(l.j).key(), link)
        })
        .collect()
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
            let link = GatherLink {
                sender: root,
                sender_face: face,
                source: LinkSource::Face(face),
                visibility: v as f32,
            };
            out.push((m.face.of(ctx.forest.root(m.face.surface())).key(), link));
        });
    }
    out
}
