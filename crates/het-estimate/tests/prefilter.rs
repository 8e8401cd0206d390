//! Prefiltered averaging: the closed forms for stripes and checks against Monte Carlo averages
//! over the same footprints, the Sone estimator's prefiltered default against its Monte Carlo
//! path, the flatness fallback on a curved surface, and the texture-coordinate charts'
//! agreement test over random affine maps.
//!
//! Monte Carlo comparisons use independent uniform points (rejection from the square, this
//! file's own generator) and a fixed seed; the tolerance is 5 standard errors of a Bernoulli
//! mean, sqrt(p(1 − p)/N), plus 1e-12.

use glam::{DVec2, DVec3};
use het_estimate::FieldCapabilities;
use het_estimate::analytic::{CheckField, Plane, PlanePoint, StripeField};
use het_estimate::pattern::{BinaryPattern, Check, Stripe};
use het_estimate::prefilter::{FootprintWeight, PlaneFootprint, check_fraction, stripe_fraction};
use het_estimate::{
    Averaging, CoefficientField, Coefficients, Estimator, PlanarEllipse, SampleBudget, SoneParams,
    SplitMix64, SurfacePoint, SurfaceQuery, UniformSource,
};

const N_MC: usize = 40_000;
const K_SE: f64 = 5.0;

/// Uniform points of the unit disk (rejection).
fn disk_point(rng: &mut SplitMix64) -> DVec2 {
    loop {
        let p = DVec2::new(2.0 * rng.next_f64() - 1.0, 2.0 * rng.next_f64() - 1.0);
        if p.length_squared() <= 1.0 {
            return p;
        }
    }
}

/// The Monte Carlo fraction of `fp` where `pattern` selects 1, and its standard error.
fn mc_fraction(pattern: &impl BinaryPattern, fp: &PlaneFootprint, seed: u64) -> (f64, f64) {
    let mut rng = SplitMix64::new(seed);
    let ones = (0..N_MC)
        .filter(|_| {
            let u = disk_point(&mut rng);
            let p = fp.centre + u.x * fp.axis_u + u.y * fp.axis_v;
            pattern.select(p.x, p.y) == 1
        })
        .count();
    let p = ones as f64 / N_MC as f64;
    (p, (p * (1.0 - p) / N_MC as f64).sqrt())
}

/// Footprints of assorted sizes, shears and orientations, with a fixed seed.
fn footprints() -> Vec<PlaneFootprint> {
    let mut rng = SplitMix64::new(2024);
    let mut r = move || rng.next_f64();
    (0..24)
        .map(|k| {
            let size = [0.3, 2.0, 7.0, 15.0][k % 4];
            let angle = 6.3 * r();
            let a = size * (0.2 + r());
            let b = a * (0.05 + 1.5 * r());
            let shear = r() - 0.5;
            let (s, c) = angle.sin_cos();
            PlaneFootprint {
                centre: DVec2::new(20.0 * r() - 10.0, 20.0 * r() - 10.0),
                axis_u: DVec2::new(c, s) * a,
                axis_v: (DVec2::new(-s, c) + shear * DVec2::new(c, s)) * b,
                weight: FootprintWeight::Uniform,
            }
        })
        .collect()
}

#[test]
fn stripe_closed_form_matches_monte_carlo() {
    for (k, fp) in footprints().iter().enumerate() {
        let stripe = Stripe::new([4.0, 1.3][k % 2], 0.4 * k as f64);
        let exact = stripe_fraction(&stripe, fp).unwrap();
        let (mc, se) = mc_fraction(&stripe, fp, 100 + k as u64);
        assert!(
            (exact - mc).abs() <= K_SE * se + 1e-12,
            "footprint {k}: closed form {exact}, Monte Carlo {mc} ± {se}"
        );
    }
}

#[test]
fn check_closed_form_matches_monte_carlo() {
    for (k, fp) in footprints().iter().enumerate() {
        let check = Check {
            width: [4.0, 1.3][k % 2],
        };
        let exact = check_fraction(&check, fp).unwrap();
        let (mc, se) = mc_fraction(&check, fp, 200 + k as u64);
        assert!(
            (exact - mc).abs() <= K_SE * se + 1e-12,
            "footprint {k}: closed form {exact}, Monte Carlo {mc} ± {se}"
        );
    }
}

/// Independent exact cases: a footprint inside one cell, and a disk centred on a check corner
/// (four quarter disks: half of it is value 1), and a disk centred on a stripe edge.
#[test]
fn closed_forms_in_symmetric_cases() {
    let disk = |c: DVec2, r: f64| PlaneFootprint {
        centre: c,
        axis_u: DVec2::X * r,
        axis_v: DVec2::Y * r,
        weight: FootprintWeight::Uniform,
    };
    let check = Check { width: 4.0 };
    assert_eq!(check_fraction(&check, &disk(DVec2::ZERO, 1.0)), Some(0.0));
    assert_eq!(
        check_fraction(&check, &disk(DVec2::new(4.0, 0.0), 1.0)),
        Some(1.0)
    );
    let f = check_fraction(&check, &disk(DVec2::new(2.0, 2.0), 1.5)).unwrap();
    assert!((f - 0.5).abs() < 1e-14, "{f}");
    let stripe = Stripe::new(4.0, 0.0);
    let f = stripe_fraction(&stripe, &disk(DVec2::new(2.0, 5.0), 1.5)).unwrap();
    assert!((f - 0.5).abs() < 1e-14, "{f}");
    // A footprint much wider than the period sees half of each value (to ~ (w/h)^{3/2}).
    let f = stripe_fraction(&stripe, &disk(DVec2::ZERO, 400.0)).unwrap();
    assert!((f - 0.5).abs() < 1e-3, "{f}");
    // Too many cells: declined, so that the estimator samples.
    assert!(check_fraction(&check, &disk(DVec2::ZERO, 1e4)).is_none());
    // A segment (zero area) is the b → 0 limit: along x from −3 to 3 it lies in cells 0 and
    // ±1 (value 0 for |x| < 2, 1 beyond), and the semicircle law puts 1 − F(2/3) + F(−2/3)
    // of its weight beyond |x| = 2.
    let mut line = disk(DVec2::ZERO, 3.0);
    line.axis_v = DVec2::ZERO;
    let z: f64 = 2.0 / 3.0;
    let beyond = 1.0 - 2.0 * (z * (1.0 - z * z).sqrt() + z.asin()) / std::f64::consts::PI;
    let f = check_fraction(&check, &line).unwrap();
    assert!((f - beyond).abs() < 1e-14, "{f} vs {beyond}");
}

/// The check fraction of `fp` by brute force, independently of the closed form's polygon
/// areas: the unit disk cut into chords along the footprint's first axis (x), each chord's
/// fraction of value 1 exact from its crossings of the cell edges, integrated over the
/// chords' offset y (weight (2/π)√(1 − y²), midpoint rule in y = sin θ over 20,000 nodes).
/// Thin footprints are cut along their length, so every chord sees them whole and the
/// integrand varies slowly with y, whatever the aspect.
fn brute_check_fraction(check: &Check, fp: &PlaneFootprint) -> f64 {
    let n = 20_000;
    let w = check.width;
    let mut total = 0.0;
    for k in 0..n {
        let theta =
            -std::f64::consts::FRAC_PI_2 + std::f64::consts::PI * (k as f64 + 0.5) / n as f64;
        let (y, half) = (theta.sin(), theta.cos());
        // The chord p(x) = c + x·A + y·B, x ∈ [−half, half].
        let base = fp.centre + y * fp.axis_v;
        let mut cuts = vec![-half, half];
        for (c, d) in [(base.x, fp.axis_u.x), (base.y, fp.axis_u.y)] {
            if d == 0.0 {
                continue;
            }
            let (lo, hi) = (c - half * d.abs(), c + half * d.abs());
            let mut edge = ((lo / w - 0.5).ceil() + 0.5) * w;
            while edge <= hi {
                let x = (edge - c) / d;
                if x > -half && x < half {
                    cuts.push(x);
                }
                edge += w;
            }
        }
        cuts.sort_by(f64::total_cmp);
        let ones: f64 = cuts
            .windows(2)
            .map(|x| {
                let p = base + 0.5 * (x[0] + x[1]) * fp.axis_u;
                check.select(p.x, p.y) as f64 * (x[1] - x[0])
            })
            .sum();
        // Weight of the chord: (2/π) cos²θ dθ; its fraction: ones / (2 half).
        total += 2.0 / std::f64::consts::PI * half * half * std::f64::consts::PI / n as f64
            * (ones / (2.0 * half));
    }
    total
}

/// Thin footprints (issue 38): the check's closed form against brute force at aspects b/a
/// from 1 down to 10⁻¹², and a segment (b = 0), over orientations, shears, sizes and
/// positions; the stripe's too. Below b/a = 10⁻⁶ the check takes the segment limit; above,
/// the polygon areas, whose unit-disk images grow as a/b: before the limit existed they
/// returned 0.83, 0 or 1 where 0.444 was right at b/a ≤ 3·10⁻⁹.
#[test]
fn closed_forms_hold_for_thin_footprints() {
    let mut rng = SplitMix64::new(38);
    let mut r = move || rng.next_f64();
    let mut worst: f64 = 0.0;
    let mut checked = 0;
    for exponent in 0..=13 {
        let aspect = if exponent == 13 {
            0.0
        } else {
            10f64.powi(-exponent)
        };
        for k in 0..12 {
            let a = [0.7, 3.0, 11.0][k % 3] * (0.5 + r());
            let angle = 6.3 * r();
            let (s, c) = angle.sin_cos();
            // Conjugate semi-axes: B = b (n + shear·u) keeps the area π a b.
            let shear = 2.0 * r() - 1.0;
            let fp = PlaneFootprint {
                centre: DVec2::new(20.0 * r() - 10.0, 20.0 * r() - 10.0),
                axis_u: DVec2::new(c, s) * a,
                axis_v: (DVec2::new(-s, c) + shear * DVec2::new(c, s)) * (aspect * a),
                weight: FootprintWeight::Uniform,
            };
            let width = [4.0, 1.3, 0.7][(k / 3) % 3];
            let check = Check { width };
            let got = check_fraction(&check, &fp).expect("a thin footprint has a closed form");
            let want = brute_check_fraction(&check, &fp);
            worst = worst.max((got - want).abs());
            assert!(
                (got - want).abs() < 2e-6,
                "b/a {aspect:e}, footprint {k}: check {got}, brute force {want}"
            );
            let stripe = Stripe::new(width, angle + 0.3 + r());
            let got = stripe_fraction(&stripe, &fp).unwrap();
            let (mc, se) = mc_fraction(&stripe, &fp, 3800 + 20 * exponent as u64 + k as u64);
            assert!(
                (got - mc).abs() <= K_SE * se + 1e-12,
                "b/a {aspect:e}, footprint {k}: stripe {got}, Monte Carlo {mc} ± {se}"
            );
            checked += 1;
        }
    }
    eprintln!("thin check footprints: {checked}, largest difference from brute force {worst:.1e}");
}

fn check_preset() -> CheckField {
    CheckField {
        pattern: Check { width: 4.0 },
        values: [Coefficients::grey(0.005, 1.0), Coefficients::grey(0.1, 1.0)],
    }
}

/// The whole Sone estimate, prefiltered (default) against Monte Carlo with 4096 samples per
/// stage, over 32 seeds, on the check preset: within 5 standard errors of the Monte Carlo mean
/// (plus 1e-9). Both stages enter (the disk mean sets the ellipse's width).
#[test]
fn sone_prefiltered_matches_monte_carlo_on_the_check() {
    let f = check_preset();
    let pre = Estimator::Sone(SoneParams::paper())
        .prepare(0.0, 1.0)
        .unwrap();
    let mc = Estimator::Sone(
        SoneParams::paper()
            .with_averaging(Averaging::MonteCarlo)
            .with_samples(SampleBudget::fixed(4096)),
    )
    .prepare(0.0, 1.0)
    .unwrap();
    let x_i = PlanePoint::new(0.3, -0.2);
    for x_o in [
        PlanePoint::new(5.0, 1.0),
        PlanePoint::new(-3.0, 9.0),
        PlanePoint::new(11.0, -6.5),
    ] {
        let p = pre.estimate(&Plane, &f, &x_i, &x_o, &mut SplitMix64::new(1));
        assert_eq!(p.diagnostics.field_averages, 2);
        assert_eq!(p.diagnostics.projections, 0);
        let v: Vec<f64> = (0..32)
            .map(|s| {
                mc.estimate(&Plane, &f, &x_i, &x_o, &mut SplitMix64::new(s))
                    .coefficients
                    .sigma_a[0]
            })
            .collect();
        let mean = v.iter().sum::<f64>() / 32.0;
        let sd = (v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / 31.0).sqrt();
        let se = sd / 32f64.sqrt();
        let got = p.coefficients.sigma_a[0];
        assert!(
            (got - mean).abs() <= K_SE * se + 1e-9,
            "{x_o:?}: prefiltered {got}, Monte Carlo {mean} ± {se}"
        );
    }
}

/// A sphere of radius `R` at the origin with a stripe field projected along z; its closed-form
/// average reads the ellipse as it lies in its plane (the flat-footprint reading).
const R: f64 = 3.0;

#[derive(Debug, Clone, Copy)]
struct SpherePoint(DVec3);
impl SurfacePoint for SpherePoint {
    fn position(&self) -> DVec3 {
        self.0
    }
    fn normal(&self) -> DVec3 {
        self.0.normalize()
    }
}
struct Sphere;
impl SurfaceQuery for Sphere {
    type Point = SpherePoint;
    fn project(&self, o: DVec3, d: DVec3) -> Option<SpherePoint> {
        let (b, c) = (o.dot(d), o.length_squared() - R * R);
        let disc = b * b - c;
        (disc >= 0.0).then(|| {
            let t = [-b - disc.sqrt(), -b + disc.sqrt()]
                .into_iter()
                .min_by(|x, y| x.abs().total_cmp(&y.abs()))
                .unwrap();
            SpherePoint(o + t * d)
        })
    }
}
struct ProjectedStripe(StripeField);
impl CoefficientField<SpherePoint> for ProjectedStripe {
    fn coefficients(&self, p: &SpherePoint) -> Coefficients {
        self.0.coefficients(&PlanePoint::new(p.0.x, p.0.y))
    }
    fn bounds(&self) -> Option<het_estimate::FieldBounds> {
        CoefficientField::<PlanePoint>::bounds(&self.0)
    }
    fn ellipse_average(&self, e: &PlanarEllipse) -> Option<Coefficients> {
        let fp = PlaneFootprint::of_ellipse(e, |v| DVec2::new(v.x, v.y));
        let f = stripe_fraction(&self.0.pattern, &fp)?;
        let [v0, v1] = self.0.values;
        Some(Coefficients {
            sigma_a: v0.sigma_a * (1.0 - f) + v1.sigma_a * f,
            sigma_s: v0.sigma_s * (1.0 - f) + v1.sigma_s * f,
        })
    }
    fn capabilities(&self) -> FieldCapabilities {
        FieldCapabilities {
            ellipse_average: true,
            ..FieldCapabilities::default()
        }
    }
}

/// On a small sphere, pairs far apart fail the flatness criterion: they are sampled (as the
/// Monte Carlo path would, to the bit) and flagged; a close pair is answered by the field.
#[test]
fn fallback_triggers_on_a_small_sphere_and_is_counted() {
    let field = ProjectedStripe(StripeField {
        pattern: Stripe::new(0.5, 0.7),
        values: [Coefficients::grey(0.005, 1.0), Coefficients::grey(0.1, 1.0)],
    });
    let pre = Estimator::Sone(SoneParams::paper())
        .prepare(0.0, 1.0)
        .unwrap();
    let mc = Estimator::Sone(SoneParams::paper().with_averaging(Averaging::MonteCarlo))
        .prepare(0.0, 1.0)
        .unwrap();
    let on = |theta: f64, phi: f64| {
        SpherePoint(
            R * DVec3::new(
                theta.sin() * phi.cos(),
                theta.sin() * phi.sin(),
                theta.cos(),
            ),
        )
    };
    let mut fallbacks = 0;
    for k in 0..20 {
        let (x_i, x_o) = (on(0.3, 0.1 * k as f64), on(0.9, 0.2 + 0.1 * k as f64));
        let p = pre.estimate(&Sphere, &field, &x_i, &x_o, &mut SplitMix64::new(k));
        let m = mc.estimate(&Sphere, &field, &x_i, &x_o, &mut SplitMix64::new(k));
        assert!(p.diagnostics.prefilter_fallback, "pair {k} not flagged");
        assert_eq!(p.diagnostics.field_averages, 0);
        assert_eq!(p.coefficients, m.coefficients);
        fallbacks += p.diagnostics.prefilter_fallback as u32;
    }
    assert_eq!(fallbacks, 20);
    // 0.02 apart on a radius-3 sphere: normals 0.38° apart, flat.
    let (x_i, x_o) = (on(0.5, 0.0), on(0.5 + 0.02 / R, 0.0));
    let p = pre.estimate(&Sphere, &field, &x_i, &x_o, &mut SplitMix64::new(1));
    assert!(!p.diagnostics.prefilter_fallback);
    assert_eq!(p.diagnostics.field_averages, 2);
    // Monte Carlo averaging never asks and never flags.
    let m = mc.estimate(&Sphere, &field, &x_i, &x_o, &mut SplitMix64::new(1));
    assert!(!m.diagnostics.prefilter_fallback && m.diagnostics.field_averages == 0);
}

mod uv_charts {
    //! `UvChart::between`, the agreement test of the texture coordinates at x_i and x_o, over
    //! random affine maps, triangles and scales (1e-4 to 1e4 texture units per scene unit).
    use glam::{DVec2, DVec3};
    use het_estimate::UvChart;
    use proptest::prelude::*;

    /// The affine map (x, y, z) ↦ offset + scale·G·(x, y), G = [[g0, g1], [g2, g3]] (z, along the
    /// normal of the charts' plane, does not count).
    fn map(g: [f64; 4], offset: [f64; 2], scale: f64) -> impl Fn(DVec3) -> DVec2 {
        move |x: DVec3| {
            DVec2::new(
                offset[0] + scale * (g[0] * x.x + g[1] * x.y),
                offset[1] + scale * (g[2] * x.x + g[3] * x.y),
            )
        }
    }

    /// The chart at `at` of the triangle with corners `at + corners`, on the plane z = 2.
    fn chart(f: &impl Fn(DVec3) -> DVec2, at: DVec3, corners: [DVec2; 3]) -> Option<UvChart> {
        let p = corners.map(|c| at + DVec3::new(c.x, c.y, 0.0));
        UvChart::of_triangle(p, p.map(f), at, f(at))
    }

    fn corners() -> impl Strategy<Value = [DVec2; 3]> {
        (0.1f64..3.0, 0.1f64..3.0, 0.0f64..std::f64::consts::TAU).prop_map(|(a, b, t)| {
            let (s, c) = t.sin_cos();
            [
                DVec2::new(-0.3 * a * c, -0.3 * a * s),
                DVec2::new(a * c, a * s),
                DVec2::new(-b * s, b * c),
            ]
        })
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(256))]

        /// One affine map seen from two triangles: accepted, symmetric to the bit, and the
        /// midpoint chart is the map; a seam beyond the tolerance, or one end's gradients 2.5 %
        /// larger, is refused.
        #[test]
        fn charts_of_one_map_agree_and_a_seam_or_stretch_does_not(
            g in prop::array::uniform4(-1.0f64..1.0),
            offset in prop::array::uniform2(-5.0f64..5.0),
            log_scale in -4.0f64..4.0,
            ci in corners(),
            co in corners(),
            xi in prop::array::uniform2(-10.0f64..10.0),
            xo in prop::array::uniform2(-10.0f64..10.0),
        ) {
            let det = g[0] * g[3] - g[1] * g[2];
            prop_assume!(det.abs() > 0.05);
            let scale = 10f64.powf(log_scale);
            let f = map(g, offset, scale);
            let (xi, xo) = (DVec3::new(xi[0], xi[1], 2.0), DVec3::new(xo[0], xo[1], 2.0));
            prop_assume!((xo - xi).length() > 0.1);
            let a = chart(&f, xi, ci).unwrap();
            let b = chart(&f, xo, co).unwrap();
            let mid = UvChart::between(&a, &b).expect("one affine map");
            prop_assert_eq!(Some(mid), UvChart::between(&b, &a));
            for x in [xi, xo, DVec3::new(3.0, -7.0, 2.0)] {
                let want = f(x);
                let err = (mid.uv_at(x) - want).length();
                prop_assert!(err <= 1e-9 * (1.0 + want.length()), "{} at {:?}", err, x);
            }
            // A seam: the far end's coordinates shifted by 3 % of the chord's reach.
            let reach = 0.02
                * (a.grad_u.length_squared() + a.grad_v.length_squared()).sqrt()
                * (xo - xi).length();
            let seam = UvChart { uv: b.uv + DVec2::new(1.5 * reach + 1e-5 * (1.0 + b.uv.length()), 0.0), ..b };
            prop_assert!(UvChart::between(&a, &seam).is_none());
            // A stretch: the far end's gradients 2.5 % larger.
            let stretched = UvChart { grad_u: 1.025 * b.grad_u, grad_v: 1.025 * b.grad_v, ..b };
            prop_assert!(UvChart::between(&a, &stretched).is_none());
        }
    }
}
