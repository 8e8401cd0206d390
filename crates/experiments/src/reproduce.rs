//! `het-bssrdf reproduce`: the paper's experiments end to end — the Figure 4 beam maps for
//! both texture presets with every estimator and both profiles against light tracing, the
//! Figure 5 checker-slab renders, convergence studies on both — written as EXR + PNG + CSV
//! and summarised in `report.md`.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

use bssrdf_core::{ProfileModel, Scattering};
use serde::Serialize;

use crate::beam::{
    BeamSetup, BeamTexture, ColourRange, PhotonBudget, run_method, write_beam_map,
    write_beam_map_in,
};
use crate::converge::{MethodSummary, summarize, write_outputs};
use crate::error::WriteError;
use crate::ledger::{Ledger, LedgerError};
use crate::metrics::{ErrorRow, compare, compare_films};
use crate::scenes::CHECKER_SLAB;
use crate::study::{
    BeamBudgets, BeamReference, REFERENCE_SEED_OFFSET, StudyError, beam_study, scene_study,
};
use pipeline::files::write_render;
use pipeline::job::{RenderJob, render_scene};
use tracer::integrator::Method;
use tracer::output::{write_atomic, write_exr};
use tracer::render::Budget;
use tracer::scene::Scene;

/// How much work `reproduce` does.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Scale {
    /// Name shown in the report.
    pub name: &'static str,
    /// Beam map resolution N.
    pub beam_resolution: u32,
    /// Photons of the light-traced beam maps (the references of the beam comparisons).
    pub beam_photons: u64,
    /// K: K × K points per pixel of the BSSRDF beam maps.
    pub beam_subsamples: u32,
    /// Checker-slab resolution (square).
    pub slab_resolution: u32,
    /// Samples per pixel of the checker-slab renders.
    pub slab_spp: u32,
    /// Samples per pixel of the checker-slab path-traced reference.
    pub slab_reference_spp: u32,
    /// Largest spp of the checker-slab convergence study.
    pub converge_max_spp: u32,
    /// Largest photon count of the beam convergence study (from 2^16).
    pub converge_max_photons: u64,
    /// Largest K of the beam convergence study.
    pub converge_max_subsamples: u32,
    /// Expected wall time on 2 cores, for the up-front message.
    pub expected: &'static str,
}

impl Scale {
    /// A few seconds: the integration test's miniature.
    pub const TINY: Scale = Scale {
        name: "tiny",
        beam_resolution: 12,
        beam_photons: 1 << 14,
        beam_subsamples: 1,
        slab_resolution: 12,
        // Enough for the integration test to compare the path tracer with its reference at a
        // few % (still well under a second).
        slab_spp: 32,
        slab_reference_spp: 128,
        converge_max_spp: 2,
        converge_max_photons: 1 << 16,
        converge_max_subsamples: 1,
        expected: "a few seconds",
    };
    /// About 3 minutes on 2 quiet cores (`--quick`).
    pub const QUICK: Scale = Scale {
        name: "quick",
        beam_resolution: 120,
        beam_photons: 1 << 23,
        beam_subsamples: 4,
        slab_resolution: 128,
        slab_spp: 16,
        slab_reference_spp: 512,
        converge_max_spp: 32,
        converge_max_photons: 1 << 22,
        converge_max_subsamples: 4,
        expected: "about 3 minutes on 2 cores (measured 2m46s)",
    };
    /// The full run (about 15 minutes on 2 quiet cores).
    pub const FULL: Scale = Scale {
        name: "full",
        beam_resolution: 120,
        beam_photons: 1 << 26,
        beam_subsamples: 8,
        slab_resolution: 128,
        slab_spp: 64,
        slab_reference_spp: 4096,
        converge_max_spp: 128,
        converge_max_photons: 1 << 24,
        converge_max_subsamples: 8,
        expected: "about 15 minutes on 2 cores (measured 15m04s)",
    };
}

/// The BSSRDF estimators compared in the beam experiment.
pub const BEAM_ESTIMATORS: [&str; 4] = ["jensen-out", "segment", "endpoints", "sone"];
/// Methods of the checker-slab renders. The paper's Figure 5 shows Jensen's lookup at the
/// incident point (`jensen-in`); `jensen-out`, the exitant point as in its Figure 4, is kept
/// beside it.
pub const SLAB_METHODS: [&str; 4] = ["pt", "jensen-in", "jensen-out", "sone"];
/// Methods of the convergence studies.
pub const CONVERGE_METHODS: [&str; 4] = ["pt", "jensen-out", "endpoints", "sone"];

/// Why `reproduce` failed.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ReproduceError {
    /// A study or render.
    #[error(transparent)]
    Study(#[from] StudyError),
    /// Writing results.
    #[error(transparent)]
    Write(#[from] WriteError),
    /// `--resume` cannot use the earlier run's ledger.
    #[error(transparent)]
    Ledger(#[from] LedgerError),
    /// Creating a directory.
    #[error("cannot create the directory `{path}`")]
    Dir {
        /// The directory.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
}

impl From<tracer::error::OutputError> for ReproduceError {
    fn from(e: tracer::error::OutputError) -> Self {
        ReproduceError::Write(e.into())
    }
}

impl From<tracer::error::SceneError> for ReproduceError {
    fn from(e: tracer::error::SceneError) -> Self {
        ReproduceError::Study(e.into())
    }
}

fn mkdir(path: &Path) -> Result<(), ReproduceError> {
    std::fs::create_dir_all(path).map_err(|source| ReproduceError::Dir {
        path: path.to_path_buf(),
        source,
    })
}

/// A built-in method by name, Sone in the paper's literal reading (b = w/2,
/// [`het_estimate::SoneParams::paper`]): these are the paper's experiments.
fn method(name: &str) -> Method {
    let m: Method = name.parse().expect("built-in method names");
    m.with_semi_minor(Some(het_estimate::SemiMinorAxis::HalfWidth))
}

/// Every value rounded to `f32`, as an EXR holds it (see [`crate::ledger`]: references are
/// compared as written, so that a resumed run's numbers equal an uninterrupted one's).
fn as_written(values: &mut [f64]) {
    for v in values {
        *v = f64::from(*v as f32);
    }
}

/// Runs everything into `out` and writes `report.md`; `step(message)` is called before each
/// step (for progress display). Returns the report's path.
///
/// With `resume`, steps that an earlier run into `out` with the same scale and seed finished
/// are not run again: their numbers come from its ledger and their references from their
/// EXR files ([`crate::ledger`]).
pub fn reproduce(
    out: &Path,
    scale: &Scale,
    seed: u64,
    resume: bool,
    step: &mut dyn FnMut(&str),
) -> Result<PathBuf, ReproduceError> {
    let start = Instant::now();
    mkdir(out)?;
    let ledger = Ledger::open(out, scale.name, seed, resume)?;
    let mut run = Reproduction {
        out,
        scale,
        seed,
        ledger,
        step,
        rows: Vec::new(),
        report: String::new(),
    };
    let _ = writeln!(
        run.report,
        "# het-bssrdf: reproduction report\n\nScale `{}` ({}); seed {seed}; {} threads.\n",
        scale.name,
        scale.expected,
        rayon::current_num_threads()
    );
    let _ = writeln!(run.report, "{}", crate::commentary::METHODS_AND_METRICS);
    let stripe_reference = run.beam_maps()?;
    let slab = run.checker_slab()?;
    run.convergence_studies(&slab, stripe_reference)?;
    run.notes(start);
    write_atomic(&out.join("errors.csv"), errors_csv(&run.rows).as_bytes())?;
    let path = out.join("report.md");
    write_atomic(&path, run.report.as_bytes())?;
    Ok(path)
}

/// What the steps of one [`reproduce`] run share: where it writes, its scale and seed, the
/// ledger of finished steps, the progress callback, and the error rows and report so far.
struct Reproduction<'a> {
    out: &'a Path,
    scale: &'a Scale,
    seed: u64,
    ledger: Ledger,
    step: &'a mut dyn FnMut(&str),
    rows: Vec<ErrorRow>,
    report: String,
}

/// The checker slab of Figure 5 as rendered: its scene, the job every method's render starts
/// from, and the path-traced reference (as written).
struct Slab {
    scene: Scene,
    base: RenderJob,
    reference: tracer::film::Film,
}

impl Reproduction<'_> {
    /// 1. The beam maps (Figure 4) of both presets, their error table and comments; returns
    ///    the stripe preset's setup and reference for the beam convergence study.
    fn beam_maps(&mut self) -> Result<(BeamSetup, Vec<f64>), ReproduceError> {
        let mut stripe_reference: Option<(BeamSetup, Vec<f64>)> = None;
        let _ = writeln!(
            self.report,
            "## Figure 4: a pencil beam in a textured half-space\n\nσs = 1, isotropic, η = 1, multiple \
             scattering only; σa = 0.005 / 0.1 (stripes at 45° or checks, width 4). Maps cover \
             [−15, 15]², {n} × {n} pixels; the reference is light tracing with {p} photons. Errors \
             ignore pixels within 1 unit of the beam (the singular peak). These are one seed's \
             numbers: differences between estimators smaller than the seed-to-seed spread \
             (docs/results.md gives it over 4 seeds) mean nothing.\n",
            n = self.scale.beam_resolution,
            p = self.scale.beam_photons
        );
        for preset in ["stripe", "check"] {
            let reference = self.beam_preset(preset)?;
            if preset == "stripe" {
                stripe_reference = Some(reference);
            }
        }
        let _ = writeln!(
            self.report,
            "{}",
            error_table(
                self.rows
                    .iter()
                    .filter(|r| r.experiment.starts_with("beam"))
            )
        );
        for preset in ["stripe", "check"] {
            let experiment = format!("beam {preset}");
            let of: Vec<&ErrorRow> = self
                .rows
                .iter()
                .filter(|r| r.experiment == experiment)
                .collect();
            let _ = write!(
                self.report,
                "{}",
                crate::commentary::beam_comment(preset, &of)
            );
        }
        let _ = writeln!(self.report);
        Ok(stripe_reference.expect("the stripe preset ran"))
    }

    /// The beam maps of one texture preset: the light-traced reference, then every estimator
    /// with both profiles in the reference's colour range, with their error rows and the
    /// report's section; returns the preset's setup and reference.
    fn beam_preset(&mut self, preset: &str) -> Result<(BeamSetup, Vec<f64>), ReproduceError> {
        let (scale, seed) = (self.scale, self.seed);
        let dir = self.out.join("beam").join(preset);
        mkdir(&dir)?;
        let mut setup = BeamSetup::paper(BeamTexture::preset(preset).expect("built-in preset"));
        setup.resolution = scale.beam_resolution;
        let pt_values = self.beam_reference(preset, &setup, &dir.join("pt.exr"))?;
        // Every map of the preset in the reference's colour range, so that panels compare.
        let range = ColourRange::of(&pt_values);
        let n = setup.resolution as usize;
        let keep = |i: usize| {
            let (x, y) = (i % n, i / n);
            let e = setup.extent;
            let px = -e + (x as f64 + 0.5) * 2.0 * e / n as f64;
            let py = e - (y as f64 + 0.5) * 2.0 * e / n as f64;
            px.hypot(py) >= 1.0
        };
        let mut images = vec![format!("![pt](beam/{preset}/pt.png)")];
        for profile in [ProfileModel::Dipole, ProfileModel::Pbd] {
            for est in BEAM_ESTIMATORS {
                let name = format!("{est}-{profile}");
                let path = dir.join(format!("{name}.exr"));
                let key = format!("beam/{preset}/{name}");
                images.push(format!("![{name}](beam/{preset}/{name}.png)"));
                let label = format!("beam {preset}: {est} with {profile}");
                let row = self.ledger.step(&key, &[&path], self.step, &label, || {
                    let map = run_method(
                        &setup,
                        method(est),
                        profile,
                        PhotonBudget::Count(1),
                        scale.beam_subsamples,
                        seed,
                        &|_| {},
                    )?;
                    write_beam_map_in(
                        &map,
                        &setup,
                        &path,
                        serde_json::json!({"seed": seed}),
                        range,
                    )?;
                    let metrics =
                        compare(&map.values, &pt_values, 1, keep).map_err(StudyError::from)?;
                    Ok::<_, ReproduceError>(ErrorRow {
                        experiment: format!("beam {preset}"),
                        method: name,
                        seconds: map.seconds,
                        metrics,
                    })
                })?;
                self.rows.push(row);
            }
        }
        let _ = writeln!(
            self.report,
            "### {preset}\n\nEvery map of this preset is drawn over the reference's colour range \
             ({:.1e} to {:.1e} per unit area), so that equal colours are equal exitances.\n\n{}\n",
            range.min,
            range.max,
            images.join(" ")
        );
        Ok((setup, pt_values))
    }

    /// The light-traced reference map of a beam preset (as written): read from `pt_path` when
    /// an earlier run finished it, else traced and written there.
    fn beam_reference(
        &mut self,
        preset: &str,
        setup: &BeamSetup,
        pt_path: &Path,
    ) -> Result<Vec<f64>, ReproduceError> {
        let key = format!("beam/{preset}/pt");
        if self.ledger.reuse::<bool>(&key, &[pt_path])?.is_some() {
            (self.step)(&format!("beam {preset}: light tracing (done earlier)"));
            return Ok(tracer::output::read_exr(pt_path)?
                .pixels
                .iter()
                .map(|p| p.0[0])
                .collect());
        }
        (self.step)(&format!(
            "beam {preset}: light tracing {} photons",
            self.scale.beam_photons
        ));
        let ref_seed = self.seed.wrapping_add(REFERENCE_SEED_OFFSET);
        let pt = run_method(
            setup,
            Method::PathTraced,
            ProfileModel::Dipole,
            PhotonBudget::Count(self.scale.beam_photons),
            1,
            ref_seed,
            &|_| {},
        )?;
        write_beam_map(&pt, setup, pt_path, serde_json::json!({"seed": ref_seed}))?;
        self.ledger.record(&key, &true)?;
        let mut values = pt.values;
        as_written(&mut values);
        Ok(values)
    }

    /// 2. The checker slab (Figure 5): the reference and every method's render, their error
    ///    rows and the report's section.
    fn checker_slab(&mut self) -> Result<Slab, ReproduceError> {
        let (scale, seed) = (self.scale, self.seed);
        let slab_dir = self.out.join("slab");
        mkdir(&slab_dir)?;
        let r = scale.slab_resolution;
        let scene =
            Scene::from_toml_str(CHECKER_SLAB, Path::new("."), "checker-slab.toml (built in)")?
                .with_resolution(r, r)
                .expect("positive resolution");
        let base = RenderJob {
            seed,
            ..RenderJob::from_scene(&scene, Method::PathTraced)
        };
        let reference_film = self.slab_reference(&scene, &base, &slab_dir)?;
        let mut slab_images = vec!["![reference](slab/reference-pt.png)".to_string()];
        for name in SLAB_METHODS {
            let path = slab_dir.join(format!("{name}.exr"));
            let key = format!("slab/{name}");
            slab_images.push(format!("![{name}](slab/{name}.png)"));
            let label = format!("checker slab: {name} at {} spp", scale.slab_spp);
            let row = self.ledger.step(&key, &[&path], self.step, &label, || {
                let job = RenderJob {
                    method: method(name),
                    budget: Budget::Samples(scale.slab_spp),
                    ..base.clone()
                };
                let outcome = render_scene(&scene, &job).map_err(StudyError::from)?;
                write_render(&outcome, &scene, &job, &path, 0.0)?;
                let metrics = compare_films(&outcome.film, &reference_film, None)
                    .map_err(StudyError::from)?;
                Ok::<_, ReproduceError>(ErrorRow {
                    experiment: "checker slab".into(),
                    method: name.into(),
                    seconds: outcome.seconds,
                    metrics,
                })
            })?;
            self.rows.push(row);
        }
        let _ = writeln!(
            self.report,
            "## Figure 5: the checker slab\n\nThe box [−10, 10]² × [−10, 0], σs = 1, σa = checks of \
             0.005 / 0.1 (width 4), η = 1, one directional light along −(0.4, 0, 1); orthographic view \
             from above, {r} × {r}. Reference: path tracing at {} spp; methods at {} spp.\n\n{}\n\n{}",
            scale.slab_reference_spp,
            scale.slab_spp,
            slab_images.join(" "),
            error_table(self.rows.iter().filter(|r| r.experiment == "checker slab"))
        );
        let sone_mean = tracer::output::read_exr(&slab_dir.join("sone.exr"))?.mean();
        let reference_mean = reference_film.mean();
        if let Some(c) = crate::commentary::slab_comment(sone_mean.0[0] / reference_mean.0[0]) {
            let _ = writeln!(self.report, "{c}\n");
        }
        Ok(Slab {
            scene,
            base,
            reference: reference_film,
        })
    }

    /// The checker slab's path-traced reference (as written): read from `slab_dir` when an
    /// earlier run finished it, else rendered and written there (EXR and PNG).
    fn slab_reference(
        &mut self,
        scene: &Scene,
        base: &RenderJob,
        slab_dir: &Path,
    ) -> Result<tracer::film::Film, ReproduceError> {
        let reference_path = slab_dir.join("reference-pt.exr");
        let reference_png = slab_dir.join("reference-pt.png");
        if self
            .ledger
            .reuse::<bool>("slab/reference", &[&reference_path, &reference_png])?
            .is_some()
        {
            (self.step)("checker slab: path-traced reference (done earlier)");
            return Ok(tracer::output::read_exr(&reference_path)?);
        }
        (self.step)(&format!(
            "checker slab: path-traced reference at {} spp",
            self.scale.slab_reference_spp
        ));
        let reference = render_scene(
            scene,
            &RenderJob {
                budget: Budget::Samples(self.scale.slab_reference_spp),
                seed: self.seed.wrapping_add(REFERENCE_SEED_OFFSET),
                ..base.clone()
            },
        )
        .map_err(StudyError::from)?;
        write_exr(&reference.film, &reference_path)?;
        tracer::output::write_png(&reference.film, &reference_png, 0.0)?;
        self.ledger.record("slab/reference", &true)?;
        let mut film = reference.film;
        for p in &mut film.pixels {
            as_written(&mut p.0);
        }
        Ok(film)
    }

    /// 3. Convergence studies on the checker slab and on the stripe beam (its setup and
    ///    reference `stripe`), and the report's section on them.
    fn convergence_studies(
        &mut self,
        slab: &Slab,
        stripe: (BeamSetup, Vec<f64>),
    ) -> Result<(), ReproduceError> {
        let (scale, seed) = (self.scale, self.seed);
        let methods: Vec<Method> = CONVERGE_METHODS.iter().map(|m| method(m)).collect();
        let dir = self.out.join("converge-slab");
        mkdir(&dir)?;
        let csv = dir.join("convergence.csv");
        let slab_summary = self.ledger.step(
            "converge-slab",
            &[&csv],
            self.step,
            "convergence study: checker slab",
            || {
                let spp: Vec<u32> = std::iter::successors(Some(1u32), |s| Some(s * 2))
                    .take_while(|&s| s <= scale.converge_max_spp)
                    .collect();
                let slab_runs = scene_study(
                    &slab.scene,
                    &slab.base,
                    &methods,
                    &spp,
                    &slab.reference,
                    |_, _| {},
                )?;
                let slab_summary = summarize(&slab_runs);
                write_outputs(
                    &dir,
                    "checker slab — error against time",
                    &slab_runs,
                    &slab_summary,
                    serde_json::json!({"reference_spp": scale.slab_reference_spp}),
                )?;
                Ok::<_, ReproduceError>(slab_summary)
            },
        )?;
        let (setup, pt_values) = stripe;
        let dir = self.out.join("converge-beam-stripe");
        mkdir(&dir)?;
        let csv = dir.join("convergence.csv");
        let beam_summary = self.ledger.step(
            "converge-beam-stripe",
            &[&csv],
            self.step,
            "convergence study: beam, stripe preset",
            || {
                let budgets = BeamBudgets {
                    photons: std::iter::successors(Some(1u64 << 16), |p| Some(p * 2))
                        .take_while(|&p| p <= scale.converge_max_photons.max(1 << 16))
                        .collect(),
                    subsamples: std::iter::successors(Some(1u32), |k| Some(k * 2))
                        .take_while(|&k| k <= scale.converge_max_subsamples)
                        .collect(),
                };
                let beam_runs = beam_study(
                    &setup,
                    &methods,
                    ProfileModel::Dipole,
                    &budgets,
                    seed,
                    BeamReference {
                        values: &pt_values,
                        min_radius: 1.0,
                    },
                    |_, _| {},
                )?;
                let beam_summary = summarize(&beam_runs);
                write_outputs(
                    &dir,
                    "beam (stripe) — error against time",
                    &beam_runs,
                    &beam_summary,
                    serde_json::json!({"setup": setup, "min_radius": 1.0}),
                )?;
                Ok::<_, ReproduceError>(beam_summary)
            },
        )?;
        let _ = writeln!(
            self.report,
            "## Error against time\n\nEach method at doubling budgets against the references above \
             (full data: `convergence.csv`). *Converged error*: relative L2 at the largest budget; \
             *time*: first budget within 10 % of it; *PT time*: what path tracing needs for the same \
             error (interpolated log–log, or extrapolated along t^(−1/2), marked \\*).\n\n### Checker slab\n\n\
             ![convergence](converge-slab/convergence.png)\n\n{}\n{}\n### Beam, stripe preset (dipole)\n\n\
             ![convergence](converge-beam-stripe/convergence.png)\n\n{}\n{}",
            summary_table(&slab_summary),
            crate::commentary::speedup_comment("checker slab", &slab_summary),
            summary_table(&beam_summary),
            crate::commentary::speedup_comment("stripe beam map", &beam_summary)
        );
        Ok(())
    }

    /// The report's closing notes: the command, its time (from `start`), how much was
    /// resumed.
    fn notes(&mut self, start: Instant) {
        let (reused, steps) = self.ledger.reused();
        let resumed = if reused > 0 {
            format!(" (resumed: {reused} of its {steps} steps were finished by an earlier run)")
        } else {
            String::new()
        };
        let _ = writeln!(
            self.report,
            "## Notes\n\n* Every figure above was produced by `het-bssrdf reproduce --scale {}` in {:.0} s{resumed}.\n\
             * Scattering orders: multiple only ({}), as in the paper.\n\
             * Error tables as CSV: `errors.csv`.\n",
            self.scale.name,
            start.elapsed().as_secs_f64(),
            Scattering::Multiple
        );
    }
}

fn error_table<'a>(rows: impl Iterator<Item = &'a ErrorRow>) -> String {
    let mut s = String::from(
        "| experiment | method | seconds | rel. L2 | RMSE | mean abs log10 |\n|---|---|---:|---:|---:|---:|\n",
    );
    for r in rows {
        let _ = writeln!(
            s,
            "| {} | {} | {:.2} | {:.4} | {:.3e} | {:.4} |",
            r.experiment,
            r.method,
            r.seconds,
            r.metrics.rel_l2,
            r.metrics.rmse,
            r.metrics.mean_abs_log10
        );
    }
    s
}

fn summary_table(summary: &[MethodSummary]) -> String {
    let mut s = String::from(
        "| method | converged rel. L2 | mean abs log10 | time (s) | PT time (s) | speed-up |\n|---|---:|---:|---:|---:|---:|\n",
    );
    for m in summary {
        let star = if m.pt_extrapolated { "\\*" } else { "" };
        let _ = writeln!(
            s,
            "| {} | {:.4} | {:.4} | {:.3} | {} | {} |",
            m.method,
            m.converged_error,
            m.converged_mean_abs_log10,
            m.time_to_converge,
            m.pt_time_to_same_error
                .map(|t| format!("{t:.3}{star}"))
                .unwrap_or_else(|| "–".into()),
            m.speedup
                .map(|x| format!("{x:.2}×"))
                .unwrap_or_else(|| "–".into())
        );
    }
    s
}

fn errors_csv(rows: &[ErrorRow]) -> String {
    let mut s = String::from("experiment,method,seconds,rel_l2,rmse,mean_abs_log10\n");
    for r in rows {
        let _ = writeln!(
            s,
            "{},{},{:.6},{:.6e},{:.6e},{:.6e}",
            r.experiment,
            r.method,
            r.seconds,
            r.metrics.rel_l2,
            r.metrics.rmse,
            r.metrics.mean_abs_log10
        );
    }
    s
}

#[cfg(test)]
mod tests {
    use het_estimate::SemiMinorAxis;
    use tracer::integrator::Method;

    /// `reproduce` runs the paper's Sone (b = w/2), not the command line's default (b = w).
    #[test]
    fn reproduce_runs_the_papers_sone() {
        assert_eq!(
            super::method("sone").semi_minor(),
            Some(SemiMinorAxis::HalfWidth)
        );
        let default: Method = "sone".parse().unwrap();
        assert_eq!(default.semi_minor(), Some(SemiMinorAxis::Width));
        assert_eq!(super::method("kernel").semi_minor(), None);
    }
}
