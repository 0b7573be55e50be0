//! `cargo xtask viewer`: every bundled scene, and tests/bake's, solved
//! (default quality),
//! baked (`trilux bake`'s code) and previewed (`trilux render --preview`'s);
//! every bake checked by the Khronos glTF validator, and photographed in
//! docs/viewer by headless Chromium from the scene's own camera, beside
//! the preview of the same view.
//!
//! Gates: the validator reports no error and no warning; every bake takes
//! under [`MAX_BAKE_SECONDS`]; for scenes without glossy materials (whose
//! view-dependent part a bake leaves out) the screenshot's mean, after
//! tone mapping (PNG values at exposure [`EXPOSURE`]), is within
//! [`MAX_MEAN_GAP`] of the preview's. Writes `target/viewer/NAME.glb`,
//! `NAME-preview.png`, `NAME-viewer.png` and `report.md`.
//!
//! Then the viewer's interior tests (docs/viewer/test/interior.test.mjs:
//! walk mode, touch, the glossy notice, the compact overlay, `trilux
//! view`) run in headless Chromium on these bakes and the release
//! `trilux` binary (built here if needed).
//!
//! Here the bakes leave the glossy light out (`trilux bake --no-glossy`,
//! the glossy notice's test needs it), and crossing-room is also baked
//! with it (the default bake) as `crossing-room-glossy.glb`, for the
//! interior tests of the viewer's glossy shader.
//!
//! `--glossy` checks the directional bake instead (module
//! `viewer_glossy`): every scene baked with its glossy light (the
//! default bake), the glossy scenes' screenshots against full renders
//! from two views, the glossy shader's frame time; reported in a table
//! (docs/results.md) and gated (`cargo xtask ci` runs it), without the
//! interior tests.
//!
//! `--solutions DIR` loads `DIR/NAME.sol` where it exists instead of
//! solving (CI passes the solutions the golden step saved).
//!
//! Needs `npm ci` in docs/viewer and Debian's Chromium
//! (`docs/viewer/scripts/ci.sh` installs both).

use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::{Context, Result, bail};
use trilux::{Observer, Plan, RenderPlan, SolutionSource, ViewOverrides};
use trilux_brdf::BsdfParams;
use trilux_render::Estimator;
use trilux_solver::{Quality, SolverSettings};

use crate::golden::root;
use crate::viewer_glossy::{
    FULL_SPP, MAX_FRAME_RATIO, ViewFigures, compare_views, frame_cost, full_renders,
};

/// The scene also baked with its glossy light in the CI mode, for the
/// interior tests of the glossy shader (small: its glossy fit is quick).
const GLOSSY_TEST_SCENE: &str = "crossing-room";
use crate::viewer_shots::{node, png_compare, png_size};

/// Exposure of both PNGs, in stops (the furnace's radiance of 2.0 shows
/// as grey, not clipped white).
const EXPOSURE: f64 = -1.5;
/// Largest relative gap between the screenshot's mean and the preview's.
const MAX_MEAN_GAP: f64 = 0.03;
/// Longest bake after the solve.
const MAX_BAKE_SECONDS: f64 = 2.0;

/// One bake's figures.
struct Row {
    /// The scene (its preview is `SCENE-preview.png`).
    scene: String,
    /// The bake's file stem (`NAME.glb`, `NAME-viewer.png`).
    name: String,
    /// False for the `--no-albedo-maps` variant of a textured scene (shown
    /// for comparison, not gated) and the extra `--glossy` bake.
    default: bool,
    glossy: bool,
    /// Baked with the glossy light (`--glossy`).
    glossy_bake: bool,
    /// Seconds of preparing the scene and solving it, or loading its
    /// solution.
    solve_seconds: f64,
    bake_seconds: f64,
    /// Of `bake_seconds`, the glossy light's.
    glossy_seconds: f64,
    bytes: usize,
    triangles: usize,
    /// Preview mean, viewer mean, RMSE of the PNG values.
    means: Option<(f64, f64, f64)>,
    /// The views of a glossy scene's full renders (viewer `lookat`, if
    /// not the file's camera).
    views: Vec<(&'static str, Option<String>)>,
    /// The viewer against the full renders, per view.
    against_full: Vec<ViewFigures>,
}

/// The bundled scenes (scenes/*.xml, *.gltf, *.glb), then the bake's own
/// test scenes (tests/bake: a diffuse textured room), each by name.
fn scenes() -> Result<Vec<PathBuf>> {
    let mut all = Vec::new();
    for dir in ["scenes", "tests/bake"] {
        let mut out: Vec<PathBuf> = std::fs::read_dir(root().join(dir))?
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| {
                p.extension()
                    .is_some_and(|e| e == "xml" || e == "gltf" || e == "glb")
            })
            .collect();
        out.sort();
        all.extend(out);
    }
    Ok(all)
}

/// The material has a glossy part on some side (trilux-brdf's own rule).
fn glossy(b: &BsdfParams) -> bool {
    trilux_brdf::Bsdf::<3>::new(b).is_ok_and(|b| {
        [trilux_brdf::Side::Front, trilux_brdf::Side::Back]
            .into_iter()
            .any(|s| b.has_glossy(s))
    })
}

fn name_of(path: &Path) -> String {
    path.file_stem()
        .map_or_else(String::new, |s| s.to_string_lossy().into_owned())
}

fn bake_options(albedo_maps: bool, glossy: bool) -> trilux_bake::BakeOptions {
    let mut options = trilux_bake::BakeOptions::default();
    options.albedo_maps = albedo_maps;
    options.glossy = glossy;
    options
}

/// Solves, bakes (with the glossy light when `glossy_mode`) and previews
/// one scene into `dir`; a textured scene is baked a second time without
/// albedo maps, and [`GLOSSY_TEST_SCENE`] outside `glossy_mode` with its
/// glossy light, from the saved solution.
fn bake_scene(
    path: &Path,
    dir: &Path,
    solutions: Option<&Path>,
    glossy_mode: bool,
) -> Result<Vec<Row>> {
    let name = name_of(path);
    let scene = trilux_scene::load(path).map_err(|e| anyhow::anyhow!("{e}"))?;
    let render = scene.camera.as_ref().map(|camera| {
        let mut settings = trilux::render_settings(camera);
        settings.estimator = Estimator::Preview;
        settings.spp = 1;
        RenderPlan {
            view: ViewOverrides::default(),
            settings,
        }
    });
    let saved = solutions
        .map(|d| d.join(format!("{name}.sol")))
        .filter(|p| p.exists());
    let solved_before = saved.is_some();
    let solution = saved.unwrap_or_else(|| dir.join(format!("{name}.sol")));
    let mut plan = Plan {
        mode: scene.mode(),
        solver: SolverSettings::preset(Quality::Default),
        source: match solved_before {
            true => SolutionSource::Load(&solution),
            false => SolutionSource::Solve,
        },
        save: (!solved_before).then_some(solution.as_path()),
        solution_file: false,
        bake: Some(bake_options(true, glossy_mode)),
        render,
    };
    let outcome = Observer::quiet(|o| trilux::pipeline::run(&scene, &plan, o))?;
    if let Some(image) = &outcome.image {
        std::fs::write(
            dir.join(format!("{name}-preview.png")),
            image.png_bytes(EXPOSURE)?,
        )?;
    }
    let solve_seconds = outcome.prepare_seconds + outcome.solve_seconds;
    let row = |stem: String, default: bool, baked: trilux_bake::Baked| -> Result<Row> {
        std::fs::write(dir.join(format!("{stem}.glb")), &baked.glb)?;
        Ok(Row {
            scene: name.clone(),
            name: stem,
            default,
            glossy: scene.shapes.iter().any(|s| glossy(&s.bsdf)),
            glossy_bake: baked.stats.glossy_vertices > 0,
            solve_seconds,
            bake_seconds: baked.stats.seconds,
            glossy_seconds: baked.stats.glossy_seconds,
            bytes: baked.stats.bytes,
            triangles: baked.stats.triangles,
            means: None,
            views: Vec::new(),
            against_full: Vec::new(),
        })
    };
    let mut rows = vec![row(
        name.clone(),
        true,
        outcome.baked.context("the plan bakes")?,
    )?];
    if rows[0].glossy && glossy_mode {
        rows[0].views = full_renders(&scene, &name, &solution, dir, EXPOSURE)?;
    }
    if scene.shapes.iter().any(|s| !s.textures.is_empty()) {
        plan.source = SolutionSource::Load(&solution);
        plan.save = None;
        plan.render = None;
        plan.bake = Some(bake_options(false, glossy_mode));
        let outcome = Observer::quiet(|o| trilux::pipeline::run(&scene, &plan, o))?;
        let baked = outcome.baked.context("the plan bakes")?;
        rows.push(row(format!("{name}-vertex"), false, baked)?);
    }
    if name == GLOSSY_TEST_SCENE && !glossy_mode {
        plan.source = SolutionSource::Load(&solution);
        plan.save = None;
        plan.render = None;
        plan.bake = Some(bake_options(true, true));
        let outcome = Observer::quiet(|o| trilux::pipeline::run(&scene, &plan, o))?;
        let baked = outcome.baked.context("the plan bakes")?;
        rows.push(row(format!("{name}-glossy"), false, baked)?);
    }
    Ok(rows)
}

/// docs/viewer/test/interior.test.mjs on the bakes in `dir`, with the
/// release `trilux` (built first: `cargo build` is quick when it is up to
/// date).
fn interior_tests(dir: &Path) -> Result<()> {
    let status = Command::new("cargo")
        .current_dir(root())
        .args(["build", "--release", "-p", "trilux", "--bin", "trilux"])
        .status()
        .context("could not start cargo")?;
    if !status.success() {
        bail!("cargo build --release -p trilux failed ({status})");
    }
    let target =
        std::env::var_os("CARGO_TARGET_DIR").map_or_else(|| root().join("target"), PathBuf::from);
    let test = root().join("docs/viewer/test/interior.test.mjs");
    eprintln!("xtask: node --test {}", test.display());
    let status = Command::new("node")
        .arg("--test")
        .arg(&test)
        .env("TRILUX_BAKES", dir)
        .env("TRILUX", target.join("release/trilux"))
        .status()
        .context(
            "could not start node (docs/viewer/scripts/ci.sh installs what the viewer needs)",
        )?;
    if !status.success() {
        bail!("the viewer's interior tests failed ({status})");
    }
    Ok(())
}

/// The viewer's screenshot of `row`'s bake beside its preview.
fn photograph(row: &mut Row, dir: &Path) -> Result<()> {
    let preview = dir.join(format!("{}-preview.png", row.scene));
    if !preview.exists() {
        return Ok(());
    }
    let (w, h) = png_size(&preview)?;
    let shot = dir.join(format!("{}-viewer.png", row.name));
    let glb = dir.join(format!("{}.glb", row.name));
    let args = [
        "--glb".into(),
        glb.display().to_string(),
        "--width".into(),
        w.to_string(),
        "--height".into(),
        h.to_string(),
        "--out".into(),
        shot.display().to_string(),
        "--exposure".into(),
        EXPOSURE.to_string(),
    ];
    node("test/screenshot.mjs", &args)?;
    row.means = Some(png_compare(&preview, &shot)?);
    row.against_full = compare_views(&row.scene, &row.name, &row.views, dir, EXPOSURE)?;
    Ok(())
}

/// Runs the whole check (module docs).
pub fn main(args: &[String]) -> Result<()> {
    let usage = "usage: cargo xtask viewer [--glossy] [--solutions DIR]";
    let (mut solutions, mut glossy_mode) = (None, false);
    let mut args = args.iter();
    while let Some(arg) = args.next() {
        match arg.as_str() {
            "--glossy" => glossy_mode = true,
            "--solutions" => solutions = Some(PathBuf::from(args.next().context(usage)?)),
            _ => bail!(usage),
        }
    }
    let dir = root().join("target/viewer");
    std::fs::create_dir_all(&dir)?;
    let mut rows = Vec::new();
    for path in scenes()? {
        eprintln!("xtask viewer: {}", path.display());
        rows.extend(bake_scene(&path, &dir, solutions.as_deref(), glossy_mode)?);
    }
    let glbs: Vec<String> = rows
        .iter()
        .map(|r| dir.join(format!("{}.glb", r.name)).display().to_string())
        .collect();
    node("test/validate.mjs", &glbs)?;
    for row in &mut rows {
        photograph(row, &dir)?;
    }
    if glossy_mode {
        return glossy_measurement(&rows, &dir);
    }
    let report = report(&rows);
    print!("{report}");
    std::fs::write(dir.join("report.md"), &report)?;
    interior_tests(&dir)?;
    let failed: Vec<&str> = rows
        .iter()
        .filter(|r| !passes(r))
        .map(|r| r.name.as_str())
        .collect();
    if !failed.is_empty() {
        bail!("the bakes of {} miss the viewer gates", failed.join(", "));
    }
    Ok(())
}

/// `--glossy`: the report with the glossy table and the frame time; fails
/// when a glossy scene's view misses the gates (viewer mean within 5 % of
/// the full render's, glossy sides within 10 %) or the glossy shader
/// costs more than [`MAX_FRAME_RATIO`] times diffuse only.
fn glossy_measurement(rows: &[Row], dir: &Path) -> Result<()> {
    let largest = rows
        .iter()
        .filter(|r| r.glossy)
        .max_by_key(|r| r.triangles)
        .context("no glossy scene to time the shader on")?;
    let cost = frame_cost(&dir.join(format!("{}.glb", largest.name)))?;
    let ratio = cost["ratio"].as_f64().unwrap_or(f64::INFINITY);
    let report = report(rows) + &glossy_report(rows, &cost, largest);
    print!("{report}");
    std::fs::write(dir.join("report-glossy.md"), &report)?;
    let missed: Vec<&str> = rows
        .iter()
        .filter(|r| r.default && !r.against_full.iter().all(ViewFigures::passes))
        .map(|r| r.name.as_str())
        .collect();
    if !missed.is_empty() || ratio > MAX_FRAME_RATIO {
        bail!(
            "xtask viewer --glossy: not within the gates (5 % mean, 10 % glossy sides): {}; frame time ratio {ratio:.2} (at most {MAX_FRAME_RATIO})",
            if missed.is_empty() {
                "none".to_string()
            } else {
                missed.join(", ")
            }
        );
    }
    Ok(())
}

fn gap(r: &Row) -> Option<f64> {
    r.means.map(|(p, v, _)| v / p - 1.0)
}

fn passes(r: &Row) -> bool {
    let mean_ok = r.glossy || !r.default || gap(r).is_none_or(|g| g.abs() <= MAX_MEAN_GAP);
    mean_ok && r.bake_seconds - r.glossy_seconds < MAX_BAKE_SECONDS
}

/// The glossy scenes' table: the viewer against the full renders, per
/// view; then the shader's frame time.
fn glossy_report(rows: &[Row], cost: &serde_json::Value, largest: &Row) -> String {
    let mut s = format!(
        "\nViewer against the full render ({FULL_SPP} spp), glossy scenes:\n\n\
         | bake | view | glossy s | full mean | viewer mean | gap | RMSE | glossy sides: full | viewer | gap |\n\
         |---|---|---|---|---|---|---|---|---|---|\n"
    );
    for r in rows.iter().filter(|r| r.default) {
        for v in &r.against_full {
            let (f, m, e) = v.means;
            let (mf, mv, mg) = match (v.masked, v.mask_gap()) {
                (Some((a, b)), Some(g)) => (
                    format!("{a:.4}"),
                    format!("{b:.4}"),
                    format!("{:+.2} %", 100.0 * g),
                ),
                _ => ("–".into(), "–".into(), "–".into()),
            };
            s += &format!(
                "| {} | {} | {:.2} | {f:.4} | {m:.4} | {:+.2} % | {e:.4} | {mf} | {mv} | {mg} |\n",
                r.scene,
                v.view,
                r.glossy_seconds,
                100.0 * v.gap(),
            );
        }
    }
    let ms = |k: &str| cost[k].as_f64().unwrap_or(f64::NAN);
    s += &format!(
        "\nFrame time on {} ({} triangles, {:.1} bytes a triangle, {}×{}): glossy {:.1} ms, diffuse only {:.1} ms, ratio {:.2}\n",
        largest.name,
        largest.triangles,
        largest.bytes as f64 / largest.triangles.max(1) as f64,
        cost["width"],
        cost["height"],
        ms("glossy_ms"),
        ms("diffuse_ms"),
        ms("ratio"),
    );
    s
}

fn report(rows: &[Row]) -> String {
    let mut s = String::from(
        "| bake | glossy | solve or load s | bake s | file MB | triangles | preview mean | viewer mean | gap | RMSE |\n\
         |---|---|---|---|---|---|---|---|---|---|\n",
    );
    for r in rows {
        let (p, v, e) = r
            .means
            .map_or(("–".into(), "–".into(), "–".into()), |(p, v, e)| {
                (format!("{p:.4}"), format!("{v:.4}"), format!("{e:.4}"))
            });
        let g = gap(r).map_or("–".into(), |g| format!("{:+.2} %", 100.0 * g));
        let mut label = r.scene.clone();
        if r.name.ends_with("-vertex") {
            label += " (`--no-albedo-maps`)";
        }
        if r.glossy_bake {
            label += " (`--glossy`)";
        }
        s += &format!(
            "| {label} | {} | {:.2} | {:.3} | {:.2} | {} | {p} | {v} | {g} | {e} |\n",
            if r.glossy { "yes" } else { "no" },
            r.solve_seconds,
            r.bake_seconds,
            r.bytes as f64 / 1e6,
            r.triangles,
        );
    }
    s
}
