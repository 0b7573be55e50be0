//! `trilux info SCENE [--json] [--mode rgb|spectral]`: what a scene loads to.

use std::collections::BTreeMap;
use std::fmt::Write;
use std::path::PathBuf;

use anyhow::Result;
use clap::Args;
use serde::Serialize;
use trilux_color::Mode;
use trilux_geometry::ShapeKind;
use trilux_scene::Scene;

use crate::options::ModeArg;
use crate::power::emitted_power;

/// Arguments of `trilux info`.
#[derive(Debug, Args)]
pub struct InfoArgs {
    /// The scene file (Mitsuba 3 XML subset, or glTF 2.0: .gltf, .glb).
    pub scene: PathBuf,
    #[command(flatten)]
    pub params: crate::options::SceneParams,
    /// The glTF camera to show (a camera's or its node's name; default: the
    /// first).
    #[arg(long)]
    pub camera: Option<String>,
    /// Print a JSON object instead of text.
    #[arg(long)]
    pub json: bool,
    /// Override the scene's colour mode (spectral when some `<spectrum>` has
    /// wavelength:value pairs).
    #[arg(long, value_enum)]
    pub mode: Option<ModeArg>,
}

/// The JSON of `info --json`, exactly these keys (README, "Using it").
#[derive(Debug, Serialize)]
struct InfoJson {
    shapes: usize,
    input_surfaces: usize,
    emitters: usize,
    /// Lights without area (point, spot, directional).
    lights: usize,
    bsdfs: BTreeMap<String, usize>,
    emitted_power: Vec<f64>,
    mode: &'static str,
    /// `null` when the scene has no sensor.
    camera: Option<CameraJson>,
    /// A glTF file's cameras by name (`Scene::camera_names`).
    cameras: Vec<Option<String>>,
    /// Every shape, in file order: what the text lists line by line.
    shape_list: Vec<ShapeJson>,
}

/// One shape of `info`.
#[derive(Debug, Serialize)]
struct ShapeJson {
    /// Its index (the solver's shape index).
    index: usize,
    /// Its `id` (XML) or node name (glTF), if any.
    id: Option<String>,
    /// `rectangle`, `cube`, `disk`, `sphere`, `cylinder` or `mesh`.
    kind: &'static str,
    /// A mesh's triangles (`null` for the other kinds).
    triangles: Option<usize>,
    /// Surface area in scene units².
    area: f64,
    /// True when it carries an area emitter.
    emitter: bool,
    /// Textures it uses.
    textures: usize,
    /// Where it is written: `line N` (XML) or a JSON pointer (glTF).
    at: String,
}

#[derive(Debug, Serialize)]
struct CameraJson {
    origin: [f64; 3],
    target: [f64; 3],
    up: [f64; 3],
    fov: f64,
    fov_axis: &'static str,
    width: u32,
    height: u32,
}

/// Runs `trilux info`.
pub fn run(args: &InfoArgs) -> Result<()> {
    let scene =
        trilux_scene::open_with_camera(&args.scene, args.camera.as_deref(), &args.params.define)?
            .finish()?;
    crate::warn_loading(&scene);
    let mode = match args.mode {
        Some(ModeArg::Rgb) => Mode::Rgb,
        Some(ModeArg::Spectral) => Mode::Spectral,
        None => scene.mode(),
    };
    let geometry = scene.build_geometry()?;
    let info = InfoJson {
        shapes: scene.shapes.len(),
        input_surfaces: geometry.surfaces().len(),
        emitters: scene.emitters().count(),
        lights: scene.lights.len(),
        bsdfs: scene.bsdf_counts.clone(),
        emitted_power: emitted_power(&scene, mode, trilux_solver::lights::scene_radius(&geometry))?,
        mode: mode.name(),
        camera: scene.camera.as_ref().map(|c| CameraJson {
            origin: c.origin.to_array(),
            target: c.target.to_array(),
            up: c.up.to_array(),
            fov: c.fov,
            fov_axis: c.fov_axis.name(),
            width: c.width,
            height: c.height,
        }),
        cameras: scene.camera_names.clone(),
        shape_list: scene.shapes.iter().enumerate().map(shape_json).collect(),
    };
    if args.json {
        crate::streams::print(&format!("{}\n", serde_json::to_string_pretty(&info)?))
    } else {
        crate::streams::print(&text(&scene, &info)?)
    }
}

/// The text report of `info`, written whole at once (`streams::print`).
fn text(scene: &Scene, info: &InfoJson) -> Result<String, std::fmt::Error> {
    let mut out = String::new();
    writeln!(out, "scene          {}", scene.path.display())?;
    writeln!(
        out,
        "mode           {} (the file is {})",
        info.mode,
        if scene.spectral { "spectral" } else { "rgb" }
    )?;
    writeln!(out, "shapes         {}", info.shapes)?;
    writeln!(out, "input surfaces {}", info.input_surfaces)?;
    writeln!(out, "emitters       {}", info.emitters)?;
    writeln!(out, "lights         {}", info.lights)?;
    let bsdfs: Vec<String> = info.bsdfs.iter().map(|(k, v)| format!("{k} {v}")).collect();
    writeln!(out, "bsdfs          {}", bsdfs.join(", "))?;
    let power: Vec<String> = info
        .emitted_power
        .iter()
        .map(|p| format!("{p:.6}"))
        .collect();
    writeln!(out, "emitted power  [{}] W", power.join(", "))?;
    if let Some(d) = scene.max_depth {
        writeln!(out, "max_depth      {d}")?;
    }
    match (&info.camera, &scene.camera) {
        (Some(c), Some(cam)) => {
            writeln!(
                out,
                "camera         origin {:?} target {:?} up {:?}",
                c.origin, c.target, c.up
            )?;
            writeln!(
                out,
                "               fov {} ({}), {}x{} px, {} spp, {:?} filter",
                c.fov, c.fov_axis, c.width, c.height, cam.sample_count, cam.rfilter
            )?;
        }
        _ => writeln!(out, "camera         none (the scene has no <sensor>)")?,
    }
    if !info.cameras.is_empty() {
        let names: Vec<&str> = info
            .cameras
            .iter()
            .map(|n| n.as_deref().unwrap_or("(unnamed)"))
            .collect();
        writeln!(out, "cameras        {}", names.join(", "))?;
    }
    for s in &info.shape_list {
        let kind = match s.triangles {
            Some(n) => format!("mesh ({n} triangles)"),
            None => s.kind.to_string(),
        };
        let textures = match s.textures {
            0 => String::new(),
            n => format!(", {n} texture{}", if n == 1 { "" } else { "s" }),
        };
        writeln!(
            out,
            "  shape {:3} {:16} {kind:24} area {:.6}{}{textures}  ({})",
            s.index,
            s.id.as_deref().unwrap_or("-"),
            s.area,
            if s.emitter { ", emitter" } else { "" },
            s.at,
        )?;
    }
    Ok(out)
}

/// Shape `index` of the scene as `info` shows it.
fn shape_json((index, s): (usize, &trilux_scene::SceneShape)) -> ShapeJson {
    let (kind, triangles) = match &s.shape.kind {
        ShapeKind::Rectangle => ("rectangle", None),
        ShapeKind::Cube => ("cube", None),
        ShapeKind::Disk => ("disk", None),
        ShapeKind::Sphere { .. } => ("sphere", None),
        ShapeKind::Cylinder { .. } => ("cylinder", None),
        ShapeKind::Mesh(m) => ("mesh", Some(m.triangles.len())),
    };
    ShapeJson {
        index,
        id: s.id.clone(),
        kind,
        triangles,
        area: trilux_scene::surface_area(&s.shape),
        emitter: s.emitter.is_some(),
        textures: s.textures.len(),
        at: match &s.location.pointer {
            Some(p) => p.to_string(),
            None => format!("line {}", s.location.line),
        },
    }
}
