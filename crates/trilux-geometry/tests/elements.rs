//! Element trees: exact areas, subdivision, sampling densities, bounds,
//! normal cones, and errors for bad shapes.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test, bench or example may panic

mod common;

use common::*;
use glam::{DMat4, DQuat, DVec2, DVec3};
use trilux_geometry::{
    ElementForest, ElementId, Shape, ShapeKind, ShapeProblem, SurfaceId, TriangleMesh,
};

/// Subdivides every element `levels` times and returns the leaves.
fn refine(g: &mut ElementForest, root: ElementId, levels: u32) -> Vec<ElementId> {
    let mut f = vec![root];
    for _ in 0..levels {
        f = f.into_iter().flat_map(|e| g.subdivide(e)).collect();
    }
    f
}

#[test]
fn ellipsoid_area_is_exact() {
    // A prolate spheroid (a = b = 0.7, c = 1.3) from a unit sphere scaled
    // non-uniformly and rotated: S = 2πa² (1 + c/(a e) asin e).
    let (a, c) = (0.7f64, 1.3f64);
    let m =
        DMat4::from_scale_rotation_translation(DVec3::new(a, a, c), DQuat::IDENTITY, DVec3::ONE);
    let m = DMat4::from_quat(DQuat::from_euler(glam::EulerRot::XYZ, 0.3, 0.2, 0.1)) * m;
    let g = common::forest(&[sphere(DVec3::ZERO, 1.0, m, false)]).expect("valid");
    let e = (1.0 - a * a / (c * c)).sqrt();
    let exact = 2.0 * std::f64::consts::PI * a * a * (1.0 + c / (a * e) * e.asin());
    let total: f64 = g.geometry().surfaces().iter().map(|s| s.area()).sum();
    assert!((total - exact).abs() < 1e-9 * exact, "{total} vs {exact}");
}

#[test]
fn elliptic_cylinder_area_is_exact() {
    // Semi-axes 0.5 and 1.2, height 2: perimeter by the trapezoid rule on
    // the periodic integrand (exponentially accurate).
    let m = DMat4::from_scale(DVec3::new(0.5, 1.2, 1.0));
    let g = common::forest(&[cylinder(
        DVec3::new(0.0, 0.0, -1.0),
        DVec3::new(0.0, 0.0, 1.0),
        1.0,
        m,
        false,
    )])
    .expect("valid");
    let n = 4096;
    let perimeter: f64 = (0..n)
        .map(|k| {
            let t = std::f64::consts::TAU * k as f64 / n as f64;
            ((0.5 * t.sin()).powi(2) + (1.2 * t.cos()).powi(2)).sqrt()
        })
        .sum::<f64>()
        * std::f64::consts::TAU
        / n as f64;
    let total: f64 = g.geometry().surfaces().iter().map(|s| s.area()).sum();
    assert!(
        (total - 2.0 * perimeter).abs() < 1e-9 * total,
        "{total} vs {}",
        2.0 * perimeter
    );
}

#[test]
fn children_areas_sum_to_the_parent_and_densities_integrate_to_the_area() {
    let shear = DMat4::from_cols_array(&[
        1.0, 0.0, 0.0, 0.0, 0.4, 1.0, 0.0, 0.0, 0.0, 0.3, 0.8, 0.0, 0.1, 0.2, 0.3, 1.0,
    ]);
    let mut g = common::forest(&[
        sphere(DVec3::new(0.2, 0.0, 0.0), 0.8, shear, true),
        cylinder(DVec3::ZERO, DVec3::new(0.0, 1.0, 1.0), 0.3, shear, false),
        Shape {
            kind: ShapeKind::Disk,
            world_from_object: shear,
            flip_normals: false,
        },
        cube(shear, false),
        Shape {
            kind: ShapeKind::Rectangle,
            world_from_object: shear,
            flip_normals: true,
        },
    ])
    .expect("valid");
    for s in 0..g.geometry().surfaces().len() {
        let root = g.root(SurfaceId(s as u32));
        let leaves = refine(&mut g, root, 3);
        let sum: f64 = leaves.iter().map(|&l| g.element(l).area).sum();
        assert!(
            (sum - g.element(root).area).abs() < 1e-10 * sum,
            "surface {s}: {sum} vs {}",
            g.element(root).area
        );
        for &l in leaves.iter().step_by(7) {
            let el = g.element(l).clone();
            // ∫ 1/pdf du = area, by composite 3-point Gauss–Legendre on
            // 16×16 cells (degree 5 per cell: error ≪ 1e-9 for these smooth
            // integrands).
            let gl = [
                (0.5 - 0.387_298_334_620_741_7, 5.0 / 18.0),
                (0.5, 8.0 / 18.0),
                (0.5 + 0.387_298_334_620_741_7, 5.0 / 18.0),
            ];
            let n = 16;
            let mut acc = 0.0;
            for i in 0..n * 3 {
                for j in 0..n * 3 {
                    let (xi, wi) = gl[i % 3];
                    let (xj, wj) = gl[j % 3];
                    let u = DVec2::new(
                        ((i / 3) as f64 + xi) / n as f64,
                        ((j / 3) as f64 + xj) / n as f64,
                    );
                    let w = wi * wj / (n * n) as f64;
                    let smp = g.sample_element(l, u);
                    assert!(smp.pdf_area > 0.0 && smp.pdf_area.is_finite());
                    assert!(
                        el.bounds.contains(smp.point),
                        "surface {s}: {:?} outside {:?}",
                        smp.point,
                        el.bounds
                    );
                    assert!(smp.normal.dot(el.normal) >= el.normal_cone_cos - 1e-12);
                    assert!(g.element_contains(l, smp.coord));
                    assert_eq!(g.locate(SurfaceId(s as u32), smp.coord), l);
                    acc += w / smp.pdf_area;
                }
            }
            // Sheared sphere pieces (surfaces 0..8) sampled uniformly in
            // cos θ have a √(1 − z²) factor in the integrand at the poles,
            // which limits this composite rule to ~1e-6; the pointwise check
            // below tests their density everywhere.
            let tol = if s < 8 { 1e-5 } else { 1e-9 };
            assert!(
                (acc - el.area).abs() < tol * el.area,
                "surface {s}: {acc} vs {}",
                el.area
            );
            // Pointwise: pdf = 1 / |∂p/∂u₁ × ∂p/∂u₂| of the sampling map, by
            // central differences (h = 1e-6: relative error ~1e-7).
            for &(a, b) in &[(0.3, 0.6), (0.77, 0.15), (0.5, 0.02), (0.05, 0.95)] {
                let h = 1e-6;
                let p = |x: f64, y: f64| g.sample_element(l, DVec2::new(x, y)).point;
                let du = (p(a + h, b) - p(a - h, b)) / (2.0 * h);
                let dv = (p(a, b + h) - p(a, b - h)) / (2.0 * h);
                let jac = du.cross(dv).length();
                let pdf = g.sample_element(l, DVec2::new(a, b)).pdf_area;
                assert!(
                    (pdf * jac - 1.0).abs() < 1e-5,
                    "surface {s}: pdf {pdf} vs 1/{jac}"
                );
            }
            for p in g.element_points(l) {
                assert!(el.bounds.contains(p));
            }
        }
    }
}

#[test]
fn bad_shapes_are_errors_naming_the_shape() {
    let ok = Shape {
        kind: ShapeKind::Rectangle,
        world_from_object: DMat4::IDENTITY,
        flip_normals: false,
    };
    type Check = fn(&ShapeProblem) -> bool;
    let cases: Vec<(Shape, Check)> = vec![
        (
            Shape {
                kind: ShapeKind::Rectangle,
                world_from_object: DMat4::from_scale(DVec3::new(f64::NAN, 1.0, 1.0)),
                flip_normals: false,
            },
            |p| matches!(p, ShapeProblem::NonFiniteTransform),
        ),
        (
            Shape {
                kind: ShapeKind::Rectangle,
                world_from_object: DMat4::from_scale(DVec3::new(0.0, 1.0, 1.0)),
                flip_normals: false,
            },
            |p| matches!(p, ShapeProblem::SingularTransform),
        ),
        (sphere(DVec3::ZERO, -1.0, DMat4::IDENTITY, false), |p| {
            matches!(p, ShapeProblem::BadRadius { .. })
        }),
        (sphere(DVec3::ZERO, 0.0, DMat4::IDENTITY, false), |p| {
            matches!(p, ShapeProblem::BadRadius { .. })
        }),
        (
            sphere(DVec3::new(f64::NAN, 0.0, 0.0), 1.0, DMat4::IDENTITY, false),
            |p| matches!(p, ShapeProblem::NonFinite { .. }),
        ),
        (
            cylinder(DVec3::ZERO, DVec3::ZERO, 1.0, DMat4::IDENTITY, false),
            |p| matches!(p, ShapeProblem::DegenerateAxis),
        ),
        (
            cylinder(DVec3::ZERO, DVec3::Z, f64::INFINITY, DMat4::IDENTITY, false),
            |p| matches!(p, ShapeProblem::NonFinite { .. }),
        ),
        (
            mesh(
                vec![DVec3::ZERO, DVec3::X, DVec3::Y],
                vec![[0, 1, 3]],
                DMat4::IDENTITY,
            ),
            |p| matches!(p, ShapeProblem::IndexOutOfRange { .. }),
        ),
        (
            mesh(
                vec![DVec3::ZERO, DVec3::X, DVec3::Y],
                vec![],
                DMat4::IDENTITY,
            ),
            |p| matches!(p, ShapeProblem::EmptyMesh),
        ),
        (
            mesh(
                vec![DVec3::ZERO, DVec3::X, 2.0 * DVec3::X],
                vec![[0, 1, 2]],
                DMat4::IDENTITY,
            ),
            |p| matches!(p, ShapeProblem::ZeroArea),
        ),
        (
            mesh(
                vec![DVec3::ZERO, DVec3::X, DVec3::new(0.0, f64::NAN, 0.0)],
                vec![[0, 1, 2]],
                DMat4::IDENTITY,
            ),
            |p| matches!(p, ShapeProblem::NonFiniteVertex { vertex: 2 }),
        ),
        (
            Shape {
                kind: ShapeKind::Mesh(TriangleMesh {
                    positions: vec![DVec3::ZERO, DVec3::X, DVec3::Y],
                    normals: Some(vec![DVec3::Z]),
                    triangles: vec![[0, 1, 2]],
                    face_normals: false,
                    texcoords: None,
                }),
                world_from_object: DMat4::IDENTITY,
                flip_normals: false,
            },
            |p| matches!(p, ShapeProblem::NormalCountMismatch { .. }),
        ),
    ];
    for (k, (bad, check)) in cases.into_iter().enumerate() {
        let err = common::forest(&[ok.clone(), bad]).expect_err("bad shape accepted");
        assert_eq!(err.shape, 1, "case {k}");
        assert!(check(&err.problem), "case {k}: {err}");
        assert!(err.to_string().starts_with("shape 1: "));
    }
    // Degenerate triangles inside a valid mesh are skipped, not errors.
    let g = common::forest(&[mesh(
        vec![DVec3::ZERO, DVec3::X, DVec3::Y, 2.0 * DVec3::X],
        vec![[0, 1, 2], [0, 1, 3]],
        DMat4::IDENTITY,
    )])
    .expect("valid");
    assert_eq!(g.geometry().primitive_count(), 1);
    // An empty scene is fine and every ray misses.
    let g = common::forest(&[]).expect("empty scene");
    assert!(
        g.geometry()
            .intersect(
                &trilux_geometry::Ray {
                    origin: DVec3::ZERO,
                    dir: DVec3::X
                },
                f64::INFINITY
            )
            .is_none()
    );
    assert!(!g.geometry().occluded(DVec3::ZERO, DVec3::ONE));
}

#[test]
fn mitsuba_conventions() {
    // Rectangle: [-1,1]², normal +z, u along x.
    let g = common::forest(&[Shape {
        kind: ShapeKind::Rectangle,
        world_from_object: DMat4::IDENTITY,
        flip_normals: false,
    }])
    .expect("valid");
    let p = g
        .geometry()
        .surface_point(
            SurfaceId(0),
            trilux_geometry::SurfaceCoord::Uv(DVec2::new(0.75, 0.25)),
        )
        .expect("uv");
    assert!((p.point - DVec3::new(0.5, -0.5, 0.0)).length() < 1e-15);
    assert_eq!(p.normal, DVec3::Z);
    // flip_normals flips the front.
    let g = common::forest(&[Shape {
        kind: ShapeKind::Disk,
        world_from_object: DMat4::IDENTITY,
        flip_normals: true,
    }])
    .expect("valid");
    assert_eq!(g.element(g.root(SurfaceId(0))).normal, -DVec3::Z);
    // Cylinder: an open tube from p0 to p1, outward normals; area 2π r h.
    let g = common::forest(&[cylinder(
        DVec3::ZERO,
        DVec3::new(0.0, 0.0, 2.0),
        0.5,
        DMat4::IDENTITY,
        false,
    )])
    .expect("valid");
    let total: f64 = g.geometry().surfaces().iter().map(|s| s.area()).sum();
    assert!((total - std::f64::consts::TAU).abs() < 1e-12);
    for (k, s) in g.geometry().surfaces().iter().enumerate() {
        let e = g.element(g.root(SurfaceId(k as u32)));
        let radial = DVec3::new(e.centre.x, e.centre.y, 0.0).normalize();
        assert!((e.normal - radial).length() < 1e-12);
        assert!(!s.can_see_itself() && s.back_can_see_itself());
    }
    // The tube is open: a ray along its axis passes through.
    assert!(
        g.geometry()
            .intersect(
                &trilux_geometry::Ray {
                    origin: DVec3::new(0.0, 0.0, -1.0),
                    dir: DVec3::Z
                },
                f64::INFINITY
            )
            .is_none()
    );
    // Cube: outward normals, 6 faces of area 4.
    let g = common::forest(&[cube(DMat4::IDENTITY, false)]).expect("valid");
    for (k, s) in g.geometry().surfaces().iter().enumerate() {
        let e = g.element(g.root(SurfaceId(k as u32)));
        assert!((e.normal - e.centre).length() < 1e-12);
        assert!((s.area() - 4.0).abs() < 1e-12);
    }
}
