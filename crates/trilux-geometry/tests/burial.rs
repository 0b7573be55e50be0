//! Buried parts of faces: a cube standing on a floor covers exactly its
//! footprint (an analytic area), a cube lifted off it covers nothing, and
//! shadow segments from the covered part count as blocked.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test, bench or example may panic

use glam::{DMat4, DVec2, DVec3};
use trilux_geometry::{
    BurialMap, BurialRequest, ElementForest, FaceElement, FaceId, Geometry, Shape, ShapeKind, Side,
    SurfaceCoord, SurfaceId, Visibility,
};

/// A 4 × 4 floor (Mitsuba rectangle scaled by 2, normal +z) and a cube of
/// half-side `h` whose bottom is at height `lift`, rotated by `angle`
/// degrees about z.
fn scene(h: f64, lift: f64, angle: f64) -> ElementForest {
    let floor = Shape {
        kind: ShapeKind::Rectangle,
        world_from_object: DMat4::from_scale(DVec3::new(2.0, 2.0, 1.0)),
        flip_normals: false,
    };
    let cube = Shape {
        kind: ShapeKind::Cube,
        world_from_object: DMat4::from_translation(DVec3::new(0.3, -0.2, h + lift))
            * DMat4::from_rotation_z(angle.to_radians())
            * DMat4::from_scale(DVec3::splat(h)),
        flip_normals: false,
    };
    ElementForest::new(Geometry::build_shared(&[floor, cube]).expect("valid scene"))
}

fn floor_burial(g: &ElementForest, resolution: u32) -> BurialMap {
    BurialMap::probe(
        g.geometry(),
        &[BurialRequest {
            face: FaceId::new(SurfaceId(0), Side::Front),
            resolution,
        }],
    )
}

const FLOOR_FRONT: FaceId = FaceId(0);
const FLOOR_BACK: FaceId = FaceId(1);

#[test]
fn a_standing_cube_covers_its_footprint() {
    // Footprint (2h)² of a 16 m² floor. The map resolves it to about the
    // width of the refined cells along the outline: 4 × 0.8 m × (4 m /
    // (64 · 4)) / 16 m² ≈ 0.3 % of the floor; allow twice that.
    for angle in [0.0, 17.0] {
        let h = 0.4;
        let g = scene(h, 0.0, angle);
        let map = floor_burial(&g, 64);
        let root = g.root(SurfaceId(0));
        let exposed = map.exposed_fraction(&g, FaceElement::front(root));
        let want = 1.0 - (2.0 * h) * (2.0 * h) / 16.0;
        assert!(
            (exposed - want).abs() < 0.006,
            "angle {angle}: exposed {exposed}, footprint says {want}"
        );
        // The point under the cube's centre is buried, one 0.2 m outside
        // its edge is not; the back face was not probed.
        let uv = |x: f64, y: f64| SurfaceCoord::Uv(DVec2::new((x + 2.0) / 4.0, (y + 2.0) / 4.0));
        assert!(map.is_buried(FLOOR_FRONT, uv(0.3, -0.2)));
        assert!(!map.is_buried(FLOOR_FRONT, uv(0.3 + 0.8, -0.2)));
        assert!(!map.is_buried(FLOOR_BACK, uv(0.3, -0.2)));
    }
}

#[test]
fn a_lifted_cube_covers_nothing() {
    // 0.3 m above the floor: the gap is wider than a cell, light gets in.
    let g = scene(0.4, 0.3, 0.0);
    let map = floor_burial(&g, 64);
    assert!(map.is_empty());
    assert_eq!(
        map.exposed_fraction(&g, FaceElement::front(g.root(SurfaceId(0)))),
        1.0
    );
}

#[test]
fn segments_from_the_covered_part_are_blocked() {
    // A floor element wholly under the cube sees the cube's inside faces;
    // once the map is set, those segments carry no light.
    let mut g = scene(0.4, 0.0, 0.0);
    let map = floor_burial(&g, 64);
    // Subdivide the floor until an element lies under the cube.
    let mut e = g.root(SurfaceId(0));
    let target = DVec3::new(0.3, -0.2, 0.0);
    for _ in 0..4 {
        let children = g.subdivide(e);
        e = children
            .into_iter()
            .min_by(|a, b| {
                let da = (g.element(*a).centre - target).length();
                let db = (g.element(*b).centre - target).length();
                da.total_cmp(&db)
            })
            .expect("four children");
    }
    assert!(map.exposed_fraction(&g, FaceElement::front(e)) == 0.0);
    // The cube's top face, seen from below (its back).
    let top = g
        .geometry()
        .surfaces()
        .iter()
        .position(|s| s.shape == 1 && s.bounds.min.z > 0.7)
        .map(|i| g.root(SurfaceId(i as u32)))
        .expect("top face");
    let vis = Visibility::new(&g, Some(&map));
    let v = vis.fraction(FaceElement::front(e), FaceElement::new(top, Side::Back), 64);
    assert_eq!(v, 0.0, "segments from a buried element must be blocked");
}

/// Burial is contact, whatever the cells' size: on a 200 × 200 m ground
/// probed in cells of 100 m, a ceiling 4 m up (a building on the
/// ground) buries nothing under it, while a 30 m cube resting on the
/// ground still buries its footprint (where the outline's finer cells
/// fall inside it). With the cells' size as the reach, every
/// probe ray under the ceiling met it within 8 m and that part of the
/// ground counted as covered (the classroom's floor, results.md).
#[test]
fn a_ceiling_high_above_coarse_cells_covers_nothing() {
    let rect = |centre: DVec3, half: f64, down: bool| Shape {
        kind: ShapeKind::Rectangle,
        world_from_object: DMat4::from_translation(centre)
            * DMat4::from_rotation_x(if down { std::f64::consts::PI } else { 0.0 })
            * DMat4::from_scale(DVec3::new(half, half, 1.0)),
        flip_normals: false,
    };
    let cube = Shape {
        kind: ShapeKind::Cube,
        world_from_object: DMat4::from_translation(DVec3::new(50.0, 50.0, 15.0))
            * DMat4::from_scale(DVec3::splat(15.0)),
        flip_normals: false,
    };
    let shapes = [
        rect(DVec3::ZERO, 100.0, false),
        rect(DVec3::new(-50.0, -50.0, 4.0), 20.0, true),
        cube,
    ];
    let g = ElementForest::new(Geometry::build_shared(&shapes).expect("valid scene"));
    let map = floor_burial(&g, 2);
    let uv =
        |x: f64, y: f64| SurfaceCoord::Uv(DVec2::new((x + 100.0) / 200.0, (y + 100.0) / 200.0));
    assert!(
        !map.is_buried(FLOOR_FRONT, uv(-50.0, -50.0)),
        "under the ceiling"
    );
    assert!(map.is_buried(FLOOR_FRONT, uv(45.0, 45.0)), "under the cube");
}
