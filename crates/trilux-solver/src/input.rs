//! From a loaded scene to what the solver needs.

use trilux_brdf::BsdfParams;
use trilux_color::ColorParam;
use trilux_geometry::Shape;
use trilux_scene::Scene;

use crate::solver::SolverInput;

/// An owned [`SolverInput`]: per shape its geometry, material and emission.
#[derive(Clone, Debug, Default)]
pub struct SceneInput {
    /// The shapes, in scene order.
    pub shapes: Vec<Shape>,
    /// One material per shape.
    pub bsdfs: Vec<BsdfParams>,
    /// One optional area-emitter radiance per shape.
    pub emission: Vec<Option<ColorParam>>,
}

impl SceneInput {
    /// Takes shapes, materials and emitters from a loaded scene (the camera,
    /// film and sampler do not matter to the solve).
    pub fn from_scene(scene: &Scene) -> Self {
        SceneInput {
            shapes: scene.shapes.iter().map(|s| s.shape.clone()).collect(),
            bsdfs: scene.shapes.iter().map(|s| s.bsdf.clone()).collect(),
            emission: scene
                .shapes
                .iter()
                .map(|s| s.emitter.as_ref().map(|e| e.radiance.clone()))
                .collect(),
        }
    }

    /// Borrowed view for [`crate::Solver::new`].
    pub fn as_input(&self) -> SolverInput<'_> {
        SolverInput {
            shapes: &self.shapes,
            bsdfs: &self.bsdfs,
            emission: &self.emission,
        }
    }
}
