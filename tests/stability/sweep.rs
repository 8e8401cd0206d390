//! The numerical-stability sweep (issue 7): every public numerical function of `bssrdf-core` and
//! `het-estimate` evaluated over a grid of extreme inputs, with statistics per function and a
//! record of every violation (NaN, ±∞, negative value, missing sample).
//!
//! Shared by the `stability` test module (which fails on any violation and prints the offending
//! inputs) and `examples/stability_sweep.rs` (which writes `docs/stability.md`); the example
//! includes this file with `#[path]`, so it depends only on the library crates and `glam`.
//!
//! # Grid
//! σa, σs ∈ [`SIGMAS`] (0 and 1e-6 … 1e6, which covers the task's 1e-6 … 1e4 and the project
//! standard's σt up to 1e6), g ∈ [`GS`], η ∈ [`ETAS`], radii r ∈ [`RADII`] (0 … 1e9) and chord
//! lengths d ∈ [`DISTANCES`] (0 … 1e9).
//!
//! # What is checked
//! * Profiles (every [`ProfileModel`] × every [`Scattering`]): `eval(r)`, `total()`,
//!   `sample_r(u)` (must be `Some` for a non-zero profile), `pdf_r(r)` and `pdf_r` at the
//!   sampled radius (must be > 0: the renderer divides by it), `radius_for_fraction(f)`.
//! * The table sampler ([`ProfileTable::sampler`]) for the same profiles: the same five
//!   methods, plus [`ProfileTable::rho_eff`] / [`ProfileTable::invert_rho_eff`].
//! * The directional dipole `S_d` (FHK14) over nine geometries, degenerate ones included.
//! * The path-integral width of Eq. (2) ([`path_integral::width`]) with both ⟨θ²⟩ choices.
//! * Every estimator (and Sone variants) on the analytic plane with stripe and check fields
//!   built from the grid's coefficient pairs, x_i and x_o separated by every d (0 included);
//!   then a degenerate-geometry pass (points on pattern boundaries, chords along the pattern
//!   normal, normals parallel to the chord, opposite, zero or tiny normals).
//!   Estimates must be finite, ≥ 0 and inside the field's bounds; the Sone width finite, ≥ 0.
//!
//! Every value must be finite and ≥ 0; anything else is a [`Violation`], recorded with the
//! inputs that produced it.

use std::collections::BTreeMap;
use std::time::Instant;

use bssrdf_core::glam::DVec3;
use bssrdf_core::{ProfileFamily, ProfileModel, ProfileTable, RadialProfile, Rgb, Scattering};
use het_estimate::analytic::{Plane, PlanePoint, StripeField};
use het_estimate::path_integral::{self, MeanSquareAngle};
use het_estimate::pattern::{Check, Stripe};
use het_estimate::{
    Averaging, CoefficientField, Coefficients, Estimator, FieldBounds, MissPolicy, Named,
    SampleBudget, SemiMinorAxis, SoneParams, SplitMix64, SurfacePoint, SurfaceQuery,
};

/// Coefficient values (1/length) for σa and σs.
pub const SIGMAS: [f64; 8] = [0.0, 1e-6, 1e-4, 1e-2, 1.0, 1e2, 1e4, 1e6];
/// Henyey–Greenstein g values.
pub const GS: [f64; 5] = [-0.99, -0.5, 0.0, 0.5, 0.99];
/// Relative indices of refraction.
pub const ETAS: [f64; 4] = [1.0, 1.33, 2.0, 3.0];
/// Radii (length) for profile evaluation.
pub const RADII: [f64; 10] = [0.0, 1e-9, 1e-6, 1e-3, 0.1, 1.0, 10.0, 1e3, 1e6, 1e9];
/// Chord lengths x_i–x_o (length).
pub const DISTANCES: [f64; 6] = [0.0, 1e-9, 1e-3, 1.0, 1e3, 1e9];
/// Uniform numbers for `sample_r`, extremes included.
const US: [f64; 6] = [0.0, 1e-12, 0.3, 0.5, 0.999_999, 1.0 - f64::EPSILON];
/// Energy fractions for `radius_for_fraction`.
const FRACTIONS: [f64; 4] = [0.0, 0.5, 0.999, 1.0];
/// Violations kept (with their inputs) per function; the rest are only counted.
const KEEP: usize = 20;

/// How much of the sweep to run.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Extent {
    /// Everything (the example, and the test when it is fast enough).
    Full,
    /// A deterministic subset: the numerical totals and radii of photon beam diffusion (the
    /// expensive part) only on every `n`-th coefficient pair.
    Strided(usize),
}

impl Extent {
    fn keep(self, index: usize) -> bool {
        match self {
            Extent::Full => true,
            Extent::Strided(n) => index.is_multiple_of(n.max(1)),
        }
    }
}

/// A value that broke the contract: not finite, negative, or a missing/zero-density sample.
#[derive(Debug, Clone)]
pub struct Violation {
    /// The function and its inputs.
    pub inputs: String,
    /// The offending value (NaN, ±∞, negative; 0 or NaN for a missing sample).
    pub value: f64,
}

/// Statistics of one function's outputs over the sweep.
#[derive(Debug, Clone)]
pub struct Stat {
    /// Evaluations.
    pub evals: u64,
    /// Outputs exactly 0.
    pub zeros: u64,
    /// Smallest output.
    pub min: f64,
    /// Smallest positive output.
    pub min_pos: f64,
    /// Largest output.
    pub max: f64,
    /// Label and (min, max) of a derived quantity (`2πr·R`, `r·S_d`, `w/d`, …), if any.
    pub derived: Option<(&'static str, f64, f64)>,
    /// CPU seconds spent in the function (summed over threads; includes loop overhead).
    pub seconds: f64,
    /// Violations.
    pub violations: u64,
    /// The first [`KEEP`] violations with their inputs.
    pub examples: Vec<Violation>,
}

impl Default for Stat {
    fn default() -> Self {
        Self {
            evals: 0,
            zeros: 0,
            min: f64::INFINITY,
            min_pos: f64::INFINITY,
            max: f64::NEG_INFINITY,
            derived: None,
            seconds: 0.0,
            violations: 0,
            examples: Vec::new(),
        }
    }
}

impl Stat {
    /// Records one output; `inputs` is only called for a violation.
    #[inline]
    pub fn record(&mut self, v: f64, inputs: impl FnOnce() -> String) {
        self.evals += 1;
        if !(v.is_finite() && v >= 0.0) {
            self.violate(v, inputs);
            return;
        }
        if v == 0.0 {
            self.zeros += 1;
        } else {
            self.min_pos = self.min_pos.min(v);
        }
        self.min = self.min.min(v);
        self.max = self.max.max(v);
    }

    /// Records a derived quantity (no violation check: its base value is checked).
    #[inline]
    pub fn derive(&mut self, label: &'static str, v: f64) {
        if !v.is_finite() {
            return;
        }
        let (_, lo, hi) = self
            .derived
            .get_or_insert((label, f64::INFINITY, f64::NEG_INFINITY));
        *lo = lo.min(v);
        *hi = hi.max(v);
    }

    /// Records a contract violation that is not about the value's range (a missing sample).
    pub fn violate(&mut self, v: f64, inputs: impl FnOnce() -> String) {
        self.violations += 1;
        if self.examples.len() < KEEP {
            self.examples.push(Violation {
                inputs: inputs(),
                value: v,
            });
        }
    }

    fn merge(&mut self, o: &Stat) {
        self.evals += o.evals;
        self.zeros += o.zeros;
        self.min = self.min.min(o.min);
        self.min_pos = self.min_pos.min(o.min_pos);
        self.max = self.max.max(o.max);
        if let Some((label, lo, hi)) = o.derived {
            let d = self
                .derived
                .get_or_insert((label, f64::INFINITY, f64::NEG_INFINITY));
            d.1 = d.1.min(lo);
            d.2 = d.2.max(hi);
        }
        self.seconds += o.seconds;
        self.violations += o.violations;
        for e in &o.examples {
            if self.examples.len() < KEEP {
                self.examples.push(e.clone());
            }
        }
    }
}

/// Key of a row: section (ordering), function, variant.
pub type Key = (u8, &'static str, String);

/// Every function's statistics, in section order.
#[derive(Debug, Clone, Default)]
pub struct Report {
    /// The rows.
    pub stats: BTreeMap<Key, Stat>,
    /// Wall-clock seconds of the whole sweep.
    pub wall_seconds: f64,
}

impl Report {
    /// The row for (`section`, `function`, `variant`), created on first use.
    pub fn stat(&mut self, section: u8, function: &'static str, variant: &str) -> &mut Stat {
        self.stats
            .entry((section, function, variant.to_string()))
            .or_default()
    }

    fn merge(&mut self, o: Report) {
        for (k, s) in o.stats {
            self.stats.entry(k).or_default().merge(&s);
        }
    }

    /// Total evaluations.
    pub fn evals(&self) -> u64 {
        self.stats.values().map(|s| s.evals).sum()
    }

    /// Total violations.
    pub fn violations(&self) -> u64 {
        self.stats.values().map(|s| s.violations).sum()
    }

    /// The first violations of every function, one per line (for a failure message).
    pub fn violation_lines(&self, max: usize) -> Vec<String> {
        self.stats
            .iter()
            .flat_map(|((_, f, v), s)| {
                s.examples
                    .iter()
                    .map(move |e| format!("{f} [{v}] {}: {}", e.inputs, e.value))
            })
            .take(max)
            .collect()
    }
}

/// Section numbers (row order in the report).
pub mod section {
    /// `Profile` methods.
    pub const PROFILE: u8 = 1;
    /// `RadiusSampler` methods.
    pub const TABLE: u8 = 2;
    /// Directional dipole.
    pub const DIRPOLE: u8 = 3;
    /// Path-integral width.
    pub const WIDTH: u8 = 4;
    /// Estimators on the analytic plane.
    pub const ESTIMATOR: u8 = 5;
    /// Estimators on degenerate geometry.
    pub const DEGENERATE: u8 = 6;
}

/// Runs the whole sweep (in parallel over (g, η) and over estimator cases).
pub fn run(extent: Extent) -> Report {
    use tracer::rayon::prelude::*;
    let start = Instant::now();
    let mut jobs: Vec<Job> = Vec::new();
    for &g in &GS {
        for &eta in &ETAS {
            jobs.push(Job::Profiles { g, eta });
            jobs.push(Job::Dirpole { g, eta });
        }
    }
    jobs.push(Job::Width);
    for (k, _) in estimator_cases().iter().enumerate() {
        for field in [FieldKind::Stripe, FieldKind::Check] {
            jobs.push(Job::Estimators { case: k, field });
        }
    }
    jobs.push(Job::Degenerate);
    let mut report =
        jobs.into_par_iter()
            .map(|job| job.run(extent))
            .reduce(Report::default, |mut a, b| {
                a.merge(b);
                a
            });
    report.wall_seconds = start.elapsed().as_secs_f64();
    report
}

#[derive(Debug, Clone, Copy)]
enum Job {
    Profiles { g: f64, eta: f64 },
    Dirpole { g: f64, eta: f64 },
    Width,
    Estimators { case: usize, field: FieldKind },
    Degenerate,
}

impl Job {
    fn run(self, extent: Extent) -> Report {
        let mut r = Report::default();
        match self {
            Job::Profiles { g, eta } => profiles(&mut r, g, eta, extent),
            Job::Dirpole { g, eta } => directional_dipole(&mut r, g, eta),
            Job::Width => widths(&mut r),
            Job::Estimators { case, field } => estimators(&mut r, case, field),
            Job::Degenerate => degenerate(&mut r),
        }
        r
    }
}

/// `(σa, σs)` for every pair of the grid.
fn sigma_pairs() -> impl Iterator<Item = (usize, f64, f64)> {
    SIGMAS
        .iter()
        .flat_map(|&a| SIGMAS.iter().map(move |&s| (a, s)))
        .enumerate()
        .map(|(i, (a, s))| (i, a, s))
}

fn variant(model: ProfileModel, sc: Scattering) -> String {
    format!("{model}/{sc}")
}

/// Times `f` into `stat.seconds`.
#[inline]
fn timed<T>(seconds: &mut f64, f: impl FnOnce() -> T) -> T {
    let t = Instant::now();
    let v = f();
    *seconds += t.elapsed().as_secs_f64();
    v
}

/// Checks the five `RadialProfile` methods of `p` (a `Profile` or a `RadiusSampler`).
#[allow(clippy::too_many_arguments)]
fn check_radial(
    r: &mut Report,
    sec: u8,
    kind: &'static str,
    var: &str,
    p: &impl RadialProfile,
    is_zero: bool,
    with_totals: bool,
    ctx: &dyn Fn() -> String,
) {
    let names: [&'static str; 5] = match sec {
        section::PROFILE => [
            "Profile::eval",
            "Profile::total",
            "Profile::sample_r",
            "Profile::pdf_r",
            "Profile::radius_for_fraction",
        ],
        _ => [
            "RadiusSampler::eval",
            "RadiusSampler::total",
            "RadiusSampler::sample_r",
            "RadiusSampler::pdf_r",
            "RadiusSampler::radius_for_fraction",
        ],
    };
    let _ = kind;
    {
        let st = r.stat(sec, names[0], var);
        for &rad in &RADII {
            let v = timed(&mut st.seconds, || p.eval(rad));
            st.record(v, || format!("{} r={rad:e}", ctx()));
            st.derive("2πr·R", std::f64::consts::TAU * rad * v);
        }
    }
    if with_totals {
        let st = r.stat(sec, names[1], var);
        let v = timed(&mut st.seconds, || p.total());
        st.record(v, ctx);
    }
    let mut samples = Vec::with_capacity(US.len());
    {
        let st = r.stat(sec, names[2], var);
        for &u in &US {
            let s = timed(&mut st.seconds, || p.sample_r(u));
            match s {
                Some(x) => {
                    st.record(x, || format!("{} u={u:e}", ctx()));
                    samples.push((u, x));
                }
                None if !is_zero => st.violate(f64::NAN, || {
                    format!("{} u={u:e}: None for a non-zero profile", ctx())
                }),
                None => {}
            }
        }
    }
    {
        let st = r.stat(sec, names[3], var);
        for &rad in &RADII {
            let v = timed(&mut st.seconds, || p.pdf_r(rad));
            st.record(v, || format!("{} r={rad:e}", ctx()));
        }
        // At its own samples the density must be positive: the renderer divides by it.
        for &(u, x) in &samples {
            let v = timed(&mut st.seconds, || p.pdf_r(x));
            st.record(v, || format!("{} at sample r={x:e} (u={u:e})", ctx()));
            // r = 0 (drawn at u = 0 exactly) may have density 0 in r: 2πr·R vanishes there.
            if v == 0.0 && x > 0.0 {
                st.violate(v, || {
                    format!("{} pdf 0 at its own sample r={x:e} (u={u:e})", ctx())
                });
            }
        }
    }
    if with_totals {
        let st = r.stat(sec, names[4], var);
        let mut prev = 0.0;
        for &f in &FRACTIONS {
            let v = timed(&mut st.seconds, || p.radius_for_fraction(f));
            st.record(v, || format!("{} f={f}", ctx()));
            if v < prev {
                st.violate(v, || {
                    format!("{} f={f}: radius {v:e} below the previous {prev:e}", ctx())
                });
            }
            prev = v;
        }
    }
}

/// Every profile model and scattering selection at one (g, η): `Profile` and the table
/// sampler.
fn profiles(r: &mut Report, g: f64, eta: f64, extent: Extent) {
    for &model in ProfileModel::ALL {
        for &sc in Scattering::ALL {
            // Single scattering does not depend on the model: sweep it once.
            if sc == Scattering::Single && model != ProfileModel::Dipole {
                continue;
            }
            let var = if sc == Scattering::Single {
                "any/single".to_string()
            } else {
                variant(model, sc)
            };
            let family = match ProfileFamily::new(model, sc, g, eta) {
                Ok(f) => f,
                // The table covers η ≤ 1.6; beyond, a typed error is the documented answer.
                Err(_)
                    if model == ProfileModel::Tabulated
                        && eta > bssrdf_core::tabulated::half_space::ETA_MAX =>
                {
                    continue;
                }
                Err(e) => panic!("{model} {sc} g={g} η={eta}: {e}"),
            };
            let expensive = model == ProfileModel::Pbd || sc == Scattering::All;
            for (i, sa, ss) in sigma_pairs() {
                let ctx = || format!("{var} σa={sa:e} σs={ss:e} g={g} η={eta}");
                let p = family.profile(sa, ss).expect("valid coefficients");
                let with_totals = !expensive || extent.keep(i);
                check_radial(
                    r,
                    section::PROFILE,
                    "profile",
                    &var,
                    &p,
                    p.is_zero(),
                    with_totals,
                    &ctx,
                );
            }
            let build = Instant::now();
            let table = ProfileTable::new(family);
            r.stat(section::TABLE, "ProfileTable::new", &var).seconds +=
                build.elapsed().as_secs_f64();
            r.stat(section::TABLE, "ProfileTable::new", &var).evals += 1;
            for (_, sa, ss) in sigma_pairs() {
                let ctx = || format!("{var} σa={sa:e} σs={ss:e} g={g} η={eta}");
                let s = table.sampler(sa, ss).expect("valid coefficients");
                check_radial(
                    r,
                    section::TABLE,
                    "table",
                    &var,
                    &s,
                    s.is_zero(),
                    true,
                    &ctx,
                );
            }
            let st = r.stat(section::TABLE, "ProfileTable::rho_eff/invert", &var);
            for alpha in [0.0, 1e-6, 0.3, 0.9, 0.999_999, 1.0] {
                let rho = timed(&mut st.seconds, || table.rho_eff(alpha));
                st.record(rho, || format!("{var} g={g} η={eta} α'={alpha}"));
                let back = timed(&mut st.seconds, || table.invert_rho_eff(rho));
                st.record(back, || format!("{var} g={g} η={eta} invert ρ={rho}"));
                if back > 1.0 {
                    st.violate(back, || format!("{var} g={g} η={eta} invert ρ={rho} > 1"));
                }
            }
        }
    }
}

/// Geometries of the directional dipole: `(name, x_i, w_i, n_i, chord direction, n_o)`.
fn dirpole_geometries() -> Vec<(&'static str, DVec3, DVec3, DVec3, DVec3, DVec3)> {
    let z = DVec3::Z;
    let x = DVec3::X;
    let o = DVec3::ZERO;
    let n = |v: DVec3| v.normalize();
    vec![
        ("flat, normal incidence", o, z, z, x, z),
        ("flat, grazing incidence", o, x, z, x, z),
        ("light from below", o, -z, z, x, z),
        ("exit through the opposite face", o, z, z, x, -z),
        ("chord along n_i (x_o below)", o, z, z, -z, z),
        ("chord along n_i (x_o above)", o, z, z, z, -z),
        ("perpendicular n_o", o, z, z, x, x),
        (
            "oblique",
            o,
            n(DVec3::new(0.5, -0.2, 0.8)),
            n(DVec3::new(0.3, 0.1, 1.0)),
            n(DVec3::new(0.6, 0.8, 0.0)),
            n(DVec3::new(-0.2, 0.3, 1.0)),
        ),
        (
            "far from the origin",
            DVec3::new(1e6, -1e6, 1e6),
            n(DVec3::new(0.1, 0.0, 1.0)),
            z,
            n(DVec3::new(1.0, 1.0, 0.0)),
            z,
        ),
    ]
}

fn directional_dipole(r: &mut Report, g: f64, eta: f64) {
    let family = ProfileFamily::new(ProfileModel::Dipole, Scattering::Multiple, g, eta)
        .expect("valid family");
    let geoms = dirpole_geometries();
    for (_, sa, ss) in sigma_pairs() {
        let dd = family
            .directional_dipole(sa, ss)
            .expect("valid coefficients");
        for &(name, x_i, w_i, n_i, dir, n_o) in &geoms {
            let st = r.stat(section::DIRPOLE, "DirectionalDipole::s_d", name);
            for &rad in &RADII {
                let x_o = x_i + rad * dir;
                let v = timed(&mut st.seconds, || dd.s_d(x_i, w_i, n_i, x_o, n_o));
                st.record(v, || {
                    format!("{name} σa={sa:e} σs={ss:e} g={g} η={eta} r={rad:e}")
                });
                st.derive("r²·S_d", rad * rad * v);
            }
        }
    }
}

fn widths(r: &mut Report) {
    let mut thetas: Vec<(String, f64)> = vec![("⟨θ²⟩=0".into(), 0.0)];
    for m in MeanSquareAngle::ALL {
        for &g in &GS {
            thetas.push((
                format!("{} g={g}", m.name()),
                m.evaluate(g).expect("valid g"),
            ));
        }
    }
    let st = r.stat(section::WIDTH, "path_integral::width", "Eq. (2)");
    for (label, t2) in &thetas {
        for (_, sa, ss) in sigma_pairs() {
            for &d in &DISTANCES {
                let w = timed(&mut st.seconds, || path_integral::width(*t2, ss, sa, d));
                match w {
                    Ok(w) => {
                        st.record(w, || format!("{label} σa={sa:e} σs={ss:e} d={d:e}"));
                        if d > 0.0 {
                            st.derive("w/d", w / d);
                        }
                    }
                    Err(e) => st.violate(f64::NAN, || {
                        format!("{label} σa={sa:e} σs={ss:e} d={d:e}: error {e}")
                    }),
                }
            }
        }
    }
}

/// The estimators swept: every named estimator with its defaults, then Sone variants.
pub fn estimator_cases() -> Vec<(String, Estimator)> {
    let mut v: Vec<(String, Estimator)> = Estimator::ALL
        .iter()
        .map(|e| (e.name().to_string(), *e))
        .collect();
    let mut alt = SoneParams::paper();
    alt.semi_minor = SemiMinorAxis::Width;
    alt.mean_square_angle = MeanSquareAngle::SmallAngle;
    alt.misses = MissPolicy::Endpoints;
    alt.averaging = Averaging::MonteCarlo;
    v.push((
        "sone (b=w, 2(1−g), miss→endpoints)".into(),
        Estimator::Sone(alt),
    ));
    let mut adaptive = SoneParams::paper();
    adaptive = adaptive.with_samples(SampleBudget::TargetRelError {
        rel_se: 0.05,
        max: std::num::NonZeroU32::new(256).expect("non-zero"),
    });
    v.push((
        "sone (target 5 % SE, ≤ 256)".into(),
        Estimator::Sone(adaptive),
    ));
    v
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum FieldKind {
    Stripe,
    Check,
}

/// A binary pattern field over the plane (stripe or check, width 1).
#[derive(Debug, Clone, Copy)]
enum PlaneField {
    Stripe(StripeField),
    Check(het_estimate::analytic::CheckField),
}

impl PlaneField {
    fn new(kind: FieldKind, values: [Coefficients; 2], angle: f64) -> Self {
        match kind {
            FieldKind::Stripe => PlaneField::Stripe(StripeField {
                pattern: Stripe::new(1.0, angle),
                values,
            }),
            FieldKind::Check => PlaneField::Check(het_estimate::analytic::CheckField {
                pattern: Check { width: 1.0 },
                values,
            }),
        }
    }
}

impl CoefficientField<PlanePoint> for PlaneField {
    fn coefficients(&self, p: &PlanePoint) -> Coefficients {
        match self {
            PlaneField::Stripe(f) => f.coefficients(p),
            PlaneField::Check(f) => f.coefficients(p),
        }
    }
    fn bounds(&self) -> Option<FieldBounds> {
        match self {
            PlaneField::Stripe(f) => f.bounds(),
            PlaneField::Check(f) => f.bounds(),
        }
    }
}

/// Checks one estimate: finite, ≥ 0, inside the bounds; Sone's width finite and ≥ 0.
fn check_estimate(
    st: &mut Stat,
    est: &het_estimate::Estimate,
    bounds: Option<FieldBounds>,
    ctx: &dyn Fn() -> String,
) {
    let c = est.coefficients;
    for ch in 0..3 {
        for (which, v) in [("σa", c.sigma_a[ch]), ("σs", c.sigma_s[ch])] {
            st.record(v, || format!("{} → {which}[{ch}]", ctx()));
        }
        if let Some(b) = bounds {
            let inside = |v: f64, lo: f64, hi: f64| v >= lo && v <= hi;
            if !inside(c.sigma_a[ch], b.min.sigma_a[ch], b.max.sigma_a[ch])
                || !inside(c.sigma_s[ch], b.min.sigma_s[ch], b.max.sigma_s[ch])
            {
                st.violate(c.sigma_a[ch], || {
                    format!("{} → channel {ch} outside the field's bounds: {c:?}", ctx())
                });
            }
        }
    }
    if let Some(w) = est.diagnostics.width {
        for ch in 0..3 {
            if !(w[ch].is_finite() && w[ch] >= 0.0) {
                st.violate(w[ch], || format!("{} → width[{ch}]", ctx()));
            }
        }
    }
}

/// Every estimator case on stripe and check fields made of every pair of grid coefficients,
/// chords of every length from a point at the centre of a cell.
fn estimators(r: &mut Report, case: usize, kind: FieldKind) {
    let cases = estimator_cases();
    let (name, estimator) = &cases[case];
    let is_sone = matches!(estimator, Estimator::Sone(_));
    let gs: &[f64] = if is_sone { &GS } else { &[0.0] };
    let adaptive = name.contains("target");
    let field_name = match kind {
        FieldKind::Stripe => "stripe",
        FieldKind::Check => "check",
    };
    let var = format!("{name} / {field_name}");
    let pairs: Vec<(f64, f64)> = sigma_pairs().map(|(_, a, s)| (a, s)).collect();
    let mut rng = SplitMix64::new(0x5eed ^ case as u64);
    let dir = DVec3::new(30f64.to_radians().cos(), 30f64.to_radians().sin(), 0.0);
    for &g in gs {
        let prepared = estimator.prepare(g, 1.3).expect("valid estimator");
        for (i, &(a0, s0)) in pairs.iter().enumerate() {
            for (j, &(a1, s1)) in pairs.iter().enumerate() {
                // The adaptive budget is ~10× dearer: a deterministic quarter of the pairs.
                if adaptive && (i + j) % 4 != 0 {
                    continue;
                }
                let values = [Coefficients::grey(a0, s0), Coefficients::grey(a1, s1)];
                let field = PlaneField::new(kind, values, 45f64.to_radians());
                let bounds = field.bounds();
                let st = r.stat(section::ESTIMATOR, "PreparedEstimator::estimate", &var);
                for &d in &DISTANCES {
                    let x_i = PlanePoint::new(0.0, 0.0);
                    let x_o = PlanePoint::new(d * dir.x, d * dir.y);
                    let est = timed(&mut st.seconds, || {
                        prepared.estimate(&Plane, &field, &x_i, &x_o, &mut rng)
                    });
                    let ctx = || {
                        format!(
                            "{var} g={g} values=[(σa {a0:e}, σs {s0:e}), (σa {a1:e}, σs {s1:e})] d={d:e}"
                        )
                    };
                    check_estimate(st, &est, bounds, &ctx);
                }
            }
        }
    }
}

/// A plane point with an arbitrary reported normal (degenerate-normal cases).
#[derive(Debug, Clone, Copy)]
struct NormalPoint {
    p: PlanePoint,
    n: DVec3,
}

impl SurfacePoint for NormalPoint {
    fn position(&self) -> DVec3 {
        self.p.position()
    }
    fn normal(&self) -> DVec3 {
        self.n
    }
}

/// The plane z = 0 whose projected points report the normal `n`.
struct NormalPlane {
    n: DVec3,
}

impl SurfaceQuery for NormalPlane {
    type Point = NormalPoint;
    fn project(&self, origin: DVec3, dir: DVec3) -> Option<NormalPoint> {
        Plane
            .project(origin, dir)
            .map(|p| NormalPoint { p, n: self.n })
    }
}

/// A plane field seen through [`NormalPoint`]s.
struct Lifted(PlaneField);

impl CoefficientField<NormalPoint> for Lifted {
    fn coefficients(&self, p: &NormalPoint) -> Coefficients {
        self.0.coefficients(&p.p)
    }
    fn bounds(&self) -> Option<FieldBounds> {
        self.0.bounds()
    }
}

/// Degenerate geometry: x_i at a cell centre, on a stripe boundary and on a check corner;
/// chords along the stripe normal, at 30° and along a boundary; normals +z, −z, along the
/// chord (n_i ∥ x̂, where FHK14's modified normal is undefined), tiny, and zero; non-grey
/// coefficient pairs of extreme contrast.
fn degenerate(r: &mut Report) {
    let contrast = [
        (0.0, 0.0),
        (0.0, 1e6),
        (1e6, 0.0),
        (1e-6, 1e-6),
        (1e6, 1e6),
        (1e-2, 1.0),
    ];
    let starts = [
        ("cell centre", PlanePoint::new(0.0, 0.0)),
        ("stripe/check boundary", PlanePoint::new(0.5, 0.0)),
        ("check corner", PlanePoint::new(0.5, 0.5)),
        ("far away", PlanePoint::new(1e9 + 0.5, -1e9)),
    ];
    let dirs = [
        ("along x", DVec3::X),
        ("30°", DVec3::new(0.866_025_403_784_438_6, 0.5, 0.0)),
        ("along the boundary", DVec3::Y),
    ];
    let cases = estimator_cases();
    let mut rng = SplitMix64::new(0xde9e);
    for (name, estimator) in &cases {
        let prepared = estimator.prepare(0.3, 1.3).expect("valid estimator");
        for kind in [FieldKind::Stripe, FieldKind::Check] {
            for &(a0, s0) in &contrast {
                for &(a1, s1) in &contrast {
                    // Non-grey: each channel takes the pair's values in a different order.
                    let v0 = Coefficients {
                        sigma_a: Rgb::new(a0, a1, a0),
                        sigma_s: Rgb::new(s0, s0, s1),
                    };
                    let v1 = Coefficients {
                        sigma_a: Rgb::new(a1, a0, a1),
                        sigma_s: Rgb::new(s1, s1, s0),
                    };
                    let field = Lifted(PlaneField::new(kind, [v0, v1], 0.0));
                    let bounds = field.bounds();
                    for &(start_name, x_i) in &starts {
                        for &(dir_name, dir) in &dirs {
                            let normals = [
                                ("+z", DVec3::Z, DVec3::Z),
                                ("−z", -DVec3::Z, -DVec3::Z),
                                ("n_i ∥ chord", dir, DVec3::Z),
                                ("n_i, n_o ∥ chord", dir, dir),
                                ("opposite", DVec3::Z, -DVec3::Z),
                                ("tiny", DVec3::new(0.0, 0.0, 1e-300), DVec3::Z),
                                ("zero", DVec3::ZERO, DVec3::ZERO),
                            ];
                            for &(n_name, n_i, n_o) in &normals {
                                let var = format!("{name} / normals {n_name}");
                                let st = r.stat(
                                    section::DEGENERATE,
                                    "PreparedEstimator::estimate",
                                    &var,
                                );
                                for &d in &DISTANCES {
                                    let p_o = PlanePoint::new(x_i.x + d * dir.x, x_i.y + d * dir.y);
                                    let pi = NormalPoint { p: x_i, n: n_i };
                                    let po = NormalPoint { p: p_o, n: n_o };
                                    let surface = NormalPlane { n: n_i };
                                    let est = timed(&mut st.seconds, || {
                                        prepared.estimate(&surface, &field, &pi, &po, &mut rng)
                                    });
                                    let ctx = || {
                                        format!(
                                            "{var} {start_name} {dir_name} d={d:e} v0={v0:?} v1={v1:?}"
                                        )
                                    };
                                    check_estimate(st, &est, bounds, &ctx);
                                }
                            }
                        }
                    }
                }
            }
        }
    }
}
