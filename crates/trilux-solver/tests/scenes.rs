//! Every bundled scene solves with a balanced ledger: no shot and no
//! receiving element creates energy, and no radiance is negative.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test, bench or example may panic

use std::path::PathBuf;

use trilux_color::Mode;
mod common;

use trilux_solver::{Quality, SolveStats, Solver, SolverSettings};

fn scenes() -> Vec<PathBuf> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    let mut out: Vec<PathBuf> = std::fs::read_dir(&dir)
        .expect("scenes/ exists")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "xml"))
        .collect();
    out.sort();
    out
}

fn check(stats: &SolveStats, bands: usize, name: &str) {
    for b in 0..bands {
        let e = stats.emitted_flux[b];
        let sum = stats.absorbed_flux[b] + stats.escaped_flux[b] + stats.residual_flux[b];
        assert!(
            (e - sum).abs() <= 1e-6 * e.max(1e-300),
            "{name} band {b}: {e} vs {sum}"
        );
        assert!(
            stats.escaped_flux[b] >= -1e-9 * e,
            "{name}: negative escaped flux"
        );
    }
    assert!(
        stats.min_shot_escaped >= -1e-9,
        "{name}: a shot created energy"
    );
    assert!(
        stats.min_element_absorbed >= -1e-9,
        "{name}: an element created energy"
    );
}

#[test]
fn every_bundled_scene_balances() {
    let list = scenes();
    assert!(list.len() >= 2, "scenes/ holds the bundled scenes");
    for path in list {
        let scene = trilux_scene::load(&path).expect("bundled scene loads");
        let shown = path.display().to_string();
        let mut settings = SolverSettings::preset(Quality::Draft);
        settings.max_shots = 200;
        let name = path.display().to_string();
        match scene.mode() {
            Mode::Rgb => {
                let s = Solver::<3>::new(common::prepare(&shown), settings)
                    .expect("solver builds")
                    .solve(|_| {});
                check(s.stats(), 3, &name);
                assert!(s.min_radiance() >= 0.0, "{name}");
            }
            Mode::Spectral => {
                const N: usize = trilux_color::SPECTRAL_BANDS;
                let s = Solver::<N>::new(common::prepare(&shown), settings)
                    .expect("solver builds")
                    .solve(|_| {});
                check(s.stats(), N, &name);
                assert!(s.min_radiance() >= 0.0, "{name}");
            }
        }
    }
}
