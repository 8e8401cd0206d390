//! The surface around a pair (x_i, x_o) as a quadric over the averaging plane: what lets the
//! estimators prefilter, and place their sample points without projection rays, on curved
//! surfaces (`docs/physics.md#prefiltered-averages`, "Curved surfaces").
//!
//! # The model
//! In the averaging plane's frame (m the chord's midpoint, u along the chord x̂, v along the
//! minor axis ŷ = n* × x̂, heights along the plane normal ŝ oriented out of the medium), a
//! smooth surface through x_i and x_o (at u = ±a, a = d/2, v = 0) is, to second order, the
//! height field
//!
//! `f(u, v) = ½·(H_uu·(u² − a²) + 2·H_uv·u·v + H_vv·v²)`,
//!
//! with H = −C̄ the negated mean of the surface's curvature tensors at the two ends
//! ([`Curvature`], restricted to the plane). The constant and linear terms are fixed by the
//! data: f vanishes at both ends (they lie in the plane), and the mean slope across the chord is
//! zero because the plane's normal is the modified normal of n_i + n_o (`chord.rs`), which has
//! no component along ŷ. A point p of the plane stands for the surface point p + f(p)·ŝ, which
//! is where the estimators' projection rays (paper §3.2, Figure 3) meet a surface of that shape.
//!
//! # What it may be trusted for
//! The model is checked against what it did not use, the shading normals at the ends: the
//! slopes it predicts there, (H_uu·u_e, H_uv·u_e), against the slopes the normals give,
//! −(n·x̂, n·ŷ)/(n·ŝ). The largest difference `slope_error` (a crease, a kink in the shading
//! normals, a curvature that changes between the ends) bounds how far the true surface can
//! be from the model over a region of radius R around m:
//!
//! `ε(R) = excess·(R + a) + ½·‖C_i − C_o‖·(R + a)² + κ³·(R + a)⁴/8`
//!
//! (‖C_i − C_o‖ of the two tensors as forms on the plane, so that the turning of the tangent
//! planes between the ends does not count as a change of curvature)
//!
//! (a slope error at an end integrates over at most R + a; a curvature that differs between the
//! ends by ΔC departs from their mean by ΔC/2 over that distance; a quadric misses a sphere of
//! curvature κ by κ³ρ⁴/8 at distance ρ, its fourth-order term). `excess` is the slope error
//! beyond the 2·(κa)³ that a smooth surface's own fourth-order term leaves at the ends (a
//! sphere's: 1.5·(κa)³), which the last term already counts. The model is refused where
//! the ends' normals lean more than about 37° from the plane's normal, where the slope error
//! exceeds [`MAX_SLOPE_ERROR`], or where the region bends by more than [`MAX_BEND`]
//! (κ_max·R: beyond it the surface is no longer a height field over the region, and a
//! small object may end inside the region).
//!
//! # Reciprocity
//! Every quantity is computed from the two ends through commutative operations (sums,
//! maxima, norms of differences), and the frame is the chord's canonical one, so swapping x_i
//! and x_o gives the same model bit for bit (`docs/reciprocity.md`).

use glam::{DMat3, DVec3};

use crate::ellipse::PlanarEllipse;

/// Largest difference between the slopes the model predicts at an end and those its shading
/// normal gives (radians, about): beyond it the surface between x_i and x_o is not one smooth
/// quadric (a crease, a corner, a kink in the normals), and the regions are projected by rays.
pub const MAX_SLOPE_ERROR: f64 = 0.1;
/// Largest κ_max·R over a region (κ_max the model's largest principal curvature, R the
/// region's largest semi-axis): a region that spans more than about 30° of arc is projected by
/// rays.
pub const MAX_BEND: f64 = 0.5;
/// Smallest cosine between an end's normal and the plane's normal (about 37°).
const MIN_NORMAL_COSINE: f64 = 0.8;

/// The curvature of a surface at a point: its second fundamental form, as a symmetric tensor C
/// in world coordinates (1/length) whose restriction to the tangent plane is the shape
/// operator, with the sign convention that the surface near p is
/// `p + x − ½·(xᵀ·C·x)·n` for a tangent vector x and the unit normal n pointing out of the
/// medium: a convex body has C ≥ 0 (a sphere of radius R: C = (I − n nᵀ)/R).
///
/// Equivalently the normal changes along the surface as dn = C·dx (the Weingarten equation),
/// which is how meshes estimate it from their shading normals (RUS04).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Curvature {
    /// The symmetric tensor's components `[xx, yy, zz, xy, xz, yz]` (1/length).
    c: [f64; 6],
}

impl Curvature {
    /// A flat surface.
    pub const ZERO: Curvature = Curvature { c: [0.0; 6] };

    /// The tensor `m` (symmetrised: (m + mᵀ)/2); `None` where it is not finite.
    pub fn from_matrix(m: DMat3) -> Option<Curvature> {
        let s = |i: usize, j: usize| 0.5 * (m.col(j)[i] + m.col(i)[j]);
        let c = [s(0, 0), s(1, 1), s(2, 2), s(0, 1), s(0, 2), s(1, 2)];
        c.iter().all(|v| v.is_finite()).then_some(Curvature { c })
    }

    /// The tensor from its components `[xx, yy, zz, xy, xz, yz]`; `None` where one is not
    /// finite.
    pub fn from_components(c: [f64; 6]) -> Option<Curvature> {
        c.iter().all(|v| v.is_finite()).then_some(Curvature { c })
    }

    /// Curvature `k` in every tangent direction of the plane with unit normal `n` (a sphere of
    /// radius 1/k): k·(I − n nᵀ).
    pub fn isotropic(k: f64, n: DVec3) -> Option<Curvature> {
        Self::from_matrix(k * (DMat3::IDENTITY - outer(n, n)))
    }

    /// The components `[xx, yy, zz, xy, xz, yz]`.
    pub fn components(&self) -> [f64; 6] {
        self.c
    }

    /// `aᵀ·C·b`.
    #[inline]
    pub fn form(&self, a: DVec3, b: DVec3) -> f64 {
        let [xx, yy, zz, xy, xz, yz] = self.c;
        a.x * (xx * b.x + xy * b.y + xz * b.z)
            + a.y * (xy * b.x + yy * b.y + yz * b.z)
            + a.z * (xz * b.x + yz * b.y + zz * b.z)
    }

    /// The Frobenius norm (an upper bound on every principal curvature's magnitude).
    #[inline]
    pub fn norm(&self) -> f64 {
        let [xx, yy, zz, xy, xz, yz] = self.c;
        (xx * xx + yy * yy + zz * zz + 2.0 * (xy * xy + xz * xz + yz * yz)).sqrt()
    }

    /// The component-wise sum (the mean of two tensors is `0.5 * (a + b)`, symmetric in a, b).
    #[inline]
    fn plus(&self, o: &Curvature) -> Curvature {
        Curvature {
            c: std::array::from_fn(|k| self.c[k] + o.c[k]),
        }
    }

    /// The component-wise difference.
    #[inline]
    fn minus(&self, o: &Curvature) -> Curvature {
        Curvature {
            c: std::array::from_fn(|k| self.c[k] - o.c[k]),
        }
    }
}

#[inline]
fn outer(a: DVec3, b: DVec3) -> DMat3 {
    DMat3::from_cols(a * b.x, a * b.y, a * b.z)
}

/// One end of the pair, as the model sees it.
#[derive(Debug, Clone, Copy)]
pub(crate) struct End {
    /// Position (scene units).
    pub position: DVec3,
    /// Unit shading normal, out of the medium.
    pub normal: DVec3,
    /// The surface's curvature there.
    pub curvature: Curvature,
}

/// The quadric over a pair's averaging plane (module docs).
#[derive(Debug, Clone, Copy)]
pub(crate) struct LocalSurface {
    mid: DVec3,
    x_hat: DVec3,
    y_hat: DVec3,
    /// The plane's normal, oriented out of the medium.
    out: DVec3,
    /// Half the chord length.
    a: f64,
    /// H = −C̄ in the plane's frame.
    h_uu: f64,
    h_uv: f64,
    h_vv: f64,
    /// The largest principal curvature of the model (1/length).
    kappa: f64,
    /// Largest slope difference at the ends (module docs).
    slope_error: f64,
    /// ‖C_i − C_o‖ as forms on the plane (Frobenius).
    curvature_change: f64,
}

impl LocalSurface {
    /// The model for the chord (midpoint `mid`, half length `a`, unit axes `x_hat` and
    /// `y_hat`, unit plane normal `normal`, of either sign) and its two ends; `None` where
    /// an end's normal leans too far from the plane's, where the slopes at the ends contradict
    /// the curvature (more than [`MAX_SLOPE_ERROR`]), or where the input is not finite.
    pub fn new(
        mid: DVec3,
        a: f64,
        x_hat: DVec3,
        y_hat: DVec3,
        normal: DVec3,
        ends: [&End; 2],
    ) -> Option<LocalSurface> {
        let sum = ends[0].normal + ends[1].normal;
        let out = if sum.dot(normal) >= 0.0 {
            normal
        } else {
            -normal
        };
        let mean = ends[0].curvature.plus(&ends[1].curvature);
        let h_uu = -0.5 * mean.form(x_hat, x_hat);
        let h_uv = -0.5 * mean.form(x_hat, y_hat);
        let h_vv = -0.5 * mean.form(y_hat, y_hat);
        // The 2 × 2 form's largest eigenvalue magnitude.
        let half_trace = 0.5 * (h_uu + h_vv);
        let radius = (0.25 * (h_uu - h_vv).powi(2) + h_uv * h_uv).sqrt();
        let kappa = half_trace.abs() + radius;
        let mut slope_error: f64 = 0.0;
        for e in ends {
            let n_s = e.normal.dot(out);
            if n_s.is_nan() || n_s < MIN_NORMAL_COSINE {
                return None;
            }
            let u = (e.position - mid).dot(x_hat);
            let (su, sv) = (-e.normal.dot(x_hat) / n_s, -e.normal.dot(y_hat) / n_s);
            let err = ((su - h_uu * u).powi(2) + (sv - h_uv * u).powi(2)).sqrt();
            slope_error = slope_error.max(err);
        }
        // The change of the curvature between the ends, as forms on the plane (the tensors'
        // tangent planes turn with the normals, which is not a change of curvature).
        let diff = ends[0].curvature.minus(&ends[1].curvature);
        let (d_uu, d_uv, d_vv) = (
            diff.form(x_hat, x_hat),
            diff.form(x_hat, y_hat),
            diff.form(y_hat, y_hat),
        );
        let curvature_change = (d_uu * d_uu + 2.0 * d_uv * d_uv + d_vv * d_vv).sqrt();
        let model = LocalSurface {
            mid,
            x_hat,
            y_hat,
            out,
            a,
            h_uu,
            h_uv,
            h_vv,
            kappa,
            slope_error,
            curvature_change,
        };
        (slope_error <= MAX_SLOPE_ERROR && kappa.is_finite() && curvature_change.is_finite())
            .then_some(model)
    }

    /// The region's semi-axis lengths `(along the chord, across it)`.
    #[inline]
    fn semi_axes(e: &PlanarEllipse) -> (f64, f64) {
        (e.semi_major.length(), e.semi_minor.length())
    }

    /// Whether the model holds over the region `e` (centred at the midpoint, in the plane):
    /// it bends by at most [`MAX_BEND`] over the region's largest semi-axis.
    pub fn covers(&self, e: &PlanarEllipse) -> bool {
        let (sa, sb) = Self::semi_axes(e);
        self.kappa * sa.max(sb) <= MAX_BEND
    }

    /// How far the true surface may be from the model over the region `e` (scene units):
    /// ε(R) of the module docs, R the region's largest semi-axis.
    pub fn model_error(&self, e: &PlanarEllipse) -> f64 {
        let (sa, sb) = Self::semi_axes(e);
        self.error_within(sa.max(sb))
    }

    /// ε(R) for a disk of radius `r` around the midpoint (module docs).
    fn error_within(&self, r: f64) -> f64 {
        let reach = r + self.a;
        let k = self.kappa;
        self.excess_slope() * reach
            + 0.5 * self.curvature_change * reach * reach
            + 0.125 * k * k * k * reach.powi(4)
    }

    /// The part of the ends' slope error that a smooth surface of the model's curvature does
    /// not explain: a sphere's quadric misses its slopes at the ends by 1.5·(κa)³ (its
    /// fourth-order term), so 2·(κa)³ of the error is taken as truncation, already counted by
    /// ε's last term.
    fn excess_slope(&self) -> f64 {
        (self.slope_error - 2.0 * (self.kappa * self.a).powi(3)).max(0.0)
    }

    /// The largest R such that a disk of radius R around the midpoint is covered
    /// (κ_max·R ≤ [`MAX_BEND`]) and ε(R) ≤ `tolerance` (scene units); 0 where none is, ∞ for
    /// an exactly flat pair.
    pub fn lifting_radius(&self, tolerance: f64) -> f64 {
        let bend = if self.kappa > 0.0 {
            MAX_BEND / self.kappa
        } else {
            f64::INFINITY
        };
        if self.error_within(0.0) > tolerance {
            return 0.0;
        }
        if self.error_within(bend) <= tolerance {
            return bend;
        }
        // ε grows with R: bisect for ε(R) = tolerance within 1e-3 of the bend radius (or of
        // the chord where the bend radius is unbounded and ε is not).
        let (mut lo, mut hi) = if bend.is_finite() {
            (0.0, bend)
        } else {
            let mut hi = self.a.max(f64::MIN_POSITIVE);
            while self.error_within(hi) <= tolerance && hi < f64::MAX / 4.0 {
                hi *= 2.0;
            }
            (0.0, hi)
        };
        for _ in 0..40 {
            let mid = 0.5 * (lo + hi);
            if self.error_within(mid) <= tolerance {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        lo
    }

    /// The largest height of the model over the region `e` (scene units), a bound:
    /// |f| ≤ ½·(|H_uu|·a² + |H_uv|·a·b + |H_vv|·b²) for |u| ≤ a (the region's extent along
    /// the chord), |u·v| ≤ a·b/2, v² ≤ b².
    pub fn max_height(&self, e: &PlanarEllipse) -> f64 {
        let (sa, sb) = Self::semi_axes(e);
        0.5 * (self.h_uu.abs() * sa.max(self.a).powi(2)
            + self.h_uv.abs() * sa * sb
            + self.h_vv.abs() * sb * sb)
    }

    /// The model's height at the plane point `p` (scene units, out of the medium).
    #[inline]
    pub fn height(&self, p: DVec3) -> f64 {
        let r = p - self.mid;
        let (u, v) = (r.dot(self.x_hat), r.dot(self.y_hat));
        0.5 * (self.h_uu * (u * u - self.a * self.a) + 2.0 * self.h_uv * u * v + self.h_vv * v * v)
    }

    /// The surface point that stands for the plane point `p`: `p + f(p)·ŝ`.
    #[inline]
    pub fn lift(&self, p: DVec3) -> DVec3 {
        p + self.height(p) * self.out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The ends of a chord of the sphere of radius `r` centred at the origin, between the unit
    /// directions `p` and `q`.
    fn sphere_ends(r: f64, p: DVec3, q: DVec3) -> [End; 2] {
        [p, q].map(|d| {
            let n = d.normalize();
            End {
                position: r * n,
                normal: n,
                curvature: Curvature::isotropic(1.0 / r, n).unwrap(),
            }
        })
    }

    fn model(ends: &[End; 2]) -> Option<LocalSurface> {
        let c = crate::chord::Chord::new(
            ends[0].position,
            ends[0].normal,
            ends[1].position,
            ends[1].normal,
        )
        .unwrap();
        LocalSurface::new(
            c.mid,
            c.half_len,
            c.x_hat,
            c.minor_dir,
            c.normal,
            [&ends[0], &ends[1]],
        )
    }

    /// On a sphere the lifted points of the averaging plane lie on the sphere to third order:
    /// within κ²·R⁴/4 + 2·(a/R)³·R-ish of it for regions up to [`MAX_BEND`].
    #[test]
    fn lifted_points_lie_on_a_sphere() {
        let r = 10.0;
        for (p, q) in [
            (DVec3::new(0.1, 0.2, 1.0), DVec3::new(0.3, -0.1, 1.0)),
            (DVec3::new(1.0, 0.05, 0.1), DVec3::new(0.9, 0.2, 0.3)),
            (DVec3::new(-0.3, -0.7, -0.5), DVec3::new(-0.4, -0.6, -0.55)),
        ] {
            let ends = sphere_ends(r, p, q);
            let m = model(&ends).expect("a sphere is smooth");
            let c = crate::chord::Chord::new(
                ends[0].position,
                ends[0].normal,
                ends[1].position,
                ends[1].normal,
            )
            .unwrap();
            let a = c.half_len;
            for b in [0.5 * a, a, 3.0 * a] {
                let e = c.ellipse(b);
                if !m.covers(&e) {
                    continue;
                }
                let bound = m.model_error(&e);
                for k in 0..64 {
                    let t = k as f64 * 0.3;
                    let u = glam::DVec2::new(t.cos(), t.sin()) * ((k % 8) as f64 / 8.0).sqrt();
                    let x = m.lift(e.point(u));
                    let off = (x.length() - r).abs();
                    assert!(off <= bound, "{off} > {bound} (a {a}, b {b})");
                    assert!(m.height(e.point(u)).abs() <= m.max_height(&e) * (1.0 + 1e-12));
                }
            }
            // The model's own error is small on a sphere: the slopes agree to (a/R)³.
            assert!(m.slope_error <= 2.0 * (a / r).powi(3), "{}", m.slope_error);
        }
    }

    /// Swapping the ends gives the same model, bit for bit.
    #[test]
    fn the_model_is_symmetric_in_the_ends() {
        let ends = sphere_ends(3.0, DVec3::new(0.2, 0.1, 1.0), DVec3::new(-0.1, 0.3, 1.0));
        let (a, b) = (model(&ends).unwrap(), model(&[ends[1], ends[0]]).unwrap());
        assert_eq!(format!("{a:?}"), format!("{b:?}"));
    }

    /// A crease (a box's edge: two faces with curvature zero whose normals differ by 90°)
    /// is refused, and a flat pair has height zero everywhere.
    #[test]
    fn a_crease_is_refused_and_a_plane_is_flat() {
        let top = End {
            position: DVec3::new(0.0, 0.0, 0.0),
            normal: DVec3::Z,
            curvature: Curvature::ZERO,
        };
        let side = End {
            position: DVec3::new(1.0, 0.0, -0.5),
            normal: DVec3::X,
            curvature: Curvature::ZERO,
        };
        assert!(model(&[top, side]).is_none());
        let other = End {
            position: DVec3::new(1.0, 2.0, 0.0),
            ..top
        };
        let m = model(&[top, other]).unwrap();
        assert_eq!(m.height(DVec3::new(5.0, -3.0, 0.0)), 0.0);
        assert_eq!(
            m.model_error(&PlanarEllipse {
                centre: DVec3::ZERO,
                semi_major: DVec3::X,
                semi_minor: DVec3::Y,
                normal: DVec3::Z,
            }),
            0.0
        );
        // A small kink between two flat faces (a tilt t = 0.05 about y at the far end): the
        // tilted end's slope differs from the flat model's by t/√5 along the chord (1, 2, 0)
        // and, the plane taking half the tilt across it, by t/√5 across: t·√(2/5).
        let tilted = DVec3::new(0.05, 0.0, 1.0).normalize();
        let kinked = End {
            normal: tilted,
            ..other
        };
        let m = model(&[top, kinked]).unwrap();
        let want = 0.05 * (0.4f64).sqrt();
        assert!(
            (m.slope_error - want).abs() < 1e-3 * want,
            "{}",
            m.slope_error
        );
    }

    /// `form` is xᵀ·C·y, and the isotropic tensor is tangent to its plane.
    #[test]
    fn curvature_forms() {
        let n = DVec3::new(1.0, 2.0, 2.0) / 3.0;
        let c = Curvature::isotropic(0.5, n).unwrap();
        assert!(c.form(n, n).abs() < 1e-15);
        let t = n.any_orthonormal_vector();
        assert!((c.form(t, t) - 0.5).abs() < 1e-15);
        assert!((c.norm() - 0.5 * 2f64.sqrt()).abs() < 1e-15);
        assert!(Curvature::from_components([f64::NAN, 0.0, 0.0, 0.0, 0.0, 0.0]).is_none());
    }
}
