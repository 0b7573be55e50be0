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
//!
//! This module holds the links as the solution keeps them; `final_gather`
//! makes them.

use trilux_color::Spectrum;
use trilux_geometry::{ElementId, FaceElement, FaceId};

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
