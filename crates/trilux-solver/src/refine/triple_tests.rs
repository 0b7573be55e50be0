//! The stage-2 oracle against answers that follow from its definition:
//! the photometric criterion, refinement down to the depth limit, and
//! which element a link that is not accurate splits.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests may panic

use glam::DVec3;

use std::f64::consts::PI;

use trilux_brdf::area::Element as Driver;
use trilux_color::Spectrum;
use trilux_geometry::ElementId;

use super::RefineContext;
use super::incidences::IncidenceMemo;
use super::triple::{Incidence, MAX_SAMPLED_GAIN, TripleErrors, TripleTask};
use crate::interaction::{Hierarchy, Split};
use crate::link::Sent;
use crate::link::{NodeLink, Sender};
use crate::setup::Setup;
use crate::state::ShotState;
use crate::test_scenes as ts;
use crate::throughput::ThroughputCache;

/// An emitter E (surface 0) facing down at (−1, 0, 1), a glossy floor
/// R (surface 1, side `floor`) at the origin facing up, and a grey
/// plate K (surface 2, side `plate`) facing down at (1, 0, 1), in R's
/// mirror direction from E.
pub(super) fn mirror_scene(
    floor: f64,
    plate: f64,
    depth: u32,
    eps: f64,
) -> (Setup<3>, ShotState<3>) {
    let shapes = [
        ts::square(DVec3::new(-1.0, 0.0, 1.0), 1.0, true),
        ts::square(DVec3::ZERO, floor, false),
        ts::square(DVec3::new(1.0, 0.0, 1.0), plate, true),
    ];
    let mut settings = ts::settings(depth);
    settings.ff_eps = eps;
    settings.fr_eps = eps;
    let setup = ts::setup(
        &shapes,
        &[ts::diffuse(0.0), ts::glossy(0.3), ts::diffuse(0.5)],
        &[Some(1.0), None, None],
        settings,
    );
    let state = ShotState::new(&setup);
    (setup, state)
}

/// Runs `f` with the stage-2 task of E's shot into hierarchy R → K
/// (photometric threshold `threshold`), the incidence of the root pair
/// (E, R) and the context; returns the hierarchy and the links made.
fn with_task(
    setup: &Setup<3>,
    state: &mut ShotState<3>,
    threshold: f64,
    f: impl FnOnce(&RefineContext<'_, 3>, &mut TripleTask<'_, 3>, &Incidence<3>),
) -> (Hierarchy<3>, Vec<NodeLink<3>>) {
    let cache = ThroughputCache::new(1 << 16);
    let mut ctx = setup.refine_context(&cache);
    ctx.flux_threshold = threshold;
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
    let incidence = ctx
        .incidence(&sender, ts::root(ctx.forest, e), ts::root(ctx.forest, r))
        .expect("light passes from E to R");
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
    f(&ctx, &mut task, &incidence);
    let out = std::mem::take(&mut task.out);
    (h, out)
}

/// The root elements of E and R.
fn roots(setup: &Setup<3>) -> (ElementId, ElementId) {
    let forest = setup.forest();
    (
        forest.root(ts::front(0).surface()),
        forest.root(ts::front(1).surface()),
    )
}

/// A link whose flux on towards K is below the threshold (here every
/// link's) is made at the root node, and the hierarchy does not grow.
#[test]
fn a_link_below_the_photometric_threshold_is_not_refined() {
    let (setup, mut state) = mirror_scene(1.0, 1.0, 2, 0.01);
    let (i, j) = roots(&setup);
    let (h, links) = with_task(&setup, &mut state, f64::INFINITY, |ctx, task, inc| {
        ctx.refine_triple(task, i, j, 0, Some(inc));
    });
    assert_eq!(links.len(), 1);
    assert_eq!(links[0].node, 0);
    assert!(!links[0].gathered.is_black(), "light reflects towards K");
    assert_eq!(h.nodes.len(), 1, "the hierarchy did not grow");
}

/// An element of K straddling j's plane is refined across it only when
/// the pair link's whole flux π T_ij δL_i reaches the photometric
/// threshold: below it (every shot late in a solve) the hierarchy does
/// not grow and no link is made (the group's renormalisation makes
/// up); with no threshold, K splits.
#[test]
fn a_pair_below_the_threshold_is_not_refined_across_the_plane() {
    let (setup, _) = mirror_scene(1.0, 1.0, 2, 0.01);
    let (i, j) = roots(&setup);
    for (threshold, grows) in [(f64::INFINITY, false), (0.0, true)] {
        let mut state = ShotState::new(&setup);
        let (h, links) = with_task(&setup, &mut state, threshold, |ctx, task, inc| {
            let flux = PI * inc.tij.t * inc.unshot.sum();
            assert!(flux > 0.0 && (threshold == 0.0 || flux < threshold));
            ctx.split_across_plane(task, i, j, 0, inc, true);
        });
        assert_eq!(h.nodes.len() > 1, grows, "threshold {threshold}");
        if !grows {
            assert!(links.is_empty(), "threshold {threshold}");
        }
    }
}

/// With no photometric threshold and (nearly) zero error bounds,
/// nothing is accurate enough: every link ends on a node joining two
/// leaves of R and K at the depth limit, and a leaf node receives at
/// most one link from each of E's leaves.
#[test]
fn a_link_above_the_threshold_is_refined_to_the_depth_limit() {
    let depth = 1;
    let (setup, mut state) = mirror_scene(1.0, 1.0, depth, 1e-12);
    let (i, j) = roots(&setup);
    let (h, links) = with_task(&setup, &mut state, 0.0, |ctx, task, inc| {
        ctx.refine_triple(task, i, j, 0, Some(inc));
    });
    let forest = setup.forest();
    assert!(!links.is_empty());
    let mut per_node = std::collections::HashMap::new();
    for l in &links {
        let node = &h.nodes[l.node as usize];
        assert_eq!(node.split, Split::None, "a leaf node");
        for e in [node.from, node.to] {
            assert!(forest.element(e).children().is_none());
            assert_eq!(forest.element(e).depth, depth);
        }
        *per_node.entry(l.node).or_insert(0) += 1;
    }
    let sender_leaves = 4usize.pow(depth);
    assert!(per_node.values().all(|&c| c <= sender_leaves));
}

/// A link that is not accurate splits (docs/solver.md, "Refinement",
/// stage 2): the BRDF's driver when the BRDF error dominates, otherwise
/// the larger of J and K; an accurate link is made as it is. Split I
/// is virtual (the hierarchy keeps its node, four sender sub-pairs link
/// to it); splits J and K split the node on its sender or receiver.
#[test]
fn a_link_splits_the_element_its_errors_point_to() {
    // (floor side, plate side, errors (BRDF, FF), driver, expected)
    let cases = [
        (1.0, 1.0, (0.5, 0.5), Driver::K, None),
        (1.0, 1.0, (5.0, 0.0), Driver::K, Some(Split::To)),
        (1.0, 1.0, (5.0, 0.0), Driver::J, Some(Split::From)),
        (1.0, 1.0, (5.0, 0.0), Driver::I, Some(Split::None)),
        (1.0, 2.0, (0.0, 5.0), Driver::I, Some(Split::To)),
        (2.0, 1.0, (0.0, 5.0), Driver::I, Some(Split::From)),
    ];
    for (floor, plate, (brdf, ff), driver, expected) in cases {
        let (setup, mut state) = mirror_scene(floor, plate, 2, 0.01);
        let (i, j) = roots(&setup);
        let errors = TripleErrors {
            brdf,
            ff,
            partial: false,
            driver,
        };
        let link = NodeLink {
            node: 0,
            group: 0,
            gathered: Spectrum::splat(1.0),
            sampled: false,
        };
        let made = link.clone();
        let (h, links) = with_task(&setup, &mut state, f64::INFINITY, |ctx, task, inc| {
            assert!(!inc.straddle_i);
            ctx.link_or_split(task, (i, j, 0), inc, made, errors);
        });
        let case = format!("{floor} {plate} {brdf} {ff} {driver:?}");
        match expected {
            None => {
                assert_eq!(links.len(), 1, "{case}");
                assert_eq!(links[0].gathered, link.gathered, "{case}");
                assert_eq!(h.nodes.len(), 1, "{case}");
            }
            Some(Split::None) => {
                assert_eq!(h.nodes.len(), 1, "{case}");
                assert_eq!(links.len(), 4, "{case}");
                assert!(links.iter().all(|l| l.node == 0), "{case}");
            }
            Some(side) => {
                assert_eq!(h.nodes[0].split, side, "{case}");
                assert!(!links.is_empty(), "{case}");
                assert!(links.iter().all(|l| l.node != 0), "{case}");
            }
        }
    }
}

/// A sampled link (docs/solver.md, "Narrow lobes") adds at most 4 times
/// the sender's δL to its node's radiance, whatever T_jk: its
/// expectation is at most δL (∫ fr cos dω ≤ 1), and 4 leaves room for
/// the sampled ratio's fluctuations. Here T_jk is set a billion times
/// below T_ij (as a point-sampled T_jk of surfaces in contact can come
/// out) with half the lobe landing in K: δL · S_K · T_ij / T_jk would
/// be 5·10⁸ δL.
#[test]
fn a_sampled_link_is_bounded_by_the_light_that_arrives() {
    let (setup, mut state) = mirror_scene(1.0, 1.0, 2, 0.01);
    let (i, j) = roots(&setup);
    let mut unshot = Spectrum::zero();
    let (_, links) = with_task(&setup, &mut state, f64::INFINITY, |ctx, task, inc| {
        unshot = inc.unshot;
        task.h.nodes[0].t = 1e-9 * inc.tij.t;
        ctx.link_sampled(task, (i, j, 0), inc, (Spectrum::splat(0.5), &[]), false);
    });
    assert_eq!(links.len(), 1);
    for b in 0..3 {
        let got = links[0].gathered[b];
        assert!(
            got > 0.0 && got <= MAX_SAMPLED_GAIN * unshot[b] * (1.0 + 1e-12),
            "band {b}: {got} against δL {}",
            unshot[b]
        );
    }
}
