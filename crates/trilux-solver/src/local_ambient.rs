//! The light the residual will still bring, where it will bring it
//! (docs/solver.md, "The residual's later bounces"): the unshot radiance
//! δL left when the solve stops, bounced over the final gather's links
//! until it has died out.
//!
//! Cohen's ambient term (`ambient`) spreads that future light evenly over
//! the lit reflecting area. A room lit through its windows by a sky box
//! holds a few watts of a hundred thousand, and most of that area is the
//! sky-lit ground outside: spread evenly, the room's own future light all
//! but vanishes, and the classroom stopped at CR 0.95 rendered 0.92 of
//! Mitsuba's mean (results.md, "Real interiors").
//!
//! The final gather's links already hold, for every receiving element, the
//! senders it sees and their visible fractions. Each bounce gathers over
//! them, as the render's gather does (a leaf takes its own links and its
//! ancestors'),
//!
//!   I_e = Σ_links F_es V_es S_s,
//!
//! with S the radiance the senders send in this bounce (δL for the first)
//! and F the pair's form factor (`form_factor`: exact from the smaller
//! element's middle for near pairs, point-to-disc for far ones); the
//! next bounce sends
//! S_e = ρ_e I_e, pulled up the element trees by exposed area. The sum of
//! the I over the bounces is what a Lambertian element of reflectance ρ
//! adds ρ times. Glossy senders (links to stored nodes) send their face's
//! unshot light spread evenly over it, then their glossy albedo times the
//! face's mean I. The render's gather reads the senders' L, which holds δL,
//! so δL's first bounce is in the image already; this term is the bounce
//! after it and every later one, which is what Cohen's term stands for.
//! In a closed enclosure of uniform reflectance ρ with F_ij = A_j / A the
//! two agree.

use glam::DVec2;
use rayon::prelude::*;
use trilux_color::Spectrum;
use trilux_geometry::{
    ElementForest, ElementId, FaceElement, FaceId, PerFace, PointFormFactors, Side, Sided,
    SurfaceId,
};

use crate::gather_links::{GatherLinks, LinkSource};
use crate::refine::disc_facing;
use crate::setup::Setup;
use crate::state::ShotState;

/// Pairs whose centres are closer than √NEAR times the larger element's
/// size take the exact point form factor (`form_factor`).
const NEAR: f64 = 4.0;

/// The most bounces summed.
const MAX_BOUNCES: usize = 64;

/// The bounces stop once one sends less than this share of the light all
/// the bounces so far brought.
const STOP_SHARE: f64 = 1e-3;

/// Per side and element, Σ I over the bounces (module docs): the radiance
/// a Lambertian element of reflectance ρ sends ρ times more.
pub(crate) fn future_irradiance<const N: usize>(
    setup: &Setup<N>,
    state: &ShotState<N>,
    links: &GatherLinks,
) -> Sided<Vec<Spectrum<N>>> {
    let forest = setup.forest();
    let plan = Plan::new(setup, links);
    let mut total = Sided::from_fn(|_| vec![Spectrum::<N>::zero(); forest.element_count()]);
    let mut sending = Sending {
        element: state.field.unshot.clone(),
        glossy: glossy_unshot_radiance(setup, state),
    };
    let (mut brought, mut last) = (0.0, f64::INFINITY);
    for _ in 0..MAX_BOUNCES {
        let incident = plan.bounce(&sending);
        let flux = plan.flux(&incident);
        // Reflectances below 1 and weights capped at 1 make every bounce
        // smaller than the last; a larger one means estimates that do not
        // conserve light, and the series is cut there.
        if !(flux.is_finite() && flux <= last) {
            break;
        }
        last = flux;
        for side in Side::BOTH {
            for (t, i) in total[side].iter_mut().zip(&incident[side]) {
                *t += *i;
            }
        }
        brought += flux;
        if flux <= STOP_SHARE * brought {
            break;
        }
        sending = plan.reflect(&incident);
    }
    total
}

/// What senders send in one bounce.
struct Sending<const N: usize> {
    /// Per side and element (Lambertian parts, pulled up the trees).
    element: Sided<Vec<Spectrum<N>>>,
    /// Per face: the glossy part, even over the face.
    glossy: PerFace<Spectrum<N>>,
}

/// One link as the bounces read it.
#[derive(Clone, Copy)]
struct Weighted {
    /// F V of the pair.
    weight: f64,
    sender: FaceElement,
    /// A stored node's face (its glossy part), else `None`.
    glossy: Option<FaceId>,
}

/// The links with their weights, and what reflection reads.
struct Plan<'a, const N: usize> {
    setup: &'a Setup<N>,
    forest: &'a ElementForest,
    /// Row starts by receiver key, as in [`GatherLinks`].
    offsets: &'a [u32],
    links: Vec<Weighted>,
    /// Per receiver key: Σ F V of its row.
    coverage: Vec<f64>,
    /// Per side and element: ρ_d (a textured element its own).
    rho: Sided<Vec<Spectrum<N>>>,
    /// Per face: the glossy part's albedo (hemisphere mean).
    glossy_albedo: PerFace<Spectrum<N>>,
}

impl<'a, const N: usize> Plan<'a, N> {
    fn new(setup: &'a Setup<N>, links: &'a GatherLinks) -> Self {
        let forest = setup.forest();
        let (offsets, raw) = links.raw();
        let points = &PointFormFactors::new(forest);
        let weighted: Vec<Weighted> = (0..offsets.len().saturating_sub(1))
            .into_par_iter()
            .flat_map_iter(|k| {
                let recv = receiver(k);
                raw[offsets[k] as usize..offsets[k + 1] as usize]
                    .iter()
                    .map(move |l| {
                        let sender = FaceElement::new(l.sender, l.sender_face.side());
                        let f = form_factor(setup, points, recv, sender);
                        let weight = f * f64::from(l.visibility);
                        Weighted {
                            weight: if weight.is_finite() {
                                weight.max(0.0)
                            } else {
                                0.0
                            },
                            sender,
                            glossy: match l.source {
                                LinkSource::Face(_) => None,
                                LinkSource::Node { .. } => Some(l.sender_face),
                            },
                        }
                    })
            })
            .collect();
        let scene = &setup.scene;
        // Per material once (each is a hemisphere integral), then per face.
        let by_material: Vec<[Spectrum<N>; 2]> = scene
            .materials()
            .iter()
            .map(crate::solution::glossy_albedo)
            .collect();
        let glossy_albedo = PerFace::from_fn(forest.geometry().surfaces().len(), |face| {
            let shape = forest.geometry().surface(face.surface()).shape as usize;
            let side = usize::from(face.side() == Side::Back);
            by_material.get(shape).map_or(Spectrum::zero(), |a| a[side])
        });
        let mut plan = Plan {
            setup,
            forest,
            offsets,
            links: weighted,
            coverage: Vec::new(),
            rho: element_reflectance(setup),
            glossy_albedo,
        };
        plan.coverage = (0..offsets.len().saturating_sub(1))
            .map(|k| plan.row(k).iter().map(|l| l.weight).sum())
            .collect();
        // Keys past the rows (elements no link reaches) read 0.
        plan.coverage.resize(2 * forest.element_count(), 0.0);
        plan
    }

    /// One bounce: every receiving element gathers over its links, then
    /// the sums go down the trees (a leaf has its ancestors' too) and the
    /// leaves' are pulled up by exposed area.
    fn bounce(&self, s: &Sending<N>) -> Sided<Vec<Spectrum<N>>> {
        let gathered: Vec<Spectrum<N>> = (0..self.offsets.len().saturating_sub(1))
            .into_par_iter()
            .map(|k| {
                self.row(k)
                    .iter()
                    .map(|l| {
                        let sent = match l.glossy {
                            Some(face) => s.glossy[face],
                            None => s.element[l.sender.side][l.sender.element.index()],
                        };
                        sent * l.weight
                    })
                    .sum()
            })
            .collect();
        let elements = self.forest.element_count();
        let mut out = Sided::from_fn(|_| vec![Spectrum::zero(); elements]);
        for surface in 0..self.forest.geometry().surfaces().len() as u32 {
            let root = self.forest.root(SurfaceId(surface));
            for side in Side::BOTH {
                let top = (Spectrum::zero(), 0.0);
                self.down_up(root, side, top, &gathered, &mut out[side]);
            }
        }
        out
    }

    fn row(&self, k: usize) -> &[Weighted] {
        &self.links[self.offsets[k] as usize..self.offsets[k + 1] as usize]
    }

    /// Writes the sums from above plus the element's own on the leaves
    /// under `e`, and their exposed-area means on the elements above them;
    /// returns `e`'s. `above` carries the gathered light and the weights
    /// Σ F V over the ancestors: a leaf whose weights pass 1
    /// (point-to-disc estimates of near pairs overlap) is scaled back to 1,
    /// so that no bounce brings more than its senders send.
    fn down_up(
        &self,
        e: ElementId,
        side: Side,
        above: (Spectrum<N>, f64),
        gathered: &[Spectrum<N>],
        out: &mut [Spectrum<N>],
    ) -> Spectrum<N> {
        let key = FaceElement::new(e, side).key() as usize;
        let own = gathered.get(key).copied().unwrap_or_else(Spectrum::zero);
        let here = (above.0 + own, above.1 + self.coverage[key]);
        let value = match self.forest.element(e).children() {
            None => here.0 * (1.0 / here.1.max(1.0)),
            Some(children) => {
                let exposed = &self.setup.exposed_area[side];
                let (mut sum, mut area) = (Spectrum::zero(), 0.0);
                for c in children {
                    let v = self.down_up(c, side, here, gathered, out);
                    sum += v * exposed[c.index()];
                    area += exposed[c.index()];
                }
                if area > 0.0 {
                    sum * (1.0 / area)
                } else {
                    here.0 * (1.0 / here.1.max(1.0))
                }
            }
        };
        out[e.index()] = value;
        value
    }

    /// What the receivers send in the next bounce: ρ I per element
    /// (textured elements their own ρ_d), the glossy parts their albedo
    /// times the face's mean.
    fn reflect(&self, incident: &Sided<Vec<Spectrum<N>>>) -> Sending<N> {
        let forest = self.forest;
        let element = Sided::from_fn(|side| {
            incident[side]
                .iter()
                .zip(&self.rho[side])
                .map(|(i, r)| *i * *r)
                .collect()
        });
        let glossy = PerFace::from_fn(forest.geometry().surfaces().len(), |face| {
            let root = forest.root(face.surface());
            self.glossy_albedo[face] * incident[face.side()][root.index()]
        });
        Sending { element, glossy }
    }

    /// Flux of one bounce's incident light over every face (band sum).
    fn flux(&self, incident: &Sided<Vec<Spectrum<N>>>) -> f64 {
        let forest = self.forest;
        (0..forest.geometry().surfaces().len() as u32)
            .flat_map(|s| Side::BOTH.map(|side| (s, side)))
            .map(|(s, side)| {
                let root = forest.root(SurfaceId(s)).index();
                incident[side][root].sum() * self.setup.exposed_area[side][root]
            })
            .sum()
    }
}

/// ρ_d of every element and side: its face's, or a textured element's own
/// (`crate::textures`).
fn element_reflectance<const N: usize>(setup: &Setup<N>) -> Sided<Vec<Spectrum<N>>> {
    let forest = setup.forest();
    Sided::from_fn(|side| {
        (0..forest.element_count() as u32)
            .map(|e| {
                let e = ElementId(e);
                let face = FaceId::new(forest.element(e).surface, side);
                setup
                    .textures
                    .as_ref()
                    .and_then(|t| t.rho(face, e))
                    .unwrap_or(setup.faces[face].rho_d)
            })
            .collect()
    })
}

/// The receiving face element of row `k` (`FaceElement::key`'s inverse).
fn receiver(k: usize) -> FaceElement {
    FaceElement::new(ElementId((k / 2) as u32), Side::from_back(k % 2 == 1))
}

/// F from the receiving element to the sender: the exact point form
/// factor (Lambert's closed form over the other element's polygons) from
/// the middle of the smaller of the two, turned by reciprocity
/// (A_r F_rs = A_s F_sr) when that is the sender. From the middle of a
/// large receiver, a small sender just below part of it (a light fitting
/// under a ceiling) is seen edge-on and counts for nothing; from the
/// sender's middle the receiver fills its hemisphere.
fn form_factor<const N: usize>(
    setup: &Setup<N>,
    points: &PointFormFactors,
    recv: FaceElement,
    send: FaceElement,
) -> f64 {
    let forest = setup.forest();
    let (ar, as_) = (
        setup.exposed_area[recv.side][recv.element.index()],
        setup.exposed_area[send.side][send.element.index()],
    );
    if ar <= 0.0 || as_ <= 0.0 {
        return 0.0;
    }
    // Far apart (centres more than twice the larger element's size), the
    // point-to-disc estimate from centre to centre is close enough, and
    // most links are far.
    let (er, es) = (forest.element(recv.element), forest.element(send.element));
    if (es.centre - er.centre).length_squared() > NEAR * ar.max(as_) {
        return disc_form_factor(setup, recv, send);
    }
    let from = |e: FaceElement, to: FaceElement| {
        let x = forest.sample_element(e.element, DVec2::splat(0.5));
        points.eval(x.point, x.normal * e.side.sign(), to)
    };
    if ar <= as_ {
        from(recv, send)
    } else {
        (from(send, recv) * as_ / ar).min(1.0)
    }
}

/// The point-to-disc form factor from centre to centre (the sender's
/// exposed area), zero where the centres do not face each other
/// (refinement's estimate takes both cosines as 1 there, a bound, which
/// here would count coplanar neighbours).
fn disc_form_factor<const N: usize>(setup: &Setup<N>, recv: FaceElement, send: FaceElement) -> f64 {
    let forest = setup.forest();
    let (er, es) = (forest.element(recv.element), forest.element(send.element));
    let area = setup.exposed_area[send.side][send.element.index()];
    let (nr, ns) = (er.normal * recv.side.sign(), es.normal * send.side.sign());
    disc_facing(er.centre, nr, es.centre, ns, area).unwrap_or(0.0)
}

/// Per face, the unshot light of its stored (glossy) transport as a
/// radiance spread evenly over the face: its hierarchies', far field's
/// and waiting light's unshot flux over π times its exposed area.
fn glossy_unshot_radiance<const N: usize>(
    setup: &Setup<N>,
    state: &ShotState<N>,
) -> PerFace<Spectrum<N>> {
    let forest = setup.forest();
    let surfaces = forest.geometry().surfaces().len();
    let mut flux = PerFace::from_fn(surfaces, |_| Spectrum::<N>::zero());
    for h in state.hierarchies.iter().flatten() {
        flux[h.from] += h.unshot_flux;
    }
    for f in state.far.values().flatten() {
        flux[f.face] += f.unshot_flux;
    }
    for (face, room) in state.deferred.room.iter() {
        flux[face] += *room;
    }
    PerFace::from_fn(surfaces, |face| {
        let a = setup.exposed_area[face.side()][forest.root(face.surface()).index()];
        if a > 0.0 {
            flux[face] * (1.0 / (std::f64::consts::PI * a))
        } else {
            Spectrum::zero()
        }
    })
}
