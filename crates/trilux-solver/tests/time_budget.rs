//! The solve's stopping rules (docs/solver.md, "Stopping"): a time budget
//! returns the best solution so far and says so, a generous one changes
//! nothing, and the convergence trace never goes backwards. No test here
//! times anything: a budget of zero must stop before the first shot, one of
//! a year must never stop a solve of two plates.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test, bench or example may panic

use std::f64::consts::PI;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use glam::{DMat4, DVec3};
use trilux_brdf::BsdfParams;
use trilux_color::ColorParam;
use trilux_geometry::{Shape, ShapeKind};
use trilux_solver::{
    Quality, SceneDescription, Solution, Solver, SolverError, SolverSettings, StopReason,
};

/// A unit square centred at `centre`, facing down (−z) or up (+z).
fn square(centre: DVec3, down: bool) -> Shape {
    let rot = if down {
        DMat4::from_rotation_x(PI)
    } else {
        DMat4::IDENTITY
    };
    Shape {
        kind: ShapeKind::Rectangle,
        world_from_object: DMat4::from_translation(centre)
            * rot
            * DMat4::from_scale(DVec3::splat(0.5)),
        flip_normals: false,
    }
}

fn diffuse(r: f64) -> BsdfParams {
    BsdfParams::Diffuse {
        reflectance: ColorParam::Float(r),
    }
}

/// Two facing plates that both reflect: light bounces between them, so the
/// solve takes many shots to reach its target.
fn solver(budget: Option<f64>) -> Result<Solver<3>, SolverError> {
    let shapes = vec![
        square(DVec3::new(0.0, 0.0, 0.5), true),
        square(DVec3::ZERO, false),
    ];
    let bsdfs = vec![diffuse(0.6), diffuse(0.8)];
    let emission = vec![Some(ColorParam::Float(1.0)), None];
    let input = SceneDescription {
        shapes: &shapes,
        bsdfs: &bsdfs,
        emission: &emission,
    };
    let mut settings = SolverSettings::preset(Quality::Draft);
    settings.convergence = 0.999;
    settings.time_budget_seconds = budget;
    Solver::<3>::from_description(&input, settings)
}

fn solve(budget: Option<f64>) -> Result<Solution<3>, SolverError> {
    Ok(solver(budget)?.solve(|_| {}))
}

#[test]
fn a_stop_flag_ends_the_loop_after_the_shot_that_set_it_with_a_partial_solution() {
    let flag = Arc::new(AtomicBool::new(false));
    let setter = Arc::clone(&flag);
    let s = solver(None)
        .unwrap()
        .stop_when(flag)
        .solve(|p| setter.store(p.shots == 3, Ordering::Relaxed));
    let stats = s.stats();
    // The flag is read between shots: set after shot 3, no shot 4.
    assert_eq!(stats.shots, 3);
    assert_eq!(stats.stop_reason, StopReason::Interrupted);
    assert!(stats.convergence_ratio > 0.0 && stats.convergence_ratio < 0.999);
    let partial: Vec<_> = stats
        .warnings
        .iter()
        .filter(|w| w.contains("partial"))
        .collect();
    assert_eq!(partial.len(), 1, "{:?}", stats.warnings);
    // The last trace point is where it stopped.
    let last = stats.convergence_trace.last().unwrap();
    assert_eq!(last.shots, 3);
    // Energy is still accounted for: emitted = absorbed + escaped + unshot.
    for b in 0..3 {
        let sum = stats.absorbed_flux[b] + stats.escaped_flux[b] + stats.residual_flux[b];
        assert!((sum - stats.emitted_flux[b]).abs() <= 1e-9 * stats.emitted_flux[b]);
    }
    // A flag set before the first shot stops before it.
    let s = solver(None)
        .unwrap()
        .stop_when(Arc::new(AtomicBool::new(true)))
        .solve(|_| {});
    assert_eq!(s.stats().shots, 0);
    assert_eq!(s.stats().stop_reason, StopReason::Interrupted);
}

#[test]
fn a_budget_of_zero_stops_before_the_first_shot_and_says_so() {
    let s = solve(Some(0.0)).unwrap();
    let stats = s.stats();
    assert_eq!(stats.shots, 0);
    assert_eq!(stats.stop_reason, StopReason::TimeBudget);
    assert_eq!(stats.time_budget_seconds, Some(0.0));
    // Nothing shot: all the emitted flux is still unshot.
    assert_eq!(stats.convergence_ratio, 0.0);
    for b in 0..3 {
        assert!((stats.residual_flux[b] - stats.emitted_flux[b]).abs() <= 1e-12);
    }
    assert!(
        stats.warnings.iter().any(|w| w.contains("time budget")),
        "{:?}",
        stats.warnings
    );
}

#[test]
fn a_generous_budget_changes_nothing() {
    let free = solve(None).unwrap();
    let budgeted = solve(Some(365.0 * 24.0 * 3600.0)).unwrap();
    let (a, b) = (free.stats(), budgeted.stats());
    assert_eq!(a.stop_reason, StopReason::Converged);
    assert_eq!(b.stop_reason, StopReason::Converged);
    assert_eq!(a.shots, b.shots);
    assert!(a.shots > 4, "the plates need several shots: {}", a.shots);
    assert_eq!(a.convergence_ratio, b.convergence_ratio);
    assert_eq!(a.residual_flux, b.residual_flux);
    assert!(a.warnings.iter().all(|w| !w.contains("time budget")));
}

#[test]
fn the_convergence_trace_rises_and_ends_at_the_last_shot() {
    let s = solve(None).unwrap();
    let stats = s.stats();
    let trace = &stats.convergence_trace;
    // Shots 1, 2, 4, … and the last.
    assert_eq!(trace[0].shots, 1);
    for w in trace.windows(2) {
        assert!(w[1].shots > w[0].shots);
        // Shooting never adds unshot flux: what a shot delivers is at most
        // what it sent, and receivers reflect at most what arrived. (The
        // convergence ratio itself may dip when the estimate of the
        // interreflection changes: docs/solver.md.)
        assert!(w[1].paper_convergence_ratio >= w[0].paper_convergence_ratio);
        assert!(w[1].seconds >= w[0].seconds);
    }
    let last = trace.last().unwrap();
    assert_eq!(last.shots, stats.shots);
    assert_eq!(last.convergence_ratio, stats.convergence_ratio);
    assert_eq!(last.paper_convergence_ratio, stats.paper_convergence_ratio);
    assert!(last.convergence_ratio >= 0.999);
}

#[test]
fn a_budget_that_is_not_a_duration_is_refused_before_the_solve() {
    for bad in [-1.0, f64::NAN, f64::INFINITY, 1e12] {
        let e = solve(Some(bad)).err().expect("refused");
        assert!(e.to_string().contains("time budget"), "{e}");
    }
}
