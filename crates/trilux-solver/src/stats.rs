//! Statistics of a solve, as `--stats` writes them (README, "Using it").

use serde::{Deserialize, Serialize};

/// What a solve did and where the energy went.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
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
    /// Most links alive at once (links live for one shot, paper §4.2).
    pub links_peak: usize,
    /// Links created over the whole solve.
    pub links_total: u64,
    /// Gather links kept with the solution for rendering (the final
    /// gather's transfers, `gather_links`).
    #[serde(default)]
    pub gather_links: usize,
    /// Shooting iterations.
    pub shots: u64,
    /// CR = (IF − RF)/IF (paper §6).
    pub convergence_ratio: f64,
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
    /// Warnings (e.g. a Lambertian reflectance above 1 clamped).
    pub warnings: Vec<String>,
}
