//! The solution: radiance leaving any point towards any other point, for
//! final gathering (paper §4.5). Its file format is in [`file`].

mod ambient;
pub(crate) use ambient::glossy_albedo;
mod file;

use std::collections::HashMap;
use std::sync::Arc;

use trilux_color::Spectrum;
use trilux_geometry::{ElementForest, FaceId, Side, Sided, SurfaceCoord, SurfaceId};

use crate::cluster::{ClusterId, ClusterTree};
use crate::discretisation::Discretisation;
use crate::gather_links::{GatherLink, GatherLinks, LinkSource, link_radiance};
use crate::interaction::Hierarchy;
use crate::prepared::PreparedScene;
use crate::settings::SolverSettings;
use crate::stats::SolveStats;

pub use file::{FORMAT_VERSION, MAX_FILE_BYTES, solve_hash};

/// A view-independent solution of the scene's light.
pub struct Solution<const N: usize> {
    scene: Arc<PreparedScene<N>>,
    /// The depth limits and element trees the solve used (the file
    /// records the limits).
    discretisation: Discretisation,
    settings: SolverSettings,
    /// Exposed area of every element's faces, per side
    /// (`trilux_geometry::burial`).
    exposed_area: Sided<Vec<f64>>,
    /// Two-point (Lambertian) reflected radiance, per side and element.
    radiance: Sided<Vec<Spectrum<N>>>,
    hierarchies: Vec<Hierarchy<N>>,
    by_faces: HashMap<(FaceId, FaceId), u32>,
    /// The far fields of glossy faces: radiance towards each far block
    /// (`cluster_transport`), in face order.
    far: Vec<FarRecord<N>>,
    /// The far radiance by (sending face, far cluster).
    far_index: HashMap<(FaceId, ClusterId), Spectrum<N>>,
    /// Faces that have a far field.
    far_faces: Vec<bool>,
    /// The cluster hierarchy the far fields refer to (rebuilt from the
    /// geometry: it is deterministic).
    tree: ClusterTree,
    /// The final gather's links into every receiving element.
    links: GatherLinks,
    /// The radiance every gather link's sender sends, in link order
    /// (with the ambient term when it is on).
    link_radiance: Vec<Spectrum<N>>,
    /// The unshot remainder's stand-in (`crate::ambient`).
    ambient: ambient::AmbientTerm<N>,
    stats: SolveStats,
}

/// One end of a radiance query: a point of an input surface and the face
/// the light leaves or arrives on.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceSite {
    /// The face (input surface and side).
    pub face: FaceId,
    /// The point, in the surface's coordinates.
    pub coord: SurfaceCoord,
}

impl SurfaceSite {
    /// The point `coord` of `surface`, on side `side`.
    pub fn new(surface: SurfaceId, side: Side, coord: SurfaceCoord) -> Self {
        SurfaceSite {
            face: FaceId::new(surface, side),
            coord,
        }
    }
}

/// The far field of one glossy face as the solution keeps it.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct FarRecord<const N: usize> {
    /// The sending face.
    pub face: FaceId,
    /// (far cluster, radiance towards it).
    pub blocks: Vec<(ClusterId, Spectrum<N>)>,
}

/// What a solution is made of, before its derived indexes.
pub(crate) struct Parts<const N: usize> {
    pub scene: Arc<PreparedScene<N>>,
    pub discretisation: Discretisation,
    pub settings: SolverSettings,
    pub exposed_area: Sided<Vec<f64>>,
    pub radiance: Sided<Vec<Spectrum<N>>>,
    pub hierarchies: Vec<Hierarchy<N>>,
    pub far: Vec<FarRecord<N>>,
    pub links: GatherLinks,
    pub stats: SolveStats,
    /// The local ambient term (`crate::local_ambient`), when the solve or
    /// the file gives it.
    pub local_ambient: Option<Sided<Vec<Spectrum<N>>>>,
}

/// The stored hierarchies' index by (sender face, receiver face).
fn index_by_faces<const N: usize>(hierarchies: &[Hierarchy<N>]) -> HashMap<(FaceId, FaceId), u32> {
    hierarchies
        .iter()
        .enumerate()
        .map(|(i, h)| ((h.from, h.to), i as u32))
        .collect()
}

impl<const N: usize> Solution<N> {
    /// A solution from its parts (a solve's or a file's), with the indexes
    /// derived from them.
    pub(crate) fn assemble(mut p: Parts<N>) -> Self {
        let forest = p.discretisation.forest();
        let far_index = p
            .far
            .iter()
            .flat_map(|r| r.blocks.iter().map(|&(c, l)| ((r.face, c), l)))
            .collect();
        let mut far_faces = vec![false; 2 * forest.geometry().surfaces().len()];
        for r in &p.far {
            if let Some(f) = far_faces.get_mut(r.face.index()) {
                *f = true;
            }
        }
        let local = p.local_ambient.take();
        let ambient = ambient::AmbientTerm::new(&p, local);
        let mut s = Solution {
            tree: ClusterTree::build(forest.geometry()),
            far: p.far,
            far_index,
            far_faces,
            by_faces: index_by_faces(&p.hierarchies),
            scene: p.scene,
            discretisation: p.discretisation,
            settings: p.settings,
            exposed_area: p.exposed_area,
            radiance: p.radiance,
            hierarchies: p.hierarchies,
            links: p.links,
            link_radiance: Vec::new(),
            ambient,
            stats: p.stats,
        };
        s.link_radiance = s.sender_radiance();
        s
    }

    /// The radiance every gather link's sender sends (`link_radiance`),
    /// with the ambient term when it is on.
    fn sender_radiance(&self) -> Vec<Spectrum<N>> {
        let forest = self.forest();
        self.links
            .iter()
            .map(|(_, l)| {
                let base = link_radiance(
                    l,
                    &self.radiance,
                    self.scene.emission(),
                    |f| forest.geometry().surface(f.surface()).shape as usize,
                    |h, n| {
                        self.hierarchies
                            .get(h as usize)
                            .and_then(|h| h.nodes.get(n as usize))
                            .map_or(Spectrum::zero(), |n| n.radiance)
                    },
                );
                base + match l.source {
                    LinkSource::Face(face) => {
                        self.ambient
                            .lambertian_element(&self.scene, forest, face, l.sender)
                    }
                    LinkSource::Node { hierarchy, .. } => self
                        .hierarchies
                        .get(hierarchy as usize)
                        .map_or(Spectrum::zero(), |h| {
                            self.ambient.glossy(&self.scene, forest, h.from)
                        }),
                }
            })
            .collect()
    }

    /// Whether the readers add the ambient term (on by default; off gives
    /// the stopped solve's light alone). Every reader follows: radiance
    /// queries, face and surface means, the gather links' senders.
    pub fn set_ambient(&mut self, on: bool) {
        if self.ambient.on != on && !self.ambient.is_empty() {
            self.ambient.on = on;
            self.link_radiance = self.sender_radiance();
        }
    }

    /// Cohen's uniform ambient radiance A_amb (stats' `ambient`); zero
    /// when off or when the solve left nothing. The readers add it (times
    /// each face's reflectance) only to a solution without the residual's
    /// later bounces (`crate::local_ambient`), which replace it.
    pub fn ambient_radiance(&self) -> Spectrum<N> {
        if self.ambient.on {
            self.ambient.radiance
        } else {
            Spectrum::zero()
        }
    }

    /// The gather links into one face element, each with the radiance its
    /// sender sends (`gather_links`).
    pub fn gather_links(
        &self,
        e: trilux_geometry::FaceElement,
    ) -> impl Iterator<Item = (&GatherLink, Spectrum<N>)> {
        let row = self.links.row(e);
        self.links
            .at(e)
            .iter()
            .zip(self.link_radiance[row].iter().copied())
    }

    /// All gather links (for statistics and the file).
    pub fn all_gather_links(&self) -> &GatherLinks {
        &self.links
    }

    /// Statistics of the solve that made this solution.
    pub fn stats(&self) -> &SolveStats {
        &self.stats
    }

    /// Mutable statistics (for the caller's timing of rendering).
    pub fn stats_mut(&mut self) -> &mut SolveStats {
        &mut self.stats
    }

    /// The scene the solution is of.
    pub fn scene(&self) -> &Arc<PreparedScene<N>> {
        &self.scene
    }

    /// The element trees the solution refers to (with the solve's
    /// subdivisions).
    pub fn forest(&self) -> &ElementForest {
        self.discretisation.forest()
    }

    /// The settings of the solve.
    pub fn settings(&self) -> &SolverSettings {
        &self.settings
    }

    /// Reflected radiance leaving `from` towards `to` (emission excluded):
    /// the Lambertian part from the leaf element containing the point, plus
    /// the stored part from the deepest node of hierarchy (from, to) whose
    /// elements contain both points (paper Fig. 11c).
    pub fn radiance(&self, from: &SurfaceSite, to: &SurfaceSite) -> Spectrum<N> {
        self.lambertian_radiance(from) + self.stored_radiance(from, to)
    }

    /// The stored (glossy, direction-dependent) part alone of
    /// [`Solution::radiance`]: the hierarchy joining the two faces, or,
    /// for a receiver in one of the sender's far blocks, the sender's far
    /// radiance towards that block (`cluster_transport`); zero where
    /// neither exists.
    pub fn stored_radiance(&self, from: &SurfaceSite, to: &SurfaceSite) -> Spectrum<N> {
        let ambient = self.ambient.glossy(&self.scene, self.forest(), from.face);
        if let Some(&h) = self.by_faces.get(&(from.face, to.face)) {
            return self.hierarchies[h as usize].radiance_at(self.forest(), from.coord, to.coord)
                + ambient;
        }
        self.far_radiance(from.face, to.face) + ambient
    }

    /// The far radiance face `from` sends towards the far block holding
    /// `to`'s surface, if any.
    fn far_radiance(&self, from: FaceId, to: FaceId) -> Spectrum<N> {
        if !self.far_faces.get(from.index()).copied().unwrap_or(false) {
            return Spectrum::zero();
        }
        self.tree
            .ancestors(to.surface())
            .find_map(|c| self.far_index.get(&(from, c)).copied())
            .unwrap_or_else(Spectrum::zero)
    }

    /// The final radiance L + Le that element `e` of a face sends (its
    /// two-point radiance with the ambient term and, on an emitter's
    /// front, its emission).
    pub fn face_radiance(&self, face: FaceId, e: trilux_geometry::ElementId) -> Spectrum<N> {
        let le = match face.side() {
            Side::Front => {
                let shape = self.forest().geometry().surface(face.surface()).shape as usize;
                self.scene.emission()[shape]
            }
            Side::Back => Spectrum::zero(),
        };
        self.radiance[face.side()][e.index()]
            + le
            + self
                .ambient
                .lambertian_element(&self.scene, self.forest(), face, e)
    }

    /// The part of element `e`'s area that is exposed on `face`'s side
    /// (buried parts, under another shape, send and receive nothing).
    pub fn exposed_area(&self, face: FaceId, e: trilux_geometry::ElementId) -> f64 {
        self.exposed_area[face.side()][e.index()]
    }

    /// Every element's texture averages (its Lambertian reflectance ρ_d
    /// and glossy ratio), as the solve took them; `None` when no material
    /// is textured.
    pub fn element_textures(&self) -> Option<crate::ElementTextures<N>> {
        crate::ElementTextures::new(self.forest(), &self.scene, &self.exposed_area)
    }

    /// The Lambertian (two-point) reflected radiance alone at a point, with
    /// ρ_d times the ambient term.
    pub fn lambertian_radiance(&self, from: &SurfaceSite) -> Spectrum<N> {
        let leaf = self.forest().locate(from.face.surface(), from.coord);
        self.radiance[from.face.side()][leaf.index()]
            + self
                .ambient
                .lambertian(&self.scene, from.face, leaf, || from.coord)
    }

    /// Area mean of the Lambertian (two-point) reflected radiance over one
    /// face of an input surface: its leaf elements' radiance weighted by
    /// their exposed areas, over the face's whole area (buried parts send
    /// nothing). For a diffuse scene solved in two-point mode this is
    /// the face's mean exitant radiance less emission, which a path tracer's
    /// irradiance meter gives independently as ρ Ē / π.
    pub fn surface_mean_radiance(&self, face: FaceId) -> Spectrum<N> {
        let mut sum = Spectrum::<N>::zero();
        let mut area = 0.0;
        let mut stack = vec![self.forest().root(face.surface())];
        let side = face.side();
        while let Some(id) = stack.pop() {
            let e = self.forest().element(id);
            if let Some(children) = e.children() {
                stack.extend(children);
            } else {
                let ambient = self
                    .ambient
                    .lambertian_element(&self.scene, self.forest(), face, id);
                sum += (self.radiance[side][id.index()] + ambient)
                    * self.exposed_area[side][id.index()];
                area += e.area;
            }
        }
        if area > 0.0 { sum * (1.0 / area) } else { sum }
    }

    /// [`Solution::surface_mean_radiance`] over all the input surfaces of
    /// one shape (a cube's six faces, a mesh's charts), area-weighted.
    pub fn shape_mean_radiance(&self, shape: u32, side: Side) -> Spectrum<N> {
        let mut sum = Spectrum::<N>::zero();
        let mut area = 0.0;
        let geom = self.forest().geometry();
        for s in geom.surfaces_of_shape(shape) {
            let a = geom.surface(s).area();
            sum += self.surface_mean_radiance(FaceId::new(s, side)) * a;
            area += a;
        }
        if area > 0.0 { sum * (1.0 / area) } else { sum }
    }

    /// Flux π Σ T L carried by the stored interaction from one face to
    /// another (flux-weighted over its hierarchy, so it is the root's
    /// π T L), if that interaction exists.
    pub fn interaction_flux(&self, from: FaceId, to: FaceId) -> Option<Spectrum<N>> {
        let h = &self.hierarchies[*self.by_faces.get(&(from, to))? as usize];
        let root = &h.nodes[0];
        Some(root.radiance * (std::f64::consts::PI * root.t))
    }

    /// The smallest radiance value (any band, any element or node) of the
    /// solution; NaN if any value is not finite.
    pub fn min_radiance(&self) -> f64 {
        let mut min = f64::INFINITY;
        let mut visit = |s: &Spectrum<N>| {
            for b in 0..N {
                if !s[b].is_finite() {
                    min = f64::NAN;
                } else if !min.is_nan() {
                    min = min.min(s[b]);
                }
            }
        };
        for (_, side) in self.radiance.iter() {
            side.iter().for_each(&mut visit);
        }
        for h in &self.hierarchies {
            h.nodes.iter().for_each(|n| visit(&n.radiance));
        }
        for r in &self.far {
            r.blocks.iter().for_each(|(_, l)| visit(l));
        }
        min
    }

    /// Number of stored interaction hierarchies and of their nodes.
    pub fn interaction_counts(&self) -> (usize, usize) {
        (
            self.hierarchies.len(),
            self.hierarchies.iter().map(|h| h.nodes.len()).sum(),
        )
    }

    /// Whether the solution has stored (direction-dependent) radiance from
    /// `from`'s face towards `to`'s face.
    pub fn has_stored(&self, from: &SurfaceSite, to: &SurfaceSite) -> bool {
        self.by_faces.contains_key(&(from.face, to.face))
            || (self
                .far_faces
                .get(from.face.index())
                .copied()
                .unwrap_or(false)
                && self
                    .tree
                    .ancestors(to.face.surface())
                    .any(|c| self.far_index.contains_key(&(from.face, c))))
    }

    /// Number of glossy far fields and of their far blocks
    /// (`cluster_transport`).
    pub fn far_field_counts(&self) -> (usize, usize) {
        (
            self.far.len(),
            self.far.iter().map(|r| r.blocks.len()).sum(),
        )
    }
}
