//! Phase 5 of a shot (`shot`): what every pair link (a "group") delivers
//! to its receiving element — the Lambertian share into j's two-point
//! radiance, the glossy share renormalised (`glossy`), into the face's far
//! field, or left waiting (`deferred`) — and the ledger's bookings.

use std::f64::consts::PI;

use rayon::prelude::*;
use trilux_color::Spectrum;
use trilux_geometry::ElementId;

use crate::cluster_transport::FarField;
use crate::deferred::GlossyIn;
use crate::link::{NodeLink, PairLink};
use crate::refine::Incidence;
use crate::shot::{Glossy, Groups};
use crate::solver::{Solver, Source};

impl<const N: usize> Solver<N> {
    /// Phase 5: what every pair link (a group) delivers to its receiving
    /// element j. The flux π T_ij δL arrives; its Lambertian share ρ_d goes
    /// straight into j's two-point radiance; the glossy share is what the
    /// group's node links gathered, renormalised (`glossy`) so that j never
    /// reflects more than arrived; the rest is absorbed. A glossy share
    /// that waits (`deferred`) is neither reflected nor absorbed yet; a
    /// released sum is reflected and absorbed now. Books absorbed and
    /// escaped flux in the ledger, what was reflected in the
    /// interreflection estimate (`share` of the shot's flux `phi` being
    /// reflected light), and returns each group's glossy scale.
    pub(crate) fn receive(
        &mut self,
        groups: &Groups<N>,
        glossy: &Glossy<N>,
        incidences: &[Option<Incidence<N>>],
        node_links: &[NodeLink<N>],
        (phi, share): (Spectrum<N>, Spectrum<N>),
    ) -> Vec<(Spectrum<N>, Spectrum<N>)> {
        self.trace_far_fields(glossy);
        let (glossy_flux, sampled_flux, far_adds) =
            self.glossy_fluxes(glossy, incidences, node_links);
        let late = self.past_deadline();
        let targets = self.glossy_targets(glossy, incidences, (&glossy_flux, late));
        let mut group_scale =
            vec![(Spectrum::<N>::splat(1.0), Spectrum::splat(1.0)); groups.links.len()];
        let mut total_arrived = Spectrum::<N>::zero();
        let mut absorbed = Spectrum::<N>::zero();
        for (g, l) in groups.links.iter().enumerate() {
            let arrived = l.unshot * groups.scale * (PI * l.t);
            let rho_d = self.receive_lambertian(l, groups.scale);
            // Light spreads over j's exposed area. (No transfer reaches an
            // element that is wholly buried, whose segments all count as
            // blocked; if one did, its light would be absorbed.)
            let aj = self.setup.exposed_area[l.face.side()][l.j.index()];
            let kept = |arrived: Spectrum<N>| {
                let diffuse = if aj > 0.0 {
                    arrived * rho_d
                } else {
                    Spectrum::zero()
                };
                (diffuse, (arrived - diffuse).max(Spectrum::zero()))
            };
            let (diffuse, room_own) = kept(arrived);
            // What an element reflects may not exceed what arrived there
            // (of a released sum: all that waited).
            let room = match &groups.plan[g] {
                GlossyIn::Now => room_own,
                GlossyIn::Wait { from } => {
                    self.state.deferred.book_waiting(l.face, *from, room_own);
                    self.state.queue.touch(Source::Deferred(l.face));
                    Spectrum::zero()
                }
                GlossyIn::Flush { waited, .. } => *waited + room_own,
            };
            let (glossy_g, sampled) = (glossy_flux[g], sampled_flux[g]);
            let target = targets[g];
            self.state.stats.late_groups += u64::from(late && target.is_some());
            self.state.stats.coarse_groups +=
                u64::from(target.is_some() && incidences[g].as_ref().is_some_and(|i| i.coarse));
            let scale = crate::glossy::group_scale(target, glossy_g, sampled, room);
            group_scale[g] = scale;
            let reflected_glossy = glossy_g * scale.0 + sampled * scale.1;
            let absorbed_g = room - reflected_glossy;
            // (A share that waits has absorbed nothing yet.)
            if !matches!(groups.plan[g], GlossyIn::Wait { .. }) {
                let base = (arrived + room).max_value().max(1e-300);
                self.state.ledger.min_element_absorbed = self
                    .state
                    .ledger
                    .min_element_absorbed
                    .min(absorbed_g.min_value() / base);
            }
            total_arrived += arrived;
            absorbed += absorbed_g;
            let ir = &mut self.state.interreflection;
            match &groups.plan[g] {
                GlossyIn::Flush {
                    share: released, ..
                } => {
                    ir.book_group(l.face, arrived, diffuse, share);
                    ir.book_group(l.face, Spectrum::zero(), reflected_glossy, *released);
                }
                _ => ir.book_group(l.face, arrived, diffuse + reflected_glossy, share),
            }
            self.state.used[l.i.index()] = true;
            self.state.used[l.j.index()] = true;
        }
        self.add_far_reflection(&groups.links, far_adds, &group_scale);
        self.state.ledger.book_shot(phi, total_arrived, absorbed);
        group_scale
    }

    /// Traces the far fields of the faces that this shot's glossy light
    /// reaches for the first time (`FarField::trace`), in parallel over
    /// the faces, before anything reads their T_AC.
    fn trace_far_fields(&mut self, glossy: &Glossy<N>) {
        let far = &mut self.state.far;
        // Taking a field out leaves `None`, so each face is taken once.
        let mut fields: Vec<FarField<N>> = (glossy.links.iter())
            .filter_map(|l| far[l.face].take_if(|field| !field.traced))
            .collect();
        if fields.is_empty() {
            return;
        }
        let ctx = self.setup.refine_context(&self.state.cache).far();
        let cuts = &self.setup.clusters.cuts;
        (fields.par_iter_mut()).for_each(|field| field.trace(&ctx, &cuts[field.face]));
        for field in fields {
            let face = field.face;
            far[face] = Some(field);
        }
    }

    /// Per group, the glossy flux its node links carry (midpoint-rule
    /// links, renormalised, and sampled ones, already conserving:
    /// docs/solver.md, "Narrow lobes"), with what it reflects into its
    /// face's far field (per far block, before the renormalisation).
    #[allow(clippy::type_complexity)]
    fn glossy_fluxes(
        &self,
        glossy: &Glossy<N>,
        incidences: &[Option<Incidence<N>>],
        node_links: &[NodeLink<N>],
    ) -> (
        Vec<Spectrum<N>>,
        Vec<Spectrum<N>>,
        Vec<Option<Vec<Spectrum<N>>>>,
    ) {
        let n = glossy.links.len();
        let mut glossy_flux = vec![Spectrum::<N>::zero(); n];
        let mut sampled_flux = vec![Spectrum::<N>::zero(); n];
        for nl in node_links {
            if let Some(h) = &self.state.hierarchies[nl.hierarchy as usize] {
                let t = h.nodes[nl.node as usize].t;
                let g = nl.group as usize;
                let flux = nl.gathered * glossy.scales[g] * (PI * t);
                if nl.sampled {
                    sampled_flux[g] += flux;
                } else {
                    glossy_flux[g] += flux;
                }
            }
        }
        let far_adds: Vec<Option<Vec<Spectrum<N>>>> = glossy
            .links
            .par_iter()
            .zip(&glossy.scales)
            .zip(incidences)
            .map(|((l, &scale), inc)| self.far_reflection(l, inc.as_ref(), scale))
            .collect();
        for (g, adds) in far_adds.iter().enumerate() {
            if let (Some(adds), Some(field)) = (adds, &self.state.far[glossy.links[g].face]) {
                for (b, dl) in field.blocks.iter().zip(adds) {
                    glossy_flux[g] += *dl * (PI * b.t);
                }
            }
        }
        (glossy_flux, sampled_flux, far_adds)
    }

    /// Each group's far-field increments, renormalised with its group.
    fn add_far_reflection(
        &mut self,
        links: &[PairLink<N>],
        far_adds: Vec<Option<Vec<Spectrum<N>>>>,
        group_scale: &[(Spectrum<N>, Spectrum<N>)],
    ) {
        for (g, adds) in far_adds.into_iter().enumerate() {
            let Some(adds) = adds else { continue };
            let Some(field) = self.state.far[links[g].face].as_mut() else {
                continue;
            };
            for (b, dl) in field.blocks.iter_mut().zip(adds) {
                let dl = dl * group_scale[g].0;
                b.radiance += dl;
                b.unshot += dl;
                field.unshot_flux += dl * (PI * b.t);
            }
            self.state.queue.touch(Source::Far(links[g].face));
        }
    }

    /// The radiance increments ΔL_AC = π fr(i→j→C) T_ij δL_i / A_A that
    /// pair link `l` into element j of glossy face A adds to A's far field,
    /// one per far block (`cluster_transport`); `None` when A has no far
    /// field or the light arrives from behind.
    fn far_reflection(
        &self,
        l: &PairLink<N>,
        incidence: Option<&Incidence<N>>,
        shot_scale: Spectrum<N>,
    ) -> Option<Vec<Spectrum<N>>> {
        let field = self.state.far[l.face].as_ref()?;
        let to_light = incidence?.direction()?;
        let root = self.setup.forest().root(l.face.surface());
        let area = self.setup.exposed_area[l.face.side()][root.index()];
        if area <= 0.0 {
            return None;
        }
        let bsdf = self.setup.scene.material(self.setup.faces[l.face].shape);
        let frame = trilux_brdf::Frame::from_normal(self.setup.forest().element(l.j).normal);
        let wi = frame.to_local(to_light);
        let dl = l.unshot * shot_scale * (PI * l.t / area);
        Some(
            field
                .blocks
                .iter()
                .map(|b| {
                    let wo = frame.to_local(b.direction);
                    if wo.z * wi.z <= 0.0 {
                        Spectrum::zero()
                    } else {
                        dl * bsdf.eval_glossy(wi, wo)
                    }
                })
                .collect(),
        )
    }

    /// Each group's glossy target (`glossy::glossy_target`), in parallel:
    /// its hemisphere coverage traces rays.
    fn glossy_targets(
        &self,
        glossy: &Glossy<N>,
        incidences: &[Option<Incidence<N>>],
        (glossy_flux, late): (&[Spectrum<N>], bool),
    ) -> Vec<Option<Spectrum<N>>> {
        glossy
            .links
            .par_iter()
            .zip(&glossy.scales)
            .zip(incidences)
            .zip(glossy_flux)
            .map(|(((l, &scale), inc), &flux)| {
                let arrived = l.unshot * scale * (PI * l.t);
                self.glossy_target(l, inc.as_ref(), arrived, (flux, late))
            })
            .collect()
    }

    /// The Lambertian share of a pair link: ρ_d (T_ij / A_j) δL into j's
    /// gathered radiance and its flux into the face's key. On
    /// smooth-shaded meshes the BSDF takes the cosine about the shading
    /// normal (as Mitsuba does), which changes the irradiance it reflects
    /// (never beyond what arrived). Returns the ρ_d used.
    fn receive_lambertian(&mut self, l: &PairLink<N>, shot_scale: Spectrum<N>) -> Spectrum<N> {
        let face = &self.setup.faces[l.face];
        let rho = match &self.setup.textures {
            Some(t) => t.rho(l.face, l.j).unwrap_or(face.rho_d),
            None => face.rho_d,
        };
        let rho_d = (rho * self.shading_factor(l.i, l.j)).min(Spectrum::splat(1.0));
        let side = l.face.side();
        let aj = self.setup.exposed_area[side][l.j.index()];
        if !rho_d.is_black() && aj > 0.0 {
            let dl = l.unshot * shot_scale * rho_d * (l.t / aj);
            self.state.field.gathered[side][l.j.index()] += dl;
            self.state.face_flux[l.face] += dl * (PI * aj);
            self.state.queue.touch(Source::Radiosity(l.face));
        }
        rho_d
    }

    /// The irradiance about j's shading normals over the one about its
    /// geometric normals, for light from i's centre (1 where shading and
    /// geometric normals agree): (Σ A n_s · d)/(Σ A n_g · d), in [¼, 4].
    fn shading_factor(&self, i: ElementId, j: ElementId) -> f64 {
        let Some((s, g)) = self.setup.shading[j.index()] else {
            return 1.0;
        };
        let d = self.setup.forest().element(i).centre - self.setup.forest().element(j).centre;
        let (ds, dg) = (s.dot(d), g.dot(d));
        if dg.abs() <= 1e-12 * g.length() * d.length() || ds * dg <= 0.0 {
            return 1.0;
        }
        (ds / dg).clamp(0.25, 4.0)
    }
}
