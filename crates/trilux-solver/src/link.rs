//! The links and senders of refinement: what a sender sends ([`Sender`],
//! its unshot radiance during a shot or its final radiance for the gather
//! links) and the transient links a shot makes — pair links of stage 1
//! ([`PairLink`]) and node links of stage 2 ([`NodeLink`]); paper §4.2.
//! Links live for one shot; `refine` makes them, `shot` applies them.

use trilux_color::Spectrum;
use trilux_geometry::{ElementForest, ElementId, FaceId, Side};

use crate::interaction::Hierarchy;
use crate::radiosity::ElementRadiance;

/// What a sender sends: its unshot radiance δL (a shot), or its final
/// radiance L plus emission (the gather links made after the solve).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Sent {
    /// δL, during the solve.
    Unshot,
    /// L + Le, after the solve.
    Final,
}

/// Where refinement takes the radiance a sender sends, by element pair.
pub(crate) enum Sender<'a, const N: usize> {
    /// A Lambertian face: the radiance of its element tree, the same
    /// towards every j.
    Radiosity {
        /// The face's per-element radiance.
        field: &'a ElementRadiance<N>,
        /// The side it sends from.
        side: Side,
        /// Unshot or final radiance.
        sent: Sent,
        /// The face's emitted radiance (added to the final radiance).
        emission: Spectrum<N>,
    },
    /// A stored interaction hierarchy.
    Stored {
        /// The hierarchy.
        hierarchy: &'a Hierarchy<N>,
        /// Unshot or final radiance.
        sent: Sent,
    },
    /// A glossy face's far field (`cluster_transport`): the unshot
    /// radiance it sends towards each receiving surface, by surface (zero
    /// for surfaces outside its far blocks).
    Far {
        /// δL towards every input surface.
        by_surface: &'a [Spectrum<N>],
    },
    /// A pair link's glossy share summed over shots (`deferred`): the
    /// pair's average δL, the same from every sub-element of i towards
    /// every sub-element of j, as the pair link carried it.
    Uniform {
        /// δL.
        unshot: Spectrum<N>,
    },
}

impl<const N: usize> Sender<'_, N> {
    /// The radiance element i sends towards element j: its unshot
    /// radiance δL during a shot ([`Sent::Unshot`]), its final radiance
    /// L (+ Le for a face) for the gather links ([`Sent::Final`]); a far
    /// field always sends its unshot radiance.
    pub(crate) fn sent_radiance(
        &self,
        forest: &ElementForest,
        i: ElementId,
        j: ElementId,
    ) -> Spectrum<N> {
        match *self {
            Sender::Radiosity {
                field,
                side,
                sent,
                emission,
            } => match sent {
                Sent::Unshot => field.unshot[side][i.index()],
                Sent::Final => field.radiance[side][i.index()] + emission,
            },
            Sender::Stored { hierarchy, sent } => {
                let node = &hierarchy.nodes[hierarchy.node_for(forest, i, j) as usize];
                match sent {
                    Sent::Unshot => node.unshot,
                    Sent::Final => node.radiance,
                }
            }
            Sender::Far { by_surface } => by_surface
                .get(forest.element(j).surface.index())
                .copied()
                .unwrap_or_else(Spectrum::zero),
            Sender::Uniform { unshot } => unshot,
        }
    }
}

/// What every pair link of one stage-1 refinement shares: where the unshot
/// radiance comes from, the sending face and the receiving face.
#[derive(Clone, Copy)]
pub(crate) struct PairShot<'s, const N: usize> {
    /// Unshot radiance by element pair.
    pub sender: &'s Sender<'s, N>,
    /// The sending face.
    pub si: FaceId,
    /// The receiving face.
    pub sj: FaceId,
}

/// A transient link of stage 1.
#[derive(Clone, Debug)]
pub(crate) struct PairLink<const N: usize> {
    /// Sending element.
    pub i: ElementId,
    /// Receiving element.
    pub j: ElementId,
    /// Receiving face.
    pub face: FaceId,
    /// T_ij.
    pub t: f64,
    /// δL_i sent along the link.
    pub unshot: Spectrum<N>,
}

/// A transient link of stage 2: a radiance increment for one node of the
/// hierarchy whose list holds it (`shot::StageTwo`).
#[derive(Clone, Debug)]
pub(crate) struct NodeLink<const N: usize> {
    /// Node within its hierarchy.
    pub node: u32,
    /// The pair link (stage 1) this transfer belongs to.
    pub group: u32,
    /// ΔL^G = δL_ij · R(i→j→k) (paper §4.2, step 2).
    pub gathered: Spectrum<N>,
    /// R was estimated by sampling the lobe (docs/solver.md, "Narrow
    /// lobes"): the link's flux already conserves energy and is not
    /// renormalised.
    pub sampled: bool,
}

/// A shot's node links, per receiving hierarchy (its index).
pub(crate) type NodeLinks<const N: usize> = Vec<(u32, Vec<NodeLink<N>>)>;
