//! The link gather's techniques against closed forms and brute force.
//!
//! The scene: a diffuse floor (4 × 4, ρ = 0.5) under a square emitter
//! (1 × 1, Le = 1, black, facing down at height 1), optionally with a black
//! square occluder between them. Nothing but the floor reflects, so the
//! radiance arriving at a floor point is exactly Le · F(x → light) · V,
//! which the link sum Σ L_i F(x → i) V must give:
//! - fully visible: F by the closed form of a point under a parallel
//!   rectangle (sums of the corner formula, Hottel's; independent of
//!   trilux's polygon code). Far senders are interpolated bilinearly in
//!   the logarithm over the floor's leaves (side 1/8): over the far part of
//!   this floor the closed form's own interpolation error is at most
//!   0.33 % (evaluated on a 7 × 7 grid in every far leaf; 0.62 % for a
//!   linear interpolation, which this test catches at (−1.8, 0)), so 0.4 %.
//! - in the occluder's penumbra: the traced estimate averaged over 4096
//!   sample indices against 10⁶ stratified area samples of the light with
//!   shadow rays (both errors stated as 4σ of their own samples).
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test, bench or example may panic

use std::f64::consts::PI;

use glam::{DVec2, DVec3};
use trilux::prepare;
use trilux_geometry::{FaceElement, PointFormFactors, Side, SurfaceCoord, SurfaceId};
use trilux_render::LinkVisibility;
use trilux_render::link_sum::{LinkCache, LinkField, Receiver, link_sum};
use trilux_render::{GatherStats, PixelSampler};
use trilux_solver::{Quality, Solution, Solver, SolverSettings};

fn scene_xml(occluder: bool) -> String {
    let occ = if occluder {
        r#"<shape type="rectangle">
            <transform name="to_world">
                <scale x="0.2" y="0.2" z="0.2"/>
                <rotate x="1" angle="90"/>
                <translate x="0.3" y="0.5" z="0"/>
            </transform>
            <bsdf type="diffuse"><rgb name="reflectance" value="0"/></bsdf>
        </shape>"#
    } else {
        ""
    };
    format!(
        r#"<scene version="3.0.0">
        <shape type="rectangle">
            <transform name="to_world">
                <scale x="2" y="2" z="2"/>
                <rotate x="1" angle="-90"/>
            </transform>
            <bsdf type="diffuse"><rgb name="reflectance" value="0.5"/></bsdf>
        </shape>
        <shape type="rectangle">
            <transform name="to_world">
                <scale x="0.5" y="0.5" z="0.5"/>
                <rotate x="1" angle="90"/>
                <translate y="1"/>
            </transform>
            <bsdf type="diffuse"><rgb name="reflectance" value="0"/></bsdf>
            <emitter type="area"><rgb name="radiance" value="1"/></emitter>
        </shape>
        {occ}
    </scene>"#
    )
}

fn solve(occluder: bool) -> Solution<3> {
    let scene = trilux_scene::load_str(&scene_xml(occluder), "links.xml").unwrap();
    let prepared = prepare::<3>(&scene).unwrap();
    Solver::new(prepared, SolverSettings::preset(Quality::Default))
        .unwrap()
        .solve(|_| {})
}

/// F from a point (normal up) to the rectangle [a0, a1] × [b0, b1] in a
/// parallel plane at height h above it (coordinates relative to the
/// point): Hottel's corner formula summed with signs.
fn rect_ff(a: (f64, f64), b: (f64, f64), h: f64) -> f64 {
    let corner = |x: f64, y: f64| {
        let (x, y) = (x / h, y / h);
        let (sx, sy) = ((1.0 + x * x).sqrt(), (1.0 + y * y).sqrt());
        (x / sx * (y / sx).atan() + y / sy * (x / sy).atan()) / (2.0 * PI)
    };
    corner(a.1, b.1) - corner(a.0, b.1) - corner(a.1, b.0) + corner(a.0, b.0)
}

/// The floor point at (u, v) ∈ [0, 1]² with its receiver.
fn receiver(solution: &Solution<3>, u: f64, v: f64) -> Receiver {
    let forest = solution.forest();
    let floor = SurfaceId(0);
    let s = forest.sample_element(forest.root(floor), DVec2::new(u, v));
    let SurfaceCoord::Uv(_) = s.coord else {
        panic!("a rectangle has (u, v) coordinates")
    };
    Receiver {
        x: s.point,
        n: s.normal,
        coord: s.coord,
        leaf: FaceElement::new(forest.locate(floor, s.coord), Side::Front),
    }
}

fn field(solution: &Solution<3>) -> LinkField<3> {
    let forest = solution.forest();
    LinkField::new(PointFormFactors::new(forest), forest.element_count())
}

#[test]
fn link_sum_under_a_square_light_is_lamberts_closed_form() {
    let solution = solve(false);
    let field = field(&solution);
    let mut cache = LinkCache::<3>::default();
    let mut stats = GatherStats::default();
    let mut worst: f64 = 0.0;
    for i in 0..9 {
        for j in 0..9 {
            let (u, v) = (0.05 + 0.1125 * f64::from(i), 0.05 + 0.1125 * f64::from(j));
            let r = receiver(&solution, u, v);
            assert!((r.x.y).abs() < 1e-9 && r.n.dot(DVec3::Y) > 0.999);
            cache.clear();
            let got = link_sum(
                &solution,
                &field,
                &r,
                LinkVisibility::Cached,
                &mut cache,
                &mut stats,
            );
            let want = rect_ff(
                (-0.5 - r.x.x, 0.5 - r.x.x),
                (-0.5 - r.x.z, 0.5 - r.x.z),
                1.0,
            );
            for c in got.0 {
                let rel = (c - want).abs() / want;
                worst = worst.max(rel);
                assert!(
                    rel <= 0.004,
                    "at {:?}: link sum {c}, closed form {want}",
                    r.x
                );
            }
        }
    }
    println!("largest relative difference {worst:.2e}");
}

#[test]
fn traced_partial_visibility_is_unbiased_in_a_penumbra() {
    let solution = solve(true);
    let field = field(&solution);
    let geometry = solution.forest().geometry();
    let light = solution.forest().root(SurfaceId(1));
    // Floor points under the occluder's edge (penumbra) and beside it.
    for (u, v) in [(0.575, 0.5), (0.6, 0.55), (0.55, 0.45)] {
        let r = receiver(&solution, u, v);
        let (n, k) = (4096u32, 1000u32);
        let (mut sum, mut sum2) = (0.0, 0.0);
        let mut stats = GatherStats::default();
        for s in 0..n {
            let mut sampler = PixelSampler::new(7, 3, 5);
            sampler.start_sample(s);
            let mut cache = LinkCache::<3>::default();
            let vis = LinkVisibility::Traced {
                sampler: &sampler,
                dim: trilux_render::sampler::dims::LINKS,
            };
            let e = link_sum(&solution, &field, &r, vis, &mut cache, &mut stats).0[0];
            sum += e;
            sum2 += e * e;
        }
        let mean = sum / f64::from(n);
        let sd_links = ((sum2 / f64::from(n) - mean * mean).max(0.0) / f64::from(n)).sqrt();
        // Brute force: k × k stratified points on the light.
        let (mut b, mut b2) = (0.0, 0.0);
        let area = 1.0;
        for i in 0..k {
            for j in 0..k {
                let uu = DVec2::new(
                    (f64::from(i) + 0.5) / f64::from(k),
                    (f64::from(j) + 0.5) / f64::from(k),
                );
                let y = solution.forest().sample_element(light, uu);
                let d = y.point - r.x;
                let d2 = d.length_squared();
                let w = d / d2.sqrt();
                let g = r.n.dot(w).max(0.0) * y.normal.dot(-w).max(0.0) / (PI * d2) * area;
                let v = if geometry.occluded(r.x, y.point) {
                    0.0
                } else {
                    1.0
                };
                b += g * v;
                b2 += (g * v) * (g * v);
            }
        }
        let m = f64::from(k * k);
        let brute = b / m;
        let sd_brute = ((b2 / m - brute * brute).max(0.0) / m).sqrt();
        let open = rect_ff(
            (-0.5 - r.x.x, 0.5 - r.x.x),
            (-0.5 - r.x.z, 0.5 - r.x.z),
            1.0,
        );
        println!(
            "at {:?}: links {mean:.6} ± {sd_links:.1e}, brute force {brute:.6}, unoccluded {open:.6}",
            r.x
        );
        assert!(brute < 0.97 * open, "the point is not in a penumbra");
        assert!(
            (mean - brute).abs() <= 4.0 * (sd_links + sd_brute) + 1e-6,
            "links {mean} against brute force {brute}"
        );
    }
}

#[test]
fn the_solution_links_are_what_the_gather_reads() {
    // The floor's two-point radiance under the light is ρ E/π, and its
    // links must bring that same light: the link sum at the leaves'
    // centres, times ρ, averages to the solution's radiance over the floor.
    let solution = solve(false);
    let field = field(&solution);
    let forest = solution.forest();
    let mut cache = LinkCache::<3>::default();
    let mut stats = GatherStats::default();
    let (mut links, mut solved, mut area) = (0.0, 0.0, 0.0);
    let face = trilux_geometry::FaceId::new(SurfaceId(0), Side::Front);
    for leaf in forest.leaves(forest.root(SurfaceId(0))) {
        let e = forest.element(leaf);
        let c = forest.sample_element(leaf, DVec2::splat(0.5));
        let r = Receiver {
            x: c.point,
            n: c.normal,
            coord: c.coord,
            leaf: FaceElement::new(leaf, Side::Front),
        };
        cache.clear();
        let s = link_sum(
            &solution,
            &field,
            &r,
            LinkVisibility::Cached,
            &mut cache,
            &mut stats,
        );
        links += 0.5 * s.0[0] * e.area;
        solved += solution.face_radiance(face, leaf).0[0] * e.area;
        area += e.area;
    }
    let ratio = links / solved;
    println!(
        "floor mean: links {:.5}, solution {:.5}",
        links / area,
        solved / area
    );
    // The solve's form factors are cubatures over element pairs; 1 % bounds
    // their error on this scene's elements (docs/validation.md).
    assert!((ratio - 1.0).abs() <= 0.01, "ratio {ratio}");
}
