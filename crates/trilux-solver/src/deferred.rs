//! Deferred glossy reception (docs/solver.md, "Deferred glossy
//! reception").
//!
//! Stage 2 spreads every pair link that reaches a glossy face over all the
//! face's stored hierarchies, however little light the link carries. Late
//! in a solve nearly every link is below the photometric threshold, and a
//! face that many others light (the floor of a room) sends one such link
//! to every glossy face at each of its many shots: on a room of 256 boxes
//! these links were most of the solve.
//!
//! Everything a link's glossy share does at its face (the area
//! reflectances of its three-point links, its far field, its
//! renormalisation, the ledger) is linear in δL_i T_ij for a fixed pair
//! (i, j). So a root-to-root link below the threshold keeps its Lambertian
//! share at once (as before) and leaves its glossy share waiting at its
//! face, summed with the earlier ones of the same sender element; when the
//! sum reaches the threshold it is refined in one go, as the link of that
//! pair carrying the sum. Light waiting counts in the residual (it is
//! arrived light not yet reflected), and a face's waiting light is a
//! source like any other: when it is the largest, all of it is refined
//! (`Source::Deferred`). `Solver::plan_glossy` (in `shot`) decides which
//! links may wait.

use std::collections::HashMap;
use std::collections::hash_map::Entry;

use trilux_color::Spectrum;
use trilux_geometry::{ElementId, FaceElement, FaceId, PerFace};

use crate::link::PairLink;
use crate::throughput::BuildKeyHasher;

/// A pair's glossy light waiting at its receiving face.
#[derive(Clone, Debug)]
pub(crate) struct Pending<const N: usize> {
    /// The sending face.
    pub face: FaceId,
    /// The sending element.
    pub from: FaceElement,
    /// Σ δL_i T_ij over the pair's links, each with its shot's scale.
    pub sum: Spectrum<N>,
    /// Σ δL_i T_ij × the reflected share of each link's shot (`ambient`).
    pub reflected: Spectrum<N>,
    /// T_ij.
    pub t: f64,
    /// The flux waiting, Σ π T_ij δL_i (1 − ρ_d): what arrived and was
    /// neither reflected diffusely nor yet glossily (in the residual).
    pub room: Spectrum<N>,
}

/// Every face's waiting glossy light.
pub(crate) struct Deferred<const N: usize> {
    /// By receiving face, by the sending element's key.
    pub faces: PerFace<HashMap<u64, Pending<N>, BuildKeyHasher>>,
    /// Σ room by face: the key of its source.
    pub room: PerFace<Spectrum<N>>,
}

impl<const N: usize> Deferred<N> {
    /// Nothing waiting, for `surfaces` input surfaces.
    pub fn new(surfaces: usize) -> Self {
        Deferred {
            faces: PerFace::from_fn(surfaces, |_| HashMap::default()),
            room: PerFace::from_fn(surfaces, |_| Spectrum::zero()),
        }
    }

    /// All the flux waiting.
    pub fn total(&self) -> Spectrum<N> {
        self.room.values().copied().sum()
    }

    /// Bytes the waiting light holds (entries × (key + value), with the
    /// hash table's load factor of about 8/7): at most one entry per near
    /// pair of faces.
    pub fn bytes(&self) -> usize {
        let entries: usize = self.faces.values().map(HashMap::capacity).sum();
        entries * (std::mem::size_of::<u64>() + std::mem::size_of::<Pending<N>>() + 1)
            + self.room.values().len() * std::mem::size_of::<Spectrum<N>>()
    }
}

/// What becomes of one pair link's glossy share in this shot.
#[derive(Clone, Debug)]
pub(crate) enum GlossyIn<const N: usize> {
    /// Refined now with the link's own δL (the paper's way).
    Now,
    /// Waits at its face, summed with the pair's earlier links.
    Wait {
        /// The sending element.
        from: FaceElement,
    },
    /// The pair's sum, this link's δL included, refined now.
    Flush {
        /// The sending face.
        face: FaceId,
        /// δL = Σ δL T / T: the radiance of one link carrying the sum.
        unshot: Spectrum<N>,
        /// The reflected share of the sum (`ambient`).
        share: Spectrum<N>,
        /// The flux that waited before this shot (leaves the residual).
        waited: Spectrum<N>,
    },
}

impl<const N: usize> GlossyIn<N> {
    /// The face whose light this group's glossy share is: the pair's
    /// sender, or `shot`'s for a link refined now.
    pub fn send_face(&self, shot: FaceId) -> FaceId {
        match self {
            GlossyIn::Flush { face, .. } => *face,
            _ => shot,
        }
    }

    /// The pair link whose glossy share is refined in this shot (δL zero
    /// while it waits), and the scale its node links take: the shot's
    /// for its own light, 1 for a sum (its links were scaled as they
    /// arrived).
    pub fn link(&self, own: &PairLink<N>, shot_scale: Spectrum<N>) -> (PairLink<N>, Spectrum<N>) {
        match self {
            GlossyIn::Now => (own.clone(), shot_scale),
            GlossyIn::Wait { .. } => (
                PairLink {
                    unshot: Spectrum::zero(),
                    ..own.clone()
                },
                Spectrum::zero(),
            ),
            GlossyIn::Flush { unshot, .. } => (
                PairLink {
                    unshot: *unshot,
                    ..own.clone()
                },
                Spectrum::splat(1.0),
            ),
        }
    }
}

impl<const N: usize> Deferred<N> {
    /// One link that may wait (`Solver::plan_glossy` decides which): adds
    /// it to its pair's sum, released when it reaches `threshold`.
    pub fn wait_or_release(
        &mut self,
        l: &PairLink<N>,
        send_face: FaceId,
        threshold: f64,
        (shot_scale, share): (Spectrum<N>, Spectrum<N>),
    ) -> GlossyIn<N> {
        let from = send_face.of(l.i);
        let own = l.unshot * shot_scale * l.t;
        let mut slot = match self.faces[l.face].entry(from.key()) {
            Entry::Occupied(o) => o,
            Entry::Vacant(v) => v.insert_entry(Pending {
                face: send_face,
                from,
                sum: Spectrum::zero(),
                reflected: Spectrum::zero(),
                t: l.t,
                room: Spectrum::zero(),
            }),
        };
        let pending = slot.get_mut();
        pending.sum += own;
        pending.reflected += own * share;
        pending.t = l.t;
        if std::f64::consts::PI * pending.sum.sum() < threshold {
            return GlossyIn::Wait { from };
        }
        let p = slot.remove();
        self.room[l.face] -= p.room;
        released(p)
    }

    /// Everything waiting at `face` (whose root element is `j`), as pair
    /// links that carry no new light (their own δL zero) and release their
    /// sums: the groups of the source `Source::Deferred`.
    pub fn take(&mut self, face: FaceId, j: ElementId) -> (Vec<PairLink<N>>, Vec<GlossyIn<N>>) {
        let waiting = std::mem::take(&mut self.faces[face]);
        self.room[face] = Spectrum::zero();
        let mut pending: Vec<Pending<N>> = waiting.into_values().collect();
        // A fixed order (the map's is not): solves repeat exactly.
        pending.sort_by_key(|p| p.from.key());
        pending
            .into_iter()
            .map(|p| {
                let link = PairLink {
                    i: p.from.element,
                    j,
                    face,
                    t: p.t,
                    unshot: Spectrum::zero(),
                };
                (link, released(p))
            })
            .unzip()
    }

    /// Books the flux a waiting link adds at its face (what arrived less
    /// its Lambertian share): it stays in the residual until released.
    pub fn book_waiting(&mut self, face: FaceId, from: FaceElement, room: Spectrum<N>) {
        if let Some(p) = self.faces[face].get_mut(&from.key()) {
            p.room += room;
            self.room[face] += room;
        }
    }

    /// The faces where light waits.
    pub fn waiting_faces(&self) -> Vec<FaceId> {
        self.faces
            .iter()
            .filter(|(_, m)| !m.is_empty())
            .map(|(f, _)| f)
            .collect()
    }
}

/// A pair's sum released: the radiance of one link carrying it.
fn released<const N: usize>(p: Pending<N>) -> GlossyIn<N> {
    let unshot = if p.t > 0.0 {
        p.sum * (1.0 / p.t)
    } else {
        Spectrum::zero()
    };
    let share = Spectrum::new(std::array::from_fn(|b| {
        if p.sum[b] > 0.0 {
            (p.reflected[b] / p.sum[b]).clamp(0.0, 1.0)
        } else {
            0.0
        }
    }));
    GlossyIn::Flush {
        face: p.face,
        unshot,
        share,
        waited: p.room,
    }
}
