//! Ray queries: the BVH against brute force over every primitive (proptest),
//! an independent world-space reference for the analytic shapes, closed-cube
//! watertightness, and rays that start on surfaces.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test, bench or example may panic

mod common;

use common::*;
use glam::{DMat4, DQuat, DVec2, DVec3};
use proptest::prelude::*;
use trilux_geometry::{Ray, Shape, SurfaceId};

fn arb_vec(r: f64) -> impl Strategy<Value = DVec3> {
    (-r..r, -r..r, -r..r).prop_map(|(x, y, z)| DVec3::new(x, y, z))
}

fn arb_rotation() -> impl Strategy<Value = DQuat> {
    (0.0..6.3f64, 0.0..6.3f64, 0.0..6.3f64)
        .prop_map(|(a, b, c)| DQuat::from_euler(glam::EulerRot::XYZ, a, b, c))
}

/// A transform: rotation, translation, and a uniform or (if `nonuniform`)
/// per-axis scale.
fn arb_transform(nonuniform: bool) -> impl Strategy<Value = DMat4> {
    (
        arb_rotation(),
        arb_vec(3.0),
        0.2..2.0f64,
        0.5..1.5f64,
        0.5..1.5f64,
    )
        .prop_map(move |(q, t, s, sy, sz)| {
            let scale = if nonuniform {
                DVec3::new(s, s * sy, s * sz)
            } else {
                DVec3::splat(s)
            };
            DMat4::from_scale_rotation_translation(scale, q, t)
        })
}

fn arb_shape(nonuniform: bool) -> impl Strategy<Value = Shape> {
    prop_oneof![
        (arb_transform(nonuniform), any::<bool>()).prop_map(|(m, f)| Shape {
            kind: trilux_geometry::ShapeKind::Rectangle,
            world_from_object: m,
            flip_normals: f
        }),
        (arb_transform(nonuniform), any::<bool>()).prop_map(|(m, f)| cube(m, f)),
        (arb_transform(nonuniform), any::<bool>()).prop_map(|(m, f)| Shape {
            kind: trilux_geometry::ShapeKind::Disk,
            world_from_object: m,
            flip_normals: f
        }),
        (
            arb_transform(nonuniform),
            arb_vec(0.5),
            0.1..1.0f64,
            any::<bool>()
        )
            .prop_map(|(m, c, r, f)| sphere(c, r, m, f)),
        (
            arb_transform(nonuniform),
            arb_vec(1.0),
            arb_vec(1.0),
            0.1..1.0f64
        )
            .prop_filter_map("axis", |(m, a, b, r)| ((a - b).length() > 0.1)
                .then(|| cylinder(a, b, r, m, false))),
        (prop::collection::vec((arb_vec(3.0), arb_vec(0.8), arb_vec(0.8)), 1..40)).prop_map(
            |tris| {
                let mut p = Vec::new();
                let mut t = Vec::new();
                for (i, (a, b, c)) in tris.into_iter().enumerate() {
                    p.extend([a, a + b, a + c]);
                    let k = 3 * i as u32;
                    t.push([k, k + 1, k + 2]);
                }
                mesh(p, t, DMat4::IDENTITY)
            }
        ),
    ]
}

fn arb_ray() -> impl Strategy<Value = Ray> {
    (arb_vec(6.0), arb_vec(1.0)).prop_filter_map("dir", |(o, d)| {
        (d.length() > 1e-3).then_some(Ray { origin: o, dir: d })
    })
}

fn same_hit(a: &Option<trilux_geometry::Hit>, b: &Option<trilux_geometry::Hit>) -> bool {
    match (a, b) {
        (None, None) => true,
        (Some(x), Some(y)) => {
            (x.t - y.t).abs() <= 1e-12 * x.t.abs().max(1.0)
                && (x.surface == y.surface || x.t == y.t)
        }
        _ => false,
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 96, ..ProptestConfig::default() })]

    /// Closest hit and occlusion through the BVH equal a brute-force loop
    /// over every primitive, on random scenes of every shape kind
    /// (non-uniform scales included).
    #[test]
    fn bvh_agrees_with_brute_force(shapes in prop::collection::vec(arb_shape(true), 1..8), rays in prop::collection::vec(arb_ray(), 64), tmax in prop_oneof![Just(f64::INFINITY), 0.5..20.0f64]) {
        let g = common::forest(&shapes).expect("valid shapes");
        for r in &rays {
            let a = g.geometry().intersect(r, tmax);
            let b = g.geometry().intersect_brute_force(r, tmax);
            prop_assert!(same_hit(&a, &b), "ray {:?}: bvh {:?} brute {:?}", r, a, b);
            prop_assert_eq!(g.geometry().ray_occluded(r, tmax), b.is_some());
            if let Some(h) = a {
                prop_assert!(h.point.is_finite() && h.geometric_normal.is_finite() && h.shading_normal.is_finite());
                prop_assert!((h.geometric_normal.length() - 1.0).abs() < 1e-9);
                // The hit point lies on the surface it names, at its coordinate.
                let sp = g.geometry().surface_point(h.surface, h.coord).expect("coordinate fits surface");
                prop_assert!((sp.point - h.point).length() < 1e-6 * (1.0 + h.point.length()), "{:?} vs {:?}", sp.point, h.point);
            }
        }
    }

    /// Segments between points: occluded(p, q) equals "the brute-force
    /// closest hit from p lies before q".
    #[test]
    fn occluded_segments_agree_with_brute_force(shapes in prop::collection::vec(arb_shape(true), 1..8), pts in prop::collection::vec((arb_vec(5.0), arb_vec(5.0)), 64)) {
        let g = common::forest(&shapes).expect("valid shapes");
        // The hinted form (last occluder tested first, carried across
        // unrelated segments here) must give the same answers.
        let mut hint = None;
        for (p, q) in pts {
            let d = q - p;
            let brute = g.geometry().intersect_brute_force(&Ray { origin: p, dir: d }, 1.0 - 1e-9 * (q.abs().max_element() + 10.0) / d.length()).is_some();
            prop_assert_eq!(g.geometry().occluded(p, q), brute);
            prop_assert_eq!(g.geometry().occluded_hint(p, q, &mut hint), brute);
        }
    }

    /// Against an independent world-space reference for spheres (uniform
    /// scale): distance and normal.
    #[test]
    fn spheres_match_world_space_reference(c in arb_vec(2.0), r in 0.1..2.0f64, m in arb_transform(false), rays in prop::collection::vec(arb_ray(), 64)) {
        let g = common::forest(&[sphere(c, r, m, false)]).expect("valid sphere");
        let (s, _, _) = m.to_scale_rotation_translation();
        let wc = m.transform_point3(c);
        let wr = r * s.x;
        for ray in rays {
            let f = ray.origin - wc;
            let a = ray.dir.length_squared();
            let b = f.dot(ray.dir);
            let cc = f.length_squared() - wr * wr;
            let disc = b * b - a * cc;
            let reference = if disc < 0.0 { None } else {
                let sq = disc.sqrt();
                [(-b - sq) / a, (-b + sq) / a].into_iter().find(|&t| t > 1e-6)
            };
            let hit = g.geometry().intersect(&ray, f64::INFINITY);
            // Skip rays that graze the silhouette (ill-conditioned).
            if disc.abs() < 1e-6 * b * b { continue; }
            match (reference, hit) {
                (None, None) => {}
                (Some(t), Some(h)) => {
                    prop_assert!((t - h.t).abs() < 1e-7 * (1.0 + t), "{} vs {}", t, h.t);
                    let n = (h.point - wc).normalize();
                    prop_assert!((n - h.geometric_normal).length() < 1e-7);
                }
                (a, b) => prop_assert!(false, "reference {:?} vs {:?}", a, b),
            }
        }
    }

    /// Rays leaving a sphere outwards never hit it again; rays going inwards
    /// hit it at the far end of the chord, t = −2 (p − c)·d / |d|².
    #[test]
    fn rays_from_sphere_surface(c in arb_vec(2.0), r in 0.1..3.0f64, u in prop::collection::vec((0.0..1.0f64, 0.0..1.0f64, arb_vec(1.0)), 64)) {
        let g = common::forest(&[sphere(c, r, DMat4::IDENTITY, false)]).expect("valid sphere");
        for (i, (u0, u1, d)) in u.into_iter().enumerate() {
            if d.length() < 1e-3 { continue; }
            let smp = g.sample_surface(SurfaceId((i % 8) as u32), DVec2::new(u0, u1));
            let ray = Ray { origin: smp.point, dir: d };
            let hit = g.geometry().intersect(&ray, f64::INFINITY);
            let cosine = d.normalize().dot(smp.normal);
            if cosine > 1e-6 {
                prop_assert!(hit.is_none(), "outward ray re-hit {:?}", hit);
            } else if cosine < -1e-6 {
                let t = -2.0 * (smp.point - c).dot(d) / d.length_squared();
                let h = hit.expect("inward ray hits the far side");
                prop_assert!((h.t - t).abs() < 1e-9 * (1.0 + t / r) * r.max(1.0), "{} vs {}", h.t, t);
            }
        }
    }

    /// Inside a closed cube, every ray from any interior point hits the cube,
    /// including rays aimed exactly at edges and corners (no leaks), and rays
    /// starting on a face hit another face, never their own.
    #[test]
    fn closed_cube_has_no_leaks(m in arb_transform(true), targets in prop::collection::vec((0usize..8, 0usize..8, 0.0..1.0f64, arb_vec(0.99)), 200)) {
        let g = common::forest(&[cube(m, true)]).expect("valid cube");
        let corner = |i: usize| m.transform_point3(DVec3::new(if i & 1 != 0 { 1.0 } else { -1.0 }, if i & 2 != 0 { 1.0 } else { -1.0 }, if i & 4 != 0 { 1.0 } else { -1.0 }));
        for (a, b, s, o) in targets {
            // A point on an edge, a face diagonal or a corner of the cube
            // (corners differing in at most two coordinates share a face).
            if (a ^ b).count_ones() > 2 { continue; }
            let target = corner(a).lerp(corner(b), s);
            let origin = m.transform_point3(o);
            let d = target - origin;
            if d.length() < 1e-9 { continue; }
            let h = g.geometry().intersect(&Ray { origin, dir: d }, f64::INFINITY);
            prop_assert!(h.is_some(), "leak: ray from {:?} to {:?}", origin, target);
            let h = h.unwrap();
            prop_assert!(h.t <= 1.0 + 1e-9, "t = {}", h.t);
            // From the hit point on a face onwards, the ray must not stop on
            // that face again, and going back it must reach another face.
            let back = g.geometry().intersect(&Ray { origin: h.point, dir: -d }, f64::INFINITY);
            prop_assert!(back.is_some(), "leak on the way back");
            prop_assert!(back.unwrap().t > 1e-6);
        }
    }

    /// Rays grazing a cube from outside through points of its edges, almost
    /// parallel to one of the two faces there, enter the cube: they hit at
    /// (or, by rounding, a hair after) the aimed point; none leaks through.
    #[test]
    fn grazing_rays_hit_cube_edges(m in arb_transform(true), targets in prop::collection::vec((0usize..12, 0.01..0.99f64, -1e-3..1e-3f64, 1e-9..1e-3f64, any::<bool>()), 200)) {
        let g = common::forest(&[cube(m, false)]).expect("valid cube");
        // Edges as (corner a, corner b, the two axes whose faces meet there).
        let corner = |i: usize| m.transform_point3(DVec3::new(if i & 1 != 0 { 1.0 } else { -1.0 }, if i & 2 != 0 { 1.0 } else { -1.0 }, if i & 4 != 0 { 1.0 } else { -1.0 }));
        let nm = m.inverse().transpose();
        let face_normal = |axis: usize, positive: bool| {
            let mut n = DVec3::ZERO;
            n[axis] = if positive { 1.0 } else { -1.0 };
            nm.transform_vector3(n).normalize()
        };
        for (e, s, along_amount, delta, swap) in targets {
            // Edge e: the two corners differ in axis `ax`; the other two axes
            // fix the faces.
            let ax = e / 4;
            let bits = e % 4;
            let (o1, o2) = ((ax + 1) % 3, (ax + 2) % 3);
            let base = ((bits & 1) << o1) | (((bits >> 1) & 1) << o2);
            let (a, b) = (base, base | (1 << ax));
            let target = corner(a).lerp(corner(b), s);
            let na = face_normal(o1, bits & 1 != 0);
            let nb = face_normal(o2, bits & 2 != 0);
            let (na, nb) = if swap { (nb, na) } else { (na, nb) };
            let along = (corner(b) - corner(a)).normalize();
            let dir = (-delta * na - nb + along_amount * along).normalize();
            let origin = target - 5.0 * dir;
            let h = g.geometry().intersect(&Ray { origin, dir }, f64::INFINITY);
            prop_assert!(h.is_some(), "leak through an edge: origin {:?} dir {:?}", origin, dir);
            let t = h.unwrap().t;
            prop_assert!(t <= 5.0 + 1e-6 + 1e-13 / delta, "passed through the edge: t = {}", t);
        }
    }

    /// Axis-aligned boxes and rectangles, whose faces lie on the scene's
    /// bounding box, with rays from outside and from on their surfaces:
    /// the BVH equals brute force (obvhs culls boxes within 1e-4 of the
    /// traversal origin; this guards the work-around).
    #[test]
    fn axis_aligned_scenes_agree_with_brute_force(boxes in prop::collection::vec((arb_vec(2.0), arb_vec(1.0), any::<bool>(), any::<bool>()), 1..6), rays in prop::collection::vec((arb_ray(), 0usize..1000, 0.0..1.0f64, 0.0..1.0f64), 64)) {
        let shapes: Vec<Shape> = boxes.iter().map(|&(c, s, is_cube, flip)| {
            let m = DMat4::from_scale_rotation_translation(s.abs() + DVec3::splat(0.05), DQuat::IDENTITY, c);
            if is_cube { cube(m, flip) } else { Shape { kind: trilux_geometry::ShapeKind::Rectangle, world_from_object: m, flip_normals: flip } }
        }).collect();
        let g = common::forest(&shapes).expect("valid shapes");
        for (r, s, u0, u1) in rays {
            let a = g.geometry().intersect(&r, f64::INFINITY);
            let b = g.geometry().intersect_brute_force(&r, f64::INFINITY);
            prop_assert!(same_hit(&a, &b), "ray {:?}: bvh {:?} brute {:?}", r, a, b);
            // From a point on a surface.
            let sid = SurfaceId((s % g.geometry().surfaces().len()) as u32);
            let start = g.sample_surface(sid, DVec2::new(u0, u1)).point;
            let r2 = Ray { origin: start, dir: r.dir };
            let a = g.geometry().intersect(&r2, f64::INFINITY);
            let b = g.geometry().intersect_brute_force(&r2, f64::INFINITY);
            prop_assert!(same_hit(&a, &b), "ray {:?}: bvh {:?} brute {:?}", r2, a, b);
            let far = start + 1e-5 * r.dir;
            prop_assert_eq!(g.geometry().occluded(start, far), g.geometry().intersect_brute_force(&Ray { origin: start, dir: far - start }, 1.0 - 1e-9 * (far.abs().max_element() + 10.0) / (far - start).length()).is_some());
        }
    }

    /// Rays starting on any surface (sampled on its elements) never stop on
    /// that surface at their origin: a planar surface is never hit again,
    /// a curved one only far away.
    #[test]
    fn rays_from_surfaces_do_not_self_intersect(shapes in prop::collection::vec(arb_shape(true), 1..6), starts in prop::collection::vec((0usize..1000, 0.0..1.0f64, 0.0..1.0f64, arb_vec(1.0)), 64)) {
        let g = common::forest(&shapes).expect("valid shapes");
        for (s, u0, u1, d) in starts {
            if d.length() < 1e-3 { continue; }
            let sid = SurfaceId((s % g.geometry().surfaces().len()) as u32);
            let smp = g.sample_surface(sid, DVec2::new(u0, u1));
            if let Some(h) = g.geometry().intersect(&Ray { origin: smp.point, dir: d }, f64::INFINITY) {
                let dist = h.t * d.length();
                prop_assert!(dist > 1e-7 * (1.0 + smp.point.length()), "re-hit at distance {}", dist);
                if g.geometry().surface(sid).is_planar() {
                    prop_assert!(h.surface != sid, "planar surface hit itself");
                }
            }
        }
    }

    /// Disks and cylinders (uniform scale) against independent world-space
    /// references.
    #[test]
    fn disks_and_cylinders_match_world_space_reference(p0 in arb_vec(1.0), p1 in arb_vec(1.0), r in 0.1..1.5f64, m in arb_transform(false), rays in prop::collection::vec(arb_ray(), 64)) {
        prop_assume!((p1 - p0).length() > 0.1);
        let g = common::forest(&[cylinder(p0, p1, r, m, false), Shape { kind: trilux_geometry::ShapeKind::Disk, world_from_object: m, flip_normals: false }]).expect("valid shapes");
        let (s, _, _) = m.to_scale_rotation_translation();
        let (a, b) = (m.transform_point3(p0), m.transform_point3(p1));
        let wr = r * s.x;
        let axis = (b - a).normalize();
        let (dc, dn, dr) = (m.transform_point3(DVec3::ZERO), m.transform_vector3(DVec3::Z).normalize(), s.x);
        for ray in rays {
            let mut best: Option<(f64, bool)> = None;
            let mut margin = f64::INFINITY;
            // Cylinder: |(o + t d − a)⊥|² = r², 0 ≤ (·)∥ ≤ |b − a|.
            let f = ray.origin - a;
            let fp = f - f.dot(axis) * axis;
            let dp = ray.dir - ray.dir.dot(axis) * axis;
            let qa = dp.length_squared();
            let qb = fp.dot(dp);
            let qc = fp.length_squared() - wr * wr;
            let disc = qb * qb - qa * qc;
            if qa > 0.0 && disc >= 0.0 {
                margin = margin.min(disc.abs() / (qb * qb + 1e-300));
                for t in [(-qb - disc.sqrt()) / qa, (-qb + disc.sqrt()) / qa] {
                    let z = (f + t * ray.dir).dot(axis);
                    margin = margin.min(z.abs()).min((z - (b - a).length()).abs());
                    if t > 1e-6 && z >= 0.0 && z <= (b - a).length() && best.is_none_or(|x| t < x.0) {
                        best = Some((t, true));
                    }
                }
            }
            // Disk.
            let den = ray.dir.dot(dn);
            if den != 0.0 {
                let t = (dc - ray.origin).dot(dn) / den;
                let rho = (ray.origin + t * ray.dir - dc).length();
                margin = margin.min((rho - dr).abs());
                if t > 1e-6 && rho <= dr && best.is_none_or(|x| t < x.0) {
                    best = Some((t, false));
                }
            }
            if margin < 1e-6 { continue; }
            let hit = g.geometry().intersect(&ray, f64::INFINITY);
            match (best, hit) {
                (None, None) => {}
                (Some((t, cyl)), Some(h)) => {
                    prop_assert!((t - h.t).abs() < 1e-7 * (1.0 + t), "{} vs {}", t, h.t);
                    prop_assert_eq!(cyl, h.surface.0 < 4);
                }
                (x, y) => prop_assert!(false, "reference {:?} vs {:?}", x, y),
            }
        }
    }
}

#[test]
fn segments_between_faces_of_a_closed_room_are_unoccluded() {
    let g = common::forest(&[cube(DMat4::from_scale(DVec3::new(2.0, 1.0, 3.0)), true)])
        .expect("valid cube");
    let mut n = 0;
    for a in 0..6u32 {
        for b in 0..6u32 {
            if a == b {
                continue;
            }
            for k in 0..64u32 {
                let u = DVec2::new((k % 8) as f64 / 8.0 + 0.01, (k / 8) as f64 / 8.0 + 0.02);
                let p = g.sample_surface(SurfaceId(a), u).point;
                let q = g.sample_surface(SurfaceId(b), DVec2::ONE - u).point;
                assert!(!g.geometry().occluded(p, q), "{p:?} {q:?}");
                n += 1;
            }
        }
    }
    assert_eq!(n, 30 * 64);
}

#[test]
fn shared_edges_of_a_triangulated_cube_do_not_leak() {
    // An OBJ-like closed cube mesh (12 triangles): rays from the centre to
    // every point of a fine grid on the edges must hit.
    let p: Vec<DVec3> = (0..8)
        .map(|i| {
            DVec3::new((i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64) * 2.0 - 1.0
        })
        .collect();
    let t = vec![
        [0, 2, 3],
        [0, 3, 1],
        [4, 5, 7],
        [4, 7, 6],
        [0, 1, 5],
        [0, 5, 4],
        [2, 6, 7],
        [2, 7, 3],
        [0, 4, 6],
        [0, 6, 2],
        [1, 3, 7],
        [1, 7, 5],
    ];
    let m = DMat4::from_scale_rotation_translation(
        DVec3::new(1.3, 0.7, 2.1),
        DQuat::from_euler(glam::EulerRot::XYZ, 0.3, 1.1, -0.4),
        DVec3::new(0.1, 0.2, 0.3),
    );
    let g = common::forest(&[mesh(p.clone(), t, m)]).expect("valid mesh");
    let o = m.transform_point3(DVec3::new(0.1, -0.2, 0.05));
    let mut rays = 0;
    for a in 0..8usize {
        for b in 0..8 {
            if (a ^ b).count_ones() > 2 {
                continue;
            }
            for k in 0..=100 {
                let target = m.transform_point3(p[a].lerp(p[b], k as f64 / 100.0));
                let h = g.geometry().intersect(
                    &Ray {
                        origin: o,
                        dir: target - o,
                    },
                    f64::INFINITY,
                );
                assert!(
                    h.is_some_and(|h| h.t <= 1.0 + 1e-9),
                    "leak towards {target:?}"
                );
                rays += 1;
            }
        }
    }
    // 8 corner rays per corner + 24 edge and 24 face-diagonal ordered pairs.
    assert_eq!(rays, (8 + 24 + 24) * 101);
}
