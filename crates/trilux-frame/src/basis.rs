//! The orthonormal basis around a unit vector: the one definition that
//! shading frames (trilux-brdf's `Frame`), Mitsuba-style look-at and
//! cylinder frames (trilux-scene) and the analytic test scenes share, so
//! that every tangent frame in trilux is the same, bit for bit.

use glam::DVec3;

/// Two unit tangents `(s, t)` such that `(s, t, n)` is a right-handed
/// orthonormal basis around the unit vector `n`: Duff et al. 2017,
/// "Building an Orthonormal Basis, Revisited" (listing 3), branchless and
/// continuous except across the sign change of `n.z`. It is Mitsuba 3's
/// `coordinate_system`, so frames built from it match Mitsuba's.
pub fn coordinate_system(n: DVec3) -> (DVec3, DVec3) {
    let sign = 1f64.copysign(n.z);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    (
        DVec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x),
        DVec3::new(b, sign + n.y * n.y * a, -n.y),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_basis_is_right_handed_and_orthonormal() {
        // Directions over the sphere, the poles and the n.z = 0 equator.
        let mut normals = vec![DVec3::Z, -DVec3::Z, DVec3::X, -DVec3::Y];
        for i in 0..12 {
            for j in 0..7 {
                let (phi, z) = (0.523 * f64::from(i), -0.99 + 0.33 * f64::from(j));
                let r = (1.0 - z * z).sqrt();
                normals.push(DVec3::new(r * phi.cos(), r * phi.sin(), z));
            }
        }
        for n in normals {
            let (s, t) = coordinate_system(n);
            for (u, v) in [(s, t), (t, n), (s, n)] {
                assert!(u.dot(v).abs() < 1e-12, "{n}: {u} · {v}");
            }
            for u in [s, t] {
                assert!((u.length() - 1.0).abs() < 1e-12, "{n}: |{u}|");
            }
            assert!((s.cross(t) - n).length() < 1e-12, "{n}: s × t ≠ n");
        }
    }
}
