//! Gather links: the final gather of hierarchical radiosity, kept with the
//! solution for rendering.
//!
//! Once the solve has converged, every Lambertian sender — the two-point
//! tree of a face, with its final radiance L + Le — is refined against
//! every receiving face once more, exactly as a shot refines (paper §3.2.2, §4.3: photometric
//! criterion, sender variation, form-factor spread, partial visibility).
//! The pair links this makes partition every (sender face × receiver face)
//! product, so for any point x of a receiving face the links of the
//! elements containing x (its leaf and the leaf's ancestors) cover every
//! sender exactly once. A renderer evaluates them at x at pixel resolution:
//! L_in(x) ≈ Σ L_i F(x → i) V(x, i), with the point-to-element form factor
//! F computed exactly and the visibility taken from the link (1 when the
//! link's shadow rays all passed) or traced per pixel where it is partial.
//! Direct light is the part of this sum whose senders emit. Glossy senders
//! are left out: their stored radiance is constant over whole receiving
//! elements, too coarse to read at pixel resolution; a renderer gathers
//! their light by sampling.

use rayon::prelude::*;
use trilux_color::Spectrum;
use trilux_geometry::{ElementId, FaceElement, FaceId};

use crate::faces::TransportFace;
use crate::link::{PairLink, PairShot, Sender, Sent};
use crate::refine::RefineContext;
use crate::solver::Solver;

/// Where a gather link's sender radiance comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LinkSource {
    /// The two-point radiance of a face's element (plus its emission).
    Face(FaceId),
    /// A node of a stored interaction hierarchy.
    Node {
        /// The hierarchy's index.
        hierarchy: u32,
        /// The node.
        node: u32,
    },
}

/// One sender of a receiving element.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GatherLink {
    /// The sending element.
    pub sender: ElementId,
    /// The sending face's side (the sender is seen from it).
    pub sender_face: FaceId,
    /// Where its radiance is read.
    pub source: LinkSource,
    /// The visible fraction the solve measured for the pair: 1 when every
    /// shadow ray passed, in (0, 1) when partial.
    pub visibility: f32,
}

/// Every receiving element's gather links, by face element.
#[derive(Clone, Debug, Default)]
pub struct GatherLinks {
    /// Start of each face element's links (indexed by `FaceElement::key`),
    /// one more entry than keys.
    offsets: Vec<u32>,
    links: Vec<GatherLink>,
}

impl GatherLinks {
    /// The positions of the links into one face element (empty for an
    /// element the links do not know).
    pub fn row(&self, e: FaceElement) -> std::ops::Range<usize> {
        let k = e.key() as usize;
        match (self.offsets.get(k), self.offsets.get(k + 1)) {
            (Some(&a), Some(&b)) => a as usize..b as usize,
            _ => 0..0,
        }
    }

    /// The links into one face element.
    pub fn at(&self, e: FaceElement) -> &[GatherLink] {
        &self.links[self.row(e)]
    }

    /// Number of links.
    pub fn len(&self) -> usize {
        self.links.len()
    }

    /// Bytes held (row starts and links).
    pub fn bytes(&self) -> usize {
        self.offsets.capacity() * std::mem::size_of::<u32>()
            + self.links.capacity() * std::mem::size_of::<GatherLink>()
    }

    /// True when there are none.
    pub fn is_empty(&self) -> bool {
        self.links.is_empty()
    }

    /// Every (receiver, link), in receiver order.
    pub fn iter(&self) -> impl Iterator<Item = (FaceElement, &GatherLink)> {
        self.offsets.windows(2).enumerate().flat_map(move |(k, w)| {
            let receiver = FaceElement::new(
                ElementId((k / 2) as u32),
                trilux_geometry::Side::from_back(k % 2 == 1),
            );
            self.links[w[0] as usize..w[1] as usize]
                .iter()
                .map(move |l| (receiver, l))
        })
    }

    /// The row starts (one per face element, plus the end) and the links,
    /// for the solution file.
    pub(crate) fn raw(&self) -> (&[u32], &[GatherLink]) {
        (&self.offsets, &self.links)
    }

    /// Links from their row starts, checked: rows non-decreasing, the last
    /// at the end of `links`.
    pub(crate) fn from_raw(offsets: Vec<u32>, links: Vec<GatherLink>) -> Result<Self, String> {
        let ordered = offsets.windows(2).all(|w| w[0] <= w[1]);
        let complete = offsets.first() == Some(&0)
            && offsets.last().is_some_and(|&l| l as usize == links.len());
        if ordered && complete {
            Ok(GatherLinks { offsets, links })
        } else {
            Err("corrupt gather links (rows out of order)".into())
        }
    }

    /// Links sorted by receiver into compressed rows over `elements`
    /// elements.
    pub(crate) fn from_pairs(elements: usize, mut pairs: Vec<(u64, GatherLink)>) -> Self {
        pairs.sort_by_key(|(k, _)| *k);
        let keys = 2 * elements;
        let mut offsets = vec![0u32; keys + 1];
        for (k, _) in &pairs {
            offsets[*k as usize + 1] += 1;
        }
        for k in 0..keys {
            offsets[k + 1] += offsets[k];
        }
        GatherLinks {
            offsets,
            links: pairs.into_iter().map(|(_, l)| l).collect(),
        }
    }
}

impl<const N: usize> Solver<N> {
    /// The gather links of the converged solution (module docs).
    pub(crate) fn gather_links(&self) -> GatherLinks {
        let ctx = self.refine_context();
        let faces: Vec<(FaceId, &TransportFace<N>)> = self
            .faces
            .iter()
            .filter(|(_, f)| !(f.rho_d.is_black() && f.emission.is_black()))
            .collect();
        let from_faces = faces.par_iter().flat_map_iter(|&(face, f)| {
            let sender = Sender::Radiosity {
                field: &self.field,
                side: face.side(),
                sent: Sent::Final,
                emission: f.emission,
            };
            let root = self.forest.root(face.surface());
            let pairs: Vec<_> = self.partners[face]
                .iter()
                .map(|&r| (root, r, self.forest.root(r.surface())))
                .collect();
            let mut out = links(&ctx, &sender, face, &pairs, |_, _| LinkSource::Face(face));
            out.extend(far_gather_links(&ctx, &self.field, face, f));
            out
        });
        let pairs: Vec<(u64, GatherLink)> = from_faces.collect();
        GatherLinks::from_pairs(self.forest.element_count(), pairs)
    }
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
    field: &crate::radiosity::ElementRadiance<N>,
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

/// The final radiance a link's sender sends (L + Le for a face, L_IJ for a
/// hierarchy node), from the solution's parts.
pub(crate) fn link_radiance<const N: usize>(
    link: &GatherLink,
    radiance: &trilux_geometry::Sided<Vec<Spectrum<N>>>,
    emission: &[Spectrum<N>],
    shape_of: impl Fn(FaceId) -> usize,
    node_radiance: impl Fn(u32, u32) -> Spectrum<N>,
) -> Spectrum<N> {
    match link.source {
        LinkSource::Face(face) => {
            let le = match face.side() {
                trilux_geometry::Side::Front => emission[shape_of(face)],
                trilux_geometry::Side::Back => Spectrum::zero(),
            };
            radiance[face.side()][link.sender.index()] + le
        }
        LinkSource::Node { hierarchy, node } => node_radiance(hierarchy, node),
    }
}
