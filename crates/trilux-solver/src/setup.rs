//! The setup of a solve: everything fixed before the first shot — the
//! prepared scene, the settings, the discretisation (depth limits and
//! element trees), the transport faces, the buried parts, the exposed
//! areas, the cluster hierarchy with every face's cut and near partners,
//! the stored interactions' face pairs and the emitted flux IF. Refinement
//! reads it through a [`RefineContext`]; nothing in it changes during the
//! shots (the throughput and far-visibility caches aside, which only
//! memoise values that do not depend on when they are asked).
//!
//! The per-shot state (unshot radiance, hierarchies, ledger, statistics)
//! is in `state`.

use std::collections::HashSet;
use std::f64::consts::PI;
use std::sync::Arc;

use glam::{DVec2, DVec3};
use rayon::prelude::*;
use trilux_brdf::{AlbedoTable, Bsdf};
use trilux_color::Spectrum;
use trilux_geometry::{
    BurialMap, BurialRequest, ElementForest, ElementId, FaceElement, FaceId, PerFace, Side, Sided,
    Visibility,
};

use crate::cluster::ClusterTree;
use crate::cluster_transport::{Clusters, Cut, FarPoints, cut_angle, cut_of};
use crate::discretisation::Discretisation;
use crate::error::SolverError;
use crate::faces::{TransportFace, build_faces, eligible_pairs};
use crate::prepared::PreparedScene;
use crate::refine::RefineContext;
use crate::settings::SolverSettings;
use crate::textures::ElementTextures;
use crate::throughput::ThroughputCache;

/// What a solve fixes before its first shot (module docs).
pub(crate) struct Setup<const N: usize> {
    pub scene: Arc<PreparedScene<N>>,
    /// Depth limits and the element trees subdivided to them.
    pub discretisation: Discretisation,
    /// The buried parts of every face that sends light (`None` when no
    /// face has any).
    pub burial: Option<BurialMap>,
    pub settings: SolverSettings,
    /// Directional albedo per material (for the glossy renormalisation).
    pub albedo: Vec<AlbedoTable<N>>,
    pub faces: PerFace<TransportFace<N>>,
    /// Near partners of every face: refined from their roots by the
    /// paper's algorithm (every partner when clustering is off).
    pub partners: PerFace<Vec<FaceId>>,
    /// The cluster hierarchy and every face's cut (`cluster_transport`).
    pub clusters: Clusters,
    /// Shading-normal moments of chart elements of smooth-shaded meshes
    /// (`ElementForest::shading_moments`).
    pub shading: Vec<Option<(DVec3, DVec3)>>,
    /// (sender face, receiver face) of every stored interaction, in the
    /// order of the solver's hierarchies.
    pub root_pairs: Vec<(FaceId, FaceId)>,
    /// The same pairs, for lookup.
    pub stored_pairs: HashSet<(FaceId, FaceId)>,
    /// The range of `root_pairs` (and of the hierarchies) whose sender is
    /// each face: they are contiguous, so a shot and the glossy coverage
    /// visit a face's hierarchies without scanning all of them.
    pub stored_from: PerFace<std::ops::Range<usize>>,
    /// Exposed area of every element's faces, per side.
    pub exposed_area: Sided<Vec<f64>>,
    /// `element_points` of every element (refinement reads them often).
    pub points: Vec<[DVec3; 5]>,
    /// The centres of every element's 2×2 quadrants.
    pub interior: Vec<[DVec3; 4]>,
    /// ρ_d and g of the elements of textured faces (`None` without
    /// textures).
    pub textures: Option<ElementTextures<N>>,
    /// The emitted flux IF per band (paper §6), the lights' included.
    pub emitted: Spectrum<N>,
    /// The flux of every light without area (`lights`), then of the sky
    /// (`sky`) when there is one.
    pub light_flux: Vec<Spectrum<N>>,
    /// Warnings of the preparation (clamped reflectances).
    pub warnings: Vec<String>,
}

impl<const N: usize> Setup<N> {
    /// Prepares a solve of `scene`: discretisation, faces, buried parts,
    /// clusters and partners, the stored interactions' pairs and IF.
    pub fn new(
        scene: Arc<PreparedScene<N>>,
        settings: SolverSettings,
    ) -> Result<Self, SolverError> {
        settings.validate().map_err(SolverError::Settings)?;
        let discretisation = Discretisation::new(scene.geometry(), &settings);
        let forest = discretisation.forest();
        if let Some(t) =
            crate::divergence::trapped_light(forest, scene.materials(), scene.emission())
        {
            return Err(SolverError::NoFiniteSolution {
                shape: t.shape,
                band: t.band,
                bands: N,
            });
        }
        let albedo = albedo_tables(scene.materials());
        let mut faces = build_faces(
            forest,
            scene.materials(),
            scene.emission(),
            settings.transport,
        );
        let warnings = clamp_reflectances(&mut faces);
        let (burial, plain) = probe_burial(forest, &faces, discretisation.depth_limits());
        let exposed_area = exposed_areas(forest, burial.as_ref());
        let textures = ElementTextures::new(forest, &scene, &exposed_area);
        if textures.is_some() && settings.transport != crate::settings::Transport::TwoPoint {
            return Err(SolverError::Settings(
                "textured materials need two-point transport (the uniform transport is for ablation only)".into(),
            ));
        }
        let (mut clusters, partners) = clusters_and_partners(forest, &faces, &settings);
        clusters.partly_cut = partly_cut(&exposed_area, forest, plain.as_ref());
        let far = clusters.cuts.values().any(|c| !c.far.is_empty());
        clusters.points = FarPoints::new(forest, burial.as_ref(), far);
        let root_pairs = root_pairs(&faces, &partners);
        let mut emitted = Spectrum::zero();
        for (face, f) in faces.iter() {
            if !f.emission.is_black() {
                emitted += emitted_flux(forest, face, f, &exposed_area);
            }
        }
        let radius = crate::lights::scene_radius(scene.geometry());
        let mut light_flux: Vec<Spectrum<N>> =
            scene.lights().iter().map(|l| l.flux(radius)).collect();
        light_flux.extend(scene.sky().map(|s| s.flux(radius)));
        for f in &light_flux {
            emitted += *f;
        }
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
        let stored_from = ranges_by_sender(faces.len(), &root_pairs);
        Ok(Setup {
            stored_pairs: root_pairs.iter().copied().collect(),
            stored_from,
            root_pairs,
            scene,
            discretisation,
            burial,
            settings,
            albedo,
            faces,
            partners,
            clusters,
            shading,
            exposed_area,
            points,
            interior,
            textures,
            emitted,
            light_flux,
            warnings,
        })
    }

    /// The element trees (pre-subdivided to the depth limits).
    pub fn forest(&self) -> &ElementForest {
        self.discretisation.forest()
    }

    /// Shadow-ray visibility with the scene's buried parts.
    pub fn visibility(&self) -> Visibility<'_> {
        Visibility::new(self.forest(), self.burial.as_ref())
    }

    /// The photometric threshold (paper §4.3): `flux_eps` of the emitted
    /// flux, summed over the bands.
    pub fn flux_threshold(&self) -> f64 {
        self.settings.flux_eps * self.emitted.sum()
    }

    /// Everything refinement reads: this setup and the throughput cache.
    pub fn refine_context<'a>(&'a self, cache: &'a ThroughputCache) -> RefineContext<'a, N> {
        RefineContext {
            forest: self.forest(),
            visibility: self.visibility(),
            settings: &self.settings,
            faces: &self.faces,
            materials: self.scene.materials(),
            cache,
            flux_threshold: self.flux_threshold(),
            points: &self.points,
            interior: &self.interior,
            exposed_area: &self.exposed_area,
            textures: self.textures.as_ref(),
            clusters: &self.clusters,
            albedo: &self.albedo,
            deadline: None,
            final_release: false,
            late: Default::default(),
        }
    }
}

/// The directional albedo table of every material, computed once per
/// distinct material (a scene's shapes often repeat one; a table costs
/// tens of milliseconds) and shared by its copies.
fn albedo_tables<const N: usize>(materials: &[Bsdf<N>]) -> Vec<AlbedoTable<N>> {
    let mut distinct: Vec<usize> = Vec::new();
    let slot: Vec<usize> = materials
        .iter()
        .enumerate()
        .map(
            |(i, m)| match distinct.iter().position(|&d| materials[d] == *m) {
                Some(k) => k,
                None => {
                    distinct.push(i);
                    distinct.len() - 1
                }
            },
        )
        .collect();
    let tables: Vec<AlbedoTable<N>> = distinct
        .par_iter()
        .map(|&d| materials[d].albedo_table())
        .collect();
    slot.into_iter().map(|k| tables[k].clone()).collect()
}

/// The flux IF = π A Le an emitting face sends, over its exposed area
/// (zero for a face that does not emit; paper §6).
pub(crate) fn emitted_flux<const N: usize>(
    forest: &ElementForest,
    face: FaceId,
    f: &TransportFace<N>,
    exposed_area: &Sided<Vec<f64>>,
) -> Spectrum<N> {
    if f.emission.is_black() {
        return Spectrum::zero();
    }
    let root = forest.root(face.surface());
    f.emission * (PI * exposed_area[face.side()][root.index()])
}

/// Exposed area A × (exposed share) of every element's two faces: leaves
/// from the burial map, parents the sum of their children (so that flux
/// pulls stay exact).
fn exposed_areas(forest: &ElementForest, burial: Option<&BurialMap>) -> Sided<Vec<f64>> {
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
            let emitter = !faces[f].emission.is_black();
            let angle = cut_angle(clustering, settings.cluster_angle, emitter);
            cut_of(forest, &tree, f, planar, angle)
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
            points: FarPoints::default(),
        },
        partners,
    )
}

/// The face pairs of the root interactions: every eligible pair whose
/// sender needs stored interactions (a glossy part, or any reflection in
/// uniform mode) and whose receiver reflects. Emission is Lambertian
/// (Mitsuba's area emitter) and always enters as a two-point source, whose
/// flux π A Le is exact.
fn root_pairs<const N: usize>(
    faces: &PerFace<TransportFace<N>>,
    partners: &PerFace<Vec<FaceId>>,
) -> Vec<(FaceId, FaceId)> {
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
    roots
}

/// The range of `roots` whose sender is each face (`roots` are grouped by
/// sender, as `root_pairs` makes them).
fn ranges_by_sender(faces: usize, roots: &[(FaceId, FaceId)]) -> PerFace<std::ops::Range<usize>> {
    let mut out: Vec<std::ops::Range<usize>> = vec![0..0; faces];
    let mut start = 0;
    for k in 1..=roots.len() {
        if k == roots.len() || roots[k].0 != roots[start].0 {
            let face = roots[start].0;
            debug_assert!(out[face.index()].is_empty(), "root pairs grouped by sender");
            out[face.index()] = start..k;
            start = k;
        }
    }
    PerFace::from(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use trilux_brdf::{BsdfParams, Distribution, RoughConductorParams};
    use trilux_color::ColorParam;

    fn conductor(alpha: f64) -> Bsdf<3> {
        let p = BsdfParams::RoughConductor(RoughConductorParams {
            distribution: Distribution::Ggx,
            alpha,
            eta_k: None,
            specular_reflectance: ColorParam::Float(0.8),
        });
        Bsdf::new(&p).expect("valid parameters")
    }

    /// Shared tables are each material's own table, in material order
    /// (the rougher conductor's albedo differs, so a mix-up would show).
    #[test]
    fn albedo_tables_are_each_materials_own() {
        let materials = vec![
            conductor(0.1),
            conductor(0.6),
            conductor(0.1),
            Bsdf::new(&BsdfParams::default()).expect("valid parameters"),
            conductor(0.6),
        ];
        let expected: Vec<AlbedoTable<3>> = materials.iter().map(Bsdf::albedo_table).collect();
        assert_ne!(expected[0], expected[1]);
        assert_eq!(albedo_tables(&materials), expected);
    }
}
