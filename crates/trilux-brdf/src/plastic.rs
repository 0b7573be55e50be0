//! Mitsuba 3's `plastic` and `roughplastic`: a diffuse base under a
//! dielectric coat of relative index η (`src/bsdfs/plastic.cpp`,
//! `roughplastic.cpp`), in the local frame of the front side (`wi` to the
//! light, `wo` to the viewer; black on the back, no transmission).
//!
//! fr(wi, wo) = coat(wi, wo) + ρ' T(wi) T(wo) / (π η²), with
//! ρ' = ρ/(1 − F_dr) (or ρ/(1 − ρ F_dr) when `nonlinear`) and T the coat's
//! transmittance:
//! - `plastic`: T(μ) = 1 − F(μ), F_dr Mitsuba's fit of the internal
//!   diffuse Fresnel reflectance F_dr(1/η); the coat is a mirror of
//!   weight F(μ)·specular_reflectance, a delta lobe: `eval` leaves it out
//!   (as Mitsuba's does) and [`Plastic::delta`] gives it.
//! - `roughplastic`: the coat is a microfacet dielectric reflection
//!   F(wo·h) D G / (4 cosθi cosθo) · specular_reflectance; T(μ) is
//!   interpolated linearly in a 64-entry table of the rough coat's
//!   transmittance and F_dr is the coat's internal reflectance, both
//!   computed by Mitsuba's own quadratures ([`CoatTables`]).
//!
//! **The solver's split** (docs/solver.md, "Plastics"): the Lambertian
//! part is the base term's albedo under uniform incidence, ρ_d = ρ' T̄²/η²
//! with T̄ = 2∫T(μ)μ dμ (it reflects, over all directions, exactly the
//! energy the base term does); the glossy part is the rough coat's lobe. The
//! base term's angular shape T(wi)T(wo) is left to the render, which
//! estimates fr − ρ_d/π by its gather ([`Plastic::eval`] less ρ_d/π). The
//! smooth coat's mirror carries, in the solve, its uniform-incidence albedo
//! (1 − T̄)·specular_reflectance inside ρ_d: energy is kept, its direction
//! is not.

use std::collections::HashMap;
use std::f64::consts::{FRAC_1_PI, PI};
use std::sync::{Arc, Mutex, OnceLock};

use glam::{DVec2, DVec3};
use trilux_color::Spectrum;

use crate::frame::square_to_cosine_hemisphere;
use crate::fresnel::{fresnel_dielectric, fresnel_diffuse_reflectance};
use crate::microfacet::{Microfacet, microfacet_albedo};
use crate::params::Distribution;

/// Entries of the rough coat's transmittance table (Mitsuba's
/// `MI_ROUGH_TRANSMITTANCE_RES`).
const TABLE: usize = 64;

/// A plastic side, ready to evaluate.
#[derive(Clone, Debug, PartialEq)]
pub struct Plastic<const N: usize> {
    /// The rough coat's distribution; `None` for the smooth `plastic`.
    pub coat: Option<Microfacet>,
    /// Relative index of refraction, int_ior / ext_ior.
    pub eta: f64,
    /// ρ'/η² per band (module docs).
    pub base: Spectrum<N>,
    /// Multiplies the coat's reflection.
    pub specular_reflectance: Spectrum<N>,
    /// Mitsuba's specular sampling weight s/(d + s), from the means of the
    /// specular and diffuse reflectances.
    pub specular_sampling_weight: f64,
    tables: Option<Arc<CoatTables>>,
    /// T̄ = 2∫T(μ)μ dμ.
    mean_transmittance: f64,
    /// F_dr.
    fdr: f64,
}

/// What a rough coat needs precomputed (Mitsuba's `parameters_changed`).
#[derive(Clone, Debug, PartialEq)]
pub struct CoatTables {
    /// The coat's transmittance from outside at μ = i/63.
    pub transmittance: [f64; TABLE],
    /// The coat's internal reflectance (Mitsuba's `m_internal_reflectance`).
    pub internal_reflectance: f64,
}

/// Tables already computed, by (distribution, α, η) bits: scenes reuse a
/// few coats for many materials, and each table costs ≈ 1 M microfacet
/// samples.
type TableCache = Mutex<HashMap<(bool, u64, u64), Arc<CoatTables>>>;

fn table_cache() -> &'static TableCache {
    static CACHE: OnceLock<TableCache> = OnceLock::new();
    CACHE.get_or_init(|| Mutex::new(HashMap::new()))
}

impl CoatTables {
    /// The tables of a coat (cached).
    pub fn of(mf: &Microfacet, eta: f64) -> Arc<CoatTables> {
        let key = (
            mf.distribution == Distribution::Ggx,
            mf.alpha.to_bits(),
            eta.to_bits(),
        );
        let cache = table_cache();
        if let Some(t) = cache.lock().ok().and_then(|c| c.get(&key).cloned()) {
            return t;
        }
        let t = Arc::new(CoatTables::compute(mf, eta));
        if let Ok(mut c) = cache.lock() {
            c.insert(key, Arc::clone(&t));
        }
        t
    }

    /// Mitsuba's `eval_transmittance` at μ = max(1e-6, i/63) (η, 32² Gauss–
    /// Legendre nodes over its visible-normal sampler) and twice the mean of
    /// μ·`eval_reflectance` from inside (1/η, 128² nodes).
    fn compute(mf: &Microfacet, eta: f64) -> CoatTables {
        let mut transmittance = [0.0; TABLE];
        let mut internal = 0.0;
        let (n_out, w_out) = gauss_legendre(if eta > 1.0 { 32 } else { 128 });
        let (n_in, w_in) = gauss_legendre(if 1.0 / eta > 1.0 { 32 } else { 128 });
        for (i, t) in transmittance.iter_mut().enumerate() {
            let mu = (i as f64 / (TABLE - 1) as f64).max(1e-6);
            let wi = DVec3::new((1.0 - mu * mu).max(0.0).sqrt(), 0.0, mu);
            *t = quadrature(&n_out, &w_out, |u| {
                let m = sample_visible_mitsuba(mf, wi, u);
                let (f, cos_t, _, eta_ti) = fresnel_dielectric(wi.dot(m), eta);
                let wo = m * (wi.dot(m) * eta_ti + cos_t) - wi * eta_ti;
                if wo.z * wi.z >= 0.0 {
                    0.0
                } else {
                    mf.smith_g1(wo, m) * (1.0 - f)
                }
            });
            let r = quadrature(&n_in, &w_in, |u| {
                let m = sample_visible_mitsuba(mf, wi, u);
                let wo = 2.0 * wi.dot(m) * m - wi;
                if wo.z <= 0.0 {
                    0.0
                } else {
                    mf.smith_g1(wo, m) * fresnel_dielectric(wi.dot(m), 1.0 / eta).0
                }
            });
            internal += r * mu;
        }
        CoatTables {
            transmittance,
            internal_reflectance: 2.0 * internal / TABLE as f64,
        }
    }

    /// T(μ) by Mitsuba's `lerp_gather`.
    fn at(&self, mu: f64) -> f64 {
        let x = mu * (TABLE - 1) as f64;
        let i = (x.max(0.0) as usize).min(TABLE - 2);
        let (a, b) = (self.transmittance[i], self.transmittance[i + 1]);
        a + (b - a) * (x - i as f64)
    }
}

/// Σ f(node) w_x w_y / 4 over the tensor Gauss–Legendre rule mapped to
/// [0, 1]².
fn quadrature(nodes: &[f64], weights: &[f64], f: impl Fn(DVec2) -> f64) -> f64 {
    let mut sum = 0.0;
    for (x, wx) in nodes.iter().zip(weights) {
        for (y, wy) in nodes.iter().zip(weights) {
            let v = f(DVec2::new(x * 0.5 + 0.5, y * 0.5 + 0.5));
            sum += v * wx * wy * 0.25;
        }
    }
    sum
}

/// Gauss–Legendre nodes and weights on [−1, 1] (Newton on Pₙ from
/// Chebyshev guesses, as Mitsuba's `quad::gauss_legendre`).
pub(crate) fn gauss_legendre(n: usize) -> (Vec<f64>, Vec<f64>) {
    let mut nodes = vec![0.0; n];
    let mut weights = vec![0.0; n];
    let legendre = |x: f64| -> (f64, f64) {
        // (Pₙ(x), Pₙ'(x)) by the three-term recurrence.
        let (mut p0, mut p1) = (1.0, x);
        for k in 2..=n {
            let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
            p0 = p1;
            p1 = p2;
        }
        let d = n as f64 * (x * p1 - p0) / (x * x - 1.0);
        (p1, d)
    };
    for i in 0..n.div_ceil(2) {
        let mut x = -((2 * i + 1) as f64 / (2 * n) as f64 * PI).cos();
        for _ in 0..100 {
            let (p, d) = legendre(x);
            let step = p / d;
            x -= step;
            if step.abs() <= 4.0 * x.abs() * f64::EPSILON {
                break;
            }
        }
        let (_, d) = legendre(x);
        let w = 2.0 / ((1.0 - x * x) * d * d);
        nodes[i] = x;
        nodes[n - 1 - i] = -x;
        weights[i] = w;
        weights[n - 1 - i] = w;
    }
    if n % 2 == 1 {
        nodes[n / 2] = 0.0;
    }
    (nodes, weights)
}

/// Mitsuba's visible-normal sampler (`MicrofacetDistribution::sample` with
/// `sample_visible`), reproduced mapping for mapping because its tables are
/// quadratures over this mapping: Beckmann's slopes by three Newton steps
/// from Mitsuba's initial guess, GGX's by its concentric-disk projection.
/// (trilux's own sampler, [`Microfacet::sample_normal`], inverts more
/// accurately; the tables must be Mitsuba's.)
fn sample_visible_mitsuba(mf: &Microfacet, wi: DVec3, u: DVec2) -> DVec3 {
    let a = mf.alpha;
    let wp = DVec3::new(a * wi.x, a * wi.y, wi.z).normalize();
    let sin2 = wp.x * wp.x + wp.y * wp.y;
    let (sin_phi, cos_phi) = if sin2 <= 4.0 * f64::from(f32::EPSILON) {
        (0.0, 1.0)
    } else {
        let inv = 1.0 / sin2.sqrt();
        ((wp.y * inv).clamp(-1.0, 1.0), (wp.x * inv).clamp(-1.0, 1.0))
    };
    let (sx, sy) = match mf.distribution {
        Distribution::Beckmann => beckmann_slopes_mitsuba(wp.z, u),
        Distribution::Ggx => ggx_slopes_mitsuba(wp.z, u),
    };
    let (sx, sy) = (
        (cos_phi * sx - sin_phi * sy) * a,
        (sin_phi * sx + cos_phi * sy) * a,
    );
    DVec3::new(-sx, -sy, 1.0).normalize()
}

fn beckmann_slopes_mitsuba(cos_theta: f64, u: DVec2) -> (f64, f64) {
    use crate::special::{erf, erf_inv_fast as erf_inv};
    let tan = (1.0 - cos_theta * cos_theta).max(0.0).sqrt() / cos_theta;
    let cot = 1.0 / tan;
    let maxval = erf(cot);
    let u = u.clamp(DVec2::splat(1e-6), DVec2::splat(1.0 - 1e-6));
    let mut x = maxval - (maxval + 1.0) * erf((-u.x.ln()).sqrt());
    let inv_sqrt_pi = 1.0 / PI.sqrt();
    let tail = if tan == 0.0 {
        0.0
    } else {
        inv_sqrt_pi * tan * (-cot * cot).exp()
    };
    let ux = u.x * (1.0 + maxval + tail);
    for _ in 0..3 {
        let slope = erf_inv(x);
        let value = 1.0 + x + inv_sqrt_pi * tan * (-slope * slope).exp() - ux;
        let derivative = 1.0 - slope * tan;
        x -= value / derivative;
    }
    (erf_inv(x), erf_inv(2.0 * u.y - 1.0))
}

fn ggx_slopes_mitsuba(cos_theta: f64, u: DVec2) -> (f64, f64) {
    let d = square_to_cosine_hemisphere(u); // its x, y: the concentric disk
    let s = 0.5 * (1.0 + cos_theta);
    let x = d.x;
    let y = (1.0 - x * x).max(0.0).sqrt() * (1.0 - s) + d.y * s;
    let z = (1.0 - x * x - y * y).max(0.0).sqrt();
    let sin = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
    let norm = 1.0 / (sin * y + cos_theta * z);
    ((cos_theta * y - sin * z) * norm, x * norm)
}

/// 2∫₀¹ T(μ) μ dμ by 4096 midpoints.
fn mean_of(t: impl Fn(f64) -> f64) -> f64 {
    const M: usize = 4096;
    (0..M)
        .map(|i| {
            let mu = (i as f64 + 0.5) / M as f64;
            2.0 * t(mu) * mu
        })
        .sum::<f64>()
        / M as f64
}

impl<const N: usize> Plastic<N> {
    /// A plastic side from its reflectances (already per band), indices
    /// and coat. `diffuse_mean` and `specular_mean` are the reflectances'
    /// means over their channels (and texels), for the sampling weight.
    pub fn new(
        diffuse: Spectrum<N>,
        specular_reflectance: Spectrum<N>,
        eta: f64,
        nonlinear: bool,
        coat: Option<Microfacet>,
        (diffuse_mean, specular_mean): (f64, f64),
    ) -> Self {
        let tables = coat.map(|mf| CoatTables::of(&mf, eta));
        let fdr = match &tables {
            Some(t) => t.internal_reflectance,
            None => fresnel_diffuse_reflectance(1.0 / eta),
        };
        let base = Spectrum::from_fn(|b| {
            let d = diffuse[b];
            let denom = 1.0 - if nonlinear { d * fdr } else { fdr };
            d / denom / (eta * eta)
        });
        let mean_transmittance = match &tables {
            Some(t) => mean_of(|mu| t.at(mu)),
            None => mean_of(|mu| 1.0 - fresnel_dielectric(mu, eta).0),
        };
        let total = diffuse_mean + specular_mean;
        Plastic {
            coat,
            eta,
            base,
            specular_reflectance,
            specular_sampling_weight: if total > 0.0 {
                specular_mean / total
            } else {
                0.5
            },
            tables,
            mean_transmittance,
            fdr,
        }
    }

    /// T̄ = 2∫T(μ)μ dμ, the coat's transmittance under uniform light.
    pub fn mean_transmittance(&self) -> f64 {
        self.mean_transmittance
    }

    /// F_dr: the coat's reflectance seen from inside under uniform light
    /// (Mitsuba's fit for a smooth coat, its quadrature for a rough one).
    pub fn internal_reflectance(&self) -> f64 {
        self.fdr
    }

    /// The coat's transmittance T(μ) from outside.
    pub fn transmittance(&self, mu: f64) -> f64 {
        match &self.tables {
            Some(t) => t.at(mu),
            None => 1.0 - fresnel_dielectric(mu, self.eta).0,
        }
    }

    /// The rough coat's lobe (zero for the smooth coat, a delta).
    pub fn eval_coat(&self, wi: DVec3, wo: DVec3) -> Spectrum<N> {
        let Some(mf) = &self.coat else {
            return Spectrum::zero();
        };
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return Spectrum::zero();
        }
        let h = (wi + wo).normalize();
        if !h.is_finite() {
            return Spectrum::zero();
        }
        let d = mf.d(h);
        if d == 0.0 {
            return Spectrum::zero();
        }
        // The mean of wi·h and wo·h: reciprocal bit for bit (see Conductor).
        let f = fresnel_dielectric(0.5 * (wi.dot(h) + wo.dot(h)), self.eta).0;
        let s = f * d * mf.g(wi, wo, h) / (4.0 * wi.z * wo.z);
        if s.is_finite() && s > 0.0 {
            self.specular_reflectance * s
        } else {
            Spectrum::zero()
        }
    }

    /// The base term ρ' T(wi) T(wo)/(π η²).
    pub fn eval_base(&self, wi: DVec3, wo: DVec3) -> Spectrum<N> {
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return Spectrum::zero();
        }
        self.base * (FRAC_1_PI * self.transmittance(wi.z) * self.transmittance(wo.z))
    }

    /// fr(wi, wo), the smooth coat's delta excluded (Mitsuba's `eval`).
    pub fn eval(&self, wi: DVec3, wo: DVec3) -> Spectrum<N> {
        self.eval_coat(wi, wo) + self.eval_base(wi, wo)
    }

    /// The smooth coat's mirror reflection for viewer `wo`: the direction
    /// and its weight F(cosθ)·specular_reflectance (`None` for a rough
    /// coat).
    pub fn delta(&self, wo: DVec3) -> Option<(DVec3, Spectrum<N>)> {
        if self.coat.is_some() || wo.z <= 0.0 {
            return None;
        }
        let f = fresnel_dielectric(wo.z, self.eta).0;
        Some((
            DVec3::new(-wo.x, -wo.y, wo.z),
            self.specular_reflectance * f,
        ))
    }

    /// The probability with which Mitsuba samples the coat for viewer
    /// `wo`: (1 − T)·w / ((1 − T)·w + T·(1 − w)), w the specular sampling
    /// weight.
    pub fn prob_specular(&self, wo: DVec3) -> f64 {
        let t = self.transmittance(wo.z);
        let w = self.specular_sampling_weight;
        let (s, d) = ((1.0 - t) * w, t * (1.0 - w));
        if s + d > 0.0 { s / (s + d) } else { 0.0 }
    }

    /// The probability of sampling the rough coat: Mitsuba's for a rough
    /// coat, 0 for a smooth one (its delta is not sampled here; see
    /// [`Plastic::delta`]).
    fn prob_coat(&self, wo: DVec3) -> f64 {
        if self.coat.is_some() {
            self.prob_specular(wo)
        } else {
            0.0
        }
    }

    /// Samples wi as Mitsuba does (coat with [`Plastic::prob_specular`],
    /// u.x rescaled; else the cosine hemisphere); the smooth coat samples
    /// its base only.
    pub fn sample(&self, wo: DVec3, u: DVec2) -> Option<DVec3> {
        let p = self.prob_coat(wo);
        let wi = match &self.coat {
            Some(mf) if u.x < p => {
                let ux = (u.x / p).min(1.0 - f64::EPSILON);
                let m = mf.sample_normal(wo, DVec2::new(ux, u.y));
                crate::frame::reflect(wo, m)
            }
            _ => {
                let ux = ((u.x - p) / (1.0 - p)).clamp(0.0, 1.0 - f64::EPSILON);
                square_to_cosine_hemisphere(DVec2::new(ux, u.y))
            }
        };
        (wi.z > 0.0 && wi.is_finite()).then_some(wi)
    }

    /// The density of [`Plastic::sample`]: Mitsuba's `pdf` for a rough coat
    /// (with the exact Smith G1 in the coat's part, which is what trilux's
    /// sampler draws: see [`crate::microfacet`]); cosθi/π for a smooth one.
    pub fn pdf(&self, wo: DVec3, wi: DVec3) -> f64 {
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return 0.0;
        }
        let p = self.prob_coat(wo);
        let mut pdf = (1.0 - p) * wi.z * FRAC_1_PI;
        if let Some(mf) = &self.coat {
            let h = (wi + wo).normalize();
            let dot = wo.dot(h);
            if dot > 0.0 {
                let c = mf.normal_pdf(wo, h) / (4.0 * dot);
                if c.is_finite() {
                    pdf += p * c;
                }
            }
        }
        pdf
    }

    /// The Lambertian part's reflectance ρ_d (module docs).
    pub fn diffuse_albedo(&self) -> Spectrum<N> {
        let t = self.mean_transmittance;
        let mut rho = self.base * (t * t);
        if self.coat.is_none() {
            rho += self.specular_reflectance * (1.0 - t);
        }
        rho
    }

    /// Directional albedo ∫ fr cosθi dωi for viewer `wo`, the smooth coat's
    /// delta F(cosθo)·specular_reflectance included.
    pub fn albedo(&self, wo: DVec3) -> Spectrum<N> {
        if wo.z <= 0.0 {
            return Spectrum::zero();
        }
        let base = self.base * (self.transmittance(wo.z) * self.mean_transmittance);
        let coat = match &self.coat {
            Some(mf) => microfacet_albedo(mf, wo, |c| {
                self.specular_reflectance * fresnel_dielectric(c, self.eta).0
            }),
            None => self.delta(wo).map_or(Spectrum::zero(), |(_, w)| w),
        };
        base + coat
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gauss_legendre_integrates_polynomials() {
        for n in [1, 2, 5, 32] {
            let (x, w) = gauss_legendre(n);
            // Exact for degree 2n − 1: ∫x^k over [−1, 1].
            for k in 0..(2 * n) {
                let got: f64 = x.iter().zip(&w).map(|(x, w)| w * x.powi(k as i32)).sum();
                let want = if k % 2 == 1 {
                    0.0
                } else {
                    2.0 / (k + 1) as f64
                };
                assert!((got - want).abs() < 1e-12, "n {n} k {k}: {got} {want}");
            }
        }
    }

    /// White plastic (ρ = 1, specular 1) loses no energy: F + T·T̄/(η²(1 −
    /// F_dr)) = 1 when F_dr is exact, so the albedo is 1 at every angle to
    /// within Mitsuba's F_dr fit (0.1 % at η = 1.49) and the quadrature.
    #[test]
    fn white_smooth_plastic_conserves_energy() {
        let p: Plastic<1> = Plastic::new(
            Spectrum::splat(1.0),
            Spectrum::splat(1.0),
            1.49 / 1.000277,
            false,
            None,
            (1.0, 1.0),
        );
        for k in 0..=20 {
            let th = (k as f64 * 4.45).to_radians();
            let a = p.albedo(DVec3::new(th.sin(), 0.0, th.cos()))[0];
            assert!((a - 1.0).abs() < 3e-3, "θ {}: {a}", k as f64 * 4.45);
        }
        assert!((p.diffuse_albedo()[0] - 1.0).abs() < 3e-3);
    }
}
