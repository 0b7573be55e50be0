//! The discretisation: how finely each input surface may be subdivided, and
//! the element trees subdivided to it (paper §4.2's "potential elements").
//!
//! The depth limit of every input surface follows from the global limit
//! and MinArea ([`SolverSettings::max_depth`],
//! [`SolverSettings::min_area_fraction`]); the element trees are
//! subdivided uniformly to those limits before the first shot, so that
//! they stay immutable (and shareable across threads) during the solve.
//! The solver, its solution and the solution file share this one value: a
//! file records the depth limits it was made with, and its reader builds
//! the discretisation here and compares, so a change to how surfaces are
//! discretised cannot silently change what a saved file means.

use std::sync::Arc;

use trilux_geometry::{ElementForest, Geometry, SurfaceId};

use crate::settings::SolverSettings;

/// The depth limit of every input surface and the element trees
/// subdivided to them.
pub(crate) struct Discretisation {
    /// Depth limit per input surface, in surface order.
    depths: Vec<u32>,
    /// The element trees, every surface subdivided to its depth limit.
    forest: ElementForest,
}

impl Discretisation {
    /// The discretisation of `geometry` under `settings`.
    pub fn new(geometry: &Arc<Geometry>, settings: &SolverSettings) -> Self {
        Self::with_limits(geometry, Self::limits(geometry, settings))
    }

    /// The depth limits alone, cheap beside the trees: a solution file's
    /// reader compares them with the file's before building anything.
    pub fn limits(geometry: &Geometry, settings: &SolverSettings) -> Vec<u32> {
        depth_limits(geometry, settings)
    }

    /// The trees for `depths`, which must be [`Discretisation::limits`]'s.
    pub fn with_limits(geometry: &Arc<Geometry>, depths: Vec<u32>) -> Self {
        let forest = presubdivided(Arc::clone(geometry), &depths);
        Discretisation { depths, forest }
    }

    /// The depth limit of every input surface, in surface order.
    pub fn depth_limits(&self) -> &[u32] {
        &self.depths
    }

    /// The element trees, pre-subdivided to the depth limits.
    pub fn forest(&self) -> &ElementForest {
        &self.forest
    }

    /// The number of potential elements: the leaves of every surface's
    /// tree at its depth limit, Σ 4^depth.
    pub fn potential_elements(&self) -> u64 {
        self.depths.iter().map(|&d| 4u64.pow(d)).sum()
    }
}

/// Per-surface depth limits from the global limit and MinArea: a surface
/// is subdivided while a quarter of its elements' area is at least
/// MinArea (a fraction of the squared scene diagonal).
fn depth_limits(geometry: &Geometry, settings: &SolverSettings) -> Vec<u32> {
    let diag = geometry.bounds().diagonal().length();
    let min_area = settings.min_area_fraction * diag * diag;
    geometry
        .surfaces()
        .iter()
        .map(|s| {
            let mut d = 0;
            let mut a = s.area();
            while d < settings.max_depth && a / 4.0 >= min_area {
                a /= 4.0;
                d += 1;
            }
            d
        })
        .collect()
}

/// The element trees of `geometry`, subdivided uniformly to each surface's
/// depth limit. Their element count is O(n).
fn presubdivided(geometry: Arc<Geometry>, depths: &[u32]) -> ElementForest {
    let mut forest = ElementForest::new(geometry);
    for (s, &depth) in depths.iter().enumerate() {
        forest.subdivide_to_depth(SurfaceId(s as u32), depth);
    }
    forest
}
