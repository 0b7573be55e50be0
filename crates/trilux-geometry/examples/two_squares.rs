//! Form factor between two parallel unit squares one unit apart, against the
//! closed form (docs/validation.md (a): 0.199825), then with a blocker plate
//! halfway between them.
//!
//! Run: `cargo run -p trilux-geometry --release --example two_squares`
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test, bench or example may panic

use glam::{DMat4, DVec4};
use trilux_geometry::{
    ElementForest, FaceElement, Geometry, Shape, ShapeKind, SurfaceId, Visibility,
    form_factor_front,
};

/// The rectangle [-1,1]² scaled by `half`, at height `z`, facing down if
/// `flip`.
fn square(half: f64, z: f64, flip: bool) -> Shape {
    Shape {
        kind: ShapeKind::Rectangle,
        world_from_object: DMat4::from_cols(
            DVec4::new(half, 0.0, 0.0, 0.0),
            DVec4::new(0.0, half, 0.0, 0.0),
            DVec4::new(0.0, 0.0, 1.0, 0.0),
            DVec4::new(0.0, 0.0, z, 1.0),
        ),
        flip_normals: flip,
    }
}

fn main() -> Result<(), trilux_geometry::GeometryError> {
    let geom = ElementForest::new(Geometry::build_shared(&[
        square(0.5, 0.0, false),
        square(0.5, 1.0, true),
    ])?);
    let (a, b) = (geom.root(SurfaceId(0)), geom.root(SurfaceId(1)));
    let f = form_factor_front(&geom, a, b);
    println!(
        "F(square → square) = {:.6} ± {:.1e}   closed form 0.199825",
        f.value, f.error
    );
    println!(
        "visibility         = {:.3}",
        Visibility::new(&geom, None).fraction(FaceElement::front(a), FaceElement::front(b), 64)
    );

    let blocked = ElementForest::new(Geometry::build_shared(&[
        square(0.5, 0.0, false),
        square(0.5, 1.0, true),
        square(0.25, 0.5, false),
    ])?);
    let v = Visibility::new(&blocked, None).fraction(
        FaceElement::front(a),
        FaceElement::front(b),
        1024,
    );
    println!("with a 0.5×0.5 blocker halfway: visibility = {v:.3}");
    Ok(())
}
