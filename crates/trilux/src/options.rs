//! Command-line options shared by `solve` and `render`, and the value
//! parsers that turn a malformed value into a usage error (status 2) before
//! any file is read.

use clap::{Args, ValueEnum};
use glam::DVec3;
use trilux::pipeline::{Plan, RenderPlan, SolutionSource};
use trilux_color::Mode;
use trilux_solver::{Quality, SolverSettings};

/// How light is carried: 3 RGB bands or spectral bands.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum ModeArg {
    /// Linear sRGB, 3 bands.
    Rgb,
    /// Spectral bands (20 of 15 nm over the visible range).
    Spectral,
}

/// Solver options shared by `solve` and `render`.
#[derive(Debug, Args, Clone)]
pub struct SolveOptions {
    /// Quality preset: error bounds, depth limit and default convergence.
    #[arg(long, value_enum, default_value = "default")]
    pub quality: QualityArg,
    /// Target convergence ratio CR in [0, 1]: the share of all the light
    /// the surfaces will reflect that they have reflected (default from
    /// --quality: 0.95, 0.999, 0.9999).
    #[arg(long, value_parser = parse_unit)]
    pub convergence: Option<f64>,
    /// Stop the solve after this many seconds (from the start of its
    /// preparation) with the best solution so far; the stats say what it
    /// reached.
    #[arg(long, value_name = "SECONDS", value_parser = parse_budget, allow_hyphen_values = true)]
    pub time_budget: Option<f64>,
    /// Override the scene's colour mode.
    #[arg(long, value_enum)]
    pub mode: Option<ModeArg>,
}

/// `$name` values for an XML scene, as Mitsuba's `-D name=value`.
#[derive(Debug, Args, Clone, Default)]
pub struct SceneParams {
    /// Set the XML scene's $NAME to VALUE, overriding its <default> (as
    /// Mitsuba's -D); repeatable.
    #[arg(short = 'D', long = "define", value_name = "NAME=VALUE", value_parser = parse_define)]
    pub define: Vec<(String, String)>,
}

/// `NAME=VALUE`, NAME made of letters, digits and `_` (the characters a
/// `$name` reference takes).
fn parse_define(text: &str) -> Result<(String, String), String> {
    let Some((name, value)) = text.split_once('=') else {
        return Err(format!("{} is not NAME=VALUE", quoted(text)));
    };
    if name.is_empty() || !name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') {
        return Err(format!(
            "{} is not a parameter name (letters, digits and _)",
            quoted(name)
        ));
    }
    Ok((name.to_string(), value.to_string()))
}

/// The quality presets.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum QualityArg {
    /// Fast previews (CR 0.95, coarse elements).
    Draft,
    /// CR 0.999.
    Default,
    /// CR 0.9999, fine elements.
    High,
}

impl SolveOptions {
    /// The solver settings these options ask for.
    pub fn settings(&self) -> SolverSettings {
        let quality = match self.quality {
            QualityArg::Draft => Quality::Draft,
            QualityArg::Default => Quality::Default,
            QualityArg::High => Quality::High,
        };
        let mut settings = SolverSettings::preset(quality);
        if let Some(cr) = self.convergence {
            settings.convergence = cr;
        }
        settings.time_budget_seconds = self.time_budget;
        settings
    }

    /// The colour mode: the override, else the scene's own.
    pub fn mode(&self, scene: &trilux_scene::Scene) -> Mode {
        match self.mode {
            Some(ModeArg::Rgb) => Mode::Rgb,
            Some(ModeArg::Spectral) => Mode::Spectral,
            None => scene.mode(),
        }
    }

    /// The plan of a command (`solve`, `render`, `bake`): these options'
    /// mode and solver settings, the saved `solution` to load (else a
    /// solve), and what the command makes of the solution.
    pub fn plan<'p>(
        &self,
        scene: &trilux_scene::Scene,
        solution: Option<&'p std::path::Path>,
        product: Product,
    ) -> Plan<'p> {
        let mut plan = Plan {
            mode: self.mode(scene),
            solver: self.settings(),
            source: source(solution),
            save: None,
            solution_file: false,
            bake: None,
            render: None,
        };
        match product {
            Product::SolutionFile => plan.solution_file = true,
            Product::Render(r) => plan.render = Some(r),
            Product::Bake(b) => plan.bake = Some(b),
        }
        plan
    }
}

/// What a command makes of its solution.
#[derive(Debug)]
pub enum Product {
    /// The solution file's bytes (`trilux solve`).
    SolutionFile,
    /// A rendered view (`trilux render`).
    Render(RenderPlan),
    /// A glTF bake (`trilux bake`).
    Bake(trilux_bake::BakeOptions),
}

/// A finite number for which `ok` holds, `range` naming the values
/// accepted in the message.
fn parse_real(text: &str, ok: impl Fn(f64) -> bool, range: &str) -> Result<f64, String> {
    let v: f64 = text
        .parse()
        .map_err(|_| format!("{} is not a number", quoted(text)))?;
    if v.is_finite() && ok(v) {
        Ok(v)
    } else {
        Err(format!("{v} is not {range}"))
    }
}

/// A number in [0, 1].
fn parse_unit(text: &str) -> Result<f64, String> {
    parse_real(text, |v| (0.0..=1.0).contains(&v), "in [0, 1]")
}

/// A time budget: seconds, finite, not negative, at most a year.
fn parse_budget(text: &str) -> Result<f64, String> {
    let max = trilux_solver::settings::MAX_TIME_BUDGET_SECONDS;
    parse_real(
        text,
        |v| (0.0..=max).contains(&v),
        "a number of seconds in [0, 31536000] (a year)",
    )
}

/// `text` quoted for a message, its middle elided when long (a value of
/// megabytes must not become an error line of megabytes).
pub fn quoted(text: &str) -> String {
    format!("'{}'", trilux_scene::error::elide(text, 60))
}

/// An integer in `1..=max`.
fn parse_in(text: &str, max: u32, what: &str) -> Result<u32, String> {
    match text.parse::<u32>() {
        Ok(v) if (1..=max).contains(&v) => Ok(v),
        Ok(_) => Err(format!("must lie in 1..={max} ({what})")),
        Err(_) => Err(format!("{} is not a positive integer", quoted(text))),
    }
}

/// Worker threads: 1 to 1024.
pub fn parse_threads(text: &str) -> Result<u32, String> {
    parse_in(text, 1024, "threads")
}

/// A film edge: 1 to `MAX_FILM_EDGE` pixels (docs/limits.md).
pub fn parse_film_edge(text: &str) -> Result<u32, String> {
    use trilux_scene::limits::MAX_FILM_EDGE;
    parse_in(text, MAX_FILM_EDGE, "pixels, docs/limits.md")
}

/// Samples per pixel: 1 to the sampler's maximum.
pub fn parse_spp(text: &str) -> Result<u32, String> {
    parse_in(
        text,
        trilux_render::sampler::MAX_SAMPLES,
        "samples per pixel",
    )
}

/// A relative error target in (0, 1).
pub fn parse_target_error(text: &str) -> Result<f64, String> {
    parse_real(text, |v| v > 0.0 && v < 1.0, "in (0, 1)")
}

/// An exposure in stops, within ±64 (2^64 already turns any radiance
/// trilux accepts into white or black).
pub fn parse_exposure(text: &str) -> Result<f64, String> {
    parse_real(text, |v| v.abs() <= 64.0, "within ±64 stops")
}

/// A field of view in (0, 180) degrees.
pub fn parse_fov(text: &str) -> Result<f64, String> {
    parse_real(text, |v| v > 0.0 && v < 180.0, "in (0, 180) degrees")
}

/// Eye, target and optional up of `--lookat`.
pub type LookAt = (DVec3, DVec3, Option<DVec3>);

/// `ox,oy,oz,tx,ty,tz[,ux,uy,uz]`: 6 or 9 finite numbers.
pub fn parse_lookat(text: &str) -> Result<LookAt, String> {
    let values: Vec<f64> = text
        .split(',')
        .map(|v| v.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|_| format!("{} is not a comma-separated list of numbers", quoted(text)))?;
    use trilux_geometry::limits::{MAX_COORDINATE, within};
    if values.iter().any(|v| !within(*v)) {
        return Err(format!(
            "values must be finite and within the coordinate limit ±{MAX_COORDINATE:e} (docs/limits.md)"
        ));
    }
    let v = |i: usize| DVec3::new(values[i], values[i + 1], values[i + 2]);
    match values.len() {
        6 => Ok((v(0), v(3), None)),
        9 => Ok((v(0), v(3), Some(v(6)))),
        n => Err(format!("takes 6 or 9 numbers (eye, target[, up]), got {n}")),
    }
}

/// Where a command's solution comes from: the saved one given by
/// `--solution`, else a solve.
fn source(solution: Option<&std::path::Path>) -> SolutionSource<'_> {
    match solution {
        Some(path) => SolutionSource::Load(path),
        None => SolutionSource::Solve,
    }
}
