//! # trilux-py — trilux from Python
//!
//! Layer: beside the command, on top of the `trilux` library. The Python
//! module `trilux` (built by maturin from this crate, `pyproject.toml`)
//! loads a scene, solves it, saves and loads solutions, renders views to
//! NumPy arrays and bakes glTF files, through the library's one-call API
//! (`trilux::oneshot`): the same orchestration as the `trilux` command, so
//! that a render from Python is the command's image for the same settings.
//!
//! ```python
//! import trilux
//! image = trilux.render("scenes/cornell-box.xml", spp=16)   # H × W × 3 float32
//! scene = trilux.load("scenes/cornell-box.xml", defines={"res": 64})
//! solution = scene.solve(quality="draft")
//! solution.save("box.sol")
//! image = trilux.render(scene, solution=solution, spp=4)
//! ```
//!
//! Contents, in reading order:
//! - `args`: the Python arguments checked and converted (a bad one is a
//!   `ValueError`, before any work).
//! - `objects`: the `Scene` and `Solution` classes, and a scene argument
//!   given as a path or a `Scene`.
//! - this file: the module's functions (`load`, `load_solution`,
//!   `render`, `bake`, `read_exr`) and its exception, `TriluxError`, whose message is
//!   the command's error line (the file and the place in it).
//!
//! The GIL is released during the work (loading, solving, rendering,
//! baking), so other Python threads run meanwhile.

mod args;
mod objects;

use std::path::PathBuf;

use numpy::{PyArray1, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use args::{defines_of, solve_options, view_options};
use objects::{Scene, SceneArg, Solution};

pyo3::create_exception!(
    trilux,
    TriluxError,
    pyo3::exceptions::PyException,
    "An error of trilux: a scene, solution or output it cannot use; the message names the file and the place in it, as the command's error line does."
);

/// A library error as a [`TriluxError`] with the command's message.
pub(crate) fn trilux_error(e: impl std::fmt::Display) -> PyErr {
    TriluxError::new_err(e.to_string())
}

/// An image as a NumPy float32 array of height × width × 3, linear sRGB,
/// row 0 at the top (the EXR the command writes).
fn to_array<'py>(
    py: Python<'py>,
    image: &trilux_render::Image,
) -> PyResult<Bound<'py, numpy::PyArray3<f32>>> {
    let flat: Vec<f32> = image.pixels().iter().flatten().copied().collect();
    let shape = [image.height() as usize, image.width() as usize, 3];
    PyArray1::from_vec(py, flat).reshape(shape)
}

/// Loads a scene file (Mitsuba 3 XML subset, or glTF 2.0 .gltf/.glb).
///
/// `defines` sets the XML scene's `$name` parameters (as `mitsuba.load_file(path,
/// name=value)` and the command's `-D name=value`); a name the scene does
/// not use is an error, as in Mitsuba 3. Raises `TriluxError` (with the
/// file and the place) for a scene trilux cannot read.
#[pyfunction]
#[pyo3(signature = (path, defines = None))]
fn load(py: Python<'_>, path: PathBuf, defines: Option<&Bound<'_, PyDict>>) -> PyResult<Scene> {
    let defines = defines_of(defines)?;
    let loaded = py
        .detach(|| trilux::load_file(&path, &defines))
        .map_err(trilux_error)?;
    Ok(Scene::new(loaded))
}

/// Loads a solution saved by `Solution.save` or `trilux solve` for the
/// scene (a path or a `Scene`), made with the same `quality`,
/// `convergence` and `mode`; raises `TriluxError` for a file made for
/// another scene or setting.
#[pyfunction]
#[pyo3(signature = (scene, solution_path, quality = "default", convergence = None, mode = None, defines = None))]
fn load_solution(
    py: Python<'_>,
    scene: SceneArg,
    solution_path: PathBuf,
    quality: &str,
    convergence: Option<f64>,
    mode: Option<&str>,
    defines: Option<&Bound<'_, PyDict>>,
) -> PyResult<Solution> {
    let options = solve_options(quality, convergence, mode)?;
    let scene = scene.resolve(py, defines)?;
    Solution::load(py, scene, options, solution_path)
}

/// Renders a view of a scene (a path or a `Scene`) as `trilux render`
/// does and returns it as a float32 NumPy array of height × width × 3
/// (linear sRGB radiance, the EXR the command writes; row 0 at the top).
///
/// `spp`, `width`, `height`: the scene's own when None. The light is
/// solved first with `quality`/`convergence`/`mode`, unless `solution`
/// (a `Solution`) is given. The same arguments and `seed` give the same
/// image as the command. Raises `ValueError` for a bad argument and
/// `TriluxError` for a scene or solution trilux cannot use.
#[pyfunction]
#[pyo3(signature = (scene, spp = None, width = None, height = None, seed = 0, quality = "default", convergence = None, mode = None, solution = None, defines = None))]
#[allow(clippy::too_many_arguments)] // Python keyword arguments
fn render<'py>(
    py: Python<'py>,
    scene: SceneArg,
    spp: Option<i64>,
    width: Option<i64>,
    height: Option<i64>,
    seed: i64,
    quality: &str,
    convergence: Option<f64>,
    mode: Option<&str>,
    solution: Option<PyRef<'_, Solution>>,
    defines: Option<&Bound<'_, PyDict>>,
) -> PyResult<Bound<'py, numpy::PyArray3<f32>>> {
    let view = view_options(spp, width, height, seed)?;
    let image = match solution {
        Some(solution) => {
            solution.check_scene(&scene, defines)?;
            solution.render(py, &view)?
        }
        None => {
            let options = solve_options(quality, convergence, mode)?;
            let scene = scene.resolve(py, defines)?;
            py.detach(|| trilux::render_scene(&scene, &options, None, &view))
                .map_err(trilux_error)?
        }
    };
    to_array(py, &image)
}

/// Bakes a scene's light (a path or a `Scene`) into a glTF binary at
/// `output` (a .glb name), as `trilux bake`: solving first, or from
/// `solution`. `exposure` scales COLOR_0 by 2^stops; `albedo_maps` keeps
/// textured materials as an albedo map times the light. Returns the
/// bake's figures (`bytes`, `vertices`, `triangles`, `seconds`,
/// `max_flux_error`).
#[pyfunction]
#[pyo3(signature = (scene, output, solution = None, exposure = 0.0, albedo_maps = true, quality = "default", convergence = None, mode = None, defines = None))]
#[allow(clippy::too_many_arguments)] // Python keyword arguments
fn bake<'py>(
    py: Python<'py>,
    scene: SceneArg,
    output: PathBuf,
    solution: Option<PyRef<'_, Solution>>,
    exposure: f64,
    albedo_maps: bool,
    quality: &str,
    convergence: Option<f64>,
    mode: Option<&str>,
    defines: Option<&Bound<'_, PyDict>>,
) -> PyResult<Bound<'py, PyDict>> {
    let options = args::bake_options(&output, exposure, albedo_maps)?;
    let baked = match solution {
        Some(solution) => {
            solution.check_scene(&scene, defines)?;
            solution.bake(py, &options)?
        }
        None => {
            let solve = solve_options(quality, convergence, mode)?;
            let scene = scene.resolve(py, defines)?;
            py.detach(|| trilux::bake_scene(&scene, &solve, None, &options))
                .map_err(trilux_error)?
        }
    };
    std::fs::write(&output, &baked.glb)
        .map_err(|e| TriluxError::new_err(format!("{}: cannot write: {e}", output.display())))?;
    let s = &baked.stats;
    let stats = PyDict::new(py);
    stats.set_item("bytes", s.bytes)?;
    stats.set_item("vertices", s.vertices)?;
    stats.set_item("triangles", s.triangles)?;
    stats.set_item("seconds", s.seconds)?;
    stats.set_item("max_flux_error", s.max_flux_error)?;
    Ok(stats)
}

/// Reads an OpenEXR image written by `trilux render` (or any RGB EXR) as
/// the float32 height × width × 3 array `render` returns.
#[pyfunction]
fn read_exr<'py>(py: Python<'py>, path: PathBuf) -> PyResult<Bound<'py, numpy::PyArray3<f32>>> {
    let image = py
        .detach(|| trilux_render::Image::read_exr(&path))
        .map_err(trilux_error)?;
    to_array(py, &image)
}

/// The Python module `trilux`.
#[pymodule]
#[pyo3(name = "trilux")]
fn trilux_py(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add("TriluxError", m.py().get_type::<TriluxError>())?;
    m.add_class::<Scene>()?;
    m.add_class::<Solution>()?;
    m.add_function(wrap_pyfunction!(load, m)?)?;
    m.add_function(wrap_pyfunction!(load_solution, m)?)?;
    m.add_function(wrap_pyfunction!(render, m)?)?;
    m.add_function(wrap_pyfunction!(bake, m)?)?;
    m.add_function(wrap_pyfunction!(read_exr, m)?)?;
    Ok(())
}
