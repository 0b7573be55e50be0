//! Helpers shared by the solver's integration tests.
#![allow(dead_code)]

use std::sync::Arc;

use trilux_solver::{PreparedScene, SceneDescription};

/// A bundled scene file, loaded and prepared for `N` bands.
pub fn prepare<const N: usize>(path: &str) -> Arc<PreparedScene<N>> {
    let scene = trilux_scene::load(path).unwrap_or_else(|e| panic!("{e}"));
    prepare_scene(&scene)
}

/// A loaded scene prepared for `N` bands.
pub fn prepare_scene<const N: usize>(scene: &trilux_scene::Scene) -> Arc<PreparedScene<N>> {
    let (shapes, bsdfs, emission) = (
        scene.geometry_shapes(),
        scene.bsdf_params(),
        scene.emitter_radiance(),
    );
    let desc = SceneDescription {
        shapes: &shapes,
        bsdfs: &bsdfs,
        emission: &emission,
    };
    let prepared = PreparedScene::new(&desc).unwrap_or_else(|e| panic!("{e}"));
    Arc::new(
        prepared
            .with_lights(&scene.light_params())
            .unwrap_or_else(|e| panic!("{e}")),
    )
}
