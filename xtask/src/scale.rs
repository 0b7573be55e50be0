//! `cargo xtask scale`: solve cost against scene size, measured as a user
//! would (the pipeline the `trilux` command runs: scene file read,
//! prepared, solved; no render), one case after another on generated
//! scenes (`scale_scenes`).
//!
//! For every case: input surfaces, wall-clock seconds (preparing and
//! solving, the gather links included), shots, links made, stored
//! interactions, gather links, the process's peak memory (a counting global
//! allocator over the whole case) and the solver's own `peak_memory_bytes`.
//! Written to `target/scale/scale.json`, a Markdown table on standard
//! output, and with `--plot FILE.svg` a log–log plot of seconds (and peak
//! memory) against input surfaces, one series per kind of case.
//!
//! `cargo xtask scale [--boxes 4,16,64,256] [--meshes 4,16,64,256]
//! [--grid 20000,200000] [--curtain] [--facets AROUND,ALONG] [--scene
//! FILE.xml]... [--quality Q] [--no-clustering] [--cluster-angle θ] [--plot
//! FILE.svg] [--out DIR]`, or `--compare 4,16 [--angles 0.25,0.5]`
//! (clustered at each θ against unclustered surface means on the boxes
//! rooms).

use std::fmt::Write as _;
use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context, Result, bail};
use trilux::{Observer, Plan, SolutionSource};
use trilux_solver::{Quality, SolverSettings};

use crate::counting_alloc;
use crate::golden::root;
use crate::scale_scenes::{Case, write_case};

/// One measured case.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Row {
    /// Case name.
    pub case: String,
    /// Kind of case (series of the plot).
    pub kind: String,
    /// Input surfaces.
    pub input_surfaces: usize,
    /// Wall-clock seconds, prepare + solve.
    pub seconds: f64,
    /// Shots.
    pub shots: u64,
    /// Links made over the solve.
    pub links: u64,
    /// Stored interaction nodes after the solve.
    pub interactions: usize,
    /// Root interactions (stored hierarchies).
    pub root_interactions: usize,
    /// Gather links kept with the solution.
    pub gather_links: usize,
    /// Peak bytes allocated by the process during the case.
    pub peak_bytes: usize,
    /// The solver's own `peak_memory_bytes`.
    pub solver_peak_bytes: u64,
    /// Convergence ratio reached.
    pub convergence_ratio: f64,
}

fn list(s: Option<&String>) -> Result<Vec<u32>> {
    s.context("a comma-separated list is needed")?
        .split(',')
        .map(|v| v.trim().parse::<u32>().context("bad number"))
        .collect()
}

/// Runs one case.
fn run_case(case: Case, settings: &SolverSettings, dir: &std::path::Path) -> Result<Row> {
    let path = write_case(case, dir)?;
    let mut row = run_file(&path, settings)?;
    row.case = case.name();
    row.kind = match case {
        Case::Boxes(_) => "boxes",
        Case::Meshes(_) => "meshes",
        Case::Grid(_) => "grid",
        Case::Curtain => "curtain",
        Case::Facets(..) => "facets",
    }
    .into();
    Ok(row)
}

/// Runs one scene file.
fn run_file(path: &std::path::Path, settings: &SolverSettings) -> Result<Row> {
    counting_alloc::reset_peak();
    let start = Instant::now();
    let scene = trilux_scene::load(path).map_err(|e| anyhow::anyhow!("{e}"))?;
    let plan = Plan {
        mode: scene.mode(),
        solver: settings.clone(),
        source: SolutionSource::Solve,
        save: None,
        solution_file: false,
        bake: None,
        render: None,
    };
    // Progress every 2 000 shots, so that a long case shows where it is.
    let mut on_shot = |p: &trilux_solver::Progress| {
        if p.shots.is_multiple_of(2000) {
            eprintln!(
                "  {} shots, CR {:.4}, {} interactions, {:.0} s",
                p.shots,
                p.convergence_ratio,
                p.interactions,
                start.elapsed().as_secs_f64()
            );
        }
    };
    let observer = Observer {
        solve: &mut on_shot,
        render: &|_, _| {},
        stop: None,
    };
    let outcome = trilux::pipeline::run(&scene, &plan, observer)?;
    let seconds = start.elapsed().as_secs_f64();
    let s = &outcome.solve;
    let name = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    Ok(Row {
        case: name,
        kind: "file".into(),
        input_surfaces: s.input_surfaces,
        seconds,
        shots: s.shots,
        links: s.links_total,
        interactions: s.interactions,
        root_interactions: s.root_interactions,
        gather_links: s.gather_links,
        peak_bytes: counting_alloc::peak(),
        solver_peak_bytes: s.peak_memory_bytes,
        convergence_ratio: s.convergence_ratio,
    })
}

/// Solves `case` without clustering and with it at each θ of `angles`
/// (default quality) and prints, per θ, the ratio of each reflecting
/// face's mean Lambertian radiance with clustering to without:
/// area-weighted mean and spread, the worst face, and the escaped share
/// of the emitted flux (a closed room: light lost to estimation error).
fn compare(case: Case, dir: &std::path::Path, angles: &[f64]) -> Result<()> {
    use trilux_solver::Solution;
    let path = write_case(case, dir)?;
    let scene = trilux_scene::load(&path).map_err(|e| anyhow::anyhow!("{e}"))?;
    let prepared = trilux::prepare::<3>(&scene)?;
    let solve = |angle: Option<f64>| -> Result<Solution<3>> {
        let mut settings = SolverSettings::preset(Quality::Default);
        settings.clustering = angle.is_some();
        settings.cluster_angle = angle.unwrap_or(settings.cluster_angle);
        let start = Instant::now();
        let solver = trilux_solver::Solver::<3>::new(std::sync::Arc::clone(&prepared), settings)
            .map_err(|e| anyhow::anyhow!("{e}"))?;
        let solution = solver.solve(|_| {});
        let s = solution.stats();
        let escaped: f64 = s.escaped_flux.iter().sum::<f64>() / s.emitted_flux.iter().sum::<f64>();
        eprintln!(
            "{}: cluster angle {angle:?}: {:.2} s, {} shots, escaped {:.4} %",
            case.name(),
            start.elapsed().as_secs_f64(),
            s.shots,
            100.0 * escaped
        );
        Ok(solution)
    };
    let reference = solve(None)?;
    for &angle in angles {
        let clustered = solve(Some(angle))?;
        let r = face_ratios(&clustered, &reference);
        println!(
            "{}: θ {angle}: surface mean radiance, clustered / unclustered: area-weighted mean {:.4}, sd {:.4}, worst face {:.4}, worst face above 1 m² {:.4}",
            case.name(),
            r.mean,
            r.sd,
            r.worst,
            r.big_worst
        );
    }
    Ok(())
}

/// Area-weighted statistics of per-face ratios of mean radiance.
struct Ratios {
    mean: f64,
    sd: f64,
    worst: f64,
    big_worst: f64,
}

/// The ratio of every reflecting front face's mean radiance in `a` to the
/// one in `b` (faces dark in `b` left out).
fn face_ratios(a: &trilux_solver::Solution<3>, b: &trilux_solver::Solution<3>) -> Ratios {
    use trilux_geometry::{FaceId, Side};
    let geom = a.forest().geometry();
    let (mut worst, mut big_worst) = (1.0f64, 1.0f64);
    let (mut sum_w, mut sum_wr, mut sum_wr2) = (0.0, 0.0, 0.0);
    for s in 0..geom.surfaces().len() as u32 {
        let surface = trilux_geometry::SurfaceId(s);
        let area = geom.surface(surface).area();
        let face = FaceId::new(surface, Side::Front);
        let (x, y) = (
            a.surface_mean_radiance(face).sum(),
            b.surface_mean_radiance(face).sum(),
        );
        if y <= 1e-9 {
            continue;
        }
        let r = x / y;
        if (r - 1.0).abs() > 0.05 && std::env::var("SCALE_DEBUG").is_ok() {
            let sf = geom.surface(surface);
            eprintln!(
                "  surface {s} shape {} piece {} area {area:.3} centre {:?}: {x:.4} vs {y:.4}",
                sf.shape,
                sf.piece,
                sf.bounds.centre()
            );
        }
        if (r - 1.0).abs() > (worst - 1.0).abs() {
            worst = r;
        }
        if area > 1.0 && (r - 1.0).abs() > (big_worst - 1.0).abs() {
            big_worst = r;
        }
        sum_w += area;
        sum_wr += area * r;
        sum_wr2 += area * r * r;
    }
    let mean = sum_wr / sum_w;
    let sd = (sum_wr2 / sum_w - mean * mean).max(0.0).sqrt();
    Ratios {
        mean,
        sd,
        worst,
        big_worst,
    }
}

fn table(rows: &[Row]) -> String {
    let mut t = String::from(
        "| case | input surfaces | seconds | shots | links | interactions | gather links | peak memory (MB) | solver arenas (MB) | CR |\n|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for r in rows {
        let _ = writeln!(
            t,
            "| {} | {} | {:.2} | {} | {} | {} | {} | {:.0} | {:.0} | {:.4} |",
            r.case,
            r.input_surfaces,
            r.seconds,
            r.shots,
            r.links,
            r.interactions,
            r.gather_links,
            r.peak_bytes as f64 / 1e6,
            r.solver_peak_bytes as f64 / 1e6,
            r.convergence_ratio
        );
    }
    t
}

/// `cargo xtask scale` (module docs).
pub fn main(args: &[String]) -> Result<()> {
    let mut cases = Vec::new();
    let mut rows_extra: Vec<PathBuf> = Vec::new();
    let mut quality = Quality::Default;
    let mut clustering = true;
    let mut cluster_angle: Option<f64> = None;
    let mut compare_cases: Vec<u32> = Vec::new();
    let mut angles: Vec<f64> = Vec::new();
    let mut plot: Option<PathBuf> = None;
    let mut out = root().join("target/scale");
    let mut it = args.iter();
    while let Some(a) = it.next() {
        match a.as_str() {
            "--boxes" => cases.extend(list(it.next())?.into_iter().map(Case::Boxes)),
            "--meshes" => cases.extend(list(it.next())?.into_iter().map(Case::Meshes)),
            "--grid" => cases.extend(list(it.next())?.into_iter().map(Case::Grid)),
            "--curtain" => cases.push(Case::Curtain),
            "--facets" => {
                let v = list(it.next())?;
                if v.len() != 2 {
                    bail!("--facets needs AROUND,ALONG");
                }
                cases.push(Case::Facets(v[0], v[1]));
            }
            "--scene" => {
                let p = PathBuf::from(it.next().context("--scene needs a file")?);
                rows_extra.push(p);
            }
            "--compare" => compare_cases = list(it.next())?,
            "--angles" => {
                let v = it.next().context("--angles needs θ,θ,...")?;
                angles = v
                    .split(',')
                    .map(|x| x.parse::<f64>().with_context(|| format!("--angles: '{x}'")))
                    .collect::<Result<_>>()?;
            }
            "--cluster-angle" => {
                let v = it.next().context("--cluster-angle needs a value")?;
                cluster_angle = Some(
                    v.parse()
                        .with_context(|| format!("--cluster-angle: '{v}'"))?,
                );
            }
            "--quality" => {
                quality = it
                    .next()
                    .context("--quality needs a value")?
                    .parse()
                    .map_err(|e: String| anyhow::anyhow!(e))?;
            }
            "--no-clustering" => clustering = false,
            "--plot" => plot = Some(PathBuf::from(it.next().context("--plot needs a file")?)),
            "--out" => out = PathBuf::from(it.next().context("--out needs a folder")?),
            other => bail!("unknown argument {other}"),
        }
    }
    if !compare_cases.is_empty() {
        if angles.is_empty() {
            angles.push(SolverSettings::preset(Quality::Default).cluster_angle);
        }
        for n in compare_cases {
            compare(Case::Boxes(n), &root().join("target/scale/scenes"), &angles)?;
        }
        return Ok(());
    }
    if cases.is_empty() {
        cases = [4, 16, 64, 256].into_iter().map(Case::Boxes).collect();
        cases.extend([4, 16, 64, 256].into_iter().map(Case::Meshes));
    }
    let mut settings = SolverSettings::preset(quality);
    settings.clustering = clustering;
    if let Some(theta) = cluster_angle {
        settings.cluster_angle = theta;
    }
    // Experiments on one setting at a time (`TRILUX_MAX_SHOTS` and the
    // others `SolverSettings::override_from` names); unset, the preset.
    settings
        .override_from(|name| std::env::var(name).ok())
        .map_err(|e| anyhow::anyhow!(e))?;
    let scenes = out.join("scenes");
    let mut rows = Vec::new();
    for case in cases {
        let row = run_case(case, &settings, &scenes)?;
        eprintln!(
            "scale: {} ({} surfaces): {:.2} s, {} shots, {} links, {:.0} MB",
            row.case,
            row.input_surfaces,
            row.seconds,
            row.shots,
            row.links,
            row.peak_bytes as f64 / 1e6
        );
        rows.push(row);
    }
    for p in rows_extra {
        let row = run_file(&p, &settings)?;
        eprintln!(
            "scale: {} ({} surfaces): {:.2} s",
            row.case, row.input_surfaces, row.seconds
        );
        rows.push(row);
    }
    let json = serde_json::to_string_pretty(&rows)?;
    std::fs::create_dir_all(&out)?;
    std::fs::write(out.join("scale.json"), json)?;
    print!("{}", table(&rows));
    for pair in rows.windows(2) {
        let (a, b) = (&pair[0], &pair[1]);
        if a.kind == b.kind && a.input_surfaces > 0 {
            println!(
                "{} → {}: ×{:.2} input surfaces, ×{:.2} time",
                a.case,
                b.case,
                b.input_surfaces as f64 / a.input_surfaces as f64,
                b.seconds / a.seconds.max(1e-9)
            );
        }
    }
    if let Some(p) = plot {
        std::fs::write(&p, svg(&rows)).with_context(|| format!("writing {}", p.display()))?;
    }
    Ok(())
}

/// A log–log SVG plot: seconds (solid) and peak memory in GB (dashed)
/// against input surfaces, one colour per kind of case, with the slopes
/// k¹ and k² for reference.
fn svg(rows: &[Row]) -> String {
    let (w, h, m) = (640.0, 420.0, 60.0);
    let (x0, x1, y0, y1) = (1.0f64, 4.0f64, -2.0f64, 3.0f64); // log10 ranges
    let px = |k: f64| m + (k.log10() - x0) / (x1 - x0) * (w - 2.0 * m);
    let py = |v: f64| h - m - (v.max(1e-3).log10() - y0) / (y1 - y0) * (h - 2.0 * m);
    let mut s = format!(
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" font-family="sans-serif" font-size="11"><rect width="100%" height="100%" fill="white"/>"#
    );
    for e in 1..=4 {
        let x = px(10f64.powi(e));
        let _ = write!(
            s,
            r##"<line x1="{x}" y1="{m}" x2="{x}" y2="{}" stroke="#ddd"/><text x="{x}" y="{}" text-anchor="middle">10^{e}</text>"##,
            h - m,
            h - m + 15.0
        );
    }
    for e in -2..=3 {
        let y = py(10f64.powi(e));
        let _ = write!(
            s,
            r##"<line x1="{m}" y1="{y}" x2="{}" y2="{y}" stroke="#ddd"/><text x="{}" y="{}" text-anchor="end">10^{e}</text>"##,
            w - m,
            m - 5.0,
            y + 4.0
        );
    }
    let _ = write!(
        s,
        r#"<text x="{}" y="{}" text-anchor="middle">input surfaces k</text><text x="15" y="{}" transform="rotate(-90 15 {})" text-anchor="middle">seconds (solid), peak GB (dashed)</text>"#,
        w / 2.0,
        h - 20.0,
        h / 2.0,
        h / 2.0
    );
    // Reference slopes through (30, 1 s).
    for (p, label) in [(1.0, "k"), (2.0, "k²")] {
        let k1 = 1000.0f64;
        let _ = write!(
            s,
            r##"<line x1="{}" y1="{}" x2="{}" y2="{}" stroke="#999" stroke-dasharray="2,3"/><text x="{}" y="{}" fill="#999">{label}</text>"##,
            px(30.0),
            py(1.0),
            px(k1),
            py((k1 / 30.0).powf(p)),
            px(k1) + 3.0,
            py((k1 / 30.0).powf(p))
        );
    }
    let colours = [
        ("boxes", "#c0392b"),
        ("meshes", "#2471a3"),
        ("grid", "#239b56"),
        ("curtain", "#7d3c98"),
    ];
    for (i, (kind, colour)) in colours.iter().enumerate() {
        let series: Vec<&Row> = rows.iter().filter(|r| r.kind == *kind).collect();
        if series.is_empty() {
            continue;
        }
        for (dash, value) in [("", 0usize), ("5,4", 1)] {
            let pts: Vec<String> = series
                .iter()
                .map(|r| {
                    let v = if value == 0 {
                        r.seconds
                    } else {
                        r.peak_bytes as f64 / 1e9
                    };
                    format!("{:.1},{:.1}", px(r.input_surfaces as f64), py(v))
                })
                .collect();
            let _ = write!(
                s,
                r#"<polyline points="{}" fill="none" stroke="{colour}" stroke-width="2" stroke-dasharray="{dash}"/>"#,
                pts.join(" ")
            );
        }
        let _ = write!(
            s,
            r#"<text x="{}" y="{}" fill="{colour}">{kind}</text>"#,
            m + 10.0,
            m + 15.0 + 14.0 * i as f64
        );
    }
    s.push_str("</svg>\n");
    s
}
