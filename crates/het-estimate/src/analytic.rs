//! Analytic implementations of the two traits, for tests, examples, benchmarks, the beam
//! experiments and the Python bindings: the infinite plane z = 0 and closed-form coefficient
//! fields over it.
//!
//! The plane's outward normal is +z (the medium fills z < 0). Fields are functions of the
//! point's (x, y), using the shared definitions of [`crate::pattern`].

use glam::{DVec2, DVec3};

use crate::ellipse::PlanarEllipse;
use crate::field::{CoefficientField, Coefficients, FieldBounds, FieldCapabilities};
use crate::pattern::{BinaryPattern, Check, Ramp, Stripe};
use crate::prefilter::{PlaneFootprint, check_fraction, stripe_fraction};
use crate::surface::{SurfacePoint, SurfaceQuery};

/// The infinite plane z = 0 with outward normal +z.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Plane;

/// A point (x, y, 0) of [`Plane`].
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PlanePoint {
    /// x coordinate (scene units).
    pub x: f64,
    /// y coordinate (scene units).
    pub y: f64,
}

impl PlanePoint {
    /// The point (x, y, 0).
    pub const fn new(x: f64, y: f64) -> Self {
        Self { x, y }
    }
}

impl SurfacePoint for PlanePoint {
    #[inline]
    fn position(&self) -> DVec3 {
        DVec3::new(self.x, self.y, 0.0)
    }
    #[inline]
    fn normal(&self) -> DVec3 {
        DVec3::Z
    }
}

impl SurfaceQuery for Plane {
    type Point = PlanePoint;

    /// The intersection of the line `origin + t·dir` with z = 0 (whichever of the two rays
    /// reaches it); `None` when `dir` is parallel to the plane (|dir.z| < 1e-12) or the
    /// intersection is not finite.
    #[inline]
    fn project(&self, origin: DVec3, dir: DVec3) -> Option<PlanePoint> {
        if dir.z.abs() < 1e-12 || !dir.z.is_finite() {
            return None;
        }
        let t = -origin.z / dir.z;
        let (x, y) = (origin.x + t * dir.x, origin.y + t * dir.y);
        (x.is_finite() && y.is_finite()).then_some(PlanePoint { x, y })
    }
}

/// The same coefficients everywhere (bounds: constant, so estimators short-circuit).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ConstantField(pub Coefficients);

impl CoefficientField<PlanePoint> for ConstantField {
    #[inline]
    fn coefficients(&self, _: &PlanePoint) -> Coefficients {
        self.0
    }
    #[inline]
    fn bounds(&self) -> Option<FieldBounds> {
        Some(FieldBounds::constant(self.0))
    }
    fn ellipse_average(&self, _: &PlanarEllipse) -> Option<Coefficients> {
        Some(self.0)
    }
    fn capabilities(&self) -> FieldCapabilities {
        FieldCapabilities {
            ellipse_average: true,
            ..FieldCapabilities::default()
        }
    }
}

/// Two coefficient values arranged by a binary pattern (stripes, checks) of
/// [`crate::pattern`]: `values[pattern.select(x, y)]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PatternField<P> {
    /// The pattern.
    pub pattern: P,
    /// The value where the pattern selects 0 (the cell containing the origin), and 1.
    pub values: [Coefficients; 2],
}

/// Stripes of two coefficient values.
pub type StripeField = PatternField<Stripe>;
/// A checkerboard of two coefficient values.
pub type CheckField = PatternField<Check>;

/// The projection of a vector along `n` onto the plane z = 0, as (x, y); `None` when `n` is
/// parallel to the plane.
fn along_onto_plane(n: DVec3) -> Option<impl Fn(DVec3) -> DVec2> {
    (n.z.abs() >= 1e-12 && n.is_finite()).then_some(move |v: DVec3| {
        let p = v - n * (v.z / n.z);
        DVec2::new(p.x, p.y)
    })
}

/// A pattern with a closed-form average over a footprint in its plane (fraction of value 1).
pub trait FootprintPattern: BinaryPattern {
    /// The weighted fraction of `fp` where the pattern selects value 1, if it has a closed
    /// form ([`crate::prefilter`]).
    fn fraction(&self, fp: &PlaneFootprint) -> Option<f64>;
}

impl FootprintPattern for Stripe {
    fn fraction(&self, fp: &PlaneFootprint) -> Option<f64> {
        stripe_fraction(self, fp)
    }
}

impl FootprintPattern for Check {
    fn fraction(&self, fp: &PlaneFootprint) -> Option<f64> {
        check_fraction(self, fp)
    }
}

impl<P: FootprintPattern> CoefficientField<PlanePoint> for PatternField<P> {
    #[inline]
    fn coefficients(&self, p: &PlanePoint) -> Coefficients {
        self.values[self.pattern.select(p.x, p.y)]
    }

    /// The pattern at (x, y): it is a function of position alone (constant along z), so the
    /// kernel reads its points in the plane without projecting them.
    #[inline]
    fn averaged_at_point(&self, x: DVec3) -> Option<Coefficients> {
        Some(self.values[self.pattern.select(x.x, x.y)])
    }

    fn capabilities(&self) -> FieldCapabilities {
        FieldCapabilities {
            point_lookup: true,
            ellipse_average: true,
            ..FieldCapabilities::default()
        }
    }

    /// Exact: the plane is flat, so projecting the ellipse along its normal onto z = 0 is
    /// affine and the closed forms of [`crate::prefilter`] apply.
    fn ellipse_average(&self, e: &PlanarEllipse) -> Option<Coefficients> {
        let fp = PlaneFootprint::of_ellipse(e, along_onto_plane(e.normal)?);
        let f = self.pattern.fraction(&fp)?;
        let [v0, v1] = self.values;
        Some(Coefficients {
            sigma_a: v0.sigma_a * (1.0 - f) + v1.sigma_a * f,
            sigma_s: v0.sigma_s * (1.0 - f) + v1.sigma_s * f,
        })
    }

    #[inline]
    fn bounds(&self) -> Option<FieldBounds> {
        Some(FieldBounds {
            min: self.values[0].min(self.values[1]),
            max: self.values[0].max(self.values[1]),
        })
    }
}

/// Linear ramps per coefficient and channel, clamped below at 0:
/// `σ(x, y) = max(0, v0 + gx·x + gy·y)`.
///
/// Exactly linear (so that its average over a centrally symmetric region is its value at the
/// centre) wherever every ramp is ≥ 0; [`RampField::min_over_disk`] checks a disk. Bounds:
/// components with zero gradient are constant; the others range over [0, +∞).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RampField {
    /// σa ramp per channel.
    pub sigma_a: [Ramp; 3],
    /// σs ramp per channel.
    pub sigma_s: [Ramp; 3],
}

impl RampField {
    /// The same ramps in every channel.
    pub const fn grey(sigma_a: Ramp, sigma_s: Ramp) -> Self {
        Self {
            sigma_a: [sigma_a; 3],
            sigma_s: [sigma_s; 3],
        }
    }

    /// The unclamped linear values at (x, y).
    pub fn linear(&self, x: f64, y: f64) -> Coefficients {
        let mut c = Coefficients::default();
        for k in 0..3 {
            c.sigma_a[k] = self.sigma_a[k].value(x, y);
            c.sigma_s[k] = self.sigma_s[k].value(x, y);
        }
        c
    }

    fn ramps(&self) -> impl Iterator<Item = &Ramp> {
        self.sigma_a.iter().chain(self.sigma_s.iter())
    }

    /// The smallest unclamped value of any ramp over the disk of radius `r` centred at
    /// (x, y): the field is exactly linear there when this is ≥ 0.
    pub fn min_over_disk(&self, x: f64, y: f64, r: f64) -> f64 {
        self.ramps()
            .map(|q| q.value(x, y) - r * q.gradient[0].hypot(q.gradient[1]))
            .fold(f64::INFINITY, f64::min)
    }
}

impl CoefficientField<PlanePoint> for RampField {
    #[inline]
    fn coefficients(&self, p: &PlanePoint) -> Coefficients {
        let c = self.linear(p.x, p.y);
        Coefficients {
            sigma_a: c.sigma_a.map(|v| v.max(0.0)),
            sigma_s: c.sigma_s.map(|v| v.max(0.0)),
        }
    }

    #[inline]
    fn bounds(&self) -> Option<FieldBounds> {
        let range = |q: &Ramp| {
            if q.gradient == [0.0, 0.0] {
                (q.v0.max(0.0), q.v0.max(0.0))
            } else {
                (0.0, f64::INFINITY)
            }
        };
        let mut b = FieldBounds::constant(Coefficients::default());
        for k in 0..3 {
            (b.min.sigma_a[k], b.max.sigma_a[k]) = range(&self.sigma_a[k]);
            (b.min.sigma_s[k], b.max.sigma_s[k]) = range(&self.sigma_s[k]);
        }
        Some(b)
    }

    /// Exact when the projected ellipse lies where every ramp is ≥ 0: projection along the
    /// ellipse normal onto z = 0 is affine, so the projected area measure is uniform on the
    /// projected ellipse and a linear function averages to its value at the projected centre.
    /// `None` otherwise (clamping active, or normal parallel to the plane).
    fn ellipse_average(&self, e: &PlanarEllipse) -> Option<Coefficients> {
        let n = e.normal;
        if n.z.abs() < 1e-12 {
            return None;
        }
        let along = |v: DVec3| v - n * (v.z / n.z); // projection of a vector onto z = 0
        let c = along(e.centre);
        let (u, v) = (along(e.semi_major), along(e.semi_minor));
        let ok = self.ramps().all(|q| {
            let (gu, gv) = (
                q.gradient[0] * u.x + q.gradient[1] * u.y,
                q.gradient[0] * v.x + q.gradient[1] * v.y,
            );
            q.value(c.x, c.y) - gu.hypot(gv) >= 0.0
        });
        ok.then(|| self.linear(c.x, c.y))
    }

    fn capabilities(&self) -> FieldCapabilities {
        FieldCapabilities {
            ellipse_average: true,
            ..FieldCapabilities::default()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use bssrdf_core::Rgb;

    #[test]
    fn plane_projection() {
        let p = Plane
            .project(DVec3::new(1.0, 2.0, 3.0), DVec3::new(0.0, 0.6, 0.8))
            .unwrap();
        assert!((p.x - 1.0).abs() < 1e-15 && (p.y - (2.0 - 2.25)).abs() < 1e-15);
        // Either sign of the direction reaches the plane.
        let q = Plane
            .project(DVec3::new(1.0, 2.0, 3.0), DVec3::new(0.0, -0.6, -0.8))
            .unwrap();
        assert_eq!(p, q);
        assert!(Plane.project(DVec3::ONE, DVec3::X).is_none());
    }

    /// A field behind a reference keeps its optional capabilities (an estimator handed
    /// `&field` must not lose the point lookup or the closed forms).
    #[test]
    fn a_reference_answers_as_its_field() {
        let field = PatternField {
            pattern: Check { width: 4.0 },
            values: [Coefficients::grey(0.005, 1.0), Coefficients::grey(0.1, 1.0)],
        };
        let by_ref = &field;
        let x = DVec3::new(2.5, -1.0, 0.3);
        assert!(CoefficientField::<PlanePoint>::capabilities(&by_ref).point_lookup);
        assert_eq!(
            CoefficientField::<PlanePoint>::averaged_at_point(&by_ref, x),
            CoefficientField::<PlanePoint>::averaged_at_point(&field, x)
        );
        assert!(CoefficientField::<PlanePoint>::capabilities(&by_ref).ellipse_average);
    }

    #[test]
    fn field_bounds() {
        let lo = Coefficients::grey(0.005, 1.0);
        let hi = Coefficients::grey(0.1, 1.0);
        let f = StripeField {
            pattern: Stripe::new(4.0, 0.7),
            values: [hi, lo],
        };
        let b = f.bounds().unwrap();
        assert_eq!((b.min, b.max), (lo, hi));
        assert!(ConstantField(lo).bounds().unwrap().is_constant());
        let r = RampField::grey(
            Ramp {
                v0: 1.0,
                gradient: [0.1, 0.0],
            },
            Ramp {
                v0: 2.0,
                gradient: [0.0, 0.0],
            },
        );
        let b = r.bounds().unwrap();
        assert_eq!(b.min.sigma_s, Rgb::splat(2.0));
        assert_eq!(b.max.sigma_s, Rgb::splat(2.0));
        assert_eq!(b.max.sigma_a, Rgb::splat(f64::INFINITY));
        assert_eq!(
            r.coefficients(&PlanePoint::new(-20.0, 0.0)).sigma_a,
            Rgb::ZERO
        );
        assert!((r.min_over_disk(0.0, 0.0, 5.0) - 0.5).abs() < 1e-15);
    }
}
