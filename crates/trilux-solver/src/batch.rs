//! A shot's receiving faces in batches (docs/solver.md, "One shot"): a
//! shot's node links live until their groups are received, so its glossy
//! reception runs batch by batch and holds one batch's links at once.

use std::collections::HashMap;
use std::ops::Range;

use trilux_geometry::{FaceId, PerFace};

use crate::link::PairLink;
use crate::refine::Incidence;

/// The most stored hierarchies that one batch of a shot's stage 2 reaches
/// (more only when one face alone has more). A shot's node links live
/// until their groups are received, so a shot refines its receiving faces
/// in batches and receives each batch before the next: its links in
/// memory are one batch's, not the shot's (a light's first shot into a
/// large glossy interior made 81 million at once).
pub(crate) const BATCH_HIERARCHIES: usize = 16_384;

/// A shot's groups in batches of whole receiving faces, in order of first
/// appearance, each reaching at least `limit` ([`BATCH_HIERARCHIES`])
/// stored hierarchies but the last. A group's node links all lie in its
/// face's hierarchies, so a group is received whole within its batch; a
/// face's groups stay together so that each hierarchy is refined once a
/// shot, with the sub-pair incidences its face's groups share.
pub(crate) fn batches<const N: usize>(
    limit: usize,
    stored_from: &PerFace<Range<usize>>,
    links: &[PairLink<N>],
    incidences: &[Option<Incidence<N>>],
) -> Vec<Vec<u32>> {
    let mut faces: Vec<(FaceId, Vec<u32>, bool)> = Vec::new();
    let mut slot: HashMap<FaceId, usize> = HashMap::new();
    for (g, (l, inc)) in links.iter().zip(incidences).enumerate() {
        let k = *slot.entry(l.face).or_insert_with(|| {
            faces.push((l.face, Vec::new(), false));
            faces.len() - 1
        });
        faces[k].1.push(g as u32);
        faces[k].2 |= inc.is_some();
    }
    let (mut out, mut batch, mut reached) = (Vec::new(), Vec::new(), 0);
    for (face, groups, refined) in faces {
        batch.extend(groups);
        reached += if refined { stored_from[face].len() } else { 0 };
        if reached >= limit {
            out.push(std::mem::take(&mut batch));
            reached = 0;
        }
    }
    if !batch.is_empty() || out.is_empty() {
        out.push(batch);
    }
    out
}
