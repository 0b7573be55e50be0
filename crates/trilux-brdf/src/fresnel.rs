//! Fresnel reflectance of a conductor with complex index η + ik, for
//! unpolarised light (as Mitsuba 3's `fresnel_conductor`, after K. D. Moeller,
//! "Optics", 1988). η = 0, k = 1 gives exactly 1, which is how Mitsuba
//! implements `material="none"`.

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

#[cfg(test)]
mod tests {
    use super::*;

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
