//! The contract API end to end on a small scene of every shape kind.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test, bench or example may panic

mod common;

use common::*;
use glam::{DMat4, DVec2, DVec3};
use trilux_geometry::{ElementForest, Ray, SurfaceCoord, SurfaceId, SurfaceKind};

fn scene() -> ElementForest {
    let (p, t) = curved_sheet(4);
    common::forest(&[
        cube(DMat4::from_scale(DVec3::splat(3.0)), true),
        sphere(DVec3::new(1.0, 0.0, 0.0), 0.5, DMat4::IDENTITY, false),
        cylinder(
            DVec3::new(-1.0, 0.0, -1.0),
            DVec3::new(-1.0, 0.0, 1.0),
            0.3,
            DMat4::IDENTITY,
            false,
        ),
        disk(DVec3::new(0.0, 1.5, 0.0), DVec3::X, DVec3::Z, 0.4, false),
        rect(
            DVec3::new(0.0, -1.5, 0.0),
            0.5 * DVec3::X,
            0.5 * DVec3::Z,
            true,
        ),
        mesh(p, t, DMat4::from_translation(DVec3::new(0.0, 0.0, -2.5))),
    ])
    .expect("valid scene")
}

#[test]
fn surfaces_per_shape() {
    let g = scene();
    let count = |s: u32| {
        g.geometry()
            .surfaces()
            .iter()
            .filter(|x| x.shape == s)
            .count()
    };
    assert_eq!(count(0), 6);
    assert_eq!(count(1), 8);
    assert_eq!(count(2), 4);
    assert_eq!(count(3), 1);
    assert_eq!(count(4), 1);
    assert_eq!(count(5), 1);
    assert_eq!(g.geometry().surfaces()[0].kind, SurfaceKind::Planar);
    assert_eq!(g.geometry().surfaces()[6].kind, SurfaceKind::Curved);
    assert!(g.geometry().surfaces().last().unwrap().is_chart());
    // Exact areas: cube face 36, sphere 4π r² / 8, tube 2π r h / 4, disk π r².
    let pi = std::f64::consts::PI;
    assert!((g.geometry().surfaces()[0].area() - 36.0).abs() < 1e-12);
    assert!((g.geometry().surfaces()[6].area() - 4.0 * pi * 0.25 / 8.0).abs() < 1e-12);
    assert!((g.geometry().surfaces()[14].area() - 2.0 * pi * 0.3 * 2.0 / 4.0).abs() < 1e-12);
    assert!((g.geometry().surfaces()[18].area() - pi * 0.16).abs() < 1e-12);
    // Flipped cube: normals point inwards.
    for s in 0..6 {
        let e = g.element(g.root(SurfaceId(s)));
        assert!(e.normal.dot(e.centre) < 0.0);
    }
}

#[test]
fn rays_hit_the_expected_surfaces() {
    let g = scene();
    let h = g
        .geometry()
        .intersect(
            &Ray {
                origin: DVec3::new(2.5, 0.0, 0.0),
                dir: -DVec3::X,
            },
            f64::INFINITY,
        )
        .expect("hits the sphere");
    assert!((h.point - DVec3::new(1.5, 0.0, 0.0)).length() < 1e-12);
    assert!((h.geometric_normal - DVec3::X).length() < 1e-12);
    assert_eq!(g.geometry().surfaces()[h.surface.index()].shape, 1);
    let h = g
        .geometry()
        .intersect(
            &Ray {
                origin: DVec3::new(0.0, 0.0, 0.0),
                dir: DVec3::Y,
            },
            f64::INFINITY,
        )
        .expect("hits the disk");
    assert_eq!(g.geometry().surfaces()[h.surface.index()].shape, 3);
    assert!((h.t - 1.5).abs() < 1e-12);
    // A ray along +x from the cube's inside hits the cube's +x face.
    let h = g
        .geometry()
        .intersect(
            &Ray {
                origin: DVec3::new(0.0, 2.0, 2.0),
                dir: DVec3::X,
            },
            f64::INFINITY,
        )
        .expect("hits the cube");
    assert_eq!(h.surface.0, 1);
    assert!((h.t - 3.0).abs() < 1e-12);
    assert!(
        g.geometry()
            .occluded(DVec3::new(2.5, 0.0, 0.0), DVec3::new(0.0, 0.0, 0.0))
    );
    assert!(
        !g.geometry()
            .occluded(DVec3::new(2.5, 2.5, 2.5), DVec3::new(-2.5, 2.5, 2.5))
    );
}

#[test]
fn subdivide_locate_sample() {
    let mut g = scene();
    for s in 0..g.geometry().surfaces().len() {
        let root = g.root(SurfaceId(s as u32));
        let kids = g.subdivide(root);
        assert_eq!(g.subdivide(root), kids);
        let sum: f64 = kids.iter().map(|&k| g.element(k).area).sum();
        assert!(
            (sum - g.element(root).area).abs() < 1e-9 * sum,
            "surface {s}"
        );
        for &k in &kids {
            assert_eq!(g.element(k).parent, Some(root));
            let smp = g.sample_element(k, DVec2::new(0.3, 0.7));
            assert!(smp.pdf_area > 0.0 && smp.pdf_area.is_finite());
            assert!(g.element_contains(k, smp.coord));
            assert_eq!(g.locate(trilux_geometry::SurfaceId(s as u32), smp.coord), k);
            let sp = g
                .geometry()
                .surface_point(trilux_geometry::SurfaceId(s as u32), smp.coord)
                .unwrap();
            assert!((sp.point - smp.point).length() < 1e-12);
        }
    }
    let _ = SurfaceCoord::Uv(DVec2::ZERO);
}

#[test]
fn scene_geometry_is_shareable_across_threads() {
    fn check<T: Send + Sync + Clone>() {}
    check::<ElementForest>();
    // Reading in parallel while elements exist.
    let g = scene();
    let rays: Vec<Ray> = (0..1000)
        .map(|k| Ray {
            origin: DVec3::ZERO,
            dir: DVec3::new((k as f64).sin(), (k as f64).cos(), 0.3),
        })
        .collect();
    let a = g.geometry().intersect_batch(&rays, f64::INFINITY);
    let b: Vec<_> = rays
        .iter()
        .map(|r| g.geometry().intersect(r, f64::INFINITY))
        .collect();
    assert_eq!(a, b);
}

#[test]
fn sampling_densities_are_finite_and_positive_everywhere() {
    // Including the disk's centre and the sphere's poles (u on the corners
    // and edges of the unit square), under a non-uniform scale too.
    let m = DMat4::from_scale(DVec3::new(1.0, 2.0, 0.5));
    let mut g = common::forest(&[
        sphere(DVec3::ZERO, 1.0, m, false),
        disk(DVec3::ZERO, DVec3::X, DVec3::Y, 1.0, false),
        cylinder(DVec3::ZERO, DVec3::Z, 0.5, m, true),
    ])
    .expect("valid");
    for s in 0..g.geometry().surfaces().len() {
        let root = g.root(SurfaceId(s as u32));
        let kids = g.subdivide(root);
        for e in std::iter::once(root).chain(kids) {
            for u in [
                DVec2::ZERO,
                DVec2::ONE,
                DVec2::new(0.0, 1.0),
                DVec2::new(1.0, 0.0),
                DVec2::new(0.5, 0.0),
                DVec2::new(0.0, 0.5),
            ] {
                let smp = g.sample_element(e, u);
                assert!(
                    smp.pdf_area.is_finite() && smp.pdf_area > 0.0,
                    "surface {s} u {u}: {}",
                    smp.pdf_area
                );
                assert!(smp.point.is_finite() && smp.normal.is_finite());
            }
        }
    }
}

#[test]
fn primitive_triangles_and_bvh_stats_describe_the_tree() {
    let triangles = curved_sheet(4).1.len();
    let g = scene();
    let geom = g.geometry();
    // 12 cube triangles, 2 for the rectangle, the sheet's own; the sphere,
    // cylinder and disk are analytic.
    assert_eq!(geom.primitive_triangles().len(), 12 + 2 + triangles);
    assert_eq!(geom.primitive_count(), 12 + 2 + triangles + 3);
    let s = geom.bvh_stats();
    // Every primitive in a leaf of at most four.
    assert!(4 * s.leaves >= geom.primitive_count(), "{s:?}");
    assert!(
        s.nodes >= 1 && s.depth >= 1 && s.build_seconds >= 0.0,
        "{s:?}"
    );
}

#[test]
fn an_empty_scene_answers_every_query() {
    let geom = trilux_geometry::Geometry::build(&[]).unwrap();
    let ray = Ray {
        origin: DVec3::ZERO,
        dir: DVec3::X,
    };
    assert!(geom.intersect(&ray, f64::INFINITY).is_none());
    assert!(!geom.ray_occluded(&ray, f64::INFINITY));
    assert!(!geom.occluded(DVec3::ZERO, DVec3::ONE));
    assert_eq!(geom.intersect_batch(&[ray; 3], 1.0), vec![None; 3]);
    assert_eq!(geom.bvh_stats().leaves, 0);
}
