//! Solver settings: the paper's error bounds (FFErr, FrErr, MinArea), the
//! photometric threshold of §4.3, and when to stop (§6).

use serde::{Deserialize, Serialize};

/// How light leaving Lambertian surfaces is represented.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[non_exhaustive]
pub enum Transport {
    /// Lambertian parts keep one outgoing radiance per element (two-point,
    /// like hierarchical radiosity); interactions are stored only for glossy
    /// senders (docs/architecture.md, "Two-point and stored transport"). The
    /// default.
    TwoPoint,
    /// The paper's uniform treatment: every sender, Lambertian or not, keeps
    /// per-receiver interactions. For ablation and cross-checking.
    Uniform,
}

/// Quality presets for the command line.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[non_exhaustive]
pub enum Quality {
    /// Fast previews: CR 0.95, coarse elements.
    Draft,
    /// CR 0.999 (residual 0.1 % of the emitted flux).
    Default,
    /// CR 0.9999, fine elements.
    High,
}

impl std::str::FromStr for Quality {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "draft" => Ok(Quality::Draft),
            "default" => Ok(Quality::Default),
            "high" => Ok(Quality::High),
            other => Err(format!(
                "unknown quality '{other}' (expected draft, default or high)"
            )),
        }
    }
}

/// Everything that steers a solve. Part of the solution's hash.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[non_exhaustive]
pub struct SolverSettings {
    /// Stop when the convergence ratio CR (the share of all the light the
    /// surfaces will reflect that they have reflected; the paper's §6
    /// figure in a closed scene) reaches this.
    pub convergence: f64,
    /// Stop after this many shots whatever the convergence ratio: a guard
    /// against a scene that converges too slowly, not a way to end early
    /// (a room of 6 151 input surfaces takes 206 183 shots to CR 0.999;
    /// `time_budget_seconds` bounds the time).
    pub max_shots: u32,
    /// Depth limit of element trees (the paper's tables imply 3 to 4).
    pub max_depth: u32,
    /// MinArea as a fraction of the scene's bounding-box diagonal squared:
    /// elements smaller than this are never split.
    pub min_area_fraction: f64,
    /// FFErr: a pair link is accurate enough when the point form factor to
    /// the sender varies by less than this over the receiver (so that the
    /// gathered radiance can be pushed down unchanged); three-point links
    /// compare the spread of the point form factor over (j, k) against it.
    pub ff_eps: f64,
    /// FrErr: bound on π F (fr_max − fr_min) over the three elements.
    pub fr_eps: f64,
    /// Photometric criterion (paper §4.3): a link carrying less than this
    /// fraction of the total emitted flux is not refined further.
    pub flux_eps: f64,
    /// Shadow rays per element pair for the visibility fraction (a square
    /// number gives a full stratification).
    pub visibility_samples: u32,
    /// Two-point for Lambertian parts, or the paper's uniform treatment.
    pub transport: Transport,
    /// Clustering above the input surfaces (`cluster`, docs/solver.md,
    /// "Clustering"): transport to distant groups of input surfaces at
    /// once. On in every preset; off for ablation and for the analytic
    /// tests that check the paper's algorithm alone.
    #[serde(default = "clustering_default")]
    pub clustering: bool,
    /// θ, the clustering's error bound (radians): a cluster of radius r_C
    /// is far from a face of radius r_A at distance d when r_C ≤ θ (d −
    /// r_A) (docs/solver.md, "Clustering", where the default is measured
    /// against unclustered solves). Emitters' cuts use the tighter of this
    /// and 0.1.
    #[serde(default = "cluster_angle_default")]
    pub cluster_angle: f64,
    /// Deferred glossy reception (`deferred`, docs/solver.md, "Deferred
    /// glossy reception"): the glossy share of a link below the
    /// photometric threshold waits at its face, summed per sender, until
    /// the sum reaches the threshold. On in every preset; off for ablation.
    #[serde(default = "defer_glossy_default")]
    pub defer_glossy: bool,
    /// Stop shooting once this many seconds have passed since the solve's
    /// preparation began, with the best solution so far (progressive
    /// refinement's promise). The final gather's links are still made
    /// after the last shot. Not part of the solution's identity: it is
    /// neither saved nor hashed, so a solution made within a budget loads
    /// with any budget.
    #[serde(skip)]
    pub time_budget_seconds: Option<f64>,
}

fn clustering_default() -> bool {
    true
}

fn defer_glossy_default() -> bool {
    true
}

/// The default θ of every preset.
pub(crate) const DEFAULT_CLUSTER_ANGLE: f64 = 0.5;

fn cluster_angle_default() -> f64 {
    DEFAULT_CLUSTER_ANGLE
}

/// The longest time budget a solve accepts (a year, in seconds).
pub const MAX_TIME_BUDGET_SECONDS: f64 = 365.0 * 24.0 * 3600.0;

impl SolverSettings {
    /// The settings of a quality preset.
    pub fn preset(quality: Quality) -> Self {
        match quality {
            Quality::Draft => SolverSettings {
                convergence: 0.95,
                max_shots: 20_000,
                max_depth: 4,
                min_area_fraction: 1e-5,
                ff_eps: 0.02,
                fr_eps: 0.5,
                flux_eps: 1e-4,
                visibility_samples: 9,
                transport: Transport::TwoPoint,
                clustering: true,
                cluster_angle: DEFAULT_CLUSTER_ANGLE,
                defer_glossy: true,
                time_budget_seconds: None,
            },
            Quality::Default => SolverSettings {
                convergence: 0.999,
                max_shots: 1_000_000,
                max_depth: 5,
                min_area_fraction: 1e-6,
                ff_eps: 0.005,
                fr_eps: 0.25,
                flux_eps: 1e-5,
                visibility_samples: 16,
                transport: Transport::TwoPoint,
                clustering: true,
                cluster_angle: DEFAULT_CLUSTER_ANGLE,
                defer_glossy: true,
                time_budget_seconds: None,
            },
            Quality::High => SolverSettings {
                convergence: 0.9999,
                max_shots: 5_000_000,
                max_depth: 6,
                min_area_fraction: 1e-7,
                ff_eps: 0.001,
                fr_eps: 0.1,
                flux_eps: 1e-6,
                visibility_samples: 25,
                transport: Transport::TwoPoint,
                clustering: true,
                cluster_angle: DEFAULT_CLUSTER_ANGLE,
                defer_glossy: true,
                time_budget_seconds: None,
            },
        }
    }

    /// Overrides single settings from `TRILUX_MAX_SHOTS`, `TRILUX_MAX_DEPTH`, `TRILUX_FF_EPS`,
    /// `TRILUX_FR_EPS`, `TRILUX_FLUX_EPS`, `TRILUX_VISIBILITY_SAMPLES` and
    /// `TRILUX_CLUSTERING` and `TRILUX_DEFER_GLOSSY` (`true` or `false`)
    /// as `lookup` returns them (the examples pass `std::env::var`): a way
    /// to run experiments on one parameter at a time. The message names
    /// the variable that does not parse.
    pub fn override_from(&mut self, lookup: impl Fn(&str) -> Option<String>) -> Result<(), String> {
        fn parse<T: std::str::FromStr>(name: &str, v: &str) -> Result<T, String> {
            v.parse().map_err(|_| format!("{name}: cannot parse '{v}'"))
        }
        if let Some(v) = lookup("TRILUX_MAX_SHOTS") {
            self.max_shots = parse("TRILUX_MAX_SHOTS", &v)?;
        }
        if let Some(v) = lookup("TRILUX_MAX_DEPTH") {
            self.max_depth = parse("TRILUX_MAX_DEPTH", &v)?;
        }
        if let Some(v) = lookup("TRILUX_FF_EPS") {
            self.ff_eps = parse("TRILUX_FF_EPS", &v)?;
        }
        if let Some(v) = lookup("TRILUX_FR_EPS") {
            self.fr_eps = parse("TRILUX_FR_EPS", &v)?;
        }
        if let Some(v) = lookup("TRILUX_FLUX_EPS") {
            self.flux_eps = parse("TRILUX_FLUX_EPS", &v)?;
        }
        if let Some(v) = lookup("TRILUX_VISIBILITY_SAMPLES") {
            self.visibility_samples = parse("TRILUX_VISIBILITY_SAMPLES", &v)?;
        }
        if let Some(v) = lookup("TRILUX_CLUSTERING") {
            self.clustering = parse("TRILUX_CLUSTERING", &v)?;
        }
        if let Some(v) = lookup("TRILUX_DEFER_GLOSSY") {
            self.defer_glossy = parse("TRILUX_DEFER_GLOSSY", &v)?;
        }
        if let Some(v) = lookup("TRILUX_CLUSTER_ANGLE") {
            self.cluster_angle = parse("TRILUX_CLUSTER_ANGLE", &v)?;
        }
        self.validate()
    }

    /// Checks that every value is usable; the message names the field.
    pub fn validate(&self) -> Result<(), String> {
        let unit = |name: &str, v: f64| {
            if v.is_finite() && (0.0..=1.0).contains(&v) {
                Ok(())
            } else {
                Err(format!("{name} must be in [0, 1], got {v}"))
            }
        };
        unit("convergence", self.convergence)?;
        unit("min_area_fraction", self.min_area_fraction)?;
        unit("flux_eps", self.flux_eps)?;
        for (name, v) in [("ff_eps", self.ff_eps), ("fr_eps", self.fr_eps)] {
            if !(v.is_finite() && v > 0.0) {
                return Err(format!("{name} must be positive, got {v}"));
            }
        }
        if !(self.cluster_angle.is_finite()
            && self.cluster_angle > 0.0
            && self.cluster_angle <= 1.0)
        {
            return Err(format!(
                "cluster_angle must be in (0, 1] radians, got {}",
                self.cluster_angle
            ));
        }
        if self.visibility_samples == 0 {
            return Err("visibility_samples must be at least 1".into());
        }
        if self.max_depth > 12 {
            return Err(format!("max_depth {} is above 12", self.max_depth));
        }
        if let Some(seconds) = self.time_budget_seconds {
            Self::validate_time_budget(seconds)?;
        }
        Ok(())
    }

    /// A time budget must be a finite number of seconds, not negative, and
    /// at most a year (a `Duration` holds it exactly).
    pub(crate) fn validate_time_budget(seconds: f64) -> Result<(), String> {
        if seconds.is_finite() && (0.0..=MAX_TIME_BUDGET_SECONDS).contains(&seconds) {
            Ok(())
        } else {
            Err(format!(
                "time budget must be in [0, {MAX_TIME_BUDGET_SECONDS}] seconds, got {seconds}"
            ))
        }
    }
}

impl Default for SolverSettings {
    fn default() -> Self {
        SolverSettings::preset(Quality::Default)
    }
}

#[cfg(test)]
mod tests {
    //! The clustering's θ: read from its variable, refused outside (0, 1].

    use super::*;

    #[test]
    fn cluster_angle_is_read_and_bounded() {
        let mut s = SolverSettings::preset(Quality::Default);
        assert_eq!(s.cluster_angle, DEFAULT_CLUSTER_ANGLE);
        let lookup =
            |v: &'static str| move |n: &str| (n == "TRILUX_CLUSTER_ANGLE").then(|| v.to_string());
        s.override_from(lookup("0.3"))
            .unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(s.cluster_angle, 0.3);
        for bad in ["0", "-0.5", "1.5", "NaN", "inf"] {
            let mut s = SolverSettings::preset(Quality::Default);
            let e = s.override_from(lookup(bad));
            assert!(
                e.as_ref().is_err_and(|e| e.contains("cluster_angle")),
                "{bad}: {e:?}"
            );
        }
        let mut s = SolverSettings::preset(Quality::Default);
        let e = s.override_from(lookup("wide"));
        assert!(e.is_err_and(|e| e.contains("TRILUX_CLUSTER_ANGLE")));
    }
}
