//! Triangle meshes become a handful of charts whose element trees reach
//! every triangle exactly once.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test, bench or example may panic

mod common;

use common::*;
use glam::{DMat4, DVec2, DVec3};
use trilux_geometry::{
    CHART_MAX_TRIANGLES, ElementForest, ElementId, Ray, SurfaceCoord, SurfaceId, SurfaceKind,
};

#[test]
fn an_8192_triangle_sheet_becomes_a_handful_of_charts_covering_every_triangle_once() {
    let (p, t) = curved_sheet(64);
    assert_eq!(t.len(), 8192);
    let mut g = common::forest(&[mesh(p.clone(), t.clone(), DMat4::IDENTITY)]).expect("valid mesh");
    let charts = g.geometry().surfaces().len();
    println!("{charts} charts");
    assert!(
        (8192 / CHART_MAX_TRIANGLES..=24).contains(&charts),
        "{charts} charts"
    );
    assert!(
        g.geometry()
            .surfaces()
            .iter()
            .all(|s| s.kind == SurfaceKind::Chart)
    );
    // The sheet is a dome in the middle (its back sees itself there) and a
    // saddle near the corners.
    assert!(
        g.geometry()
            .surfaces()
            .iter()
            .any(|s| s.back_can_see_itself())
    );
    let total: f64 = g.geometry().surfaces().iter().map(|s| s.area()).sum();
    let exact: f64 = t
        .iter()
        .map(|tri| {
            0.5 * (p[tri[1] as usize] - p[tri[0] as usize])
                .cross(p[tri[2] as usize] - p[tri[0] as usize])
                .length()
        })
        .sum();
    assert!((total - exact).abs() < 1e-12 * exact);

    // Subdivide every tree until each leaf is a single piece.
    let mut covered = vec![0.0f64; t.len()];
    let mut leaves_per_triangle = vec![0u32; t.len()];
    let mut stack: Vec<ElementId> = (0..g.geometry().surfaces().len() as u32)
        .map(|s| g.root(SurfaceId(s)))
        .collect();
    let mut max_depth = 0;
    while let Some(e) = stack.pop() {
        let pieces = g.element_pieces(e).to_vec();
        assert!(!pieces.is_empty());
        if pieces.len() == 1 {
            covered[pieces[0].triangle as usize] += pieces[0].area_fraction();
            leaves_per_triangle[pieces[0].triangle as usize] += 1;
            max_depth = max_depth.max(g.element(e).depth);
            continue;
        }
        let kids = g.subdivide(e);
        let sum: f64 = kids.iter().map(|&k| g.element(k).area).sum();
        assert!(
            (sum - g.element(e).area).abs() < 1e-12 * sum,
            "{sum} vs {} ({} pieces)",
            g.element(e).area,
            pieces.len()
        );
        let n: usize = kids.iter().map(|&k| g.element_pieces(k).len()).sum();
        assert!(kids.iter().all(|&k| !g.element_pieces(k).is_empty()));
        assert!(n == pieces.len() || (pieces.len() < 4 && n == 4));
        stack.extend(kids);
    }
    for (k, c) in covered.iter().enumerate() {
        assert!((c - 1.0).abs() < 1e-12, "triangle {k} covered {c}");
    }
    // Most triangles end as one whole leaf; the others are cut in two.
    let whole = leaves_per_triangle.iter().filter(|&&n| n == 1).count();
    println!("{whole} of 8192 triangles are whole single-piece leaves, max depth {max_depth}");
    assert!(leaves_per_triangle.iter().all(|&n| n == 1 || n == 2));
    // Clusters of at most 768 triangles halve twice per level.
    assert!(max_depth <= 6, "depth {max_depth}");
}

#[test]
fn hits_on_a_chart_locate_the_triangle_they_hit() {
    let (p, t) = curved_sheet(32);
    let mut g = common::forest(&[mesh(p, t, DMat4::IDENTITY)]).expect("valid mesh");
    // Subdivide every chart three levels.
    let mut frontier: Vec<ElementId> = (0..g.geometry().surfaces().len() as u32)
        .map(|s| g.root(SurfaceId(s)))
        .collect();
    for _ in 0..3 {
        frontier = frontier.into_iter().flat_map(|e| g.subdivide(e)).collect();
    }
    for i in 0..50 {
        for j in 0..50 {
            let o = DVec3::new((i as f64 + 0.5) / 50.0, (j as f64 + 0.5) / 50.0, 1.0);
            let h = g
                .geometry()
                .intersect(
                    &Ray {
                        origin: o,
                        dir: -DVec3::Z,
                    },
                    f64::INFINITY,
                )
                .expect("hits the sheet");
            assert!(h.geometric_normal.z > 0.0);
            let leaf = g.locate(h.surface, h.coord);
            assert!(g.element(leaf).is_leaf());
            assert!(g.element_contains(leaf, h.coord));
            assert_eq!(g.element(leaf).surface, h.surface);
            if let SurfaceCoord::Triangle { index, bary } = h.coord {
                assert!(bary.x >= 0.0 && bary.y >= 0.0 && bary.x + bary.y <= 1.0 + 1e-12);
                assert!(g.element_pieces(leaf).iter().any(|p| p.triangle == index));
            } else {
                panic!("chart hit without triangle coordinates");
            }
        }
    }
    // Sampling a chart element gives points on it with a uniform density.
    for &e in &frontier {
        let el = g.element(e).clone();
        for k in 0..16 {
            let s = g.sample_element(e, DVec2::new((k as f64 + 0.5) / 16.0, 0.37));
            assert!((s.pdf_area * el.area - 1.0).abs() < 1e-12);
            assert!(g.element_contains(e, s.coord));
            assert!(el.bounds.padded(1e-12).contains(s.point));
            assert!(s.normal.dot(el.normal) >= el.normal_cone_cos - 1e-12);
        }
    }
}

#[test]
fn concave_and_convex_charts() {
    // A valley z = 0.3 |y| (normals 33° apart, one chart): concave from the
    // front, convex from the back.
    let p = vec![
        DVec3::ZERO,
        DVec3::new(1.0, 0.0, 0.0),
        DVec3::new(1.0, 1.0, 0.3),
        DVec3::new(0.0, 1.0, 0.3),
        DVec3::new(1.0, -1.0, 0.3),
        DVec3::new(0.0, -1.0, 0.3),
    ];
    let t = vec![[0, 1, 2], [0, 2, 3], [1, 0, 5], [1, 5, 4]];
    let g = common::forest(&[mesh(p, t, DMat4::IDENTITY)]).expect("valid mesh");
    assert_eq!(g.geometry().surfaces().len(), 1);
    let s = &g.geometry().surfaces()[0];
    assert!(g.element(g.root(SurfaceId(0))).normal.z > 0.9);
    assert!(s.can_see_itself());
    assert!(!s.back_can_see_itself());
    assert!(!s.is_planar());

    // A tessellated sphere cap (outward normals) is convex from the front.
    let n = 24;
    let mut p = vec![DVec3::Z];
    for i in 1..=n / 2 {
        for j in 0..n {
            let th = 0.6 * i as f64 / (n / 2) as f64;
            let ph = std::f64::consts::TAU * j as f64 / n as f64;
            p.push(DVec3::new(
                th.sin() * ph.cos(),
                th.sin() * ph.sin(),
                th.cos(),
            ));
        }
    }
    let mut t = Vec::new();
    for j in 0..n {
        t.push([0, 1 + j as u32, 1 + ((j + 1) % n) as u32]);
    }
    for i in 0..(n / 2 - 1) {
        for j in 0..n {
            let a = (1 + i * n + j) as u32;
            let b = (1 + i * n + (j + 1) % n) as u32;
            t.push([a, a + n as u32, b + n as u32]);
            t.push([a, b + n as u32, b]);
        }
    }
    let g = common::forest(&[mesh(p, t, DMat4::IDENTITY)]).expect("valid mesh");
    assert!(g.geometry().surfaces().iter().all(|s| !s.can_see_itself()));
    assert!(
        g.geometry()
            .surfaces()
            .iter()
            .all(|s| s.back_can_see_itself())
    );
    assert!(
        g.geometry().surfaces().iter().enumerate().all(|(k, _)| g
            .element(g.root(SurfaceId(k as u32)))
            .normal
            .z
            > 0.0)
    );
}

#[test]
fn locate_agrees_with_a_descent_from_the_root() {
    // Uneven subdivision, then every sampled point is located both by
    // `locate` (which jumps to the deepest element holding the whole
    // triangle) and by descending from the root through the children that
    // contain it.
    let (p, t) = curved_sheet(24);
    let mut g = common::forest(&[mesh(p, t, DMat4::IDENTITY)]).expect("valid mesh");
    let mut frontier: Vec<ElementId> = (0..g.geometry().surfaces().len() as u32)
        .map(|s| g.root(SurfaceId(s)))
        .collect();
    for level in 0..7 {
        let next: Vec<ElementId> = frontier
            .iter()
            .enumerate()
            .filter(|(k, _)| (k + level) % 3 != 0)
            .flat_map(|(_, &e)| g.subdivide(e))
            .collect();
        frontier = next;
    }
    let reference = |g: &ElementForest, s: trilux_geometry::SurfaceId, c: SurfaceCoord| {
        let mut id = g.root(s);
        while let Some(kids) = g.element(id).children() {
            match kids.iter().find(|&&k| g.element_contains(k, c)) {
                Some(&k) => id = k,
                None => break,
            }
        }
        id
    };
    let mut checked = 0;
    for e in 0..g.element_count() as u32 {
        for k in 0..3 {
            let smp = g.sample_element(
                ElementId(e),
                DVec2::new(0.13 + 0.3 * k as f64, 0.71 - 0.2 * k as f64),
            );
            let s = g.element(ElementId(e)).surface;
            assert_eq!(g.locate(s, smp.coord), reference(&g, s, smp.coord));
            checked += 1;
        }
    }
    assert!(checked > 3000, "{checked}");
}

#[test]
fn a_triangle_soup_becomes_a_handful_of_charts() {
    // 8192 separate (unconnected) small triangles scattered over a gently
    // curved sheet, all facing up: never one input surface per triangle.
    let (p, t) = curved_sheet(64);
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    for tri in &t {
        let k = positions.len() as u32;
        let c = (p[tri[0] as usize] + p[tri[1] as usize] + p[tri[2] as usize]) / 3.0;
        for &v in tri {
            positions.push(c + 0.8 * (p[v as usize] - c));
        }
        triangles.push([k, k + 1, k + 2]);
    }
    let mut g = common::forest(&[mesh(positions, triangles, DMat4::IDENTITY)]).expect("valid mesh");
    let charts = g.geometry().surfaces().len();
    println!("{charts} charts for a soup of 8192 triangles");
    assert!((16..=32).contains(&charts), "{charts} charts");
    // Every triangle is in exactly one chart and reachable by locate.
    let mut seen = vec![0u32; 8192];
    for s in 0..charts {
        let root = g.root(SurfaceId(s as u32));
        for p in g.element_pieces(root) {
            seen[p.triangle as usize] += 1;
        }
        let _ = g.subdivide(root);
    }
    assert!(seen.iter().all(|&n| n == 1));
}

/// Copies of one triangle (each with its own corners, in either winding)
/// are one surface: a single BVH primitive and a single chart, so a ray
/// through them tests one triangle, not one per copy (200 000 copies made
/// every ray test 200 000), and the surface's area is the triangle's.
#[test]
fn repeated_triangles_are_one_surface() {
    for copies in [2u32, 4_096] {
        let mut p = Vec::new();
        let mut t = Vec::new();
        for k in 0..copies {
            let first = p.len() as u32;
            p.extend([DVec3::ZERO, DVec3::X, DVec3::Y]);
            t.push(if k % 2 == 0 {
                [first, first + 1, first + 2]
            } else {
                [first + 2, first + 1, first]
            });
        }
        let g = common::forest(&[mesh(p, t, DMat4::IDENTITY)]).expect("valid mesh");
        assert_eq!(g.geometry().primitive_count(), 1, "{copies} copies");
        assert_eq!(g.geometry().surfaces().len(), 1, "{copies} copies");
        let area = g.geometry().surfaces()[0].area();
        assert!((area - 0.5).abs() < 1e-15, "{area}");
    }
}
