//! Analytic scenes for testing and benchmarking the final gather.
//!
//! Everything a [`GatherScene`] answers is written here by hand, with closed
//! forms, independently of trilux's geometry, BRDF and solver crates, so the
//! estimator can be checked against known answers:
//! - [`Furnace`]: the inside of an emitting, reflecting closed cube, whose
//!   radiance is le / (1 − ρ) everywhere;
//! - [`LitFloor`]: a diffuse floor under a square light, whose radiance is
//!   ρ · Le · F(point → square) (Lambert's polygon formula).

use std::f64::consts::PI;

use glam::{DVec2, DVec3};
use trilux_color::Spectrum;
use trilux_geometry::FaceElement;

use crate::link_sum::LinkCache;
use crate::records::{
    BsdfSample, FitSite, GatherStats, LightSample, LinkVisibility, PunctualSample, SkyRay,
    SurfacePoint,
};
use crate::scene::{GatherScene, SolutionGather};

/// [`SolutionGather`] for an analytic scene with no links, no glossy part
/// and flat shading, whose elements all have the linear size `$size`: the
/// estimators read nothing from it but the path gather. Stated per scene
/// (the trait has no defaults), written once.
macro_rules! path_gather_only {
    ($scene:ty, $locator:ty, |$this:ident| $size:expr) => {
        impl<const N: usize> SolutionGather<N> for $scene {
            fn element_size(&self, _at: &SurfacePoint<$locator>) -> f64 {
                let $this = self;
                $size
            }
            fn shading_differs(&self, _at: &SurfacePoint<$locator>) -> bool {
                false
            }
            fn has_links(&self) -> bool {
                false
            }
            fn has_glossy_faces(&self) -> bool {
                false
            }
            fn diffuse_albedo(&self, _at: &SurfacePoint<$locator>, _wo: DVec3) -> Spectrum<N> {
                Spectrum::zero()
            }
            fn solution_irradiance(
                &self,
                _at: &SurfacePoint<$locator>,
                _wo: DVec3,
                _visibility: LinkVisibility<'_>,
                _cache: &mut LinkCache<N>,
                _stats: &mut GatherStats,
            ) -> Option<Spectrum<N>> {
                None
            }
            fn near_correction(
                &self,
                _at: &SurfacePoint<$locator>,
                _wo: DVec3,
                _coarse_near: &[FaceElement],
                _cache: &mut LinkCache<N>,
                _stats: &mut GatherStats,
            ) -> Option<Spectrum<N>> {
                None
            }
            fn is_glossy(&self, _at: &SurfacePoint<$locator>, _wo: DVec3) -> bool {
                false
            }
            fn glossy_cos(
                &self,
                _at: &SurfacePoint<$locator>,
                _wi: DVec3,
                _wo: DVec3,
            ) -> Spectrum<N> {
                Spectrum::zero()
            }
            fn reflected_glossy(
                &self,
                _from: &SurfacePoint<$locator>,
                _to: &SurfacePoint<$locator>,
            ) -> Spectrum<N> {
                Spectrum::zero()
            }
            fn cosine_pdf(&self, _at: &SurfacePoint<$locator>, _wo: DVec3, _wi: DVec3) -> f64 {
                0.0
            }
            fn sample_cosine(
                &self,
                _at: &SurfacePoint<$locator>,
                _wo: DVec3,
                _u: DVec2,
            ) -> Option<DVec3> {
                None
            }
            fn fit_sites(
                &self,
                _at: &SurfacePoint<$locator>,
                _wo: DVec3,
            ) -> Vec<FitSite<$locator>> {
                Vec::new()
            }
        }
    };
}

/// Cosine-weighted hemisphere direction around `n`.
pub fn cosine_sample(n: DVec3, u: DVec2) -> DVec3 {
    let r = u.x.sqrt();
    let phi = 2.0 * PI * u.y;
    let (t, b) = trilux_geometry::coordinate_system(n);
    (t * (r * phi.cos()) + b * (r * phi.sin()) + n * (1.0 - u.x).max(0.0).sqrt()).normalize()
}

/// Diffuse BSDF pieces shared by the mocks (front side only).
fn diffuse_cos(rho: f64, n: DVec3, wi: DVec3, wo: DVec3) -> f64 {
    let ci = n.dot(wi);
    if ci > 0.0 && n.dot(wo) > 0.0 {
        rho / PI * ci
    } else {
        0.0
    }
}

fn diffuse_sample<const N: usize>(
    rho: f64,
    n: DVec3,
    wo: DVec3,
    u: DVec2,
) -> Option<BsdfSample<N>> {
    if n.dot(wo) <= 0.0 {
        return None;
    }
    let wi = cosine_sample(n, u);
    let c = n.dot(wi);
    if c <= 0.0 {
        return None;
    }
    Some(BsdfSample {
        wi,
        weight: Spectrum::splat(rho),
        pdf: c / PI,
    })
}

fn diffuse_pdf(n: DVec3, wo: DVec3, wi: DVec3) -> f64 {
    if n.dot(wo) > 0.0 {
        n.dot(wi).max(0.0) / PI
    } else {
        0.0
    }
}

/// The inside of the cube [-1, 1]³: every face emits `le` inwards, reflects
/// diffusely with albedo `rho`, and the "solution" answers `reflected`
/// everywhere. The radiance everywhere is le / (1 − rho) when
/// `reflected` = rho·le / (1 − rho).
pub struct Furnace {
    /// Emitted radiance of every face.
    pub le: f64,
    /// Diffuse albedo.
    pub rho: f64,
    /// What the solution answers for the reflected radiance.
    pub reflected: f64,
    /// Element size the solution reports.
    pub element: f64,
}

impl<const N: usize> GatherScene<N> for Furnace {
    type Locator = usize;

    fn intersect(&self, o: DVec3, d: DVec3) -> Option<SurfacePoint<usize>> {
        // Leave the cube through the nearest slab.
        let mut best = (f64::INFINITY, 0usize);
        for a in 0..3 {
            if d[a] != 0.0 {
                let t = (d[a].signum() - o[a]) / d[a];
                if t > 1e-9 && t < best.0 {
                    best = (t, a);
                }
            }
        }
        if !best.0.is_finite() {
            return None;
        }
        let (t, a) = best;
        let mut n = DVec3::ZERO;
        n[a] = -d[a].signum();
        let face = 2 * a + usize::from(d[a] > 0.0);
        Some(SurfacePoint {
            point: o + d * t,
            normal: n,
            t,
            locator: face,
        })
    }
    fn punctual_count(&self) -> usize {
        0
    }

    fn punctual_at(
        &self,
        _k: usize,
        _reference: &SurfacePoint<Self::Locator>,
    ) -> Option<PunctualSample<N>> {
        None
    }

    fn sky(&self, _from: DVec3, _wi: DVec3) -> (Spectrum<N>, f64) {
        (Spectrum::zero(), 0.0)
    }

    fn sample_sky(&self, _reference: &SurfacePoint<usize>, _u: DVec2) -> Option<SkyRay<N>> {
        None
    }

    fn unoccluded(&self, _from: &SurfacePoint<usize>, _to: DVec3) -> bool {
        true // convex: nothing inside
    }
    fn emitted(&self, at: &SurfacePoint<usize>, wo: DVec3) -> Spectrum<N> {
        if at.normal.dot(wo) > 0.0 {
            Spectrum::splat(self.le)
        } else {
            Spectrum::zero()
        }
    }
    fn sample_light(&self, r: &SurfacePoint<usize>, pick: f64, u: DVec2) -> Option<LightSample<N>> {
        if self.le == 0.0 {
            return None;
        }
        let face = ((pick * 6.0) as usize).min(5);
        let a = face / 2;
        let sign = if face % 2 == 1 { 1.0 } else { -1.0 };
        let mut p = DVec3::ZERO;
        p[a] = sign;
        p[(a + 1) % 3] = 2.0 * u.x - 1.0;
        p[(a + 2) % 3] = 2.0 * u.y - 1.0;
        let mut n = DVec3::ZERO;
        n[a] = -sign;
        let radiance = if n.dot(r.point - p) > 0.0 {
            Spectrum::splat(self.le)
        } else {
            Spectrum::zero()
        };
        Some(LightSample {
            point: p,
            normal: n,
            radiance,
            pdf_area: 1.0 / 24.0,
        })
    }
    fn light_pdf_area(&self, _at: &SurfacePoint<usize>) -> f64 {
        if self.le == 0.0 { 0.0 } else { 1.0 / 24.0 }
    }
    fn bsdf_cos(&self, at: &SurfacePoint<usize>, wi: DVec3, wo: DVec3) -> Spectrum<N> {
        Spectrum::splat(diffuse_cos(self.rho, at.normal, wi, wo))
    }
    fn sample_bsdf(&self, at: &SurfacePoint<usize>, wo: DVec3, u: DVec2) -> Option<BsdfSample<N>> {
        diffuse_sample(self.rho, at.normal, wo, u)
    }
    fn bsdf_pdf(&self, at: &SurfacePoint<usize>, wo: DVec3, wi: DVec3) -> f64 {
        diffuse_pdf(at.normal, wo, wi)
    }
    fn reflected(
        &self,
        _from: &SurfacePoint<usize>,
        _towards: &SurfacePoint<usize>,
    ) -> Spectrum<N> {
        Spectrum::splat(self.reflected)
    }
    fn lobe_solid_angle(&self, _at: &SurfacePoint<usize>, _wo: DVec3) -> f64 {
        2.0 * PI
    }
}

path_gather_only!(Furnace, usize, |scene| scene.element);

/// A diffuse floor z = 0 (albedo `rho`, unbounded) under a square emitter
/// [-s, s]² at height `h`, facing down with radiance `le`, black itself.
/// Nothing else: the solution's reflected radiance is zero (light reaching
/// the floor only once is all there is).
pub struct LitFloor {
    /// Floor albedo.
    pub rho: f64,
    /// Half side of the emitter.
    pub s: f64,
    /// Height of the emitter.
    pub h: f64,
    /// Emitted radiance.
    pub le: f64,
}

impl LitFloor {
    /// Irradiance-based closed form: the radiance leaving floor point p is
    /// rho · le · F(p → square), with F from Lambert's formula for a
    /// polygon seen from a differential area (normal +z).
    pub fn expected(&self, p: DVec3) -> f64 {
        let s = self.s;
        let h = self.h;
        let corners = [
            DVec3::new(-s, -s, h),
            DVec3::new(s, -s, h),
            DVec3::new(s, s, h),
            DVec3::new(-s, s, h),
        ];
        let mut f = 0.0;
        for i in 0..4 {
            let a = (corners[i] - p).normalize();
            let b = (corners[(i + 1) % 4] - p).normalize();
            let g = a.cross(b);
            let gamma = a.dot(b).clamp(-1.0, 1.0).acos();
            f += gamma * g.z / g.length();
        }
        self.rho * self.le * (f / (2.0 * PI)).abs()
    }
}

/// Closest hit of a ray with the floor z = 0 (facing +z, locator 0) and a
/// square light of half-size `s` at height `h` facing down (locator 1): the
/// geometry of the analytic lit-floor scenes.
pub fn floor_and_square_light(o: DVec3, d: DVec3, h: f64, s: f64) -> Option<SurfacePoint<u8>> {
    let mut best: Option<SurfacePoint<u8>> = None;
    if d.z != 0.0 {
        let t = -o.z / d.z;
        if t > 1e-9 {
            best = Some(SurfacePoint {
                point: o + d * t,
                normal: DVec3::Z,
                t,
                locator: 0,
            });
        }
        let t = (h - o.z) / d.z;
        let p = o + d * t;
        if t > 1e-9 && p.x.abs() <= s && p.y.abs() <= s && best.is_none_or(|b| t < b.t) {
            best = Some(SurfacePoint {
                point: p,
                normal: -DVec3::Z,
                t,
                locator: 1,
            });
        }
    }
    best
}

impl<const N: usize> GatherScene<N> for LitFloor {
    /// 0 = floor, 1 = emitter.
    type Locator = u8;

    fn intersect(&self, o: DVec3, d: DVec3) -> Option<SurfacePoint<u8>> {
        floor_and_square_light(o, d, self.h, self.s)
    }
    fn punctual_count(&self) -> usize {
        0
    }

    fn punctual_at(
        &self,
        _k: usize,
        _reference: &SurfacePoint<Self::Locator>,
    ) -> Option<PunctualSample<N>> {
        None
    }

    fn sky(&self, _from: DVec3, _wi: DVec3) -> (Spectrum<N>, f64) {
        (Spectrum::zero(), 0.0)
    }

    fn sample_sky(&self, _reference: &SurfacePoint<u8>, _u: DVec2) -> Option<SkyRay<N>> {
        None
    }

    fn unoccluded(&self, _from: &SurfacePoint<u8>, _to: DVec3) -> bool {
        true
    }
    fn emitted(&self, at: &SurfacePoint<u8>, wo: DVec3) -> Spectrum<N> {
        if at.locator == 1 && at.normal.dot(wo) > 0.0 {
            Spectrum::splat(self.le)
        } else {
            Spectrum::zero()
        }
    }
    fn sample_light(&self, r: &SurfacePoint<u8>, _pick: f64, u: DVec2) -> Option<LightSample<N>> {
        let p = DVec3::new(
            (2.0 * u.x - 1.0) * self.s,
            (2.0 * u.y - 1.0) * self.s,
            self.h,
        );
        let radiance = if r.point.z < self.h {
            Spectrum::splat(self.le)
        } else {
            Spectrum::zero()
        };
        Some(LightSample {
            point: p,
            normal: -DVec3::Z,
            radiance,
            pdf_area: 1.0 / (4.0 * self.s * self.s),
        })
    }
    fn light_pdf_area(&self, at: &SurfacePoint<u8>) -> f64 {
        if at.locator == 1 {
            1.0 / (4.0 * self.s * self.s)
        } else {
            0.0
        }
    }
    fn bsdf_cos(&self, at: &SurfacePoint<u8>, wi: DVec3, wo: DVec3) -> Spectrum<N> {
        let rho = if at.locator == 0 { self.rho } else { 0.0 };
        Spectrum::splat(diffuse_cos(rho, at.normal, wi, wo))
    }
    fn sample_bsdf(&self, at: &SurfacePoint<u8>, wo: DVec3, u: DVec2) -> Option<BsdfSample<N>> {
        if at.locator == 0 {
            diffuse_sample(self.rho, at.normal, wo, u)
        } else {
            None
        }
    }
    fn bsdf_pdf(&self, at: &SurfacePoint<u8>, wo: DVec3, wi: DVec3) -> f64 {
        if at.locator == 0 {
            diffuse_pdf(at.normal, wo, wi)
        } else {
            0.0
        }
    }
    fn reflected(&self, _from: &SurfacePoint<u8>, _towards: &SurfacePoint<u8>) -> Spectrum<N> {
        Spectrum::zero()
    }
    fn lobe_solid_angle(&self, _at: &SurfacePoint<u8>, _wo: DVec3) -> f64 {
        2.0 * PI
    }
}

path_gather_only!(LitFloor, u8, |_scene| 0.1);
