//! The scene's `<integrator>`: which of Mitsuba 3.9.1's integrators and
//! parameters a trilux solve can stand for.
//!
//! A trilux solve carries light over paths of every length, so it stands
//! for Mitsuba's unbiased global-illumination integrators (`path` and its
//! relatives, which converge to the same image in a scene without media).
//! Parameters that only change how Mitsuba samples (`rr_depth`, pass and
//! block sizes, `timeout`) are read and ignored; the integrators that
//! compute something else (direct light only, AOVs, depth, …) are refused.
//! `max_depth` and `hide_emitters` are kept for the renderer, which honours
//! them (`trilux_render::RenderSettings`).

use crate::error::{Result, SceneError, SourceLocation};
use crate::props::Props;
use crate::xml::Element;

/// Mitsuba 3.9.1's integrators whose converged image, in a scene without
/// participating media, is the global illumination a trilux solve computes.
/// (Its Python integrators, `prb` and kin, are left out: they exist only
/// in its differentiable variants and default to `max_depth` 6.)
const GLOBAL_ILLUMINATION: [&str; 4] = ["path", "volpath", "volpathmis", "ptracer"];

/// What trilux keeps of an `<integrator>`.
pub(crate) struct IntegratorParams {
    /// `max_depth` as written (-1: unlimited).
    pub max_depth: Option<i64>,
    /// `hide_emitters` (false when not written).
    pub hide_emitters: bool,
}

/// Reads an `<integrator>` as Mitsuba 3.9.1's integrator base class reads
/// it (`max_depth`, `rr_depth`, `hide_emitters`, `samples_per_pass`,
/// `block_size`, `timeout`); anything else is an unknown parameter, as in
/// Mitsuba.
pub(crate) fn integrator(e: &Element) -> Result<IntegratorParams> {
    e.check_attrs(&["type", "id", "name"])?;
    let t = e.plugin_type()?;
    if !GLOBAL_ILLUMINATION.contains(&t) {
        return Err(SceneError::at(
            &e.required("type")?.loc,
            format!(
                "integrator \"{t}\" does not compute global illumination; trilux's solution stands for Mitsuba's {}",
                GLOBAL_ILLUMINATION.join(", ")
            ),
        ));
    }
    let props = Props::new(e)?;
    props.no_objects()?;
    let max_depth = props.integer("max_depth")?;
    if let Some(d) = max_depth
        && d < -1
    {
        return Err(SceneError::at(
            &props.loc("max_depth"),
            format!("max_depth must be -1 (unlimited) or at least 0, found {d}"),
        ));
    }
    let hide_emitters = props.boolean("hide_emitters")?.unwrap_or(false);
    // Russian roulette's start, the samples of a pass, the image blocks and
    // a time limit change Mitsuba's noise and speed, not the image it
    // converges to.
    props.integer("rr_depth")?;
    props.integer("samples_per_pass")?;
    props.integer("block_size")?;
    props.float("timeout")?;
    if t == "volpathmis" {
        // How it weighs wavelengths in media (a trilux scene has none).
        props.boolean("use_spectral_mis")?;
    }
    props.finish()?;
    Ok(IntegratorParams {
        max_depth,
        hide_emitters,
    })
}

/// Where `e` writes its `max_depth`, else where `e` starts.
pub(crate) fn max_depth_location(e: &Element) -> SourceLocation {
    e.children
        .iter()
        .find(|c| c.attr("name").is_some_and(|n| n.value == "max_depth"))
        .map_or(&e.loc, |c| &c.loc)
        .clone()
}
