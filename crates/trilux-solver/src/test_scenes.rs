//! Small scenes for the unit tests of refinement, push-pull and the
//! cluster cut: squares and plain materials, prepared into a [`Setup`].
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests may panic

use std::f64::consts::PI;
use std::sync::Arc;

use glam::{DMat4, DVec3};
use trilux_brdf::{BsdfParams, Distribution, RoughConductorParams};
use trilux_color::ColorParam;
use trilux_geometry::{ElementForest, ElementId, FaceElement, FaceId, Shape, ShapeKind, Side};

use crate::prepared::{PreparedScene, SceneDescription};
use crate::settings::{Quality, SolverSettings};
use crate::setup::Setup;

/// A square of side `size` centred at `centre`, facing down (−z) or up
/// (+z).
pub fn square(centre: DVec3, size: f64, down: bool) -> Shape {
    let rot = if down {
        DMat4::from_rotation_x(PI)
    } else {
        DMat4::IDENTITY
    };
    Shape {
        kind: ShapeKind::Rectangle,
        world_from_object: DMat4::from_translation(centre)
            * rot
            * DMat4::from_scale(DVec3::splat(0.5 * size)),
        flip_normals: false,
    }
}

/// A Lambertian material of reflectance `r`.
pub fn diffuse(r: f64) -> BsdfParams {
    BsdfParams::Diffuse {
        reflectance: ColorParam::Float(r),
    }
}

/// A GGX rough conductor of roughness `alpha` that reflects everything.
pub fn glossy(alpha: f64) -> BsdfParams {
    BsdfParams::RoughConductor(RoughConductorParams {
        distribution: Distribution::Ggx,
        alpha,
        eta_k: None,
        specular_reflectance: ColorParam::Float(1.0),
    })
}

/// The default settings with every surface subdivided to `max_depth`
/// (MinArea out of the way).
pub fn settings(max_depth: u32) -> SolverSettings {
    let mut s = SolverSettings::preset(Quality::Default);
    s.max_depth = max_depth;
    s.min_area_fraction = 1e-12;
    s
}

/// The setup of a scene of `shapes`, each with its material and emitted
/// radiance (`None`: no emission).
pub fn setup(
    shapes: &[Shape],
    bsdfs: &[BsdfParams],
    emission: &[Option<f64>],
    settings: SolverSettings,
) -> Setup<3> {
    let emission: Vec<Option<ColorParam>> =
        emission.iter().map(|e| e.map(ColorParam::Float)).collect();
    let desc = SceneDescription {
        shapes,
        bsdfs,
        emission: &emission,
    };
    let scene = Arc::new(PreparedScene::new(&desc).expect("prepares"));
    Setup::new(scene, settings).expect("sets up")
}

/// The root of `face`'s surface, as a face element.
pub fn root(forest: &ElementForest, face: FaceId) -> FaceElement {
    face.of(forest.root(face.surface()))
}

/// The front face of input surface `s`.
pub fn front(s: u32) -> FaceId {
    FaceId::new(trilux_geometry::SurfaceId(s), Side::Front)
}

/// Every leaf element under `e`.
pub fn leaves(forest: &ElementForest, e: ElementId) -> Vec<ElementId> {
    let mut out = Vec::new();
    let mut stack = vec![e];
    while let Some(x) = stack.pop() {
        match forest.element(x).children() {
            Some(c) => stack.extend(c),
            None => out.push(x),
        }
    }
    out
}
