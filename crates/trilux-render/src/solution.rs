//! What the renderer reads from a view-independent solution
//! ([`RadianceSolution`]): the solver's [`trilux_solver::Solution`], or a
//! stand-in that knows no indirect light ([`DirectOnly`]).

use std::sync::Arc;

use trilux_color::Spectrum;
use trilux_geometry::{ElementForest, ElementId, FaceElement, FaceId};
use trilux_solver::{GatherLink, PreparedScene, SurfaceSite};

/// What the renderer needs of a view-independent solution.
pub trait RadianceSolution<const N: usize>: Sync {
    /// The scene the solution is of (geometry, materials, emitters).
    fn scene(&self) -> &PreparedScene<N>;
    /// The element trees the solution refers to (with the solve's
    /// subdivisions), over the scene's geometry.
    fn forest(&self) -> &ElementForest;
    /// Reflected radiance (emission excluded) leaving `from` towards `to`.
    fn reflected(&self, from: &SurfaceSite, to: &SurfaceSite) -> Spectrum<N>;

    /// True when the solution has gather links (`trilux_solver::gather_links`).
    fn has_links(&self) -> bool {
        false
    }

    /// Calls `f` with every gather link into element `e` and the radiance
    /// its sender sends.
    fn for_each_link(&self, _e: FaceElement, _f: &mut dyn FnMut(&GatherLink, Spectrum<N>)) {}

    /// The final radiance L + Le element `e` of `face` sends (for refining
    /// a sender near the point being shaded).
    fn face_radiance(&self, _face: FaceId, _e: ElementId) -> Spectrum<N> {
        Spectrum::zero()
    }

    /// The stored (glossy) part alone of [`Self::reflected`].
    fn reflected_glossy(&self, _from: &SurfaceSite, _to: &SurfaceSite) -> Spectrum<N> {
        Spectrum::zero()
    }
}

/// A stand-in solution that knows no indirect light (every reflected
/// radiance is zero): the final gather then renders direct lighting only.
/// Also answers a constant, for tests (`constant`).
pub struct DirectOnly<const N: usize> {
    scene: Arc<PreparedScene<N>>,
    forest: ElementForest,
    constant: Spectrum<N>,
}

impl<const N: usize> DirectOnly<N> {
    /// Direct light only: every reflected radiance is zero.
    pub fn new(scene: Arc<PreparedScene<N>>) -> Self {
        Self::constant(scene, Spectrum::zero())
    }

    /// A solution that answers `constant` everywhere (for tests).
    pub fn constant(scene: Arc<PreparedScene<N>>, constant: Spectrum<N>) -> Self {
        DirectOnly {
            forest: ElementForest::new(Arc::clone(scene.geometry())),
            scene,
            constant,
        }
    }
}

impl<const N: usize> RadianceSolution<N> for DirectOnly<N> {
    fn scene(&self) -> &PreparedScene<N> {
        &self.scene
    }
    fn forest(&self) -> &ElementForest {
        &self.forest
    }
    fn reflected(&self, _from: &SurfaceSite, _to: &SurfaceSite) -> Spectrum<N> {
        self.constant
    }
}

/// The solver's solution answers the renderer's queries directly.
impl<const N: usize> RadianceSolution<N> for trilux_solver::Solution<N> {
    fn scene(&self) -> &PreparedScene<N> {
        trilux_solver::Solution::scene(self)
    }
    fn forest(&self) -> &ElementForest {
        trilux_solver::Solution::forest(self)
    }
    fn reflected(&self, from: &SurfaceSite, to: &SurfaceSite) -> Spectrum<N> {
        self.radiance(from, to)
    }
    fn has_links(&self) -> bool {
        !self.all_gather_links().is_empty()
    }
    fn for_each_link(&self, e: FaceElement, f: &mut dyn FnMut(&GatherLink, Spectrum<N>)) {
        for (link, l) in self.gather_links(e) {
            f(link, l);
        }
    }
    fn face_radiance(&self, face: FaceId, e: ElementId) -> Spectrum<N> {
        trilux_solver::Solution::face_radiance(self, face, e)
    }
    fn reflected_glossy(&self, from: &SurfaceSite, to: &SurfaceSite) -> Spectrum<N> {
        self.stored_radiance(from, to)
    }
}
