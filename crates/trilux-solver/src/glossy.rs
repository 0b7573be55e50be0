//! The glossy renormalisation (beyond the paper; docs/solver.md, "Glossy
//! renormalisation"): what a receiving element's glossy part reflects in
//! one shot is rescaled towards what its BRDF reflects over the receivers
//! it stores interactions towards.
//!
//! Point samples of a peaked lobe over coarse receivers K fall short of
//! (or overshoot) the lobe's integral. For each pair link i → j (a group)
//! the node links' glossy flux is scaled towards a target:
//! - where (nearly) every direction from j reaches a stored receiver
//!   (cosine-weighted coverage ≥ [`CLOSED_COVERAGE`]), the glossy albedo of
//!   j's BRDF for light from i times the covered share;
//! - in an open hemisphere, the share of the lobe that meets a stored
//!   receiver, by sampling the BRDF ([`LOBE_SAMPLES`] traced samples).
//!
//! The scale is bounded by [`MAX_RENORMALISATION`] either way, and never
//! lets j reflect more than arrived. Two-point transport only: the uniform
//! mode stays the paper's, for ablation.

use glam::{DVec2, DVec3};
use trilux_brdf::Frame;
use trilux_brdf::frame::square_to_cosine_hemisphere;
use trilux_color::Spectrum;
use trilux_geometry::sampling::hammersley;
use trilux_geometry::{ElementId, FaceId, Ray};

use crate::link::PairLink;
use crate::refine::Incidence;
use crate::settings::Transport;
use crate::solver::Solver;
use crate::throughput::compute_throughput;

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

/// Rays per element for the traced hemisphere coverage of a face with a
/// far field.
const COVERAGE_RAYS: u32 = 64;

/// The per-band scales of a group's glossy flux: of `glossy`, the flux of
/// its midpoint-rule links, towards `target` less what the sampled links
/// carry (within [`MAX_RENORMALISATION`]); of `sampled`, the flux of its
/// sampled links (docs/solver.md, "Narrow lobes"), 1, as sampling already
/// conserves energy. Both are lowered alike if together they would exceed
/// `room`, what arrived less the Lambertian share.
pub(crate) fn group_scale<const N: usize>(
    target: Option<Spectrum<N>>,
    glossy: Spectrum<N>,
    sampled: Spectrum<N>,
    room: Spectrum<N>,
) -> (Spectrum<N>, Spectrum<N>) {
    let mut mid = Spectrum::<N>::splat(1.0);
    let mut smp = Spectrum::<N>::splat(1.0);
    for b in 0..N {
        if let Some(t) = target
            && glossy[b] > 0.0
        {
            let want = (t[b] - sampled[b]).max(0.0);
            mid[b] = (want / glossy[b]).clamp(1.0 / MAX_RENORMALISATION, MAX_RENORMALISATION);
        }
        let total = glossy[b] * mid[b] + sampled[b];
        if total > room[b] && total > 0.0 {
            let f = room[b].max(0.0) / total;
            mid[b] *= f;
            smp[b] *= f;
        }
    }
    (mid, smp)
}

impl<const N: usize> Solver<N> {
    /// The glossy flux a group should reflect (module docs), for the flux
    /// `arrived` through pair link `l`, `late` past the solve's deadline;
    /// `None` where no renormalisation applies. The light arrives from the
    /// part of i in front of j (the same direction the group's area
    /// reflectances used).
    pub(crate) fn glossy_target(
        &self,
        l: &PairLink<N>,
        incidence: Option<&Incidence<N>>,
        arrived: Spectrum<N>,
        (glossy, late): (Spectrum<N>, bool),
    ) -> Option<Spectrum<N>> {
        let face = &self.setup.faces[l.face];
        if !face.stored || glossy.is_black() || self.setup.settings.transport != Transport::TwoPoint
        {
            return None;
        }
        let to_light = incidence.and_then(Incidence::direction)?;
        // A faint glossy share (received above j) takes the face's mean
        // coverage, as past the deadline.
        let coarse = incidence.is_some_and(|inc| inc.coarse);
        let covered = self.hemisphere_coverage(l.face, l.j, late || coarse);
        // A textured j reflects g(j) times the nominal glossy part.
        let g = self
            .setup
            .textures
            .as_ref()
            .map_or(Spectrum::splat(1.0), |t| t.glossy(l.face, l.j));
        if covered >= CLOSED_COVERAGE {
            let normal = self.setup.forest().element(l.j).normal * l.face.side().sign();
            let wi = Frame::from_normal(normal).to_local(to_light);
            let glossy_albedo = self.setup.albedo[face.shape].albedo(wi) - face.rho_d;
            Some((arrived * glossy_albedo * g * covered.min(1.0)).max(Spectrum::zero()))
        } else {
            // An open hemisphere: the share of the lobe that meets a stored
            // receiver (a narrow lobe need not miss the open part in
            // proportion).
            Some(arrived * self.covered_lobe(l.face, to_light, l.j) * g)
        }
    }

    /// ∫ fr_glossy cos dω over the directions from j's centre that meet a
    /// face that `face` stores an interaction towards, for light arriving
    /// from the unit direction `to_light` (world space): [`LOBE_SAMPLES`]
    /// stratified samples of the BSDF, each traced.
    fn covered_lobe(&self, face: FaceId, to_light: DVec3, j: ElementId) -> Spectrum<N> {
        let geom = self.setup.forest().geometry();
        let ts = &self.setup.faces[face];
        let sign = face.side().sign();
        let ej = self.setup.forest().element(j);
        let normal = ej.normal * sign;
        let frame = Frame::from_normal(normal);
        let wi = frame.to_local(to_light);
        let bsdf = self.setup.scene.material(ts.shape);
        // The BSDF's frame is the front's: flip z for a back face.
        let to_bsdf = |v: DVec3| DVec3::new(v.x, v.y, v.z * sign);
        let origin = ej.centre + normal * (1e-7 * geom.bounds().diagonal().length());
        let mut sum = Spectrum::<N>::zero();
        let grid = (LOBE_SAMPLES as f64).sqrt() as u32;
        for a in 0..grid {
            for b in 0..grid {
                let u = DVec2::new(
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
                let ray = Ray {
                    origin,
                    dir: frame.to_world(wo),
                };
                if !self.reaches(face, geom.intersect(&ray, f64::INFINITY), &ray) {
                    continue;
                }
                let f = bsdf.eval_glossy(to_bsdf(wi), smp.wi);
                sum += f * (wo.z / smp.pdf);
            }
        }
        sum * (1.0 / f64::from(grid * grid))
    }

    /// True when `face`'s far field sends to surface `s`.
    fn far_reaches(&self, face: FaceId, s: trilux_geometry::SurfaceId) -> bool {
        self.state.far[face].is_some()
            && crate::cluster_transport::block_of(
                &self.setup.clusters.tree,
                &self.setup.clusters.cuts[face],
                s,
            )
            .is_some()
    }

    /// The cosine-weighted share of j's hemisphere that `face` sends light
    /// to (1 in a closed room), cached per (face, element). Without a far
    /// field it is Σ over the face's stored hierarchies of T(j, K) / A_j;
    /// with one, it is traced ([`Self::traced_coverage`]). Past the
    /// deadline (`late`) the face's mean stands in for j's: its root's,
    /// from the root throughputs the hierarchies already hold, instead of
    /// a new throughput to every stored receiver per element
    /// (docs/solver.md, "The deadline inside a shot").
    pub(crate) fn hemisphere_coverage(&self, face: FaceId, j: ElementId, late: bool) -> f64 {
        let j = if late {
            self.setup.forest().root(face.surface())
        } else {
            j
        };
        if let Ok(cache) = self.state.coverage.lock()
            && let Some(&c) = cache.get(&(face, j))
        {
            return c;
        }
        let a = self.setup.exposed_area[face.side()][j.index()];
        if a <= 0.0 {
            return 0.0;
        }
        let c = if self.state.far[face].is_some() {
            self.traced_coverage(face, j)
        } else {
            self.stored_coverage(face, j, late) / a
        };
        if let Ok(mut cache) = self.state.coverage.lock() {
            cache.insert((face, j), c);
        }
        c
    }

    /// Σ over the face's stored hierarchies of T(j, K): a throughput from
    /// j to every stored receiver (past the deadline, j being the root,
    /// the hierarchies' root throughputs where they are made).
    fn stored_coverage(&self, face: FaceId, j: ElementId, late: bool) -> f64 {
        let vis = self.setup.visibility();
        let mut t = 0.0;
        for h in self.state.hierarchies[self.setup.stored_from[face].clone()]
            .iter()
            .flatten()
        {
            if late && !h.pending {
                t += h.nodes[0].t;
                continue;
            }
            let k = h.to.of(h.nodes[0].to);
            t += compute_throughput(
                &vis,
                k,
                face.of(j),
                self.setup.settings.visibility_samples,
                false,
            )
            .t;
        }
        t
    }

    /// The coverage of a face with a far field, traced: the share of
    /// [`COVERAGE_RAYS`] rays from exposed points of j (the R2 sequence),
    /// in cosine-distributed directions (the Hammersley set), whose first hit is a
    /// face that `face` stores an interaction towards or its far field
    /// reaches (the test [`Self::covered_lobe`] makes of its samples); 0
    /// when every point is buried. A face with a far field has many
    /// receivers: a throughput to each per element was most of what its
    /// coverage cost, and the far blocks' cluster estimates (point-to-disc
    /// form factors, one visible fraction per block) put elements of a
    /// closed room anywhere from 0.6 to 1.2.
    fn traced_coverage(&self, face: FaceId, j: ElementId) -> f64 {
        let forest = self.setup.forest();
        let geom = forest.geometry();
        let sign = face.side().sign();
        let eps = 1e-7 * geom.bounds().diagonal().length();
        let (mut rays, mut hits) = (0u32, 0u32);
        for k in 0..COVERAGE_RAYS {
            let x = forest.sample_element(j, crate::cluster_transport::r2(k, 0.5));
            if (self.setup.burial.as_ref()).is_some_and(|b| b.is_buried(face, x.coord)) {
                continue;
            }
            let normal = x.normal * sign;
            // Cell midpoints of a grid would never reach the grazing ring
            // that open scenes lose light through.
            let u = hammersley(k, COVERAGE_RAYS);
            let ray = Ray {
                origin: x.point + normal * eps,
                dir: Frame::from_normal(normal).to_world(square_to_cosine_hemisphere(u)),
            };
            rays += 1;
            hits += u32::from(self.reaches(face, geom.intersect(&ray, f64::INFINITY), &ray));
        }
        if rays == 0 {
            0.0
        } else {
            f64::from(hits) / f64::from(rays)
        }
    }

    /// True when a ray leaving `face` whose first hit is `hit` meets a face
    /// that `face` stores an interaction towards or its far field reaches.
    fn reaches(&self, face: FaceId, hit: Option<trilux_geometry::Hit>, ray: &Ray) -> bool {
        let Some(hit) = hit else {
            return false;
        };
        let hit_face = FaceId::new(
            hit.surface,
            trilux_geometry::Side::from_back(!hit.front_facing(ray)),
        );
        self.setup.stored_pairs.contains(&(face, hit_face)) || self.far_reaches(face, hit.surface)
    }
}

#[cfg(test)]
mod tests {
    //! The traced hemisphere coverage of a glossy face with a far field,
    //! against a closed room (exactly 1) and the closed-form form factor
    //! of a parallel square.
    #![allow(clippy::unwrap_used, clippy::expect_used)] // tests may panic

    use glam::{DMat4, DVec3};
    use trilux_color::ColorParam;
    use trilux_geometry::{Shape, ShapeKind};

    use crate::prepared::SceneDescription;
    use crate::solver::Solver;
    use crate::test_scenes as ts;

    /// A 5 × 5 grid of glossy squares 0.1 wide, 1 apart, facing up at
    /// z = 0, and an emitter of side `light` facing down at height 1 over
    /// the middle one, in `extra` shapes (diffuse).
    fn glossy_grid(light: f64, extra: &[Shape]) -> Solver<3> {
        let mut shapes = vec![ts::square(DVec3::new(0.0, 0.0, 1.0), light, true)];
        let mut bsdfs = vec![ts::diffuse(0.0)];
        let mut emission = vec![Some(ColorParam::Float(1.0))];
        for a in -2..=2 {
            for b in -2..=2 {
                let c = DVec3::new(f64::from(a), f64::from(b), 0.0);
                shapes.push(ts::square(c, 0.1, false));
                bsdfs.push(ts::glossy(0.3));
                emission.push(None);
            }
        }
        for s in extra {
            shapes.push(s.clone());
            bsdfs.push(ts::diffuse(0.5));
            emission.push(None);
        }
        let desc = SceneDescription {
            shapes: &shapes,
            bsdfs: &bsdfs,
            emission: &emission,
        };
        Solver::from_description(&desc, ts::settings(2)).unwrap()
    }

    /// The middle square's front, with its root: it has a far field (the
    /// other squares are far from it).
    fn middle(s: &Solver<3>) -> (trilux_geometry::FaceId, trilux_geometry::ElementId) {
        // Shape 0 is the emitter; the grid's middle is the 13th square.
        let face = ts::front(13);
        assert!(
            s.state.far[face].is_some(),
            "the middle square has a far field"
        );
        (face, s.setup.forest().root(face.surface()))
    }

    /// Inside a closed box every ray meets a face the square sends to.
    #[test]
    fn a_closed_room_is_covered_whole() {
        let inside = Shape {
            kind: ShapeKind::Cube,
            world_from_object: DMat4::from_translation(DVec3::new(0.0, 0.0, 0.5))
                * DMat4::from_scale(DVec3::new(3.0, 3.0, 1.5)),
            flip_normals: true,
        };
        let s = glossy_grid(1.0, &[inside]);
        let (face, root) = middle(&s);
        assert_eq!(s.hemisphere_coverage(face, root, false), 1.0);
    }

    /// With nothing else around, the rays that meet a face the square
    /// sends to are those towards the emitter (side 4 at height 1):
    /// F = 0.8310 from the square's centre (parallel rectangle, closed
    /// form), where a uniform instead of cosine weighting would give the
    /// solid angle's share, 0.590. Tolerance 0.14: three standard
    /// deviations of a 64-ray binomial estimate (stratification only
    /// lowers it); F varies by less than 0.01 over the 0.1-wide square.
    #[test]
    fn an_open_square_is_covered_by_its_emitter_form_factor() {
        let s = glossy_grid(4.0, &[]);
        let (face, root) = middle(&s);
        // Four corners of X = Y = 2: (2/π)[X/√(1+X²) atan(Y/√(1+X²))] × 2.
        let x: f64 = 2.0;
        let q = (1.0 + x * x).sqrt();
        let f = 4.0 / std::f64::consts::PI * (x / q) * (x / q).atan();
        assert!((f - 0.8310).abs() < 1e-3, "{f}");
        let c = s.hemisphere_coverage(face, root, false);
        assert!((c - f).abs() <= 0.14, "coverage {c}, form factor {f}");
    }
}
