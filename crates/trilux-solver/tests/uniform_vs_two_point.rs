//! The paper's uniform treatment (every sender keeps per-receiver
//! interactions) and trilux's two-point treatment of Lambertian parts must
//! agree on a diffuse scene (docs/architecture.md, "Two-point and stored
//! transport"): compared on the classic Cornell
//! box, surface by surface, on a fixed grid of points through the Solution
//! API.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test, bench or example may panic

use std::path::PathBuf;

use glam::DVec2;
mod common;

use trilux_geometry::{Side, SurfaceCoord, SurfaceId};
use trilux_solver::{Quality, Solution, Solver, SolverSettings, SurfaceSite, Transport};

fn solve(transport: Transport) -> Solution<3> {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenes/cornell-box.xml");
    let scene = common::prepare(&path.display().to_string());
    let mut settings = SolverSettings::preset(Quality::Default);
    settings.convergence = 0.999;
    settings.transport = transport;
    settings.flux_eps = 1e-7;
    settings.max_depth = DEPTH;
    Solver::<3>::new(scene, settings)
        .expect("builds")
        .solve(|_| {})
}

/// The depth limit of both solves.
const DEPTH: u32 = 3;

/// One point per leaf element (2^DEPTH × 2^DEPTH leaves on every
/// rectangle), so that the grid mean is the exact area mean of either
/// solution's piecewise-constant radiance. (A coarser grid samples a
/// subset of the leaves, and then the two solutions, whose radiance is
/// resolved differently over a face, need not agree on it.)
const GRID: usize = 1 << DEPTH;

/// Mean reflected radiance of surface `a` over the GRID² grid, read
/// towards one point y of another surface for which `reference` stores an
/// interaction and which the centre of `a` faces (the two-point answer does
/// not depend on the direction; the uniform one must not either, in the
/// mean). Points that do not see the target are left out.
fn surface_mean(
    solution: &Solution<3>,
    reference: &Solution<3>,
    a: u32,
    surfaces: u32,
) -> Option<[f64; 3]> {
    let g = reference.forest().geometry();
    let site =
        |s: u32, uv: DVec2| SurfaceSite::new(SurfaceId(s), Side::Front, SurfaceCoord::Uv(uv));
    let centre = DVec2::splat(0.5);
    let x = g.surface_point(SurfaceId(a), SurfaceCoord::Uv(centre))?;
    let target = (0..surfaces)
        .filter(|&b| b != a && reference.has_stored(&site(a, centre), &site(b, centre)))
        .find_map(|b| {
            let y = g.surface_point(SurfaceId(b), SurfaceCoord::Uv(centre))?;
            let d = y.point - x.point;
            let r = d.length();
            (d.dot(x.normal) > 0.3 * r && -d.dot(y.normal) > 0.3 * r).then(|| site(b, centre))
        })?;
    let y = g.surface_point(target.face.surface(), target.coord)?.point;
    let mut mean = [0.0; 3];
    let mut count = 0;
    for i in 0..GRID {
        for j in 0..GRID {
            let uv = DVec2::new(
                (i as f64 + 0.5) / GRID as f64,
                (j as f64 + 0.5) / GRID as f64,
            );
            // Only points that see the target: the final gather never asks
            // about any other.
            let x = g.surface_point(SurfaceId(a), SurfaceCoord::Uv(uv))?;
            if g.occluded(x.point, y) {
                continue;
            }
            let l = solution.radiance(&site(a, uv), &target);
            for band in 0..3 {
                mean[band] += l[band];
            }
            count += 1;
        }
    }
    (count > 0).then(|| mean.map(|m| m / count as f64))
}

#[test]
fn uniform_and_two_point_agree_on_the_diffuse_cornell_box() {
    let two = solve(Transport::TwoPoint);
    let uni = solve(Transport::Uniform);
    let surfaces = two.forest().geometry().surfaces().len() as u32;
    let mut compared = 0;
    let mut worst: f64 = 0.0;
    let (mut sum_two, mut sum_uni) = (0.0, 0.0);
    for a in 0..surfaces {
        let (Some(m2), Some(mu)) = (
            surface_mean(&two, &uni, a, surfaces),
            surface_mean(&uni, &uni, a, surfaces),
        ) else {
            continue;
        };
        for band in 0..3 {
            sum_two += m2[band];
            sum_uni += mu[band];
            if m2[band] > 1e-3 {
                worst = worst.max((m2[band] - mu[band]).abs() / m2[band]);
            }
        }
        compared += 1;
        eprintln!("surface {a}: two-point {m2:?} uniform {mu:?}");
    }
    eprintln!("worst per-surface relative difference {worst:.4}");
    assert!(compared >= 12, "compared {compared} surfaces");
    // The gate: every surface (every band above 1e-3) within 1%.
    assert!(
        worst <= 0.01,
        "a surface differs by {worst} between the modes"
    );
    let global = (sum_two - sum_uni).abs() / sum_two;
    eprintln!("scene-wide mean relative difference {global:.4}");
    assert!(global <= 0.01, "scene-wide mean differs by {global}");
    // Two-point stores no interactions at all in a diffuse scene.
    assert_eq!(two.interaction_counts().1, 0);
    assert!(
        uni.interaction_counts().1 > 1000,
        "uniform stores {:?}",
        uni.interaction_counts()
    );
    eprintln!(
        "interactions: uniform {:?}, two-point {:?}",
        uni.interaction_counts(),
        two.interaction_counts()
    );
}
