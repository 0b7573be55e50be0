//! Mitsuba's `constant` emitter: light of one radiance arriving from every
//! direction at infinity (a uniform sky).
//!
//! Radiance does not change along a ray, so a closed surface around the
//! whole scene that emits that radiance inward, and absorbs what reaches
//! it, is the same light for every point and direction inside it: a ray
//! that leaves the scene meets it and brings back exactly the radiance it
//! would have brought from infinity, and light that leaves the scene is
//! lost either way. The loader therefore stands the environment in as such
//! an *enclosure*: a box 2 % beyond the scene's bounds and the camera's
//! position, black, emitting inward. The solver shoots from it and the
//! renderer samples it as it does any area light, with no code of their
//! own. It must be a tight box: the solver's smallest element (MinArea)
//! is a fraction of the scene's diagonal, which a distant sphere would
//! enlarge. Its one limit: a view from outside the box (a camera moved
//! there after loading) sees the box's black back. docs/scene-format.md,
//! "Environment".

use glam::{DMat4, DVec3};
use trilux_brdf::BsdfParams;
use trilux_color::ColorParam;
use trilux_geometry::{Bounds, Shape, ShapeKind};

use crate::error::{Result, SceneError};
use crate::props::Props;
use crate::scene::{AreaEmitter, Environment, Scene, SceneShape};
use crate::xml::Element;

/// Builds a top-level `<emitter type="constant">`.
pub(crate) fn constant(e: &Element) -> Result<Environment> {
    e.check_attrs(&["type", "id", "name"])?;
    let props = Props::new(e)?;
    props.no_objects()?;
    props.float("sampling_weight")?;
    let radiance = crate::material::emitted_strength(&props, "radiance")?;
    props.finish()?;
    Ok(Environment {
        radiance,
        map: None,
        shape: None,
        location: e.loc.clone(),
    })
}

/// The error for a second environment (Mitsuba 3 allows one).
pub(crate) fn second(e: &Element, first: &Environment) -> SceneError {
    SceneError::at(
        &e.loc,
        format!(
            "only one environment emitter is allowed (the first is at line {})",
            first.location.line
        ),
    )
}

/// Appends the enclosure of the scene's environment, if it has one (module
/// docs); every mesh must be read already.
pub(crate) fn enclose(scene: &mut Scene) {
    let Some(env) = &scene.environment else {
        return;
    };
    if env.map.is_some() {
        // An envmap is a distant light, not a box (`crate::envmap`).
        return;
    }
    let mut bounds = scene
        .shapes
        .iter()
        .fold(Bounds::EMPTY, |b, s| b.union(world_bounds(&s.shape)));
    if let Some(c) = &scene.camera {
        bounds = bounds.with_point(c.origin);
    }
    if bounds.is_empty() {
        // No shape and no camera: a unit box around the origin.
        bounds = Bounds::from_points([DVec3::splat(-1.0), DVec3::splat(1.0)]);
    }
    let (lo, hi) = (bounds.min, bounds.max);
    let centre = 0.5 * (lo + hi);
    let diagonal = (hi - lo).length().max(1e-3);
    // 2 % beyond the bounds on each axis, and at least 0.1 % of the
    // diagonal (a flat scene still gets a box with volume).
    let half = 0.5 * (hi - lo) * 1.02 + DVec3::splat(1e-3 * diagonal);
    let shape = SceneShape {
        id: None,
        shape: Shape {
            kind: ShapeKind::Cube,
            world_from_object: DMat4::from_translation(centre) * DMat4::from_scale(half),
            flip_normals: true,
        },
        bsdf: BsdfParams::Diffuse {
            reflectance: ColorParam::Float(0.0),
        },
        emitter: Some(AreaEmitter {
            radiance: env.radiance.clone(),
            location: env.location.clone(),
        }),
        textures: Vec::new(),
        transmission: None,
        location: env.location.clone(),
    };
    let index = scene.shapes.len();
    scene.shapes.push(shape);
    if let Some(env) = &mut scene.environment {
        env.shape = Some(index);
    }
}

/// A box holding the shape in world space: the world images of its object
/// box's corners (exact for meshes' vertices' box up to the transform).
fn world_bounds(shape: &Shape) -> Bounds {
    let object = match &shape.kind {
        ShapeKind::Rectangle | ShapeKind::Disk => {
            Bounds::from_points([DVec3::new(-1.0, -1.0, 0.0), DVec3::new(1.0, 1.0, 0.0)])
        }
        ShapeKind::Cube => Bounds::from_points([DVec3::splat(-1.0), DVec3::splat(1.0)]),
        ShapeKind::Sphere { center, radius } => {
            Bounds::from_points([*center - *radius, *center + *radius])
        }
        ShapeKind::Cylinder { p0, p1, radius } => {
            Bounds::from_points([p0.min(*p1) - *radius, p0.max(*p1) + *radius])
        }
        ShapeKind::Mesh(m) => Bounds::from_points(m.positions.iter().copied()),
    };
    if object.is_empty() || !(object.min.is_finite() && object.max.is_finite()) {
        return Bounds::EMPTY;
    }
    let (a, b) = (object.min, object.max);
    Bounds::from_points((0..8).map(|k| {
        let corner = DVec3::new(
            if k & 1 == 0 { a.x } else { b.x },
            if k & 2 == 0 { a.y } else { b.y },
            if k & 4 == 0 { a.z } else { b.z },
        );
        shape.world_from_object.transform_point3(corner)
    }))
}
