//! The progressive shooting loop (paper §4, Fig. 7 and 9; notes §4).
//!
//! ```text
//! until CR ≥ target or the shot budget is spent:
//!     S ← the source with the greatest unshot flux δΦ
//!     push-pull S (lazily, only now: §4.4)
//!     refine and link S to every receiver (two stages, see refine.rs)
//!     shoot: every link adds δL·R to its receiver's L^G
//!     unlink (links live for one shot: memory O(n + k²), §4.2)
//!     zero δL over S
//! ```
//!
//! A source is either the two-point tree of a Lambertian side (emission
//! enters here) or a stored interaction hierarchy of a glossy side.

use std::collections::HashMap;
use std::f64::consts::PI;
use std::time::Instant;

use rayon::prelude::*;
use trilux_brdf::{AlbedoTable, Bsdf, BsdfParams, Frame};
use trilux_color::{ColorParam, Spectrum};
use trilux_geometry::{BurialRequest, ElementId, SceneGeometry, Shape, Side};

use crate::error::SolverError;
use crate::interaction::Hierarchy;
use crate::ledger::Ledger;
use crate::radiosity::ElementRadiance;
use crate::refine::{NodeLink, PairLink, PairShot, RefineContext, Sender, TripleTask};
use crate::settings::SolverSettings;
use crate::sides::{SideId, TransportSide, build_sides, eligible_pairs};
use crate::solution::Solution;
use crate::stats::SolveStats;
use crate::throughput::{SidedElement, ThroughputCache, compute_throughput};

/// What the solver needs of a scene: per shape its geometry, its material
/// and its area emitter's radiance. (The scene layer builds this; the solver
/// never parses files.)
#[derive(Clone, Debug)]
pub struct SolverInput<'a> {
    /// The shapes.
    pub shapes: &'a [Shape],
    /// One material per shape.
    pub bsdfs: &'a [BsdfParams],
    /// One optional area-emitter radiance per shape.
    pub emission: &'a [Option<ColorParam>],
}

/// Progress after each shot, for progress bars (the solver never prints).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Progress {
    /// Shots so far.
    pub shots: u64,
    /// Convergence ratio CR = (IF − RF)/IF.
    pub convergence_ratio: f64,
    /// The target CR.
    pub target: f64,
    /// Stored interaction nodes.
    pub interactions: usize,
    /// Links alive during the last shot.
    pub live_links: usize,
}

/// A light source for shooting.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Source {
    /// The two-point tree of a side.
    Radiosity(SideId),
    /// A stored interaction hierarchy.
    Stored(u32),
}

/// A prepared solve: geometry, materials, sides, root interactions.
pub struct Solver<const N: usize> {
    pub(crate) geom: SceneGeometry,
    pub(crate) settings: SolverSettings,
    pub(crate) materials: Vec<Bsdf<N>>,
    /// Directional albedo per material (for the renormalisation).
    albedo: Vec<AlbedoTable<N>>,
    /// Σ_K T(j, K) / A_j per (side, element): how much of j's hemisphere
    /// the side's stored receivers cover.
    coverage: std::sync::Mutex<HashMap<(SideId, ElementId), f64>>,
    pub(crate) sides: Vec<TransportSide<N>>,
    partners: Vec<Vec<SideId>>,
    /// Shading-normal moments of chart elements of smooth-shaded meshes
    /// (`SceneGeometry::shading_moments`).
    shading: Vec<Option<(glam::DVec3, glam::DVec3)>>,
    /// (sender side, receiver side) of every stored interaction.
    stored_pairs: std::collections::HashSet<(SideId, SideId)>,
    pub(crate) field: ElementRadiance<N>,
    side_flux: Vec<Spectrum<N>>,
    pub(crate) hierarchies: Vec<Hierarchy<N>>,
    cache: ThroughputCache,
    pub(crate) ledger: Ledger,
    emitted: Spectrum<N>,
    pub(crate) depth_of: Vec<u32>,
    /// Exposed area of every element's faces, `[back][element]`.
    pub(crate) exposed_area: [Vec<f64>; 2],
    pub(crate) stats: SolveStats,
    used: Vec<bool>,
    /// `element_points` of every element (refinement reads them often).
    points: Vec<[glam::DVec3; 5]>,
    /// The centres of every element's 2×2 quadrants.
    interior: Vec<[glam::DVec3; 4]>,
}

/// The most a stored interaction's shot is scaled up to carry its whole
/// unshot flux (see `shoot`).
const MAX_STORED_SHOT_SCALE: f64 = 1.25;

/// The most a group's area reflectances are scaled up or down to match the
/// albedo (a guard against estimation noise).
const MAX_RENORMALISATION: f64 = 50.0;

/// BSDF samples per pair link for the covered share of an open
/// hemisphere's glossy lobe (a square number: stratified on a grid).
const LOBE_SAMPLES: u32 = 64;

/// The coverage above which j's hemisphere counts as (nearly) closed: the
/// target is then the albedo times the covered share, which assumes the
/// lobe misses the uncovered part in proportion (an error of at most 1 −
/// coverage of the target).
const CLOSED_COVERAGE: f64 = 0.9;

/// Exposed area A × (exposed share) of every element's two faces,
/// `[back][element]`: leaves from the burial map, parents the sum of their
/// children (so that flux pulls stay exact).
fn exposed_areas(geom: &SceneGeometry) -> [Vec<f64>; 2] {
    let mut out = [
        vec![0.0; geom.element_count()],
        vec![0.0; geom.element_count()],
    ];
    for (s, face) in [Side::Front, Side::Back].into_iter().enumerate() {
        for surface in geom.surfaces() {
            exposed_rec(geom, surface.root, face, &mut out[s]);
        }
    }
    out
}

fn exposed_rec(geom: &SceneGeometry, e: ElementId, face: Side, out: &mut [f64]) -> f64 {
    let a = match geom.element(e).children() {
        None => geom.element(e).area * geom.exposed_fraction(e, face),
        Some(children) => children
            .into_iter()
            .map(|c| exposed_rec(geom, c, face, out))
            .sum(),
    };
    out[e.index()] = a;
    a
}

/// Per-surface depth limits from the global limit and MinArea.
fn depth_limits(geom: &SceneGeometry, settings: &SolverSettings) -> Vec<u32> {
    let diag = geom.bounds().diagonal().length();
    let min_area = settings.min_area_fraction * diag * diag;
    geom.surfaces()
        .iter()
        .map(|s| {
            let mut d = 0;
            let mut a = s.area();
            while d < settings.max_depth && a / 4.0 >= min_area {
                a /= 4.0;
                d += 1;
            }
            d
        })
        .collect()
}

/// Subdivides every surface's tree uniformly to its depth limit, so that the
/// geometry is immutable (and shareable across threads) during the solve.
/// These are the paper's "potential elements"; their count is O(n).
pub(crate) fn presubdivide(geom: &mut SceneGeometry, depths: &[u32]) {
    for (s, &depth) in depths.iter().enumerate() {
        let mut level = vec![geom.surfaces()[s].root];
        for _ in 0..depth {
            let mut next = Vec::with_capacity(level.len() * 4);
            for e in level {
                next.extend(geom.subdivide(e));
            }
            level = next;
        }
    }
}

impl<const N: usize> Solver<N> {
    /// Builds geometry, materials, sides and root interactions.
    pub fn new(input: &SolverInput<'_>, settings: SolverSettings) -> Result<Self, SolverError> {
        settings.validate().map_err(SolverError::Settings)?;
        let mut geom = SceneGeometry::build(input.shapes)?;
        let mut materials = Vec::with_capacity(input.shapes.len());
        let mut emission = Vec::with_capacity(input.shapes.len());
        for shape in 0..input.shapes.len() {
            let params = input.bsdfs.get(shape).cloned().unwrap_or_default();
            let bsdf = Bsdf::<N>::new(&params).map_err(|e| SolverError::Material {
                shape,
                message: e.to_string(),
            })?;
            materials.push(bsdf);
            let le = match input.emission.get(shape).and_then(Option::as_ref) {
                Some(c) => c.emission::<N>().map_err(|e| SolverError::Material {
                    shape,
                    message: e.to_string(),
                })?,
                None => Spectrum::zero(),
            };
            if !(le.is_finite() && le.is_non_negative()) {
                return Err(SolverError::Material {
                    shape,
                    message: "emitted radiance must be finite and non-negative".into(),
                });
            }
            emission.push(le);
        }
        let albedo = materials.par_iter().map(Bsdf::albedo_table).collect();
        let depth_of = depth_limits(&geom, &settings);
        presubdivide(&mut geom, &depth_of);
        let mut sides = build_sides(&geom, &materials, &emission, settings.transport);
        let mut warnings = Vec::new();
        for side in &mut sides {
            if side.rho_d.max_value() > 1.0 {
                warnings.push(format!(
                    "shape {}: Lambertian reflectance above 1 clamped to 1 (it would create energy)",
                    side.shape
                ));
                side.rho_d = side.rho_d.min(Spectrum::splat(1.0));
            }
        }
        warnings.dedup();
        // Buried parts of every face that sends light (the floor under a
        // box): visibility treats them as blocked, and radiance is spread
        // over the exposed area only (trilux_geometry::burial).
        let requests: Vec<BurialRequest> = sides
            .iter()
            .filter(|s| !s.is_absorber())
            .map(|s| BurialRequest {
                surface: s.surface,
                side: if s.back { Side::Back } else { Side::Front },
                resolution: 2u32.pow(depth_of[s.surface.index()] + 1).min(256),
            })
            .collect();
        let burial = geom.compute_burial(&requests);
        geom.set_burial(burial);
        let exposed_area = exposed_areas(&geom);
        let partners = eligible_pairs(&geom, &sides);
        let cache = ThroughputCache::new(1 << 22);

        // Root interactions: every eligible pair whose sender needs stored
        // interactions (a glossy part, or any reflection in uniform mode)
        // and whose receiver reflects. Emission is Lambertian (Mitsuba's area
        // emitter) and always enters as a two-point source, whose flux
        // π A Le is exact.
        let mut roots = Vec::new();
        for (a, list) in partners.iter().enumerate() {
            let sa = &sides[a];
            if !sa.stored {
                continue;
            }
            for &b in list {
                if !sides[b as usize].is_absorber() {
                    roots.push((a as SideId, b));
                }
            }
        }
        let root_elem = |s: SideId| geom.surfaces()[sides[s as usize].surface.index()].root;
        let th: Vec<_> = roots
            .par_iter()
            .map(|&(a, b)| {
                let (ea, eb) = (root_elem(a), root_elem(b));
                let sa = crate::throughput::SidedElement {
                    element: ea,
                    back: sides[a as usize].back,
                };
                let sb = crate::throughput::SidedElement {
                    element: eb,
                    back: sides[b as usize].back,
                };
                crate::throughput::compute_throughput(&geom, sb, sa, settings.visibility_samples)
            })
            .collect();
        let mut hierarchies = Vec::with_capacity(roots.len());
        let mut hierarchies_from = vec![Vec::new(); sides.len()];
        for (&(a, b), t) in roots.iter().zip(th) {
            hierarchies_from[a as usize].push(hierarchies.len() as u32);
            hierarchies.push(Hierarchy::new(a, b, root_elem(a), root_elem(b), t));
        }

        // Emission: IF = π A Le per emitting side (paper §6).
        let mut field = ElementRadiance::new(geom.element_count());
        let mut side_flux = vec![Spectrum::zero(); sides.len()];
        let mut emitted = Spectrum::zero();
        for (s, side) in sides.iter().enumerate() {
            if side.emission.is_black() {
                continue;
            }
            let surface = &geom.surfaces()[side.surface.index()];
            let flux =
                side.emission * (PI * exposed_area[usize::from(side.back)][surface.root.index()]);
            emitted += flux;
            {
                let mut stack = vec![surface.root];
                while let Some(e) = stack.pop() {
                    field.unshot[usize::from(side.back)][e.index()] = side.emission;
                    if let Some(c) = geom.element(e).children() {
                        stack.extend(c);
                    }
                }
                side_flux[s] = flux;
            }
        }
        let ledger = Ledger::new(emitted.to_array().to_vec());
        let potential: u64 = depth_of.iter().map(|&d| 4u64.pow(d)).sum();
        let stats = SolveStats {
            input_surfaces: geom.surfaces().len(),
            potential_elements: potential,
            potential_interactions: potential.saturating_mul(potential),
            root_interactions: hierarchies.len(),
            bands: N,
            wavelengths_nm: (N != 3).then(trilux_color::Bands::<N>::edges),
            warnings,
            ..SolveStats::default()
        };
        let used = vec![false; geom.element_count()];
        let points = (0..geom.element_count() as u32)
            .map(|e| geom.element_points(ElementId(e)))
            .collect();
        let interior = (0..geom.element_count() as u32)
            .map(|e| {
                [(0.25, 0.25), (0.75, 0.25), (0.25, 0.75), (0.75, 0.75)].map(|(u, v)| {
                    geom.sample_element(ElementId(e), glam::DVec2::new(u, v))
                        .point
                })
            })
            .collect();
        let stored_pairs = hierarchies.iter().map(|h| (h.from, h.to)).collect();
        let shading = (0..geom.element_count() as u32)
            .map(|e| geom.shading_moments(ElementId(e)))
            .collect();
        Ok(Solver {
            shading,
            stored_pairs,
            geom,
            settings,
            materials,
            albedo,
            coverage: std::sync::Mutex::new(HashMap::new()),
            sides,
            partners,
            field,
            side_flux,
            hierarchies,
            cache,
            ledger,
            emitted,
            depth_of,
            exposed_area,
            stats,
            used,
            points,
            interior,
        })
    }

    /// Total unshot (residual) flux per band.
    pub fn residual(&self) -> Spectrum<N> {
        let mut r: Spectrum<N> = self.side_flux.iter().copied().sum();
        r += self
            .hierarchies
            .iter()
            .map(|h| h.unshot_flux)
            .sum::<Spectrum<N>>();
        r
    }

    /// CR = (IF − RF)/IF (paper §6); 1 for a scene that emits nothing.
    pub fn convergence_ratio(&self) -> f64 {
        let emitted = self.emitted.sum();
        if emitted <= 0.0 {
            return 1.0;
        }
        ((emitted - self.residual().sum()) / emitted).clamp(0.0, 1.0)
    }

    fn next_source(&self) -> Option<(Source, f64)> {
        let mut best: Option<(Source, f64)> = None;
        let mut consider = |s: Source, flux: f64| {
            if flux > 0.0 && best.is_none_or(|(_, f)| flux > f) {
                best = Some((s, flux));
            }
        };
        for (s, f) in self.side_flux.iter().enumerate() {
            consider(Source::Radiosity(s as SideId), f.sum());
        }
        for (h, hier) in self.hierarchies.iter().enumerate() {
            consider(Source::Stored(h as u32), hier.unshot_flux.sum());
        }
        best
    }

    /// Runs shots until the target convergence ratio or the shot budget,
    /// calling `progress` after each shot, then makes every hierarchy
    /// consistent and returns the solution.
    pub fn solve(mut self, mut progress: impl FnMut(&Progress)) -> Solution<N> {
        let start = Instant::now();
        while self.convergence_ratio() < self.settings.convergence
            && self.stats.shots < u64::from(self.settings.max_shots)
        {
            let Some((source, _)) = self.next_source() else {
                break;
            };
            let live = self.shoot(source);
            self.stats.shots += 1;
            progress(&Progress {
                shots: self.stats.shots,
                convergence_ratio: self.convergence_ratio(),
                target: self.settings.convergence,
                interactions: self.hierarchies.iter().map(|h| h.nodes.len()).sum(),
                live_links: live,
            });
        }
        self.finish(start.elapsed().as_secs_f64())
    }

    /// One shot from `source`; returns the number of links it made.
    fn shoot(&mut self, source: Source) -> usize {
        let geom = &self.geom;
        // δΦ_S leaves the residual now.
        let phi = match source {
            Source::Radiosity(s) => std::mem::take(&mut self.side_flux[s as usize]),
            Source::Stored(h) => std::mem::take(&mut self.hierarchies[h as usize].unshot_flux),
        };
        // Lazy push-pull (paper §4.4), and the sender.
        let (send_side, src_hierarchy) = match source {
            Source::Radiosity(s) => {
                let side = &self.sides[s as usize];
                let root = geom.surfaces()[side.surface.index()].root;
                self.field.push_pull(
                    geom,
                    root,
                    side.back,
                    &self.exposed_area[usize::from(side.back)],
                );
                (s, None)
            }
            Source::Stored(h) if self.hierarchies[h as usize].is_self() => {
                // A surface's interaction with itself (paper §5.2's
                // secondary interactions of a glossy concave surface)
                // receives from its own shot: it stays in place as a
                // receiver, and a copy of its unshot radiance sends.
                let hier = &mut self.hierarchies[h as usize];
                hier.push_pull();
                (hier.from, Some((h, hier.clone())))
            }
            Source::Stored(h) => {
                // An inert stand-in while it sends: no side has id
                // SideId::MAX, so nothing looks it up.
                let mut hier = std::mem::replace(
                    &mut self.hierarchies[h as usize],
                    Hierarchy::new(
                        SideId::MAX,
                        SideId::MAX,
                        ElementId(0),
                        ElementId(0),
                        Default::default(),
                    ),
                );
                hier.push_pull();
                (hier.from, Some((h, hier)))
            }
        };
        let emitted_sum = self.emitted.sum();
        let ctx = RefineContext {
            geom,
            settings: &self.settings,
            sides: &self.sides,
            materials: &self.materials,
            cache: &self.cache,
            flux_threshold: self.settings.flux_eps * emitted_sum,
            points: &self.points,
            interior: &self.interior,
            exposed_area: &self.exposed_area,
        };
        let sender = match &src_hierarchy {
            None => Sender::Radiosity {
                field: &self.field,
                back: self.sides[send_side as usize].back,
            },
            Some((_, hier)) => Sender::Stored(hier),
        };
        let root_of = |s: SideId| geom.surfaces()[self.sides[s as usize].surface.index()].root;

        // Stage 1: pair links to every receiving side, in parallel: from the
        // roots of the two surfaces for a Lambertian source, from the root
        // pair of a stored hierarchy (whose nodes give the unshot radiance
        // of every sub-pair: Sender::unshot).
        let pairs: Vec<(ElementId, SideId, ElementId)> = match &src_hierarchy {
            None => self.partners[send_side as usize]
                .iter()
                .map(|&r| (root_of(send_side), r, root_of(r)))
                .collect(),
            Some((_, hier)) => vec![(hier.nodes[0].from, hier.to, hier.nodes[0].to)],
        };
        let pair_links: Vec<PairLink<N>> = pairs
            .par_iter()
            .flat_map_iter(|&(i, r, j)| {
                let mut out = Vec::new();
                let shot = PairShot {
                    sender: &sender,
                    si: send_side,
                    sj: r,
                };
                ctx.refine_pair(shot, i, j, self.settings.ff_eps, &mut out);
                out
            })
            .collect();

        // Shot-level renormalisation: the links may not carry more flux than
        // the source had (form-factor error could otherwise create energy).
        // A stored interaction I→K sends all its unshot flux to K (its key
        // was summed as π T_IK δL), so its links are also scaled *up* to
        // carry it when their own throughput estimates, made at other
        // levels, fall short (up to MAX_STORED_SHOT_SCALE); without this
        // the shortfall left as "escaped" light, 0.3 % of every bounce in
        // the uniform Cornell box. A Lambertian source's shortfall is
        // light that really leaves (an open scene).
        let mut arrived = Spectrum::<N>::zero();
        for l in &pair_links {
            arrived += l.unshot * (PI * l.t);
        }
        let stored_source = matches!(source, Source::Stored(_));
        let shot_scale = Spectrum::<N>::new(std::array::from_fn(|b| {
            if arrived[b] > phi[b] && arrived[b] > 0.0 {
                phi[b] / arrived[b]
            } else if stored_source && arrived[b] > 0.0 {
                (phi[b] / arrived[b]).min(MAX_STORED_SHOT_SCALE)
            } else {
                1.0
            }
        }));

        // Stage 2: three-point links into the stored hierarchies of every
        // glossy receiving side, in parallel over those hierarchies.
        let mut groups_of_side: HashMap<SideId, Vec<u32>> = HashMap::new();
        for (g, l) in pair_links.iter().enumerate() {
            if self.sides[l.side as usize].stored {
                groups_of_side.entry(l.side).or_default().push(g as u32);
            }
        }
        // Each pair link's part of its three-point links, once for all the
        // hierarchies that leave its receiving side.
        let incidences: Vec<_> = pair_links
            .par_iter()
            .map(|l| {
                self.sides[l.side as usize]
                    .stored
                    .then(|| ctx.incidence(&sender, send_side, l.i, l.side, l.j))
                    .flatten()
            })
            .collect();
        // The source hierarchy was taken out to send (unless it is a
        // surface's interaction with itself, which stays to receive).
        let self_source = src_hierarchy
            .as_ref()
            .is_some_and(|(_, hier)| hier.is_self());
        let busy = src_hierarchy
            .as_ref()
            .filter(|_| !self_source)
            .map(|(h, _)| *h);
        let results: Vec<(Vec<NodeLink<N>>, u32, Spectrum<N>)> = self
            .hierarchies
            .par_iter_mut()
            .enumerate()
            .filter(|(h, hier)| Some(*h as u32) != busy && groups_of_side.contains_key(&hier.from))
            .map(|(h, hier)| {
                let from = hier.from;
                let mut task = TripleTask {
                    sender: &sender,
                    si: send_side,
                    h: hier,
                    h_index: h as u32,
                    group: 0,
                    lost: Spectrum::zero(),
                    out: Vec::new(),
                };
                for &g in &groups_of_side[&from] {
                    let l = &pair_links[g as usize];
                    let Some(incidence) = incidences[g as usize] else {
                        continue;
                    };
                    task.group = g;
                    for n in ctx.nodes_for(task.h, l.j, &mut task.lost) {
                        ctx.refine_triple(&mut task, l.i, l.j, n, Some(incidence));
                    }
                }
                (task.out, h as u32, task.lost)
            })
            .collect();
        let mut node_links = Vec::new();
        for (links, h, lost) in results {
            // Flux that a split could not keep leaves the residual.
            let hier = &mut self.hierarchies[h as usize];
            hier.unshot_flux = (hier.unshot_flux - lost).max(Spectrum::zero());
            for b in 0..N {
                self.ledger.escaped[b] += lost[b];
            }
            node_links.extend(links);
        }

        // Per-group renormalisation: what a receiving element reflects may
        // not exceed what arrived there (notes §7).
        let mut glossy_flux = vec![Spectrum::<N>::zero(); pair_links.len()];
        for nl in &node_links {
            let t = self.hierarchies[nl.hierarchy as usize].nodes[nl.node as usize].t;
            glossy_flux[nl.group as usize] += nl.gathered * shot_scale * (PI * t);
        }
        let mut group_scale = vec![Spectrum::<N>::splat(1.0); pair_links.len()];
        let mut total_arrived = Spectrum::<N>::zero();
        let mut absorbed = Spectrum::<N>::zero();
        for (g, l) in pair_links.iter().enumerate() {
            let side = &self.sides[l.side as usize];
            let arrived_g = l.unshot * shot_scale * (PI * l.t);
            // Light spreads over j's exposed area. (No transfer reaches an
            // element that is wholly buried, whose segments all count as
            // blocked; if one did, its light would be absorbed.)
            let aj = self.exposed_area[usize::from(side.back)][l.j.index()];
            // On smooth-shaded meshes the BSDF takes the cosine about the
            // shading normal (as Mitsuba does), which changes the
            // irradiance it reflects (never beyond what arrived).
            let rho_d = (side.rho_d * self.shading_factor(l.i, l.j)).min(Spectrum::splat(1.0));
            let diffuse_g = if aj > 0.0 {
                arrived_g * rho_d
            } else {
                Spectrum::zero()
            };
            // What an element reflects may not exceed what arrived there.
            let room = (arrived_g - diffuse_g).max(Spectrum::zero());
            let glossy_g = glossy_flux[g];
            // Where (nearly) every direction from j reaches a stored
            // receiver, the discretised area reflectances must reflect the
            // BRDF's albedo over the covered share (notes §7: renormalise
            // against the albedo); point samples of a peaked lobe over
            // coarse K's fall short of it. (Two-point mode only: the
            // uniform mode stays the paper's, for ablation.)
            // The light arrives from the part of i in front of j (the
            // same direction the group's area reflectances used).
            let to_light = incidences[g].and_then(|inc| inc.direction());
            let target = match to_light {
                Some(to_light)
                    if side.stored
                        && !glossy_g.is_black()
                        && self.settings.transport == crate::settings::Transport::TwoPoint =>
                {
                    let covered = self.hemisphere_coverage(l.side, l.j);
                    if covered >= CLOSED_COVERAGE {
                        let wi = Frame::from_normal(geom.element(l.j).normal * side.sign())
                            .to_local(to_light);
                        let glossy_albedo = self.albedo[side.shape].albedo(wi) - side.rho_d;
                        Some((arrived_g * glossy_albedo * covered.min(1.0)).max(Spectrum::zero()))
                    } else {
                        // An open hemisphere: the share of the lobe that
                        // meets a stored receiver, by sampling the BRDF (a
                        // narrow lobe need not miss the open part in
                        // proportion).
                        Some(arrived_g * self.covered_lobe(l.side, to_light, l.j))
                    }
                }
                _ => None,
            };
            let scale = Spectrum::<N>::new(std::array::from_fn(|b| {
                let mut f = 1.0;
                if let Some(t) = target
                    && glossy_g[b] > 0.0
                {
                    f = (t[b] / glossy_g[b]).clamp(1.0 / MAX_RENORMALISATION, MAX_RENORMALISATION);
                }
                if glossy_g[b] * f > room[b] && glossy_g[b] > 0.0 {
                    f = room[b] / glossy_g[b];
                }
                f
            }));
            group_scale[g] = scale;
            let absorbed_g = arrived_g - diffuse_g - glossy_g * scale;
            self.ledger.min_element_absorbed = self
                .ledger
                .min_element_absorbed
                .min(absorbed_g.min_value() / arrived_g.max_value().max(1e-300));
            total_arrived += arrived_g;
            absorbed += absorbed_g;
            // The Lambertian share: straight into j's radiance (two-point).
            if !rho_d.is_black() && aj > 0.0 {
                let dl = l.unshot * shot_scale * rho_d * (l.t / aj);
                self.field.gathered[usize::from(side.back)][l.j.index()] += dl;
                self.side_flux[l.side as usize] += dl * (PI * aj);
            }
            self.used[l.i.index()] = true;
            self.used[l.j.index()] = true;
        }
        // The group's renormalisation applies to the radiance it gathers
        // and to the flux it adds to the residual alike.
        for nl in &node_links {
            let hier = &mut self.hierarchies[nl.hierarchy as usize];
            let node = &mut hier.nodes[nl.node as usize];
            let dl = nl.gathered * shot_scale * group_scale[nl.group as usize];
            node.gathered += dl;
            let t = node.t;
            hier.unshot_flux += dl * (PI * t);
        }
        let escaped = phi - total_arrived;
        for b in 0..N {
            self.ledger.escaped[b] += escaped[b];
            self.ledger.absorbed[b] += absorbed[b];
        }
        let rel = escaped.min_value() / phi.max_value().max(1e-300);
        self.ledger.min_shot_escaped = self.ledger.min_shot_escaped.min(rel);

        // Unlink and zero δL over the source.
        let live = pair_links.len() + node_links.len();
        self.stats.links_peak = self.stats.links_peak.max(live);
        self.stats.links_total += live as u64;
        match (source, src_hierarchy) {
            (Source::Radiosity(s), _) => {
                let side = &self.sides[s as usize];
                let root = self.geom.surfaces()[side.surface.index()].root;
                self.field.clear_unshot(&self.geom, root, side.back);
            }
            (Source::Stored(h), Some(_)) if self_source => {
                self.hierarchies[h as usize].clear_unshot();
            }
            (Source::Stored(h), Some((_, mut hier))) => {
                hier.clear_unshot();
                self.hierarchies[h as usize] = hier;
            }
            (Source::Stored(_), None) => {}
        }
        live
    }

    /// ∫ fr_glossy cos dω over the directions from j's centre that meet a
    /// face j's side stores an interaction towards, for light arriving from
    /// the unit direction `to_light` (world space): [`LOBE_SAMPLES`]
    /// stratified samples of the BSDF, each traced.
    fn covered_lobe(&self, side: SideId, to_light: glam::DVec3, j: ElementId) -> Spectrum<N> {
        let geom = &self.geom;
        let ts = &self.sides[side as usize];
        let ej = geom.element(j);
        let normal = ej.normal * ts.sign();
        let frame = Frame::from_normal(normal);
        let wi = frame.to_local(to_light);
        let bsdf = &self.materials[ts.shape];
        // The BSDF's frame is the front's: flip z for a back side.
        let to_bsdf = |v: glam::DVec3| glam::DVec3::new(v.x, v.y, v.z * ts.sign());
        let origin = ej.centre + normal * (1e-7 * geom.bounds().diagonal().length());
        let mut sum = Spectrum::<N>::zero();
        let n = LOBE_SAMPLES;
        let grid = (n as f64).sqrt() as u32;
        for a in 0..grid {
            for b in 0..grid {
                let u = glam::DVec2::new(
                    (f64::from(a) + 0.5) / f64::from(grid),
                    (f64::from(b) + 0.5) / f64::from(grid),
                );
                let Some(smp) = bsdf.sample(to_bsdf(wi), u) else {
                    continue;
                };
                let wo = to_bsdf(smp.wi);
                if wo.z <= 0.0 {
                    continue;
                }
                let ray = trilux_geometry::Ray {
                    origin,
                    dir: frame.to_world(wo),
                };
                let Some(hit) = geom.intersect(&ray, f64::INFINITY) else {
                    continue;
                };
                let hit_side = 2 * hit.surface.0 + u32::from(!hit.front_facing(&ray));
                if !self.stored_pairs.contains(&(side, hit_side)) {
                    continue;
                }
                let f = bsdf.eval_glossy(to_bsdf(wi), smp.wi);
                sum += f * (wo.z / smp.pdf);
            }
        }
        sum * (1.0 / f64::from(grid * grid))
    }

    /// The irradiance about j's shading normals over the one about its
    /// geometric normals, for light from i's centre (1 where shading and
    /// geometric normals agree): (Σ A n_s · d)/(Σ A n_g · d), in [¼, 4].
    fn shading_factor(&self, i: ElementId, j: ElementId) -> f64 {
        let Some((s, g)) = self.shading[j.index()] else {
            return 1.0;
        };
        let d = self.geom.element(i).centre - self.geom.element(j).centre;
        let (ds, dg) = (s.dot(d), g.dot(d));
        if dg.abs() <= 1e-12 * g.length() * d.length() || ds * dg <= 0.0 {
            return 1.0;
        }
        (ds / dg).clamp(0.25, 4.0)
    }

    /// Σ over the side's stored hierarchies of T(j, K) / A_j: the
    /// cosine-weighted share of j's hemisphere that stored receivers cover
    /// (1 in a closed room).
    fn hemisphere_coverage(&self, side: SideId, j: ElementId) -> f64 {
        if let Ok(cache) = self.coverage.lock()
            && let Some(&c) = cache.get(&(side, j))
        {
            return c;
        }
        let a = self.exposed_area[usize::from(self.sides[side as usize].back)][j.index()];
        if a <= 0.0 {
            return 0.0;
        }
        let this = SidedElement {
            element: j,
            back: self.sides[side as usize].back,
        };
        let mut t = 0.0;
        for h in self.hierarchies.iter().filter(|h| h.from == side) {
            let k = h.nodes[0].to;
            let other = SidedElement {
                element: k,
                back: self.sides[h.to as usize].back,
            };
            t += compute_throughput(&self.geom, other, this, self.settings.visibility_samples).t;
        }
        let c = t / a;
        if let Ok(mut cache) = self.coverage.lock() {
            cache.insert((side, j), c);
        }
        c
    }

    /// Final push-pull of everything, statistics, and the solution.
    fn finish(mut self, seconds: f64) -> Solution<N> {
        for side in &self.sides {
            let root = self.geom.surfaces()[side.surface.index()].root;
            self.field.push_pull(
                &self.geom,
                root,
                side.back,
                &self.exposed_area[usize::from(side.back)],
            );
        }
        // Pushing makes pending energy part of δL again; the residual keys
        // already count it.
        for h in &mut self.hierarchies {
            h.push_pull();
            for n in &h.nodes {
                self.used[n.from.index()] = true;
                self.used[n.to.index()] = true;
            }
        }
        let residual = self.residual();
        let stats = &mut self.stats;
        stats.elements = self.used.iter().filter(|&&u| u).count();
        stats.interactions = self.hierarchies.iter().map(|h| h.nodes.len()).sum();
        let emitted_sum = self.emitted.sum();
        stats.convergence_ratio = if emitted_sum > 0.0 {
            ((emitted_sum - residual.sum()) / emitted_sum).clamp(0.0, 1.0)
        } else {
            1.0
        };
        stats.emitted_flux = self.ledger.emitted.clone();
        stats.absorbed_flux = self.ledger.absorbed.clone();
        stats.escaped_flux = self.ledger.escaped.clone();
        stats.residual_flux = residual.to_array().to_vec();
        stats.solve_seconds = seconds;
        stats.min_shot_escaped = self.ledger.min_shot_escaped;
        stats.min_element_absorbed = self.ledger.min_element_absorbed;
        Solution::from_solver(self)
    }

    /// The geometry (with its pre-subdivided element trees).
    pub fn geometry(&self) -> &SceneGeometry {
        &self.geom
    }
}
