//! Area reflectance R(I→J→K) and the BRDF variation estimate over three
//! elements (paper Eq. 5; docs/solver.md, "Area reflectance").
//!
//! Light leaves element I, reflects on element J and leaves towards element
//! K. With the radiance coefficient (the paper's printed integral
//! normalises by ∫∫G, a flux ratio; docs/solver.md, "Area reflectance",
//! explains the correction):
//!
//!   R(I→J→K) ≈ π · F_{J→I} · fr(I→J→K),
//!
//! fr evaluated at J's centre for the directions towards I's centre (light,
//! `wi`) and K's centre (viewer, `wo`), in J's local frame. The visibility
//! V_{J→I} is the caller's (the solver caches F·V per interaction).
//!
//! The Lambertian part is an exact constant: π F_JI ρ_d/π = ρ_d F_JI,
//! independent of K (it needs no per-receiver interactions: docs/architecture.md, "Two-point
//! and stored transport").
//! Only the glossy part varies over the elements, and only it is sampled by
//! [`brdf_variation`].

use glam::DVec3;
use trilux_color::Spectrum;

use crate::bsdf::Bsdf;
use crate::frame::{Frame, reflect};
use trilux_frame::Side;

/// An element seen as points: what the BRDF variation estimate needs.
#[derive(Clone, Copy, Debug)]
pub struct ElementPoints<'a> {
    /// A representative point (the element's centre).
    pub centre: DVec3,
    /// The element's front normal (unit).
    pub normal: DVec3,
    /// Sample points over the element (for example its corners and centre,
    /// as `trilux_geometry`'s `element_points` gives them).
    pub points: &'a [DVec3],
}

/// R(I→J→K) split into its Lambertian and glossy parts.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AreaReflectance<const N: usize> {
    /// ρ_d · F_JI (0 if I or K is behind J's reflecting side).
    pub diffuse: Spectrum<N>,
    /// π · F_JI · fr_glossy(I→J→K).
    pub glossy: Spectrum<N>,
}

impl<const N: usize> AreaReflectance<N> {
    /// The whole R.
    pub fn total(&self) -> Spectrum<N> {
        self.diffuse + self.glossy
    }
}

/// The reflecting side of J for light from `to_i` towards `to_k` (world
/// directions from J), or `None` if they are on opposite sides.
pub(crate) fn reflecting_side(j_normal: DVec3, to_i: DVec3, to_k: DVec3) -> Option<Side> {
    let (a, b) = (to_i.dot(j_normal), to_k.dot(j_normal));
    if a > 0.0 && b > 0.0 {
        Some(Side::Front)
    } else if a < 0.0 && b < 0.0 {
        Some(Side::Back)
    } else {
        None
    }
}

/// R(I→J→K) = π F_{J→I} fr(I→J→K) (paper Eq. 5, corrected normalisation),
/// with fr at `j_centre` for the directions to `i_centre` and `k_centre`.
/// `ff_ji` is the form factor from J to I (times visibility if wanted).
pub fn area_reflectance<const N: usize>(
    bsdf: &Bsdf<N>,
    ff_ji: f64,
    i_centre: DVec3,
    j_centre: DVec3,
    j_normal: DVec3,
    k_centre: DVec3,
) -> AreaReflectance<N> {
    let zero = AreaReflectance {
        diffuse: Spectrum::zero(),
        glossy: Spectrum::zero(),
    };
    let to_i = (i_centre - j_centre).normalize();
    let to_k = (k_centre - j_centre).normalize();
    if !(to_i.is_finite() && to_k.is_finite() && ff_ji.is_finite() && ff_ji > 0.0) {
        return zero;
    }
    let Some(side) = reflecting_side(j_normal, to_i, to_k) else {
        return zero;
    };
    let frame = Frame::from_normal(j_normal);
    let glossy = if bsdf.has_glossy(side) {
        bsdf.eval_glossy(frame.to_local(to_i), frame.to_local(to_k))
            * (std::f64::consts::PI * ff_ji)
    } else {
        Spectrum::zero()
    };
    AreaReflectance {
        diffuse: bsdf.diffuse_albedo(side) * ff_ji,
        glossy,
    }
}

/// Which of the three elements a variation is attributed to.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Element {
    /// The sender I.
    I,
    /// The reflector J.
    J,
    /// The receiver K.
    K,
}

/// The spread of the glossy fr over three elements (docs/solver.md, "Refinement").
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BrdfVariation<const N: usize> {
    /// Band-wise minimum of the sampled glossy fr.
    pub fr_min: Spectrum<N>,
    /// Band-wise maximum of the sampled glossy fr.
    pub fr_max: Spectrum<N>,
    /// Spread (max − min of the largest band) when only I's points vary.
    pub spread_i: f64,
    /// Spread when only J's points vary.
    pub spread_j: f64,
    /// Spread when only K's points vary (including the mirror direction).
    pub spread_k: f64,
    /// True when the mirror direction of I's centre about J falls inside
    /// K's cone of directions (and fr was evaluated there).
    pub mirror_in_k: bool,
    /// Number of fr evaluations made.
    pub evaluations: u32,
}

impl<const N: usize> BrdfVariation<N> {
    /// ΔR ≈ π F_JI (fr_max − fr_min), the largest band: the BRDF error
    /// FrErr compares against (docs/solver.md, "Refinement").
    pub fn delta_r(&self, ff_ji: f64) -> f64 {
        std::f64::consts::PI * ff_ji * (self.fr_max - self.fr_min).max_value().max(0.0)
    }

    /// The element whose points make fr vary most: the one to split.
    pub fn driver(&self) -> Element {
        if self.spread_i >= self.spread_j && self.spread_i >= self.spread_k {
            Element::I
        } else if self.spread_j >= self.spread_k {
            Element::J
        } else {
            Element::K
        }
    }
}

/// Estimates the spread of the glossy fr over I, J and K (docs/solver.md, "Refinement"):
/// fr at J for directions from I's points to K's points, varying one element
/// at a time around the three centres, plus the mirror direction of I's
/// centre about J when it falls inside K (a narrow lobe between K's points
/// would otherwise be missed). J's normal is used at every point of J. The
/// Lambertian part is constant and left out: a purely Lambertian J gives zero
/// spread at no cost.
pub fn brdf_variation<const N: usize>(
    bsdf: &Bsdf<N>,
    i: &ElementPoints<'_>,
    j: &ElementPoints<'_>,
    k: &ElementPoints<'_>,
) -> BrdfVariation<N> {
    let mut v = BrdfVariation {
        fr_min: Spectrum::splat(f64::INFINITY),
        fr_max: Spectrum::splat(f64::NEG_INFINITY),
        spread_i: 0.0,
        spread_j: 0.0,
        spread_k: 0.0,
        mirror_in_k: false,
        evaluations: 0,
    };
    let side_c = reflecting_side(j.normal, i.centre - j.centre, k.centre - j.centre);
    let glossy = match side_c {
        Some(s) => bsdf.has_glossy(s),
        None => bsdf.has_glossy(Side::Front) || bsdf.has_glossy(Side::Back),
    };
    if !glossy {
        v.fr_min = Spectrum::zero();
        v.fr_max = Spectrum::zero();
        return v;
    }
    let frame = Frame::from_normal(j.normal);
    let eval = |xi: DVec3, xj: DVec3, xk: DVec3, evals: &mut u32| -> Spectrum<N> {
        *evals += 1;
        let wi = (xi - xj).normalize();
        let wo = (xk - xj).normalize();
        if !(wi.is_finite() && wo.is_finite()) {
            return Spectrum::zero();
        }
        bsdf.eval_glossy(frame.to_local(wi), frame.to_local(wo))
    };
    let mut evals = 0u32;
    let spread = |vals: &[Spectrum<N>]| -> (Spectrum<N>, Spectrum<N>, f64) {
        let mut lo = Spectrum::splat(f64::INFINITY);
        let mut hi = Spectrum::splat(f64::NEG_INFINITY);
        for s in vals {
            lo = lo.min(*s);
            hi = hi.max(*s);
        }
        (lo, hi, (hi - lo).max_value())
    };
    let centre = eval(i.centre, j.centre, k.centre, &mut evals);
    let mut vi = vec![centre];
    vi.extend(
        i.points
            .iter()
            .map(|&p| eval(p, j.centre, k.centre, &mut evals)),
    );
    let mut vj = vec![centre];
    vj.extend(
        j.points
            .iter()
            .map(|&p| eval(i.centre, p, k.centre, &mut evals)),
    );
    let mut vk = vec![centre];
    vk.extend(
        k.points
            .iter()
            .map(|&p| eval(i.centre, j.centre, p, &mut evals)),
    );
    // The mirror direction: inside K's cone of directions from J's centre?
    let to_i = (i.centre - j.centre).normalize();
    let to_kc = (k.centre - j.centre).normalize();
    if to_i.is_finite() && to_kc.is_finite() {
        let mirror = reflect(to_i, j.normal);
        let cone_cos = k
            .points
            .iter()
            .filter_map(|&p| {
                let d = (p - j.centre).normalize();
                d.is_finite().then(|| d.dot(to_kc))
            })
            .fold(1.0f64, f64::min);
        if mirror.dot(to_kc) >= cone_cos {
            v.mirror_in_k = true;
            evals += 1;
            vk.push(bsdf.eval_glossy(frame.to_local(to_i), frame.to_local(mirror)));
        }
    }
    let (a_lo, a_hi, si) = spread(&vi);
    let (b_lo, b_hi, sj) = spread(&vj);
    let (c_lo, c_hi, sk) = spread(&vk);
    v.fr_min = a_lo.min(b_lo).min(c_lo);
    v.fr_max = a_hi.max(b_hi).max(c_hi);
    v.spread_i = si;
    v.spread_j = sj;
    v.spread_k = sk;
    v.evaluations = evals;
    v
}

/// The angular width, in radians, of the glossy lobe of one side of a
/// material: 2·atan(α) for a microfacet part of roughness α (the reflected
/// directions spread about twice as far as the microfacet normals),
/// `None` for a side without a glossy part. The width decides how a
/// three-point link's area reflectance is estimated ([`is_narrow`]).
pub fn lobe_width<const N: usize>(bsdf: &Bsdf<N>, side: Side) -> Option<f64> {
    if !bsdf.has_glossy(side) {
        return None;
    }
    bsdf.min_alpha(side).map(|a| 2.0 * a.max(0.0).atan())
}

/// The rule that chooses the estimate of a glossy area reflectance
/// (docs/solver.md, "Narrow lobes"): a lobe of angular width `width` is
/// *narrow* against a receiver of angular radius `angular_radius` (both in
/// radians, as seen from J's centre) when it is narrower than an eighth of
/// that radius. The midpoint rule evaluates fr at K's quadrant centres,
/// about one angular radius apart, and refinement by the BRDF variation
/// halves that spacing at each split of K: a lobe narrower than the
/// spacing two splits further down is one the BRDF criterion would chase
/// through several levels (to the leaves, for a mirror), and is estimated
/// by sampling it ([`sample_glossy_lobe`]) instead. (With a quarter or a
/// half of the radius, lobes of α = 0.12–0.25 were sampled over the largest
/// receivers, where the sampled links then stayed coarser than the BRDF
/// criterion had made them: five golden images got slightly worse, by up
/// to 0.0023 of relative RMSE.)
pub fn is_narrow(width: f64, angular_radius: f64) -> bool {
    width < 0.125 * angular_radius
}

/// One direction of a sampled glossy lobe and the share of the reflected
/// light it carries.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LobeSample<const N: usize> {
    /// The outgoing direction (the BSDF's local frame).
    pub wo: DVec3,
    /// The glossy albedo's share that leaves along `wo`: non-negative, and
    /// the shares of one call sum to at most `glossy_albedo` per band.
    pub share: Spectrum<N>,
}

/// Samples the glossy lobe of `bsdf` for light arriving from `wi` (local
/// frame, either side) on a `grid` × `grid` stratified grid, appending one
/// [`LobeSample`] per sample that leaves on wi's side, scaled by `scale`.
///
/// The samples say *where* the light goes (importance sampling of the
/// BSDF, each weighted by fr_glossy cos / pdf); `glossy_albedo` (the
/// material's directional albedo less its Lambertian part, e.g. from an
/// `AlbedoTable`) says *how much*: the weights are normalised to sum to it.
/// Counting the shares that land in a receiver K therefore estimates
/// ∫_{Ω_K} fr_glossy cos dω (the flux ratio of K, docs/solver.md,
/// "Area reflectance") without bias from the lobe's width, and the shares
/// over receivers that do not overlap never sum to more than the albedo.
pub fn sample_glossy_lobe<const N: usize>(
    bsdf: &Bsdf<N>,
    wi: DVec3,
    glossy_albedo: Spectrum<N>,
    grid: u32,
    scale: f64,
    out: &mut Vec<LobeSample<N>>,
) {
    let start = out.len();
    let mut total = Spectrum::<N>::zero();
    let g = f64::from(grid.max(1));
    for a in 0..grid.max(1) {
        for b in 0..grid.max(1) {
            let u = glam::DVec2::new((f64::from(a) + 0.5) / g, (f64::from(b) + 0.5) / g);
            let Some(s) = bsdf.sample(wi, u) else {
                continue;
            };
            if s.wi.z * wi.z <= 0.0 {
                continue;
            }
            let w = bsdf.eval_glossy(wi, s.wi) * (s.wi.z.abs() / s.pdf);
            if !w.is_finite() || w.is_black() {
                continue;
            }
            let w = w.max(Spectrum::zero());
            total += w;
            out.push(LobeSample { wo: s.wi, share: w });
        }
    }
    let albedo = glossy_albedo.max(Spectrum::zero());
    let norm = Spectrum::<N>::new(std::array::from_fn(|c| {
        if total[c] > 0.0 {
            albedo[c] * scale / total[c]
        } else {
            0.0
        }
    }));
    for s in &mut out[start..] {
        s.share *= norm;
    }
}
