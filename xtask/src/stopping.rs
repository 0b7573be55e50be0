//! `cargo xtask stopping`: what stopping at a convergence ratio leaves out
//! of the image (docs/solver.md, "Convergence ratio and ambient term").
//!
//! Per scene: a reference solved to CR 0.9999, then the same scene stopped
//!
//! - **before**: where the paper's CR (IF − RF)/IF first reaches the target
//!   (how trilux stopped before this measure existed; the solve is stopped
//!   by its stop flag after that shot), rendered without the ambient term;
//! - **after, no ambient**: at the target of today's CR, without the term;
//! - **after**: at the target of today's CR, with the ambient term,
//!
//! each rendered the same way as the reference (same estimator, samples
//! and seed), and the image means compared. Scenes: `scenes/NAME.xml`
//! names, or `atrium` (built in: an open courtyard under a black sky box
//! that emits inward, as `scenes/interiors/convert.py` makes Sponza's
//! sky) and `closed-room` (built in: a closed room lit by a lamp).
//!
//! `cargo xtask stopping [--target CR] [--gather links|preview] [--spp N]
//! [--size PIXELS] [--quality draft|default|high] [SCENE ...]`

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use anyhow::{Context, Result, bail};
use trilux::{ViewOverrides, prepare, scene_camera};
use trilux_color::WithBands;
use trilux_render::{Estimator, RenderSettings, render};
use trilux_solver::{Quality, Solution, Solver, SolverSettings};

use crate::golden::{estimator, quality, root};

/// The open courtyard: a 4 × 4 m floor, 3 m walls and two pillars, no
/// roof, inside a black box 12 m wide that emits radiance 1 inward (the
/// sky); the camera looks across the courtyard.
const ATRIUM: &str = r#"<scene version="3.0.0">
    <sensor type="perspective">
        <float name="fov" value="70"/>
        <transform name="to_world">
            <lookat origin="1.6, 1.2, 1.7" target="-1, 0.6, -1" up="0, 1, 0"/>
        </transform>
        <film type="hdrfilm">
            <integer name="width" value="128"/>
            <integer name="height" value="128"/>
        </film>
    </sensor>
    <bsdf type="diffuse" id="stone"><rgb name="reflectance" value="0.65, 0.6, 0.5"/></bsdf>
    <bsdf type="diffuse" id="floor"><rgb name="reflectance" value="0.5, 0.45, 0.4"/></bsdf>
    <shape type="rectangle">
        <transform name="to_world"><scale x="2" y="2"/><rotate x="1" angle="-90"/></transform>
        <ref id="floor"/>
    </shape>
    <shape type="rectangle">
        <transform name="to_world"><scale x="2" y="1.5"/><translate y="1.5" z="-2"/></transform>
        <ref id="stone"/>
    </shape>
    <shape type="rectangle">
        <transform name="to_world"><scale x="2" y="1.5"/><rotate y="1" angle="180"/><translate y="1.5" z="2"/></transform>
        <ref id="stone"/>
    </shape>
    <shape type="rectangle">
        <transform name="to_world"><scale x="2" y="1.5"/><rotate y="1" angle="90"/><translate x="-2" y="1.5"/></transform>
        <ref id="stone"/>
    </shape>
    <shape type="rectangle">
        <transform name="to_world"><scale x="2" y="1.5"/><rotate y="1" angle="-90"/><translate x="2" y="1.5"/></transform>
        <ref id="stone"/>
    </shape>
    <shape type="cube">
        <transform name="to_world"><scale x="0.2" y="1.2" z="0.2"/><translate x="-0.8" y="1.2" z="-0.5"/></transform>
        <ref id="stone"/>
    </shape>
    <shape type="cube">
        <transform name="to_world"><scale x="0.2" y="1.2" z="0.2"/><translate x="0.6" y="1.2" z="-1.0"/></transform>
        <ref id="stone"/>
    </shape>
    <shape type="cube">
        <boolean name="flip_normals" value="true"/>
        <transform name="to_world"><scale x="6" y="3" z="6"/><translate y="3.01"/></transform>
        <bsdf type="diffuse"><rgb name="reflectance" value="0"/></bsdf>
        <emitter type="area"><rgb name="radiance" value="1"/></emitter>
    </shape>
</scene>"#;

/// A closed room, 4 × 3 × 4 m, lit by a lamp under its ceiling, with a
/// box on the floor; the camera inside.
const CLOSED_ROOM: &str = r#"<scene version="3.0.0">
    <sensor type="perspective">
        <float name="fov" value="70"/>
        <transform name="to_world">
            <lookat origin="1.6, 1.7, 1.7" target="-1, 0.6, -1" up="0, 1, 0"/>
        </transform>
        <film type="hdrfilm">
            <integer name="width" value="128"/>
            <integer name="height" value="128"/>
        </film>
    </sensor>
    <shape type="cube">
        <boolean name="flip_normals" value="true"/>
        <transform name="to_world"><scale x="2" y="1.5" z="2"/><translate y="1.5"/></transform>
        <bsdf type="diffuse"><rgb name="reflectance" value="0.7, 0.68, 0.6"/></bsdf>
    </shape>
    <shape type="cube">
        <transform name="to_world"><scale x="0.4" y="0.4" z="0.4"/><translate x="-0.6" y="0.4" z="-0.8"/></transform>
        <bsdf type="diffuse"><rgb name="reflectance" value="0.3, 0.4, 0.6"/></bsdf>
    </shape>
    <shape type="rectangle">
        <transform name="to_world"><scale x="0.3" y="0.3"/><rotate x="1" angle="90"/><translate y="2.99"/></transform>
        <bsdf type="diffuse"><rgb name="reflectance" value="0"/></bsdf>
        <emitter type="area"><rgb name="radiance" value="30"/></emitter>
    </shape>
</scene>"#;

/// What to measure.
struct Options {
    target: f64,
    estimator: Estimator,
    gather: String,
    spp: u32,
    size: u32,
    quality: Quality,
    scenes: Vec<String>,
}

fn parse(args: &[String]) -> Result<Options> {
    let mut o = Options {
        target: 0.95,
        estimator: Estimator::Links,
        gather: "links".into(),
        spp: 16,
        size: 128,
        quality: Quality::Default,
        scenes: Vec::new(),
    };
    let mut it = args.iter();
    while let Some(a) = it.next() {
        let mut value = || it.next().with_context(|| format!("{a} needs a value"));
        match a.as_str() {
            "--target" => o.target = value()?.parse().context("--target")?,
            "--gather" => {
                o.gather = value()?.clone();
                o.estimator = estimator(&o.gather)?;
            }
            "--spp" => o.spp = value()?.parse().context("--spp")?,
            "--size" => o.size = value()?.parse().context("--size")?,
            "--quality" => o.quality = quality(value()?)?,
            s if s.starts_with('-') => bail!("unknown option {s}"),
            s => o.scenes.push(s.to_string()),
        }
    }
    if o.scenes.is_empty() {
        o.scenes = vec!["atrium".into(), "cornell-box".into(), "closed-room".into()];
    }
    Ok(o)
}

/// One stopped solve's row.
struct Row {
    variant: &'static str,
    shots: u64,
    seconds: f64,
    cr: f64,
    paper_cr: f64,
    ambient_share: f64,
    mean: f64,
}

/// `cargo xtask stopping ...` (module docs).
pub fn main(args: &[String]) -> Result<()> {
    let o = parse(args)?;
    println!(
        "target CR {}, {} gather, {} spp, {} px, quality {:?}",
        o.target, o.gather, o.spp, o.size, o.quality
    );
    println!(
        "| scene | stopped by | shots | solve s | CR | paper CR | ambient share | mean / converged |"
    );
    println!("|---|---|---|---|---|---|---|---|");
    for name in &o.scenes {
        let scene = match name.as_str() {
            "atrium" => trilux_scene::load_str(ATRIUM, "atrium.xml"),
            "closed-room" => trilux_scene::load_str(CLOSED_ROOM, "closed-room.xml"),
            other => trilux_scene::load(root().join("scenes").join(format!("{other}.xml"))),
        }
        .map_err(|e| anyhow::anyhow!("{e}"))?;
        let rows = scene.mode().with_bands(Bench {
            scene: &scene,
            o: &o,
        })?;
        for r in rows {
            println!(
                "| {name} | {} | {} | {:.2} | {:.4} | {:.4} | {:.4} | {:.4} |",
                r.variant, r.shots, r.seconds, r.cr, r.paper_cr, r.ambient_share, r.mean
            );
        }
    }
    Ok(())
}

/// One scene's measurements, generic over its band count.
struct Bench<'a> {
    scene: &'a trilux_scene::Scene,
    o: &'a Options,
}

impl WithBands for Bench<'_> {
    type Output = Result<Vec<Row>>;
    fn run<const N: usize>(self) -> Result<Vec<Row>> {
        let Bench { scene, o } = self;
        let prepared = prepare::<N>(scene)?;
        let settings = |cr: f64| {
            let mut s = SolverSettings::preset(o.quality);
            s.convergence = cr;
            s
        };
        let view = ViewOverrides {
            width: Some(o.size),
            height: Some(o.size),
            ..Default::default()
        };
        let camera = scene_camera(scene, &view)?;
        let render_settings = RenderSettings {
            spp: o.spp,
            estimator: o.estimator,
            ..trilux::render_settings(scene.camera.as_ref().context("no camera")?)
        };
        let mean = |s: &Solution<N>| -> Result<f64> {
            let (img, _) = render(s, &camera, &render_settings, |_, _| {})?;
            Ok(img.mean().iter().sum::<f64>())
        };
        let timed = |solver: Solver<N>, stop: Option<f64>| -> Solution<N> {
            let start = Instant::now();
            let flag = Arc::new(AtomicBool::new(false));
            let setter = Arc::clone(&flag);
            let mut s = solver.stop_when(flag).solve(|p| {
                if stop.is_some_and(|t| p.paper_convergence_ratio >= t) {
                    setter.store(true, Ordering::Relaxed);
                }
            });
            s.stats_mut().solve_seconds = start.elapsed().as_secs_f64();
            s
        };
        let converged = timed(Solver::new(Arc::clone(&prepared), settings(0.9999))?, None);
        let reference = mean(&converged)?;
        let row = |variant, s: &Solution<N>, m: f64| Row {
            variant,
            shots: s.stats().shots,
            seconds: s.stats().solve_seconds,
            cr: s.stats().convergence_ratio,
            paper_cr: s.stats().paper_convergence_ratio,
            ambient_share: if s.ambient_radiance().max_value() > 0.0 {
                s.stats().ambient.share
            } else {
                0.0
            },
            mean: m / reference,
        };
        let mut rows = vec![row("converged (CR 0.9999)", &converged, reference)];
        let mut before = timed(
            Solver::new(Arc::clone(&prepared), settings(1.0))?,
            Some(o.target),
        );
        before.set_ambient(false);
        let m = mean(&before)?;
        rows.push(row("before: paper CR, no ambient", &before, m));
        let mut after = timed(
            Solver::new(Arc::clone(&prepared), settings(o.target))?,
            None,
        );
        let m = mean(&after)?;
        after.set_ambient(false);
        let m_plain = mean(&after)?;
        rows.push(row("after: CR, no ambient", &after, m_plain));
        after.set_ambient(true);
        rows.push(row("after: CR and ambient", &after, m));
        Ok(rows)
    }
}
