//! A shot's receiving faces in batches (docs/solver.md, "One shot"): a
//! shot's node links live until their groups are received, so its glossy
//! reception runs batch by batch and holds one batch's links at once.

use std::ops::Range;

use trilux_geometry::PerFace;

use crate::link::PairLink;
use crate::refine::Incidence;

/// The most stored hierarchies that one batch of a shot's stage 2 reaches
/// (more only when one face alone has more). A shot's node links live
/// until their groups are received, so a shot refines its receiving faces
/// in batches and receives each batch before the next: its links in
/// memory are one batch's, not the shot's (a light's first shot into a
/// large glossy interior made 81 million at once).
pub(crate) const BATCH_HIERARCHIES: usize = 16_384;

/// A shot's groups in batches of whole receiving faces, each reaching at
/// least `limit` ([`BATCH_HIERARCHIES`]) stored hierarchies but the last.
/// A group's node links all lie in its face's hierarchies, so a group is
/// received whole within its batch; a face's groups stay together so that
/// each hierarchy is refined once a shot, with the sub-pair incidences its
/// face's groups share. Most shots reach few hierarchies: counted once per
/// group (over-counting each face), under the limit they are one batch in
/// their own order, without sorting.
pub(crate) fn batches<const N: usize>(
    limit: usize,
    stored_from: &PerFace<Range<usize>>,
    links: &[PairLink<N>],
    incidences: &[Option<Incidence<N>>],
) -> Vec<Vec<u32>> {
    let refined = |g: u32| incidences[g as usize].is_some();
    let face = |g: u32| links[g as usize].face;
    let all = 0..links.len() as u32;
    let bound: usize = all
        .clone()
        .filter(|&g| refined(g))
        .map(|g| stored_from[face(g)].len())
        .sum();
    if bound < limit {
        return vec![all.collect()];
    }
    let mut order: Vec<u32> = all.collect();
    order.sort_by_key(|&g| face(g));
    let (mut out, mut batch, mut reached) = (Vec::new(), Vec::new(), 0);
    for run in order.chunk_by(|&a, &b| face(a) == face(b)) {
        batch.extend_from_slice(run);
        if run.iter().any(|&g| refined(g)) {
            reached += stored_from[face(run[0])].len();
        }
        if reached >= limit {
            out.push(std::mem::take(&mut batch));
            reached = 0;
        }
    }
    if !batch.is_empty() {
        out.push(batch);
    }
    out
}
