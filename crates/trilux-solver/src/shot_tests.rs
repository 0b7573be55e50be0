//! Tests of one shot (`shot`): a shot that starts after the solve's
//! deadline (a budget of zero, shot by hand: the loop itself would not
//! start it) still carries its source's light, coarser; a shot received
//! in batches delivers what one batch does.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests may panic

use std::f64::consts::PI;

use glam::DVec3;
use trilux_brdf::BsdfParams;
use trilux_color::ColorParam;

use crate::prepared::SceneDescription;
use crate::solver::Solver;
use crate::test_scenes as ts;

/// A scene of unit squares: an emitter (Le = 1) facing down at height 1
/// over `receivers` (centre, facing down, material), prepared with
/// `settings`.
fn under_emitter(
    receivers: &[(DVec3, bool, BsdfParams)],
    settings: crate::settings::SolverSettings,
) -> Solver<3> {
    let mut shapes = vec![ts::square(DVec3::new(0.0, 0.0, 1.0), 1.0, true)];
    let mut bsdfs = vec![ts::diffuse(0.0)];
    let mut emission = vec![Some(ColorParam::Float(1.0))];
    for (centre, down, bsdf) in receivers {
        shapes.push(ts::square(*centre, 1.0, *down));
        bsdfs.push(bsdf.clone());
        emission.push(None);
    }
    let desc = SceneDescription {
        shapes: &shapes,
        bsdfs: &bsdfs,
        emission: &emission,
    };
    Solver::from_description(&desc, settings).unwrap()
}

/// The first shot of [`under_emitter`]'s scene, with time budget
/// `budget`.
fn first_shot(budget: Option<f64>, receivers: &[(DVec3, bool, BsdfParams)]) -> Solver<3> {
    let mut settings = ts::settings(3);
    settings.time_budget_seconds = budget;
    let mut solver = under_emitter(receivers, settings);
    let source = solver.next_source().unwrap();
    solver.shoot(source);
    solver
}

/// A shot's receiving faces refined and received in batches (one
/// glossy face each here) deliver what one batch of them all does:
/// nothing a batch computes may depend on another batch (a reception
/// reset per batch fails here, in the ledger).
/// Three glossy floor tiles under the emitter reflect towards two grey
/// plates beside it; after six shots the residual, the ledger, every
/// hierarchy's unshot flux and every element's gathered radiance agree
/// to rounding (the sums run in another order: 1e-9 relative).
#[test]
fn a_shot_in_batches_delivers_what_one_batch_does() {
    let run = |limit: usize| {
        let plates = [-1.5, 1.5].map(|x| (DVec3::new(x, 0.0, 1.0), true, ts::diffuse(0.5)));
        let tiles = [-1.0, 0.0, 1.0].map(|x| (DVec3::new(x, 0.0, 0.0), false, ts::glossy(0.3)));
        let receivers: Vec<_> = plates.into_iter().chain(tiles).collect();
        let mut solver = under_emitter(&receivers, ts::settings(2));
        solver.batch_hierarchies = limit;
        for s in 3..6 {
            assert!(!solver.setup.stored_from[ts::front(s)].is_empty());
        }
        for _ in 0..6 {
            let source = solver.next_source().unwrap();
            solver.shoot(source);
        }
        assert_ledger(&solver);
        let mut values: Vec<f64> = solver.residual().0.to_vec();
        values.extend(solver.state.ledger.absorbed.iter().copied());
        for h in solver.state.hierarchies.iter().flatten() {
            values.extend(h.unshot_flux.0);
        }
        let gathered = &solver.state.field.gathered;
        for side in [&gathered.front, &gathered.back] {
            values.extend(side.iter().flat_map(|l| l.0));
        }
        values
    };
    let (one, many) = (run(usize::MAX), run(1));
    assert_eq!(one.len(), many.len());
    assert!(one.iter().any(|&v| v > 0.0));
    for (a, b) in one.iter().zip(&many) {
        assert!((a - b).abs() <= 1e-9 * a.abs().max(1e-12), "{a} {b}");
    }
}

/// Energy is booked whole and no term is negative (docs/solver.md,
/// "Energy ledger"); what is unshot is finite and non-negative.
fn assert_ledger(s: &Solver<3>) {
    let (ledger, residual) = (&s.state.ledger, s.residual());
    for b in 0..3 {
        let sum = ledger.absorbed[b] + ledger.escaped[b] + residual[b];
        assert!((sum - ledger.emitted[b]).abs() <= 1e-9 * ledger.emitted[b]);
    }
    assert!(residual.is_finite() && residual.is_non_negative());
    assert!(
        ledger.min_shot_escaped >= -1e-9,
        "{}",
        ledger.min_shot_escaped
    );
    assert!(ledger.min_element_absorbed >= -1e-9);
}

/// A grey plate (ρ = 0.5) under the emitter, both unit squares at
/// distance 1 (A F = 0.199825, docs/validation.md, closed form (a)):
/// the first shot leaves ρ π A F Le = 0.3139 W per band to shoot on,
/// however fine its links, since the T of a pair is the sum of its
/// sub-pairs' (within the form factors' cubature error: 1 % at the
/// root, 2 % summed over leaves, `refine::pair::tests`). After the
/// deadline the shot makes one root link and counts it late; without
/// a budget it refines and counts nothing.
#[test]
fn a_shot_after_the_deadline_carries_the_same_light_coarser() {
    let plate = [(DVec3::ZERO, false, ts::diffuse(0.5))];
    let expected = 0.5 * PI * 0.199825;
    let free = first_shot(None, &plate);
    let late = first_shot(Some(0.0), &plate);
    assert_eq!(free.state.stats.late_links, 0);
    assert!(free.state.stats.links_total > 1);
    assert!(late.state.stats.late_links > 0);
    assert_eq!(late.state.stats.links_total, 1, "one root link");
    for s in [&free, &late] {
        assert_ledger(s);
        let r = s.residual();
        for b in 0..3 {
            assert!((r[b] - expected).abs() < 0.02 * expected, "{}", r[b]);
        }
    }
}

/// A glossy floor (GGX α 0.3) under the emitter and a grey plate over
/// it beside the emitter: after the deadline stage 2 links the
/// floor's hierarchy where it stands, and the light the floor reflects
/// towards the plate is still carried (positive, finite, within what
/// arrived).
#[test]
fn a_glossy_receiver_after_the_deadline_still_reflects() {
    let scene = [
        (DVec3::new(0.5, 0.0, 0.0), false, ts::glossy(0.3)),
        (DVec3::new(1.5, 0.0, 1.0), true, ts::diffuse(0.5)),
    ];
    for budget in [None, Some(0.0)] {
        let s = first_shot(budget, &scene);
        assert_eq!(s.state.stats.late_links > 0, budget.is_some());
        assert_eq!(s.state.stats.late_groups > 0, budget.is_some());
        assert_ledger(&s);
        let glossy: f64 = s
            .state
            .hierarchies
            .iter()
            .flatten()
            .map(|h| h.unshot_flux.sum())
            .sum();
        assert!(glossy > 0.0 && glossy.is_finite(), "{glossy}");
        // At most the emitter's flux arrives on the floor.
        assert!(glossy <= 3.0 * PI, "{glossy}");
    }
}

/// Past the deadline a glossy face's hemisphere coverage is its
/// root's, summed from the root throughputs its hierarchies hold, for
/// any element j: the same form factors as the root coverage made
/// afresh, the visibility from other shadow rays (hundreds per root
/// pair, nearly all unblocked here: within 1 %).
#[test]
fn the_late_coverage_is_the_roots_from_the_stored_throughputs() {
    let scene = [
        (DVec3::new(0.5, 0.0, 0.0), false, ts::glossy(0.3)),
        (DVec3::new(1.5, 0.0, 1.0), true, ts::diffuse(0.5)),
    ];
    let s = first_shot(None, &scene);
    let floor = ts::front(1);
    let root = s.setup.forest().root(floor.surface());
    let leaf = *ts::leaves(s.setup.forest(), root).last().unwrap();
    assert!(
        s.state
            .hierarchies
            .iter()
            .flatten()
            .any(|h| h.from == floor && !h.pending)
    );
    let fresh = s.hemisphere_coverage(floor, root, false);
    s.state.coverage.lock().unwrap().clear();
    let late = s.hemisphere_coverage(floor, leaf, true);
    assert!(fresh > 0.0 && fresh < 1.0, "{fresh}");
    assert!((late - fresh).abs() <= 0.01 * fresh, "{late} {fresh}");
    // Not j's own: the leaf's coverage made afresh differs.
    s.state.coverage.lock().unwrap().clear();
    let own = s.hemisphere_coverage(floor, leaf, false);
    assert!((own - fresh).abs() > 0.05 * fresh, "{own} {fresh}");
}
