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
use crate::link::{NodeLinks, PairLink};
use crate::refine::Incidence;
use crate::shot::{Glossy, Groups};
use crate::solver::{Solver, Source};

/// What the glossy shares of a shot's groups reflect, per group: filled
/// batch by batch of receiving faces (`Solver::reflect_batch`), booked once
/// for the whole shot (`Solver::receive`).
pub(crate) struct Reception<const N: usize> {
    /// The flux of the midpoint-rule node links and far-field increments.
    glossy_flux: Vec<Spectrum<N>>,
    /// The flux of the sampled node links (docs/solver.md, "Narrow lobes").
    sampled_flux: Vec<Spectrum<N>>,
    /// The far-field increments, before the renormalisation.
    far_adds: Vec<Option<Vec<Spectrum<N>>>>,
    /// What arrives through each group and what it may reflect.
    rooms: Vec<GroupRoom<N>>,
    /// Each group's scales of its midpoint-rule and sampled links.
    pub scales: Vec<(Spectrum<N>, Spectrum<N>)>,
}

/// What arrives through one group and what its glossy share may reflect.
struct GroupRoom<const N: usize> {
    /// π T_ij δL, the flux that arrives at j.
    arrived: Spectrum<N>,
    /// The ρ_d that j reflects it with (`lambertian_rho`).
    rho_d: Spectrum<N>,
    /// Its Lambertian share.
    diffuse: Spectrum<N>,
    /// What the glossy share may reflect of its own light.
    own: Spectrum<N>,
    /// What it may reflect now (none for a share that waits; for a
    /// released sum, all that waited too).
    now: Spectrum<N>,
}

impl<const N: usize> Solver<N> {
    /// Before a shot's batches: what arrives through each group, the far
    /// fields its glossy light reaches traced, and what each group adds to
    /// them as its first glossy flux.
    pub(crate) fn begin_reception(
        &mut self,
        groups: &Groups<N>,
        glossy: &Glossy<N>,
        incidences: &[Option<Incidence<N>>],
    ) -> Reception<N> {
        let rooms = (0..groups.links.len())
            .map(|g| self.group_room(groups, g))
            .collect();
        self.trace_far_fields(glossy);
        let n = glossy.links.len();
        let far_adds: Vec<Option<Vec<Spectrum<N>>>> = glossy
            .links
            .par_iter()
            .zip(&glossy.scales)
            .zip(incidences)
            .map(|((l, &scale), inc)| self.far_reflection(l, inc.as_ref(), scale))
            .collect();
        let mut glossy_flux = vec![Spectrum::<N>::zero(); n];
        for (g, adds) in far_adds.iter().enumerate() {
            if let (Some(adds), Some(field)) = (adds, &self.state.far[glossy.links[g].face]) {
                for (b, dl) in field.blocks.iter().zip(adds) {
                    glossy_flux[g] += *dl * (PI * b.t);
                }
            }
        }
        Reception {
            glossy_flux,
            sampled_flux: vec![Spectrum::zero(); n],
            far_adds,
            rooms,
            scales: vec![(Spectrum::splat(1.0), Spectrum::splat(1.0)); n],
        }
    }

    /// One batch of a shot's groups (whole receiving faces) after its
    /// stage 2: its node links' flux, then each group's scales
    /// (`glossy::group_scale`) towards its target, so that j never
    /// reflects more than arrived.
    pub(crate) fn reflect_batch(
        &mut self,
        (glossy, incidences): (&Glossy<N>, &[Option<Incidence<N>>]),
        node_links: &NodeLinks<N>,
        batch: &[u32],
        reception: &mut Reception<N>,
    ) {
        self.add_node_fluxes(glossy, node_links, reception);
        let late = self.past_deadline();
        let targets: Vec<Option<Spectrum<N>>> = batch
            .par_iter()
            .map(|&g| {
                let g = g as usize;
                let (l, scale) = (&glossy.links[g], glossy.scales[g]);
                let arrived = l.unshot * scale * (PI * l.t);
                let flux = reception.glossy_flux[g];
                self.glossy_target(l, incidences[g].as_ref(), arrived, (flux, late))
            })
            .collect();
        for (&g, target) in batch.iter().zip(targets) {
            let g = g as usize;
            let room = reception.rooms[g].now;
            self.state.stats.late_groups += u64::from(late && target.is_some());
            self.state.stats.coarse_groups +=
                u64::from(target.is_some() && incidences[g].as_ref().is_some_and(|i| i.coarse));
            let (glossy_g, sampled) = (reception.glossy_flux[g], reception.sampled_flux[g]);
            reception.scales[g] = crate::glossy::group_scale(target, glossy_g, sampled, room);
        }
    }

    /// Phase 5: what every pair link (a group) delivers to its receiving
    /// element j. The flux π T_ij δL arrives; its Lambertian share ρ_d goes
    /// straight into j's two-point radiance; the glossy share is what the
    /// group's node links gathered, renormalised (`reflect_batch`); the
    /// rest is absorbed. A glossy share that waits (`deferred`) is neither
    /// reflected nor absorbed yet; a released sum is reflected and
    /// absorbed now. Books absorbed and escaped flux in the ledger, what
    /// was reflected in the interreflection estimate (`share` of the
    /// shot's flux `phi` being reflected light), and the far fields'
    /// increments.
    pub(crate) fn receive(
        &mut self,
        groups: &Groups<N>,
        reception: Reception<N>,
        (phi, share): (Spectrum<N>, Spectrum<N>),
    ) {
        let mut total_arrived = Spectrum::<N>::zero();
        let mut absorbed = Spectrum::<N>::zero();
        for (g, l) in groups.links.iter().enumerate() {
            let room = &reception.rooms[g];
            self.receive_lambertian(l, room.rho_d, groups.scale);
            if let GlossyIn::Wait { from } = &groups.plan[g] {
                self.state.deferred.book_waiting(l.face, *from, room.own);
                self.state.queue.touch(Source::Deferred(l.face));
            }
            let scale = reception.scales[g];
            let reflected_glossy =
                reception.glossy_flux[g] * scale.0 + reception.sampled_flux[g] * scale.1;
            let absorbed_g = room.now - reflected_glossy;
            // (A share that waits has absorbed nothing yet.)
            if !matches!(groups.plan[g], GlossyIn::Wait { .. }) {
                let base = (room.arrived + room.now).max_value().max(1e-300);
                self.state.ledger.min_element_absorbed = self
                    .state
                    .ledger
                    .min_element_absorbed
                    .min(absorbed_g.min_value() / base);
            }
            total_arrived += room.arrived;
            absorbed += absorbed_g;
            let ir = &mut self.state.interreflection;
            match &groups.plan[g] {
                GlossyIn::Flush {
                    share: released, ..
                } => {
                    ir.book_group(l.face, room.arrived, room.diffuse, share);
                    ir.book_group(l.face, Spectrum::zero(), reflected_glossy, *released);
                }
                _ => ir.book_group(l.face, room.arrived, room.diffuse + reflected_glossy, share),
            }
            self.state.used[l.i.index()] = true;
            self.state.used[l.j.index()] = true;
        }
        self.add_far_reflection(&groups.links, reception.far_adds, &reception.scales);
        self.state.ledger.book_shot(phi, total_arrived, absorbed);
    }

    /// What arrives through group `g` and what its glossy share may
    /// reflect (what arrived less the Lambertian share). Light spreads
    /// over j's exposed area. (No transfer reaches an element that is
    /// wholly buried, whose segments all count as blocked; if one did,
    /// its light would be absorbed.)
    fn group_room(&self, groups: &Groups<N>, g: usize) -> GroupRoom<N> {
        let l = &groups.links[g];
        let arrived = l.unshot * groups.scale * (PI * l.t);
        let aj = self.setup.exposed_area[l.face.side()][l.j.index()];
        let rho_d = self.lambertian_rho(l);
        let diffuse = if aj > 0.0 {
            arrived * rho_d
        } else {
            Spectrum::zero()
        };
        let own = (arrived - diffuse).max(Spectrum::zero());
        // What an element reflects may not exceed what arrived there (of
        // a released sum: all that waited).
        let now = match &groups.plan[g] {
            GlossyIn::Now => own,
            GlossyIn::Wait { .. } => Spectrum::zero(),
            GlossyIn::Flush { waited, .. } => *waited + own,
        };
        GroupRoom {
            arrived,
            rho_d,
            diffuse,
            own,
            now,
        }
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

    /// Adds, per group, the flux of a batch's node links: midpoint-rule
    /// links (renormalised later) and sampled ones (already conserving:
    /// docs/solver.md, "Narrow lobes").
    fn add_node_fluxes(
        &self,
        glossy: &Glossy<N>,
        node_links: &NodeLinks<N>,
        reception: &mut Reception<N>,
    ) {
        for (h, links) in node_links {
            let Some(h) = &self.state.hierarchies[*h as usize] else {
                continue;
            };
            for nl in links {
                let t = h.nodes[nl.node as usize].t;
                let g = nl.group as usize;
                let flux = nl.gathered * glossy.scales[g] * (PI * t);
                if nl.sampled {
                    reception.sampled_flux[g] += flux;
                } else {
                    reception.glossy_flux[g] += flux;
                }
            }
        }
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

    /// The Lambertian share of a pair link: ρ_d (T_ij / A_j) δL into j's
    /// gathered radiance and its flux into the face's key.
    fn receive_lambertian(&mut self, l: &PairLink<N>, rho_d: Spectrum<N>, shot_scale: Spectrum<N>) {
        let side = l.face.side();
        let aj = self.setup.exposed_area[side][l.j.index()];
        if !rho_d.is_black() && aj > 0.0 {
            let dl = l.unshot * shot_scale * rho_d * (l.t / aj);
            self.state.field.gathered[side][l.j.index()] += dl;
            self.state.face_flux[l.face] += dl * (PI * aj);
            self.state.queue.touch(Source::Radiosity(l.face));
        }
    }

    /// The ρ_d that j reflects light from i with. On smooth-shaded meshes
    /// the BSDF takes the cosine about the shading normal (as Mitsuba
    /// does), which changes the irradiance it reflects (never beyond what
    /// arrived).
    fn lambertian_rho(&self, l: &PairLink<N>) -> Spectrum<N> {
        let face = &self.setup.faces[l.face];
        let rho = match &self.setup.textures {
            Some(t) => t.rho(l.face, l.j).unwrap_or(face.rho_d),
            None => face.rho_d,
        };
        (rho * self.shading_factor(l.i, l.j)).min(Spectrum::splat(1.0))
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
