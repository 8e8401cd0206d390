//! Tests of the estimators through the public API, on the analytic plane and on small test
//! surfaces defined here. Expected values come from closed forms or from quadratures written
//! independently in this file (never from the code under test).

use std::f64::consts::{FRAC_PI_4, PI};
use std::num::NonZeroU32;

use glam::DVec3;
use het_estimate::FieldCapabilities;
use het_estimate::analytic::{
    CheckField, ConstantField, Plane, PlanePoint, RampField, StripeField,
};
use het_estimate::pattern::{Check, Ramp, Stripe};
use het_estimate::{
    Averaging, CoefficientField, Coefficients, Estimate, Estimator, KernelParams, MissPolicy,
    Named, Region, Rgb, SampleBudget, SegmentParams, SemiMinorAxis, SoneParams, SplitMix64,
    SurfacePoint, SurfaceQuery, WidthScattering,
};
use proptest::prelude::*;

// ---------------------------------------------------------------------------------------------
// Helpers written independently of the crate.

/// Isotropic exact ⟨θ²⟩ = (π² − 4)/2.
const ISO_THETA2: f64 = (PI * PI - 4.0) / 2.0;

/// The stripe pattern, re-implemented from its definition in `pattern.rs`'s docs.
fn stripe_index(x: f64, y: f64, width: f64, angle: f64) -> usize {
    let u = x * angle.cos() + y * angle.sin();
    let k = (u / width + 0.5).floor() as i64;
    k.rem_euclid(2) as usize
}

/// The paper's Figure 4 stripe preset: width 4, 45°, σa 0.005 / 0.1, σs = 1.
fn stripe_preset() -> StripeField {
    StripeField {
        pattern: Stripe::new(4.0, FRAC_PI_4),
        values: [Coefficients::grey(0.005, 1.0), Coefficients::grey(0.1, 1.0)],
    }
}

/// Eq. (2) exactly as printed in the paper (σs > 0).
fn eq2(theta2: f64, ss: f64, sa: f64, d: f64) -> f64 {
    let ell = ss * d / 2.0;
    (theta2 * ell * (d / 2.0).powi(2) / (24.0 * (1.0 + theta2 * (sa / ss) * ell * ell / 12.0)))
        .sqrt()
}

/// Midpoint-rule area average of `f` over the ellipse `m + a s x̂ + b t ŷ` (s² + t² ≤ 1) in
/// the plane z = 0, with ŷ = ẑ × x̂, on a `g × g` grid of the square [−1, 1]².
fn ellipse_quadrature(
    m: [f64; 2],
    xh: [f64; 2],
    a: f64,
    b: f64,
    g: usize,
    f: impl Fn(f64, f64) -> f64,
) -> f64 {
    let yh = [-xh[1], xh[0]];
    let (mut sum, mut n) = (0.0, 0u64);
    for j in 0..g {
        let t = -1.0 + (j as f64 + 0.5) * 2.0 / g as f64;
        for i in 0..g {
            let s = -1.0 + (i as f64 + 0.5) * 2.0 / g as f64;
            if s * s + t * t <= 1.0 {
                sum += f(
                    m[0] + a * s * xh[0] + b * t * yh[0],
                    m[1] + a * s * xh[1] + b * t * yh[1],
                );
                n += 1;
            }
        }
    }
    sum / n as f64
}

fn fixed(n: u32) -> SampleBudget {
    SampleBudget::Fixed(NonZeroU32::new(n).unwrap())
}

/// Sone with fixed budgets and Monte Carlo averaging (the sampling under test; the
/// prefiltered default is tested explicitly).
fn sone(disk: u32, ellipse: u32) -> SoneParams {
    let mut p = SoneParams::paper().with_averaging(Averaging::MonteCarlo);
    p.disk = fixed(disk);
    p.ellipse = fixed(ellipse);
    p
}

fn segment(n: u32) -> SegmentParams {
    SegmentParams::new().with_samples(fixed(n))
}

/// A coefficient field given by a closure (for test surfaces).
struct FnField<F>(F);
impl<P, F: Fn(&P) -> Coefficients> CoefficientField<P> for FnField<F> {
    fn coefficients(&self, p: &P) -> Coefficients {
        (self.0)(p)
    }
}

/// A slab between z = 0 (normal +z) and z = −thickness (normal −z): lets x_i and x_o lie on
/// opposite faces, with n_i = −n_o and n_i ∥ (x_o − x_i).
struct Slab {
    thickness: f64,
}
#[derive(Debug, Clone, Copy)]
struct SlabPoint {
    p: DVec3,
    n: DVec3,
}
impl SurfacePoint for SlabPoint {
    fn position(&self) -> DVec3 {
        self.p
    }
    fn normal(&self) -> DVec3 {
        self.n
    }
}
impl SurfaceQuery for Slab {
    type Point = SlabPoint;
    fn project(&self, o: DVec3, dir: DVec3) -> Option<SlabPoint> {
        if dir.z.abs() < 1e-12 {
            return None;
        }
        let t_top = -o.z / dir.z;
        let t_bot = (-self.thickness - o.z) / dir.z;
        let (t, n) = if t_top.abs() <= t_bot.abs() {
            (t_top, DVec3::Z)
        } else {
            (t_bot, -DVec3::Z)
        };
        let p = o + t * dir;
        p.is_finite().then_some(SlabPoint { p, n })
    }
}

/// A surface that never reports a hit (every projection misses).
struct Nowhere;
impl SurfaceQuery for Nowhere {
    type Point = PlanePoint;
    fn project(&self, _: DVec3, _: DVec3) -> Option<PlanePoint> {
        None
    }
}

fn run<S: SurfaceQuery, F: CoefficientField<S::Point>>(
    e: Estimator,
    g: f64,
    s: &S,
    f: &F,
    x_i: &S::Point,
    x_o: &S::Point,
    seed: u64,
) -> Estimate {
    e.prepare(g, 1.3)
        .unwrap()
        .estimate(s, f, x_i, x_o, &mut SplitMix64::new(seed))
}

fn all_estimators(n: u32) -> [Estimator; 6] {
    [
        Estimator::JensenIn,
        Estimator::JensenOut,
        Estimator::Endpoints,
        Estimator::Segment(segment(n)),
        Estimator::Sone(sone(n, n)),
        Estimator::Kernel(KernelParams::new().with_samples(fixed(n))),
    ]
}

fn mean_sd(v: &[f64]) -> (f64, f64) {
    let n = v.len() as f64;
    let m = v.iter().sum::<f64>() / n;
    let var = v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (n - 1.0);
    (m, var.sqrt())
}

// ---------------------------------------------------------------------------------------------
// Names and preparation.

#[test]
fn names_round_trip_and_are_exact() {
    let names: Vec<&str> = Estimator::ALL.iter().map(|e| e.name()).collect();
    assert_eq!(
        names,
        [
            "jensen-in",
            "jensen-out",
            "endpoints",
            "segment",
            "sone",
            "kernel"
        ]
    );
    for e in Estimator::ALL {
        let parsed: Estimator = e.to_string().parse().unwrap();
        assert_eq!(parsed, *e);
    }
    assert_eq!(
        "sone".parse::<Estimator>().unwrap(),
        Estimator::Sone(SoneParams::default())
    );
    let err = "Sone".parse::<Estimator>().unwrap_err();
    assert!(
        err.to_string()
            .contains("jensen-in, jensen-out, endpoints, segment, sone, kernel")
    );
    assert_eq!(
        "endpoints".parse::<MissPolicy>().unwrap(),
        MissPolicy::Endpoints
    );
}

#[test]
fn prepare_rejects_invalid_parameters() {
    for e in Estimator::ALL {
        assert!(e.prepare(1.0, 1.3).is_err());
        assert!(e.prepare(f64::NAN, 1.3).is_err());
        assert!(e.prepare(-0.99, 1.3).is_ok());
        assert!(e.prepare(0.0, 0.9).is_err());
        assert!(e.prepare(0.0, f64::NAN).is_err());
        assert!(e.prepare(0.0, 3.0).is_ok());
    }
    let mut p = SoneParams::paper();
    p.ellipse = SampleBudget::TargetRelError {
        rel_se: 0.0,
        max: NonZeroU32::new(64).unwrap(),
    };
    assert!(Estimator::Sone(p).prepare(0.0, 1.0).is_err());
    let prepared = Estimator::Sone(SoneParams::paper())
        .prepare(0.0, 1.0)
        .unwrap();
    assert!((prepared.mean_square_angle().unwrap() - ISO_THETA2).abs() < 1e-9);
    let mut p = SoneParams::paper();
    p.mean_square_angle = het_estimate::MeanSquareAngle::SmallAngle;
    let prepared = Estimator::Sone(p).prepare(0.5, 1.0).unwrap();
    assert_eq!(prepared.mean_square_angle(), Some(1.0));
}

// ---------------------------------------------------------------------------------------------
// Exact answers.

#[test]
fn constant_field_short_circuits_every_estimator() {
    let c = Coefficients {
        sigma_a: Rgb::new(0.01, 0.02, 0.03),
        sigma_s: Rgb::new(1.0, 2.0, 3.0),
    };
    let (x_i, x_o) = (PlanePoint::new(0.0, 0.0), PlanePoint::new(3.0, -4.0));
    for e in all_estimators(64) {
        let est = run(e, 0.3, &Plane, &ConstantField(c), &x_i, &x_o, 1);
        assert_eq!(est.coefficients, c, "{e}");
        let d = est.diagnostics;
        assert!(d.short_circuit, "{e}");
        assert_eq!((d.lookups, d.projections, d.samples), (0, 0, 0), "{e}");
        assert_eq!(d.region, Region::Constant);
    }
}

#[test]
fn point_lookups_are_exact() {
    let f = stripe_preset();
    let v = |p: &PlanePoint| f.values[stripe_index(p.x, p.y, 4.0, FRAC_PI_4)];
    for (a, b) in [
        ((0.0, 0.0), (3.0, 0.0)),
        ((-6.0, 1.0), (2.0, 2.0)),
        ((5.0, 5.0), (5.0, 5.0)),
    ] {
        let (x_i, x_o) = (PlanePoint::new(a.0, a.1), PlanePoint::new(b.0, b.1));
        let jin = run(Estimator::JensenIn, 0.0, &Plane, &f, &x_i, &x_o, 0);
        let jout = run(Estimator::JensenOut, 0.0, &Plane, &f, &x_i, &x_o, 0);
        let ends = run(Estimator::Endpoints, 0.0, &Plane, &f, &x_i, &x_o, 0);
        assert_eq!(jin.coefficients, v(&x_i));
        assert_eq!(jout.coefficients, v(&x_o));
        let want = (v(&x_i).sigma_a + v(&x_o).sigma_a) * 0.5;
        assert!((ends.coefficients.sigma_a - want).max_component().abs() < 1e-17);
        assert_eq!(ends.coefficients.sigma_s, Rgb::ONE);
        assert_eq!(jin.diagnostics.lookups, 1);
        assert_eq!(ends.diagnostics.lookups, 2);
        // σs is constant in this preset: counted, not averaged.
        assert_eq!(jin.diagnostics.constant_components, 3);
    }
}

/// A per-channel plane wave σ(p) = A + B cos(k·p), non-linear in every direction, so its
/// average over a region depends on the region's width, axis and orientation (a linear
/// field's does not: antithetic pairs average any centred region to the midpoint exactly).
fn wave(c: [(f64, f64, [f64; 2]); 6]) -> impl Fn(&PlanePoint) -> Coefficients + Copy {
    move |p: &PlanePoint| {
        let v = |k: usize| c[k].0 + c[k].1 * (c[k].2[0] * p.x + c[k].2[1] * p.y).cos();
        Coefficients {
            sigma_a: Rgb::new(v(0), v(1), v(2)),
            sigma_s: Rgb::new(v(3), v(4), v(5)),
        }
    }
}

/// Segment and Sone estimates on a non-linear field against independent quadratures, in every
/// channel, with the three channels' ellipses of different widths: the chord average for
/// `segment`; disk quadrature → Eq. (2) as printed → ellipse quadrature for `sone`, for both
/// semi-minor readings. Compared at 4 standard errors over 32 seeds plus the quadrature's own
/// error.
#[test]
fn nonlinear_field_matches_quadrature_in_every_channel() {
    // Wave vectors mostly across the chord (x̂ ≈ (0.75, −0.66)), wavelengths ≈ 2–4.
    let f = wave([
        (0.5, 0.4, [1.2, 1.4]),
        (0.2, 0.15, [2.0, 1.6]),
        (1.0, 0.6, [0.9, 1.3]),
        (2.0, 1.5, [1.1, 1.5]),
        (5.0, 2.0, [1.6, 1.8]),
        (1.0, 0.5, [0.7, 1.0]),
    ]);
    let field = FnField(f);
    let (x_i, x_o) = (PlanePoint::new(-1.0, 2.0), PlanePoint::new(3.0, -1.5));
    let (dx, dy) = (x_o.x - x_i.x, x_o.y - x_i.y);
    let d = (dx * dx + dy * dy).sqrt();
    let m = [(x_i.x + x_o.x) / 2.0, (x_i.y + x_o.y) / 2.0];
    let xh = [dx / d, dy / d];
    let at = |x: f64, y: f64| f(&PlanePoint::new(x, y));
    let channel = |c: Coefficients, k: usize| [c.sigma_a[k], c.sigma_s[k]];
    let seeds = 32u64;
    let check = |name: &str, ests: &[Estimate], want: &[[f64; 2]; 3]| {
        for (k, want_k) in want.iter().enumerate() {
            for (j, coef) in ["σa", "σs"].iter().enumerate() {
                let vals: Vec<f64> = ests.iter().map(|e| channel(e.coefficients, k)[j]).collect();
                let (mean, sd) = mean_sd(&vals);
                let se = sd / (seeds as f64).sqrt();
                let w = want_k[j];
                assert!(
                    (mean - w).abs() < 4.0 * se + 1e-4 * w,
                    "{name} channel {k} {coef}: {mean} ± {se}, quadrature {w}"
                );
            }
        }
    };
    // Segment: uniform along the chord (midpoint rule).
    let q = 100_000;
    let mut seg_want = [[0.0; 2]; 3];
    for i in 0..q {
        let t = (i as f64 + 0.5) / q as f64;
        let c = at(x_i.x + t * dx, x_i.y + t * dy);
        for (k, w) in seg_want.iter_mut().enumerate() {
            let v = channel(c, k);
            w[0] += v[0] / q as f64;
            w[1] += v[1] / q as f64;
        }
    }
    let ests: Vec<Estimate> = (0..seeds)
        .map(|s| {
            run(
                Estimator::Segment(segment(64)),
                0.0,
                &Plane,
                &field,
                &x_i,
                &x_o,
                s,
            )
        })
        .collect();
    check("segment", &ests, &seg_want);
    // Sone, per channel.
    let g = 1000;
    for semi in SemiMinorAxis::ALL {
        let mut want = [[0.0; 2]; 3];
        let mut widths = [0.0; 3];
        for k in 0..3 {
            let comp = |j: usize| move |x: f64, y: f64| channel(at(x, y), k)[j];
            let disk_sa = ellipse_quadrature(m, xh, d / 2.0, d / 2.0, g, comp(0));
            let disk_ss = ellipse_quadrature(m, xh, d / 2.0, d / 2.0, g, comp(1));
            let w = eq2(ISO_THETA2, disk_ss, disk_sa, d);
            let b = if *semi == SemiMinorAxis::HalfWidth {
                w / 2.0
            } else {
                w
            };
            widths[k] = w;
            want[k] = [
                ellipse_quadrature(m, xh, d / 2.0, b, g, comp(0)),
                ellipse_quadrature(m, xh, d / 2.0, b, g, comp(1)),
            ];
        }
        let mut p = sone(256, 256);
        p.semi_minor = *semi;
        let ests: Vec<Estimate> = (0..seeds)
            .map(|s| run(Estimator::Sone(p), 0.0, &Plane, &field, &x_i, &x_o, s))
            .collect();
        check(&format!("sone {semi:?}"), &ests, &want);
        for (k, want_w) in widths.iter().enumerate() {
            let ws: Vec<f64> = ests
                .iter()
                .map(|e| e.diagnostics.width.unwrap()[k])
                .collect();
            let (mw, _) = mean_sd(&ws);
            assert!(
                (mw - want_w).abs() < 0.02 * want_w,
                "channel {k}: width {mw} vs {want_w}"
            );
        }
        assert!(
            widths[0] != widths[1] && widths[1] != widths[2],
            "three distinct ellipses expected"
        );
        // 3 ellipses × n points, plus n disk points.
        assert_eq!(ests[0].diagnostics.projections, 4 * 256);
    }
}

/// A linear field averages exactly to its value at the midpoint (all regions are centrally
/// symmetric about m and the samples come in antithetic pairs), and the field's own exact
/// ellipse-average hook must give the same without sampling. This checks the hook and the
/// antithetic pairing, not the regions' shape: `nonlinear_field_matches_quadrature_in_every_channel`
/// does that.
#[test]
fn linear_ramp_gives_the_centroid_value() {
    let ramp = |v0: f64, gx: f64, gy: f64| Ramp {
        v0,
        gradient: [gx, gy],
    };
    let field = RampField {
        sigma_a: [
            ramp(0.5, 0.01, 0.02),
            ramp(0.2, -0.01, 0.005),
            ramp(1.0, 0.0, 0.03),
        ],
        sigma_s: [
            ramp(2.0, 0.05, -0.03),
            ramp(5.0, 0.1, 0.1),
            ramp(1.0, -0.02, 0.0),
        ],
    };
    let (x_i, x_o) = (PlanePoint::new(-1.0, 2.0), PlanePoint::new(3.0, -1.5));
    let m = ((x_i.x + x_o.x) / 2.0, (x_i.y + x_o.y) / 2.0);
    // The widest region (b = w can exceed d/2) stays in the linear domain.
    assert!(field.min_over_disk(m.0, m.1, 12.0) > 0.0);
    let want = field.linear(m.0, m.1);
    let close = |c: Coefficients| {
        (c.sigma_a - want.sigma_a).map(f64::abs).max_component() < 1e-12
            && (c.sigma_s - want.sigma_s).map(f64::abs).max_component() < 1e-12
    };
    for n in [2, 16, 64] {
        let est = run(
            Estimator::Segment(segment(n)),
            0.0,
            &Plane,
            &field,
            &x_i,
            &x_o,
            n as u64,
        );
        assert!(
            close(est.coefficients),
            "segment n={n}: {:?}",
            est.coefficients
        );
        for semi_minor in SemiMinorAxis::ALL {
            let mut p = sone(n, n);
            p.semi_minor = *semi_minor;
            p.averaging = Averaging::MonteCarlo;
            let est = run(Estimator::Sone(p), 0.2, &Plane, &field, &x_i, &x_o, 7);
            assert!(
                close(est.coefficients),
                "sone n={n}: {:?}",
                est.coefficients
            );
            let w = est.diagnostics.width.unwrap();
            assert!(
                w[0] != w[1] && w[1] != w[2],
                "three distinct ellipses expected"
            );
            // 3 ellipses × n points, plus n disk points.
            assert_eq!(est.diagnostics.projections, 4 * n);
            // The field's own exact ellipse average gives the same, without sampling.
            p.averaging = Averaging::Prefiltered;
            let fa = run(Estimator::Sone(p), 0.2, &Plane, &field, &x_i, &x_o, 7);
            assert!(close(fa.coefficients));
            assert_eq!(fa.diagnostics.field_averages, 4);
            assert_eq!(fa.diagnostics.projections, 0);
        }
    }
    // The presets too (the reference preset stops early: a linear field has no variance).
    for p in [SoneParams::paper(), SoneParams::reference()] {
        let mut p = p;
        p.averaging = Averaging::MonteCarlo;
        let est = run(Estimator::Sone(p), 0.0, &Plane, &field, &x_i, &x_o, 3);
        assert!(close(est.coefficients), "{p:?}: {:?}", est.coefficients);
    }
}

/// The Sone estimate on the Figure 4 stripe preset against an independent computation:
/// disk quadrature → ⟨σa⟩ → Eq. (2) as printed → ellipse quadrature. Compared at 4 standard
/// errors (measured over 64 seeds) plus the quadrature's own error. The two semi-minor
/// readings give answers ~7 standard errors apart here, so a wrong b fails. The prefiltered
/// default (closed form, no variance) must match within the quadrature's error alone.
#[test]
fn sone_stripe_matches_brute_force_quadrature() {
    let f = stripe_preset();
    for averaging in Averaging::ALL {
        let sa = |x: f64, y: f64| f.values[stripe_index(x, y, 4.0, FRAC_PI_4)].sigma_a[0];
        for (xo, semi) in [
            ((6.0, 1.0), SemiMinorAxis::HalfWidth),
            ((-3.0, 9.0), SemiMinorAxis::Width),
        ] {
            let (x_i, x_o) = (PlanePoint::new(0.0, 0.0), PlanePoint::new(xo.0, xo.1));
            let d = (xo.0 * xo.0 + xo.1 * xo.1).sqrt();
            let m = [xo.0 / 2.0, xo.1 / 2.0];
            let xh = [xo.0 / d, xo.1 / d];
            let g = 2000;
            let disk_sa = ellipse_quadrature(m, xh, d / 2.0, d / 2.0, g, sa);
            let w = eq2(ISO_THETA2, 1.0, disk_sa, d);
            let b = if semi == SemiMinorAxis::HalfWidth {
                w / 2.0
            } else {
                w
            };
            let want = ellipse_quadrature(m, xh, d / 2.0, b, g, sa);

            let mut p = sone(512, 512).with_averaging(*averaging);
            p.semi_minor = semi;
            let ests: Vec<Estimate> = (0..64)
                .map(|s| run(Estimator::Sone(p), 0.0, &Plane, &f, &x_i, &x_o, s))
                .collect();
            let vals: Vec<f64> = ests.iter().map(|e| e.coefficients.sigma_a[0]).collect();
            let (mean, sd) = mean_sd(&vals);
            let se = sd / 8.0;
            assert!(
                (mean - want).abs() < 4.0 * se + 1e-4 * want,
                "{mean} vs {want} (se {se})"
            );
            // The reported width and step-1 mean agree with the independent ones.
            let ws: Vec<f64> = ests
                .iter()
                .map(|e| e.diagnostics.width.unwrap()[0])
                .collect();
            assert!(
                (mean_sd(&ws).0 - w).abs() < 2e-3 * w,
                "width {} vs {w}",
                mean_sd(&ws).0
            );
            assert_eq!(ests[0].diagnostics.region, Region::Ellipse);
            assert!(ests.iter().all(|e| e.coefficients.sigma_s == Rgb::ONE));
            let answered = ests[0].diagnostics.field_averages;
            match averaging {
                Averaging::Prefiltered => assert!(answered == 2 && se <= 1e-12 * mean),
                Averaging::MonteCarlo => assert!(answered == 0 && se > 0.0),
            }
        }
    }
}

/// Henyey–Greenstein ⟨θ²⟩ = ∫ θ² p(θ) dω by the midpoint rule in θ (independent of the crate).
fn hg_theta2(g: f64) -> f64 {
    let n = 200_000;
    let h = PI / n as f64;
    (0..n)
        .map(|k| {
            let t = (k as f64 + 0.5) * h;
            let p = (1.0 - g * g) / (4.0 * PI * (1.0 + g * g - 2.0 * g * t.cos()).powf(1.5));
            t * t * p * 2.0 * PI * t.sin() * h
        })
        .sum()
}

/// Eq. (2)'s three readings for g ≠ 0: the width Sone reports is Eq. (2) with σs or
/// (1 − g)σs, and the phase function's ⟨θ²⟩ or the isotropic one; at g = 0 all three agree.
#[test]
fn width_scattering_readings_of_eq2() {
    let f = stripe_preset();
    let sa = |x: f64, y: f64| f.values[stripe_index(x, y, 4.0, FRAC_PI_4)].sigma_a[0];
    let xo = (6.0, 1.0);
    let (x_i, x_o) = (PlanePoint::new(0.0, 0.0), PlanePoint::new(xo.0, xo.1));
    let d = (xo.0 * xo.0 + xo.1 * xo.1).sqrt();
    let m = [xo.0 / 2.0, xo.1 / 2.0];
    let xh = [xo.0 / d, xo.1 / d];
    let disk_sa = ellipse_quadrature(m, xh, d / 2.0, d / 2.0, 2000, sa);
    for g in [0.0, 0.8] {
        for (reading, theta2, ss) in [
            (WidthScattering::Unreduced, hg_theta2(g), 1.0),
            (WidthScattering::Reduced, hg_theta2(g), 1.0 - g),
            (WidthScattering::SimilarIsotropic, ISO_THETA2, 1.0 - g),
        ] {
            let mut p = sone(512, 512);
            p.width_scattering = reading;
            let ws: Vec<f64> = (0..16)
                .map(|s| {
                    run(Estimator::Sone(p), g, &Plane, &f, &x_i, &x_o, s)
                        .diagnostics
                        .width
                        .unwrap()[0]
                })
                .collect();
            let want = eq2(theta2, ss, disk_sa, d);
            let got = mean_sd(&ws).0;
            assert!(
                (got - want).abs() < 2e-3 * want,
                "g {g}, {reading}: width {got} vs {want}"
            );
        }
    }
}

/// The segment estimator against an independent midpoint quadrature along the chord.
#[test]
fn segment_stripe_matches_quadrature() {
    let f = stripe_preset();
    let (x_i, x_o) = (PlanePoint::new(-1.0, 0.5), PlanePoint::new(7.0, 3.0));
    let q = 200_000;
    let want = (0..q)
        .map(|k| {
            let t = (k as f64 + 0.5) / q as f64;
            let (x, y) = (x_i.x + t * (x_o.x - x_i.x), x_i.y + t * (x_o.y - x_i.y));
            f.values[stripe_index(x, y, 4.0, FRAC_PI_4)].sigma_a[0]
        })
        .sum::<f64>()
        / q as f64;
    let vals: Vec<f64> = (0..32)
        .map(|s| {
            run(
                Estimator::Segment(segment(256)),
                0.0,
                &Plane,
                &f,
                &x_i,
                &x_o,
                s,
            )
            .coefficients
            .sigma_a[0]
        })
        .collect();
    let (mean, sd) = mean_sd(&vals);
    let se = sd / (32f64).sqrt();
    assert!(
        (mean - want).abs() < 4.0 * se + 1e-5,
        "{mean} vs {want} (se {se})"
    );
}

/// With σs = 0 the width is 0 and the ellipse degenerates to the chord; the average is then
/// the chord average with the semicircle weight √(1 − s²) (the continuous limit), checked
/// against an independent quadrature, and continuous in σs → 0.
#[test]
fn zero_width_limit_is_the_semicircle_weighted_chord_average() {
    let sigma_a = [0.02, 0.3];
    let field_with = |ss: f64| StripeField {
        pattern: Stripe::new(3.0, 0.3),
        values: [
            Coefficients::grey(sigma_a[0], ss),
            Coefficients::grey(sigma_a[1], ss),
        ],
    };
    let (x_i, x_o) = (PlanePoint::new(0.5, 0.0), PlanePoint::new(9.0, 4.0));
    let q = 400_000;
    let (mut num, mut den) = (0.0, 0.0);
    for k in 0..q {
        let s = -1.0 + (k as f64 + 0.5) * 2.0 / q as f64;
        let t = (s + 1.0) / 2.0;
        let (x, y) = (x_i.x + t * (x_o.x - x_i.x), x_i.y + t * (x_o.y - x_i.y));
        let wgt = (1.0 - s * s).sqrt();
        num += wgt * sigma_a[stripe_index(x, y, 3.0, 0.3)];
        den += wgt;
    }
    let want = num / den;
    let vals = |ss: f64| -> Vec<f64> {
        (0..32)
            .map(|s| {
                let e = run(
                    Estimator::Sone(sone(64, 256)),
                    0.0,
                    &Plane,
                    &field_with(ss),
                    &x_i,
                    &x_o,
                    s,
                );
                if ss == 0.0 {
                    assert_eq!(e.diagnostics.region, Region::DegenerateEllipse);
                    assert_eq!(e.diagnostics.width.unwrap(), Rgb::ZERO);
                }
                e.coefficients.sigma_a[0]
            })
            .collect()
    };
    let (mean, sd) = mean_sd(&vals(0.0));
    assert!(
        (mean - want).abs() < 4.0 * sd / 32f64.sqrt() + 1e-5,
        "{mean} vs {want}"
    );
    let (tiny, _) = mean_sd(&vals(1e-9));
    assert!(
        (tiny - mean).abs() < 1e-6,
        "not continuous: {tiny} vs {mean}"
    );
}

#[test]
fn zero_distance_is_a_point_lookup() {
    let f = CheckField {
        pattern: Check { width: 2.0 },
        values: [Coefficients::grey(0.1, 2.0), Coefficients::grey(0.4, 0.5)],
    };
    let p = PlanePoint::new(2.5, 0.3);
    for e in [
        Estimator::Segment(segment(16)),
        Estimator::Sone(sone(16, 16)),
    ] {
        let est = run(e, 0.0, &Plane, &f, &p, &p, 3);
        assert_eq!(est.coefficients, f.values[1]);
        assert_eq!(est.diagnostics.region, Region::Endpoints);
        assert_eq!(est.diagnostics.projections, 0);
    }
}

// ---------------------------------------------------------------------------------------------
// Statistics.

/// The standard deviation over seeds shrinks at least as fast as 1/√N (N → 4N halves it or
/// better; randomised low-discrepancy points do better). Measured over 300 seeds per N, so
/// the ratio's own sampling error is ~6%; the bound 0.6 leaves room for that.
#[test]
fn standard_deviation_shrinks_at_least_as_one_over_sqrt_n() {
    let f = stripe_preset();
    let (x_i, x_o) = (PlanePoint::new(0.0, 0.0), PlanePoint::new(5.0, 2.0));
    let sd_at = |e: Estimator| {
        let v: Vec<f64> = (0..300)
            .map(|s| {
                run(e, 0.0, &Plane, &f, &x_i, &x_o, 1000 + s)
                    .coefficients
                    .sigma_a[0]
            })
            .collect();
        mean_sd(&v).1
    };
    for (small, big) in [
        (
            Estimator::Segment(segment(16)),
            Estimator::Segment(segment(64)),
        ),
        (Estimator::Sone(sone(16, 16)), Estimator::Sone(sone(64, 64))),
        (Estimator::Sone(sone(4, 4)), Estimator::Sone(sone(16, 16))),
    ] {
        let (a, b) = (sd_at(small), sd_at(big));
        assert!(a > 0.0, "{small}: no variance at all?");
        assert!(b / a < 0.6, "{small}: sd {a} -> {b} (ratio {})", b / a);
    }
}

/// The adaptive budget meets its target on the stripe preset, and its answer agrees with a
/// large fixed-N run within the claimed error.
#[test]
fn target_relative_error_budget() {
    let f = stripe_preset();
    let (x_i, x_o) = (PlanePoint::new(0.0, 0.0), PlanePoint::new(5.0, 2.0));
    let mut p = SoneParams::paper().with_samples(SampleBudget::TargetRelError {
        rel_se: 0.01,
        max: NonZeroU32::new(4096).unwrap(),
    });
    p.averaging = Averaging::MonteCarlo;
    let est = run(Estimator::Sone(p), 0.0, &Plane, &f, &x_i, &x_o, 11);
    let err = est.diagnostics.rel_std_error.unwrap();
    assert!(err <= 0.01, "{err}");
    assert!(est.diagnostics.samples < 2 * 4096);
    let reference: Vec<f64> = (0..8)
        .map(|s| {
            run(
                Estimator::Sone(sone(4096, 4096)),
                0.0,
                &Plane,
                &f,
                &x_i,
                &x_o,
                s,
            )
            .coefficients
            .sigma_a[0]
        })
        .collect();
    let r = mean_sd(&reference).0;
    // 5 claimed standard errors (the error estimate itself has 7 degrees of freedom).
    assert!(
        (est.coefficients.sigma_a[0] - r).abs() < 5.0 * err * r,
        "{} vs {r}",
        est.coefficients.sigma_a[0]
    );
}

// ---------------------------------------------------------------------------------------------
// Symmetry, misses, degenerate geometry, invalid fields.

#[test]
fn estimators_are_symmetric_in_x_i_and_x_o_on_a_plane() {
    let f = stripe_preset();
    let mut rng = SplitMix64::new(42);
    use het_estimate::UniformSource;
    for _ in 0..50 {
        let mut pt = || PlanePoint::new(20.0 * rng.next_f64() - 10.0, 20.0 * rng.next_f64() - 10.0);
        let (a, b) = (pt(), pt());
        for e in all_estimators(16).into_iter().skip(2) {
            let ab = run(e, 0.5, &Plane, &f, &a, &b, 9).coefficients;
            let ba = run(e, 0.5, &Plane, &f, &b, &a, 9).coefficients;
            assert_eq!(ab, ba, "{e}");
        }
    }
}

#[test]
fn all_misses_fall_back_to_the_endpoints() {
    let f = stripe_preset();
    let (x_i, x_o) = (PlanePoint::new(0.0, 0.0), PlanePoint::new(3.0, 0.0));
    let ends = run(Estimator::Endpoints, 0.0, &Plane, &f, &x_i, &x_o, 0).coefficients;
    for e in [
        Estimator::Segment(segment(8)),
        Estimator::Sone(sone(8, 8)),
        // Projected points (the in-plane reading, like Sone's closed forms, takes the
        // surface to be the plane and never misses).
        Estimator::Kernel(
            KernelParams::new()
                .with_samples(fixed(8))
                .with_averaging(Averaging::MonteCarlo),
        ),
    ] {
        let est = run(e, 0.0, &Nowhere, &f, &x_i, &x_o, 0);
        assert_eq!(est.coefficients, ends);
        assert!(est.diagnostics.fallback);
        assert_eq!(est.diagnostics.misses, est.diagnostics.projections);
    }
}

/// Hits-only averaging over a surface that covers only part of the region: a half-plane
/// x < 0 (misses for x ≥ 0) with a field that is 1 for x < −1 and 3 elsewhere; the
/// segment average over hits is the chord's mean over its part with x < 0.
#[test]
fn hits_only_averages_over_the_part_that_projects() {
    struct HalfPlane;
    impl SurfaceQuery for HalfPlane {
        type Point = PlanePoint;
        fn project(&self, o: DVec3, d: DVec3) -> Option<PlanePoint> {
            Plane.project(o, d).filter(|p| p.x < 0.0)
        }
    }
    let f = FnField(|p: &PlanePoint| Coefficients::grey(if p.x < -1.0 { 1.0 } else { 3.0 }, 1.0));
    // Chord from x = −4 to x = 4 (the endpoint x_o = 4 itself lies off the half-plane, which
    // does not matter to the lookup at the endpoints).
    let (x_i, x_o) = (PlanePoint::new(-4.0, 0.0), PlanePoint::new(4.0, 0.0));
    let est = run(
        Estimator::Segment(segment(4096)),
        0.0,
        &HalfPlane,
        &f,
        &x_i,
        &x_o,
        5,
    );
    // Over x ∈ [−4, 0): 3/4 of the length has 1, 1/4 has 3 → 1.5.
    assert!(
        (est.coefficients.sigma_a[0] - 1.5).abs() < 2e-3,
        "{:?}",
        est.coefficients
    );
    let miss_rate = est.diagnostics.misses as f64 / est.diagnostics.projections as f64;
    assert!((miss_rate - 0.5).abs() < 2e-3);
    // With the endpoint policy a miss counts as ½(σ(x_i) + σ(x_o)) = 2.
    let mut p = segment(4096);
    p.misses = MissPolicy::Endpoints;
    let est = run(Estimator::Segment(p), 0.0, &HalfPlane, &f, &x_i, &x_o, 5);
    assert!((est.coefficients.sigma_a[0] - (0.5 * 1.5 + 0.5 * 2.0)).abs() < 2e-3);
}

#[test]
fn degenerate_normals_give_finite_results() {
    let slab = Slab { thickness: 2.0 };
    let f = FnField(|p: &SlabPoint| {
        let top = p.n.z > 0.0;
        Coefficients::grey(if top { 0.1 } else { 0.3 }, 1.0 + p.p.x.abs().min(5.0))
    });
    let top = SlabPoint {
        p: DVec3::ZERO,
        n: DVec3::Z,
    };
    for bottom in [DVec3::new(0.0, 0.0, -2.0), DVec3::new(0.3, 0.1, -2.0)] {
        let bot = SlabPoint {
            p: bottom,
            n: -DVec3::Z,
        };
        for e in all_estimators(16) {
            let est = run(e, 0.0, &slab, &f, &top, &bot, 1);
            assert!(est.coefficients.is_valid(), "{e}: {:?}", est.coefficients);
        }
        let est = run(Estimator::Sone(sone(16, 16)), 0.0, &slab, &f, &top, &bot, 1);
        if bottom.x == 0.0 {
            assert!(est.diagnostics.normal_fallback);
        }
    }
}

#[test]
fn invalid_field_values_are_a_debug_assertion_and_sanitised_in_release() {
    let f = FnField(|_: &PlanePoint| Coefficients {
        sigma_a: Rgb::new(f64::NAN, -1.0, f64::INFINITY),
        sigma_s: Rgb::splat(1.0),
    });
    let (x_i, x_o) = (PlanePoint::new(0.0, 0.0), PlanePoint::new(3.0, 1.0));
    for e in all_estimators(8) {
        let r = std::panic::catch_unwind(|| run(e, 0.0, &Plane, &f, &x_i, &x_o, 0));
        let debug = cfg!(debug_assertions);
        assert_eq!(
            r.is_err(),
            debug,
            "{e}: panics exactly when debug assertions are on"
        );
        if let Ok(est) = r {
            assert!(est.coefficients.is_valid());
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Property sweeps: finite, non-negative, within bounds, for extreme inputs.

fn coefficient() -> impl Strategy<Value = f64> {
    prop_oneof![Just(0.0), (-6.0f64..6.0).prop_map(|e| 10f64.powf(e))]
}

fn coefficients() -> impl Strategy<Value = Coefficients> {
    (coefficient(), coefficient(), coefficient(), coefficient()).prop_map(|(a0, a1, s0, s1)| {
        Coefficients {
            sigma_a: Rgb::new(a0, a1, a0),
            sigma_s: Rgb::new(s0, s0, s1),
        }
    })
}

fn position() -> impl Strategy<Value = (f64, f64)> {
    prop_oneof![
        (-10.0f64..10.0, -10.0f64..10.0),
        (-1e9f64..1e9, -1e9f64..1e9),
        (-1e-6f64..1e-6, -1e-6f64..1e-6),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn estimates_are_finite_non_negative_and_bounded(
        v0 in coefficients(),
        v1 in coefficients(),
        width in (-3.0f64..3.0).prop_map(|e| 10f64.powf(e)),
        angle in 0.0f64..PI,
        g in -0.99f64..0.99,
        a in position(),
        b in position(),
        same in any::<bool>(),
        n in 1u32..40,
        semi in any::<bool>(),
        seed in any::<u64>(),
    ) {
        let f = StripeField { pattern: Stripe::new(width, angle), values: [v0, v1] };
        let x_i = PlanePoint::new(a.0, a.1);
        let x_o = if same { x_i } else { PlanePoint::new(b.0, b.1) };
        let bounds = f.bounds().unwrap();
        for e in all_estimators(n) {
            let e = match e {
                Estimator::Sone(mut p) => {
                    if semi { p.semi_minor = SemiMinorAxis::Width; }
                    Estimator::Sone(p)
                }
                e => e,
            };
            let est = run(e, g, &Plane, &f, &x_i, &x_o, seed);
            let c = est.coefficients;
            prop_assert!(c.is_valid(), "{}: {:?}", e, c);
            for k in 0..3 {
                prop_assert!(c.sigma_a[k] >= bounds.min.sigma_a[k] && c.sigma_a[k] <= bounds.max.sigma_a[k]);
                prop_assert!(c.sigma_s[k] >= bounds.min.sigma_s[k] && c.sigma_s[k] <= bounds.max.sigma_s[k]);
            }
            if let Some(w) = est.diagnostics.width {
                prop_assert!(w.is_finite() && w.min_component() >= 0.0);
            }
            // The bounds above hold by construction (`Known::finish` clamps to them). With the
            // bounds hidden nothing is clamped or short-circuited, so the averaging itself must
            // stay within them: a mean of values in [lo, hi] lies in [lo, hi] up to rounding.
            let hidden = FnField(|p: &PlanePoint| f.coefficients(p));
            let raw = run(e, g, &Plane, &hidden, &x_i, &x_o, seed).coefficients;
            let within = |v: f64, lo: f64, hi: f64| {
                let tol = 1e-12 * hi.max(1e-300);
                v >= lo - tol && v <= hi + tol
            };
            for k in 0..3 {
                prop_assert!(
                    within(raw.sigma_a[k], bounds.min.sigma_a[k], bounds.max.sigma_a[k]),
                    "{}: unclamped σa {:?} outside {:?}", e, raw.sigma_a, bounds
                );
                prop_assert!(
                    within(raw.sigma_s[k], bounds.min.sigma_s[k], bounds.max.sigma_s[k]),
                    "{}: unclamped σs {:?} outside {:?}", e, raw.sigma_s, bounds
                );
            }
        }
    }

    #[test]
    fn degenerate_geometry_sweep(
        dx in prop_oneof![Just(0.0), -1e-3f64..1e-3, -50.0f64..50.0],
        dy in prop_oneof![Just(0.0), -50.0f64..50.0],
        thickness in prop_oneof![Just(1e-9), 0.01f64..100.0, Just(1e9)],
        g in prop_oneof![Just(-0.99), Just(0.99), -0.99f64..0.99],
        ss in coefficient(),
        sa in coefficient(),
        seed in any::<u64>(),
    ) {
        let slab = Slab { thickness };
        let f = FnField(move |p: &SlabPoint| {
            Coefficients::grey(if p.n.z > 0.0 { sa } else { 0.5 * sa }, ss * (1.0 + (p.p.x * 0.1).sin().abs()))
        });
        let top = SlabPoint { p: DVec3::ZERO, n: DVec3::Z };
        let bot = SlabPoint { p: DVec3::new(dx, dy, -thickness), n: -DVec3::Z };
        for e in all_estimators(8) {
            for (p, q) in [(&top, &bot), (&bot, &top), (&top, &top)] {
                let est = run(e, g, &slab, &f, p, q, seed);
                prop_assert!(est.coefficients.is_valid(), "{}: {:?}", e, est.coefficients);
            }
        }
    }
}

/// A sphere of radius 5 at the origin, for reciprocity on a curved surface.
struct Sphere;
#[derive(Clone, Copy)]
struct SpherePoint(DVec3);
impl het_estimate::SurfacePoint for SpherePoint {
    fn position(&self) -> DVec3 {
        self.0
    }
    fn normal(&self) -> DVec3 {
        self.0.normalize()
    }
}
impl SurfaceQuery for Sphere {
    type Point = SpherePoint;
    fn project(&self, o: DVec3, d: DVec3) -> Option<SpherePoint> {
        let (b, c) = (o.dot(d), o.length_squared() - 25.0);
        let disc = b * b - c;
        if disc < 0.0 {
            return None;
        }
        let t = [-b - disc.sqrt(), -b + disc.sqrt()]
            .into_iter()
            .min_by(|x, y| x.abs().total_cmp(&y.abs()))?;
        Some(SpherePoint(o + t * d))
    }
}

#[test]
fn averaging_estimators_are_reciprocal_on_a_curved_surface() {
    // Stripes of absorption in space, seen on a sphere: x_i and x_o have different normals, so
    // the paper's plane normal n_i* would differ between the two orders.
    let f = FnField(|p: &SpherePoint| {
        let stripe = ((p.0.x + 0.7 * p.0.y) / 1.5).floor().rem_euclid(2.0);
        Coefficients::grey(if stripe == 0.0 { 0.005 } else { 0.1 }, 1.0 + 0.1 * p.0.z)
    });
    let mut rng = SplitMix64::new(17);
    use het_estimate::UniformSource;
    let mut on_sphere = || {
        let v = DVec3::new(
            rng.next_f64() - 0.5,
            rng.next_f64() - 0.5,
            rng.next_f64() + 0.2,
        );
        SpherePoint(5.0 * v.normalize())
    };
    let mut differs = 0;
    for _ in 0..50 {
        let (a, b) = (on_sphere(), on_sphere());
        for e in all_estimators(16).into_iter().skip(2) {
            let ab = run(e, 0.5, &Sphere, &f, &a, &b, 9).coefficients;
            let ba = run(e, 0.5, &Sphere, &f, &b, &a, 9).coefficients;
            assert_eq!(ab, ba, "{e}: not reciprocal");
        }
        // The point lookups are the non-reciprocal baselines: jensen-in swaps into jensen-out.
        let [jin, jout, ..] = all_estimators(16);
        let fwd = run(jin, 0.5, &Sphere, &f, &a, &b, 9).coefficients;
        assert_eq!(fwd, run(jout, 0.5, &Sphere, &f, &b, &a, 9).coefficients);
        differs += usize::from(fwd != run(jin, 0.5, &Sphere, &f, &b, &a, 9).coefficients);
    }
    assert!(
        differs > 5,
        "the test field never distinguishes the two points"
    );
}

// ---------------------------------------------------------------------------------------------
// The optional averaging space (`CoefficientField::averaged` / `coefficients_of_mean`).

/// A stripe field whose coefficients are twice the stored values, stated in two ways: `Direct`
/// returns 2·v as coefficients; `Halved` averages v and maps each mean m to 2·m. Doubling is
/// exact in floating point, so every estimator must give bit-identical results for the two
/// if and only if it maps every mean it uses (widths, weights, fallbacks, the result) through
/// `coefficients_of_mean` and nothing else.
struct Doubled {
    stripes: StripeField,
    averaging_space: bool,
}

impl Doubled {
    fn double(c: Coefficients) -> Coefficients {
        Coefficients {
            sigma_a: c.sigma_a * 2.0,
            sigma_s: c.sigma_s * 2.0,
        }
    }
}

impl CoefficientField<PlanePoint> for Doubled {
    fn coefficients(&self, p: &PlanePoint) -> Coefficients {
        Self::double(self.stripes.coefficients(p))
    }
    fn bounds(&self) -> Option<het_estimate::FieldBounds> {
        let b = self.stripes.bounds()?;
        Some(if self.averaging_space {
            b
        } else {
            het_estimate::FieldBounds {
                min: Self::double(b.min),
                max: Self::double(b.max),
            }
        })
    }
    fn ellipse_average(&self, e: &het_estimate::PlanarEllipse) -> Option<Coefficients> {
        let m = self.stripes.ellipse_average(e)?;
        Some(if self.averaging_space {
            m
        } else {
            Self::double(m)
        })
    }
    fn capabilities(&self) -> FieldCapabilities {
        FieldCapabilities {
            ellipse_average: true,
            own_averaging_space: self.averaging_space,
            ..FieldCapabilities::default()
        }
    }
    fn averaged(&self, p: &PlanePoint) -> Coefficients {
        if self.averaging_space {
            self.stripes.coefficients(p)
        } else {
            self.coefficients(p)
        }
    }
    fn coefficients_of_mean(&self, mean: Coefficients) -> Coefficients {
        if self.averaging_space {
            Self::double(mean)
        } else {
            mean
        }
    }
}

#[test]
fn averaging_space_means_are_mapped_back_everywhere() {
    let stripes = StripeField {
        pattern: Stripe::new(1.5, 0.4),
        values: [
            Coefficients {
                sigma_a: Rgb::new(0.01, 0.02, 0.03),
                sigma_s: Rgb::new(1.0, 0.5, 2.0),
            },
            Coefficients {
                sigma_a: Rgb::new(0.2, 0.1, 0.05),
                sigma_s: Rgb::new(0.3, 1.5, 0.7),
            },
        ],
    };
    let direct = Doubled {
        stripes,
        averaging_space: false,
    };
    let mapped = Doubled {
        stripes,
        averaging_space: true,
    };
    // The kernel's power mean is specific to σa: fields with their own averaging space get
    // arithmetic means, so compare with exponent 1.
    let mut estimators: Vec<Estimator> = <Estimator as Named>::ALL
        .iter()
        .copied()
        .filter(|e| !matches!(e, Estimator::Kernel(_)))
        .collect();
    estimators.push(Estimator::Kernel(KernelParams::new().with_exponent(1.0)));
    estimators.push(Estimator::Sone(
        SoneParams::paper().with_averaging(Averaging::MonteCarlo),
    ));
    for est in estimators {
        let prepared = est.prepare(0.2, 1.3).unwrap();
        for (k, (a, b)) in [
            ((0.1, 0.2), (1.9, -0.7)),
            ((0.0, 0.0), (0.3, 0.1)),
            ((-2.0, 1.0), (-2.0, 1.0)),
        ]
        .into_iter()
        .enumerate()
        {
            let (x_i, x_o) = (PlanePoint::new(a.0, a.1), PlanePoint::new(b.0, b.1));
            let one =
                prepared.estimate(&Plane, &direct, &x_i, &x_o, &mut SplitMix64::new(k as u64));
            let two =
                prepared.estimate(&Plane, &mapped, &x_i, &x_o, &mut SplitMix64::new(k as u64));
            assert_eq!(one.coefficients, two.coefficients, "{est:?} pair {k}");
            assert!(one.coefficients.is_valid());
        }
    }
}

/// The kernel's in-plane reading (its default on flat pairs of fields defined in space) reads
/// the values its projections would: on the plane, every pair's estimate equals the
/// Monte Carlo one to the bit (same seed, same points), with no projection at all; Monte
/// Carlo averaging projects every point.
#[test]
fn kernel_in_plane_reading_equals_projection() {
    let field = stripe_preset();
    for k in 0..40 {
        let t = k as f64;
        let x_i = PlanePoint::new(0.0, 0.0);
        let x_o = PlanePoint::new(12.0 * (0.7 * t).sin(), 9.0 * (1.3 * t).cos());
        let kernel = |averaging: Averaging| {
            let params = KernelParams::new().with_averaging(averaging);
            run(
                Estimator::Kernel(params),
                0.0,
                &Plane,
                &field,
                &x_i,
                &x_o,
                k,
            )
        };
        let (pre, mc) = (
            kernel(Averaging::Prefiltered),
            kernel(Averaging::MonteCarlo),
        );
        assert_eq!(pre.coefficients, mc.coefficients, "pair {k}");
        if pre.diagnostics.region == Region::Kernel {
            assert_eq!(pre.diagnostics.projections, 0, "pair {k}");
            assert_eq!(pre.diagnostics.field_averages, 1, "pair {k}");
            assert_eq!(mc.diagnostics.projections, 64, "pair {k}");
        }
    }
}

/// One valid range from fields to profiles: a field whose values exceed the profiles' limit
/// (1e15, and 1e300 for σs) gives estimates clamped to `SIGMA_MAX` for every estimator, which
/// the profiles accept, never the 5e289 the old accumulation limit allowed.
#[test]
fn estimates_stay_in_the_profiles_range() {
    use het_estimate::bssrdf_core::{ProfileFamily, ProfileModel, SIGMA_MAX, Scattering};

    struct Huge;
    impl CoefficientField<PlanePoint> for Huge {
        fn coefficients(&self, p: &PlanePoint) -> Coefficients {
            let v = if p.x > 0.0 { 1e15 } else { 0.5 };
            Coefficients::grey(v, 1e300)
        }
    }
    let family = ProfileFamily::new(ProfileModel::Dipole, Scattering::Multiple, 0.0, 1.3).unwrap();
    let (x_i, x_o) = (PlanePoint::new(0.5, 0.1), PlanePoint::new(0.7, -0.2));
    for estimator in Estimator::ALL {
        let prepared = estimator.prepare(0.0, 1.3).unwrap();
        let c = prepared
            .estimate(&Plane, &Huge, &x_i, &x_o, &mut SplitMix64::new(3))
            .coefficients;
        for ch in 0..3 {
            assert!(
                (0.0..=SIGMA_MAX).contains(&c.sigma_a[ch]) && c.sigma_s[ch] == SIGMA_MAX,
                "{estimator}: {c:?}"
            );
        }
        assert!(c.validate().is_ok(), "{estimator}");
        assert!(
            family.profile_rgb(c.sigma_a, c.sigma_s).is_ok(),
            "{estimator}"
        );
    }
}
