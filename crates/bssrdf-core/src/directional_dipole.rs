//! Directional dipole (FHK14). This module currently holds the modified tangent-plane normal,
//! which the estimators reuse to orient their averaging ellipse.

use glam::DVec3;

/// FHK14's modified normal `n_i* = x̂ × (n_i × x̂) / |n_i × x̂|`, with `x̂ = (x_o − x_i)/|x_o − x_i|`;
/// equivalently `normalize(n_i − (n_i·x̂) x̂)`: `n_i` projected onto the plane perpendicular to
/// the chord, so the plane through `x_i` with this normal also contains `x_o` (physics notes §3).
///
/// Undefined when `x_o = x_i` or `n_i ∥ x̂`; in those cases (chord shorter than 1e-12 of the
/// coordinates' scale, or `|n_i × x̂| < 1e-9`) it returns `n_i` normalised, as the notes advise.
/// `n_i` must be non-zero; the result is always a finite unit vector when it is.
pub fn modified_normal(n_i: DVec3, x_i: DVec3, x_o: DVec3) -> DVec3 {
    let n = n_i.normalize_or(DVec3::Z);
    let chord = x_o - x_i;
    let len = chord.length();
    let scale = x_i
        .abs()
        .max_element()
        .max(x_o.abs().max_element())
        .max(1.0);
    if len.is_nan() || len <= 1e-12 * scale {
        return n;
    }
    let xh = chord / len;
    let proj = n - n.dot(xh) * xh;
    let plen = proj.length();
    if plen < 1e-9 {
        return n;
    }
    proj / plen
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn modified_normal_is_perpendicular_to_chord_and_matches_cross_form() {
        let n_i = DVec3::new(0.2, -0.1, 1.0).normalize();
        let x_i = DVec3::new(0.3, 0.1, 0.0);
        let x_o = DVec3::new(-1.0, 2.0, 0.5);
        let m = modified_normal(n_i, x_i, x_o);
        let xh = (x_o - x_i).normalize();
        assert!(m.dot(xh).abs() < 1e-12);
        assert!((m.length() - 1.0).abs() < 1e-12);
        let c = n_i.cross(xh);
        let cross_form = xh.cross(c) / c.length();
        assert!((m - cross_form).length() < 1e-12);
    }

    #[test]
    fn degenerate_cases_fall_back_to_n_i() {
        let n = DVec3::Z;
        assert_eq!(modified_normal(n, DVec3::ONE, DVec3::ONE), n);
        assert_eq!(
            modified_normal(n, DVec3::ZERO, DVec3::new(0.0, 0.0, 2.0)),
            n
        );
        assert_eq!(
            modified_normal(n, DVec3::ZERO, DVec3::new(0.0, 0.0, -2.0)),
            n
        );
    }
}
