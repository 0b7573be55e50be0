//! Crossings (trilux_geometry::crossing): in a room whose floor, ceiling
//! and walls run past each other, exactly the parts outside the room are
//! cut off from the light (an analytic area per surface); the trimmed room
//! has no crossed face; a box sunk into the floor cuts off the floor under
//! it and its own part below the floor.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test, bench or example may panic

use std::f64::consts::{FRAC_PI_2, PI};

use glam::{DMat4, DVec3};
use trilux_geometry::{
    BurialMap, BurialRequest, ElementForest, FaceElement, FaceId, Geometry, LightFaces, PerFace,
    Shape, ShapeKind, Side, SurfaceId, crossing,
};

/// The room [0, 4] × [0, 3] × [0, 4] (y up), every surface reaching
/// `past` beyond the others, a light under the ceiling and, with `sunk`, a
/// cube of half-side 0.4 centred 0.2 m above the floor (0.2 m of it below).
fn room(past: f64, sunk: bool) -> Vec<Shape> {
    let rect = |centre: DVec3, rot: DMat4, sx: f64, sy: f64| Shape {
        kind: ShapeKind::Rectangle,
        world_from_object: DMat4::from_translation(centre)
            * rot
            * DMat4::from_scale(DVec3::new(sx, sy, 1.0)),
        flip_normals: false,
    };
    let (hx, hy) = (2.0 + past, 1.5 + past);
    let mut shapes = vec![
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
        rect(DVec3::new(2.0, 1.5, 0.0), DMat4::IDENTITY, hx, hy),
        rect(
            DVec3::new(2.0, 1.5, 4.0),
            DMat4::from_rotation_y(PI),
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
        rect(
            DVec3::new(2.0, 2.99, 2.0),
            DMat4::from_rotation_x(FRAC_PI_2),
            0.3,
            0.3,
        ),
    ];
    if sunk {
        shapes.push(Shape {
            kind: ShapeKind::Cube,
            world_from_object: DMat4::from_translation(DVec3::new(1.2, 0.2, 1.3))
                * DMat4::from_scale(DVec3::splat(0.4)),
            flip_normals: false,
        });
    }
    shapes
}

/// The exposed area of the front of every surface, with the crossing
/// probe (emitter: the light's front; every front sends light).
fn exposed(shapes: &[Shape]) -> Vec<f64> {
    let forest = ElementForest::new(Geometry::build_shared(shapes).expect("valid"));
    let geom = forest.geometry();
    let n = geom.surfaces().len();
    let light = LightFaces {
        emitters: vec![FaceId::new(SurfaceId(6), Side::Front)],
        senders: PerFace::from_fn(n, |f| f.side() == Side::Front),
    };
    let requests: Vec<BurialRequest> = (0..n as u32)
        .map(|s| BurialRequest {
            face: FaceId::new(SurfaceId(s), Side::Front),
            resolution: 128,
        })
        .collect();
    let map = BurialMap::probe_with_light(geom, &requests, Some(&light));
    (0..n as u32)
        .map(|s| {
            let root = forest.root(SurfaceId(s));
            let share = map.exposed_fraction(&forest, FaceElement::front(root));
            share * forest.element(root).area
        })
        .collect()
}

#[test]
fn only_the_room_outside_is_cut_off() {
    let through = exposed(&room(1.0, false));
    // Floor and ceiling: 4 × 4 inside (the ceiling less the light's
    // footprint, buried); walls 4 × 3. Cells are 6/128 m across, refined
    // ×4 along outlines.
    let inside = [16.0, 16.0 - 0.36, 12.0, 12.0, 12.0, 12.0, 0.36];
    for (s, (&a, &b)) in through.iter().zip(&inside).enumerate() {
        assert!(
            (a - b).abs() <= 0.01 * b,
            "surface {s}: exposed {a}, inside {b}"
        );
    }
    let geom = Geometry::build(&room(0.0, false)).expect("valid");
    assert!((0..7).all(|s| !crossing::is_crossed(&geom, SurfaceId(s))));
}

#[test]
fn a_sunk_box_cuts_off_the_floor_under_it_and_its_part_below() {
    let e = exposed(&room(0.0, true));
    // The floor less the box's 0.8 × 0.8 footprint.
    assert!(
        (e[0] - (16.0 - 0.64)).abs() <= 0.01 * 16.0,
        "floor {}",
        e[0]
    );
    // The box's four sides (cube faces 7, 8, 11, 12; 0.8 × 0.8 each) keep
    // their part above the floor, 0.8 × 0.6, and the top (10) all of it.
    // The bottom (9) lies wholly below the floor, parallel to it: not
    // crossed, and out of reach of every segment from the room anyway.
    let sides: f64 = [7, 8, 10, 11, 12].iter().map(|&s| e[s]).sum();
    let expected = 4.0 * 0.8 * 0.6 + 0.64;
    assert!(
        (sides - expected).abs() <= 0.02 * expected,
        "box {sides} against {expected}"
    );
}
