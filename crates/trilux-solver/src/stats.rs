//! Statistics of a solve, as `--stats` writes them (README, "Using it").

use serde::{Deserialize, Serialize};

/// What a solve did and where the energy went.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[non_exhaustive]
pub struct SolveStats {
    /// Input surfaces of the scene.
    pub input_surfaces: usize,
    /// Elements that took part in the solution (appear in a link or a stored
    /// interaction).
    pub elements: usize,
    /// Elements of the uniform subdivision at the finest allowed level (the
    /// paper's "potential elements").
    pub potential_elements: u64,
    /// Stored interaction nodes after the solve.
    pub interactions: usize,
    /// Interactions between potential elements (potential_elements²).
    pub potential_interactions: u64,
    /// Root interactions (pairs of input-surface sides that exchange light).
    pub root_interactions: usize,
    /// Root interactions whose throughput was made: those whose sender
    /// face received light (the rest stay dark and trace no rays;
    /// docs/solver.md, "Lazy root throughputs").
    #[serde(default)]
    pub root_throughputs: usize,
    /// Most links alive at once (links live for one shot, paper §4.2).
    pub links_peak: usize,
    /// Links created over the whole solve.
    pub links_total: u64,
    /// Gather links kept with the solution for rendering (the final
    /// gather's transfers, `gather_links`).
    #[serde(default)]
    pub gather_links: usize,
    /// Senders the final gather refined (faces that send light).
    #[serde(default)]
    pub gather_senders: usize,
    /// Of those, the senders reached after the time budget was spent:
    /// linked at their roots, with a few shadow rays per pair, not
    /// refined (docs/solver.md, "The final gather").
    #[serde(default)]
    pub gather_coarse_senders: usize,
    /// Sender–receiver pairs the gather linked without tracing the root
    /// pair, because a bound of the flux they can carry was below the
    /// photometric threshold.
    #[serde(default)]
    pub gather_bounded_pairs: u64,
    /// Links the shots made coarser because the time budget ran out
    /// during a shot: pairs and three-point links linked where they stood
    /// instead of split, and stored nodes used above a pair link's
    /// receiver instead of split down to it (docs/solver.md, "The
    /// deadline inside a shot"). 0 without a budget or within it.
    #[serde(default)]
    pub late_links: u64,
    /// Pair links into glossy faces received after the time budget ran
    /// out, whose glossy renormalisation took the face's mean hemisphere
    /// coverage instead of their element's (docs/solver.md, "The deadline
    /// inside a shot").
    #[serde(default)]
    pub late_groups: u64,
    /// Pair links into glossy faces whose glossy share was below the
    /// photometric threshold, received at the stored nodes above their
    /// element with the face's mean coverage (docs/solver.md, "Faint
    /// glossy shares").
    #[serde(default)]
    pub coarse_groups: u64,
    /// Pair links whose glossy share waited at its face, summed with its
    /// pair's earlier ones (docs/solver.md, "Deferred glossy reception").
    #[serde(default)]
    pub deferred_links: u64,
    /// Shots that released a face's waiting glossy light (counted in
    /// `shots`).
    #[serde(default)]
    pub deferred_releases: u64,
    /// Root throughputs the shots made after the time budget ran out (the
    /// part of a cut-short shot that refinement does not bound).
    #[serde(default)]
    pub late_root_throughputs: u64,
    /// Their CPU seconds, summed over threads.
    #[serde(default)]
    pub late_root_seconds: f64,
    /// Seconds spent preparing (before the first shot) and in the final
    /// gather; `solve_seconds` counts the shots, push-pull and gather.
    #[serde(default)]
    pub prepare_seconds: f64,
    /// See `prepare_seconds`.
    #[serde(default)]
    pub gather_seconds: f64,
    /// Shooting iterations.
    pub shots: u64,
    /// CR: the share of all the light the scene's surfaces will reflect
    /// that they have reflected so far (docs/solver.md, "Convergence ratio
    /// and ambient term"); the paper's figure in a closed scene of uniform
    /// reflectance. 1 − CR bounds the light the image is missing.
    pub convergence_ratio: f64,
    /// The paper's CR = (IF − RF)/IF (§6), which counts light that left
    /// the scene (or a black surface absorbed) as converged.
    #[serde(default)]
    pub paper_convergence_ratio: f64,
    /// The unshot remainder's estimate and the ambient term the solution's
    /// readers add for it.
    #[serde(default)]
    pub ambient: Ambient,
    /// Emitted flux per band (W).
    pub emitted_flux: Vec<f64>,
    /// Absorbed flux per band (W).
    pub absorbed_flux: Vec<f64>,
    /// Escaped flux per band (W).
    pub escaped_flux: Vec<f64>,
    /// Residual (unshot) flux per band (W).
    pub residual_flux: Vec<f64>,
    /// Wall-clock seconds of the solve.
    pub solve_seconds: f64,
    /// Spectral bands.
    pub bands: usize,
    /// Band edges in nm (`None` in RGB mode).
    pub wavelengths_nm: Option<Vec<f64>>,
    /// The smallest escaped flux of any shot, as a fraction of that shot's
    /// flux (band minimum). Negative would mean a shot created energy.
    pub min_shot_escaped: f64,
    /// The smallest absorbed flux of any receiving element in any shot, as
    /// a fraction of what arrived there (band minimum). Negative would mean
    /// an element reflected more than it received.
    pub min_element_absorbed: f64,
    /// Far blocks over every face's cut through the cluster hierarchy
    /// (`cluster_transport`; 0 with clustering off or in a scene too
    /// small to have distant clusters).
    #[serde(default)]
    pub far_blocks: usize,
    /// Glossy faces with a far field.
    #[serde(default)]
    pub far_fields: usize,
    /// Peak bytes of the solver's arenas over the solve: element trees and
    /// their radiance, interaction nodes, the links of the largest shot,
    /// the throughput cache, the cluster hierarchy and the gather links
    /// (summed sizes, `Solver::arena_bytes`; not the process's whole
    /// allocation, which `cargo xtask scale` measures with a counting
    /// allocator).
    #[serde(default)]
    pub peak_memory_bytes: u64,
    /// Why the shooting loop stopped.
    #[serde(default)]
    pub stop_reason: StopReason,
    /// The time budget the solve was given (seconds from the start of its
    /// preparation), if any.
    #[serde(default)]
    pub time_budget_seconds: Option<f64>,
    /// The convergence over the solve: a point after shots 1, 2, 4, 8, …
    /// and after the last shot.
    #[serde(default)]
    pub convergence_trace: Vec<TracePoint>,
    /// Warnings (e.g. a Lambertian reflectance above 1 clamped).
    pub warnings: Vec<String>,
}

/// Why a solve's shooting loop stopped.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
#[non_exhaustive]
pub enum StopReason {
    /// The convergence ratio reached its target.
    #[default]
    Converged,
    /// No source had unshot light left (CR short of 1 only by rounding).
    NothingUnshot,
    /// The shot cap (`SolverSettings::max_shots`) was reached first.
    ShotCap,
    /// The time budget ran out first: the solution is the best so far.
    TimeBudget,
    /// The solve was asked to stop ([`crate::Solver::stop_when`]: SIGINT
    /// or SIGTERM in the command): the solution is partial, the best so far.
    Interrupted,
}

/// One point of [`SolveStats::convergence_trace`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct TracePoint {
    /// Shots so far.
    pub shots: u64,
    /// Seconds since the solve's preparation began.
    pub seconds: f64,
    /// The convergence ratio after those shots.
    pub convergence_ratio: f64,
    /// The paper's (IF − RF)/IF after those shots (never falls).
    #[serde(default)]
    pub paper_convergence_ratio: f64,
}

/// The light the residual will still add, and the ambient term that stands
/// in for it (Cohen et al. 1988; `crate::ambient`). Per band: watts and
/// radiance in the scene's units.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[non_exhaustive]
pub struct Ambient {
    /// Cohen's ambient radiance A_amb: an element of reflectance ρ would
    /// send ρ · A_amb more than the stopped solve gave it. The solution's
    /// readers use it only where the residual's later bounces were not
    /// gathered over the final links (`crate::local_ambient`; a solution
    /// file without them).
    pub radiance: Vec<f64>,
    /// The future reflected light as a share of all the light the scene
    /// will reflect (band sum): 1 − CR.
    pub share: f64,
    /// The fraction a of a shot of reflected light that comes back as
    /// reflected light (measured on the solve's shots, the unshot residual
    /// counted at the lit faces' reflectance: what CR uses; the ambient
    /// radiance uses the measured part alone).
    pub return_fraction: Vec<f64>,
    /// Light the scene's surfaces reflected during the solve (W).
    pub reflected_flux: Vec<f64>,
    /// Light the residual will still be reflected (W): its reflected part
    /// R returns R · a / (1 − a), its emitted part E (not shot yet) is
    /// reflected first at the lit faces' reflectance a₀, E · a₀ / (1 − a).
    pub future_reflected_flux: Vec<f64>,
    /// E, the emitted light in the residual (W).
    #[serde(default)]
    pub unshot_emission_flux: Vec<f64>,
    /// a₀, the reflectance unshot emission is first reflected at.
    #[serde(default)]
    pub first_reflectance: Vec<f64>,
    /// The lit reflecting area Σ ρ A the ambient light spreads over (m²).
    pub reflecting_area: Vec<f64>,
}
