//! Local frames about a unit vector.

use glam::DVec3;

/// An orthonormal basis `(t, b)` completing the unit vector `n`, so that `(t, b, n)` is
/// right-handed (Duff et al. 2017, "Building an Orthonormal Basis, Revisited"; key `DBA17` in
/// `docs/references.md`): branch-free and continuous except where `n.z` changes sign at −0.
pub fn orthonormal_basis(n: DVec3) -> (DVec3, DVec3) {
    let sign = 1.0f64.copysign(n.z);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    (
        DVec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x),
        DVec3::new(b, sign + n.y * n.y * a, -n.y),
    )
}
