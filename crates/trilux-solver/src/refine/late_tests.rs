//! Stage 2 after the solve's deadline (docs/solver.md, "The deadline
//! inside a shot") and for a faint glossy share ("Faint glossy shares"):
//! a three-point link is linked where it stands, and a stored hierarchy is
//! not split down to a pair link's receiver. Answers from the definition:
//! the link made is the one the photometric criterion makes.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests may panic

use std::sync::atomic::Ordering;
use std::time::Instant;

use trilux_color::Spectrum;

use super::{IncidenceMemo, RefineContext, TripleTask};
use crate::interaction::{Hierarchy, Split};
use crate::link::{NodeLink, Sender, Sent};
use crate::setup::Setup;
use crate::state::ShotState;
use crate::test_scenes as ts;
use crate::throughput::ThroughputCache;

/// The triple tests' scene (an emitter E, a glossy floor R, a grey plate
/// K in R's mirror direction from E) with every error bound (nearly) zero,
/// so that only the photometric criterion or the deadline stops
/// refinement.
fn mirror_scene() -> (Setup<3>, ShotState<3>) {
    super::triple_tests::mirror_scene(1.0, 1.0, 2, 1e-12)
}

/// E's shot into hierarchy R → K with photometric threshold `threshold`
/// and `deadline`: runs `f` with the context, the task and R's root, and
/// returns the hierarchy, the links and the count of late links.
fn stage_two(
    threshold: f64,
    deadline: Option<Instant>,
    f: impl FnOnce(&RefineContext<'_, 3>, &mut TripleTask<'_, 3>),
) -> (Hierarchy<3>, Vec<NodeLink<3>>, u64) {
    let (setup, mut state) = mirror_scene();
    let cache = ThroughputCache::new(1 << 16);
    let mut ctx = setup.refine_context(&cache);
    ctx.flux_threshold = threshold;
    ctx.deadline = deadline;
    let (e, r, k) = (ts::front(0), ts::front(1), ts::front(2));
    let h_index = state
        .hierarchies
        .iter()
        .position(|h| h.as_ref().is_some_and(|h| (h.from, h.to) == (r, k)))
        .expect("R stores an interaction towards K");
    let mut h = state.hierarchies[h_index].take().unwrap();
    ctx.make_root(&mut h);
    let sender = Sender::Radiosity {
        field: &state.field,
        side: e.side(),
        sent: Sent::Unshot,
        emission: Spectrum::zero(),
    };
    let memo = IncidenceMemo::new();
    let mut task = TripleTask {
        sender: &sender,
        si: e,
        h: &mut h,
        group: 0,
        lost: Spectrum::zero(),
        out: Vec::new(),
        memo: &memo,
        local: Default::default(),
    };
    f(&ctx, &mut task);
    let out = std::mem::take(&mut task.out);
    let late = ctx.late.links.load(Ordering::Relaxed);
    (h, out, late)
}

/// The roots of E and R.
fn roots() -> (trilux_geometry::ElementId, trilux_geometry::ElementId) {
    let (setup, _) = mirror_scene();
    let forest = setup.forest();
    (
        forest.root(ts::front(0).surface()),
        forest.root(ts::front(1).surface()),
    )
}

/// With no threshold and zero error bounds a link is refined to the depth
/// limit; after the deadline it is made at the root node as it stands,
/// the very link an infinite threshold makes, and the hierarchy does not
/// grow.
#[test]
fn a_three_point_link_reached_after_the_deadline_is_linked_where_it_stands() {
    let (i, j) = roots();
    let root_link = |threshold, deadline| {
        stage_two(threshold, deadline, |ctx, task| {
            let inc = ctx
                .incidence(task.sender, task.si.of(i), task.h.from.of(j))
                .expect("light passes from E to R");
            ctx.refine_triple(task, i, j, 0, Some(&inc));
        })
    };
    let (h, photometric, late) = root_link(f64::INFINITY, None);
    assert_eq!((h.nodes.len(), photometric.len(), late), (1, 1, 0));
    let (h, links, late) = root_link(0.0, Some(Instant::now()));
    assert_eq!(h.nodes.len(), 1, "the hierarchy did not grow");
    assert_eq!(late, 1);
    assert_eq!(links.len(), 1);
    assert_eq!(links[0].node, 0);
    assert_eq!(links[0].gathered, photometric[0].gathered);
    assert!(!links[0].gathered.is_black(), "light reflects towards K");
    let (h, links, late) = root_link(0.0, None);
    assert!(h.nodes.len() > 1 && links.len() > 1, "refined without one");
    assert_eq!(late, 0);
}

/// A pair link into a leaf j of R: before the deadline the hierarchy is
/// split on its sender side down to j; after it, the root node is
/// returned as it stands (its sender element R's root, above j).
#[test]
fn after_the_deadline_a_hierarchy_is_not_split_down_to_the_receiver() {
    let (_, root) = roots();
    let (setup, _) = mirror_scene();
    let leaf = *ts::leaves(setup.forest(), root).first().unwrap();
    assert_eq!(setup.forest().element(leaf).depth, 2);
    let nodes = |deadline| {
        let mut found = Vec::new();
        let (h, _, late) = stage_two(0.0, deadline, |ctx, task| {
            ctx.nodes_for(task.h, (leaf, false), &mut task.lost, &mut found);
        });
        let from: Vec<_> = found.iter().map(|&n| h.nodes[n as usize].from).collect();
        (h, found, from, late)
    };
    let (h, found, from, late) = nodes(None);
    assert!(h.nodes.len() > 1 && h.nodes[0].split == Split::From);
    assert!(!found.is_empty() && from.iter().all(|&f| f == leaf));
    assert_eq!(late, 0);
    let (h, found, from, late) = nodes(Some(Instant::now()));
    assert_eq!(
        (h.nodes.len(), found, from, late),
        (1, vec![0], vec![root], 1)
    );
}

/// A root throughput made after the deadline takes the base rays, not
/// ×16: with nothing in the way (visibility exactly 1 either way) it is
/// the full root's T, from the same form factor; it is counted.
#[test]
fn a_root_made_after_the_deadline_takes_the_base_rays() {
    let (setup, state) = mirror_scene();
    let cache = ThroughputCache::new(1 << 16);
    let (r, k) = (ts::front(1), ts::front(2));
    let pending = state
        .hierarchies
        .iter()
        .flatten()
        .find(|h| (h.from, h.to) == (r, k))
        .expect("R stores an interaction towards K");
    assert!(pending.pending);
    let root = |deadline| {
        let mut ctx = setup.refine_context(&cache);
        ctx.deadline = deadline;
        let mut h = pending.clone();
        ctx.make_root(&mut h);
        (h.nodes[0].t, ctx.late.roots.load(Ordering::Relaxed))
    };
    let (full, early) = root(None);
    let (cheap, late) = root(Some(Instant::now()));
    assert_eq!((early, late), (0, 1));
    assert!(full > 0.0 && full.is_finite());
    assert_eq!(cheap, full);
}

/// A faint pair (its glossy share below the photometric threshold) finds
/// the stored root node as it stands, as after the deadline, but counts
/// no late link; the same pair not faint splits R's hierarchy down to j.
#[test]
fn a_faint_glossy_share_is_received_at_the_stored_nodes() {
    let (_, root) = roots();
    let (setup, _) = mirror_scene();
    let leaf = *ts::leaves(setup.forest(), root).first().unwrap();
    let nodes = |coarse| {
        let mut found = Vec::new();
        let (h, _, late) = stage_two(0.0, None, |ctx, task| {
            ctx.nodes_for(task.h, (leaf, coarse), &mut task.lost, &mut found);
        });
        let from: Vec<_> = found.iter().map(|&n| h.nodes[n as usize].from).collect();
        (h.nodes.len(), found, from, late)
    };
    assert_eq!(nodes(true), (1, vec![0], vec![root], 0));
    let (grown, _, from, late) = nodes(false);
    assert!(grown > 1 && from.iter().all(|&f| f == leaf) && late == 0);
}

/// The bound that makes a pair faint bounds what its three-point links
/// carry: E's root pair into the glossy floor R, refined towards the plate
/// K with every error bound nearly zero (down to the depth limit, where
/// the midpoint rule is close to the integral), sends on to K at most
/// π T_ER (δL · ρ_g): K is one part of the hemisphere ρ_g integrates over.
#[test]
fn the_faint_bound_bounds_what_the_pairs_links_carry() {
    let (i, j) = roots();
    let mut bound = 0.0;
    let (h, links, _) = stage_two(0.0, None, |ctx, task| {
        let inc = ctx
            .incidence(task.sender, task.si.of(i), task.h.from.of(j))
            .expect("light passes from E to R");
        bound = ctx.glossy_flux_bound(task.h.from, &inc).unwrap();
        ctx.refine_triple(task, i, j, 0, Some(&inc));
    });
    let carried: f64 = links
        .iter()
        .map(|l| std::f64::consts::PI * h.nodes[l.node as usize].t * l.gathered.sum())
        .sum();
    assert!(h.nodes.len() > 1, "refined");
    assert!(carried > 0.0 && bound.is_finite());
    assert!(carried <= bound, "links carry {carried}, bound {bound}");
}
