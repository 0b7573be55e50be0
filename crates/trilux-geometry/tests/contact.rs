//! Contacts: a ground of two large triangles under a wall that ends on it
//! is cut along the wall, so that no chart of the ground reaches across
//! it; the cut keeps the ground's area, leaves no hole for a ray and
//! shades as the uncut triangles did; a small box makes no cut.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test, bench or example may panic

use glam::{DMat4, DVec3};
use trilux_geometry::{Geometry, Ray, Shape, ShapeKind, TriangleMesh};

/// Half the ground's side (m).
const HALF: f64 = 50.0;
/// Where the wall stands: the plane x = WALL_X.
const WALL_X: f64 = 1.3;

/// The ground's corners and their (unnormalised) vertex normals, tilted
/// differently at each corner so that interpolation shows.
fn ground_vertices() -> ([DVec3; 4], [DVec3; 4]) {
    let p = [
        DVec3::new(-HALF, -HALF, 0.0),
        DVec3::new(HALF, -HALF, 0.0),
        DVec3::new(HALF, HALF, 0.0),
        DVec3::new(-HALF, HALF, 0.0),
    ];
    let n = [
        DVec3::new(0.1, 0.0, 1.0),
        DVec3::new(0.0, 0.2, 1.0),
        DVec3::new(-0.1, 0.1, 1.0),
        DVec3::new(0.05, -0.15, 1.0),
    ];
    (p, n)
}

/// The ground (two triangles, normal +z, vertex normals).
fn ground() -> Shape {
    let (p, n) = ground_vertices();
    Shape {
        kind: ShapeKind::Mesh(TriangleMesh {
            positions: p.to_vec(),
            normals: Some(n.to_vec()),
            triangles: vec![[0, 1, 2], [0, 2, 3]],
            face_normals: false,
            texcoords: None,
        }),
        world_from_object: DMat4::IDENTITY,
        flip_normals: false,
    }
}

/// A wall 8 m long and 3 m high in the plane x = WALL_X, modelled to end
/// 2 mm below the ground (as the classroom's walls are).
fn wall() -> Shape {
    Shape {
        kind: ShapeKind::Rectangle,
        world_from_object: DMat4::from_translation(DVec3::new(WALL_X, 0.0, 1.499))
            * DMat4::from_rotation_y(std::f64::consts::FRAC_PI_2)
            * DMat4::from_scale(DVec3::new(1.501, 4.0, 1.0)),
        flip_normals: false,
    }
}

/// A cube of half-side `h` standing on the ground.
fn small_box(h: f64) -> Shape {
    Shape {
        kind: ShapeKind::Cube,
        world_from_object: DMat4::from_translation(DVec3::new(-3.0, 2.0, h))
            * DMat4::from_scale(DVec3::splat(h)),
        flip_normals: false,
    }
}

#[test]
fn a_wall_standing_on_the_ground_cuts_it() {
    let g = Geometry::build(&[ground(), wall()]).unwrap();
    let charts = g.surfaces_of_shape(0);
    assert!(
        charts.len() > 2,
        "the ground was not cut: {} charts",
        charts.len()
    );
    // Every chart of the ground lies on one side of the wall's plane.
    for &s in &charts {
        let b = g.surface(s).bounds;
        let tol = 1e-9 * HALF;
        assert!(
            b.max.x <= WALL_X + tol || b.min.x >= WALL_X - tol,
            "chart {s:?} straddles the wall: x from {} to {}",
            b.min.x,
            b.max.x
        );
    }
    // The cells tile the ground: their areas add up to its (2 HALF)².
    let area: f64 = charts.iter().map(|&s| g.surface(s).area()).sum();
    let want = 4.0 * HALF * HALF;
    assert!(
        (area - want).abs() <= 1e-12 * want,
        "area {area}, ground {want}"
    );
}

#[test]
fn the_cut_ground_has_no_holes_and_shades_as_before() {
    let g = Geometry::build(&[ground(), wall()]).unwrap();
    let (_, n) = ground_vertices();
    let ground = g.surfaces_of_shape(0);
    // Rays straight down on a grid between the seams, and two columns on
    // them: the cut along the wall's line (exactly on it beyond the wall,
    // 1 mm beside it where the wall stands) and the original triangles'
    // diagonal y = x, which both triangles' cells share, each cut on its
    // own side (through (WALL_X, WALL_X) too).
    let steps = 400;
    for i in 0..=steps {
        for j in 0..=steps {
            let y = -HALF + 2.0 * HALF * j as f64 / steps as f64;
            let x = match i {
                7 if y.abs() > 4.0 => WALL_X,
                7 => WALL_X + 1e-3,
                8 => y,
                _ => -HALF + 2.0 * HALF * (i as f64 + 0.37) / (steps as f64 + 1.0),
            };
            let ray = Ray {
                origin: DVec3::new(x, y, 10.0),
                dir: DVec3::NEG_Z,
            };
            let hit = g
                .intersect(&ray, f64::INFINITY)
                .unwrap_or_else(|| panic!("no hit at ({x}, {y})"));
            assert!(
                ground.contains(&hit.surface),
                "({x}, {y}) hit {:?}",
                hit.surface
            );
            // The vertex normals interpolated over the original triangle
            // (the halves y ≤ x and y ≥ x of the square).
            let (u, v) = ((x + HALF) / (2.0 * HALF), (y + HALF) / (2.0 * HALF));
            let want = if v <= u {
                (1.0 - u) * n[0] + (u - v) * n[1] + v * n[2]
            } else {
                (1.0 - v) * n[0] + (v - u) * n[3] + u * n[2]
            }
            .normalize();
            assert!(
                hit.shading_normal.distance(want) < 1e-9,
                "({x}, {y}): shading normal {:?}, want {want:?}",
                hit.shading_normal
            );
        }
    }
}

#[test]
fn a_small_box_does_not_cut_the_ground() {
    // Its sides end on the ground over 0.8 m, under the 2 % of the
    // ground triangles' size (2 m) that a cut needs.
    let g = Geometry::build(&[ground(), small_box(0.4)]).unwrap();
    assert_eq!(g.surfaces_of_shape(0).len(), 1);
    // A larger one (3 m sides) does, along its footprint.
    let g = Geometry::build(&[ground(), small_box(1.5)]).unwrap();
    assert!(g.surfaces_of_shape(0).len() > 2);
}
