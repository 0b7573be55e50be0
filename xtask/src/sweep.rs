//! `cargo xtask sweep`: error against wall time, trilux beside Mitsuba 3,
//! measured in one run on one machine.
//!
//! For every scene with a reference in tests/golden/ (or those given with
//! `--only`), at the reference's size:
//! - **solve**: trilux solves once at the quality preset and saves the
//!   solution (timed: preparing the scene, solving, writing the file);
//! - **from a solution**: for each estimator (`--gather`) and sample count
//!   (`--spp`), a render from the saved file, as `trilux render --solution`
//!   does (timed: preparing the scene, reading the solution, rendering);
//! - **full run**: the same renders with the solve's time added in place of
//!   the reading (a user who solves and renders in one command);
//! - **Mitsuba 3**'s path tracer (`path`, unbounded depth) at a range of
//!   sample counts, timed by `tests/golden/mitsuba_time.py` (kernel
//!   compilation excluded), when `python3 -c "import mitsuba"` works.
//!
//! Every image is compared with the reference (`trilux_render::compare`,
//! relative RMSE over unmasked pixels). Output in `target/sweep/` (or
//! `--out DIR`):
//! - `sweep.csv`: scene, series, gather, spp, seconds, solve_seconds,
//!   render_seconds, rel_rmse, mean_ratio;
//! - `sweep.svg`: relative RMSE against seconds on log scales, one panel
//!   per scene, with the full run, the from-solution and Mitsuba's curves
//!   (plotters).
//!
//! The summary prints, per scene and estimator, the ratio of trilux's error
//! to Mitsuba's at equal wall time (Mitsuba's error interpolated in log–log
//! between its points, extrapolated beyond them as a path tracer's noise,
//! ∝ t^(−1/2)), the worst ratio over the windows (from a solution:
//! 0.5–4 s; full run: 2–20 s; trilux's error at time t being that of its
//! best render finished by t), and the bias and noise of every series
//! (bias: the error at the largest sample count, an upper bound; noise² =
//! error² − bias²).

use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::{Context, Result, bail};
use trilux::SolutionSource;
use trilux_render::{Image, RenderSettings, compare};

use crate::golden::{Reference, TriluxSpec, estimator, quality, references, root, run_trilux};

/// One measured point.
#[derive(Clone, Debug)]
pub struct Point {
    /// Scene name.
    pub scene: String,
    /// `full`, `solution` or `mitsuba`.
    pub series: String,
    /// trilux's estimator (`links`, `paths`), `path` for Mitsuba.
    pub gather: String,
    /// Samples per pixel.
    pub spp: u32,
    /// Wall seconds of the whole run the series stands for.
    pub seconds: f64,
    /// Seconds of preparing and solving (trilux; 0 for Mitsuba).
    pub solve_seconds: f64,
    /// Seconds of the render alone.
    pub render_seconds: f64,
    /// Relative RMSE against the reference (unmasked).
    pub rel_rmse: f64,
    /// Mean ratio against the reference (unmasked).
    pub mean_ratio: f64,
}

/// What to measure.
struct Grid {
    spps: Vec<u32>,
    mitsuba_spps: Vec<u32>,
    gathers: Vec<String>,
    quality: String,
    mitsuba: bool,
}

fn mitsuba_available() -> bool {
    Command::new("python3")
        .args(["-c", "import mitsuba"])
        .output()
        .is_ok_and(|o| o.status.success())
}

/// `cargo xtask sweep [--only NAME]... [--out DIR] [--no-mitsuba]
/// [--spp a,b,c] [--gather links,paths] [--quality Q] [--mitsuba-spp a,b,c]`,
/// or `--replot` (after `--out`, if any) to redraw the plot and the summary
/// from an existing CSV.
pub fn main(args: &[String]) -> Result<()> {
    let mut only = Vec::new();
    let mut out = root().join("target/sweep");
    let mut grid = Grid {
        spps: vec![1, 4, 16, 64, 256],
        mitsuba_spps: vec![4, 16, 64, 256, 1024, 4096],
        gathers: vec!["links".into(), "paths".into()],
        quality: "default".into(),
        mitsuba: true,
    };
    let numbers = |s: Option<&String>| -> Result<Vec<u32>> {
        s.context("a comma-separated list is needed")?
            .split(',')
            .map(|v| v.trim().parse::<u32>().context("bad number"))
            .collect()
    };
    let mut it = args.iter();
    while let Some(a) = it.next() {
        match a.as_str() {
            "--only" => only.push(it.next().context("--only needs a name")?.clone()),
            "--out" => out = PathBuf::from(it.next().context("--out needs a folder")?),
            "--no-mitsuba" => grid.mitsuba = false,
            "--replot" => {
                let points = read_csv(&out.join("sweep.csv"))?;
                plot(&points, &out.join("sweep.svg"))?;
                summary(&points);
                return Ok(());
            }
            "--spp" => grid.spps = numbers(it.next())?,
            "--mitsuba-spp" => grid.mitsuba_spps = numbers(it.next())?,
            "--quality" => grid.quality = it.next().context("--quality needs a name")?.clone(),
            "--gather" => {
                grid.gathers = it
                    .next()
                    .context("--gather needs a list")?
                    .split(',')
                    .map(str::to_owned)
                    .collect()
            }
            other => bail!("unknown argument {other}"),
        }
    }
    for g in &grid.gathers {
        estimator(g)?;
    }
    std::fs::create_dir_all(&out)?;
    grid.mitsuba = grid.mitsuba && mitsuba_available();
    let mut points = Vec::new();
    for r in references(&only)? {
        points.extend(trilux_points(&r, &grid, &out)?);
        if grid.mitsuba {
            points.extend(mitsuba_points(&r, &grid, &out)?);
        }
        // Written as it goes: a long sweep stopped midway keeps its points.
        write_csv(&out.join("sweep.csv"), &points)?;
    }
    plot(&points, &out.join("sweep.svg"))?;
    summary(&points);
    println!("wrote {} and sweep.svg", out.join("sweep.csv").display());
    Ok(())
}

/// trilux's points of one scene: one solve, then from-solution renders
/// (each also a full-run point).
fn trilux_points(r: &Reference, grid: &Grid, out: &Path) -> Result<Vec<Point>> {
    let size = (r.image.width(), r.image.height());
    let file = out.join(format!("{}.solution", r.name));
    let solve = run_trilux(&TriluxSpec {
        name: &r.name,
        size,
        quality: quality(&grid.quality)?,
        source: SolutionSource::Solve,
        save: Some(&file),
        render: None,
    })?;
    eprintln!("sweep: {} solve {:.2} s", r.name, solve.solve_seconds);
    let mut points = Vec::new();
    for g in &grid.gathers {
        let est = estimator(g)?;
        for &spp in &grid.spps {
            let tweak = |s: &mut RenderSettings| {
                s.spp = spp;
                s.estimator = est;
            };
            let run = run_trilux(&TriluxSpec {
                name: &r.name,
                size,
                quality: quality(&grid.quality)?,
                source: SolutionSource::Load(&file),
                save: None,
                render: Some(&tweak),
            })?;
            let image = run.image.context("the run renders")?;
            image.write_exr(&out.join(format!("{}-{g}-{spp}.exr", r.name)))?;
            let c = compare(&image, &r.image, r.mask.as_ref())?;
            let point = |series: &str, solve_seconds: f64| Point {
                scene: r.name.clone(),
                series: series.into(),
                gather: g.clone(),
                spp,
                seconds: solve_seconds + run.render_seconds,
                solve_seconds,
                render_seconds: run.render_seconds,
                rel_rmse: c.rel_rmse,
                mean_ratio: c.mean_ratio,
            };
            points.push(point("solution", run.solve_seconds));
            points.push(point("full", solve.solve_seconds));
            eprintln!(
                "sweep: {} {g} {spp} spp: load + render {:.2} s, relRMSE {:.4}, mean {:.4}",
                r.name,
                run.solve_seconds + run.render_seconds,
                c.rel_rmse,
                c.mean_ratio
            );
        }
    }
    Ok(points)
}

/// Mitsuba's points of one scene.
fn mitsuba_points(r: &Reference, grid: &Grid, out: &Path) -> Result<Vec<Point>> {
    let scene = crate::golden::scene_path(&r.name);
    let mut points = Vec::new();
    for &spp in &grid.mitsuba_spps {
        let exr = out.join(format!("{}-mitsuba-{spp}.exr", r.name));
        let o = Command::new("python3")
            .arg(root().join("tests/golden/mitsuba_time.py"))
            .arg(&scene)
            .args([r.image.width().to_string(), spp.to_string()])
            .arg(&exr)
            .output()
            .context("starting python3")?;
        if !o.status.success() {
            bail!(
                "mitsuba_time.py failed: {}",
                String::from_utf8_lossy(&o.stderr)
            );
        }
        let text = String::from_utf8_lossy(&o.stdout);
        let seconds: f64 = text
            .lines()
            .find_map(|l| l.strip_prefix("seconds "))
            .context("mitsuba_time.py printed no time")?
            .trim()
            .parse()?;
        let c = compare(&Image::read_exr(&exr)?, &r.image, r.mask.as_ref())?;
        points.push(Point {
            scene: r.name.clone(),
            series: "mitsuba".into(),
            gather: "path".into(),
            spp,
            seconds,
            solve_seconds: 0.0,
            render_seconds: seconds,
            rel_rmse: c.rel_rmse,
            mean_ratio: c.mean_ratio,
        });
        eprintln!(
            "sweep: {} mitsuba {spp} spp: {seconds:.2} s, relRMSE {:.4}",
            r.name, c.rel_rmse
        );
    }
    Ok(points)
}

const HEADER: &str =
    "scene,series,gather,spp,seconds,solve_seconds,render_seconds,rel_rmse,mean_ratio";

/// Reads back a `sweep.csv` written by [`write_csv`].
fn read_csv(path: &Path) -> Result<Vec<Point>> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    let mut points = Vec::new();
    for (k, line) in text.lines().enumerate().skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        let [
            scene,
            series,
            gather,
            spp,
            seconds,
            solve,
            render,
            rmse,
            ratio,
        ] = f.as_slice()
        else {
            bail!(
                "{}:{}: expected the columns {HEADER}",
                path.display(),
                k + 1
            );
        };
        let num = |v: &str| -> Result<f64> {
            v.parse()
                .with_context(|| format!("{}:{}: bad number {v}", path.display(), k + 1))
        };
        points.push(Point {
            scene: scene.to_string(),
            series: series.to_string(),
            gather: gather.to_string(),
            spp: spp
                .parse()
                .with_context(|| format!("{}:{}: bad spp", path.display(), k + 1))?,
            seconds: num(seconds)?,
            solve_seconds: num(solve)?,
            render_seconds: num(render)?,
            rel_rmse: num(rmse)?,
            mean_ratio: num(ratio)?,
        });
    }
    Ok(points)
}

fn write_csv(path: &Path, points: &[Point]) -> Result<()> {
    let mut s = format!("{HEADER}\n");
    for p in points {
        s += &format!(
            "{},{},{},{},{:.4},{:.4},{:.4},{:.6},{:.6}\n",
            p.scene,
            p.series,
            p.gather,
            p.spp,
            p.seconds,
            p.solve_seconds,
            p.render_seconds,
            p.rel_rmse,
            p.mean_ratio
        );
    }
    std::fs::write(path, s).with_context(|| format!("writing {}", path.display()))
}

/// The points of one curve, by increasing time.
fn curve<'a>(points: &'a [Point], scene: &str, series: &str, gather: &str) -> Vec<&'a Point> {
    let mut c: Vec<&Point> = points
        .iter()
        .filter(|p| p.scene == scene && p.series == series && p.gather == gather)
        .filter(|p| p.seconds > 0.0 && p.rel_rmse > 0.0 && p.rel_rmse.is_finite())
        .collect();
    c.sort_by(|a, b| a.seconds.total_cmp(&b.seconds));
    c
}

/// Mitsuba's error at time `t`: log–log interpolation between its points,
/// beyond them a path tracer's t^(−1/2) from the nearest one.
fn mitsuba_error(m: &[&Point], t: f64) -> Option<f64> {
    let (first, last) = (m.first()?, m.last()?);
    if t <= first.seconds {
        return Some(first.rel_rmse * (first.seconds / t).sqrt());
    }
    if t >= last.seconds {
        return Some(last.rel_rmse * (last.seconds / t).sqrt());
    }
    let k = m.windows(2).position(|w| w[1].seconds >= t)?;
    let (a, b) = (m[k], m[k + 1]);
    let f = (t / a.seconds).ln() / (b.seconds / a.seconds).ln();
    Some((a.rel_rmse.ln() + f * (b.rel_rmse / a.rel_rmse).ln()).exp())
}

/// The worst ratio of trilux's error (its best render finished by t) to
/// Mitsuba's over a log grid of times in `window`; `None` when trilux had
/// no image by the window's start.
fn worst_ratio(c: &[&Point], m: &[&Point], window: (f64, f64)) -> Option<f64> {
    let steps = 16;
    let mut worst: f64 = 0.0;
    for i in 0..=steps {
        let t = window.0 * (window.1 / window.0).powf(f64::from(i) / f64::from(steps));
        let best = c
            .iter()
            .filter(|p| p.seconds <= t)
            .map(|p| p.rel_rmse)
            .fold(f64::INFINITY, f64::min);
        if !best.is_finite() {
            return None;
        }
        worst = worst.max(best / mitsuba_error(m, t)?);
    }
    Some(worst)
}

/// The windows and targets: (series, window, largest ratio).
const TARGETS: [(&str, (f64, f64), f64); 2] = [
    ("solution", (0.5, 4.0), 1.0 / 3.0),
    ("full", (2.0, 20.0), 1.0),
];

/// Prints the equal-time ratios, the targets and every series' bias and
/// noise.
fn summary(points: &[Point]) {
    let mut scenes: Vec<&str> = points.iter().map(|p| p.scene.as_str()).collect();
    scenes.dedup();
    let mut gathers: Vec<&str> = points
        .iter()
        .filter(|p| p.series != "mitsuba")
        .map(|p| p.gather.as_str())
        .collect();
    gathers.sort_unstable();
    gathers.dedup();
    for scene in scenes {
        let m = curve(points, scene, "mitsuba", "path");
        for &g in &gathers {
            for (series, window, target) in TARGETS {
                let c = curve(points, scene, series, g);
                if c.is_empty() {
                    continue;
                }
                let ratios: Vec<String> = c
                    .iter()
                    .filter_map(|p| {
                        let e = mitsuba_error(&m, p.seconds)?;
                        Some(format!(
                            "{} spp {:.2} s {:.2}",
                            p.spp,
                            p.seconds,
                            p.rel_rmse / e
                        ))
                    })
                    .collect();
                let worst = match worst_ratio(&c, &m, window) {
                    Some(w) if w <= target => format!("{w:.2} (target ≤ {target:.2}: met)"),
                    Some(w) => format!("{w:.2} (target ≤ {target:.2}: missed)"),
                    None if m.is_empty() => "no Mitsuba curve".to_string(),
                    None => format!("no image by {} s (target missed)", window.0),
                };
                println!(
                    "{scene} {g} {series}: error / Mitsuba's at equal time: {}; worst over {}–{} s: {worst}",
                    ratios.join(", "),
                    window.0,
                    window.1
                );
            }
            bias_and_noise(points, scene, g);
        }
    }
}

/// One series' bias (error at the largest sample count) and noise.
fn bias_and_noise(points: &[Point], scene: &str, gather: &str) {
    let c = curve(points, scene, "solution", gather);
    let Some(last) = c.iter().max_by_key(|p| p.spp) else {
        return;
    };
    let bias = last.rel_rmse;
    let noise: Vec<String> = c
        .iter()
        .map(|p| {
            let n = (p.rel_rmse.powi(2) - bias * bias).max(0.0).sqrt();
            format!("{} spp {n:.4} ({:.2} s)", p.spp, p.render_seconds)
        })
        .collect();
    println!(
        "{scene} {gather}: bias ≤ {bias:.4} (error at {} spp, mean ratio {:.4}); noise {}",
        last.spp,
        last.mean_ratio,
        noise.join(", ")
    );
}

/// Colour and label of a curve.
fn style(series: &str, gather: &str) -> (plotters::style::RGBColor, String) {
    use plotters::style::RGBColor;
    let colour = match (series, gather) {
        ("mitsuba", _) => RGBColor(30, 80, 220),
        ("solution", "links") => RGBColor(220, 30, 30),
        ("full", "links") => RGBColor(120, 0, 0),
        ("solution", _) => RGBColor(240, 150, 0),
        _ => RGBColor(150, 90, 0),
    };
    let label = match series {
        "mitsuba" => "Mitsuba 3 path".to_string(),
        "solution" => format!("trilux {gather}, from a saved solution"),
        _ => format!("trilux {gather}, solve + render"),
    };
    (colour, label)
}

/// The log–log plot of error against time, one panel per scene.
fn plot(points: &[Point], path: &Path) -> Result<()> {
    use plotters::prelude::*;
    let mut scenes: Vec<&str> = points.iter().map(|p| p.scene.as_str()).collect();
    scenes.dedup();
    let rows = scenes.len().max(1) as u32;
    let root_area = SVGBackend::new(path, (720, 360 * rows)).into_drawing_area();
    root_area.fill(&WHITE).map_err(plot_error)?;
    let panels = root_area.split_evenly((rows as usize, 1));
    for (scene, area) in scenes.iter().zip(panels) {
        let mine: Vec<&Point> = points
            .iter()
            .filter(|p| p.scene == *scene && p.seconds > 0.0 && p.rel_rmse > 0.0)
            .collect();
        let (t0, t1) = bounds(mine.iter().map(|p| p.seconds));
        let (e0, e1) = bounds(mine.iter().map(|p| p.rel_rmse));
        let mut chart = ChartBuilder::on(&area)
            .caption(*scene, ("sans-serif", 20))
            .margin(10)
            .x_label_area_size(40)
            .y_label_area_size(60)
            .build_cartesian_2d((t0..t1).log_scale(), (e0..e1).log_scale())
            .map_err(plot_error)?;
        chart
            .configure_mesh()
            .x_desc("wall time (s)")
            .y_desc("relative RMSE")
            .draw()
            .map_err(plot_error)?;
        let mut keys: Vec<(&str, &str)> = mine
            .iter()
            .map(|p| (p.series.as_str(), p.gather.as_str()))
            .collect();
        keys.sort_unstable();
        keys.dedup();
        for (series, gather) in keys {
            let c = curve(points, scene, series, gather);
            let (colour, label) = style(series, gather);
            let xy: Vec<(f64, f64)> = c.iter().map(|p| (p.seconds, p.rel_rmse)).collect();
            chart
                .draw_series(LineSeries::new(xy.clone(), colour.stroke_width(2)))
                .map_err(plot_error)?
                .label(label)
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], colour));
            chart
                .draw_series(xy.into_iter().map(|p| Circle::new(p, 3, colour.filled())))
                .map_err(plot_error)?;
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .position(SeriesLabelPosition::UpperRight)
            .draw()
            .map_err(plot_error)?;
    }
    root_area.present().map_err(plot_error)?;
    Ok(())
}

/// A log axis range covering `values` with some room.
fn bounds(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values.fold((f64::MAX, f64::MIN), |(a, b), v| (a.min(v), b.max(v)));
    if lo > hi {
        (0.1, 10.0)
    } else {
        (lo / 1.5, hi * 1.5)
    }
}

fn plot_error<E: std::fmt::Display>(e: E) -> anyhow::Error {
    anyhow::anyhow!("drawing the sweep plot: {e}")
}
