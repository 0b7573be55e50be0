//! `cargo xtask viewer --glossy`'s measurement and gates
//! (docs/results.md): a scene with glossy materials is
//! rendered in full (`trilux render`'s default estimator, [`FULL_SPP`]
//! samples a pixel) from its camera and from a second viewpoint (the eye
//! moved to [`SIDE_DISTANCE`] of its distance from the target and turned
//! [`SIDE_DEGREES`] about the up axis through the target: still inside an
//! interior, seeing the glossy surfaces from other directions),
//! and the viewer's screenshots of the bake from the same two views are
//! compared with them: the image means, and the means over the glossy
//! sides alone (the viewer's `mask=glossy` picture). Then the glossy
//! shader's frame time against diffuse only on the largest bake
//! (docs/viewer/test/frame-cost.mjs).

use std::path::Path;

use anyhow::{Context, Result};
use glam::{DQuat, DVec3};
use trilux::{Observer, Plan, RenderPlan, SolutionSource, ViewOverrides};
use trilux_render::Estimator;
use trilux_solver::{Quality, SolverSettings};

use crate::viewer_shots::{masked_means, node, node_output, png_compare, png_size};

/// Samples per pixel of the full renders.
pub(crate) const FULL_SPP: u32 = 64;
/// How far the second viewpoint turns from the scene's camera.
pub(crate) const SIDE_DEGREES: f64 = 20.0;
/// The second viewpoint's distance from the target, over the camera's.
pub(crate) const SIDE_DISTANCE: f64 = 0.6;
/// The gate for the relative gap between the viewer's mean and the full render's.
pub(crate) const MAX_GLOSSY_GAP: f64 = 0.05;
/// The gate for the relative gap over the glossy sides alone.
pub(crate) const MAX_MASK_GAP: f64 = 0.10;
/// The gate for the ratio of the glossy shader's frame time to diffuse only.
pub(crate) const MAX_FRAME_RATIO: f64 = 2.0;

/// One view of a glossy scene: full render against the viewer.
#[derive(Clone, Debug)]
pub(crate) struct ViewFigures {
    /// "camera" or "side".
    pub view: &'static str,
    /// Full render mean, viewer mean, RMSE of the PNG values.
    pub means: (f64, f64, f64),
    /// Full render and viewer means over the glossy sides.
    pub masked: Option<(f64, f64)>,
}

impl ViewFigures {
    pub(crate) fn gap(&self) -> f64 {
        self.means.1 / self.means.0 - 1.0
    }

    pub(crate) fn mask_gap(&self) -> Option<f64> {
        self.masked.map(|(f, v)| v / f - 1.0)
    }

    pub(crate) fn passes(&self) -> bool {
        self.gap().abs() <= MAX_GLOSSY_GAP
            && self.mask_gap().is_none_or(|g| g.abs() <= MAX_MASK_GAP)
    }
}

/// The second viewpoint of `camera`: eye, target, up.
fn side_view(camera: &trilux_scene::Camera) -> (DVec3, DVec3, DVec3) {
    let up = camera.up.try_normalize().unwrap_or(DVec3::Y);
    let turn = DQuat::from_axis_angle(up, SIDE_DEGREES.to_radians());
    let eye = camera.target + turn * (SIDE_DISTANCE * (camera.origin - camera.target));
    (eye, camera.target, up)
}

fn csv(v: [DVec3; 3]) -> String {
    let n: Vec<String> = v
        .iter()
        .flat_map(|p| p.to_array())
        .map(|x| format!("{x}"))
        .collect();
    n.join(",")
}

/// Full renders of `scene` from its two views, from the solution saved at
/// `solution`, as `dir/NAME-full-VIEW.png` at `exposure`; the views'
/// `lookat` for the viewer (`None`: the file's camera).
pub(crate) fn full_renders(
    scene: &trilux_scene::Scene,
    name: &str,
    solution: &Path,
    dir: &Path,
    exposure: f64,
) -> Result<Vec<(&'static str, Option<String>)>> {
    let Some(camera) = scene.camera.as_ref() else {
        return Ok(Vec::new());
    };
    let (eye, target, up) = side_view(camera);
    let views = [("camera", None), ("side", Some((eye, target, Some(up))))];
    let mut out = Vec::new();
    for (view, lookat) in views {
        let mut settings = trilux::render_settings(camera);
        settings.estimator = Estimator::default();
        settings.spp = FULL_SPP;
        let plan = Plan {
            mode: scene.mode(),
            solver: SolverSettings::preset(Quality::Default),
            source: SolutionSource::Load(solution),
            save: None,
            solution_file: false,
            bake: None,
            render: Some(RenderPlan {
                view: ViewOverrides {
                    lookat,
                    ..ViewOverrides::default()
                },
                settings,
            }),
        };
        let outcome = Observer::quiet(|o| trilux::pipeline::run(scene, &plan, o))?;
        let image = outcome.image.context("the plan renders")?;
        let png = dir.join(format!("{name}-full-{view}.png"));
        std::fs::write(&png, image.png_bytes(exposure)?)?;
        out.push((
            view,
            lookat.map(|(e, t, u)| csv([e, t, u.unwrap_or(DVec3::Y)])),
        ));
    }
    Ok(out)
}

/// The viewer's screenshots of `dir/BAKE.glb` from each of `views`
/// (`full_renders`) against the full renders of `scene`, with the glossy
/// masks.
pub(crate) fn compare_views(
    scene: &str,
    bake: &str,
    views: &[(&'static str, Option<String>)],
    dir: &Path,
    exposure: f64,
) -> Result<Vec<ViewFigures>> {
    let mut out = Vec::new();
    for (view, lookat) in views {
        let full = dir.join(format!("{scene}-full-{view}.png"));
        let (w, h) = png_size(&full)?;
        let glb = dir.join(format!("{bake}.glb")).display().to_string();
        let shot = dir.join(format!("{bake}-viewer-{view}.png"));
        let mask = dir.join(format!("{bake}-mask-{view}.png"));
        for (picture, extra) in [(&shot, None), (&mask, Some("glossy"))] {
            let mut args = vec![
                "--glb".into(),
                glb.clone(),
                "--width".into(),
                w.to_string(),
                "--height".into(),
                h.to_string(),
                "--out".into(),
                picture.display().to_string(),
                "--exposure".into(),
                exposure.to_string(),
            ];
            if let Some(l) = lookat {
                args.extend(["--lookat".into(), l.clone()]);
            }
            if let Some(m) = extra {
                args.extend(["--mask".into(), m.into()]);
            }
            node("test/screenshot.mjs", &args)?;
        }
        out.push(ViewFigures {
            view,
            means: png_compare(&full, &shot)?,
            masked: masked_means(&full, &shot, &mask)?,
        });
    }
    Ok(out)
}

/// The glossy shader against diffuse only on `glb`
/// (docs/viewer/test/frame-cost.mjs's JSON line).
pub(crate) fn frame_cost(glb: &Path) -> Result<serde_json::Value> {
    let args = ["--glb".into(), glb.display().to_string()];
    let line = node_output("test/frame-cost.mjs", &args)?;
    serde_json::from_str(line.trim()).context("frame-cost.mjs printed no JSON line")
}
