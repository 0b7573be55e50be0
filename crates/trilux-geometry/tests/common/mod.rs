//! Shape builders shared by the integration tests.
#![allow(dead_code)]

use glam::{DMat4, DVec3, DVec4};
use trilux_geometry::{Shape, ShapeKind, TriangleMesh};

/// A rectangle with centre `c` and half-edge vectors `hu`, `hv` (orthogonal);
/// its front normal is `hu × hv` (or the opposite when `flip`).
pub fn rect(c: DVec3, hu: DVec3, hv: DVec3, flip: bool) -> Shape {
    let n = hu.cross(hv).normalize();
    Shape {
        kind: ShapeKind::Rectangle,
        world_from_object: DMat4::from_cols(
            hu.extend(0.0),
            hv.extend(0.0),
            n.extend(0.0),
            c.extend(1.0),
        ),
        flip_normals: flip,
    }
}

/// A disk of radius `r` centred at `c` in the plane spanned by the unit
/// vectors `u`, `v`; front normal u × v (or the opposite when `flip`).
pub fn disk(c: DVec3, u: DVec3, v: DVec3, r: f64, flip: bool) -> Shape {
    let n = u.cross(v).normalize();
    Shape {
        kind: ShapeKind::Disk,
        world_from_object: DMat4::from_cols(
            (r * u).extend(0.0),
            (r * v).extend(0.0),
            n.extend(0.0),
            c.extend(1.0),
        ),
        flip_normals: flip,
    }
}

/// An affine map from a 3×3 linear part (columns) and a translation.
pub fn affine(x: DVec3, y: DVec3, z: DVec3, t: DVec3) -> DMat4 {
    DMat4::from_cols(
        x.extend(0.0),
        y.extend(0.0),
        z.extend(0.0),
        DVec4::new(t.x, t.y, t.z, 1.0),
    )
}

pub fn cube(m: DMat4, flip: bool) -> Shape {
    Shape {
        kind: ShapeKind::Cube,
        world_from_object: m,
        flip_normals: flip,
    }
}

pub fn sphere(c: DVec3, r: f64, m: DMat4, flip: bool) -> Shape {
    Shape {
        kind: ShapeKind::Sphere {
            center: c,
            radius: r,
        },
        world_from_object: m,
        flip_normals: flip,
    }
}

pub fn cylinder(p0: DVec3, p1: DVec3, r: f64, m: DMat4, flip: bool) -> Shape {
    Shape {
        kind: ShapeKind::Cylinder { p0, p1, radius: r },
        world_from_object: m,
        flip_normals: flip,
    }
}

pub fn mesh(positions: Vec<DVec3>, triangles: Vec<[u32; 3]>, m: DMat4) -> Shape {
    Shape {
        kind: ShapeKind::Mesh(TriangleMesh {
            positions,
            normals: None,
            triangles,
            face_normals: false,
            texcoords: None,
        }),
        world_from_object: m,
        flip_normals: false,
    }
}

/// A gently curved sheet of `n × n` quads (2 triangles each) over
/// [0, 1]², z = 0.15 sin(πx) sin(πy); normals towards +z.
pub fn curved_sheet(n: u32) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let mut p = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            let x = i as f64 / n as f64;
            let y = j as f64 / n as f64;
            let z = 0.15 * (std::f64::consts::PI * x).sin() * (std::f64::consts::PI * y).sin();
            p.push(DVec3::new(x, y, z));
        }
    }
    let mut t = Vec::new();
    let idx = |i: u32, j: u32| j * (n + 1) + i;
    for j in 0..n {
        for i in 0..n {
            t.push([idx(i, j), idx(i + 1, j), idx(i + 1, j + 1)]);
            t.push([idx(i, j), idx(i + 1, j + 1), idx(i, j + 1)]);
        }
    }
    (p, t)
}

/// The element forest (roots only) of a scene made of `shapes`.
pub fn forest(
    shapes: &[Shape],
) -> Result<trilux_geometry::ElementForest, trilux_geometry::GeometryError> {
    Ok(trilux_geometry::ElementForest::new(
        trilux_geometry::Geometry::build_shared(shapes)?,
    ))
}
