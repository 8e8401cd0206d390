//! Error against run time: the convergence study behind `het-bssrdf converge`.
//!
//! Every method is run at doubling budgets (samples per pixel, photons, or points per pixel)
//! and each result is compared with a reference. For each BSSRDF method the summary gives:
//! * its *converged error*: the relative L2 error at its largest budget (BSSRDF methods are
//!   biased, so their error levels off there);
//! * its *time to converge*: the wall time of the first budget whose error is within
//!   [`CONVERGED_TOLERANCE`] of the converged error;
//! * the *path-tracing time to the same error*: interpolated log–log between the two path
//!   tracing runs that bracket it, or, when path tracing never got that low, extrapolated from
//!   its last run along the Monte Carlo rate `error ∝ t^(−1/2)` (flagged as extrapolated);
//! * the *speed-up*: path-tracing time over the method's time — the quantity the paper
//!   reports as "roughly eight times";
//! * when the reference is itself path traced at a known budget B (`converge`'s default), the
//!   same time and speed-up *aware of the reference's noise*: every error is measured against
//!   a noisy reference, so a path-traced image at budget b has an expected squared relative
//!   error a·(1/b + 1/B) (its own noise plus the reference's, independent), not a/b. The
//!   error no longer falls like t^(−1/2) once 1/b nears 1/B, and extrapolating along that rate
//!   underestimates the path-tracing time. With a calibrated on the largest path-tracing run,
//!   the budget that reaches the error e is b = 1/(e²/a − 1/B) ([`time_to_error_with_reference`]).
//!   Within the path-tracing runs both figures are the same measured interpolation.

use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::error::WriteError;
use crate::metrics::Metrics;
use tracer::error::OutputError;
use tracer::output::{write_atomic, write_json};

/// A run counts as converged once its error is within this factor of the final error.
pub const CONVERGED_TOLERANCE: f64 = 1.1;

/// One run of one method at one budget.
#[derive(Debug, Clone, Serialize)]
pub struct Run {
    /// `pt` or the estimator name (with the profile for beam studies).
    pub method: String,
    /// Samples per pixel, photons, or points per pixel (see `unit`).
    pub budget: u64,
    /// What `budget` counts.
    pub unit: &'static str,
    /// Wall-clock seconds.
    pub seconds: f64,
    /// Errors against the reference.
    pub metrics: Metrics,
}

/// The summary of one BSSRDF method against path tracing.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
#[non_exhaustive]
pub struct MethodSummary {
    /// The method.
    pub method: String,
    /// Relative L2 error at the largest budget.
    #[serde(deserialize_with = "crate::metrics::null_as_nan")]
    pub converged_error: f64,
    /// Mean |log10(T/R)| at the largest budget (less dominated by the brightest pixels).
    #[serde(deserialize_with = "crate::metrics::null_as_nan")]
    pub converged_mean_abs_log10: f64,
    /// Seconds of the first run within `CONVERGED_TOLERANCE` of the converged error.
    #[serde(deserialize_with = "crate::metrics::null_as_nan")]
    pub time_to_converge: f64,
    /// Seconds path tracing needs to reach the same error (None without path-tracing runs).
    pub pt_time_to_same_error: Option<f64>,
    /// True when that time was extrapolated beyond the path-tracing runs.
    pub pt_extrapolated: bool,
    /// `pt_time_to_same_error / time_to_converge`.
    pub speedup: Option<f64>,
    /// The path-tracing time to the same error with the reference's own noise accounted for
    /// (see the module docs); `None` without path-tracing runs or a known reference budget,
    /// or when that error is below what path tracing can reach against this reference.
    #[serde(default)]
    pub pt_time_reference_aware: Option<f64>,
    /// `pt_time_reference_aware / time_to_converge`.
    #[serde(default)]
    pub speedup_reference_aware: Option<f64>,
}

/// Path-tracing time to reach `error`, from its `(seconds, error)` runs (see the module docs).
/// Returns the time and whether it was extrapolated.
pub fn time_to_error(pt: &[(f64, f64)], error: f64) -> Option<(f64, bool)> {
    let mut pts: Vec<(f64, f64)> = pt
        .iter()
        .copied()
        .filter(|(t, e)| *t > 0.0 && *e > 0.0 && e.is_finite())
        .collect();
    pts.sort_by(|a, b| a.0.total_cmp(&b.0));
    let (first, last) = (*pts.first()?, *pts.last()?);
    if error.is_nan() || error <= 0.0 {
        return None;
    }
    if first.1 <= error {
        // Already below at the cheapest run: go back along t^(-1/2).
        return Some((first.0 * (first.1 / error).powi(2), true));
    }
    for w in pts.windows(2) {
        let ((t0, e0), (t1, e1)) = (w[0], w[1]);
        if e1 <= error && e0 > error {
            let f = (error.ln() - e0.ln()) / (e1.ln() - e0.ln());
            return Some(((t0.ln() + f * (t1.ln() - t0.ln())).exp(), false));
        }
    }
    Some((last.0 * (last.1 / error).powi(2), true))
}

/// Path-tracing time to `error` against a reference that is a path-traced image of budget
/// `reference_budget` (same unit as the runs' budgets; see the module docs), from the `pt`
/// runs `(budget, seconds, error)`. Errors within the runs' range are interpolated as by
/// [`time_to_error`]; an error below the largest run's uses the noise model
/// e² = a·(1/b + 1/B), with a and the time per unit of budget from the largest run. `None`
/// without usable runs, or when e² ≤ a/B (the reference's own noise: unreachable).
pub fn time_to_error_with_reference(
    pt: &[(u64, f64, f64)],
    reference_budget: u64,
    error: f64,
) -> Option<f64> {
    let last = pt
        .iter()
        .filter(|(b, t, e)| *b > 0 && *t > 0.0 && *e > 0.0 && e.is_finite())
        .max_by_key(|(b, _, _)| *b)?;
    let (b_last, t_last, e_last) = (last.0 as f64, last.1, last.2);
    if error.is_nan() || error <= 0.0 || reference_budget == 0 {
        return None;
    }
    if error >= e_last {
        let timed: Vec<(f64, f64)> = pt.iter().map(|&(_, t, e)| (t, e)).collect();
        return time_to_error(&timed, error).map(|(t, _)| t);
    }
    let inv_ref = 1.0 / reference_budget as f64;
    let a = e_last * e_last / (1.0 / b_last + inv_ref);
    let inv_b = error * error / a - inv_ref;
    (inv_b > 0.0).then(|| t_last / b_last / inv_b)
}

/// Summarises every non-`pt` method of `runs` against the `pt` runs.
pub fn summarize(runs: &[Run]) -> Vec<MethodSummary> {
    summarize_with_reference(runs, None)
}

/// [`summarize`], and when the reference is path traced at `reference_budget` (in the runs'
/// unit) the reference-aware path-tracing time and speed-up too.
pub fn summarize_with_reference(runs: &[Run], reference_budget: Option<u64>) -> Vec<MethodSummary> {
    let pt_budgets: Vec<(u64, f64, f64)> = runs
        .iter()
        .filter(|r| r.method == "pt")
        .map(|r| (r.budget, r.seconds, r.metrics.rel_l2))
        .collect();
    let pt: Vec<(f64, f64)> = pt_budgets.iter().map(|&(_, t, e)| (t, e)).collect();
    let mut methods: Vec<&str> = Vec::new();
    for r in runs {
        if r.method != "pt" && !methods.contains(&r.method.as_str()) {
            methods.push(&r.method);
        }
    }
    methods
        .into_iter()
        .filter_map(|m| {
            let mut own: Vec<&Run> = runs.iter().filter(|r| r.method == m).collect();
            own.sort_by_key(|r| r.budget);
            let converged = own.last()?.metrics.rel_l2;
            let converged_log = own.last()?.metrics.mean_abs_log10;
            let time = own
                .iter()
                .find(|r| r.metrics.rel_l2 <= CONVERGED_TOLERANCE * converged)
                .map(|r| r.seconds)?;
            let pt_time = time_to_error(&pt, converged);
            let aware = reference_budget
                .and_then(|b| time_to_error_with_reference(&pt_budgets, b, converged));
            Some(MethodSummary {
                method: m.to_string(),
                converged_error: converged,
                converged_mean_abs_log10: converged_log,
                time_to_converge: time,
                pt_time_to_same_error: pt_time.map(|p| p.0),
                pt_extrapolated: pt_time.is_some_and(|p| p.1),
                speedup: pt_time.map(|p| p.0 / time.max(1e-12)),
                pt_time_reference_aware: aware,
                speedup_reference_aware: aware.map(|p| p / time.max(1e-12)),
            })
        })
        .collect()
}

/// The CSV `method,spp,seconds,rel_l2,rmse,mean_abs_log10,unit`.
pub fn csv(runs: &[Run]) -> String {
    let mut s = String::from("method,spp,seconds,rel_l2,rmse,mean_abs_log10,unit\n");
    for r in runs {
        s.push_str(&format!(
            "{},{},{:.6},{:.6e},{:.6e},{:.6e},{}\n",
            r.method,
            r.budget,
            r.seconds,
            r.metrics.rel_l2,
            r.metrics.rmse,
            r.metrics.mean_abs_log10,
            r.unit
        ));
    }
    s
}

/// Writes `convergence.csv`, `convergence.png` (+ `.svg`, feature `plot`) and `summary.json`
/// into `dir`.
pub fn write_outputs(
    dir: &Path,
    title: &str,
    runs: &[Run],
    summary: &[MethodSummary],
    extra: serde_json::Value,
) -> Result<(), WriteError> {
    write_atomic(&dir.join("convergence.csv"), csv(runs).as_bytes())?;
    #[cfg(feature = "plot")]
    {
        use crate::plot::{Series, loglog_png};
        let mut series: Vec<Series> = Vec::new();
        for r in runs {
            match series.iter_mut().find(|s| s.label == r.method) {
                Some(s) => s.points.push((r.seconds, r.metrics.rel_l2)),
                None => series.push(Series {
                    label: r.method.clone(),
                    points: vec![(r.seconds, r.metrics.rel_l2)],
                }),
            }
        }
        loglog_png(
            &dir.join("convergence.png"),
            title,
            "wall-clock seconds",
            "relative L2 error",
            &series,
        )?;
    }
    let mut value = serde_json::json!({ "title": title, "methods": summary });
    if let (Some(obj), serde_json::Value::Object(more)) = (value.as_object_mut(), extra) {
        obj.extend(more);
    }
    write_json(
        &pipeline::provenance::stamped(value),
        &dir.join("summary.json"),
    )?;
    Ok(())
}

/// Checks that `dir` exists, is a directory and accepts new files (before a long study).
pub fn check_dir(dir: &Path) -> Result<(), OutputError> {
    pipeline::files::check_dir_accepts_files(dir, &dir.join("convergence.csv"))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(method: &str, budget: u64, seconds: f64, rel_l2: f64) -> Run {
        Run {
            method: method.into(),
            budget,
            unit: "spp",
            seconds,
            metrics: Metrics {
                rel_l2,
                rmse: 0.0,
                mean_abs_log10: 0.0,
                values: 1,
                log_values: 1,
            },
        }
    }

    #[test]
    fn pt_time_interpolates_and_extrapolates_along_the_monte_carlo_rate() {
        // error = t^(-1/2): the error 0.25 is reached at t = 16 exactly.
        let pt: Vec<(f64, f64)> = [1.0, 4.0, 64.0]
            .iter()
            .map(|&t: &f64| (t, t.powf(-0.5)))
            .collect();
        let (t, ex) = time_to_error(&pt, 0.25).unwrap();
        assert!((t - 16.0).abs() < 1e-9 && !ex);
        let (t, ex) = time_to_error(&pt, 0.0625).unwrap();
        assert!((t - 256.0).abs() < 1e-9 && ex);
        let (t, ex) = time_to_error(&pt, 2.0).unwrap();
        assert!((t - 0.25).abs() < 1e-9 && ex);
        assert!(time_to_error(&[], 0.1).is_none());
    }

    #[test]
    fn reference_aware_time_follows_the_noise_model() {
        // Errors drawn from the model itself, a = 4, B = 64: e² = 4(1/b + 1/64), one second
        // per unit of budget. The budget that reaches e solves it exactly.
        let model = |b: f64| (4.0 * (1.0 / b + 1.0 / 64.0)).sqrt();
        let pt: Vec<(u64, f64, f64)> = [1u64, 2, 4, 8]
            .iter()
            .map(|&b| (b, b as f64, model(b as f64)))
            .collect();
        for b in [16.0, 100.0, 1000.0] {
            let t = time_to_error_with_reference(&pt, 64, model(b)).unwrap();
            assert!((t - b).abs() < 1e-9 * b, "{t} vs {b}");
        }
        // At or below the reference's own noise (a/B): unreachable.
        assert!(time_to_error_with_reference(&pt, 64, (4.0f64 / 64.0).sqrt()).is_none());
        // Within the runs: the measured interpolation, as time_to_error.
        let timed: Vec<(f64, f64)> = pt.iter().map(|&(_, t, e)| (t, e)).collect();
        let e = 0.5 * (model(2.0) + model(4.0));
        assert_eq!(
            time_to_error_with_reference(&pt, 64, e),
            time_to_error(&timed, e).map(|x| x.0)
        );
        // The naive rate underestimates the time once the reference's noise matters.
        let naive = time_to_error(&timed, model(100.0)).unwrap().0;
        assert!(naive < 0.5 * 100.0, "{naive}");
        assert!(time_to_error_with_reference(&[], 64, 0.1).is_none());
    }

    /// The noise model behind the reference-aware time, on real renders: against a path-traced
    /// reference of B = 16 spp, the squared relative error of b-spp path tracing is
    /// a·(1/b + 1/B) with one a for every b, while a/b alone (the naive rate) is off by
    /// (1 + b/B), a factor 2 at b = 16. Checker slab at 32², seeds fixed; the relative noise
    /// of a squared error over 1024 pixels is about 5 %.
    #[test]
    fn path_traced_errors_against_a_path_traced_reference_follow_the_model() {
        use pipeline::job::{RenderJob, render_scene};
        use tracer::integrator::Method;
        use tracer::render::Budget;
        let scene = tracer::scene::Scene::from_toml_str(
            crate::scenes::CHECKER_SLAB,
            Path::new("."),
            "checker-slab",
        )
        .unwrap()
        .with_resolution(32, 32)
        .unwrap();
        let render = |spp: u32, seed: u64| {
            let mut job = RenderJob::from_scene(&scene, Method::PathTraced);
            job.budget = Budget::Samples(spp);
            job.seed = seed;
            render_scene(&scene, &job).unwrap().film
        };
        let big = 16.0;
        let reference = render(16, 99);
        let a = |b: u32| {
            let e = crate::metrics::compare_films(&render(b, 7), &reference, None)
                .unwrap()
                .rel_l2;
            (
                e * e / (1.0 / f64::from(b) + 1.0 / big),
                e * e * f64::from(b),
            )
        };
        let ((a1, naive1), (a16, naive16)) = (a(1), a(16));
        assert!(
            (a16 / a1 - 1.0).abs() < 0.2,
            "model: a(16)/a(1) = {}",
            a16 / a1
        );
        assert!(naive16 / naive1 > 1.6, "naive: {}", naive16 / naive1);
    }

    #[test]
    fn summary_finds_converged_error_time_and_speedup() {
        let runs = vec![
            run("pt", 1, 1.0, 1.0),
            run("pt", 4, 4.0, 0.5),
            run("pt", 16, 16.0, 0.25),
            run("sone", 1, 0.5, 0.5),
            run("sone", 2, 1.0, 0.27),
            run("sone", 4, 2.0, 0.25),
        ];
        let s = summarize(&runs);
        assert_eq!(s.len(), 1);
        assert_eq!(s[0].converged_error, 0.25);
        assert_eq!(s[0].time_to_converge, 1.0); // 0.27 ≤ 1.1 × 0.25
        assert!((s[0].pt_time_to_same_error.unwrap() - 16.0).abs() < 1e-9);
        assert!((s[0].speedup.unwrap() - 16.0).abs() < 1e-9);
        assert!(!s[0].pt_extrapolated);
        let text = csv(&runs);
        assert!(text.starts_with("method,spp,seconds,rel_l2,rmse,mean_abs_log10,unit\npt,1,"));
        assert_eq!(text.lines().count(), 7);
    }
}
