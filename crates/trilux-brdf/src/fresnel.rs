//! Fresnel reflectance for unpolarised light, as Mitsuba 3 computes it
//! (`include/mitsuba/render/fresnel.h`): of a conductor with complex index
//! η + ik (after K. D. Moeller, "Optics", 1988; η = 0, k = 1 gives exactly 1,
//! which is how Mitsuba implements `material="none"`), of a dielectric
//! interface, and the dielectric's diffuse reflectance F_dr (Mitsuba's fits).

/// F(cosθ_i) for a conductor with index `eta` + i `k`.
pub(crate) fn fresnel_conductor(cos_theta_i: f64, eta: f64, k: f64) -> f64 {
    let c2 = cos_theta_i * cos_theta_i;
    let s2 = 1.0 - c2;
    let s4 = s2 * s2;
    let temp1 = eta * eta - k * k - s2;
    let a2pb2 = (temp1 * temp1 + 4.0 * k * k * eta * eta).max(0.0).sqrt();
    let a = (0.5 * (a2pb2 + temp1)).max(0.0).sqrt();
    let term1 = a2pb2 + c2;
    let term2 = 2.0 * cos_theta_i * a;
    let rs = (term1 - term2) / (term1 + term2);
    let term3 = a2pb2 * c2 + s4;
    let term4 = term2 * s2;
    let rp = rs * (term3 - term4) / (term3 + term4);
    let f = 0.5 * (rs + rp);
    if f.is_finite() {
        f.clamp(0.0, 1.0)
    } else {
        1.0
    }
}

/// A dielectric interface with relative index `eta` (inside over outside)
/// seen at cosθ_i (negative: from inside), as Mitsuba's `fresnel`:
/// (F, cosθ_t signed opposite to cosθ_i, η_it, η_ti). F = 1 under total
/// internal reflection and at grazing incidence, 0 when `eta` = 1.
pub(crate) fn fresnel_dielectric(cos_theta_i: f64, eta: f64) -> (f64, f64, f64, f64) {
    let (eta_it, eta_ti) = if cos_theta_i >= 0.0 {
        (eta, 1.0 / eta)
    } else {
        (1.0 / eta, eta)
    };
    let cos_t_sqr = 1.0 - (1.0 - cos_theta_i * cos_theta_i) * eta_ti * eta_ti;
    let ci = cos_theta_i.abs();
    let ct = cos_t_sqr.max(0.0).sqrt();
    let r = if eta == 1.0 {
        0.0
    } else if ci == 0.0 {
        1.0
    } else {
        let a_s = (ci - eta_it * ct) / (ci + eta_it * ct);
        let a_p = (ct - eta_it * ci) / (ct + eta_it * ci);
        0.5 * (a_s * a_s + a_p * a_p)
    };
    let cos_t = if cos_theta_i >= 0.0 { -ct } else { ct };
    (r, cos_t, eta_it, eta_ti)
}

/// Mitsuba's `fresnel_diffuse_reflectance(eta)`: the cosine-weighted
/// hemispherical average of F, by Egan & Hilgeman's fit for η < 1 and
/// d'Eon & Irving's for η ≥ 1 (0.1–0.6 % from the integral for η < 2).
pub(crate) fn fresnel_diffuse_reflectance(eta: f64) -> f64 {
    let inv = 1.0 / eta;
    if eta < 1.0 {
        0.0636 * inv + eta * (eta * -1.4399 + 0.7099) + 0.6681
    } else {
        let c = [0.919317, -3.4793, 6.75335, -7.80989, 4.98554, -1.36881];
        c.iter().rev().fold(0.0, |acc, &k| acc * inv + k)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// F_dr against the integral 2∫F(μ)μ dμ it approximates, within the
    /// fits' stated accuracy.
    #[test]
    fn diffuse_reflectance_fits_the_integral() {
        for eta in [1.33, 1.49, 1.8, 1.0 / 1.49, 1.0 / 1.33] {
            let n = 20_000;
            let integral: f64 = (0..n)
                .map(|i| {
                    let mu = (i as f64 + 0.5) / n as f64;
                    2.0 * fresnel_dielectric(mu, eta).0 * mu / n as f64
                })
                .sum();
            let fit = fresnel_diffuse_reflectance(eta);
            assert!(
                (fit - integral).abs() < 0.01 * integral,
                "η {eta}: fit {fit} integral {integral}"
            );
        }
    }

    #[test]
    fn dielectric_closed_forms() {
        // Normal incidence: ((η − 1)/(η + 1))².
        let (f, ct, _, _) = fresnel_dielectric(1.0, 1.5);
        assert!((f - 0.04).abs() < 1e-12 && (ct + 1.0).abs() < 1e-12);
        // Total internal reflection from inside beyond the critical angle.
        assert_eq!(fresnel_dielectric(-0.3, 1.5).0, 1.0);
        assert_eq!(fresnel_dielectric(0.7, 1.0).0, 0.0);
    }

    #[test]
    fn material_none_is_one() {
        for c in [0.0, 0.1, 0.5, 1.0] {
            assert!((fresnel_conductor(c, 0.0, 1.0) - 1.0).abs() < 1e-15);
        }
    }

    #[test]
    fn normal_incidence_closed_form() {
        // F(0°) = ((η−1)² + k²)/((η+1)² + k²).
        let (eta, k) = (0.2, 3.9);
        let want = ((eta - 1.0f64).powi(2) + k * k) / ((eta + 1.0f64).powi(2) + k * k);
        assert!((fresnel_conductor(1.0, eta, k) - want).abs() < 1e-12);
        // Dielectric limit k = 0, η = 1.5: 0.04.
        assert!((fresnel_conductor(1.0, 1.5, 0.0) - 0.04).abs() < 1e-12);
        // Grazing incidence reflects everything.
        assert!((fresnel_conductor(0.0, 1.5, 0.0) - 1.0).abs() < 1e-12);
    }
}
