//! The unshot remainder: how much light the residual will still add to the
//! scene, the convergence ratio measured on it, and the ambient term that
//! stands in for it when a solve stops early (Cohen, Chen, Wallace &
//! Greenberg 1988; docs/solver.md, "Convergence ratio and ambient term").
//!
//! The image shows the light the scene's surfaces reflect. A shot of
//! reflected light returns, as light reflected again, a fraction a of its
//! flux (the rest is absorbed, or leaves an open scene). So the residual RF
//! will still be reflected RF · a / (1 − a) (every later bounce), and
//!
//!   CR = Φ_reflected / (Φ_reflected + RF · a / (1 − a)),
//!
//! the share of all the light the scene will reflect that it has reflected
//! so far. It is the paper's (IF − RF)/IF in a closed scene of uniform
//! reflectance, but does not count light that leaves an open scene, or a
//! black sky absorbs, as converged. a is measured on the shots of
//! reflected light (each shot's flux less the emission it carried).
//!
//! The ambient term spreads that future reflected light over the lit
//! reflecting area S: an element of reflectance ρ gains ρ · A_amb with
//! A_amb = RF · a / ((1 − a) π S). In a closed enclosure of uniform
//! reflectance ρ and form factors F_ij = A_j / A this is Cohen's ambient
//! term ρ · (Σ δB A / A) / (1 − ρ), which makes the stopped radiosity
//! exact.

use std::f64::consts::PI;

use trilux_color::Spectrum;
use trilux_geometry::{FaceId, PerFace};

use crate::stats::Ambient;

/// The most of its flux a reflected shot may return in the estimate (a
/// scene that reflects everything never converges; this keeps the
/// remainder finite).
const MAX_RETURN: f64 = 1.0 - 1e-9;

/// The light still to be reflected from a residual `residual` when every
/// shot returns `a` of its flux: residual · a / (1 − a).
pub(crate) fn future_reflected(residual: f64, a: f64) -> f64 {
    let a = a.clamp(0.0, MAX_RETURN);
    residual * a / (1.0 - a)
}

/// The ambient radiance A_amb that spreads `future` watts of reflected
/// light over a reflecting area `area` (Σ ρ A, m²): an element of
/// reflectance ρ sends ρ · A_amb more.
pub(crate) fn ambient_radiance(future: f64, area: f64) -> f64 {
    if area > 0.0 && future > 0.0 {
        future / (PI * area)
    } else {
        0.0
    }
}

/// CR = reflected / (reflected + future): 1 when nothing is reflected and
/// nothing is to come.
pub(crate) fn convergence_ratio(reflected: f64, future: f64) -> f64 {
    let total = reflected + future;
    if total > 0.0 {
        (reflected / total).clamp(0.0, 1.0)
    } else {
        1.0
    }
}

/// What the shots tell about interreflection, kept as they go.
#[derive(Clone, Debug)]
pub(crate) struct Interreflection<const N: usize> {
    /// Light reflected so far by every shot's receivers (W).
    reflected: Spectrum<N>,
    /// Flux of reflected light shot (each shot's flux less the emission it
    /// carried).
    shot: Spectrum<N>,
    /// What those shots' receivers reflected.
    returned: Spectrum<N>,
    /// Light arrived, over every shot, on receivers that reflect some of it
    /// (the estimate before any reflected light was shot).
    arrived_reflecting: Spectrum<N>,
    /// Per face, from the shots of reflected light: (arrived, reflected).
    faces: PerFace<(Spectrum<N>, Spectrum<N>)>,
}

impl<const N: usize> Interreflection<N> {
    /// Nothing shot yet, for a scene of `surfaces` input surfaces.
    pub fn new(surfaces: usize) -> Self {
        Interreflection {
            reflected: Spectrum::zero(),
            shot: Spectrum::zero(),
            returned: Spectrum::zero(),
            arrived_reflecting: Spectrum::zero(),
            faces: PerFace::from_fn(surfaces, |_| (Spectrum::zero(), Spectrum::zero())),
        }
    }

    /// The share of a shot's flux `phi` that is reflected light, per band,
    /// when it carried `emission` of emitted light.
    pub fn reflected_share(phi: Spectrum<N>, emission: Spectrum<N>) -> Spectrum<N> {
        Spectrum::new(std::array::from_fn(|b| {
            if phi[b] > 0.0 {
                ((phi[b] - emission[b]) / phi[b]).clamp(0.0, 1.0)
            } else {
                0.0
            }
        }))
    }

    /// A shot of flux `phi`, `share` of it reflected light.
    pub fn book_shot(&mut self, phi: Spectrum<N>, share: Spectrum<N>) {
        self.shot += phi * share;
    }

    /// One receiving group of a shot: `arrived` on `face`, of which it
    /// reflected `reflected`; `share` of the shot was reflected light.
    pub fn book_group(
        &mut self,
        face: FaceId,
        arrived: Spectrum<N>,
        reflected: Spectrum<N>,
        share: Spectrum<N>,
    ) {
        self.reflected += reflected;
        self.returned += reflected * share;
        for b in 0..N {
            if reflected[b] > 0.0 {
                self.arrived_reflecting[b] += arrived[b];
            }
        }
        let (a, r) = &mut self.faces[face];
        *a += arrived * share;
        *r += reflected * share;
    }

    /// The fraction a of a reflected shot's flux that comes back reflected,
    /// per band, for the shots still to come from `residual`: measured on
    /// the reflected shots so far, with the residual counted as returning
    /// the prior (the reflectance of the lit reflecting faces as if the
    /// scene were closed) until it is shot:
    ///
    ///   a = (returned + a₀ · RF) / (shot + RF).
    ///
    /// The first reflected shots are the brightest faces', which are not
    /// the residual's: in the bathroom the wall in front of its lamp panel
    /// shot first and sent 95 % of its light back into the black panel, a
    /// = 0.04 from that one shot said CR 0.977 after two shots, and the
    /// ambient term then brightened the image 2 to 4 times (results.md,
    /// "Real interiors"). a tends to the measured value as RF is shot;
    /// `None` before anything arrived.
    pub fn return_fraction(&self, residual: Spectrum<N>) -> Option<Spectrum<N>> {
        let prior = |b: usize| self.prior(b);
        if self.shot.max_value() > 0.0 {
            return Some(Spectrum::new(std::array::from_fn(|b| {
                let pending = residual[b].max(0.0);
                ratio(
                    self.returned[b] + prior(b) * pending,
                    self.shot[b] + pending,
                )
            })));
        }
        if self.arrived_reflecting.max_value() > 0.0 {
            return Some(Spectrum::new(std::array::from_fn(prior)));
        }
        None
    }

    /// a₀ in band `b`: what the receivers that reflect some light
    /// reflected over what arrived on them (the lit reflecting faces'
    /// reflectance, as if the scene were closed).
    fn prior(&self, b: usize) -> f64 {
        ratio(self.reflected[b], self.arrived_reflecting[b])
    }

    /// CR for the residual `residual`, `emission` of it emitted light not
    /// yet shot (module docs): 0 while nothing has arrived anywhere.
    pub fn convergence_ratio(&self, residual: Spectrum<N>, emission: Spectrum<N>) -> f64 {
        match self.return_fraction(reflected_part(residual, emission)) {
            Some(a) => {
                let future: f64 = (0..N)
                    .map(|b| self.future_of(residual[b], emission[b], a[b], b))
                    .sum();
                convergence_ratio(self.reflected.sum(), future)
            }
            None if residual.sum() > 0.0 => 0.0,
            None => 1.0,
        }
    }

    /// The light band `b` will still reflect from a residual `residual`,
    /// `emission` of it emitted light not yet shot, at return `a`: the
    /// reflected part returns a/(1 − a) of itself; emitted light is
    /// reflected first at the reflectance of the lit reflecting faces (the
    /// prior a₀), then returns as reflected light does: a₀/(1 − a). Taken
    /// as reflected light, unshot emission would count only at the return
    /// a, which is small where the shots so far found an open scene: a sky
    /// box's four sides, 7 % of its emission and all of the light that
    /// enters a room's windows level, were left unshot at CR 0.989
    /// (docs/solver.md, "Convergence ratio and ambient term").
    /// `a` is the return of the reflected part alone (its prior counts
    /// for that part only).
    fn future_of(&self, residual: f64, emission: f64, a: f64, b: usize) -> f64 {
        let emission = emission.clamp(0.0, residual.max(0.0));
        let prior = self.prior(b);
        let a = a.clamp(0.0, MAX_RETURN);
        future_reflected(residual - emission, a) + emission * prior / (1.0 - a)
    }

    /// The lit reflecting area S = Σ ρ A per band, as the participation of
    /// the faces in the reflected light: (Σ R_k)² / Σ R_k H_k / A_k (R_k
    /// reflected and H_k arrived on face k, A_k its exposed area), which is
    /// Σ ρ_k A_k when the light spreads evenly and the area of the part
    /// that is lit when it does not. `fallback` (Σ ρ A over every face)
    /// before any reflected light was shot.
    pub fn reflecting_area(
        &self,
        area: impl Fn(FaceId) -> f64,
        fallback: Spectrum<N>,
    ) -> Spectrum<N> {
        let mut sum = Spectrum::<N>::zero();
        let mut weighted = Spectrum::<N>::zero();
        for (face, (h, r)) in self.faces.iter() {
            let a = area(face);
            if a <= 0.0 {
                continue;
            }
            sum += *r;
            weighted += *r * *h * (1.0 / a);
        }
        Spectrum::new(std::array::from_fn(|b| {
            if weighted[b] > 0.0 {
                sum[b] * sum[b] / weighted[b]
            } else {
                fallback[b]
            }
        }))
    }

    /// The stats' account of the remainder for residual `residual` and
    /// reflecting area `area`: the return fraction and future reflected
    /// flux that CR is made of, and the ambient radiance, which spreads
    /// the future light at the *measured* return (none until a shot of
    /// reflected light has measured it).
    pub fn ambient(
        &self,
        residual: Spectrum<N>,
        emission: Spectrum<N>,
        area: Spectrum<N>,
    ) -> Ambient {
        let a = self
            .return_fraction(reflected_part(residual, emission))
            .unwrap_or_else(Spectrum::zero);
        let future: Vec<f64> = (0..N)
            .map(|b| self.future_of(residual[b], emission[b], a[b], b))
            .collect();
        // The term adds light to every lit face, so it spreads the future
        // light at the measured return (returned / shot), without the
        // prior: where the shots say little comes back (the classroom's
        // sky-lit ground) the prior would add it anyway (results.md,
        // "Real interiors"). Before a shot of reflected light the measured
        // return is 0, and so is the term: the closed-scene guess could add
        // far too much light to an open scene.
        let radiance = (0..N)
            .map(|b| {
                let measured = ratio(self.returned[b], self.shot[b]);
                ambient_radiance(future_reflected(residual[b], measured), area[b])
            })
            .collect();
        Ambient {
            radiance,
            share: 1.0 - self.convergence_ratio(residual, emission),
            return_fraction: a.to_array().to_vec(),
            reflected_flux: self.reflected.to_array().to_vec(),
            future_reflected_flux: future,
            unshot_emission_flux: emission.to_array().to_vec(),
            first_reflectance: (0..N).map(|b| self.prior(b)).collect(),
            reflecting_area: area.to_array().to_vec(),
        }
    }
}

/// The residual less the emitted light in it, per band, not negative.
fn reflected_part<const N: usize>(residual: Spectrum<N>, emission: Spectrum<N>) -> Spectrum<N> {
    Spectrum::new(std::array::from_fn(|b| {
        (residual[b] - emission[b]).max(0.0)
    }))
}

/// n / d, 0 when d is not positive.
fn ratio(n: f64, d: f64) -> f64 {
    if d > 0.0 {
        (n / d).clamp(0.0, 1.0)
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use trilux_geometry::{Side, SurfaceId};

    /// An ideal enclosure: patches i of area A_i with F_ij = A_j / A
    /// (every patch sees every patch in proportion to its area, itself
    /// included), uniform reflectance ρ, emission on patch 0. Progressive
    /// shooting for a few shots, then the stopped radiosity plus ρ times
    /// the ambient term must equal the exact solution B = Le + ρ H with
    /// H = Σ Le A / (A (1 − ρ)).
    #[test]
    fn the_ambient_term_makes_a_stopped_uniform_enclosure_exact() {
        let areas = [1.0, 2.0, 0.5, 3.0, 1.5];
        let total: f64 = areas.iter().sum();
        let (rho, le) = (0.7, 10.0);
        // Exact: every patch receives the same irradiance H (radiance
        // units); L = ρ H reflected.
        let h = le * areas[0] / (total * (1.0 - rho));
        for shots in [1usize, 2, 3, 7] {
            let mut reflected = vec![0.0; areas.len()];
            let mut unshot = vec![0.0; areas.len()];
            unshot[0] = le;
            let mut tracker = Interreflection::<1>::new(areas.len());
            let mut emission_left = le * PI * areas[0];
            for _ in 0..shots {
                // Shoot the patch with the most unshot flux.
                let s = (0..areas.len())
                    .max_by(|&a, &b| (unshot[a] * areas[a]).total_cmp(&(unshot[b] * areas[b])))
                    .unwrap();
                let phi = unshot[s] * PI * areas[s];
                let share = Interreflection::reflected_share(
                    Spectrum::splat(phi),
                    Spectrum::splat(std::mem::take(&mut emission_left)),
                );
                tracker.book_shot(Spectrum::splat(phi), share);
                let irradiance = unshot[s] * areas[s] / total;
                unshot[s] = 0.0;
                for (i, &a) in areas.iter().enumerate() {
                    let arrived = irradiance * PI * a;
                    reflected[i] += rho * irradiance;
                    unshot[i] += rho * irradiance;
                    let face = FaceId::new(SurfaceId(i as u32), Side::Front);
                    tracker.book_group(
                        face,
                        Spectrum::splat(arrived),
                        Spectrum::splat(rho * arrived),
                        share,
                    );
                }
            }
            let residual: f64 = (0..areas.len()).map(|i| unshot[i] * PI * areas[i]).sum();
            let area_of = |f: FaceId| match f.side() {
                Side::Front => areas[f.surface().index()],
                Side::Back => 0.0,
            };
            let s = tracker.reflecting_area(area_of, Spectrum::splat(rho * total));
            let amb = tracker.ambient(Spectrum::splat(residual), Spectrum::zero(), s);
            // The paper's CR and this one agree in a closed uniform scene.
            let emitted = le * PI * areas[0];
            let paper = (emitted - residual) / emitted;
            let cr = tracker.convergence_ratio(Spectrum::splat(residual), Spectrum::zero());
            assert!(
                (cr - paper).abs() <= 1e-9,
                "{shots} shots: CR {cr} against the paper's {paper}"
            );
            if shots == 1 {
                // Only the emitter shot: a is not measured, no ambient.
                assert_eq!(amb.radiance[0], 0.0);
                continue;
            }
            for (i, l) in reflected.iter().enumerate() {
                let stopped = l + rho * amb.radiance[0];
                assert!(
                    (stopped - rho * h).abs() <= 1e-9 * rho * h,
                    "{shots} shots, patch {i}: {stopped} against exact {}",
                    rho * h
                );
            }
        }
    }

    /// An open scene: every reflected shot loses half its flux through an
    /// opening, so the remainder is RF · a / (1 − a) with a = ρ / 2, and
    /// CR is lower than the paper's (IF − RF)/IF, which counts the lost
    /// light as converged.
    #[test]
    fn light_that_leaves_is_not_counted_as_converged() {
        let (rho, keep) = (0.6, 0.5);
        let mut t = Interreflection::<1>::new(1);
        let face = FaceId::new(SurfaceId(0), Side::Front);
        // The emitter's shot: 1 W, 0.3 of it arrives.
        let one = Spectrum::splat(1.0);
        t.book_shot(one, Interreflection::reflected_share(one, one));
        t.book_group(
            face,
            Spectrum::splat(0.3),
            Spectrum::splat(0.3 * rho),
            Spectrum::zero(),
        );
        // One reflected shot of the 0.18 W.
        let phi = 0.3 * rho;
        let share = Interreflection::reflected_share(Spectrum::splat(phi), Spectrum::zero());
        t.book_shot(Spectrum::splat(phi), share);
        let arrived = phi * keep;
        t.book_group(
            face,
            Spectrum::splat(arrived),
            Spectrum::splat(arrived * rho),
            share,
        );
        // With nothing left to shoot a is the measured return; with the
        // residual RF left, RF counts as returning the prior (the lit
        // face's reflectance ρ) until it is shot.
        let measured = t.return_fraction(Spectrum::zero()).unwrap()[0];
        assert!((measured - rho * keep).abs() < 1e-12);
        let residual = arrived * rho;
        let a = t.return_fraction(Spectrum::splat(residual)).unwrap()[0];
        let want = (phi * rho * keep + rho * residual) / (phi + residual);
        assert!((a - want).abs() < 1e-12, "a {a}, want {want}");
        let future = residual * a / (1.0 - a);
        let reflected = 0.3 * rho + arrived * rho;
        let cr = t.convergence_ratio(Spectrum::splat(residual), Spectrum::zero());
        assert!((cr - reflected / (reflected + future)).abs() < 1e-12);
        let paper = 1.0 - residual;
        assert!(cr < paper, "CR {cr} should be below the paper's {paper}");
    }

    /// A closed room of reflectance ½: the lamp's 1 W all arrives and
    /// 0.5 W is reflected; the first reflected shot, 0.1 W from a face in
    /// front of the black lamp, brings back 5 %. That one shot does not
    /// speak for the 0.4 W still unshot: measured alone (a = 0.05) it made
    /// CR 0.96, past a draft target of 0.95, with most of the
    /// interreflection still to come (the bathroom, results.md).
    #[test]
    fn one_shot_into_a_black_lamp_does_not_converge_the_room() {
        let (mut t, face) = lamp_shot_onto_one_half_grey_face();
        let phi = Spectrum::splat(0.1);
        let share = Interreflection::reflected_share(phi, Spectrum::zero());
        t.book_shot(phi, share);
        t.book_group(face, phi, Spectrum::splat(0.005), share);
        let residual = Spectrum::splat(0.4);
        // The prior: reflected over arrived on reflecting faces, 0.505 /
        // 1.1; a = (0.005 + prior · 0.4) / (0.1 + 0.4) ≈ 0.377.
        let prior = 0.505 / 1.1;
        let want_a = (0.005 + prior * 0.4) / 0.5;
        let a = t.return_fraction(residual).unwrap()[0];
        assert!((a - want_a).abs() < 1e-12, "a {a}, want {want_a}");
        let cr = t.convergence_ratio(residual, Spectrum::zero());
        let want = 0.505 / (0.505 + 0.4 * want_a / (1.0 - want_a));
        assert!((cr - want).abs() < 1e-12, "CR {cr}, want {want}");
        assert!(cr < 0.95);
        // The ambient term spreads what the shots measured (a = 0.05),
        // not the prior: it adds light everywhere. Over S = 1 m²:
        let amb = t.ambient(residual, Spectrum::zero(), Spectrum::splat(1.0));
        let want = 0.4 * 0.05 / 0.95 / std::f64::consts::PI;
        let got = amb.radiance[0];
        assert!((got - want).abs() < 1e-12, "A_amb {got}, want {want}");
        // The stats' remainder is CR's.
        let future = amb.future_reflected_flux[0];
        let want = 0.4 * want_a / (1.0 - want_a);
        assert!(
            (future - want).abs() < 1e-12,
            "future {future}, want {want}"
        );
    }

    #[test]
    fn nothing_arrived_yet_is_not_converged() {
        let t = Interreflection::<3>::new(2);
        let none = Spectrum::zero();
        assert_eq!(t.convergence_ratio(Spectrum::splat(1.0), none), 0.0);
        assert_eq!(t.convergence_ratio(none, none), 1.0);
    }

    /// An open scene whose reflected light all leaves (a = 0): lamp A's
    /// 1 W arrives on a face of reflectance ½ and is reflected once, 0.5
    /// W; lamp B's 0.1 W, not shot yet, will land the same way and be
    /// reflected once, 0.05 W, and nothing after: CR = 0.5 / 0.55. Taken
    /// as reflected light (returning a, about 0 here) it would count for
    /// almost nothing (CR 0.98: the sky box's sides left unshot).
    #[test]
    fn unshot_emission_counts_as_light_still_to_be_reflected_once() {
        let (mut t, _) = lamp_shot_onto_one_half_grey_face();
        let phi = Spectrum::splat(0.5);
        t.book_shot(phi, Interreflection::reflected_share(phi, Spectrum::zero()));
        let lamp = Spectrum::splat(0.1);
        let cr = t.convergence_ratio(lamp, lamp);
        let want = 0.5 / 0.55;
        assert!((cr - want).abs() < 1e-12, "CR {cr}, want {want}");
        assert!(t.convergence_ratio(lamp, Spectrum::zero()) > 0.98);
    }

    /// A lamp's 1 W shot, all of it arriving on one face that reflects
    /// half: the start of the two tests above.
    fn lamp_shot_onto_one_half_grey_face() -> (Interreflection<1>, FaceId) {
        let mut t = Interreflection::<1>::new(1);
        let face = FaceId::new(SurfaceId(0), Side::Front);
        let one = Spectrum::splat(1.0);
        t.book_shot(one, Interreflection::reflected_share(one, one));
        t.book_group(face, one, Spectrum::splat(0.5), Spectrum::zero());
        (t, face)
    }
}
