//! Every setting of a run as JSON: the plan's (mode, solver, solution
//! source, render, bake) with the values the defaults and presets filled
//! in, the scene's camera, and the worker threads.

use anyhow::Result;
use serde_json::{Map, Value, json};
use trilux::pipeline::{RenderPlan, SolutionSource};
use trilux_render::{Estimator, ExtraBounce};

/// The settings of `plan` on `scene`.
pub fn of_plan(scene: &trilux_scene::Scene, plan: &trilux::Plan<'_>) -> Result<Map<String, Value>> {
    let mut solver = serde_json::to_value(&plan.solver)?;
    if let Some(map) = solver.as_object_mut() {
        // Not serialised with the settings (it is no part of a solution).
        let budget = plan.solver.time_budget_seconds;
        map.insert("time_budget_seconds".into(), json!(budget));
    }
    let solution = match plan.source {
        SolutionSource::Solve => Value::Null,
        SolutionSource::Load(path) | SolutionSource::Bytes { name: path, .. } => {
            json!(path.display().to_string())
        }
    };
    let render = match &plan.render {
        Some(r) => render(scene, r)?,
        None => Value::Null,
    };
    let bake = plan.bake.as_ref().map(|b| {
        json!({
            "exposure": b.exposure,
            "albedo_maps": b.albedo_maps,
        })
    });
    let settings = json!({
        "scene": scene.path.display().to_string(),
        "mode": plan.mode.name(),
        "solver": solver,
        "solution": solution,
        "render": render,
        "bake": bake,
        "threads": rayon::current_num_threads(),
    });
    Ok(match settings {
        Value::Object(map) => map,
        _ => Map::new(),
    })
}

/// A render's settings: samples, seed, filter, estimator, extra bounce,
/// adaptive target, tiles, the integrator's path-length limit and hidden
/// emitters, and the view: the scene's camera and the
/// command line's changes to it.
fn render(scene: &trilux_scene::Scene, plan: &RenderPlan) -> Result<Value> {
    let s = &plan.settings;
    let estimator = match s.estimator {
        Estimator::Paths => "paths",
        Estimator::Links => "links",
        Estimator::Preview => "preview",
        Estimator::Control => "control",
        // A kind added later: its Debug name until it is named here.
        other => &format!("{other:?}"),
    };
    let extra_bounce = match s.extra_bounce {
        ExtraBounce::Always => json!("always"),
        ExtraBounce::Never => json!("never"),
        ExtraBounce::Auto { close_factor } => json!({ "auto": { "close_factor": close_factor } }),
        other => json!(format!("{other:?}")),
    };
    let v = &plan.view;
    let lookat = v.lookat.map(|(eye, target, up)| {
        json!({ "origin": eye.to_array(), "target": target.to_array(), "up": up.map(|u| u.to_array()) })
    });
    Ok(json!({
        "spp": s.spp,
        "seed": s.seed,
        "filter": serde_json::to_value(s.filter)?,
        "estimator": estimator,
        "extra_bounce": extra_bounce,
        "target_error": s.target_error,
        "tile_size": s.tile_size,
        "lookups": s.lookups,
        "max_depth": s.max_depth,
        "hide_emitters": s.hide_emitters,
        "scene_camera": serde_json::to_value(&scene.camera)?,
        "view": { "lookat": lookat, "fov": v.fov, "width": v.width, "height": v.height },
    }))
}
