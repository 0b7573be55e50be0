//! The progressive shooting loop (paper §4, Fig. 7 and 9).
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
//! A source is either the two-point tree of a Lambertian face (emission
//! enters here) or a stored interaction hierarchy of a glossy face. This
//! module prepares a solve ([`Solver::new`]) and runs the loop; one shot's
//! phases are in `shot`, the glossy renormalisation in `glossy`.

use std::collections::{HashMap, HashSet};
use std::f64::consts::PI;
use std::sync::{Arc, Mutex};
use std::time::Instant;

use glam::{DVec2, DVec3};
use rayon::prelude::*;
use trilux_brdf::{AlbedoTable, Bsdf};
use trilux_color::Spectrum;
use trilux_geometry::{
    BurialMap, BurialRequest, ElementForest, ElementId, FaceElement, FaceId, Geometry, PerFace,
    Side, Sided, Visibility,
};

use crate::cluster::ClusterTree;
use crate::cluster_transport::{Clusters, Cut, FarContext, FarField, FarFields, cut_of};
use crate::error::SolverError;
use crate::faces::{TransportFace, build_faces, eligible_pairs};
use crate::interaction::Hierarchy;
use crate::ledger::Ledger;
use crate::prepared::PreparedScene;
use crate::radiosity::ElementRadiance;
use crate::settings::SolverSettings;
use crate::solution::Solution;
use crate::stats::SolveStats;
use crate::textures::ElementTextures;
use crate::throughput::{ThroughputCache, compute_throughput};

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
pub(crate) enum Source {
    /// The two-point tree of a face.
    Radiosity(FaceId),
    /// A stored interaction hierarchy.
    Stored(u32),
    /// A glossy face's far field (`cluster_transport`).
    Far(FaceId),
}

/// A prepared solve: the scene, its element trees, faces, root
/// interactions and the energy state of the shooting loop.
pub struct Solver<const N: usize> {
    pub(crate) scene: Arc<PreparedScene<N>>,
    pub(crate) forest: ElementForest,
    /// The buried parts of every face that sends light (`None` when no
    /// face has any).
    pub(crate) burial: Option<BurialMap>,
    pub(crate) settings: SolverSettings,
    /// Directional albedo per material (for the glossy renormalisation).
    pub(crate) albedo: Vec<AlbedoTable<N>>,
    /// Σ_K T(j, K) / A_j per (face, element): how much of j's hemisphere
    /// the face's stored receivers cover (`glossy`).
    pub(crate) coverage: Mutex<HashMap<(FaceId, ElementId), f64>>,
    pub(crate) faces: PerFace<TransportFace<N>>,
    /// Near partners of every face: refined from their roots by the
    /// paper's algorithm (every partner when clustering is off).
    pub(crate) partners: PerFace<Vec<FaceId>>,
    /// The cluster hierarchy and every face's cut (`cluster_transport`).
    pub(crate) clusters: Clusters,
    /// The far fields of glossy faces (`None` while one sends).
    pub(crate) far: FarFields<N>,
    /// Shading-normal moments of chart elements of smooth-shaded meshes
    /// (`ElementForest::shading_moments`).
    pub(crate) shading: Vec<Option<(DVec3, DVec3)>>,
    /// (sender face, receiver face) of every stored interaction.
    pub(crate) stored_pairs: HashSet<(FaceId, FaceId)>,
    pub(crate) field: ElementRadiance<N>,
    /// Unshot flux of every face's two-point tree (the selection key).
    pub(crate) face_flux: PerFace<Spectrum<N>>,
    /// The stored hierarchies; `None` only for the one sending in a shot.
    pub(crate) hierarchies: Vec<Option<Hierarchy<N>>>,
    pub(crate) cache: ThroughputCache,
    pub(crate) ledger: Ledger,
    pub(crate) emitted: Spectrum<N>,
    pub(crate) depth_of: Vec<u32>,
    /// Exposed area of every element's faces, per side.
    pub(crate) exposed_area: Sided<Vec<f64>>,
    pub(crate) stats: SolveStats,
    pub(crate) used: Vec<bool>,
    /// `element_points` of every element (refinement reads them often).
    pub(crate) points: Vec<[DVec3; 5]>,
    /// The centres of every element's 2×2 quadrants.
    pub(crate) interior: Vec<[DVec3; 4]>,
    /// ρ_d and g of the elements of textured faces (`None` without
    /// textures).
    pub(crate) textures: Option<ElementTextures<N>>,
}

/// Exposed area A × (exposed share) of every element's two faces: leaves
/// from the burial map, parents the sum of their children (so that flux
/// pulls stay exact).
pub(crate) fn exposed_areas(forest: &ElementForest, burial: Option<&BurialMap>) -> Sided<Vec<f64>> {
    let mut out = Sided::from_fn(|_| vec![0.0; forest.element_count()]);
    for side in Side::BOTH {
        for s in 0..forest.geometry().surfaces().len() as u32 {
            let root = forest.root(trilux_geometry::SurfaceId(s));
            exposed_rec(forest, burial, FaceElement::new(root, side), &mut out[side]);
        }
    }
    out
}

fn exposed_rec(
    forest: &ElementForest,
    burial: Option<&BurialMap>,
    e: FaceElement,
    out: &mut [f64],
) -> f64 {
    let a = match forest.element(e.element).children() {
        None => {
            let share = burial.map_or(1.0, |m| m.exposed_fraction(forest, e));
            forest.element(e.element).area * share
        }
        Some(children) => children
            .into_iter()
            .map(|c| exposed_rec(forest, burial, e.with(c), out))
            .sum(),
    };
    out[e.element.index()] = a;
    a
}

/// Per-surface depth limits from the global limit and MinArea.
pub(crate) fn depth_limits(geometry: &Geometry, settings: &SolverSettings) -> Vec<u32> {
    let diag = geometry.bounds().diagonal().length();
    let min_area = settings.min_area_fraction * diag * diag;
    geometry
        .surfaces()
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

/// The element trees of `geometry`, subdivided uniformly to each surface's
/// depth limit, so that they are immutable (and shareable across threads)
/// during the solve. These are the paper's "potential elements"; their
/// count is O(n).
pub(crate) fn presubdivided(geometry: Arc<Geometry>, depths: &[u32]) -> ElementForest {
    let mut forest = ElementForest::new(geometry);
    for (s, &depth) in depths.iter().enumerate() {
        forest.subdivide_to_depth(trilux_geometry::SurfaceId(s as u32), depth);
    }
    forest
}

/// Lambertian reflectances above 1 would create energy: clamped, with a
/// warning per shape.
fn clamp_reflectances<const N: usize>(faces: &mut PerFace<TransportFace<N>>) -> Vec<String> {
    let mut warnings = Vec::new();
    for face in faces.values_mut() {
        if face.rho_d.max_value() > 1.0 {
            warnings.push(format!(
                "shape {}: Lambertian reflectance above 1 clamped to 1 (it would create energy)",
                face.shape
            ));
            face.rho_d = face.rho_d.min(Spectrum::splat(1.0));
        }
    }
    warnings.dedup();
    warnings
}

/// The buried parts of every face that sends light (the floor under a
/// box) and the parts that a crossing cuts off from the light:
/// visibility treats them as blocked, and radiance is spread over the
/// exposed area only (`trilux_geometry::burial`, `crossing`). Returns the
/// map, and the map of burial alone.
fn probe_burial<const N: usize>(
    forest: &ElementForest,
    faces: &PerFace<TransportFace<N>>,
    depth_of: &[u32],
) -> (Option<BurialMap>, Option<BurialMap>) {
    let requests: Vec<BurialRequest> = faces
        .iter()
        .filter(|(_, f)| !f.is_absorber())
        .map(|(face, _)| BurialRequest {
            face,
            resolution: 2u32.pow(depth_of[face.surface().index()] + 1).min(256),
        })
        .collect();
    let light = trilux_geometry::LightFaces {
        emitters: faces
            .iter()
            .filter(|(_, f)| !f.emission.is_black())
            .map(|(face, _)| face)
            .collect(),
        senders: PerFace::from(faces.values().map(|f| !f.is_absorber()).collect::<Vec<_>>()),
    };
    let plain = BurialMap::probe(forest.geometry(), &requests);
    let crossed = trilux_geometry::crossing::crossed_faces(forest.geometry());
    let map = if crossed.contains(&true) {
        BurialMap::probe_with_light(forest.geometry(), &requests, Some(&light))
    } else {
        plain.clone()
    };
    let nonempty = |m: BurialMap| (!m.is_empty()).then_some(m);
    (nonempty(map), nonempty(plain))
}

/// The face elements that a crossing cuts off in part (less exposed with
/// the crossing probe than with burial alone, but not wholly cut off).
fn partly_cut(
    exposed: &Sided<Vec<f64>>,
    forest: &ElementForest,
    plain: Option<&BurialMap>,
) -> Sided<Vec<bool>> {
    let without = exposed_areas(forest, plain);
    Sided::from_fn(|side| {
        exposed[side]
            .iter()
            .zip(&without[side])
            .map(|(&a, &b)| a > 0.0 && a < 0.999 * b)
            .collect()
    })
}

/// The cluster hierarchy, every face's cut and its near partners (the
/// eligible pairs among the cut's near candidates). Clustering needs
/// two-point transport (the uniform mode stays the paper's).
fn clusters_and_partners<const N: usize>(
    forest: &ElementForest,
    faces: &PerFace<TransportFace<N>>,
    settings: &SolverSettings,
) -> (Clusters, PerFace<Vec<FaceId>>) {
    let clustering =
        settings.clustering && settings.transport == crate::settings::Transport::TwoPoint;
    let tree = ClusterTree::build(forest.geometry());
    let ids: Vec<FaceId> = faces.iter().map(|(f, _)| f).collect();
    let mut cuts: Vec<Cut> = ids
        .par_iter()
        .map(|&f| {
            if faces[f].is_absorber() {
                return Cut::default();
            }
            let s = forest.geometry().surface(f.surface());
            let root = forest.element(forest.root(f.surface()));
            let planar = s
                .is_planar()
                .then(|| (root.centre, root.normal * f.side().sign()));
            cut_of(
                forest,
                &tree,
                f,
                planar,
                clustering,
                !faces[f].emission.is_black(),
            )
        })
        .collect();
    let candidates = PerFace::from(
        cuts.iter_mut()
            .map(|c| std::mem::take(&mut c.near))
            .collect::<Vec<_>>(),
    );
    let partners = eligible_pairs(forest, faces, &candidates);
    let cuts = PerFace::from(cuts);
    let enclosed = PerFace::from(
        ids.par_iter()
            .map(|&f| clustering && crate::cluster_transport::is_enclosed(forest, f))
            .collect::<Vec<_>>(),
    );
    (
        Clusters {
            tree,
            cuts,
            enclosed,
            partly_cut: Sided::from_fn(|_| Vec::new()),
        },
        partners,
    )
}

/// The far field of every glossy face that has far blocks.
fn far_fields<const N: usize>(
    forest: &ElementForest,
    faces: &PerFace<TransportFace<N>>,
    clusters: &Clusters,
    exposed_area: &Sided<Vec<f64>>,
    burial: Option<&BurialMap>,
) -> FarFields<N> {
    let ctx = FarContext {
        forest,
        tree: &clusters.tree,
        exposed_area,
        burial,
        enclosed: &clusters.enclosed,
    };
    let ids: Vec<FaceId> = faces.iter().map(|(f, _)| f).collect();
    let fields: Vec<Option<FarField<N>>> = ids
        .par_iter()
        .map(|&f| {
            let cut = &clusters.cuts[f];
            (faces[f].stored && !cut.far.is_empty()).then(|| FarField::new(&ctx, f, cut))
        })
        .collect();
    PerFace::from(fields)
}

/// Root interactions: every eligible pair whose sender needs stored
/// interactions (a glossy part, or any reflection in uniform mode) and
/// whose receiver reflects. Emission is Lambertian (Mitsuba's area
/// emitter) and always enters as a two-point source, whose flux π A Le is
/// exact.
fn root_interactions<const N: usize>(
    vis: &Visibility<'_>,
    faces: &PerFace<TransportFace<N>>,
    partners: &PerFace<Vec<FaceId>>,
    samples: impl Fn([FaceElement; 2]) -> u32 + Sync,
) -> Vec<Hierarchy<N>> {
    let forest = vis.forest();
    let mut roots = Vec::new();
    for (a, list) in partners.iter() {
        if faces[a].stored {
            roots.extend(
                list.iter()
                    .filter(|&&b| !faces[b].is_absorber())
                    .map(|&b| (a, b)),
            );
        }
    }
    let root_of = |f: FaceId| f.of(forest.root(f.surface()));
    roots
        .par_iter()
        .map(|&(a, b)| {
            let pair = [root_of(b), root_of(a)];
            let t = compute_throughput(vis, pair[0], pair[1], samples(pair), false);
            Hierarchy::new(a, b, root_of(a).element, root_of(b).element, t)
        })
        .collect()
}

impl<const N: usize> Solver<N> {
    /// Prepares a solve of `scene`: element trees, faces, buried parts,
    /// root interactions and the emitters' unshot light.
    pub fn new(
        scene: Arc<PreparedScene<N>>,
        settings: SolverSettings,
    ) -> Result<Self, SolverError> {
        settings.validate().map_err(SolverError::Settings)?;
        let depth_of = depth_limits(scene.geometry(), &settings);
        let forest = presubdivided(Arc::clone(scene.geometry()), &depth_of);
        if let Some(t) =
            crate::divergence::trapped_light(&forest, scene.materials(), scene.emission())
        {
            return Err(SolverError::NoFiniteSolution {
                shape: t.shape,
                band: t.band,
                bands: N,
            });
        }
        let albedo = scene
            .materials()
            .par_iter()
            .map(Bsdf::albedo_table)
            .collect();
        let mut faces = build_faces(
            &forest,
            scene.materials(),
            scene.emission(),
            settings.transport,
        );
        let warnings = clamp_reflectances(&mut faces);
        let (burial, plain) = probe_burial(&forest, &faces, &depth_of);
        let exposed_area = exposed_areas(&forest, burial.as_ref());
        let textures = ElementTextures::new(&forest, &scene, &exposed_area);
        if textures.is_some() && settings.transport != crate::settings::Transport::TwoPoint {
            return Err(SolverError::Settings(
                "textured materials need two-point transport (the uniform transport is for ablation only)".into(),
            ));
        }
        let (mut clusters, partners) = clusters_and_partners(&forest, &faces, &settings);
        clusters.partly_cut = partly_cut(&exposed_area, &forest, plain.as_ref());
        let far = far_fields(&forest, &faces, &clusters, &exposed_area, burial.as_ref());
        let vis = Visibility::new(&forest, burial.as_ref());
        let samples = |pair| {
            crate::refine::visibility_samples_for(
                &clusters.partly_cut,
                pair,
                settings.visibility_samples,
            )
        };
        let hierarchies = root_interactions(&vis, &faces, &partners, samples);
        let (field, face_flux, emitted) = emission(&forest, &faces, &exposed_area);
        let stats = initial_stats::<N>(&forest, &depth_of, hierarchies.len(), warnings);
        let count = forest.element_count() as u32;
        let points = (0..count)
            .map(|e| forest.element_points(ElementId(e)))
            .collect();
        let interior = (0..count)
            .map(|e| {
                [(0.25, 0.25), (0.75, 0.25), (0.25, 0.75), (0.75, 0.75)]
                    .map(|(u, v)| forest.sample_element(ElementId(e), DVec2::new(u, v)).point)
            })
            .collect();
        let shading = (0..count)
            .map(|e| forest.shading_moments(ElementId(e)))
            .collect();
        Ok(Solver {
            stored_pairs: hierarchies.iter().map(|h| (h.from, h.to)).collect(),
            hierarchies: hierarchies.into_iter().map(Some).collect(),
            used: vec![false; count as usize],
            ledger: Ledger::new(emitted.to_array().to_vec()),
            cache: ThroughputCache::new(1 << 22),
            coverage: Mutex::new(HashMap::new()),
            scene,
            forest,
            burial,
            settings,
            albedo,
            faces,
            partners,
            clusters,
            far,
            shading,
            field,
            face_flux,
            emitted,
            depth_of,
            exposed_area,
            stats,
            points,
            interior,
            textures,
        })
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
        let mut r: Spectrum<N> = self.face_flux.values().copied().sum();
        r += self
            .hierarchies
            .iter()
            .flatten()
            .map(|h| h.unshot_flux)
            .sum::<Spectrum<N>>();
        r += self
            .far
            .values()
            .flatten()
            .map(|f| f.unshot_flux)
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

    /// The source with the greatest unshot flux (band sum), if any has some.
    fn next_source(&self) -> Option<Source> {
        let mut best: Option<(Source, f64)> = None;
        let mut consider = |s: Source, flux: f64| {
            if flux > 0.0 && best.is_none_or(|(_, f)| flux > f) {
                best = Some((s, flux));
            }
        };
        for (face, f) in self.face_flux.iter() {
            consider(Source::Radiosity(face), f.sum());
        }
        for (h, hier) in self.hierarchies.iter().enumerate() {
            if let Some(hier) = hier {
                consider(Source::Stored(h as u32), hier.unshot_flux.sum());
            }
        }
        for (face, f) in self.far.iter() {
            if let Some(f) = f {
                consider(Source::Far(face), f.unshot_flux.sum());
            }
        }
        best.map(|(s, _)| s)
    }

    /// Summed bytes of the solver's arenas now (stats'
    /// `peak_memory_bytes`): the element trees, per-element radiance,
    /// exposed areas and sample points, the stored interaction nodes, the
    /// throughput cache, the cluster hierarchy, plus `links` live links.
    pub(crate) fn arena_bytes(&self, links: usize) -> u64 {
        use std::mem::size_of;
        let elements = self.forest.element_count();
        let per_element = size_of::<trilux_geometry::Element>()
            + 9 * size_of::<Spectrum<N>>() // three fields × two sides, + spares
            + 2 * size_of::<f64>()
            + size_of::<[DVec3; 5]>()
            + size_of::<[DVec3; 4]>()
            + size_of::<Option<(DVec3, DVec3)>>()
            + size_of::<bool>()
            + size_of::<u32>();
        let nodes: usize = self
            .hierarchies
            .iter()
            .flatten()
            .map(|h| h.nodes.capacity())
            .sum();
        let hierarchies = self.hierarchies.len() * size_of::<Option<Hierarchy<N>>>();
        let partners: usize = self.partners.values().map(|p| p.capacity() * 4).sum();
        let link = size_of::<crate::link::PairLink<N>>().max(size_of::<crate::link::NodeLink<N>>());
        (elements * per_element
            + nodes * size_of::<crate::interaction::Node<N>>()
            + hierarchies
            + partners
            + self.cache.bytes()
            + self.clusters.bytes()
            + links * link) as u64
    }

    /// Stored interaction nodes, over every hierarchy.
    fn interaction_count(&self) -> usize {
        self.hierarchies
            .iter()
            .flatten()
            .map(|h| h.nodes.len())
            .sum()
    }

    /// Runs shots until the target convergence ratio or the shot budget,
    /// calling `progress` after each shot, then makes every hierarchy
    /// consistent and returns the solution.
    pub fn solve(mut self, mut progress: impl FnMut(&Progress)) -> Solution<N> {
        let start = Instant::now();
        while self.convergence_ratio() < self.settings.convergence
            && self.stats.shots < u64::from(self.settings.max_shots)
        {
            let Some(source) = self.next_source() else {
                break;
            };
            let live = self.shoot(source);
            self.stats.shots += 1;
            let bytes = self.arena_bytes(live);
            self.stats.peak_memory_bytes = self.stats.peak_memory_bytes.max(bytes);
            progress(&Progress {
                shots: self.stats.shots,
                convergence_ratio: self.convergence_ratio(),
                target: self.settings.convergence,
                interactions: self.interaction_count(),
                live_links: live,
            });
        }
        let cr = self.convergence_ratio();
        if cr < self.settings.convergence {
            self.stats.warnings.push(format!(
                "the solve stopped at its cap of {} shots with convergence ratio {cr:.4}, short of its target {} (surfaces that reflect nearly all light converge slowly: lower a reflectance, or ask for less with --convergence)",
                self.stats.shots, self.settings.convergence
            ));
        }
        self.finish(start.elapsed().as_secs_f64())
    }

    /// Final push-pull of everything, statistics, and the solution.
    fn finish(mut self, seconds: f64) -> Solution<N> {
        for (face, _) in self.faces.iter() {
            let root = self.forest.root(face.surface());
            let side = face.side();
            self.field.push_pull(
                &self.forest,
                root,
                side,
                &self.exposed_area[side],
                self.textures.as_ref(),
            );
        }
        // Pushing makes pending energy part of δL again; the residual keys
        // already count it.
        for h in self.hierarchies.iter_mut().flatten() {
            h.push_pull();
            for n in &h.nodes {
                self.used[n.from.index()] = true;
                self.used[n.to.index()] = true;
            }
        }
        let links = self.gather_links();
        let gather_bytes = links.bytes() as u64;
        let bytes = self.arena_bytes(0) + gather_bytes;
        self.stats.peak_memory_bytes = self.stats.peak_memory_bytes.max(bytes);
        let residual = self.residual();
        let stats = &mut self.stats;
        stats.gather_links = links.len();
        stats.far_blocks = self.clusters.cuts.values().map(|c| c.far.len()).sum();
        stats.far_fields = self.far.values().flatten().count();
        stats.elements = self.used.iter().filter(|&&u| u).count();
        stats.interactions = self
            .hierarchies
            .iter()
            .flatten()
            .map(|h| h.nodes.len())
            .sum();
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
        Solution::from_solver(self, links)
    }

    /// The element trees (pre-subdivided to the depth limits).
    pub fn forest(&self) -> &ElementForest {
        &self.forest
    }
}

/// Emission: every element of an emitting face starts with δL = Le; the
/// face's unshot flux is IF = π A Le over its exposed area (paper §6).
fn emission<const N: usize>(
    forest: &ElementForest,
    faces: &PerFace<TransportFace<N>>,
    exposed_area: &Sided<Vec<f64>>,
) -> (ElementRadiance<N>, PerFace<Spectrum<N>>, Spectrum<N>) {
    let mut field = ElementRadiance::new(forest.element_count());
    let mut face_flux = PerFace::from_fn(forest.geometry().surfaces().len(), |_| Spectrum::zero());
    let mut emitted = Spectrum::zero();
    for (face, f) in faces.iter() {
        if f.emission.is_black() {
            continue;
        }
        let root = forest.root(face.surface());
        let flux = f.emission * (PI * exposed_area[face.side()][root.index()]);
        emitted += flux;
        let mut stack = vec![root];
        while let Some(e) = stack.pop() {
            field.unshot[face.side()][e.index()] = f.emission;
            if let Some(c) = forest.element(e).children() {
                stack.extend(c);
            }
        }
        face_flux[face] = flux;
    }
    (field, face_flux, emitted)
}

/// The statistics known before the first shot.
fn initial_stats<const N: usize>(
    forest: &ElementForest,
    depth_of: &[u32],
    root_interactions: usize,
    warnings: Vec<String>,
) -> SolveStats {
    let potential: u64 = depth_of.iter().map(|&d| 4u64.pow(d)).sum();
    SolveStats {
        input_surfaces: forest.geometry().surfaces().len(),
        potential_elements: potential,
        potential_interactions: potential.saturating_mul(potential),
        root_interactions,
        bands: N,
        wavelengths_nm: (N != 3).then(trilux_color::Bands::<N>::edges),
        warnings,
        ..SolveStats::default()
    }
}
