//! Point-to-element form factors for many points: every element's
//! polygons (quads, triangle pieces) or integration-rule points (curved
//! pieces, disks) computed once, so that a renderer evaluating
//! F(dA_x → element) for every pixel allocates nothing and evaluates no
//! patch.

use glam::DVec3;

use crate::face::FaceElement;
use crate::forest::ElementForest;
use crate::ids::ElementId;

use super::cubature::QDom;
use super::lambert::point_to_polygon_front;
use super::{element_domains, element_polygons_up_to, kernel};

/// One element's shape for point form factors.
#[derive(Clone, Copy, Debug)]
enum Shape {
    /// Polygons `first..first + count` of the polygon arena.
    Polygons { first: u32, count: u32 },
    /// Rule points `first..first + count` of the point arena.
    Points { first: u32, count: u32 },
}

/// A planar polygon (up to 4 corners) with its front unit normal.
#[derive(Clone, Copy, Debug)]
struct Polygon {
    v: [DVec3; 4],
    len: u8,
    front: DVec3,
}

/// Every element's polygons or rule points, for [`PointFormFactors::eval`].
#[derive(Clone, Debug)]
pub struct PointFormFactors {
    shapes: Vec<Shape>,
    polygons: Vec<Polygon>,
    /// (point, front normal, weight) of the degree-5 rules.
    points: Vec<(DVec3, DVec3, f64)>,
}

impl PointFormFactors {
    /// The shapes of every element of `forest`.
    pub fn new(forest: &ElementForest) -> Self {
        let mut out = PointFormFactors {
            shapes: Vec::with_capacity(forest.element_count()),
            polygons: Vec::new(),
            points: Vec::new(),
        };
        for e in 0..forest.element_count() as u32 {
            let fe = FaceElement::front(ElementId(e));
            let shape = match element_polygons_up_to(forest, fe, usize::MAX) {
                Some(polys) => {
                    let first = out.polygons.len() as u32;
                    out.polygons.extend(polys.iter().map(|p| Polygon {
                        v: p.v,
                        len: p.len as u8,
                        front: p.n,
                    }));
                    Shape::Polygons {
                        first,
                        count: polys.len() as u32,
                    }
                }
                None => {
                    let first = out.points.len() as u32;
                    let doms = element_domains(forest, fe).unwrap_or_default();
                    out.points.extend(doms.iter().flat_map(QDom::points));
                    Shape::Points {
                        first,
                        count: out.points.len() as u32 - first,
                    }
                }
            };
            out.shapes.push(shape);
        }
        out
    }

    /// F(dA_x → to) for a point `x` with unit normal `n` (the same value as
    /// [`super::point_form_factor`]).
    pub fn eval(&self, x: DVec3, n: DVec3, to: FaceElement) -> f64 {
        let sign = to.side.sign();
        let f = match self.shapes.get(to.element.index()) {
            Some(&Shape::Polygons { first, count }) => self.polygons
                [first as usize..(first + count) as usize]
                .iter()
                .map(|p| point_to_polygon_front(x, n, &p.v[..usize::from(p.len)], sign * p.front))
                .sum::<f64>(),
            Some(&Shape::Points { first, count }) => self.points
                [first as usize..(first + count) as usize]
                .iter()
                .map(|&(y, ny, w)| w * kernel(x, n, y, sign * ny))
                .sum::<f64>(),
            None => 0.0,
        };
        f.min(1.0)
    }
}
