//! Local shading frames: z is the front normal.
//!
//! Every BRDF in this crate works in a local frame whose z axis is the
//! surface's front normal (after `flip_normals`); `wi` points towards the
//! light and `wo` towards the viewer, both away from the surface.

use glam::{DVec2, DVec3};

/// An orthonormal frame (s, t, n) with n the front normal.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    /// First tangent.
    pub s: DVec3,
    /// Second tangent.
    pub t: DVec3,
    /// Normal (local z).
    pub n: DVec3,
}

impl Frame {
    /// A frame around the unit normal `n`: its tangents are
    /// [`trilux_frame::coordinate_system`]'s (Duff et al. 2017,
    /// branchless and continuous except across n.z = 0's sign change).
    pub fn from_normal(n: DVec3) -> Frame {
        let (s, t) = trilux_frame::coordinate_system(n);
        Frame { s, t, n }
    }

    /// World → local.
    pub fn to_local(&self, v: DVec3) -> DVec3 {
        DVec3::new(v.dot(self.s), v.dot(self.t), v.dot(self.n))
    }

    /// Local → world.
    pub fn to_world(&self, v: DVec3) -> DVec3 {
        self.s * v.x + self.t * v.y + self.n * v.z
    }
}

/// Mirror reflection of `v` about the unit normal `n` (both pointing away
/// from the surface).
pub fn reflect(v: DVec3, n: DVec3) -> DVec3 {
    2.0 * v.dot(n) * n - v
}

/// Malley's method: a concentric disk sample lifted to the hemisphere; pdf
/// cosθ/π.
pub fn square_to_cosine_hemisphere(u: DVec2) -> DVec3 {
    let a = 2.0 * u - DVec2::ONE;
    let (r, phi) = if a.x == 0.0 && a.y == 0.0 {
        (0.0, 0.0)
    } else if a.x.abs() > a.y.abs() {
        (a.x, std::f64::consts::FRAC_PI_4 * (a.y / a.x))
    } else {
        (
            a.y,
            std::f64::consts::FRAC_PI_2 - std::f64::consts::FRAC_PI_4 * (a.x / a.y),
        )
    };
    let d = DVec2::new(r * phi.cos(), r * phi.sin());
    let z = (1.0 - d.length_squared()).max(0.0).sqrt();
    DVec3::new(d.x, d.y, z)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_are_orthonormal() {
        for n in [
            DVec3::Z,
            -DVec3::Z,
            DVec3::X,
            DVec3::new(0.3, -0.5, 0.8).normalize(),
            DVec3::new(-0.2, 0.1, -0.97).normalize(),
        ] {
            let f = Frame::from_normal(n);
            assert!((f.s.length() - 1.0).abs() < 1e-12);
            assert!((f.t.length() - 1.0).abs() < 1e-12);
            assert!(f.s.dot(f.t).abs() < 1e-12 && f.s.dot(n).abs() < 1e-12);
            assert!((f.s.cross(f.t) - n).length() < 1e-12);
            let v = DVec3::new(0.1, 0.7, -0.2);
            assert!((f.to_world(f.to_local(v)) - v).length() < 1e-12);
        }
    }
}
