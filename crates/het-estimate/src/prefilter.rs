//! Constant-time (prefiltered) averages over the averaging region of Eq. (3) of the paper,
//! for fields that vary in a plane: closed forms for the procedural [`Stripe`] and [`Check`]
//! patterns, and the choice between them and Monte Carlo sampling ([`Averaging`],
//! [`Flatness`]).
//!
//! # Footprint
//! A field defined in a plane (the analytic plane z = 0, or a planar projection along an axis)
//! sees the averaging ellipse `centre + x·semi_major + y·semi_minor`, `|(x, y)| ≤ 1`, through
//! a linear map into its own plane. The image is again an ellipse, given by conjugate
//! semi-axes ([`PlaneFootprint`]); the map is affine, so a uniform area weight on the ellipse
//! stays uniform on its image. The average is therefore the mean of the pattern over the
//! image of the unit disk, weighted by the footprint's [`FootprintWeight`] in unit-disk
//! coordinates. This is exact when the projected points of the Monte Carlo estimator are the
//! ellipse's own points, i.e. on a flat surface, where the ellipse lies in the surface
//! (the averaging plane contains x_i and x_o and is normal to the surface there). On curved
//! surfaces the estimator falls back to sampling ([`Flatness`]).
//!
//! # Closed forms (derivations: `docs/physics.md#prefiltered-averages`)
//! * Stripe: the stripe coordinate `u` is linear, so over the footprint it is `u_c + h·z`
//!   with `h = |Mᵀĝ|` and `z` distributed as the weight's 1-D marginal. The fraction of the
//!   weight in value 1 is a sum of marginal-CDF differences over the bands that `[u_c − h,
//!   u_c + h]` meets: O(1 + h/w).
//! * Check: value 1 is a + b − 2ab with a, b the parities of the cell's column and row. The
//!   means of a and b are band fractions along x and y (as for stripes); the mean of ab is the
//!   area of the footprint in the odd-odd cells, each the area of the unit disk inside the
//!   cell's parallelogram image, exact by the polygon–circle formula (signed areas of the disk
//!   inside the triangles spanned by the centre and each edge): O((1 + extent/w)²).
//!
//! Both are exact to rounding (the check below b/a = [`THIN_ASPECT`] to its segment limit).
//! Footprints that would need more than [`MAX_CELLS`] bands or cells (an ellipse thousands of
//! pattern periods wide) return `None`, and the estimator samples instead.

use glam::{DVec2, DVec3};

use crate::ellipse::PlanarEllipse;
use crate::names::Named;
use crate::pattern::{BinaryPattern, Check, Stripe, fast_floor, first_odd, is_odd};

/// Most stripe bands or check cells a closed form visits before it declines (`None`).
pub const MAX_CELLS: usize = 4096;

/// How the Sone estimator averages the coefficients over its disk and ellipse.
///
/// Names (CLI `--averaging`): `prefiltered` (default), `monte-carlo`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Averaging {
    /// Ask the field's constant-time average ([`crate::CoefficientField::ellipse_average`])
    /// wherever the surface is flat enough ([`Flatness`]), and sample where it is not or where
    /// the field has none.
    #[default]
    Prefiltered,
    /// Always sample (the paper's Monte Carlo estimator).
    MonteCarlo,
}

impl Named for Averaging {
    const WHAT: &'static str = "averaging";
    const ALL: &'static [Self] = &[Averaging::Prefiltered, Averaging::MonteCarlo];
    fn name(self) -> &'static str {
        match self {
            Averaging::Prefiltered => "prefiltered",
            Averaging::MonteCarlo => "monte-carlo",
        }
    }
}

named_display_fromstr!(Averaging);

impl Averaging {
    /// The name used on the command line and in sidecars.
    pub fn name(self) -> &'static str {
        Named::name(self)
    }
}

/// When a flat footprint, or the pair's local surface model, stands for the projected region:
/// the fallback criterion of prefiltered averaging (`docs/physics.md#prefiltered-averages`,
/// "Curved surfaces").
///
/// # By error
/// Where the surface reports its curvature ([`crate::SurfaceQuery::curvature`]; a surface that
/// does not is taken as flat between the ends, its curvature counted as model error) and the
/// field says how displacements along the plane's normal move its readings
/// ([`crate::CoefficientField::displacement_scale`], a length L), each region is read
/// * in closed form (the flat footprint) when the surface stays within `tolerance`·L of the
///   region's plane: the height of the pair's local quadric over the region plus the bound on
///   its error ([`crate::local_surface`]);
/// * at points placed on the model without rays, when the model's error alone is within
///   `tolerance`·L (and the model bends by at most [`crate::local_surface::MAX_BEND`] over the
///   region);
/// * by projection rays otherwise (creases, corners, thin parts, regions that span much of a
///   small object), counted in [`crate::Diagnostics::prefilter_fallback`].
///
/// A displacement δ of the points along the normal moves a band or cell edge of the field
/// across the region by δ/L of the footprint (L = max(feature, footprint extent)/|sensitivity|,
/// see the field's method), so the average moves by about (2/π)·δ/L of the contrast at most.
///
/// # By angle
/// For fields that do not give L (the trait's default), the older test applies: a pair is
/// *flat* when the normals at x_i and x_o differ by at most `max_normal_angle`, and the chord
/// leaves each tangent plane by at most that angle (|n·x̂| ≤ sin θ, which on a sphere of
/// radius R is θ = d/(2R)); otherwise the region is projected by rays. On a surface of
/// curvature radius R, a chord of length d ≤ θR sags by about d²/(8R) ≤ θd/8 below its
/// midpoint: ≤ 0.44 % of the chord at the default θ = 2°. That test sees only the two end
/// normals: a bump between x_i and x_o, or curvature across the chord beyond the endpoints'
/// reach (a minor axis b ≫ d/2), is not detected.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Flatness {
    /// θ, radians (default 2° = 0.0349), with its sine and cosine.
    max_normal_angle: f64,
    sin: f64,
    cos: f64,
    /// The largest displacement of a region's points along its normal, as a fraction of the
    /// field's displacement scale L, that a reading may leave unaccounted (default 0.05).
    tolerance: f64,
}

impl Flatness {
    /// The default displacement tolerance: 5 % of the field's displacement scale, an error of
    /// at most about 3 % of the field's contrast in one region's average (type docs).
    pub const DEFAULT_TOLERANCE: f64 = 0.05;

    /// θ = 2° (its sine and cosine are those `sin_cos` gives, checked by a test), tolerance
    /// [`Flatness::DEFAULT_TOLERANCE`].
    pub const DEFAULT: Flatness = Flatness {
        max_normal_angle: 2.0 * std::f64::consts::PI / 180.0,
        sin: 0.03489949670250097,
        cos: 0.9993908270190958,
        tolerance: Self::DEFAULT_TOLERANCE,
    };

    /// The criterion with θ = `max_normal_angle` radians and the default tolerance; a
    /// negative or non-finite angle is an error.
    pub fn new(max_normal_angle: f64) -> Result<Self, bssrdf_core::ParamError> {
        let theta =
            bssrdf_core::error::check_non_negative("flatness.max_normal_angle", max_normal_angle)?;
        let (sin, cos) = theta.sin_cos();
        Ok(Self {
            max_normal_angle: theta,
            sin,
            cos,
            tolerance: Self::DEFAULT_TOLERANCE,
        })
    }

    /// The same criterion with displacement tolerance `tolerance` (a fraction of the field's
    /// displacement scale; 0 admits only regions the model says are exactly flat); a
    /// negative or non-finite value is an error.
    pub fn with_tolerance(self, tolerance: f64) -> Result<Self, bssrdf_core::ParamError> {
        let tolerance = bssrdf_core::error::check_non_negative("flatness.tolerance", tolerance)?;
        Ok(Self { tolerance, ..self })
    }

    /// θ, radians.
    pub fn max_normal_angle(&self) -> f64 {
        self.max_normal_angle
    }

    /// The displacement tolerance (a fraction of the field's displacement scale).
    pub fn tolerance(&self) -> f64 {
        self.tolerance
    }

    /// True when the pair with unit normals `n_i`, `n_o` and unit chord direction `x_hat`
    /// is flat by the angle test above. Non-finite input is not flat.
    #[inline]
    pub fn is_flat(&self, n_i: DVec3, n_o: DVec3, x_hat: DVec3) -> bool {
        let (sin, cos) = (self.sin, self.cos);
        n_i.dot(n_o) >= cos && n_i.dot(x_hat).abs() <= sin && n_o.dot(x_hat).abs() <= sin
    }
}

impl Default for Flatness {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// The weight of a footprint over the unit disk (in the ellipse's own coordinates).
///
/// Only the uniform weight of Eq. (3) exists today. A radially symmetric kernel (a Gaussian
/// weight of a kernel estimator) fits the same closed form for stripes through its 1-D
/// marginal ([`FootprintWeight::marginal_cdf`]); the check's closed form is for the uniform
/// weight only.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[non_exhaustive]
pub enum FootprintWeight {
    /// Uniform over the unit disk (area measure; Eq. (3)).
    #[default]
    Uniform,
}

impl FootprintWeight {
    /// The weight's marginal distribution along any direction, as a CDF on z ∈ [−1, 1]
    /// (0 below, 1 above). Uniform disk: the semicircle law,
    /// F(z) = ½ + (z√(1 − z²) + asin z)/π.
    #[inline]
    pub fn marginal_cdf(self, z: f64) -> f64 {
        match self {
            // Outside [−1, 1] without the library calls (the formula gives exactly 0 and 1
            // at the ends).
            FootprintWeight::Uniform if z <= -1.0 => 0.0,
            FootprintWeight::Uniform if z >= 1.0 => 1.0,
            FootprintWeight::Uniform => {
                0.5 + (z * (1.0 - z * z).sqrt() + z.asin()) / std::f64::consts::PI
            }
        }
    }
}

/// The image of the unit disk in a pattern's plane: `centre + x·axis_u + y·axis_v` for
/// `x² + y² ≤ 1` (conjugate semi-axes; not necessarily orthogonal), with a weight.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlaneFootprint {
    /// Centre (pattern coordinates, scene units).
    pub centre: DVec2,
    /// Image of the unit disk's x axis (the ellipse's semi-major axis).
    pub axis_u: DVec2,
    /// Image of the unit disk's y axis (the ellipse's semi-minor axis).
    pub axis_v: DVec2,
    /// Weight over the unit disk.
    pub weight: FootprintWeight,
}

impl PlaneFootprint {
    /// The footprint of `e` in a plane whose coordinates are the *linear* map `to_plane`
    /// (applied to the centre and to both semi-axis vectors), uniformly weighted.
    pub fn of_ellipse(e: &PlanarEllipse, to_plane: impl Fn(DVec3) -> DVec2) -> Self {
        Self {
            centre: to_plane(e.centre),
            axis_u: to_plane(e.semi_major),
            axis_v: to_plane(e.semi_minor),
            weight: FootprintWeight::Uniform,
        }
    }

    /// Half the extent of the footprint along unit direction `g`: `|Mᵀg|`.
    #[inline]
    fn half_extent(&self, g: DVec2) -> f64 {
        // Not `hypot` (a library call): footprints are lengths far inside f64's range.
        let (a, b) = (g.dot(self.axis_u), g.dot(self.axis_v));
        (a * a + b * b).sqrt()
    }

    fn is_finite(&self) -> bool {
        self.centre.is_finite() && self.axis_u.is_finite() && self.axis_v.is_finite()
    }
}

/// The weighted fraction of `fp` where `stripe` selects value 1 (in [0, 1]); `None` for a
/// non-finite footprint or one that spans more than [`MAX_CELLS`] bands.
pub fn stripe_fraction(stripe: &Stripe, fp: &PlaneFootprint) -> Option<f64> {
    let w = stripe.width();
    if !(fp.is_finite() && w > 0.0 && w.is_finite()) {
        return None;
    }
    let (cos, sin) = stripe.direction();
    let bands = Bands::of(fp, DVec2::new(cos, sin), w);
    (bands.count() <= MAX_CELLS as f64).then(|| bands.odd_fraction(fp))
}

/// The bands `(k − ½) w ≤ g·p < (k + ½) w` (unit direction `g`) that a footprint meets:
/// `first..=last`, with the footprint's centre `u_c` and half extent `h` along `g`.
struct Bands {
    u_c: f64,
    h: f64,
    w: f64,
    first: f64,
    last: f64,
}

impl Bands {
    fn of(fp: &PlaneFootprint, g: DVec2, w: f64) -> Self {
        let (u_c, h) = (g.dot(fp.centre), fp.half_extent(g));
        let band = |u: f64| fast_floor(u / w + 0.5);
        Self {
            u_c,
            h,
            w,
            first: band(u_c - h),
            last: band(u_c + h),
        }
    }

    /// How many bands the footprint meets.
    fn count(&self) -> f64 {
        self.last - self.first + 1.0
    }

    /// The weighted fraction of `fp` (the footprint the bands were found for) in odd bands:
    /// the weight's marginal along `g` integrated band by band; the parity of the one band
    /// that holds the whole footprint.
    fn odd_fraction(&self, fp: &PlaneFootprint) -> f64 {
        if self.first == self.last || self.h == 0.0 {
            return if is_odd(self.first) { 1.0 } else { 0.0 };
        }
        let cdf = |u: f64| fp.weight.marginal_cdf((u - self.u_c) / self.h);
        let mut ones = 0.0;
        let mut k = first_odd(self.first);
        while k <= self.last {
            ones += cdf((k + 0.5) * self.w) - cdf((k - 0.5) * self.w);
            k += 2.0;
        }
        ones.clamp(0.0, 1.0)
    }
}

/// The area fraction of `fp` where `check` selects value 1 (in [0, 1]); uniform weight only.
/// `None` for another weight, a non-finite footprint, or one that spans more than
/// [`MAX_CELLS`] cells.
///
/// A footprint thinner than [`THIN_ASPECT`] (minor over major semi-axis, b/a, including a
/// segment, b = 0) is replaced by its b → 0 limit, the segment along its major axis with the
/// semicircle law, cut at the cells' edges: in unit-disk coordinates the cells' images
/// grow as a/b, and the polygon areas below lose every digit (at b/a ≤ 3·10⁻⁹ they returned
/// 0.83, 0 or 1 where 0.444 was right). The limit's own error is of order (b/a)², and
/// `tests/prefilter.rs` checks both against brute force from b/a = 10⁻¹² to 1.
///
/// Cell (i, j) holds value 1 when i + j is odd. With a = [i odd] and b = [j odd] that is
/// a + b − 2ab, so the fraction is f_a + f_b − 2 f_ab: two band fractions (closed forms in the
/// footprint's marginals, as for stripes) and the area in the cells where both i and j are
/// odd, a quarter of the cells, each the exact area of the disk inside the cell's image
/// ([`disk_polygon_area`]). Half as many cell areas as summing the value-1 cells themselves.
pub fn check_fraction(check: &Check, fp: &PlaneFootprint) -> Option<f64> {
    if fp.weight != FootprintWeight::Uniform
        || !fp.is_finite()
        || !(check.width > 0.0 && check.width.is_finite())
    {
        return None;
    }
    let det = fp.axis_u.perp_dot(fp.axis_v);
    let w = check.width;
    // Columns i (bands along x) and rows j (along y).
    let (cols, rows) = (Bands::of(fp, DVec2::X, w), Bands::of(fp, DVec2::Y, w));
    if cols.count() * rows.count() > MAX_CELLS as f64 {
        return None;
    }
    if cols.count() == 1.0 && rows.count() == 1.0 {
        return Some(check.select(fp.centre.x, fp.centre.y) as f64);
    }
    // b/a = |det| / λ_max(M Mᵀ).
    let (major, lambda) = major_axis(fp);
    if det.abs() < THIN_ASPECT * lambda {
        return Some(segment_check_fraction(check, fp.centre, major));
    }
    let (f_a, f_b) = (cols.odd_fraction(fp), rows.odd_fraction(fp));
    // Unit-disk coordinates of a pattern point: M⁻¹ (p − c).
    let inv = |p: DVec2| {
        let d = p - fp.centre;
        DVec2::new(d.perp_dot(fp.axis_v), fp.axis_u.perp_dot(d)) / det
    };
    let cell_area = w * w / det.abs();
    let mut both = 0.0;
    let mut i = first_odd(cols.first);
    while i <= cols.last {
        let (x0, x1) = ((i - 0.5) * w, (i + 0.5) * w);
        let mut j = first_odd(rows.first);
        while j <= rows.last {
            let (y0, y1) = ((j - 0.5) * w, (j + 0.5) * w);
            let quad = [
                inv(DVec2::new(x0, y0)),
                inv(DVec2::new(x1, y0)),
                inv(DVec2::new(x1, y1)),
                inv(DVec2::new(x0, y1)),
            ];
            let (lo, hi) = quad[1..]
                .iter()
                .fold((quad[0], quad[0]), |(lo, hi), &q| (lo.min(q), hi.max(q)));
            if quad.iter().all(|q| q.length_squared() <= 1.0) {
                both += cell_area; // inside the disk: the whole cell
            } else if lo.x < 1.0 && lo.y < 1.0 && hi.x > -1.0 && hi.y > -1.0 {
                both += disk_polygon_area(&quad).abs();
            } // else: the cell's bounding box misses the disk
            j += 2.0;
        }
        i += 2.0;
    }
    let f_ab = both / std::f64::consts::PI;
    Some((f_a + f_b - 2.0 * f_ab).clamp(0.0, 1.0))
}

/// Footprints with a smaller aspect b/a than this are replaced by their segment limit in
/// [`check_fraction`].
pub const THIN_ASPECT: f64 = 1e-6;

/// The footprint's major semi-axis (a vector of length a) and a² = λ_max(M Mᵀ), M = [A B].
fn major_axis(fp: &PlaneFootprint) -> (DVec2, f64) {
    let (a, b) = (fp.axis_u, fp.axis_v);
    let (sxx, syy, sxy) = (
        a.x * a.x + b.x * b.x,
        a.y * a.y + b.y * b.y,
        a.x * a.y + b.x * b.y,
    );
    let half_diff = 0.5 * (sxx - syy);
    let lambda = 0.5 * (sxx + syy) + (half_diff * half_diff + sxy * sxy).sqrt();
    // The eigenvector of λ: the larger of the two (equivalent) forms.
    let (e1, e2) = (DVec2::new(sxy, lambda - sxx), DVec2::new(lambda - syy, sxy));
    let e = if e1.length_squared() >= e2.length_squared() {
        e1
    } else {
        e2
    };
    let dir = if e.length_squared() > 0.0 {
        e.normalize()
    } else {
        DVec2::X
    };
    (dir * lambda.sqrt(), lambda)
}

/// The check fraction of the segment `centre + z·half`, z ∈ [−1, 1], weighted by the
/// semicircle law (the b → 0 limit of a uniform ellipse): the segment is cut where it crosses
/// the cells' edges, and each piece holds its midpoint's value.
fn segment_check_fraction(check: &Check, centre: DVec2, half: DVec2) -> f64 {
    let w = check.width;
    let mut cuts: Vec<f64> = vec![-1.0, 1.0];
    for (c, d) in [(centre.x, half.x), (centre.y, half.y)] {
        if d == 0.0 {
            continue;
        }
        // Edges at (k + ½) w between c − |d| and c + |d|.
        let lo = ((c - d.abs()) / w - 0.5).ceil();
        let hi = ((c + d.abs()) / w - 0.5).floor();
        let mut k = lo;
        while k <= hi {
            let z = ((k + 0.5) * w - c) / d;
            if z > -1.0 && z < 1.0 {
                cuts.push(z);
            }
            k += 1.0;
        }
    }
    cuts.sort_by(f64::total_cmp);
    let weight = FootprintWeight::Uniform;
    let ones: f64 = cuts
        .windows(2)
        .filter(|z| z[1] > z[0])
        .map(|z| {
            let p = centre + 0.5 * (z[0] + z[1]) * half;
            check.select(p.x, p.y) as f64 * (weight.marginal_cdf(z[1]) - weight.marginal_cdf(z[0]))
        })
        .sum();
    ones.clamp(0.0, 1.0)
}

/// Signed area of the unit disk (centre 0) inside the convex polygon `poly` (positive when
/// counter-clockwise): the sum over edges of the signed area of the disk inside the triangle
/// (0, a, b).
pub fn disk_polygon_area(poly: &[DVec2]) -> f64 {
    let n = poly.len();
    (0..n)
        .map(|k| disk_triangle_area(poly[k], poly[(k + 1) % n]))
        .sum()
}

/// Signed area of the unit disk inside the triangle (0, a, b).
fn disk_triangle_area(a: DVec2, b: DVec2) -> f64 {
    // Signed area of the circular sector between directions u and v (radius 1).
    let sector = |u: DVec2, v: DVec2| 0.5 * u.perp_dot(v).atan2(u.dot(v));
    let (la, lb) = (a.length_squared(), b.length_squared());
    if la <= 1.0 && lb <= 1.0 {
        return 0.5 * a.perp_dot(b);
    }
    let d = b - a;
    let qa = d.length_squared();
    if qa == 0.0 {
        return 0.0;
    }
    // |a + t d|² = 1.
    let qb = a.dot(d);
    let disc = qb * qb - qa * (la - 1.0);
    if disc <= 0.0 {
        return sector(a, b);
    }
    let s = disc.sqrt();
    let (t1, t2) = ((-qb - s) / qa, (-qb + s) / qa);
    if t2 <= 0.0 || t1 >= 1.0 {
        return sector(a, b);
    }
    let p1 = a + t1.max(0.0) * d;
    let p2 = a + t2.min(1.0) * d;
    sector(a, p1) + 0.5 * p1.perp_dot(p2) + sector(p2, b)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn flatness_keeps_the_sine_and_cosine_of_its_angle() {
        let two_degrees = Flatness::new(2.0 * std::f64::consts::PI / 180.0).unwrap();
        assert_eq!(Flatness::DEFAULT, two_degrees);
        assert_eq!(Flatness::default(), two_degrees);
        assert!(Flatness::new(-0.1).is_err() && Flatness::new(f64::NAN).is_err());
        let f = Flatness::new(0.5).unwrap();
        let n = DVec3::Z;
        // Normals 0.49 and 0.51 rad apart; a chord 0.49 rad out of the tangent plane.
        let tilt = |a: f64| DVec3::new(a.sin(), 0.0, a.cos());
        assert!(f.is_flat(n, tilt(0.49), DVec3::Y));
        assert!(!f.is_flat(n, tilt(0.51), DVec3::Y));
        assert!(f.is_flat(n, n, DVec3::new(0.49f64.cos(), 0.0, 0.49f64.sin())));
        assert!(!f.is_flat(n, n, DVec3::new(0.51f64.cos(), 0.0, 0.51f64.sin())));
    }
    use std::f64::consts::PI;

    #[test]
    fn disk_polygon_areas() {
        let square = |h: f64| {
            [
                DVec2::new(-h, -h),
                DVec2::new(h, -h),
                DVec2::new(h, h),
                DVec2::new(-h, h),
            ]
        };
        // Inside: the square's own area; containing the disk: π.
        assert!((disk_polygon_area(&square(0.5)) - 1.0).abs() < 1e-14);
        assert!((disk_polygon_area(&square(3.0)) - PI).abs() < 1e-13);
        // Clockwise gives the negative.
        let mut cw = square(3.0);
        cw.reverse();
        assert!((disk_polygon_area(&cw) + PI).abs() < 1e-13);
        // Half-plane x ≥ 0 (a large box): π/2; the strip 0 ≤ x ≤ 0.5: the segment formula.
        let right = [
            DVec2::new(0.0, -5.0),
            DVec2::new(5.0, -5.0),
            DVec2::new(5.0, 5.0),
            DVec2::new(0.0, 5.0),
        ];
        assert!((disk_polygon_area(&right) - PI / 2.0).abs() < 1e-13);
        let strip = [
            DVec2::new(0.0, -5.0),
            DVec2::new(0.5, -5.0),
            DVec2::new(0.5, 5.0),
            DVec2::new(0.0, 5.0),
        ];
        let f = |z: f64| z * (1.0 - z * z).sqrt() + z.asin();
        assert!((disk_polygon_area(&strip) - (f(0.5) - f(0.0))).abs() < 1e-13);
        // A square of side 2 centred at (1, 1): the quarter disk.
        let corner = [
            DVec2::new(0.0, 0.0),
            DVec2::new(2.0, 0.0),
            DVec2::new(2.0, 2.0),
            DVec2::new(0.0, 2.0),
        ];
        assert!((disk_polygon_area(&corner) - PI / 4.0).abs() < 1e-13);
        // Entirely outside.
        let far = square(0.1).map(|p| p + DVec2::new(3.0, 0.0));
        assert!(disk_polygon_area(&far).abs() < 1e-15);
    }

    #[test]
    fn semicircle_cdf() {
        let w = FootprintWeight::Uniform;
        assert_eq!(w.marginal_cdf(-2.0), 0.0);
        assert!((w.marginal_cdf(0.0) - 0.5).abs() < 1e-15);
        assert!((w.marginal_cdf(1.0) - 1.0).abs() < 1e-15);
        // Symmetric.
        assert!((w.marginal_cdf(0.3) + w.marginal_cdf(-0.3) - 1.0).abs() < 1e-15);
    }

    /// The value-1 cells' areas summed one by one: an independent exact reference for
    /// [`check_fraction`]'s decomposition into band fractions and odd-odd cells.
    fn check_fraction_by_cells(w: f64, fp: &PlaneFootprint) -> f64 {
        let det = fp.axis_u.perp_dot(fp.axis_v);
        let inv = |p: DVec2| {
            let d = p - fp.centre;
            DVec2::new(d.perp_dot(fp.axis_v), fp.axis_u.perp_dot(d)) / det
        };
        let (hx, hy) = (fp.half_extent(DVec2::X), fp.half_extent(DVec2::Y));
        let cell = |v: f64| (v / w + 0.5).floor() as i64;
        let mut ones = 0.0;
        for i in cell(fp.centre.x - hx) - 1..=cell(fp.centre.x + hx) + 1 {
            for j in cell(fp.centre.y - hy) - 1..=cell(fp.centre.y + hy) + 1 {
                if (i + j).rem_euclid(2) == 1 {
                    let (x0, x1) = ((i as f64 - 0.5) * w, (i as f64 + 0.5) * w);
                    let (y0, y1) = ((j as f64 - 0.5) * w, (j as f64 + 0.5) * w);
                    let quad = [(x0, y0), (x1, y0), (x1, y1), (x0, y1)]
                        .map(|(x, y)| inv(DVec2::new(x, y)));
                    ones += disk_polygon_area(&quad).abs();
                }
            }
        }
        ones / PI
    }

    #[test]
    fn check_fraction_equals_the_sum_over_value_one_cells() {
        let mut worst = 0.0f64;
        for k in 0..400 {
            let t = k as f64;
            let (a, b) = (
                0.2 + 9.0 * (0.37 * t).sin().abs(),
                0.05 + 3.0 * (0.71 * t).cos().abs(),
            );
            let (s, c) = (1.3 * t).sin_cos();
            let fp = PlaneFootprint {
                centre: DVec2::new(7.0 * (0.53 * t).sin(), 5.0 * (0.29 * t).cos()),
                axis_u: DVec2::new(c, s) * a,
                axis_v: (DVec2::new(-s, c) + 0.3 * (0.11 * t).sin() * DVec2::new(c, s)) * b,
                weight: FootprintWeight::Uniform,
            };
            let w = [4.0, 1.3, 0.7][k % 3];
            let got = check_fraction(&Check { width: w }, &fp).unwrap();
            let want = check_fraction_by_cells(w, &fp);
            worst = worst.max((got - want).abs());
        }
        assert!(worst < 1e-12, "largest difference {worst}");
    }

    #[test]
    fn flatness_criterion() {
        let f = Flatness::DEFAULT;
        assert!(f.is_flat(DVec3::Z, DVec3::Z, DVec3::X));
        // Sphere of radius 10, chord 0.5 apart (θ = 2.9°): not flat; 0.2 apart (1.1°): flat.
        let on = |a: f64| DVec3::new(a.sin(), 0.0, a.cos());
        for (d, flat) in [(0.5, false), (0.2, true)] {
            let a = d / 10.0 / 2.0;
            let (n_i, n_o) = (on(-a), on(a));
            let x_hat = (10.0 * (n_o - n_i)).normalize();
            assert_eq!(f.is_flat(n_i, n_o, x_hat), flat, "d = {d}");
        }
        assert!(!f.is_flat(DVec3::NAN, DVec3::Z, DVec3::X));
    }
}
