//! Crossings (trilux_geometry::crossing): a room whose floor and ceiling
//! run past its walls, and whose walls run past each other and past the
//! floor and ceiling, as modelled scenes often are, against the same room
//! with every surface trimmed at the others.
//!
//! The issue asks for the same inside radiance within 0.5 %. Measured
//! with the crossing probe: 0.1–1.3 % per surface (before it: 3.4–6 %),
//! and 5.5–10 % within 0.3 m of a crossing (before: 15–18 %), with 1.8 %
//! of the emitted flux escaping the crossed room (docs/solver.md,
//! "Crossings"). This test guards that measured state at 2 %; it is not
//! the bound.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test, bench or example may panic

use std::f64::consts::FRAC_PI_2;

use glam::{DMat4, DVec2, DVec3};
use trilux_brdf::BsdfParams;
use trilux_color::ColorParam;
use trilux_geometry::{Shape, ShapeKind, Side, SurfaceCoord, SurfaceId};
use trilux_solver::{Quality, SceneDescription, Solution, Solver, SolverSettings, SurfaceSite};

/// The room [0, 4] × [0, 3] × [0, 4] (y up): floor, ceiling, four walls,
/// each reaching `past` beyond the others (0: trimmed), and a light under
/// the ceiling. Returns the shapes, their materials and emission.
fn room(past: f64) -> (Vec<Shape>, Vec<BsdfParams>, Vec<Option<ColorParam>>) {
    let rect = |centre: DVec3, rot: DMat4, sx: f64, sy: f64| Shape {
        kind: ShapeKind::Rectangle,
        world_from_object: DMat4::from_translation(centre)
            * rot
            * DMat4::from_scale(DVec3::new(sx, sy, 1.0)),
        flip_normals: false,
    };
    let (hx, hy) = (2.0 + past, 1.5 + past);
    let shapes = vec![
        // Floor (normal +y) and ceiling (normal −y).
        rect(
            DVec3::new(2.0, 0.0, 2.0),
            DMat4::from_rotation_x(-FRAC_PI_2),
            hx,
            hx,
        ),
        rect(
            DVec3::new(2.0, 3.0, 2.0),
            DMat4::from_rotation_x(FRAC_PI_2),
            hx,
            hx,
        ),
        // Walls z = 0 (+z), z = 4 (−z), x = 0 (+x), x = 4 (−x).
        rect(DVec3::new(2.0, 1.5, 0.0), DMat4::IDENTITY, hx, hy),
        rect(
            DVec3::new(2.0, 1.5, 4.0),
            DMat4::from_rotation_y(std::f64::consts::PI),
            hx,
            hy,
        ),
        rect(
            DVec3::new(0.0, 1.5, 2.0),
            DMat4::from_rotation_y(FRAC_PI_2),
            hx,
            hy,
        ),
        rect(
            DVec3::new(4.0, 1.5, 2.0),
            DMat4::from_rotation_y(-FRAC_PI_2),
            hx,
            hy,
        ),
        // The light, 0.6 m square, 1 cm under the ceiling, facing down.
        rect(
            DVec3::new(2.0, 2.99, 2.0),
            DMat4::from_rotation_x(FRAC_PI_2),
            0.3,
            0.3,
        ),
    ];
    let diffuse = |r: f64| BsdfParams::Diffuse {
        reflectance: ColorParam::Float(r),
    };
    let bsdfs = vec![
        diffuse(0.5),
        diffuse(0.7),
        diffuse(0.7),
        diffuse(0.6),
        diffuse(0.7),
        diffuse(0.6),
        diffuse(0.0),
    ];
    let mut emission = vec![None; 7];
    emission[6] = Some(ColorParam::Float(20.0));
    (shapes, bsdfs, emission)
}

fn solve(past: f64) -> Solution<3> {
    let (shapes, bsdfs, emission) = room(past);
    let input = SceneDescription {
        shapes: &shapes,
        bsdfs: &bsdfs,
        emission: &emission,
    };
    let mut settings = SolverSettings::preset(Quality::Default);
    settings.override_from(|k| std::env::var(k).ok()).unwrap();
    Solver::<3>::from_description(&input, settings)
        .expect("builds")
        .solve(|_| {})
}

/// Mean Lambertian radiance (band sum) of the front of surface `s` over
/// the points of a 64 × 64 grid that lie inside the room, and over those
/// of them within 0.3 m of another of the room's surfaces.
fn inside_means(solution: &Solution<3>, s: u32) -> (f64, f64) {
    let geom = solution.forest().geometry();
    let inside = |p: DVec3| {
        let m = 1e-3;
        (m..4.0 - m).contains(&p.x) && (m..3.0 - m).contains(&p.y) && (m..4.0 - m).contains(&p.z)
            || (p.y.abs() < m || (p.y - 3.0).abs() < m)
                && (m..4.0 - m).contains(&p.x)
                && (m..4.0 - m).contains(&p.z)
            || (p.x.abs() < m || (p.x - 4.0).abs() < m)
                && (m..3.0 - m).contains(&p.y)
                && (m..4.0 - m).contains(&p.z)
            || (p.z.abs() < m || (p.z - 4.0).abs() < m)
                && (m..3.0 - m).contains(&p.y)
                && (m..4.0 - m).contains(&p.x)
    };
    let near_edge = |p: DVec3| {
        [p.x, 4.0 - p.x, p.y, 3.0 - p.y, p.z, 4.0 - p.z]
            .iter()
            .filter(|&&d| d < 0.3)
            .count()
            >= 2
    };
    let (mut all, mut n_all, mut edge, mut n_edge) = (0.0, 0, 0.0, 0);
    const G: u32 = 64;
    for i in 0..G {
        for j in 0..G {
            let uv = DVec2::new(
                (f64::from(i) + 0.5) / f64::from(G),
                (f64::from(j) + 0.5) / f64::from(G),
            );
            let coord = SurfaceCoord::Uv(uv);
            let p = geom
                .surface_point(SurfaceId(s), coord)
                .expect("a point")
                .point;
            if !inside(p) {
                continue;
            }
            let site = SurfaceSite::new(SurfaceId(s), Side::Front, coord);
            let l = solution.lambertian_radiance(&site).sum();
            all += l;
            n_all += 1;
            if near_edge(p) {
                edge += l;
                n_edge += 1;
            }
        }
    }
    assert!(
        n_all > 100 && n_edge > 10,
        "surface {s}: {n_all} and {n_edge} points"
    );
    (all / f64::from(n_all), edge / f64::from(n_edge))
}

#[test]
fn a_room_through_its_walls_matches_the_trimmed_room_inside() {
    let (trimmed, through) = (solve(0.0), solve(1.0));
    let mut worst = 0.0f64;
    for s in 0..6 {
        let (a, a_edge) = inside_means(&trimmed, s);
        let (b, b_edge) = inside_means(&through, s);
        eprintln!(
            "surface {s}: through / trimmed {:.4} (within 0.3 m of a crossing {:.4})",
            b / a,
            b_edge / a_edge
        );
        worst = worst.max((b / a - 1.0).abs());
    }
    for sol in [&trimmed, &through] {
        let st = sol.stats();
        eprintln!(
            "emitted {:.4} absorbed {:.4} escaped {:.4} residual {:.4}",
            st.emitted_flux[0], st.absorbed_flux[0], st.escaped_flux[0], st.residual_flux[0]
        );
    }
    assert!(worst <= 0.02, "inside means differ by up to {worst}");
    // The light reaches the inside only: the outside parts are not
    // counted as part of any face's area that sends light.
    let stats = through.stats();
    let absorbed: f64 = stats.absorbed_flux.iter().sum();
    let emitted: f64 = stats.emitted_flux.iter().sum();
    assert!(
        absorbed > 0.95 * emitted,
        "absorbed {absorbed} of {emitted}"
    );
}
