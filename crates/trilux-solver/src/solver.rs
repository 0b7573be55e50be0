//! The progressive shooting loop (paper §4, Fig. 7 and 9).
//!
//! ```text
//! until CR ≥ target or the shot budget is spent:
//!     S ← the source with the greatest unshot flux δΦ
//!     push-pull S (lazily, only now: §4.4)
//!     refine and link S to every receiver (two stages, see `refine`)
//!     shoot: every link adds δL·R to its receiver's L^G
//!     unlink (links live for one shot: memory O(n + k²), §4.2)
//!     zero δL over S
//! ```
//!
//! A source is either the two-point tree of a Lambertian face (emission
//! enters here) or a stored interaction hierarchy of a glossy face. This
//! module prepares a solve ([`Solver::new`]) and runs the loop; one shot's
//! phases are in `shot`, the glossy renormalisation in `glossy`.
//!
//! A solver is its `Setup` (what is fixed before the first shot: the
//! scene, the discretisation, faces, clusters, partners) and its
//! `ShotState` (what the shots change: unshot radiance, hierarchies,
//! ledger, statistics).

use std::time::{Duration, Instant};

use glam::DVec3;
use trilux_color::Spectrum;
use trilux_geometry::{ElementForest, FaceId};

use crate::error::SolverError;
use crate::final_gather::gather_links;
use crate::gather_links::GatherLinks;
use crate::interaction::Hierarchy;
use crate::link::{NodeLink, PairLink};
use crate::prepared::PreparedScene;
pub(crate) use crate::queue::Source;
use crate::settings::SolverSettings;
use crate::setup::Setup;
use crate::solution::{FarRecord, Parts, Solution};
use crate::state::ShotState;
use crate::stats::{StopReason, TracePoint};

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

/// Progress after each shot, for progress bars (the solver never prints).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Progress {
    /// Shots so far.
    pub shots: u64,
    /// Convergence ratio CR: the share of the light the scene will reflect
    /// that it has reflected (`SolveStats::convergence_ratio`).
    pub convergence_ratio: f64,
    /// The paper's (IF − RF)/IF, which never falls between shots.
    pub paper_convergence_ratio: f64,
    /// The target CR.
    pub target: f64,
    /// Stored interaction nodes.
    pub interactions: usize,
    /// Links alive during the last shot.
    pub live_links: usize,
    /// Seconds since the solve's preparation began.
    pub elapsed_seconds: f64,
    /// The time budget, if the solve has one
    /// ([`SolverSettings::time_budget_seconds`]).
    pub time_budget_seconds: Option<f64>,
}

/// Bytes of one live link of a shot (pair or node link).
fn link_bytes<const N: usize>() -> usize {
    std::mem::size_of::<PairLink<N>>().max(std::mem::size_of::<NodeLink<N>>())
}

/// How often the solve loop sums the arenas and the interaction count
/// over every hierarchy (for `peak_memory_bytes` and the progress).
const REFRESH_SHOTS: u64 = 64;

/// A prepared solve: its setup, fixed before the first shot, and the state
/// the shooting loop changes.
pub struct Solver<const N: usize> {
    pub(crate) setup: Setup<N>,
    pub(crate) state: ShotState<N>,
    /// When preparation began: the time budget counts from here.
    started: Instant,
    /// Stop shooting once this much time has passed since `started`.
    time_budget: Option<Duration>,
    /// Stop shooting once this is set (by another thread or a signal
    /// handler): an interrupted solve keeps the best solution so far.
    stop: Option<Arc<AtomicBool>>,
    /// Set while the waiting glossy light is released after the last shot
    /// (`release_all_deferred`): root throughputs are then made with the
    /// base rays.
    pub(crate) final_release: bool,
    /// The most stored hierarchies one batch of a shot's stage 2 reaches
    /// (`batch::BATCH_HIERARCHIES`; smaller in tests).
    pub(crate) batch_hierarchies: usize,
}

impl<const N: usize> Solver<N> {
    /// Prepares a solve of `scene`: element trees, faces, buried parts,
    /// root interactions and the emitters' unshot light.
    pub fn new(
        scene: Arc<PreparedScene<N>>,
        settings: SolverSettings,
    ) -> Result<Self, SolverError> {
        let started = Instant::now();
        let setup = Setup::new(scene, settings)?;
        let mut state = ShotState::new(&setup);
        let budget = setup.settings.time_budget_seconds;
        state.stats.time_budget_seconds = budget;
        state.stats.prepare_seconds = started.elapsed().as_secs_f64();
        Ok(Solver {
            setup,
            state,
            started,
            time_budget: budget.map(Duration::from_secs_f64),
            stop: None,
            final_release: false,
            batch_hierarchies: crate::batch::BATCH_HIERARCHIES,
        })
    }

    /// When the time budget runs out (`None` without one): shots reached
    /// after it stop refining (docs/solver.md, "The deadline inside a
    /// shot").
    pub(crate) fn deadline(&self) -> Option<Instant> {
        self.time_budget.map(|b| self.started + b)
    }

    /// True once the deadline has passed (never without a budget).
    pub(crate) fn past_deadline(&self) -> bool {
        self.deadline().is_some_and(|d| Instant::now() >= d)
    }

    /// Stops the shooting loop, between shots, once `flag` is set: the
    /// solve then ends as with a spent time budget, with stop reason
    /// `interrupted` (a Ctrl-C or a scheduler's SIGTERM in the command).
    pub fn stop_when(mut self, flag: Arc<AtomicBool>) -> Self {
        self.stop = Some(flag);
        self
    }

    /// Prepares `desc` ([`PreparedScene::new`]) and a solve of it.
    pub fn from_description(
        desc: &crate::prepared::SceneDescription<'_>,
        settings: SolverSettings,
    ) -> Result<Self, SolverError> {
        Solver::new(Arc::new(PreparedScene::new(desc)?), settings)
    }

    /// Total unshot (residual) flux per band.
    pub fn residual(&self) -> Spectrum<N> {
        let state = &self.state;
        let mut r: Spectrum<N> = state.face_flux.values().copied().sum();
        r += state
            .hierarchies
            .iter()
            .flatten()
            .map(|h| h.unshot_flux)
            .sum::<Spectrum<N>>();
        r += state
            .far
            .values()
            .flatten()
            .map(|f| f.unshot_flux)
            .sum::<Spectrum<N>>();
        r += state.light_flux.iter().copied().sum::<Spectrum<N>>();
        r + state.deferred.total()
    }

    /// CR: the share of all the light the scene's surfaces will reflect
    /// that they have reflected so far (`ambient`); 1 for a scene that
    /// emits nothing.
    pub fn convergence_ratio(&self) -> f64 {
        self.convergence_ratio_of(self.residual())
    }

    /// CR for the residual `residual` (the loop sums it once a shot).
    fn convergence_ratio_of(&self, residual: Spectrum<N>) -> f64 {
        if self.setup.emitted.sum() <= 0.0 {
            return 1.0;
        }
        self.state
            .interreflection
            .convergence_ratio(residual, self.unshot_emission())
    }

    /// The emitted light not shot yet, per band: faces' emission before
    /// their first shot and lights without area (`ambient`: it will be
    /// reflected at least once).
    fn unshot_emission(&self) -> Spectrum<N> {
        let state = &self.state;
        let faces: Spectrum<N> = state.unshot_emission.values().copied().sum();
        faces + state.light_flux.iter().copied().sum::<Spectrum<N>>()
    }

    /// The paper's CR = (IF − RF)/IF (§6), which counts light that left
    /// the scene as converged; 1 for a scene that emits nothing.
    pub fn paper_convergence_ratio(&self) -> f64 {
        self.paper_convergence_ratio_of(self.residual())
    }

    /// The paper's CR for the residual `residual`.
    fn paper_convergence_ratio_of(&self, residual: Spectrum<N>) -> f64 {
        let emitted = self.setup.emitted.sum();
        if emitted <= 0.0 {
            return 1.0;
        }
        ((emitted - residual.sum()) / emitted).clamp(0.0, 1.0)
    }

    /// The source with the greatest unshot flux (band sum), if any has some.
    #[cfg(test)]
    pub(crate) fn next_source(&mut self) -> Option<Source> {
        self.next_source_and_residual().0
    }

    /// [`Self::next_source`] and [`Self::residual`] (the loop needs both
    /// after every shot), from the source queue once the sources the last
    /// shot changed are read again (`queue`). With debug assertions the
    /// choice is checked against a pass over every source.
    fn next_source_and_residual(&mut self) -> (Option<Source>, Spectrum<N>) {
        let mut queue = std::mem::take(&mut self.state.queue);
        queue.refresh(|s| self.unshot_of(s));
        self.state.queue = queue;
        let (next, residual) = self.state.queue.next_and_residual();
        #[cfg(debug_assertions)]
        assert_eq!(next, self.scan_sources(), "a source changed unmarked");
        (next, residual)
    }

    /// The unshot flux of `s` now (zero while it sends).
    fn unshot_of(&self, s: Source) -> Spectrum<N> {
        let state = &self.state;
        let zero = Spectrum::zero();
        match s {
            Source::Light(k) => state.light_flux.get(k as usize).copied().unwrap_or(zero),
            Source::Radiosity(f) => state.face_flux.get(f).copied().unwrap_or(zero),
            Source::Stored(h) => state
                .hierarchies
                .get(h as usize)
                .and_then(Option::as_ref)
                .map_or(zero, |h| h.unshot_flux),
            Source::Deferred(f) => state.deferred.room.get(f).copied().unwrap_or(zero),
            Source::Far(f) => state
                .far
                .get(f)
                .and_then(Option::as_ref)
                .map_or(zero, |f| f.unshot_flux),
        }
    }

    /// The next source by a pass over every source's key (the queue's
    /// check).
    #[cfg(debug_assertions)]
    fn scan_sources(&self) -> Option<Source> {
        let mut best: Option<(Source, f64)> = None;
        let mut consider = |s: Source, flux: Spectrum<N>| {
            let sum = flux.sum();
            if sum > 0.0 && best.is_none_or(|(_, f)| sum > f) {
                best = Some((s, sum));
            }
        };
        let state = &self.state;
        for (k, f) in state.light_flux.iter().enumerate() {
            consider(Source::Light(k as u32), *f);
        }
        for (face, f) in state.face_flux.iter() {
            consider(Source::Radiosity(face), *f);
        }
        for (h, hier) in state.hierarchies.iter().enumerate() {
            if let Some(hier) = hier {
                consider(Source::Stored(h as u32), hier.unshot_flux);
            }
        }
        for (face, f) in state.deferred.room.iter() {
            consider(Source::Deferred(face), *f);
        }
        for (face, f) in state.far.iter() {
            if let Some(f) = f {
                consider(Source::Far(face), f.unshot_flux);
            }
        }
        best.map(|(s, _)| s)
    }

    /// Summed bytes of the solver's arenas now (stats'
    /// `peak_memory_bytes`): the element trees, per-element radiance,
    /// exposed areas and sample points, the stored interaction nodes, the
    /// throughput cache, the cluster hierarchy, the deferred glossy light
    /// and the root throughputs; a shot's live links come on top. It only
    /// grows, and summing it visits every hierarchy, so the loop refreshes
    /// it every [`REFRESH_SHOTS`] shots.
    pub(crate) fn arena_bytes(&self) -> u64 {
        use std::mem::size_of;
        let elements = self.setup.forest().element_count();
        let per_element = size_of::<trilux_geometry::Element>()
            + 9 * size_of::<Spectrum<N>>() // three fields × two sides, + spares
            + 2 * size_of::<f64>()
            + size_of::<[DVec3; 5]>()
            + size_of::<[DVec3; 4]>()
            + size_of::<Option<(DVec3, DVec3)>>()
            + size_of::<bool>()
            + size_of::<u32>();
        let nodes: usize = self
            .state
            .hierarchies
            .iter()
            .flatten()
            .map(|h| h.nodes.capacity())
            .sum();
        let hierarchies = self.state.hierarchies.len() * size_of::<Option<Hierarchy<N>>>();
        let partners: usize = self.setup.partners.values().map(|p| p.capacity() * 4).sum();
        (elements * per_element
            + nodes * size_of::<crate::interaction::Node<N>>()
            + hierarchies
            + partners
            + self.state.cache.bytes()
            + self.setup.clusters.bytes()
            + self.state.deferred.bytes()
            + self.state.queue.bytes()
            + self.state.roots.bytes()) as u64
    }

    /// Stored interaction nodes, over every hierarchy.
    fn interaction_count(&self) -> usize {
        self.state
            .hierarchies
            .iter()
            .flatten()
            .map(|h| h.nodes.len())
            .sum()
    }

    /// Runs shots until the target convergence ratio, the shot cap, the
    /// time budget or the stop flag ([`Solver::stop_when`]), calling `progress` after each shot, then makes every
    /// hierarchy consistent and returns the solution.
    pub fn solve(mut self, mut progress: impl FnMut(&Progress)) -> Solution<N> {
        let start = Instant::now();
        let reason = self.shoot_until_stopped(&mut progress);
        // Not past a time budget or a request to stop: the waiting light
        // then stays in the residual, with the rest of the unshot light.
        if !matches!(reason, StopReason::TimeBudget | StopReason::Interrupted) {
            self.release_all_deferred();
        }
        self.state.stats.stop_reason = reason;
        self.warn_if_short(reason);
        self.finish(start.elapsed().as_secs_f64())
    }

    /// The shooting loop; returns why it stopped.
    fn shoot_until_stopped(&mut self, progress: &mut impl FnMut(&Progress)) -> StopReason {
        let (target, max_shots) = (
            self.setup.settings.convergence,
            self.setup.settings.max_shots,
        );
        let mut next_trace = 1u64;
        let (mut next, residual) = self.next_source_and_residual();
        let mut cr = self.convergence_ratio_of(residual);
        let (mut base, mut interactions) = (self.arena_bytes(), self.interaction_count());
        loop {
            if cr >= target {
                return StopReason::Converged;
            }
            if self.state.stats.shots >= u64::from(max_shots) {
                return StopReason::ShotCap;
            }
            if self
                .time_budget
                .is_some_and(|b| self.started.elapsed() >= b)
            {
                return StopReason::TimeBudget;
            }
            if self
                .stop
                .as_ref()
                .is_some_and(|f| f.load(Ordering::Relaxed))
            {
                return StopReason::Interrupted;
            }
            let Some(source) = next else {
                return StopReason::NothingUnshot;
            };
            // On a worker of the thread pool, so that the shot's parallel
            // phases start there instead of being handed over from this
            // thread one by one (the handovers were a tenth of a large
            // scene's solve).
            let live = rayon::scope(|_| self.shoot(source));
            self.state.stats.shots += 1;
            // The sums over every hierarchy, refreshed now and then (the
            // arenas only grow; `finish` sums them once more).
            if self.state.stats.shots.is_multiple_of(REFRESH_SHOTS) {
                (base, interactions) = (self.arena_bytes(), self.interaction_count());
            }
            let bytes = base + (live * link_bytes::<N>()) as u64;
            self.state.stats.peak_memory_bytes = self.state.stats.peak_memory_bytes.max(bytes);
            // The next source and the residual, from the sources the shot
            // changed.
            let residual;
            (next, residual) = self.next_source_and_residual();
            cr = self.convergence_ratio_of(residual);
            let p = Progress {
                shots: self.state.stats.shots,
                convergence_ratio: cr,
                paper_convergence_ratio: self.paper_convergence_ratio_of(residual),
                target,
                interactions,
                live_links: live,
                elapsed_seconds: self.started.elapsed().as_secs_f64(),
                time_budget_seconds: self.time_budget.map(|b| b.as_secs_f64()),
            };
            if p.shots == next_trace {
                self.trace(&p);
                next_trace *= 2;
            }
            progress(&p);
        }
    }

    /// Appends a point to the convergence trace.
    fn trace(&mut self, p: &Progress) {
        self.state.stats.convergence_trace.push(TracePoint {
            shots: p.shots,
            seconds: p.elapsed_seconds,
            convergence_ratio: p.convergence_ratio,
            paper_convergence_ratio: p.paper_convergence_ratio,
        });
    }

    /// The last trace point, and a warning when the loop stopped short of
    /// its target.
    fn warn_if_short(&mut self, reason: StopReason) {
        let cr = self.convergence_ratio();
        let paper_convergence_ratio = self.paper_convergence_ratio();
        let shots = self.state.stats.shots;
        if self
            .state
            .stats
            .convergence_trace
            .last()
            .is_none_or(|t| t.shots != shots)
        {
            let seconds = self.started.elapsed().as_secs_f64();
            self.state.stats.convergence_trace.push(TracePoint {
                shots,
                seconds,
                convergence_ratio: cr,
                paper_convergence_ratio,
            });
        }
        let target = self.setup.settings.convergence;
        let late = self.state.stats.late_links;
        // A shot that ran into the deadline linked coarser from there on.
        let cut_short = if late > 0 {
            format!(
                "; the last shot was cut short at the budget: {late} links were made coarser than refinement asked (the light is all carried, at a lower resolution)"
            )
        } else {
            String::new()
        };
        let warning = match reason {
            StopReason::Converged | StopReason::NothingUnshot if late == 0 => return,
            StopReason::Converged | StopReason::NothingUnshot => format!(
                "the solve reached its target convergence ratio {target}, but its last shot ran past its time budget of {} s{cut_short}",
                self.time_budget.map_or(0.0, |b| b.as_secs_f64())
            ),
            StopReason::ShotCap => format!(
                "the solve stopped at its cap of {shots} shots with convergence ratio {cr:.4}, short of its target {target} (surfaces that reflect nearly all light converge slowly: lower a reflectance, or ask for less with --convergence)"
            ),
            StopReason::TimeBudget => format!(
                "the solve stopped at its time budget of {} s after {shots} shots with convergence ratio {cr:.4}, short of its target {target}: the solution is the best so far{cut_short}",
                self.time_budget.map_or(0.0, |b| b.as_secs_f64())
            ),
            StopReason::Interrupted => format!(
                "the solve was interrupted after {shots} shots with convergence ratio {cr:.4}, short of its target {target}: the solution is partial (the best so far)"
            ),
        };
        self.state.stats.warnings.push(warning);
    }

    /// Final push-pull of everything, statistics, and the solution.
    fn finish(mut self, seconds: f64) -> Solution<N> {
        let deadline = self.deadline();
        let (setup, state) = (&self.setup, &mut self.state);
        let forest = setup.forest();
        for (face, _) in setup.faces.iter() {
            let root = forest.root(face.surface());
            let side = face.side();
            state.field.push_pull(
                forest,
                root,
                side,
                &setup.exposed_area[side],
                setup.textures.as_ref(),
            );
        }
        // Pushing makes pending energy part of δL again; the residual keys
        // already count it.
        for h in state.hierarchies.iter_mut().flatten() {
            h.push_pull();
            for n in &h.nodes {
                state.used[n.from.index()] = true;
                state.used[n.to.index()] = true;
            }
        }
        let gather_start = Instant::now();
        let (links, report) = gather_links(setup, &state.field, &state.cache, deadline);
        state.stats.gather_seconds = gather_start.elapsed().as_secs_f64();
        state.stats.gather_senders = report.senders;
        state.stats.gather_coarse_senders = report.coarse_senders;
        state.stats.gather_bounded_pairs = report.bounded_pairs;
        state.stats.root_throughputs = state
            .hierarchies
            .iter()
            .flatten()
            .filter(|h| !h.pending)
            .count();
        let gather_bytes = links.bytes() as u64;
        let bytes = self.arena_bytes() + gather_bytes;
        self.state.stats.peak_memory_bytes = self.state.stats.peak_memory_bytes.max(bytes);
        let residual = self.residual();
        let convergence_ratio = self.convergence_ratio();
        let paper_convergence_ratio = self.paper_convergence_ratio();
        let ambient = self.ambient(residual);
        let (setup, state) = (&self.setup, &mut self.state);
        let stats = &mut state.stats;
        stats.convergence_ratio = convergence_ratio;
        stats.paper_convergence_ratio = paper_convergence_ratio;
        stats.ambient = ambient;
        stats.gather_links = links.len();
        stats.far_blocks = setup.clusters.cuts.values().map(|c| c.far.len()).sum();
        stats.far_fields = state.far.values().flatten().count();
        stats.elements = state.used.iter().filter(|&&u| u).count();
        stats.interactions = state
            .hierarchies
            .iter()
            .flatten()
            .map(|h| h.nodes.len())
            .sum();
        stats.emitted_flux = state.ledger.emitted.clone();
        stats.absorbed_flux = state.ledger.absorbed.clone();
        stats.escaped_flux = state.ledger.escaped.clone();
        stats.residual_flux = residual.to_array().to_vec();
        stats.solve_seconds = seconds;
        stats.min_shot_escaped = state.ledger.min_shot_escaped;
        stats.min_element_absorbed = state.ledger.min_element_absorbed;
        self.into_solution(links)
    }

    /// The unshot remainder's estimate for `residual` (`ambient`): the
    /// reflecting area from the faces that reflected light, else Σ ρ_d A
    /// over every face.
    fn ambient(&self, residual: Spectrum<N>) -> crate::stats::Ambient {
        let forest = self.setup.forest();
        let exposed =
            |f: FaceId| self.setup.exposed_area[f.side()][forest.root(f.surface()).index()];
        let fallback: Spectrum<N> = self
            .setup
            .faces
            .iter()
            .map(|(f, face)| face.rho_d * exposed(f))
            .sum();
        let area = self
            .state
            .interreflection
            .reflecting_area(exposed, fallback);
        self.state
            .interreflection
            .ambient(residual, self.unshot_emission(), area)
    }

    /// The solution of the finished solve: its discretisation, radiance,
    /// hierarchies, far fields and gather links.
    fn into_solution(self, links: GatherLinks) -> Solution<N> {
        let local_ambient = Some(crate::local_ambient::future_irradiance(
            &self.setup,
            &self.state,
            &links,
        ));
        let Solver { setup, state, .. } = self;
        let hierarchies: Vec<Hierarchy<N>> = state.hierarchies.into_iter().flatten().collect();
        let far = state
            .far
            .values()
            .flatten()
            .map(|f| FarRecord {
                face: f.face,
                blocks: f.blocks.iter().map(|b| (b.cluster, b.radiance)).collect(),
            })
            .collect();
        let mut stats = state.stats;
        // The ledger's per-element and per-shot minima are diagnostics worth
        // keeping beside the stats.
        if state.ledger.min_shot_escaped < -1e-9 {
            stats.warnings.push(format!(
                "a shot created energy: escaped flux {} of its source",
                state.ledger.min_shot_escaped
            ));
        }
        Solution::assemble(Parts {
            scene: setup.scene,
            discretisation: setup.discretisation,
            settings: setup.settings,
            exposed_area: setup.exposed_area,
            radiance: state.field.radiance,
            hierarchies,
            far,
            links,
            stats,
            local_ambient,
        })
    }

    /// The element trees (pre-subdivided to the depth limits).
    pub fn forest(&self) -> &ElementForest {
        self.setup.forest()
    }
}
