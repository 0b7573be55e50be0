//! TEMPORARY: the number of input surfaces, until trilux-geometry's
//! `SceneGeometry::build(..).surfaces().len()` is merged (branch `geometry`).
//! Replace every use of [`input_surfaces_provisional`] then.

use trilux_geometry::ShapeKind;
use trilux_scene::Scene;

/// TEMPORARY estimate: one surface per planar patch, 6 per cube, and the
/// piece counts the geometry issue suggests for curved shapes (8 sphere
/// pieces, 4 cylinder pieces) and meshes (one chart per 256 triangles).
pub fn input_surfaces_provisional(scene: &Scene) -> usize {
    scene
        .shapes
        .iter()
        .map(|s| match &s.shape.kind {
            ShapeKind::Rectangle | ShapeKind::Disk => 1,
            ShapeKind::Cube => 6,
            ShapeKind::Sphere { .. } => 8,
            ShapeKind::Cylinder { .. } => 4,
            ShapeKind::Mesh(m) => m.triangles.len().div_ceil(256),
        })
        .sum()
}
