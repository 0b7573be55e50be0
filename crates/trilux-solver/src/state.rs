//! The state of the shooting loop: what the shots change — every face's
//! two-point radiance and unshot radiance, the unshot flux that selects
//! the next source, the stored interaction hierarchies, the far fields of
//! glossy faces, the ledger and the statistics — with the caches filled
//! as the shots go (throughput, hemisphere coverage). It starts from the
//! emitters' unshot light (paper §6) and root interactions of zero
//! radiance; what is fixed before the first shot is in `setup`.

use std::collections::{BTreeMap, HashMap};
use std::sync::Mutex;

use rayon::prelude::*;
use trilux_color::Spectrum;
use trilux_geometry::{ElementForest, ElementId, FaceId, PerFace};

use crate::ambient::Interreflection;
use crate::cluster_transport::{FarField, FarFields};
use crate::deferred::Deferred;
use crate::interaction::Hierarchy;
use crate::ledger::Ledger;
use crate::queue::SourceQueue;
use crate::radiosity::ElementRadiance;
use crate::setup::{Setup, emitted_flux};
use crate::stats::SolveStats;
use crate::throughput::{Throughput, ThroughputCache};

/// What the shots change (module docs).
pub(crate) struct ShotState<const N: usize> {
    /// Two-point radiance: gathered, unshot and final, per side and
    /// element.
    pub field: ElementRadiance<N>,
    /// Unshot flux of every face's two-point tree (the selection key).
    pub face_flux: PerFace<Spectrum<N>>,
    /// The stored hierarchies, in the order of the setup's root pairs;
    /// `None` only for the one sending in a shot.
    pub hierarchies: Vec<Option<Hierarchy<N>>>,
    /// The far fields of glossy faces (`None` while one sends).
    pub far: FarFields<N>,
    /// T of every element pair refinement has met.
    pub cache: ThroughputCache,
    /// Σ_K T(j, K) / A_j per (face, element): how much of j's hemisphere
    /// the face's stored receivers cover (`glossy`).
    pub coverage: Mutex<HashMap<(FaceId, ElementId), f64>>,
    /// Where the energy went.
    pub ledger: Ledger,
    /// Emitted flux of every emitting face not yet shot (a shot's share
    /// of emission, for the interreflection estimate; summed for CR once
    /// a shot, so only those faces are kept, in face order).
    pub unshot_emission: BTreeMap<FaceId, Spectrum<N>>,
    /// What the shots tell about interreflection (`ambient`).
    pub interreflection: Interreflection<N>,
    /// Statistics so far.
    pub stats: SolveStats,
    /// Elements that a link or a stored node has used.
    pub used: Vec<bool>,
    /// Unshot flux of every light without area (`lights`).
    pub light_flux: Vec<Spectrum<N>>,
    /// Glossy light waiting at its faces (`deferred`).
    pub deferred: Deferred<N>,
    /// T of every face's root pairs with its near partners.
    pub roots: RootThroughputs,
    /// The sources' keys: the next source and the residual (`queue`).
    pub queue: SourceQueue<N>,
}

/// T of the root pair (a face's root, a near partner's root), by face and
/// in the order of its near partners (`Setup::partners`): every shot of
/// a face starts stage 1 from all of them, and reading them here instead
/// of the throughput cache saves a locked hash lookup per partner per
/// shot (a tenth of boxes-256's solve). Made the first time the face
/// shoots; `None` until then.
pub(crate) struct RootThroughputs(pub PerFace<Vec<Option<Throughput>>>);

impl RootThroughputs {
    /// Bytes held.
    pub fn bytes(&self) -> usize {
        self.0
            .values()
            .map(|v| v.capacity() * std::mem::size_of::<Option<Throughput>>())
            .sum()
    }
}

impl<const N: usize> ShotState<N> {
    /// The state before the first shot: the emitters' unshot light, the
    /// root interactions and the far fields, with nothing gathered yet.
    pub fn new(setup: &Setup<N>) -> Self {
        let forest = setup.forest();
        let far = far_fields(setup);
        let hierarchies = root_interactions(forest, &setup.root_pairs);
        let (field, face_flux) = emission(setup);
        let stats = initial_stats(setup, hierarchies.len());
        let hierarchies_len = hierarchies.len();
        let count = forest.element_count();
        let surfaces = forest.geometry().surfaces().len();
        ShotState {
            unshot_emission: face_flux
                .iter()
                .filter(|(_, f)| !f.is_black())
                .map(|(face, f)| (face, *f))
                .collect(),
            interreflection: Interreflection::new(surfaces),
            hierarchies: hierarchies.into_iter().map(Some).collect(),
            used: vec![false; count],
            ledger: Ledger::new(setup.emitted.to_array().to_vec()),
            cache: ThroughputCache::new(1 << 22),
            coverage: Mutex::new(HashMap::new()),
            far,
            field,
            face_flux,
            stats,
            queue: SourceQueue::new(setup.light_flux.len(), 2 * surfaces, hierarchies_len),
            light_flux: setup.light_flux.clone(),
            deferred: Deferred::new(surfaces),
            roots: RootThroughputs(PerFace::from_fn(surfaces, |_| Vec::new())),
        }
    }
}

/// The far field of every glossy face that has far blocks, dark and not
/// yet traced (`FarField::new`).
fn far_fields<const N: usize>(setup: &Setup<N>) -> FarFields<N> {
    let clusters = &setup.clusters;
    let faces = &setup.faces;
    let ids: Vec<FaceId> = faces.iter().map(|(f, _)| f).collect();
    let fields: Vec<Option<FarField<N>>> = ids
        .par_iter()
        .map(|&f| {
            let cut = &clusters.cuts[f];
            (faces[f].stored && !cut.far.is_empty())
                .then(|| FarField::new(setup.forest(), &clusters.tree, f, cut))
        })
        .collect();
    PerFace::from(fields)
}

/// The root interactions of the setup's root pairs (sender face, receiver
/// face): one node each, joining the two surfaces' roots, with nothing
/// gathered yet and its throughput made when light first arrives at the
/// sender (`RefineContext::make_root`): O(pairs) here, no shadow rays.
fn root_interactions<const N: usize>(
    forest: &ElementForest,
    roots: &[(FaceId, FaceId)],
) -> Vec<Hierarchy<N>> {
    roots
        .iter()
        .map(|&(a, b)| Hierarchy::pending(a, b, forest.root(a.surface()), forest.root(b.surface())))
        .collect()
}

/// Emission: every element of an emitting face starts with δL = Le; the
/// face's unshot flux is IF = π A Le over its exposed area (paper §6).
fn emission<const N: usize>(setup: &Setup<N>) -> (ElementRadiance<N>, PerFace<Spectrum<N>>) {
    let forest = setup.forest();
    let mut field = ElementRadiance::new(forest.element_count());
    let mut face_flux = PerFace::from_fn(forest.geometry().surfaces().len(), |_| Spectrum::zero());
    for (face, f) in setup.faces.iter() {
        if f.emission.is_black() {
            continue;
        }
        let root = forest.root(face.surface());
        let flux = emitted_flux(forest, face, f, &setup.exposed_area);
        let mut stack = vec![root];
        while let Some(e) = stack.pop() {
            field.unshot[face.side()][e.index()] = f.emission;
            if let Some(c) = forest.element(e).children() {
                stack.extend(c);
            }
        }
        face_flux[face] = flux;
    }
    (field, face_flux)
}

/// The statistics known before the first shot.
fn initial_stats<const N: usize>(setup: &Setup<N>, root_interactions: usize) -> SolveStats {
    let potential = setup.discretisation.potential_elements();
    SolveStats {
        input_surfaces: setup.forest().geometry().surfaces().len(),
        potential_elements: potential,
        potential_interactions: potential.saturating_mul(potential),
        root_interactions,
        bands: N,
        wavelengths_nm: (N != 3).then(trilux_color::Bands::<N>::edges),
        warnings: setup.warnings.clone(),
        ..SolveStats::default()
    }
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use glam::DVec3;
    use trilux_color::ColorParam;

    use crate::prepared::{PreparedScene, SceneDescription};
    use crate::solver::Solver;
    use crate::test_scenes as ts;

    /// Root throughputs are made only for the hierarchies whose sender
    /// face receives light: none before the first shot, and after a
    /// converged solve all but the one leaving a glossy plate G that no
    /// light reaches (G and a diffuse plate D face each other under the
    /// lit glossy floor R, which hides them from the light E).
    #[test]
    fn root_throughputs_are_made_only_where_light_arrives() {
        let shapes = [
            ts::square(DVec3::new(0.0, 0.0, 2.0), 1.0, true), // E
            ts::square(DVec3::ZERO, 2.0, false),              // R
            ts::square(DVec3::new(0.0, 0.0, -5.0), 1.0, false), // D
            ts::square(DVec3::new(0.0, 0.0, -3.0), 1.0, true), // G
        ];
        let bsdfs = [
            ts::diffuse(0.0),
            ts::glossy(0.3),
            ts::diffuse(0.5),
            ts::glossy(0.3),
        ];
        let emission = [Some(ColorParam::Float(1.0)), None, None, None];
        let desc = SceneDescription {
            shapes: &shapes,
            bsdfs: &bsdfs,
            emission: &emission,
        };
        let scene = Arc::new(PreparedScene::<3>::new(&desc).expect("prepares"));
        let solver = Solver::new(scene, ts::settings(3)).expect("sets up");
        let (g, d) = (ts::front(3), ts::front(2));
        assert!(
            solver.setup.stored_pairs.contains(&(g, d)),
            "G stores towards D"
        );
        assert!(solver.state.hierarchies.iter().flatten().all(|h| h.pending));
        let solution = solver.solve(|_| {});
        let stats = solution.stats();
        assert!(stats.root_interactions >= 2, "{stats:?}");
        assert_eq!(stats.root_throughputs, stats.root_interactions - 1);
        assert_eq!(solution.interaction_flux(g, d).map(|f| f.sum()), Some(0.0));
    }

    /// Far fields trace nothing before the first shot and are traced when
    /// light first reaches their face: the lit glossy floor R's after the
    /// light's shot, never the hidden glossy plate G's, and every field
    /// that sends light (has radiance) is traced. Small black plates far
    /// off (x = 40 … 47, above R and below G, facing them) make the far
    /// blocks of both and send nothing back.
    #[test]
    fn far_fields_are_traced_only_where_light_arrives() {
        let mut shapes = vec![
            ts::square(DVec3::new(0.0, 0.0, 2.0), 1.0, true), // E
            ts::square(DVec3::ZERO, 2.0, false),              // R
            ts::square(DVec3::new(0.0, 0.0, -5.0), 1.0, false), // D
            ts::square(DVec3::new(0.0, 0.0, -3.0), 1.0, true), // G
        ];
        let mut bsdfs = vec![
            ts::diffuse(0.0),
            ts::glossy(0.3),
            ts::diffuse(0.5),
            ts::glossy(0.3),
        ];
        let mut emission = vec![Some(ColorParam::Float(1.0)), None, None, None];
        for (k, z) in (0..16).map(|k| (k % 8, if k < 8 { 10.0 } else { -10.0 })) {
            let centre = DVec3::new(40.0 + f64::from(k), 0.0, z);
            shapes.push(ts::square(centre, 0.2, z > 0.0));
            bsdfs.push(ts::diffuse(0.0));
            emission.push(None);
        }
        let desc = SceneDescription {
            shapes: &shapes,
            bsdfs: &bsdfs,
            emission: &emission,
        };
        let mut solver = Solver::<3>::from_description(&desc, ts::settings(2)).expect("sets up");
        let (r, g) = (ts::front(1), ts::front(3));
        let traced = |s: &Solver<3>, f| s.state.far[f].as_ref().map(|field| field.traced);
        assert_eq!(traced(&solver, r), Some(false), "R has a far field");
        assert_eq!(traced(&solver, g), Some(false), "G has a far field");
        assert!(
            (solver.state.far.values().flatten())
                .all(|f| !f.traced && f.blocks.iter().all(|b| b.t == 0.0)),
            "nothing traced before the first shot"
        );
        let light = solver.next_source().expect("the light shoots");
        solver.shoot(light);
        assert_eq!(traced(&solver, r), Some(true));
        let field = solver.state.far[r].as_ref().expect("R's field");
        assert!(field.blocks.iter().any(|b| b.t > 0.0), "R sees the plates");
        while let Some(source) = solver.next_source() {
            solver.shoot(source);
        }
        assert_eq!(traced(&solver, g), Some(false), "no light reaches G");
        for f in solver.state.far.values().flatten() {
            let lit = f.blocks.iter().any(|b| !b.radiance.is_black());
            assert!(f.traced || !lit, "{:?} sends light untraced", f.face);
        }
    }
}
