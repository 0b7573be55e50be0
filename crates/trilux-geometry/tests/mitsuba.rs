//! Shape conventions against Mitsuba 3: ray hits (t and geometric normal)
//! recorded from Mitsuba 3.9 (scalar_rgb, float32) by
//! `tests/data/mitsuba_hits.py`, for rectangles, cubes, disks, spheres and
//! cylinders and OBJ meshes (one mirrored) with transforms and `flip_normals`.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test, bench or example may panic

use glam::{DMat4, DVec3};
use trilux_geometry::{Geometry, Ray, Shape, ShapeKind};

fn parse(s: &str) -> f64 {
    s.trim().parse().expect("number")
}

#[test]
fn hits_match_mitsuba() {
    let text = include_str!("data/mitsuba_hits.csv");
    let mut shapes: Vec<Geometry> = Vec::new();
    let mut checked = 0;
    let mut hits = 0;
    for line in text
        .lines()
        .filter(|l| !l.starts_with('#') && !l.is_empty())
    {
        let f: Vec<&str> = line.split(',').collect();
        match f[0] {
            "shape" => {
                let m: Vec<f64> = f[3..19].iter().map(|x| parse(x)).collect();
                let rows = DMat4::from_cols_array(&m.try_into().expect("16 numbers"));
                let world_from_object = rows.transpose();
                let extra: Vec<f64> = f[19..].iter().map(|x| parse(x)).collect();
                let kind = match f[1] {
                    "rectangle" => ShapeKind::Rectangle,
                    "cube" => ShapeKind::Cube,
                    "disk" => ShapeKind::Disk,
                    "sphere" => ShapeKind::Sphere {
                        center: DVec3::new(extra[0], extra[1], extra[2]),
                        radius: extra[3],
                    },
                    "cylinder" => ShapeKind::Cylinder {
                        p0: DVec3::new(extra[0], extra[1], extra[2]),
                        p1: DVec3::new(extra[3], extra[4], extra[5]),
                        radius: extra[6],
                    },
                    "obj" => {
                        let nv = extra[0] as usize;
                        let positions = (0..nv)
                            .map(|k| {
                                DVec3::new(extra[1 + 3 * k], extra[2 + 3 * k], extra[3 + 3 * k])
                            })
                            .collect();
                        let nt = extra[1 + 3 * nv] as usize;
                        let base = 2 + 3 * nv;
                        let triangles = (0..nt)
                            .map(|k| [0, 1, 2].map(|c| extra[base + 3 * k + c] as u32))
                            .collect();
                        ShapeKind::Mesh(trilux_geometry::TriangleMesh {
                            positions,
                            normals: None,
                            triangles,
                            face_normals: true,
                            texcoords: None,
                        })
                    }
                    other => panic!("unknown shape {other}"),
                };
                let shape = Shape {
                    kind,
                    world_from_object,
                    flip_normals: f[2] == "1",
                };
                shapes.push(Geometry::build(&[shape]).expect("valid shape"));
            }
            "ray" => {
                let k: usize = f[1].parse().expect("index");
                let v: Vec<f64> = f[2..].iter().map(|x| parse(x)).collect();
                let ray = Ray {
                    origin: DVec3::new(v[0], v[1], v[2]),
                    dir: DVec3::new(v[3], v[4], v[5]),
                };
                let ours = shapes[k].intersect(&ray, f64::INFINITY);
                if v[6] == 0.0 {
                    assert!(
                        ours.is_none(),
                        "shape {k}: Mitsuba misses, trilux hits {ours:?} ({line})"
                    );
                } else {
                    let h = ours.unwrap_or_else(|| {
                        panic!("shape {k}: Mitsuba hits, trilux misses ({line})")
                    });
                    let (t, n) = (v[7], DVec3::new(v[8], v[9], v[10]));
                    // float32 reference: relative 1e-4.
                    assert!(
                        (h.t - t).abs() <= 1e-4 * t.max(1.0),
                        "shape {k}: t {} vs Mitsuba {t}: {line} {:?}",
                        h.t,
                        h
                    );
                    assert!(
                        (h.geometric_normal - n).length() <= 1e-4,
                        "shape {k}: n {:?} vs Mitsuba {n:?}",
                        h.geometric_normal
                    );
                    hits += 1;
                }
                checked += 1;
            }
            other => panic!("unknown line kind {other}"),
        }
    }
    assert_eq!(shapes.len(), 11);
    assert_eq!(checked, 11 * 150);
    assert!(hits > 500, "{hits}");
}
