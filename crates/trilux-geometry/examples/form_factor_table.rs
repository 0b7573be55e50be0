//! Prints trilux's form factors beside the closed forms of
//! docs/validation.md, at the default accuracy and at rel_tol 1e-7.
//!
//! Run: `cargo run -p trilux-geometry --release --example form_factor_table`
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test, bench or example may panic

use glam::{DMat4, DVec3};
use trilux_geometry::{
    ElementForest, FaceElement, FormFactorOptions, Geometry, Shape, ShapeKind, SurfaceId,
    form_factor, form_factor_front,
};

fn rect(c: DVec3, hu: DVec3, hv: DVec3, flip: bool) -> Shape {
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

fn disk(c: DVec3, r: f64, flip: bool) -> Shape {
    Shape {
        kind: ShapeKind::Disk,
        world_from_object: DMat4::from_cols(
            (r * DVec3::X).extend(0.0),
            (r * DVec3::Y).extend(0.0),
            DVec3::Z.extend(0.0),
            c.extend(1.0),
        ),
        flip_normals: flip,
    }
}

fn row(name: &str, shapes: &[Shape], exact: f64) -> Result<(), trilux_geometry::GeometryError> {
    let g = ElementForest::new(Geometry::build_shared(shapes)?);
    let (a, b) = (g.root(SurfaceId(0)), g.root(SurfaceId(1)));
    let t0 = std::time::Instant::now();
    let f = form_factor_front(&g, a, b);
    let dt = t0.elapsed().as_secs_f64() * 1e6;
    let tight = form_factor(
        &g,
        FaceElement::front(a),
        FaceElement::front(b),
        &FormFactorOptions {
            rel_tol: 1e-7,
            max_depth: 12,
            samples: 64,
        },
    );
    println!(
        "{name:<44} {exact:>9.6} {:>9.6} {:>9.1e} {:>9.1e} {dt:>7.1} | {:>9.6} {:>9.1e} {:>9.1e}",
        f.value,
        (f.value - exact).abs() / exact,
        f.error,
        tight.value,
        (tight.value - exact).abs() / exact,
        tight.error
    );
    Ok(())
}

fn main() -> Result<(), trilux_geometry::GeometryError> {
    let (x, y, z) = (DVec3::X, DVec3::Y, DVec3::Z);
    println!(
        "{:<44} {:>9} {:>9} {:>9} {:>9} {:>7} | {:>9} {:>9} {:>9}",
        "case", "exact", "default", "rel.err", "est.err", "µs", "tight", "rel.err", "est.err"
    );
    for (a, b, c, f) in [
        (1.0, 1.0, 1.0, 0.199825),
        (2.0, 2.0, 1.0, 0.415253),
        (0.5, 0.5, 1.0, 0.068590),
        (1.0, 2.0, 1.0, 0.285875),
        (10.0, 10.0, 1.0, 0.826995),
    ] {
        row(
            &format!("parallel {a}×{b} at {c}"),
            &[
                rect(DVec3::ZERO, 0.5 * a * x, 0.5 * b * y, false),
                rect(c * z, 0.5 * a * x, 0.5 * b * y, true),
            ],
            f,
        )?;
    }
    for (l, h, w, f) in [
        (1.0, 1.0, 1.0, 0.200044),
        (1.0, 2.0, 1.0, 0.232853),
        (1.0, 1.0, 2.0, 0.116426),
        (2.0, 1.0, 1.0, 0.240636),
        (1.0, 0.5, 1.0, 0.146187),
    ] {
        row(
            &format!("perpendicular l={l} h={h} w={w}"),
            &[
                rect(
                    DVec3::new(0.5 * l, 0.5 * w, 0.0),
                    0.5 * l * x,
                    0.5 * w * y,
                    false,
                ),
                rect(
                    DVec3::new(0.5 * l, 0.0, 0.5 * h),
                    0.5 * l * x,
                    -0.5 * h * z,
                    false,
                ),
            ],
            f,
        )?;
    }
    for (r, h) in [(1.0, 1.0), (0.5, 2.0)] {
        row(
            &format!("patch 2e-3 to coaxial disk R={r} h={h}"),
            &[
                rect(DVec3::ZERO, 1e-3 * x, 1e-3 * y, false),
                disk(h * z, r, true),
            ],
            r * r / (r * r + h * h),
        )?;
    }
    for (r1, r2, h) in [(1.0, 1.0, 1.0), (0.5, 1.5, 1.0)] {
        let (a, b) = (r1 / h, r2 / h);
        let xx: f64 = 1.0 + (1.0 + b * b) / (a * a);
        let exact = 0.5 * (xx - (xx * xx - 4.0 * (b / a) * (b / a)).sqrt());
        row(
            &format!("disk r={r1} to disk r={r2} at {h}"),
            &[disk(DVec3::ZERO, r1, false), disk(h * z, r2, true)],
            exact,
        )?;
    }
    Ok(())
}
