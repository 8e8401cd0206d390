//! The chord x_i–x_o and the averaging plane through it (paper §3.1, Figure 3).

use glam::DVec3;

use crate::ellipse::PlanarEllipse;

/// Chords shorter than this fraction of the coordinates' magnitude are treated as d = 0
/// (their direction is rounding noise).
const DEGENERATE_CHORD: f64 = 1e-12;
/// A plane normal whose cosine with the chord exceeds this is not perpendicular to it.
const NOT_PERPENDICULAR: f64 = 1e-6;
/// `|n_i + n_o|²` below this: the two normals (nearly) cancel and their sum has no direction.
const NORMALS_CANCEL: f64 = 1e-12;

/// `v` or `−v`, whichever is lexicographically positive (a plane normal's sign is arbitrary;
/// fixing it makes the frame, and so the sample points, independent of the point order).
fn canonical(v: DVec3) -> DVec3 {
    if v.x < 0.0 || (v.x == 0.0 && (v.y < 0.0 || (v.y == 0.0 && v.z < 0.0))) {
        -v
    } else {
        v
    }
}

/// The chord and its averaging frame.
///
/// Orientation is canonical: the chord direction x̂ is ±(x_o − x_i)/d with the sign chosen so
/// that x̂ is lexicographically positive, and all points are built from the midpoint m. With
/// the plane normal symmetric in the two points too (below), swapping x_i and x_o gives
/// bit-identical sample points, which makes every averaging estimator exactly symmetric
/// (reciprocity, docs/reciprocity.md), with the same random numbers.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Chord {
    /// Midpoint m = (x_i + x_o)/2.
    pub mid: DVec3,
    /// Half the chord length, d/2.
    pub half_len: f64,
    /// Unit chord direction x̂ (canonical sign).
    pub x_hat: DVec3,
    /// Unit normal of the averaging plane, ⟂ x̂: FHK14's modified normal of n_i + n_o (so the
    /// plane does not depend on which point is x_i), with a canonical sign.
    pub normal: DVec3,
    /// Unit in-plane direction `normal × x̂` of the minor axis.
    pub minor_dir: DVec3,
    /// The modified normal of n_i + n_o was undefined and a fallback was used.
    pub normal_fallback: bool,
}

impl Chord {
    /// The chord and frame for (x_i, n_i) → (x_o, n_o); `None` when d is 0 (or below
    /// rounding noise, or the positions are not finite), where the region estimators reduce
    /// to point lookups.
    ///
    /// Plane normal: the paper uses n_i* = `modified_normal(n_i, x_i, x_o)` (FHK14), which
    /// depends on which point is x_i, so the estimate would not be reciprocal on curved
    /// surfaces. We use the modified normal of n_i + n_o instead: the same as n_i* wherever
    /// n_i = n_o (a plane), and symmetric in the two points everywhere. Where that is undefined
    /// (n_i + n_o ∥ x̂, or the normals cancel), that of n_i − n_o; failing that any
    /// unit vector ⟂ x̂ (the averaging plane must contain the chord). Every normal gets a
    /// canonical sign.
    pub fn new(x_i: DVec3, n_i: DVec3, x_o: DVec3, n_o: DVec3) -> Option<Self> {
        let diff = x_o - x_i;
        let d = diff.length();
        let scale = x_i.abs().max_element().max(x_o.abs().max_element());
        if !(d.is_finite() && scale.is_finite()) || d == 0.0 || d <= DEGENERATE_CHORD * scale {
            return None;
        }
        let mut x_hat = diff / d;
        if x_hat.x < 0.0 || (x_hat.x == 0.0 && (x_hat.y < 0.0 || (x_hat.y == 0.0 && x_hat.z < 0.0)))
        {
            x_hat = -x_hat;
        }
        // FHK14's modified normal of n (n's component perpendicular to the chord, normalised,
        // with a canonical sign), computed from x̂ at hand; `None` where n has no direction
        // or lies along the chord (a NaN n has neither).
        let modified = |n: DVec3| {
            let n_len2 = n.length_squared();
            let proj = n - n.dot(x_hat) * x_hat;
            let proj_len2 = proj.length_squared();
            let m = canonical(proj / proj_len2.sqrt());
            (n_len2 >= NORMALS_CANCEL
                && proj_len2 > 1e-18 * n_len2
                && m.is_finite()
                && m.dot(x_hat).abs() <= NOT_PERPENDICULAR)
                .then_some(m)
        };
        // The same plane whichever point is x_i: the modified normal of n_i + n_o
        // (commutative, so bit-identical under the swap). Where that is undefined (n_i + n_o
        // ∥ x̂, or the normals nearly cancel, as on the two faces of a slab), that of n_i − n_o
        // (≈ 2n_i there; negated by the swap, which the canonical sign undoes); failing that,
        // any unit vector ⟂ x̂.
        let (normal, normal_fallback) = match modified(n_i + n_o) {
            Some(m) => (m, false),
            None => (
                modified(n_i - n_o).unwrap_or_else(|| x_hat.any_orthonormal_vector()),
                true,
            ),
        };
        // Unit to rounding: the cross product of two orthogonal unit vectors.
        let minor_dir = normal.cross(x_hat);
        Some(Self {
            mid: 0.5 * (x_i + x_o),
            half_len: 0.5 * d,
            x_hat,
            normal,
            minor_dir,
            normal_fallback,
        })
    }

    /// Chord length d.
    pub fn length(&self) -> f64 {
        2.0 * self.half_len
    }

    /// The point of the chord at parameter `t` ∈ [0, 1] (t = ½ is the midpoint).
    #[inline]
    pub fn point(&self, t: f64) -> DVec3 {
        self.mid + ((2.0 * t - 1.0) * self.half_len) * self.x_hat
    }

    /// The ellipse in the averaging plane with semi-major axis d/2 along x̂ and semi-minor
    /// axis `b` along n_i* × x̂, centred at m (b = d/2 gives the step-1 disk).
    pub fn ellipse(&self, b: f64) -> PlanarEllipse {
        PlanarEllipse {
            centre: self.mid,
            semi_major: self.half_len * self.x_hat,
            semi_minor: b * self.minor_dir,
            normal: self.normal,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use bssrdf_core::directional_dipole::modified_normal;

    #[test]
    fn frame_is_orthonormal_and_contains_the_chord() {
        let x_i = DVec3::new(0.3, -1.0, 0.2);
        let x_o = DVec3::new(-2.0, 0.5, 0.9);
        let n_i = DVec3::new(0.1, 0.2, 1.0).normalize();
        let c = Chord::new(x_i, n_i, x_o, DVec3::Z).unwrap();
        assert!(!c.normal_fallback);
        for (a, b) in [
            (c.x_hat, c.normal),
            (c.x_hat, c.minor_dir),
            (c.normal, c.minor_dir),
        ] {
            assert!(a.dot(b).abs() < 1e-12);
        }
        for v in [c.x_hat, c.normal, c.minor_dir] {
            assert!((v.length() - 1.0).abs() < 1e-12);
        }
        // The endpoints are the chord's ends (in some order).
        let (p0, p1) = (c.point(0.0), c.point(1.0));
        let ok = |p: DVec3, q: DVec3| (p - q).length() < 1e-12;
        assert!((ok(p0, x_i) && ok(p1, x_o)) || (ok(p0, x_o) && ok(p1, x_i)));
        // The plane through m with normal n_i* contains x_i and x_o.
        assert!((x_i - c.mid).dot(c.normal).abs() < 1e-12);
        assert!((x_o - c.mid).dot(c.normal).abs() < 1e-12);
    }

    #[test]
    fn swapping_the_endpoints_gives_the_same_frame() {
        let x_i = DVec3::new(0.3, -1.0, 0.0);
        let x_o = DVec3::new(-2.0, 0.5, 0.0);
        let a = Chord::new(x_i, DVec3::Z, x_o, DVec3::Z).unwrap();
        let b = Chord::new(x_o, DVec3::Z, x_i, DVec3::Z).unwrap();
        assert_eq!(a.mid, b.mid);
        assert_eq!(a.x_hat, b.x_hat);
        assert_eq!(a.normal, b.normal);
        assert_eq!(a.minor_dir, b.minor_dir);
    }

    /// Different normals (a curved surface): the frame is still bit-identical under the
    /// swap, and differs from the frame the paper's n_i* alone would give.
    #[test]
    fn swapping_points_with_different_normals_gives_the_same_frame() {
        let x_i = DVec3::new(0.3, -1.0, 0.1);
        let x_o = DVec3::new(-2.0, 0.5, -0.4);
        let n_i = DVec3::new(0.3, 0.1, 1.0).normalize();
        let n_o = DVec3::new(-0.4, 0.2, 0.9).normalize();
        let a = Chord::new(x_i, n_i, x_o, n_o).unwrap();
        let b = Chord::new(x_o, n_o, x_i, n_i).unwrap();
        assert!(!a.normal_fallback);
        assert_eq!(
            (a.mid, a.half_len, a.x_hat, a.normal, a.minor_dir),
            (b.mid, b.half_len, b.x_hat, b.normal, b.minor_dir)
        );
        for t in [0.0, 0.3, 1.0] {
            assert_eq!(a.point(t), b.point(t));
        }
        let paper = canonical(modified_normal(n_i, x_i, x_o));
        assert!((paper - a.normal).length() > 1e-3);
    }

    /// The plane normal is FHK14's modified normal of n_i + n_o (computed here without its
    /// own normalisations), on random pairs to rounding.
    #[test]
    fn the_normal_is_the_modified_normal_of_the_sum() {
        let mut k = 0.0f64;
        let mut next = || {
            k += 1.0;
            DVec3::new((1.3 * k).sin(), (2.1 * k).cos(), (0.7 * k).sin())
        };
        for _ in 0..1000 {
            let (x_i, x_o) = (5.0 * next(), 5.0 * next());
            let (n_i, n_o) = (next().normalize(), next().normalize());
            let c = Chord::new(x_i, n_i, x_o, n_o).unwrap();
            if c.normal_fallback {
                continue;
            }
            let want = canonical(modified_normal(n_i + n_o, x_i, x_o));
            assert!(
                (c.normal - want).length() < 1e-13,
                "{:?} {want:?}",
                c.normal
            );
            assert!((c.minor_dir.length() - 1.0).abs() < 1e-15);
        }
    }

    #[test]
    fn degenerate_cases() {
        let p = DVec3::new(1.0, 2.0, 3.0);
        assert!(Chord::new(p, DVec3::Z, p, DVec3::Z).is_none());
        assert!(Chord::new(p, DVec3::Z, p + DVec3::splat(1e-14), DVec3::Z).is_none());
        assert!(Chord::new(p, DVec3::Z, DVec3::splat(f64::NAN), DVec3::Z).is_none());
        // n_i ∥ chord and n_o ∥ chord: any perpendicular normal.
        let c = Chord::new(DVec3::ZERO, DVec3::Z, DVec3::new(0.0, 0.0, -2.0), -DVec3::Z).unwrap();
        assert!(c.normal_fallback);
        assert!(c.normal.dot(c.x_hat).abs() < 1e-12);
        assert!((c.minor_dir.length() - 1.0).abs() < 1e-12);
        // n_i ∥ chord but n_i + n_o usable: no fallback needed, the same plane both ways.
        let n_o = DVec3::new(1.0, 0.0, 1.0).normalize();
        let end = DVec3::new(0.0, 0.0, 1.0);
        let c = Chord::new(DVec3::ZERO, DVec3::Z, end, n_o).unwrap();
        assert!(!c.normal_fallback);
        assert!((c.normal - DVec3::X).length() < 1e-12);
        let swapped = Chord::new(end, n_o, DVec3::ZERO, DVec3::Z).unwrap();
        assert_eq!(c.normal, swapped.normal);
        // Opposite normals (the two faces of a slab), chord not along them: n_i − n_o's plane,
        // the same both ways.
        let (top, bottom) = (DVec3::ZERO, DVec3::new(0.3, 0.1, -2.0));
        let c = Chord::new(top, DVec3::Z, bottom, -DVec3::Z).unwrap();
        let swapped = Chord::new(bottom, -DVec3::Z, top, DVec3::Z).unwrap();
        assert!(c.normal_fallback && c.normal.dot(c.x_hat).abs() < 1e-12);
        assert_eq!((c.normal, c.minor_dir), (swapped.normal, swapped.minor_dir));
    }
}
