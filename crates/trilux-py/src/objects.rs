//! The module's classes: a loaded [`Scene`] and its [`Solution`], and
//! [`SceneArg`], a scene given either way (a path or a `Scene`).
//!
//! A solution is kept as its file's bytes (what `trilux solve` writes),
//! with the scene and the solve options it was made with: rendering or
//! baking from it reads those bytes, as the command reads a `--solution`
//! file, so Python and the command share one path, and `save` writes
//! exactly the command's file.

use std::path::PathBuf;
use std::sync::Arc;

use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use trilux::{SavedSolution, SolveOptions, ViewOptions};

use crate::args::{defines_of, solve_options};
use crate::trilux_error;

/// A scene given as a path (`str` or `os.PathLike`) or a loaded `Scene`.
pub enum SceneArg {
    /// A file to load.
    Path(PathBuf),
    /// A scene loaded by `trilux.load`.
    Scene(Arc<trilux_scene::Scene>),
}

impl<'a, 'py> FromPyObject<'a, 'py> for SceneArg {
    type Error = PyErr;

    fn extract(ob: Borrowed<'a, 'py, PyAny>) -> PyResult<Self> {
        if let Ok(scene) = ob.cast::<Scene>() {
            return Ok(SceneArg::Scene(scene.borrow().inner()));
        }
        match ob.extract::<PathBuf>() {
            Ok(path) => Ok(SceneArg::Path(path)),
            Err(_) => Err(PyTypeError::new_err(
                "scene must be a path (str or os.PathLike) or a trilux.Scene",
            )),
        }
    }
}

impl SceneArg {
    /// The scene, loaded (with `defines`) when given as a path; `defines`
    /// with a loaded `Scene` is a `ValueError` (they were applied when it
    /// was loaded).
    pub fn resolve(
        self,
        py: Python<'_>,
        defines: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Arc<trilux_scene::Scene>> {
        match self {
            SceneArg::Scene(scene) => {
                if defines.is_some() {
                    return Err(PyValueError::new_err(
                        "defines apply when a scene is loaded: pass them to trilux.load, not with a Scene",
                    ));
                }
                Ok(scene)
            }
            SceneArg::Path(path) => {
                let defines = defines_of(defines)?;
                py.detach(|| trilux::load_file(&path, &defines))
                    .map(Arc::new)
                    .map_err(crate::trilux_error)
            }
        }
    }
}

/// A scene loaded by `trilux.load`: its shapes, materials, emitters and
/// camera, ready to solve, render or bake.
#[pyclass(module = "trilux", frozen)]
pub struct Scene {
    inner: Arc<trilux_scene::Scene>,
}

impl Scene {
    /// Wraps a loaded scene.
    pub fn new(scene: trilux_scene::Scene) -> Self {
        Scene {
            inner: Arc::new(scene),
        }
    }

    /// The loaded scene, shared.
    pub fn inner(&self) -> Arc<trilux_scene::Scene> {
        self.inner.clone()
    }
}

#[pymethods]
impl Scene {
    /// The scene file.
    #[getter]
    fn path(&self) -> PathBuf {
        self.inner.path.clone()
    }

    /// What loading left out (zero-area triangles and meshes), one line
    /// each with its place: the command line prints them as warnings.
    #[getter]
    fn warnings(&self) -> Vec<String> {
        self.inner.warnings.clone()
    }

    /// The number of shapes.
    #[getter]
    fn shapes(&self) -> usize {
        self.inner.shapes.len()
    }

    /// The number of shapes that emit light.
    #[getter]
    fn emitters(&self) -> usize {
        self.inner
            .shapes
            .iter()
            .filter(|s| s.emitter.is_some())
            .count()
    }

    /// The film's (width, height) in pixels, or None without a camera.
    #[getter]
    fn film(&self) -> Option<(u32, u32)> {
        self.inner.camera.as_ref().map(|c| (c.width, c.height))
    }

    /// The scene's colour mode: "rgb" or "spectral".
    #[getter]
    fn mode(&self) -> &'static str {
        match self.inner.mode() {
            trilux_color::Mode::Rgb => "rgb",
            trilux_color::Mode::Spectral => "spectral",
        }
    }

    /// Solves the scene's light (as `trilux solve`): `quality` "draft",
    /// "default" or "high"; `convergence` the target ratio in [0, 1]
    /// (default: the preset's); `mode` "rgb" or "spectral" (default: the
    /// scene's).
    #[pyo3(signature = (quality = "default", convergence = None, mode = None))]
    fn solve(
        &self,
        py: Python<'_>,
        quality: &str,
        convergence: Option<f64>,
        mode: Option<&str>,
    ) -> PyResult<Solution> {
        let options = solve_options(quality, convergence, mode)?;
        let scene = self.inner.clone();
        let (bytes, stats) = py
            .detach(|| trilux::solve_scene(&scene, &options))
            .map_err(trilux_error)?;
        let name = PathBuf::from(format!("<solution of {}>", scene.path.display()));
        Ok(Solution {
            scene,
            options,
            bytes,
            name,
            stats,
        })
    }

    fn __repr__(&self) -> String {
        format!(
            "trilux.Scene({:?}, {} shapes, {} emitters)",
            self.inner.path.display().to_string(),
            self.shapes(),
            self.emitters()
        )
    }
}

/// The solved light of a scene: render views from it, bake it, save it.
#[pyclass(module = "trilux", frozen)]
pub struct Solution {
    scene: Arc<trilux_scene::Scene>,
    options: SolveOptions,
    /// The solution file's bytes.
    bytes: Vec<u8>,
    /// Where the bytes came from (a file, or the solve), for errors.
    name: PathBuf,
    stats: trilux_solver::SolveStats,
}

impl Solution {
    /// Loads `path` as a solution of `scene` made with `options` (checked
    /// now: a file for another scene or setting raises `TriluxError`).
    pub fn load(
        py: Python<'_>,
        scene: Arc<trilux_scene::Scene>,
        options: SolveOptions,
        path: PathBuf,
    ) -> PyResult<Solution> {
        let bytes = std::fs::read(&path)
            .map_err(|e| crate::TriluxError::new_err(format!("{}: {e}", path.display())))?;
        let saved = SavedSolution {
            bytes: &bytes,
            name: &path,
        };
        let stats = py
            .detach(|| trilux::check_solution(&scene, &options, saved))
            .map_err(trilux_error)?;
        Ok(Solution {
            scene,
            options,
            bytes,
            name: path,
            stats,
        })
    }

    /// A `ValueError` unless `scene` is this solution's scene (the same
    /// `Scene`, or its file) and no `defines` come with it.
    pub fn check_scene(
        &self,
        scene: &SceneArg,
        defines: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<()> {
        let same = match scene {
            SceneArg::Scene(s) => Arc::ptr_eq(s, &self.scene),
            SceneArg::Path(p) => *p == self.scene.path,
        };
        if !same || defines.is_some() {
            return Err(PyValueError::new_err(format!(
                "a solution renders and bakes its own scene ({}): pass that Scene (or its path) and no defines",
                self.scene.path.display()
            )));
        }
        Ok(())
    }

    fn saved(&self) -> SavedSolution<'_> {
        SavedSolution {
            bytes: &self.bytes,
            name: &self.name,
        }
    }

    /// Renders a view from this solution.
    pub fn render(&self, py: Python<'_>, view: &ViewOptions) -> PyResult<trilux_render::Image> {
        py.detach(|| trilux::render_scene(&self.scene, &self.options, Some(self.saved()), view))
            .map_err(trilux_error)
    }

    /// Bakes this solution.
    pub fn bake(
        &self,
        py: Python<'_>,
        options: &trilux_bake::BakeOptions,
    ) -> PyResult<trilux_bake::Baked> {
        py.detach(|| trilux::bake_scene(&self.scene, &self.options, Some(self.saved()), options))
            .map_err(trilux_error)
    }
}

#[pymethods]
impl Solution {
    /// Writes the solution file (the bytes `trilux solve` writes; `trilux
    /// render --solution` and `trilux.load_solution` read it).
    fn save(&self, path: PathBuf) -> PyResult<()> {
        std::fs::write(&path, &self.bytes).map_err(|e| {
            crate::TriluxError::new_err(format!("{}: cannot write: {e}", path.display()))
        })
    }

    /// The scene file this solution is of.
    #[getter]
    fn scene_path(&self) -> PathBuf {
        self.scene.path.clone()
    }

    /// The convergence ratio the solve reached.
    #[getter]
    fn convergence_ratio(&self) -> f64 {
        self.stats.convergence_ratio
    }

    /// The solve's statistics as a dict (the keys of `trilux solve
    /// --stats`).
    fn stats<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let text = serde_json_text(&self.stats)?;
        py.import("json")?.call_method1("loads", (text,))
    }

    fn __repr__(&self) -> String {
        format!(
            "trilux.Solution(of {:?}, CR {:.4}, {} bytes)",
            self.scene.path.display().to_string(),
            self.stats.convergence_ratio,
            self.bytes.len()
        )
    }
}

/// The statistics as JSON text.
fn serde_json_text(stats: &trilux_solver::SolveStats) -> PyResult<String> {
    serde_json::to_string(stats).map_err(trilux_error)
}
