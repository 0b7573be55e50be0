//! Scenes and ray workloads shared by the benchmarks and `cargo xtask
//! rays` (generated, no files).
#![allow(dead_code)]

use glam::{DMat4, DQuat, DVec2, DVec3, DVec4};
use trilux_geometry::{ElementForest, Geometry, Ray, Shape, ShapeKind, SurfaceId, TriangleMesh};

/// A UV-tessellated sphere of `n × 2n` quads (4n² triangles) of radius
/// 1 inside a flipped cube [-2, 2]³.
pub fn sphere_in_box(n: u32) -> Vec<Shape> {
    let mut p = Vec::new();
    for i in 0..=n {
        let th = std::f64::consts::PI * i as f64 / n as f64;
        for j in 0..=2 * n {
            let ph = std::f64::consts::PI * j as f64 / n as f64;
            p.push(DVec3::new(
                th.sin() * ph.cos(),
                th.sin() * ph.sin(),
                th.cos(),
            ));
        }
    }
    let w = 2 * n + 1;
    let mut t = Vec::new();
    for i in 0..n {
        for j in 0..2 * n {
            let a = i * w + j;
            t.push([a, a + w, a + w + 1]);
            t.push([a, a + w + 1, a + 1]);
        }
    }
    vec![
        Shape {
            kind: ShapeKind::Mesh(TriangleMesh {
                positions: p,
                normals: None,
                triangles: t,
                face_normals: true,
                texcoords: None,
            }),
            world_from_object: DMat4::IDENTITY,
            flip_normals: false,
        },
        Shape {
            kind: ShapeKind::Cube,
            world_from_object: DMat4::from_scale(DVec3::splat(2.0)),
            flip_normals: true,
        },
    ]
}

fn rect(c: DVec3, hu: DVec3, hv: DVec3) -> Shape {
    let n = hu.cross(hv).normalize();
    Shape {
        kind: ShapeKind::Rectangle,
        world_from_object: DMat4::from_cols(
            hu.extend(0.0),
            hv.extend(0.0),
            n.extend(0.0),
            DVec4::new(c.x, c.y, c.z, 1.0),
        ),
        flip_normals: false,
    }
}

/// A Cornell box of the classic size (≈ 5.5 m), walls facing inwards, two
/// rotated boxes and a ceiling light.
pub fn cornell_box() -> Vec<Shape> {
    let s = 2.75;
    let (x, y, z) = (DVec3::X * s, DVec3::Y * s, DVec3::Z * s);
    let c = DVec3::new(s, s, s);
    let block = |centre: DVec3, size: DVec3, angle: f64| Shape {
        kind: ShapeKind::Cube,
        world_from_object: DMat4::from_scale_rotation_translation(
            0.5 * size,
            DQuat::from_rotation_y(angle),
            centre,
        ),
        flip_normals: false,
    };
    vec![
        rect(c - y, z, x),                                     // floor, normal +y
        rect(c + y, x, z),                                     // ceiling, normal −y
        rect(c - z, x, y),                                     // back, normal +z
        rect(c - x, y, z),                                     // left, normal +x
        rect(c + x, z, y),                                     // right, normal −x
        rect(c + y * 0.999, DVec3::X * 0.65, DVec3::Z * 0.55), // light (faces −y after flip)
        block(
            DVec3::new(1.85, 0.825, 1.69),
            DVec3::new(1.65, 1.65, 1.65),
            -0.29,
        ),
        block(
            DVec3::new(3.68, 1.65, 3.51),
            DVec3::new(1.65, 3.3, 1.65),
            0.29,
        ),
    ]
}

/// Incoherent rays from random points inside the box in random directions,
/// and segments between random pairs of such points.
pub fn workload(geom: &Geometry, count: usize, seed: u64) -> (Vec<Ray>, Vec<(DVec3, DVec3)>) {
    let mut rng = Rng(seed);
    let b = geom.bounds();
    let (lo, hi) = (b.min + 0.05 * b.diagonal(), b.max - 0.05 * b.diagonal());
    let rays = (0..count)
        .map(|_| Ray {
            origin: rng.in_box(lo, hi),
            dir: rng.direction(),
        })
        .collect();
    let segs = (0..count)
        .map(|_| (rng.in_box(lo, hi), rng.in_box(lo, hi)))
        .collect();
    (rays, segs)
}

/// Gather-like rays: from points sampled on the surfaces, into their front
/// hemisphere; shadow segments between points on two random surfaces.
pub fn surface_workload(
    forest: &ElementForest,
    count: usize,
    seed: u64,
) -> (Vec<Ray>, Vec<(DVec3, DVec3)>) {
    let mut rng = Rng(seed);
    let n = forest.geometry().surfaces().len();
    let point = |rng: &mut Rng| {
        let s = SurfaceId(((rng.next_f64() * n as f64) as usize).min(n - 1) as u32);
        forest.sample_surface(s, DVec2::new(rng.next_f64(), rng.next_f64()))
    };
    let rays = (0..count)
        .map(|_| {
            let s = point(&mut rng);
            let d = rng.direction();
            Ray {
                origin: s.point,
                dir: if d.dot(s.normal) < 0.0 { -d } else { d },
            }
        })
        .collect();
    let segs = (0..count)
        .map(|_| (point(&mut rng).point, point(&mut rng).point))
        .collect();
    (rays, segs)
}

/// A small deterministic generator (splitmix64).
pub struct Rng(pub u64);

impl Rng {
    /// Uniform in [0, 1).
    pub fn next_f64(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in the box [lo, hi].
    pub fn in_box(&mut self, lo: DVec3, hi: DVec3) -> DVec3 {
        DVec3::new(self.next_f64(), self.next_f64(), self.next_f64()) * (hi - lo) + lo
    }

    /// Uniform on the unit sphere.
    pub fn direction(&mut self) -> DVec3 {
        let z = 2.0 * self.next_f64() - 1.0;
        let ph = std::f64::consts::TAU * self.next_f64();
        let r = (1.0 - z * z).max(0.0).sqrt();
        DVec3::new(r * ph.cos(), r * ph.sin(), z)
    }
}
