//! The Python arguments, checked and converted before any work: a value
//! out of range is a `ValueError` naming the argument and the range (the
//! command's usage errors, status 2), never a panic or a silent clamp.

use std::path::Path;

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use trilux::{SolveOptions, ViewOptions};
use trilux_color::Mode;
use trilux_solver::Quality;

/// `defines` as (name, value) pairs: a name is made of letters, digits and
/// `_` (what a `$name` takes), a value is the `str()` of what is given
/// (`{"res": 64}` sets `$res` to `64`).
pub fn defines_of(defines: Option<&Bound<'_, PyDict>>) -> PyResult<Vec<(String, String)>> {
    let Some(defines) = defines else {
        return Ok(Vec::new());
    };
    let mut pairs = Vec::new();
    for (name, value) in defines.iter() {
        let name: String = name
            .extract()
            .map_err(|_| PyValueError::new_err("defines: each name must be a str"))?;
        if name.is_empty() || !name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') {
            return Err(PyValueError::new_err(format!(
                "defines: {name:?} is not a parameter name (letters, digits and _)"
            )));
        }
        pairs.push((name, value.str()?.to_string()));
    }
    Ok(pairs)
}

/// The solve's options; `quality` one of "draft", "default", "high",
/// `convergence` in [0, 1], `mode` "rgb" or "spectral" (or None: the
/// scene's).
pub fn solve_options(
    quality: &str,
    convergence: Option<f64>,
    mode: Option<&str>,
) -> PyResult<SolveOptions> {
    let quality = match quality {
        "draft" => Quality::Draft,
        "default" => Quality::Default,
        "high" => Quality::High,
        q => {
            return Err(PyValueError::new_err(format!(
                "quality must be \"draft\", \"default\" or \"high\", not {q:?}"
            )));
        }
    };
    if let Some(cr) = convergence
        && !(cr.is_finite() && (0.0..=1.0).contains(&cr))
    {
        return Err(PyValueError::new_err(format!(
            "convergence must lie in [0, 1], not {cr}"
        )));
    }
    let mode = match mode {
        None => None,
        Some("rgb") => Some(Mode::Rgb),
        Some("spectral") => Some(Mode::Spectral),
        Some(m) => {
            return Err(PyValueError::new_err(format!(
                "mode must be \"rgb\" or \"spectral\", not {m:?}"
            )));
        }
    };
    let mut options = SolveOptions::default();
    options.quality = quality;
    options.convergence = convergence;
    options.mode = mode;
    Ok(options)
}

/// `value` (when given) as an integer in `1..=max`, else a `ValueError`
/// naming `what`.
fn in_range(value: Option<i64>, max: u32, what: &str) -> PyResult<Option<u32>> {
    match value {
        None => Ok(None),
        Some(v) => match u32::try_from(v) {
            Ok(v) if (1..=max).contains(&v) => Ok(Some(v)),
            _ => Err(PyValueError::new_err(format!(
                "{what} must lie in 1..={max}, not {v}"
            ))),
        },
    }
}

/// The view's options: `spp` in 1..=the sampler's maximum, `width` and
/// `height` in 1..=the film limit (docs/limits.md), `seed` a u32.
pub fn view_options(
    spp: Option<i64>,
    width: Option<i64>,
    height: Option<i64>,
    seed: i64,
) -> PyResult<ViewOptions> {
    use trilux_scene::limits::MAX_FILM_EDGE;
    let seed = u32::try_from(seed).map_err(|_| {
        PyValueError::new_err(format!("seed must lie in 0..={}, not {seed}", u32::MAX))
    })?;
    let mut options = ViewOptions::default();
    options.spp = in_range(spp, trilux_render::sampler::MAX_SAMPLES, "spp")?;
    options.width = in_range(width, MAX_FILM_EDGE, "width")?;
    options.height = in_range(height, MAX_FILM_EDGE, "height")?;
    options.seed = seed;
    Ok(options)
}

/// The bake's options; `output` must be a .glb name (as `trilux bake -o`)
/// and `exposure` within ±64 stops.
pub fn bake_options(
    output: &Path,
    exposure: f64,
    albedo_maps: bool,
) -> PyResult<trilux_bake::BakeOptions> {
    let glb = output
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("glb"));
    if !glb {
        return Err(PyValueError::new_err(format!(
            "{}: a bake is a glTF binary; name the output .glb",
            output.display()
        )));
    }
    if !(exposure.is_finite() && exposure.abs() <= 64.0) {
        return Err(PyValueError::new_err(format!(
            "exposure must lie within ±64 stops, not {exposure}"
        )));
    }
    let mut options = trilux_bake::BakeOptions::default();
    options.exposure = exposure;
    options.albedo_maps = albedo_maps;
    Ok(options)
}
