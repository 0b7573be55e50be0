//! `cargo xtask sweep`: runtime against error, trilux beside Mitsuba 3.
//!
//! For every scene with a reference in tests/golden/ (or those given with
//! `--only`), trilux renders at each quality preset and sample count of the
//! grid, timed as solve plus render (in-process, the library the `trilux`
//! command runs), and
//! Mitsuba 3's path tracer renders at a range of sample counts (timed by
//! `tests/golden/mitsuba_time.py`, kernel compilation excluded) when
//! `python3 -c "import mitsuba"` works. Each image is compared with the
//! reference (`trilux_render::compare`, relative RMSE over unmasked
//! pixels).
//!
//! Output in `target/sweep/` (or `--out DIR`):
//! - `sweep.csv`: scene, renderer, quality, spp, seconds, solve_seconds,
//!   rel_rmse, mean_ratio;
//! - `sweep.png`: relative RMSE against seconds, both on log scales (one
//!   decade per grid line), one panel row per scene; trilux series in warm
//!   colours (draft orange, default red, high dark red), Mitsuba in blue;
//!   points joined in order of sample count.
//!
//! Bias and noise: trilux's error at its largest sample count is mostly the
//! bias of the solution (gather noise falls as 1/√spp while bias stays);
//! the summary prints both, noise² = error² − bias² per point.

use std::path::PathBuf;
use std::process::Command;

use anyhow::{Context, Result, bail};
use trilux_render::{ExtraBounce, Image, compare};

use crate::golden::{references, render_trilux, root};

/// One measured point.
#[derive(Clone, Debug)]
pub struct Point {
    /// Scene name.
    pub scene: String,
    /// `trilux` or `mitsuba`.
    pub renderer: &'static str,
    /// Quality preset (trilux) or `path` (Mitsuba).
    pub quality: String,
    /// Samples per pixel.
    pub spp: u32,
    /// Seconds (trilux: solve + render wall time).
    pub seconds: f64,
    /// Seconds of the solve alone (trilux; 0 for Mitsuba).
    pub solve_seconds: f64,
    /// Relative RMSE against the reference (unmasked).
    pub rel_rmse: f64,
    /// Mean ratio against the reference (unmasked).
    pub mean_ratio: f64,
}

fn mitsuba_available() -> bool {
    Command::new("python3")
        .args(["-c", "import mitsuba"])
        .output()
        .is_ok_and(|o| o.status.success())
}

/// `cargo xtask sweep [--only NAME]... [--out DIR] [--no-mitsuba]
/// [--spp a,b,c] [--quality q1,q2] [--mitsuba-spp a,b,c]`, or `--replot`
/// (after `--out`, if any) to redraw the plot from an existing CSV.
pub fn main(args: &[String]) -> Result<()> {
    let mut only = Vec::new();
    let mut out = root().join("target/sweep");
    let mut with_mitsuba = true;
    let mut spps = vec![4u32, 16, 64, 256];
    let mut qualities: Vec<String> = vec!["draft".into(), "default".into(), "high".into()];
    let mut mitsuba_spps = vec![4u32, 16, 64, 256, 1024];
    let list = |s: Option<&String>| -> Result<Vec<u32>> {
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
            "--no-mitsuba" => with_mitsuba = false,
            "--replot" => {
                let points = read_csv(&out.join("sweep.csv"))?;
                plot(&points)?.write_png(&out.join("sweep.png"), 0.0)?;
                summary(&points);
                return Ok(());
            }
            "--spp" => spps = list(it.next())?,
            "--mitsuba-spp" => mitsuba_spps = list(it.next())?,
            "--quality" => {
                qualities = it
                    .next()
                    .context("--quality needs a list")?
                    .split(',')
                    .map(str::to_owned)
                    .collect()
            }
            other => bail!("unknown argument {other}"),
        }
    }
    std::fs::create_dir_all(&out)?;
    let with_mitsuba = with_mitsuba && mitsuba_available();
    let mut points = Vec::new();
    for r in references(&only)? {
        let (w, h) = (r.image.width(), r.image.height());
        for q in &qualities {
            for &spp in &spps {
                let run = render_trilux(&r.name, w, h, q, spp, ExtraBounce::default())?;
                run.image
                    .write_exr(&out.join(format!("{}-{q}-{spp}.exr", r.name)))?;
                let seconds = run.solve_seconds + run.render_seconds;
                let c = compare(&run.image, &r.image, r.mask.as_ref())?;
                points.push(Point {
                    scene: r.name.clone(),
                    renderer: "trilux",
                    quality: q.clone(),
                    spp,
                    seconds,
                    solve_seconds: run.solve_seconds,
                    rel_rmse: c.rel_rmse,
                    mean_ratio: c.mean_ratio,
                });
                eprintln!(
                    "sweep: {} trilux {q} {spp} spp: {seconds:.2} s, relRMSE {:.4}",
                    r.name, c.rel_rmse
                );
            }
        }
        if with_mitsuba {
            let scene = root().join(format!("scenes/{}.xml", r.name));
            for &spp in &mitsuba_spps {
                let exr = out.join(format!("{}-mitsuba-{spp}.exr", r.name));
                let o = Command::new("python3")
                    .arg(root().join("tests/golden/mitsuba_time.py"))
                    .arg(&scene)
                    .args([w.to_string(), spp.to_string()])
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
                    renderer: "mitsuba",
                    quality: "path".into(),
                    spp,
                    seconds,
                    solve_seconds: 0.0,
                    rel_rmse: c.rel_rmse,
                    mean_ratio: c.mean_ratio,
                });
                eprintln!(
                    "sweep: {} mitsuba {spp} spp: {seconds:.2} s, relRMSE {:.4}",
                    r.name, c.rel_rmse
                );
            }
        }
    }
    write_csv(&out.join("sweep.csv"), &points)?;
    plot(&points)?.write_png(&out.join("sweep.png"), 0.0)?;
    summary(&points);
    println!("wrote {} and sweep.png", out.join("sweep.csv").display());
    Ok(())
}

/// Reads back a `sweep.csv` written by [`write_csv`].
fn read_csv(path: &std::path::Path) -> Result<Vec<Point>> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    let mut points = Vec::new();
    for line in text.lines().skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        let [scene, renderer, quality, spp, seconds, solve, rmse, ratio] = f.as_slice() else {
            bail!("bad line in {}: {line}", path.display());
        };
        points.push(Point {
            scene: scene.to_string(),
            renderer: if *renderer == "mitsuba" {
                "mitsuba"
            } else {
                "trilux"
            },
            quality: quality.to_string(),
            spp: spp.parse()?,
            seconds: seconds.parse()?,
            solve_seconds: solve.parse()?,
            rel_rmse: rmse.parse()?,
            mean_ratio: ratio.parse()?,
        });
    }
    Ok(points)
}

fn write_csv(path: &std::path::Path, points: &[Point]) -> Result<()> {
    let mut s =
        String::from("scene,renderer,quality,spp,seconds,solve_seconds,rel_rmse,mean_ratio\n");
    for p in points {
        s += &format!(
            "{},{},{},{},{:.4},{:.4},{:.6},{:.6}\n",
            p.scene,
            p.renderer,
            p.quality,
            p.spp,
            p.seconds,
            p.solve_seconds,
            p.rel_rmse,
            p.mean_ratio
        );
    }
    std::fs::write(path, s).with_context(|| format!("writing {}", path.display()))
}

/// Prints, per trilux series, the bias (error at the largest spp) and the
/// noise of each point (√(err² − bias²)).
fn summary(points: &[Point]) {
    let mut keys: Vec<(String, String)> = points
        .iter()
        .filter(|p| p.renderer == "trilux")
        .map(|p| (p.scene.clone(), p.quality.clone()))
        .collect();
    keys.dedup();
    for (scene, q) in keys {
        let series: Vec<&Point> = points
            .iter()
            .filter(|p| p.renderer == "trilux" && p.scene == scene && p.quality == q)
            .collect();
        let Some(last) = series.iter().max_by_key(|p| p.spp) else {
            continue;
        };
        let bias = last.rel_rmse;
        let noise: Vec<String> = series
            .iter()
            .map(|p| {
                format!(
                    "{} spp {:.4}",
                    p.spp,
                    (p.rel_rmse.powi(2) - bias * bias).max(0.0).sqrt()
                )
            })
            .collect();
        println!(
            "{scene} {q}: bias ≤ {bias:.4} (error at {} spp); noise {}",
            last.spp,
            noise.join(", ")
        );
    }
}

/// Colour of a series.
fn colour(renderer: &str, quality: &str) -> [f32; 3] {
    match (renderer, quality) {
        ("mitsuba", _) => [0.1, 0.3, 0.9],
        (_, "draft") => [1.0, 0.6, 0.0],
        (_, "high") => [0.5, 0.0, 0.0],
        _ => [0.9, 0.1, 0.1],
    }
}

/// 3×5 pixel glyphs for axis labels: digits, `e`, `-` (rows top to bottom,
/// 3 bits each, most significant bit = left column).
fn glyph(c: char) -> Option<[u8; 5]> {
    Some(match c {
        '0' => [7, 5, 5, 5, 7],
        '1' => [2, 6, 2, 2, 7],
        '2' => [7, 1, 7, 4, 7],
        '3' => [7, 1, 7, 1, 7],
        '4' => [5, 5, 7, 1, 1],
        '5' => [7, 4, 7, 1, 7],
        '6' => [7, 4, 7, 5, 7],
        '7' => [7, 1, 1, 1, 1],
        '8' => [7, 5, 7, 5, 7],
        '9' => [7, 5, 7, 1, 7],
        'e' => [0, 7, 7, 4, 7],
        '-' => [0, 0, 7, 0, 0],
        _ => return None,
    })
}

/// Draws `text` with its top-left corner at (x, y), 2 pixels per font pixel.
fn draw_text(px: &mut [[f32; 3]], w: usize, h: usize, x: usize, y: usize, text: &str) {
    for (k, c) in text.chars().enumerate() {
        let Some(g) = glyph(c) else { continue };
        for (row, bits) in g.iter().enumerate() {
            for col in 0..3 {
                if bits & (4 >> col) != 0 {
                    for (dy, dx) in [(0, 0), (0, 1), (1, 0), (1, 1)] {
                        let (xx, yy) = (x + k * 8 + col * 2 + dx, y + row * 2 + dy);
                        if xx < w && yy < h {
                            px[yy * w + xx] = [0.0; 3];
                        }
                    }
                }
            }
        }
    }
}

/// A log-log plot of error against time, one panel per scene (in the
/// order of the CSV). Grid lines are decades, labelled `1eK` (seconds on x,
/// relative RMSE on y).
pub fn plot(points: &[Point]) -> Result<Image> {
    let mut scenes: Vec<&str> = points.iter().map(|p| p.scene.as_str()).collect();
    scenes.dedup();
    let (pw, ph) = (480usize, 240usize);
    let (w, h) = (pw, ph * scenes.len().max(1));
    let mut px = vec![[1.0f32; 3]; w * h];
    let valid = |p: &&Point| p.seconds > 0.0 && p.rel_rmse > 0.0 && p.rel_rmse.is_finite();
    let lx = |v: f64| v.log10();
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for p in points.iter().filter(valid) {
        x0 = x0.min(lx(p.seconds).floor());
        x1 = x1.max(lx(p.seconds).ceil());
        y0 = y0.min(lx(p.rel_rmse).floor());
        y1 = y1.max(lx(p.rel_rmse).ceil());
    }
    if x0 >= x1 {
        (x0, x1) = (-1.0, 1.0);
    }
    if y0 >= y1 {
        (y0, y1) = (-3.0, 0.0);
    }
    let margin = 40.0;
    let mut all_labels: Vec<(usize, usize, String)> = Vec::new();
    for (k, scene) in scenes.iter().enumerate() {
        let oy = (k * ph) as f64;
        let to_px = |s: f64, e: f64| -> (f64, f64) {
            let fx = (lx(s) - x0) / (x1 - x0);
            let fy = (lx(e) - y0) / (y1 - y0);
            (
                margin + fx * (pw as f64 - 2.0 * margin),
                oy + ph as f64 - margin - fy * (ph as f64 - 2.0 * margin),
            )
        };
        let mut put = |x: f64, y: f64, c: [f32; 3]| {
            let (xi, yi) = (x.round() as i64, y.round() as i64);
            if xi >= 0 && yi >= 0 && (xi as usize) < w && (yi as usize) < h {
                px[yi as usize * w + xi as usize] = c;
            }
        };
        // Grid: one line per decade; panel frame.
        let grey = [0.8, 0.8, 0.8];
        for d in (x0 as i64)..=(x1 as i64) {
            let (x, _) = to_px(10f64.powi(d as i32), 1.0);
            for y in (oy as usize + 40)..(oy as usize + ph - 40) {
                put(x, y as f64, grey);
            }
        }
        for d in (y0 as i64)..=(y1 as i64) {
            let (_, y) = to_px(1.0, 10f64.powi(d as i32));
            for x in 40..(pw - 40) {
                put(x as f64, y, grey);
            }
        }
        for x in 0..pw {
            put(x as f64, oy, [0.0; 3]);
        }
        for d in (x0 as i64)..=(x1 as i64) {
            let (x, _) = to_px(10f64.powi(d as i32), 1.0);
            all_labels.push((
                (x - 8.0).max(0.0) as usize,
                oy as usize + ph - 32,
                format!("1e{d}"),
            ));
        }
        for d in (y0 as i64)..=(y1 as i64) {
            let (_, y) = to_px(1.0, 10f64.powi(d as i32));
            all_labels.push((2, (y - 5.0).max(0.0) as usize, format!("1e{d}")));
        }
        let mut series: Vec<(&str, &str)> = points
            .iter()
            .filter(|p| p.scene == *scene)
            .map(|p| (p.renderer, p.quality.as_str()))
            .collect();
        series.dedup();
        for (r, q) in series {
            let mut s: Vec<&Point> = points
                .iter()
                .filter(|p| p.scene == *scene && p.renderer == r && p.quality == q)
                .filter(valid)
                .collect();
            s.sort_by_key(|p| p.spp);
            let c = colour(r, q);
            for pair in s.windows(2) {
                let (a, b) = (
                    to_px(pair[0].seconds, pair[0].rel_rmse),
                    to_px(pair[1].seconds, pair[1].rel_rmse),
                );
                let n = ((b.0 - a.0).abs().max((b.1 - a.1).abs()) as usize).max(1);
                for i in 0..=n {
                    let t = i as f64 / n as f64;
                    put(a.0 + (b.0 - a.0) * t, a.1 + (b.1 - a.1) * t, c);
                }
            }
            for p in s {
                let (x, y) = to_px(p.seconds, p.rel_rmse);
                for dy in -2..=2 {
                    for dx in -2..=2 {
                        put(x + dx as f64, y + dy as f64, c);
                    }
                }
            }
        }
    }
    for (x, y, t) in &all_labels {
        draw_text(&mut px, w, h, *x, *y, t);
    }
    Ok(Image::from_pixels(w as u32, h as u32, px)?)
}
